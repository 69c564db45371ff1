"""Interrupted runs resume bit-identically, through the command line.

``skygas simulate``, ``reshuffle`` and ``neuron`` run as subprocesses. Each is stopped (SIGINT
at a random moment, SIGINT raised from inside the Python bookkeeping of a recording or an
injection, or SIGKILL after a periodic checkpoint), continued with ``--resume``, and its result
files are compared with those of the run left alone: every netCDF variable and attribute, every
npz array and every summary field must be equal, bit for bit, except the measured wall times.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from skygas.cli import main

SIMULATE_TOML = """\
seed = 11
temperature = 300.0
duration = 30e-6
record_interval = 0.5e-9      # a frame every 5 steps: interrupts fall among recordings
material = "S2"

[geometry]
kind = "chamber"
chamber_diameter = 600e-9
conduit_width = 100e-9
conduit_length = 50e-9

[drift]
velocity = [1.5, 0.0]         # skyrmions leave through the output: exits are recorded too

[skyrmions]
random_count = 40
min_separation = 1.5
"""

NEURON_TOML = """\
seed = 3
duration = 4e-6
[device]
chamber_diameter = 400e-9
conduit_width = 80e-9
conduit_length = 50e-9
[rule]
threshold = 6
reset_level = 2
[[inputs]]
kind = "poisson"
rate = 2e8                    # an injection attempt every 5 ns, a reading every 1 ns
[transfer]
rates = [1e8, 4e8]            # two short runs after the main one, one piece each
duration = 0.4e-6
"""

# The reshuffler's defaults already make injections dense (one every 5 ns); a short run keeps
# the test small.
RESHUFFLE_ARGS = ["--duration", "12e-6", "--seed", "4"]

#: Sends SIGINT to its own process from inside the ``nth`` call of a method, then calls the
#: method: the signal arrives in the middle of the run's Python bookkeeping.
HOOK = """
import importlib, os, signal, sys
module, owner, method, nth = sys.argv[1:5]
cls = getattr(importlib.import_module(module), owner)
original = getattr(cls, method)
calls = [0]
def hooked(*args, **kwargs):
    calls[0] += 1
    if calls[0] == int(nth):
        os.kill(os.getpid(), signal.SIGINT)
    return original(*args, **kwargs)
setattr(cls, method, hooked)
from skygas.cli import main
sys.exit(main(sys.argv[5:]))
"""

COMMANDS = {
    "simulate": {
        "files": ("trajectories.nc", "summary.json"),
        # exits are appended after the kernel returns, before the step count moves on
        "hooks": [
            ("skygas.engine.exit_log", "ExitLog", "append", 3),
            ("skygas.engine.exit_log", "ExitLog", "append", 2),
        ],
    },
    "reshuffle": {
        "files": ("reshuffler.nc", "summary.json"),
        "hooks": [
            ("skygas.reshuffler.injection", "Injector", "planned_insertions_made", 5),
            ("skygas.reshuffler.run", "ReshufflerRun", "_add_snapshots", 2),
        ],
    },
    "neuron": {
        "files": ("trace.npz", "summary.json"),
        "hooks": [
            ("skygas.neuron.inputs", "SiteInjector", "_inject", 60),
            ("skygas.neuron.device", "NeuronController", "act", 500),
            # inside a run of the transfer curve (the first build is the main run)
            ("skygas.neuron.device", "NeuronDevice", "build", 2),
        ],
    },
}


def _argv(command: str, tmp_path: Path, out: Path) -> list[str]:
    if command == "simulate":
        config = tmp_path / "simulate.toml"
        config.write_text(SIMULATE_TOML)
        return ["simulate", str(config), "--out", str(out)]
    if command == "neuron":
        config = tmp_path / "neuron.toml"
        config.write_text(NEURON_TOML)
        return ["neuron", str(config), "--out", str(out)]
    return ["reshuffle", "--out", str(out), *RESHUFFLE_ARGS]


def _env() -> dict:
    return {**os.environ, "PYTHONUNBUFFERED": "1"}


def _cli(argv: list[str], hook=None) -> subprocess.CompletedProcess:
    prefix = (
        [sys.executable, "-c", HOOK, *map(str, hook)]
        if hook
        else [sys.executable, "-m", "skygas.cli"]
    )
    return subprocess.run([*prefix, *argv], capture_output=True, text=True, env=_env(), timeout=300)


class _Started:
    """A CLI run in the background whose stderr is watched for the progress bar (shown once
    the run driver has taken over the signals and is about to step)."""

    def __init__(self, argv: list[str]):
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "skygas.cli", *argv],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            env=_env(),
        )
        self.stderr = b""
        self.bar = threading.Event()
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self) -> None:
        while chunk := self.proc.stderr.read1(4096):
            self.stderr += chunk
            if b"simulated" in self.stderr:
                self.bar.set()
        self.bar.set()

    def stop(self, signum: int, delay: float) -> int:
        assert self.bar.wait(120), self.stderr.decode()
        time.sleep(delay)
        if self.proc.poll() is None:
            self.proc.send_signal(signum)
        code = self.proc.wait(120)
        self.proc.stdout.read()
        self.reader.join(10)
        return code


def _without_wall_times(data: dict) -> dict:
    """``data`` without its measured times (wall times, a current solve's seconds)."""
    return {k: v for k, v in data.items() if "wall_time" not in k and not k.endswith("seconds")}


def _summary(path: Path) -> dict:
    return _without_wall_times(json.loads(path.read_text()))


def _attributes(attrs: dict) -> dict:
    """Dataset attributes, JSON ones parsed, wall times left out."""
    return _without_wall_times(
        {
            k: _without_wall_times(json.loads(v)) if isinstance(v, str) and v.startswith("{") else v
            for k, v in attrs.items()
        }
    )


def assert_same_results(ref: Path, out: Path, files) -> None:
    """Every array, attribute and summary field equal (wall times aside)."""
    assert not (out / "checkpoint.npz").exists()
    for name in files:
        a, b = ref / name, out / name
        if name.endswith(".json"):
            assert _summary(a) == _summary(b), name
        elif name.endswith(".npz"):
            with np.load(a) as x, np.load(b) as y:
                assert sorted(x.files) == sorted(y.files)
                for k in x.files:
                    assert np.array_equal(x[k], y[k]), f"{name}: {k}"
        else:
            with xr.open_dataset(a) as x, xr.open_dataset(b) as y:
                x.load()
                y.load()
            assert sorted(x.variables) == sorted(y.variables)
            for k in x.variables:
                assert x[k].dtype == y[k].dtype, f"{name}: {k}"
                assert np.array_equal(x[k].values, y[k].values, equal_nan=x[k].dtype.kind == "f"), (
                    f"{name}: {k}"
                )
            assert _attributes(x.attrs) == _attributes(y.attrs), name


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The uninterrupted runs, one per command (made on first use)."""
    made = {}

    def get(command: str) -> Path:
        if command not in made:
            tmp = tmp_path_factory.mktemp(f"reference-{command}")
            out = tmp / "out"
            done = _cli([*_argv(command, tmp, out), "--quiet"])
            assert done.returncode == 0, done.stderr
            made[command] = out
        return made[command]

    return get


def _resume(argv: list[str], hook=None) -> subprocess.CompletedProcess:
    return _cli([*argv, "--resume", "--quiet"], hook)


@pytest.mark.parametrize("command", list(COMMANDS))
def test_sigint_inside_bookkeeping_resumes_bit_identically(command, reference, tmp_path):
    """SIGINT raised in the middle of an injection or a recording (from inside the method that
    does it) stops the run at the end of its piece: the state saved there is consistent. The
    run is interrupted two or three times (then while resumed) before it is let finish."""
    ref = reference(command)
    out = tmp_path / "out"
    argv = _argv(command, tmp_path, out)
    first, *others = COMMANDS[command]["hooks"]
    stopped = _cli([*argv, "--quiet"], first)
    assert stopped.returncode == 130, stopped.stderr
    message = stopped.stderr.strip().splitlines()
    assert len(message) == 1 and "--resume" in message[0], stopped.stderr
    assert (out / "checkpoint.npz").is_file()
    assert not any((out / f).exists() for f in COMMANDS[command]["files"])
    for hook in others:
        again = _resume(argv, hook)
        assert again.returncode == 130, again.stderr
    done = _resume(argv)
    assert done.returncode == 0, done.stderr
    assert_same_results(ref, out, COMMANDS[command]["files"])


@pytest.mark.slow
@pytest.mark.parametrize("command, seed", [(c, k + 1) for k, c in enumerate(COMMANDS)])
def test_sigint_at_random_moments_resumes_bit_identically(command, seed, reference, tmp_path):
    """Ctrl-C at random moments of the run (two per run, a seed of its own per command)."""
    ref = reference(command)
    summary = json.loads((ref / "summary.json").read_text())
    running = summary["wall_time_s"]  # the stepping alone, measured by the reference run
    rng = np.random.default_rng(seed)
    out = tmp_path / "out"
    argv = _argv(command, tmp_path, out)
    # The reference's stepping time was measured on a machine whose load may since have
    # dropped: a first signal that comes after the end is drawn again from a shorter span (the
    # test is about signals that land while the run steps).
    for attempt in range(4):
        shutil.rmtree(out, ignore_errors=True)
        codes = []
        for k in range(2):
            run = _Started([*argv, "--resume"] if k else argv)
            code = run.stop(signal.SIGINT, rng.uniform(0.0, 0.8 * running / 2**attempt))
            finished = all((out / f).exists() for f in COMMANDS[command]["files"])
            if code == -signal.SIGINT and finished:
                code = 0  # the signal met the interpreter exiting, after the run had finished
            codes.append(code)
            assert codes[-1] in (0, 130), run.stderr.decode()
            if codes[-1] == 0:  # the signal came after the end
                break
        if codes[0] == 130:
            break
    assert codes[0] == 130  # the first signal came while the run was stepping
    if codes[-1] == 130:
        done = _resume(argv)
        assert done.returncode == 0, done.stderr
    assert_same_results(ref, out, COMMANDS[command]["files"])


@pytest.mark.parametrize("command", ["simulate", "reshuffle"])
def test_sigkill_then_resume_from_a_periodic_checkpoint(command, reference, tmp_path):
    """A killed run (no chance to save) resumes from its last periodic checkpoint."""
    ref = reference(command)
    out = tmp_path / "out"
    argv = _argv(command, tmp_path, out)
    run = _Started([*argv, "--checkpoint-seconds", "0"])
    assert run.bar.wait(120)
    deadline = time.monotonic() + 120
    while not (out / "checkpoint.npz").exists() and run.proc.poll() is None:
        assert time.monotonic() < deadline
        time.sleep(0.01)
    code = run.stop(signal.SIGKILL, 0.05)
    if code == -signal.SIGKILL:
        assert (out / "checkpoint.npz").is_file()
    done = _resume(argv)
    assert done.returncode == 0, done.stderr
    assert_same_results(ref, out, COMMANDS[command]["files"])


def test_resume_refuses_another_configuration_and_a_fresh_start_refuses_a_checkpoint(
    reference, tmp_path, capsys
):
    """A checkpoint belongs to one configuration; without --resume it is never overwritten."""
    out = tmp_path / "out"
    argv = _argv("simulate", tmp_path, out)
    stopped = _cli([*argv, "--quiet"], COMMANDS["simulate"]["hooks"][0])
    assert stopped.returncode == 130, stopped.stderr
    saved = (out / "checkpoint.npz").read_bytes()
    other = tmp_path / "other.toml"
    other.write_text(SIMULATE_TOML.replace("seed = 11", "seed = 12"))
    assert main(["simulate", str(other), "--out", str(out), "--resume", "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("skygas: error: --resume = ")
    assert "same configuration" in err[0]
    assert main([*argv, "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--resume" in err[0] and "--out" in err[0]
    assert (out / "checkpoint.npz").read_bytes() == saved
    assert main([*argv, "--quiet", "--checkpoint-seconds", "-1"]) == 2
    assert "--checkpoint-seconds = -1.0" in capsys.readouterr().err
