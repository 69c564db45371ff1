"""Running sweeps: Dask gives the serial results, and an interrupted sweep resumes exactly."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest
import zarr

from skygas.core.errors import InputError
from skygas.sweep import load_sweep, open_sweep, parse_sweep, run_sweep, start_local_cluster
from skygas.sweep.execute import LOCAL_CLUSTER_CONFIG
from skygas.sweep.store import SweepStore
from skygas.sweep.worker import QUANTITIES

# everything but the wall-clock time is a deterministic function of the sweep file
COMPARED = [q for q in QUANTITIES if q != "wall_time_s"] + [
    "running_rho",
    "running_time",
    "seed",
    "done",
]


def assert_same_results(a, b):
    for name in COMPARED:
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)


def _kill_one_worker_after_first_run(store, pids, done_at_kill):
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        if (store / "done" / "zarr.json").exists():
            n_done = int(np.asarray(zarr.open_group(store)["done"][...]).sum())
            if n_done >= 1:
                os.kill(pids[0], signal.SIGKILL)
                done_at_kill.append(n_done)
                return
        time.sleep(0.02)


def _worker_settings() -> tuple:
    import dask

    return tuple(dask.config.get(key) for key in LOCAL_CLUSTER_CONFIG)


def test_dask_two_workers_match_serial(tiny_sweep_file, tmp_path):
    from dask.distributed import Client

    sweep = load_sweep(tiny_sweep_file)
    serial = run_sweep(sweep, tmp_path / "serial.zarr", serial=True, progress=False)
    # two worker processes behind a scheduler given by address (as for a real cluster); one of
    # them is killed after the first run arrives: its nanny restarts it and Dask reruns its run
    with start_local_cluster(2) as cluster, Client(cluster) as client:
        pids = list(client.run(os.getpid).values())
        done_at_kill = []
        killer = threading.Thread(
            target=_kill_one_worker_after_first_run,
            args=(tmp_path / "dask.zarr", pids, done_at_kill),
        )
        killer.start()
        dask = run_sweep(
            sweep, tmp_path / "dask.zarr", scheduler=cluster.scheduler_address, progress=False
        )
        killer.join()
        # every worker, the restarted one included, runs with the cluster's quiet settings
        client.wait_for_workers(2, timeout=120)
        settings = client.run(_worker_settings)
        assert len(settings) == 2 and set(pids) != set(client.run(os.getpid).values())
        assert all(v == tuple(LOCAL_CLUSTER_CONFIG.values()) for v in settings.values()), settings
    assert done_at_kill and done_at_kill[0] < 4, "no worker was killed mid-sweep"
    assert len(serial.computed) == len(dask.computed) == 4
    a, b = open_sweep(tmp_path / "serial.zarr"), open_sweep(tmp_path / "dask.zarr")
    assert_same_results(a, b)
    assert int(a["done"].sum()) == 4 and np.isfinite(a["correlation"].values).all()
    assert a.attrs["root_seed"] == 11 and "current_density" in a.attrs["sweep_file"]
    assert a.attrs["skygas_version"]

    # a run whose values were written but whose `done` flag was not (a crash in between) is
    # run again; the others are not touched
    group = zarr.open_group(tmp_path / "serial.zarr", mode="r+")
    group["done"][1, 0, 1] = 0
    group["summary"][1, 0, 1, QUANTITIES.index("correlation")] = 99.0
    before = np.asarray(group["finished_at"][...])
    again = run_sweep(sweep, tmp_path / "serial.zarr", serial=True, progress=False)
    assert again.computed == [((1, 0), 1)] and again.skipped == 3
    after = np.asarray(zarr.open_group(tmp_path / "serial.zarr")["finished_at"][...])
    changed = before != after
    assert changed.sum() == 1 and changed[1, 0, 1]
    assert_same_results(open_sweep(tmp_path / "serial.zarr"), b)


def test_a_new_store_reads_as_runs_not_yet_done(tiny_sweep_file, tmp_path):
    """Created as metadata only: every run reads as not done, its values NaN, its session −1
    and its finish time NaT."""
    sweep = load_sweep(tiny_sweep_file)
    SweepStore(tmp_path / "s.zarr", sweep)
    ds = open_sweep(tmp_path / "s.zarr")
    assert ds["done"].shape == (*sweep.shape, sweep.replicas) and not ds["done"].any()
    for name in QUANTITIES:
        assert np.isnan(ds[name].values).all(), name
    assert np.isnan(ds["running_rho"].values).all() and ds.sizes["running"] > 0
    assert (ds["session"] == -1).all() and np.isnat(ds["finished_at"].values).all()
    assert (ds["seed"].values > 0).all()


def test_store_of_another_sweep_is_refused(tiny_sweep_file, tmp_path):
    SweepStore(tmp_path / "s.zarr", load_sweep(tiny_sweep_file))  # created, nothing run
    other = parse_sweep(
        {"sweep": {"seed": 12}, "base": {"preset": "paper"}, "grid": {"current_density": [1e11]}}
    )
    with pytest.raises(InputError, match="--out"):
        run_sweep(other, tmp_path / "s.zarr", serial=True, progress=False)


def _sweep_cli(*args):
    return [sys.executable, "-m", "skygas.cli", "sweep", *map(str, args), "--quiet"]


def test_killed_sweep_resumes_without_recomputing(tiny_sweep_file, tmp_path):
    # runs of 20 µs (not the tiny sweep's 1 µs): each takes a good fraction of a second, so the
    # poll below sees the first finished run before the others finish, even on a busy machine
    tiny_sweep_file.write_text(
        tiny_sweep_file.read_text().replace("duration = 1e-6", "duration = 2e-5")
    )
    store = tmp_path / "killed.zarr"
    # the client (and with it its local Dask cluster) is killed after the first finished run
    proc = subprocess.Popen(
        _sweep_cli(tiny_sweep_file, "--out", store, "--workers", "1"),
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        deadline = time.monotonic() + 60
        n_done = 0
        while time.monotonic() < deadline and proc.poll() is None:
            if (store / "done" / "zarr.json").exists():
                n_done = int(np.asarray(zarr.open_group(store)["done"][...]).sum())
                if n_done >= 1:
                    break
            time.sleep(0.05)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    partial = zarr.open_group(store)
    done_before = np.asarray(partial["done"][...]).astype(bool)
    finished_before = np.asarray(partial["finished_at"][...])
    assert 1 <= done_before.sum() < 4, "the sweep was not interrupted midway"

    resumed = subprocess.run(
        _sweep_cli(tiny_sweep_file, "--out", store, "--workers", "1"),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert resumed.returncode == 0, resumed.stderr
    n_left = 4 - int(done_before.sum())
    assert f"{n_left} runs computed, {int(done_before.sum())} already done" in resumed.stdout

    final = open_sweep(store)
    raw = zarr.open_group(store)
    # runs finished before the kill were not computed again
    np.testing.assert_array_equal(
        np.asarray(raw["finished_at"][...])[done_before], finished_before[done_before]
    )
    assert (np.asarray(raw["session"][...])[done_before] == 0).all()
    assert (np.asarray(raw["session"][...])[~done_before] == 1).all()

    reference = tmp_path / "reference.zarr"
    run_sweep(load_sweep(tiny_sweep_file), reference, serial=True, progress=False)
    assert_same_results(final, open_sweep(reference))
