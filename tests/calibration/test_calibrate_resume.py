"""`skygas calibrate` stopped, killed, resumed or solved on a running Dask cluster gives the same
bits as a run left alone on its local cluster.

Apart from test_calibrate_cli.py (the module of the shared calibration): these tests make their
own calibrations, and in a module of their own they can run on the other test worker meanwhile.
The reference, made once for the module (:func:`two_films`), is a study of two films on a
running cluster (a ``dask scheduler`` and two ``dask worker`` processes); its first point is the
S6 calibration that a calibration interrupted and resumed on the local cluster must equal, bit
for bit: so a local run, an interrupted one and one on a running cluster all give the same bits.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
import tomllib
from types import SimpleNamespace

import numpy as np
import psutil
import pytest

pytest.importorskip("magnumnp")

from skygas import cli  # noqa: E402

pytestmark = pytest.mark.slow

# cells of 2.4 nm (the coarsest S6 allows) and 5 pair distances instead of 11 (a quarter, then
# a tenth of the wall time less), and bits are bits
ARGS = ["S6", "--no-validate", "--no-mesh-check", "--quiet", "--checkpoint-seconds", "0"]
ARGS += ["--cell-size", "2.4e-9", "--pair-distances", "5"]


def assert_same_bits(a, b) -> None:
    """Two calibration folders hold the same results, bit for bit, but for their provenance
    (wall times, dates, how many workers and where)."""
    first, second = (json.loads((x / "summary.json").read_text()) for x in (a, b))
    first.pop("provenance")
    second.pop("provenance")
    assert first == second  # JSON floats read back equal only when their bits are equal
    first, second = (tomllib.loads((x / "model.toml").read_text()) for x in (a, b))
    first.pop("provenance")
    second.pop("provenance")
    assert first == second
    with np.load(a / "textures.npz") as x, np.load(b / "textures.npz") as y:
        assert sorted(x.files) == sorted(y.files)
        for name in x.files:
            assert x[name].tobytes() == y[name].tobytes(), name


def _calibrate(out, *extra):
    """``skygas calibrate`` in a process of its own, the leader of a new process group (as a
    terminal's foreground job)."""
    return subprocess.Popen(
        [sys.executable, "-m", "skygas.cli", "calibrate", *ARGS, *extra, "--out", str(out)],
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


def test_interrupted_and_resumed_gives_the_same_bits(two_films, tmp_path):
    broken = tmp_path / "broken"
    process = _calibrate(broken)
    checkpoint = broken / "checkpoint.npz"
    deadline = time.time() + 120
    while time.time() < deadline and process.poll() is None:
        if checkpoint.exists():
            with np.load(checkpoint) as data:
                if len(json.loads(str(data["results"]))) >= 6:
                    break
        time.sleep(0.2)
    # Ctrl-C in a terminal: SIGINT to every process of the group, the workers too (they
    # ignore it: the calibration saves its checkpoint and stops them)
    os.killpg(process.pid, signal.SIGINT)
    assert process.wait(timeout=120) == 130, process.stderr.read()
    (line,) = process.stderr.read().strip().splitlines()  # and no worker's complaint
    assert line.startswith("skygas: interrupted by SIGINT: state saved"), line
    assert checkpoint.exists() and not (broken / "model.toml").exists()
    assert cli.main(["calibrate", *ARGS, "--out", str(broken), "--resume"]) == 0
    # on the local cluster, stopped and resumed: the bits of the running cluster's run
    assert_same_bits(two_films.out / "point-0", broken)


@contextlib.contextmanager
def _running_cluster(folder):
    """A Dask scheduler and two workers of one thread, each a process of its own started by
    Dask's command line, as on a cluster: its ``address`` and its ``scheduler`` process."""
    from dask.distributed import Client

    file = folder / "scheduler.json"
    dask = [sys.executable, "-m", "dask"]
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
    processes = [
        subprocess.Popen(
            [*dask, "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard"]
            + ["--scheduler-file", str(file)],
            **quiet,
        )
    ]
    try:
        deadline = time.monotonic() + 60
        while not file.exists() and time.monotonic() < deadline:
            time.sleep(0.1)
        time.sleep(0.2)  # written at once, but not atomically
        address = json.loads(file.read_text())["address"]
        for _ in range(2):
            processes.append(
                subprocess.Popen(
                    [*dask, "worker", address, "--nthreads", "1", "--nworkers", "1"]
                    + ["--no-dashboard"],
                    **quiet,
                )
            )
        with Client(address, timeout="30s") as client:
            client.wait_for_workers(2, timeout=120)
        yield SimpleNamespace(address=address, scheduler=processes[0])
    finally:
        for process in reversed(processes):
            process.terminate()
        deadline = time.monotonic() + 5  # a worker whose scheduler is gone waits for it
        for process in reversed(processes):
            try:
                process.wait(timeout=max(deadline - time.monotonic(), 0.1))
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()


@pytest.fixture
def dask_cluster(tmp_path):
    """A running cluster of the test's own (:func:`_running_cluster`)."""
    with _running_cluster(tmp_path) as cluster:
        yield cluster


@pytest.fixture(scope="module")
def two_films(tmp_path_factory):
    """A study file of two films (the S6 preset, and a user's stiffer film in a TOML file) run
    on a running cluster, twice: its ``out`` folder, the two runs' records (``first``,
    ``again``) and the cluster's ``address``."""
    from skygas.calibration.material import load_micromagnetic_material

    folder = tmp_path_factory.mktemp("two-films")
    film = load_micromagnetic_material("S6").model_dump(exclude_none=True)
    film.update(name="stiffer", anisotropy=1.05 * film["anisotropy"])
    lines = [f"{k} = {json.dumps(v)}" for k, v in film.items() if not isinstance(v, dict)]
    (folder / "stiffer.toml").write_text("\n".join(lines) + "\n")
    study = folder / "films.toml"
    study.write_text(
        "[study]\n[settings]\ncell_size = 2.4e-9\npair_distances = 5\n"
        "validate_dynamics = false\nmesh_check = false\n"
        '[[points]]\nmaterial = "S6"\n[[points]]\nmaterial = "stiffer.toml"\n'
    )
    out = folder / "study"
    with _running_cluster(folder) as cluster:
        command = ["calibrate", str(study), "--scheduler", cluster.address, "--out", str(out)]
        assert cli.main([*command, "--quiet", "--json"]) == 0
        first = json.loads((out / "study.json").read_text())
        assert cli.main([*command, "--quiet", "--json"]) == 0
        again = json.loads((out / "study.json").read_text())
        return SimpleNamespace(out=out, first=first, again=again, address=cluster.address)


def test_a_study_of_two_films_runs_on_a_running_cluster(two_films):
    """Each point of the study is a calibration whose solves are tasks of the running cluster
    (its bits are those of the local cluster: the test above); run again, nothing is redone."""
    out = two_films.out
    provenance = json.loads((out / "point-0" / "summary.json").read_text())["provenance"]
    assert provenance["scheduler"] == two_films.address and provenance["workers"] == 2
    first, second = two_films.first["points"]
    assert first["computed_now"] and second["computed_now"]
    # a stiffer film (larger K) holds a smaller skyrmion
    assert second["radius_m"] < first["radius_m"]
    assert f"{second['radius_m'] * 1e9:.2f}" in (out / "report.html").read_text()
    again = two_films.again["points"]
    assert not any(p["computed_now"] for p in again)
    assert [p["radius_m"] for p in again] == [first["radius_m"], second["radius_m"]]


def test_a_lost_scheduler_is_one_line_and_the_checkpoint_stays(dask_cluster, tmp_path):
    out = tmp_path / "lost"
    process = _calibrate(out, "--scheduler", dask_cluster.address)
    checkpoint = out / "checkpoint.npz"
    deadline = time.time() + 120
    while time.time() < deadline and process.poll() is None and not checkpoint.exists():
        time.sleep(0.2)
    dask_cluster.scheduler.kill()
    assert process.wait(timeout=120) == 2, process.stderr.read()
    (line,) = process.stderr.read().strip().splitlines()  # no Dask complaint beside it
    assert line.startswith(f"skygas: error: --scheduler = '{dask_cluster.address}'"), line
    assert "--resume" in line and checkpoint.exists()


def _cpu_seconds(process: psutil.Process) -> float:
    try:
        return process.cpu_times().user
    except psutil.NoSuchProcess:
        return 0.0


def test_no_worker_outlives_a_killed_calibration(tmp_path):
    process = _calibrate(tmp_path / "killed", "--workers", "2")
    parent = psutil.Process(process.pid)
    deadline = time.monotonic() + 120
    children: list[psutil.Process] = []
    while time.monotonic() < deadline and process.poll() is None:
        children = parent.children(recursive=True)
        # both workers at work on a solve (torch imported, a relaxation under way)
        if sum(_cpu_seconds(p) > 3 for p in children) >= 2:
            break
        time.sleep(0.2)
    else:
        pytest.fail(f"no two busy workers: {process.stderr.read() if process.poll() else ''}")
    process.kill()  # SIGKILL: no chance to stop its workers
    process.wait()
    _, alive = psutil.wait_procs(children, timeout=10)
    for p in alive:
        p.kill()
    assert not alive, "a process of the calibration outlived it (a worker kept computing)"
