"""A catalogue of bad inputs, each run through the real command line in a subprocess.

Every case must end with exit status 2, exactly one line on stderr starting with
``skygas: error:`` (no traceback, no pydantic wording), and leave the folder it ran in exactly
as it was: no ``--out`` folder created, no file written, changed or removed. Most cases fail
before any numerics, so each takes about the start-up time of the command line.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from skygas import cli

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
CHAMBER = (EXAMPLES / "closed-chamber.toml").read_text()
NEURON = (EXAMPLES / "neuron.toml").read_text()
RESHUFFLER_TOML = "[device]\nchamber_diameter = 1024\n"


def _replace_line(text: str, key: str, line: str) -> str:
    lines = text.splitlines()
    hits = [i for i, old in enumerate(lines) if old.startswith(f"{key} =")]
    assert hits, key
    lines[hits[0]] = line
    return "\n".join(lines) + "\n"


def _manifest(command: str, finished: bool = True) -> str:
    return json.dumps(
        {
            "command": command,
            "skygas_version": "0",
            "config_hash": "x",
            "started_at": "2026-01-01T00:00:00Z",
            "finished_at": "2026-01-01T00:01:00Z" if finished else None,
        }
    )


#: the files each case finds in its working folder
FILES = {
    "afile": "not a folder\n",
    "big.toml": _replace_line(CHAMBER, "duration", "duration = 1e300"),
    "zero.toml": _replace_line(CHAMBER, "duration", "duration = 0"),
    "hot.toml": _replace_line(CHAMBER, "temperature", "temperature = 1e9"),
    "typo.toml": CHAMBER.replace("temperature =", "tempreature ="),
    "nan.toml": _replace_line(CHAMBER, "temperature", "temperature = nan"),
    "tiny-length.toml": _replace_line(CHAMBER, "chamber_diameter", "chamber_diameter = 1e-15"),
    "rate.toml": _replace_line(NEURON, "rate", "rate = 1e20"),
    "reshuffler.toml": RESHUFFLER_TOML,
    "walls.toml": CHAMBER + '\n[forces]\nwall_geometry = "everywhere"\n',
    "quick.toml": (EXAMPLES / "sweeps" / "quick-current.toml").read_text(),
    "x.creating/zarr.json": "{}",
    # a finished reshuffler run
    "done/manifest.json": _manifest("reshuffle"),
    "done/summary.json": '{"p_out": 0.5}\n',
    # an interrupted simulation
    "stopped/manifest.json": _manifest("simulate", finished=False),
    "stopped/checkpoint.npz": "state\n",
}

# (arguments, text the error line must contain); "OUT" is a folder that does not exist yet
CASES = {
    # tracebacks before
    "duration inf flag": (["reshuffle", "--duration", "inf", "--out", "OUT"], "--duration = inf"),
    "duration 1e300 toml": (["simulate", "big.toml", "--out", "OUT"], "duration = 1e+300"),
    "wall geometry toml": (
        ["simulate", "walls.toml", "--out", "OUT"],
        "forces.wall_geometry = 'everywhere'",
    ),
    "check-timestep inf": (["check-timestep", "big.toml", "--duration", "inf"], "duration = inf"),
    "out under /proc": (
        ["reshuffle", "--out", "/proc/skygas-test/x"],
        "--out = '/proc/skygas-test/x'",
    ),
    "out is a file": (["reshuffle", "--out", "afile"], "--out = 'afile'"),
    "out under a file": (["sc", "demo", "--out", "afile/sub"], "--out = 'afile/sub'"),
    "sc demo out is a file": (["sc", "demo", "--out", "afile"], "--out = 'afile'"),
    "sweep out is a file": (["sweep", "quick.toml", "--out", "afile", "--serial"], "--out"),
    "plot an unfinished store": (["plot", "x.creating", "--out", "OUT"], "STORE = "),
    "neuron rate 1e20": (["neuron", "rate.toml", "--out", "OUT"], "inputs.rate = 1e+20"),
    "sc demo 1e10 bits": (
        ["sc", "demo", "--n-bits", "10000000000", "--out", "OUT"],
        "--n-bits = 10000000000",
    ),
    # results overwritten or lost
    "another command's folder": (["neuron", "--out", "done"], "results of `skygas reshuffle`"),
    "finished results": (["reshuffle", "--out", "done"], "--overwrite"),
    "interrupted run without --resume": (
        ["simulate", str(EXAMPLES / "closed-chamber.toml"), "--out", "stopped"],
        "--resume",
    ),
    # nonsense accepted (refused under --strict)
    "temperature 1e9 strict": (
        ["simulate", "hot.toml", "--out", "OUT", "--strict"],
        "temperature = 1000000000.0",
    ),
    "current 1e20 strict": (
        ["reshuffle", "--current-density", "1e20", "--strict", "--out", "OUT"],
        "--current-density = 1e+20",
    ),
    # unclear messages before
    "chamber 1024 flag": (
        ["reshuffle", "--chamber-diameter", "1024", "--out", "OUT"],
        "did you mean 1024e-9",
    ),
    "chamber 1024 toml": (
        ["reshuffle", "reshuffler.toml", "--out", "OUT"],
        "device.chamber_diameter = 1024",
    ),
    "negative temperature flag": (
        ["reshuffle", "--temperature", "-5", "--out", "OUT"],
        "--temperature = -5.0: expected a number >= 0",
    ),
    "nan temperature flag": (
        ["reshuffle", "--temperature", "nan", "--out", "OUT"],
        "--temperature = nan: expected a finite number",
    ),
    "nan temperature toml": (["simulate", "nan.toml", "--out", "OUT"], "a finite number"),
    "negative current is a value": (
        ["reshuffle", "--current-density", "-1e11", "--out", "OUT"],
        "--current-density = -1",
    ),
    "duration 0 simulate": (["simulate", "zero.toml", "--out", "OUT"], "duration = 0"),
    "duration 0 reshuffle": (["reshuffle", "--duration", "0", "--out", "OUT"], "--duration = 0"),
    "duration 0 neuron": (["neuron", "--duration", "0", "--out", "OUT"], "--duration = 0"),
    # more of our own
    "length below a picometre": (["simulate", "tiny-length.toml", "--out", "OUT"], "metres"),
    "misspelt field": (["simulate", "typo.toml", "--out", "OUT"], "check the spelling"),
    "missing config": (["simulate", "nope.toml", "--out", "OUT"], "config = 'nope.toml'"),
    "negative seed": (["reshuffle", "--seed", "-1", "--out", "OUT"], "--seed = -1"),
    "p above one": (["reshuffle", "--p", "1.5", "--out", "OUT"], "--p = 1.5"),
    "unknown material": (
        ["reshuffle", "--material", "unobtainium", "--out", "OUT"],
        "material = 'unobtainium'",
    ),
    "negative checkpoint interval": (
        ["reshuffle", "--checkpoint-seconds", "-1e3", "--out", "OUT"],
        "--checkpoint-seconds = -1000.0",
    ),
    "negative bit count": (["sc", "demo", "--n-bits", "-5", "--out", "OUT"], "--n-bits = -5"),
    "diameters not numbers": (
        ["saturation", "--diameters", "big", "--out", "OUT"],
        "diameters[0] = 'big'",
    ),
    "saturation inf temperature": (
        ["saturation", "--diameters", "300e-9", "--temperature", "inf", "--out", "OUT"],
        "--temperature = inf: expected a finite number",
    ),
    "export of nothing": (["export", "OUT", "--format", "gsd", "--out", "OUT.gsd"], "OUT"),
    "inspect a missing file": (["micromag", "inspect", "missing.ovf"], "missing.ovf"),
    "memory limit": (["sc", "demo", "--out", "OUT"], "fits in memory"),
}


def _snapshot(folder: Path) -> dict[str, bytes | None]:
    """Every path under ``folder`` with the bytes of the files (None for folders)."""
    return {
        str(p.relative_to(folder)): (p.read_bytes() if p.is_file() else None)
        for p in sorted(folder.rglob("*"))
    }


def _run(args: list[str], cwd: Path, env: dict | None = None) -> subprocess.CompletedProcess:
    environment = {**os.environ, "PYTHONWARNINGS": "ignore", **(env or {})}
    return subprocess.run(
        [sys.executable, "-m", "skygas.cli", *args],
        cwd=cwd,
        env=environment,
        capture_output=True,
        text=True,
        timeout=300,
    )


@pytest.mark.parametrize("name", list(CASES))
def test_bad_input_exits_2_with_one_line_and_writes_nothing(name, tmp_path):
    args, expected = CASES[name]
    for relative, text in FILES.items():
        (tmp_path / relative).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / relative).write_text(text)
    if name == "out under /proc" and not Path("/proc").is_dir():
        pytest.skip("no /proc on this system")
    env = {"SKYGAS_MEMORY_LIMIT": "1e6"} if name == "memory limit" else None
    before = _snapshot(tmp_path)
    proc = _run(args, tmp_path, env)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2, proc.stderr
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("skygas: error: "), lines[0]
    assert expected in lines[0], lines[0]
    for leak in ("Traceback", "Input should", "pydantic", "Value error"):
        assert leak not in proc.stderr
    assert _snapshot(tmp_path) == before  # nothing created, written, changed or removed
    assert proc.stdout == ""


def test_every_subparser_takes_negative_numbers_with_exponents():
    parser = cli.build_parser()
    for value in ("-1e11", "-2.5E-9", "-.5", "-3", "-inf"):
        args = parser.parse_args(["reshuffle", "--out", "o", "--current-density", value])
        assert (
            args.current_density == float(value)
            or value == "-inf"
            and args.current_density == float("-inf")
        )
    args = parser.parse_args(["sc", "demo", "--out", "o", "--n-bits", "-5"])
    assert args.n_bits == -5
    args = parser.parse_args(["micromag", "inspect", "f.ovf", "--threshold", "-1e-1"])
    assert args.threshold == -0.1
    with pytest.raises(SystemExit):  # an option that does not exist is still an option
        parser.parse_args(["reshuffle", "--out", "o", "-x"])


def _subparsers(parser, prefix=""):
    for action in parser._actions:
        if hasattr(action, "choices") and isinstance(action.choices, dict):
            for name, sub in action.choices.items():
                yield f"{prefix}{name}", sub
                yield from _subparsers(sub, f"{prefix}{name} ")


def test_help_shows_defaults_and_one_example_per_command():
    parser = cli.build_parser()
    commands = dict(_subparsers(parser))
    assert {"simulate", "reshuffle", "neuron", "sweep", "sc demo", "micromag fit"} <= set(commands)
    for name, sub in commands.items():
        text = sub.format_help()
        assert "example:\n  skygas " in text, name
    reshuffle = commands["reshuffle"].format_help()
    assert "(default: 300.0)" in commands["saturation"].format_help()  # --temperature
    assert "--overwrite" in reshuffle and "--strict" in reshuffle
    assert (
        "(default: 4096)" in commands["sc demo"].format_help()
        or "default 4096" in commands["sc demo"].format_help()
    )


def test_an_internal_error_is_one_line_with_status_70_and_debug_shows_the_traceback(
    tmp_path, monkeypatch, capsys
):
    def broken(args):
        raise RuntimeError("something skygas did not foresee")

    import skygas.commands.report as report

    monkeypatch.setattr(report, "_report", broken)
    assert cli.main(["report", str(tmp_path)]) == cli.EXIT_INTERNAL
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("skygas: internal error: RuntimeError")
    assert "--debug" in err[0]
    with pytest.raises(RuntimeError):
        cli.main(["--debug", "report", str(tmp_path)])


def test_a_run_folder_is_refused_twice_then_replaced_with_overwrite(tmp_path, capsys):
    out = tmp_path / "run"
    args = [
        "reshuffle",
        "--duration",
        "1e-8",
        "--out",
        str(out),
        "--json",
        "--no-report",
        "--quiet",
    ]
    assert cli.main(args) == 0
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["command"] == "reshuffle" and manifest["finished_at"] is not None
    assert manifest["command_line"] == args and len(manifest["config_hash"]) == 16
    (out / "notes.txt").write_text("mine")
    before = _snapshot(out)
    capsys.readouterr()
    assert cli.main(args) == 2
    assert "--overwrite" in capsys.readouterr().err
    assert _snapshot(out) == before
    assert cli.main([*args, "--seed", "5", "--overwrite"]) == 0
    summary = json.loads(capsys.readouterr().out)  # one JSON object, standard JSON
    assert summary["seed"] == 5
    assert (out / "notes.txt").read_text() == "mine"  # nothing else in the folder is deleted
    assert json.loads((out / "manifest.json").read_text())["config_hash"] != manifest["config_hash"]


def test_a_sanity_finding_is_a_warning_without_strict(tmp_path):
    proc = _run(
        [
            "reshuffle",
            "--temperature",
            "1e9",
            "--duration",
            "1e-8",
            "--out",
            "run",
            "--json",
            "--no-report",
            "--quiet",
        ],
        tmp_path,
    )
    assert proc.returncode == 0, proc.stderr
    warnings = proc.stderr.strip().splitlines()
    assert warnings and all(w.startswith("skygas: warning: ") for w in warnings)
    assert any("temperature = 1000000000.0" in w and "600 K" in w for w in warnings)
    json.loads(proc.stdout)


# -- outputs never overwrite inputs (issue: nothing lost) --
# export, animate, report and plot read a run folder or a sweep store and write something made
# from it: an --out over one of their inputs, a run's results or into a store is refused, one
# line before any work, and an existing file is replaced only with --overwrite.

#: a finished run folder and a sweep store, as these commands find them (never read: every case
#: is refused before the run is loaded)
SAFE_FILES = {
    "run/manifest.json": _manifest("simulate"),
    "run/trajectories.nc": "netcdf\n",
    "run/summary.json": '{"seed": 4}\n',
    "run/report.html": "<html>the run's report</html>\n",
    "store.zarr/zarr.json": '{"zarr_format": 3, "node_type": "group"}\n',
    "store.zarr/seed/zarr.json": '{"zarr_format": 3, "node_type": "array"}\n',
    "old.gsd": "an earlier export\n",
    "old.mp4": "an earlier movie\n",
    "old.html": "an earlier report\n",
}

SAFE_CASES = {
    "export over its result file": (
        ["export", "run", "--format", "gsd", "--out", "run/trajectories.nc"],
        "not one of the command's inputs",
    ),
    "export over the run's summary": (
        ["export", "run", "--format", "extxyz", "--out", "run/summary.json"],
        "the only kind written into the run folder",
    ),
    "export over the run's manifest": (
        ["export", "run/trajectories.nc", "--format", "gsd", "--out", "run/manifest.json"],
        "never replaced",
    ),
    "export over an existing file": (
        ["export", "run", "--format", "gsd", "--out", "old.gsd"],
        "add --overwrite",
    ),
    "export into a store": (
        ["export", "run", "--format", "gsd", "--out", "store.zarr/run.gsd", "--overwrite"],
        "outside the sweep store",
    ),
    "animate over its result file": (
        ["animate", "run", "--out", "run/trajectories.nc"],
        "--out = 'run/trajectories.nc'",
    ),
    "animate over an existing movie": (["animate", "run", "--out", "old.mp4"], "add --overwrite"),
    "report over the run's summary": (
        ["report", "run", "--out", "run/summary.json"],
        "not one of the command's inputs",  # the report reads the summary
    ),
    "report over an existing file": (["report", "run", "--out", "old.html"], "add --overwrite"),
    "report over its input": (
        ["report", "run/trajectories.nc", "--out", "run/trajectories.nc", "--overwrite"],
        "not one of the command's inputs",
    ),
    "report into the store": (
        ["report", "store.zarr", "--out", "store.zarr/report.html"],
        "beside the store, e.g. --out store-report.html",
    ),
    "report into another store": (
        ["report", "run", "--out", "store.zarr/seed/report.html", "--overwrite"],
        "outside the sweep store",
    ),
    "plot into its store": (["plot", "store.zarr", "--out", "store.zarr"], "outside the input"),
    "plot into a folder of its store": (
        ["plot", "store.zarr", "--out", "store.zarr/figs"],
        "outside the input",
    ),
    "plot into a run folder": (["plot", "store.zarr", "--out", "run/figs"], "run folder"),
}


@pytest.mark.parametrize("name", list(SAFE_CASES))
def test_an_output_over_an_input_is_refused_and_the_inputs_are_unchanged(name, tmp_path):
    args, expected = SAFE_CASES[name]
    for relative, text in SAFE_FILES.items():
        (tmp_path / relative).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / relative).write_text(text)
    before = _snapshot(tmp_path)
    proc = _run(args, tmp_path)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2, proc.stderr
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("skygas: error: --out = "), lines[0]
    assert expected in lines[0], lines[0]
    assert _snapshot(tmp_path) == before  # inputs byte-identical, nothing created or left behind
    assert proc.stdout == ""


def test_the_reading_commands_take_overwrite():
    commands = dict(_subparsers(cli.build_parser()))
    for name in ("export", "animate", "report", "plot"):
        assert "--overwrite" in commands[name].format_help(), name


# -- readers fail cleanly (issue: nothing lost) --
def _npz_bytes(**arrays) -> bytes:
    import io

    import numpy as np

    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    return buffer.getvalue()


def _netcdf_bytes(tmp_path: Path) -> bytes:
    """A netCDF file that no skygas command wrote."""
    import numpy as np
    import xarray as xr

    file = tmp_path / "foreign-source.nc"
    xr.Dataset({"a": ("t", np.arange(200.0))}).to_netcdf(file)
    data = file.read_bytes()
    file.unlink()
    return data


def _reader_files(tmp_path: Path) -> dict[str, bytes]:
    """The files the reader cases find in their working folder."""
    import numpy as np

    short = _replace_line(CHAMBER, "duration", "duration = 5e-9")
    netcdf = _netcdf_bytes(tmp_path)
    ovf = (ROOT / "src/skygas/data/ovf/disk-tilted-edges.ovf").read_bytes()
    checkpoint = _npz_bytes(fingerprint=np.array("x"), sha256=np.array("0" * 64), a=np.ones(50))
    stopped = _manifest("simulate", finished=False).replace('"x"', "null").encode()
    return {
        "binary.toml": b"\xff\xfe\x00seed = 1\n",
        "bool.toml": _replace_line(CHAMBER, "temperature", "temperature = true").encode(),
        "string.toml": _replace_line(CHAMBER, "temperature", 'temperature = "300"').encode(),
        "no-duration.toml": "\n".join(
            line for line in CHAMBER.splitlines() if not line.startswith("duration =")
        ).encode(),
        "three.toml": (
            short.replace("random_count = 45", "positions = [[1e-7, 0.0, 0.0]]")
        ).encode(),
        "sparse.toml": _replace_line(short, "record_interval", "record_interval = 1e-8").encode(),
        "pinned.toml": (
            short + '\n[[potentials]]\nkind = "random_pinning"\ndensity = 1e40\n'
            "sigma = 5e-9\ndepth_kT = 2.0\n"
        ).encode(),
        "garbage/manifest.json": stopped,
        "garbage/checkpoint.npz": b"state\n",
        "empty/manifest.json": stopped,
        "empty/checkpoint.npz": b"",
        "cut/manifest.json": stopped,
        "cut/checkpoint.npz": checkpoint[: len(checkpoint) // 2],
        "flipped/manifest.json": stopped,
        "flipped/checkpoint.npz": checkpoint,  # its hash does not match its arrays
        "nc-empty/trajectories.nc": b"",
        "nc-cut/trajectories.nc": netcdf[: len(netcdf) // 3],
        "nc-foreign/trajectories.nc": netcdf,
        "nc-text/trajectories.nc": b"not a netCDF file\n",
        "store-empty/zarr.json": b"{}",
        "store-garbage/zarr.json": b"\x00\x01 not json",
        "cut.ovf": ovf[:800],
        "bits.csv": b"\xff\xfe\x01\x00",
        "bits.toml": b'[signal]\nkind = "file"\npath = "bits.csv"\n',
    }


_SIMULATE = [sys.executable, "-m", "skygas.cli", "simulate"]
_RESUME = ["simulate", str(EXAMPLES / "closed-chamber.toml"), "--resume", "--out"]

# (arguments, text the error line must contain, more text it must contain)
READER_CASES = {
    "binary toml": (["simulate", "binary.toml", "--out", "OUT"], "config = 'binary.toml'", "UTF-8"),
    "true as a number": (
        ["simulate", "bool.toml", "--out", "OUT"],
        "temperature = True",
        "a number",
    ),
    "string as a number": (
        ["simulate", "string.toml", "--out", "OUT"],
        "temperature = '300'",
        "without quotes",
    ),
    "field required": (
        ["simulate", "no-duration.toml", "--out", "OUT"],
        "duration",
        "a value (this field is required)",
    ),
    "three numbers for a point": (
        ["simulate", "three.toml", "--out", "OUT"],
        "skyrmions.positions.0",
        "two entries",
    ),
    "record interval beyond the run": (
        ["simulate", "sparse.toml", "--out", "OUT"],
        "record_interval = 1e-08",
        "no frame would be recorded",
    ),
    "pinning density overflow": (
        ["simulate", "pinned.toml", "--out", "OUT"],
        "potentials.0.density = 1e+40",
        "fits in memory",
    ),
    "checkpoint not an archive": ([*_RESUME, "garbage"], "checkpoint.npz", "--overwrite"),
    "checkpoint empty": ([*_RESUME, "empty"], "the file is empty", "--overwrite"),
    "checkpoint truncated": ([*_RESUME, "cut"], "truncated", "--overwrite"),
    "checkpoint bit flipped": ([*_RESUME, "flipped"], "do not match the hash", "--overwrite"),
    "netcdf empty": (["analyze", "nc-empty"], "nc-empty/trajectories.nc", "empty"),
    "netcdf truncated": (["report", "nc-cut", "--out", "OUT.html"], "nc-cut", "truncated"),
    "netcdf of another program": (
        ["export", "nc-foreign", "--format", "extxyz", "--out", "OUT.xyz"],
        "nc-foreign",
        "not a skygas run",
    ),
    "netcdf that is text": (["animate", "nc-text", "--out", "OUT.gif"], "nc-text", "not a netCDF"),
    "store without arrays": (
        ["plot", "store-empty", "--out", "OUT"],
        "STORE = 'store-empty'",
        "not a sweep store",
    ),
    "store of garbage": (["plot", "store-garbage", "--out", "OUT"], "store-garbage", "sweep store"),
    "ovf truncated": (["micromag", "inspect", "cut.ovf"], "cut.ovf", "truncated"),
    "bit file not text": (["reshuffle", "bits.toml", "--out", "OUT"], "bits.csv", "UTF-8"),
    "out empty": (["reshuffle", "--out", ""], "--out = ''", "current folder"),
    "out not text": (
        ["reshuffle", "--out", os.fsdecode(b"\xff\xfeab")],
        "--out = '\\udcff\\udcfeab'",
        "not UTF-8",
    ),
}


@pytest.mark.parametrize("name", list(READER_CASES))
def test_a_reader_refuses_a_bad_file_in_one_line_and_writes_nothing(name, tmp_path):
    args, expected, also = READER_CASES[name]
    for relative, data in _reader_files(tmp_path).items():
        (tmp_path / relative).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / relative).write_bytes(data)
    before = _snapshot(tmp_path)
    proc = _run(args, tmp_path, {"PYTHONWARNINGS": "default"})
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2, proc.stderr
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("skygas: error: "), lines[0]
    assert expected in lines[0] and also in lines[0], lines[0]
    for leak in ("Traceback", "Input should", "pydantic", "Value error", "Field required"):
        assert leak not in proc.stderr
    after = _snapshot(tmp_path)
    if "--resume" in args:  # the run's manifest is rewritten before its checkpoint is read
        after = {k: v for k, v in after.items() if not k.endswith("manifest.json")}
        before = {k: v for k, v in before.items() if not k.endswith("manifest.json")}
    assert after == before  # nothing created, written, changed or removed
    assert proc.stdout == ""


# -- estimates before allocation (issue: nothing lost) --

ESTIMATE_FILES = {
    # 10 s of the 45-skyrmion chamber, a frame every ms: its steps, not its frames, are too many
    "long.toml": _replace_line(
        _replace_line(CHAMBER, "duration", "duration = 10.0"),
        "record_interval",
        "record_interval = 1e-3",
    ),
    "huge-grid.toml": (
        "[sweep]\nreplicas = 1\n[base]\nduration = 1e-8\n[grid]\n"
        "current_density = { start = 1e11, stop = 3e11, num = 300000 }\n"
        '"signal.p" = { start = 0.2, stop = 0.8, num = 300000 }\n'
    ),
    "endless.toml": (
        '[sweep]\nreplicas = 800\n[base]\nduration = 3e-1\n[grid]\n"signal.p" = [0.2, 0.5, 0.8]\n'
    ),
    "quick.toml": (EXAMPLES / "sweeps" / "quick-current.toml").read_text(),
}

#: the speed figure the estimates use in these tests: no calibration, the same on every machine
ESTIMATE_ENV = {"SKYGAS_STEP_SECONDS": "2e-6"}

ESTIMATE_CASES = {
    "femtosecond nucleation interval": (
        ["reshuffle", "--injection-interval", "1e-15", "--out", "OUT"],
        "--injection-interval = 1e-15",
        "injection events",
    ),
    "sweep of 9e10 runs": (["sweep", "huge-grid.toml", "--out", "S"], "grid", "9e+10 runs"),
    "sweep over a day": (["sweep", "endless.toml", "--out", "S", "--serial"], "sweep", "--force"),
    "simulation over a day": (["simulate", "long.toml", "--out", "OUT"], "duration", "--force"),
    "reshuffler of 2e9 events": (
        ["reshuffle", "--duration", "10", "--out", "OUT"],
        "injection.interval = 5e-09",
        "2e+09 injection events",
    ),
    "reservoir inputs": (
        ["reservoir", "--n-inputs", "100000000000", "--out", "OUT"],
        "--n-inputs",
        "fits in memory",
    ),
    "scheduler with no answer": (
        ["sweep", "quick.toml", "--out", "S", "--scheduler", "tcp://10.255.255.1:8786"],
        "--scheduler = 'tcp://10.255.255.1:8786'",
        "no answer",
    ),
}


@pytest.mark.parametrize("name", list(ESTIMATE_CASES))
def test_an_estimate_beyond_the_machine_is_one_line(name, tmp_path):
    args, field, expected = ESTIMATE_CASES[name]
    for relative, text in ESTIMATE_FILES.items():
        (tmp_path / relative).write_text(text)
    before = _snapshot(tmp_path)
    proc = subprocess.run(  # a refusal comes before any stepping: seconds, never minutes
        [sys.executable, "-m", "skygas.cli", *args],
        cwd=tmp_path,
        env={**os.environ, "PYTHONWARNINGS": "ignore", **ESTIMATE_ENV},
        capture_output=True,
        text=True,
        timeout=60,
    )
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2, proc.stderr
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith(f"skygas: error: {field}"), lines[0]
    assert expected in lines[0], lines[0]
    assert "Traceback" not in proc.stderr
    assert _snapshot(tmp_path) == before
    assert proc.stdout == ""


def test_force_starts_a_long_run_and_announces_its_estimate(tmp_path):
    (tmp_path / "long.toml").write_text(ESTIMATE_FILES["long.toml"])
    env = {**os.environ, "PYTHONWARNINGS": "ignore", **ESTIMATE_ENV}
    proc = subprocess.Popen(
        [sys.executable, "-m", "skygas.cli", "simulate", "long.toml", "--out", "OUT", "--force"],
        cwd=tmp_path,
        env=env,
        stderr=subprocess.PIPE,
        stdout=subprocess.DEVNULL,
        text=True,
    )
    try:
        assert proc.stderr is not None
        first = proc.stderr.readline()
        # 10 s / 0.1 ns steps (the default step divides the 1 ms record interval) at 2 µs each
        assert first.startswith("skygas: estimate: "), first
        assert "steps, about" in first and "on this machine" in first, first
        assert proc.poll() is None  # started, not refused
    finally:
        proc.kill()
        proc.wait(timeout=60)


def test_the_estimator_against_a_counted_case(monkeypatch, capsys):
    from skygas.core.errors import InputError
    from skygas.core.estimates import Estimate, check, run_limits
    from skygas.reshuffler.config import parse_reshuffler_config
    from skygas.reshuffler.run import reshuffler_memory
    from skygas.runs.config import parse_config
    from skygas.runs.machine_speed import run_estimate, step_seconds
    from skygas.runs.runner import simulation_memory

    config = parse_config(
        {
            "duration": 1e-6,
            "record_interval": 1e-8,
            "geometry": {"kind": "chamber", "chamber_diameter": 1024e-9, "closed": True},
            "skyrmions": {"random_count": 10},
        }
    )
    assert simulation_memory(config, 10) == 24 * 101 * 10  # 101 frames of 10 (x, y, id)
    reshuffler = parse_reshuffler_config(
        {"duration": 1e-6, "injection": {"interval": 1e-8}, "output": {"snapshot_interval": 1e-7}}
    )
    assert reshuffler_memory(reshuffler, 100, 7) == {
        "injection.interval": 20 * 100,  # a bit and a 19-byte log entry per event
        "output.snapshot_interval": 24 * 11 * 7,  # 11 snapshots of 7 (id, x, y)
    }
    monkeypatch.setenv("SKYGAS_STEP_SECONDS", "2e-6")
    assert step_seconds(45, 2e-6) == pytest.approx(2e-6)
    estimate = run_estimate(1e9, 45, 1e6, runs=4, workers=2)
    assert estimate.seconds == pytest.approx(1e9 * 4 / 2 * 2e-6)  # 4000 s
    assert estimate.line() == (
        "skygas: estimate: 4 runs of 1e+09 steps, about 1.1 h on this machine, 977 KiB"
    )
    day = Estimate(steps=1e11, memory=1e3, seconds=2e5)
    with pytest.raises(InputError, match="--force"):
        check(day, "duration", 1.0, "the run", "use a shorter duration")
    with run_limits(force=True, announce=True):
        check(day, "duration", 1.0, "the run", "use a shorter duration")
    assert capsys.readouterr().err.startswith("skygas: estimate: 1e+11 steps, about 2.3 days")
    with run_limits(force=True, announce=True), pytest.raises(InputError, match="memory"):
        check(Estimate(1, 1e30, 1), "duration", 1.0, "the run", "use less")  # never forced


# --- skygas infer: tracks in trackpy's format ------------------------------------------------
_OUTLINE_CSV = "x,y\n0,0\n1e-6,0\n1e-6,1e-6\n0,1e-6\n"
_GOOD_ROWS = "".join(f"{f},{p},{20 + p + 0.1 * f},{30 + p}\n" for f in range(40) for p in range(3))
_STILL_ROWS = "".join(f"{f},{p},{10 * p},10\n" for f in range(100) for p in range(5))
_SHORT_ROWS = "".join(
    f"{f},{10 * f + p},{3 * p + 5},{f % 50}\n" for f in range(100) for p in range(3)
)
INFER_FILES = {
    "outline.csv": _OUTLINE_CSV,
    "tracks.csv": "frame,particle,x,y\n" + _GOOD_ROWS,
    "noframe.csv": "particle,x,y\n0,1,2\n1,2,3\n",
    "single.csv": "frame,particle,x,y\n0,0,10,10\n0,1,20,20\n",
    "still.csv": "frame,particle,x,y\n" + _STILL_ROWS,
    "short.csv": "frame,particle,x,y\n" + _SHORT_ROWS,
    "outside.csv": "frame,particle,x,y\n"
    + "".join(f"{f},{p},{500 + p},{30}\n" for f in range(40) for p in range(3)),
}
_INFER = ["infer", "--frame-interval", "5e-9", "--outline", "outline.csv", "--temperature", "300"]
INFER_CASES = {
    "no frame column": (
        [*_INFER, "noframe.csv", "--pixel-size", "1e-8", "--out", "OUT"],
        "tracks.frame",
    ),
    "pixels without a pixel size": ([*_INFER, "tracks.csv", "--out", "OUT"], "--pixel-size"),
    "a single frame": (
        [*_INFER, "single.csv", "--pixel-size", "1e-8", "--out", "OUT"],
        "at least two frames",
    ),
    "tracks outside the outline": (
        [*_INFER, "outside.csv", "--pixel-size", "1e-8", "--out", "OUT"],
        "outside it",
    ),
    "no such tracks file": (
        [*_INFER, "none.csv", "--pixel-size", "1e-8", "--out", "OUT"],
        "tracks",
    ),
    "skyrmions that never move": (
        [*_INFER, "still.csv", "--pixel-size", "1e-8", "--out", "OUT"],
        "skyrmions that move",
    ),
    "tracks too short for a step before and after": (
        [*_INFER, "short.csv", "--pixel-size", "1e-8", "--out", "OUT"],
        "at least three frames",
    ),
    "a periodic box of three sides": (
        [
            *_INFER,
            "tracks.csv",
            "--pixel-size",
            "1e-8",
            "--periodic",
            "1",
            "2",
            "3",
            "--out",
            "OUT",
        ],
        "--periodic",
    ),
    "a negative self-check length": (
        [*_INFER, "tracks.csv", "--pixel-size", "1e-8", "--check-frames", "-1", "--out", "OUT"],
        "--check-frames",
    ),
    "a zero temperature": (
        [
            "infer",
            "tracks.csv",
            "--pixel-size",
            "1e-8",
            "--frame-interval",
            "5e-9",
            "--outline",
            "outline.csv",
            "--temperature",
            "0",
            "--out",
            "OUT",
        ],
        "--temperature",
    ),
}


@pytest.mark.parametrize("name", list(INFER_CASES))
def test_infer_refuses_bad_tracks_in_one_line_and_writes_nothing(name, tmp_path):
    args, expected = INFER_CASES[name]
    for relative, text in INFER_FILES.items():
        (tmp_path / relative).write_text(text)
    before = _snapshot(tmp_path)
    proc = _run(args, tmp_path)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2, proc.stderr
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("skygas: error: "), lines[0]
    assert expected in lines[0], lines[0]
    assert "Traceback" not in proc.stderr
    assert _snapshot(tmp_path) == before


def _pinned_pairs(rng) -> str:
    """20 skyrmions that sit in pairs in 10 wells, never apart: the data that once stopped
    ``infer`` ("only 2 fit at 1.44e-07 m separation", the wells' dip in g(r) taken for the
    closest distance). Each wanders in its well (an Ornstein–Uhlenbeck walk)."""
    frames, n = 300, 20
    centre = np.column_stack([(np.arange(n) // 2) * 10 + 5.0, np.full(n, 50.0)])
    pos = centre.copy()
    rows = []
    for f in range(frames):
        pos = centre + 0.95 * (pos - centre) + rng.normal(0, 0.3, (n, 2))
        rows += [f"{f},{p},{pos[p, 0]},{pos[p, 1]}\n" for p in range(n)]
    return "frame,particle,x,y\n" + "".join(rows)


def _one_walker(rng) -> str:
    x, y = np.cumsum(rng.normal(0, 1, (2, 200)), axis=1) + 50
    return "frame,particle,x,y\n" + "".join(f"{f},0,{x[f]},{y[f]}\n" for f in range(200))


@pytest.mark.parametrize(
    "name, make", [("pinned pairs", _pinned_pairs), ("one skyrmion", _one_walker)]
)
def test_infer_gives_a_model_for_data_that_once_stopped_it(name, make, tmp_path):
    (tmp_path / "tracks.csv").write_text(make(np.random.default_rng(1)))
    args = ["infer", "tracks.csv", "--pixel-size", "1e-7", "--frame-interval", "0.01",
            "--temperature", "300", "--check-frames", "100", "--quiet", "--out", "out"]  # fmt: skip
    proc = _run(args, tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr
    assert (tmp_path / "out" / "model.toml").is_file(), name


# -- skygas optimize ----------------------------------------------------------------------------
STUDY = """[study]
device = "analytic"
seed = 1
{study}
[space]
{space}
[[objectives]]
expression = "{objective}"
"""
GOOD_SPACE = "x = { low = -1.0, high = 1.0 }"
OPTIMIZE_FILES = {
    "unknown-field.toml": STUDY.format(
        study="", space="w = { low = 0.0, high = 1.0 }", objective="f"
    ),
    "empty-range.toml": STUDY.format(
        study="", space="x = { low = 1.0, high = 1.0 }", objective="f"
    ),
    "log-through-0.toml": STUDY.format(
        study="", space="x = { low = -1.0, high = 1.0, log = true }", objective="f"
    ),
    "no-such-objective.toml": STUDY.format(study="", space=GOOD_SPACE, objective="rho"),
    "unsafe-objective.toml": STUDY.format(
        study="", space=GOOD_SPACE, objective="__import__('os').getcwd()"
    ),
    "contradictory.toml": STUDY.format(
        study='constraints = ["x + y < 0.1", "x+y > 0.5"]', space=GOOD_SPACE, objective="f"
    ),
    "unknown-device.toml": STUDY.replace('"analytic"', '"toaster"').format(
        study="", space=GOOD_SPACE, objective="f"
    ),
    "good.toml": STUDY.format(study="", space=GOOD_SPACE, objective="f"),
    # a study folder made from another study file
    "other/study.json": json.dumps({"kind": "skygas optimize study", "fingerprint": "0" * 20}),
    "other/journal.log": "",
}
OPTIMIZE_CASES = {
    "unknown field": ("unknown-field.toml", "space.w"),
    "empty range": ("empty-range.toml", "the range is empty"),
    "log range through 0": ("log-through-0.toml", "low > 0 for a log range"),
    "objective not in the summary": ("no-such-objective.toml", "'rho' is not one of them"),
    "objective that is not arithmetic": ("unsafe-objective.toml", "an arithmetic expression"),
    "contradictory constraints": ("contradictory.toml", "contradict each other"),
    "unknown device": ("unknown-device.toml", "study.device = 'toaster'"),
    "folder of another study": ("good.toml", "a study folder made from this study file"),
}


@pytest.mark.parametrize("name", list(OPTIMIZE_CASES))
def test_a_bad_study_is_one_line_and_writes_nothing(name, tmp_path):
    study, expected = OPTIMIZE_CASES[name]
    for relative, text in OPTIMIZE_FILES.items():
        (tmp_path / relative).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / relative).write_text(text)
    out = "other" if name == "folder of another study" else "OUT"
    before = _snapshot(tmp_path)
    proc = _run(["optimize", study, "--out", out, "--trials", "2", "--serial"], tmp_path)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2, proc.stderr
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("skygas: error: "), lines[0]
    assert expected in lines[0], lines[0]
    assert _snapshot(tmp_path) == before
    assert proc.stdout == ""


# -- a calibration folder keeps the report skygas calibrate wrote --
def test_report_refuses_a_calibration_folder_and_leaves_it_unchanged(tmp_path):
    files = {
        "cal/manifest.json": _manifest("calibrate"),
        "cal/summary.json": '{"skygas_version": "0"}\n',
        "cal/model.toml": "name = 'x'\n",
        "cal/report.html": "<html>the calibration's report</html>\n",
    }
    for relative, text in files.items():
        (tmp_path / relative).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / relative).write_text(text)
    before = _snapshot(tmp_path)
    proc = _run(["report", "cal"], tmp_path)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr
    assert lines[0].startswith("skygas: error: SOURCE = 'cal': expected a run folder or a sweep")
    assert "holds its own report.html" in lines[0]
    assert _snapshot(tmp_path) == before


# -- the command line's options: check-timestep on every device, demo (issue 30) --

TIMESTEP_FILES = {
    "both.toml": "[device]\nchamber_diameter = 1024e-9\n",  # the neuron's or the reshuffler's?
    "sweep.toml": (EXAMPLES / "sweeps" / "quick-current.toml").read_text(),
    "chamber.toml": CHAMBER,
}

TIMESTEP_CASES = {
    "check-timestep of no device": (["check-timestep"], "config = None"),
    "check-timestep of an ambiguous file": (
        ["check-timestep", "both.toml"],
        "config = 'both.toml': expected tables that say which device it is",
    ),
    "check-timestep of a sweep file": (["check-timestep", "sweep.toml"], "this is a sweep file"),
    "check-timestep preset of a neuron": (
        ["check-timestep", "--device", "neuron", "--preset", "paper"],
        "--preset = 'paper'",
    ),
    "check-timestep simulate without a file": (
        ["check-timestep", "--device", "simulate"],
        "a simulation's TOML file",
    ),
    "check-timestep zero duration": (
        ["check-timestep", "--device", "reservoir", "--duration", "0"],
        "--duration = 0.0",
    ),
    "check-timestep negative tolerance": (
        ["check-timestep", "--device", "reservoir", "--tolerance", "-1"],
        "--tolerance = -1.0",
    ),
    "simulate zero duration flag": (
        ["simulate", "chamber.toml", "--duration", "0", "--out", "OUT"],
        "--duration = 0.0",
    ),
    "demo negative checkpoint interval": (
        ["demo", "--checkpoint-seconds", "-1", "--out", "OUT"],
        "--checkpoint-seconds = -1.0",
    ),
}


@pytest.mark.parametrize("name", list(TIMESTEP_CASES))
def test_check_timestep_and_demo_refuse_in_one_line(name, tmp_path, monkeypatch):
    """The catalogue's test (one line, exit 2, nothing written) on the cases above."""
    monkeypatch.setitem(CASES, name, TIMESTEP_CASES[name])
    for relative, text in TIMESTEP_FILES.items():
        monkeypatch.setitem(FILES, relative, text)
    test_bad_input_exits_2_with_one_line_and_writes_nothing(name, tmp_path)


# -- movies in (skygas track, skygas render) --


def _movie_files(tmp_path: Path) -> None:
    """The movies the tracking cases find in their working folder."""
    import numpy as np
    import tifffile

    rng = np.random.default_rng(0)
    grey = rng.integers(0, 255, (3, 32, 32), dtype=np.uint8)
    tifffile.imwrite(tmp_path / "good.tif", grey, photometric="minisblack")
    tifffile.imwrite(tmp_path / "complex.tif", grey.astype(np.complex64), photometric="minisblack")
    tifffile.imwrite(tmp_path / "rgb.tif", np.stack([grey] * 3, axis=-1), photometric="rgb")
    tifffile.imwrite(tmp_path / "one.tif", grey[0])
    (tmp_path / "empty").mkdir()
    (tmp_path / "empty" / "notes.txt").write_text("no images here\n")
    (tmp_path / "movie.avi").write_bytes(b"RIFF")


MOVIE_CASES = {
    "movie of complex pixels": (["track", "complex.tif", "--out", "OUT"], "complex64"),
    "movie in colour": (["track", "rgb.tif", "--out", "OUT"], "grey-scale"),
    "movie of one frame": (["track", "one.tif", "--out", "OUT"], "at least 2 frames"),
    "movie folder empty": (["track", "empty", "--out", "OUT"], "holds none"),
    "movie missing": (["track", "missing.tif", "--out", "OUT"], "MOVIE = 'missing.tif'"),
    "movie of another kind": (["track", "movie.avi", "--out", "OUT"], "TIFF stack"),
    "movie pixel size 0": (
        ["track", "good.tif", "--out", "OUT", "--pixel-size", "0"],
        "--pixel-size = 0.0",
    ),
    "movie pixel size negative": (
        ["track", "good.tif", "--out", "OUT", "--pixel-size", "-1e-8"],
        "--pixel-size = -1e-08",
    ),
    "movie frame interval 0": (
        ["track", "good.tif", "--out", "OUT", "--frame-interval", "0"],
        "--frame-interval = 0.0",
    ),
    "movie diameter even": (["track", "good.tif", "--out", "OUT", "--diameter", "6"], "odd"),
    "render of a missing run": (
        ["render", "no-run", "--out", "m.tif", "--pixel-size", "1e-8"],
        "RUN = 'no-run'",
    ),
}


@pytest.mark.parametrize("name", list(MOVIE_CASES))
def test_a_bad_movie_is_one_line_and_writes_nothing(name, tmp_path):
    args, expected = MOVIE_CASES[name]
    _movie_files(tmp_path)
    before = _snapshot(tmp_path)
    proc = _run(args, tmp_path)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2, proc.stderr
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("skygas: error: "), lines[0]
    assert expected in lines[0], lines[0]
    assert "Traceback" not in proc.stderr
    assert _snapshot(tmp_path) == before  # nothing created, written, changed or removed
    assert proc.stdout == ""


# -- sizes and steps of simulate's configuration (issue 30: a Python API without unit traps) --
# A disk of the shapes geometry is given by its diameter, as every size; an explicit time step
# must divide the record interval, so that the frames fall on its multiples.
SIMULATE_CASES = {
    "disk radius": (
        CHAMBER.split("[geometry]")[0]
        + '[geometry]\nkind = "shapes"\nshapes = [{ kind = "disk", radius = 300e-9 }]\n'
        + "[skyrmions]\nrandom_count = 3\n",
        "diameter",
    ),
    "step not dividing the record interval": (
        _replace_line(CHAMBER, "record_interval", "record_interval = 1e-9\ntime_step = 3e-12"),
        "time_step",
    ),
}


@pytest.mark.parametrize("name", list(SIMULATE_CASES))
def test_a_simulate_size_or_step_trap_is_one_line(name, tmp_path):
    text, expected = SIMULATE_CASES[name]
    (tmp_path / "run.toml").write_text(text)
    before = _snapshot(tmp_path)
    proc = _run(["simulate", "run.toml", "--out", "OUT"], tmp_path)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2, proc.stderr
    assert len(lines) == 1 and lines[0].startswith("skygas: error: "), proc.stderr
    assert expected in lines[0], lines[0]
    assert "Traceback" not in proc.stderr
    assert _snapshot(tmp_path) == before
