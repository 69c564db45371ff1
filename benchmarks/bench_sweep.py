"""Sweep speed on Dask: a 16-point sweep of short reshuffler runs on 1 and 2 local workers.

Workload: the ``paper`` preset (1024 nm chambers), 4 current densities × 4 p-values, one
replica, ``--duration`` of simulated time per run (default 2 µs). Every point of this sweep
shares one device: a process builds its set-up (current solve, wall field: ~1.5-2 s) once and
keeps it (:mod:`skygas.core.memo`), and the disk cache (:mod:`skygas.core.disk_cache`) lets a new
process load it in ~0.1 s instead. A point then costs its simulation, ~0.2 s at 2 µs. Prints the
median wall time (and the range) over ``--repeats`` sweeps for 1 and 2 workers and their ratio, in
four modes:

- ``first``: each sweep starts its own local cluster (``skygas sweep --workers N``) with an
  empty disk cache, as the first sweep ever of a device: the cluster's start, each worker's
  imports and compiled-kernel loads, and each worker's device set-up are included;
- ``cold``: as ``first``, with the device's set-up in the disk cache (any earlier run of this
  device, in any process, left it there): each worker loads it;
- ``warm``: the cluster is started (with the settings ``skygas sweep`` gives its own,
  :func:`skygas.sweep.start_local_cluster`) and its workers warmed up first (imports and
  kernels, on another, small device), then the sweep runs on it through its scheduler address
  (``skygas sweep --scheduler ADDRESS``, a cluster that stays up); each worker loads the
  device's set-up from the disk cache;
- ``hot``: as ``warm``, but every worker has already run this device once (a cluster that ran
  an earlier sweep of the same device): only the runs themselves and the Dask path remain.

The benchmark keeps its disk cache in a temporary directory (``SKYGAS_CACHE_DIR``), filled by
the first serial sweep; ``first`` gives each sweep a new, empty one. It also runs the sweep
serially in this process, with its set-up built (``first``), loaded from disk (``cold``,
``warm``) or already in memory (``hot``), and prints the Dask path's overhead per point,
(T(1 worker) − T(serial)) / 16, for each mode. In ``warm``/``hot`` it prints how many current
solves each worker did (``skygas.core.memo`` counts), to show the set-up was not rebuilt, and the
CPU time this process (the client, the scheduler and the nannies of the local cluster) used during a
sweep: on a machine with as many cores as workers, that time is taken from them.

Run: ``.venv/bin/python benchmarks/bench_sweep.py [--repeats 3] [--duration 2e-6]
[--mode all|first|cold|warm|hot]``.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import resource
import statistics
import tempfile
import time
from pathlib import Path

import skygas.core.memo as memo
import skygas.sweep as api  # its names load on first use (skygas.sweep's lazy exports)
from machine_steal import StealMeter

# The local cluster's worker processes start by re-running this file's top level (as
# ``__mp_main__``, multiprocessing's spawn method), as they re-run the ``skygas`` command's
# script under ``skygas sweep``: importing skygas.sweep's client side (zarr, xarray) here would
# put ~0.7 s into every worker's start that the command does not have.

MODES = ("first", "cold", "warm", "hot")
#: the in-process set-up each mode's serial reference starts from
SERIAL_OF = {"first": "built", "cold": "loaded", "warm": "loaded", "hot": "in memory"}


def workload(duration: float):
    return api.parse_sweep(
        {
            "sweep": {"seed": 1, "replicas": 1},
            "base": {"preset": "paper", "duration": duration, "output": {"trajectory_window": 0.0}},
            "grid": {
                "current_density": [1.7e11, 2.2e11, 2.9e11, 3.8e11],
                "signal.p": [0.2, 0.4, 0.62, 0.8],
            },
        }
    )


def timed(sweep, tmp: Path, name: str, **kwargs) -> float:
    start = time.perf_counter()
    report = api.run_sweep(sweep, tmp / f"{name}.zarr", progress=False, **kwargs)
    assert len(report.computed) == len(sweep.runs) and not report.failed, report.failed
    return time.perf_counter() - start


def _warm_up() -> None:
    """Imports and compiled kernels, on a small device (not the benchmark's)."""
    config = (
        api.parse_sweep(
            {
                "base": {
                    "preset": "paper",
                    "duration": 5e-8,
                    "device": {"chamber_diameter": 3e-7},
                    "output": {"trajectory_window": 0.0},
                },
                "grid": {"temperature": [300.0]},
            }
        )
        .runs[0]
        .config
    )
    api.run_one(config.model_dump_json())


def _current_solves() -> int:
    return memo.memo_stats()["current"]["built"]


def _process_cpu() -> float:
    """CPU seconds used so far by this process (all its threads)."""
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def timed_on_cluster(
    sweep, tmp: Path, name: str, workers: int, hot: bool
) -> tuple[float, list, float]:
    """Wall time of the sweep on a running local cluster, the current solves each worker did,
    and the CPU time this process (client, scheduler and nannies) used meanwhile."""
    from dask.distributed import Client

    with api.start_local_cluster(workers) as cluster, Client(cluster) as client:
        client.run(_warm_up)
        if hot:  # every worker runs this device once: its set-up is then kept
            client.run(api.run_one, sweep.runs[0].config.model_dump_json())
        before = client.run(_current_solves)
        cpu = _process_cpu()
        t = timed(sweep, tmp, name, scheduler=cluster.scheduler_address)
        cpu = _process_cpu() - cpu
        after = client.run(_current_solves)
        return t, [after[w] - before[w] for w in sorted(after)], cpu


@contextlib.contextmanager
def disk_cache(tmp: Path, name: str = ""):
    """This process, and the workers it starts meanwhile, use the benchmark's disk cache
    (filled by the first run), or with ``name`` a new, empty one; the shared one after."""
    os.environ["SKYGAS_CACHE_DIR"] = str(tmp / (f"cache-{name}" if name else "cache"))
    try:
        yield
    finally:
        os.environ["SKYGAS_CACHE_DIR"] = str(tmp / "cache")


def timed_serial(sweep, tmp: Path, name: str, setup: str) -> float:
    """The sweep run in this process, its set-up ``built``, ``loaded`` from disk or
    ``in memory``."""
    memo.clear_memos()
    if setup == "in memory":
        api.run_one(sweep.runs[0].config.model_dump_json())
    with disk_cache(tmp, name if setup == "built" else ""):
        return timed(sweep, tmp, name, serial=True)


def spread(values: list[float]) -> str:
    return f"{min(values):.1f}-{max(values):.1f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--duration", type=float, default=2e-6, help="simulated time [s]")
    parser.add_argument("--mode", choices=("all", *MODES), default="all")
    args = parser.parse_args()
    steal = StealMeter()
    sweep = workload(args.duration)
    n = len(sweep.runs)
    modes = MODES if args.mode == "all" else (args.mode,)
    times = {mode: {1: [], 2: []} for mode in modes}
    serial = {setup: [] for setup in dict.fromkeys(SERIAL_OF[mode] for mode in modes)}
    solves = {mode: [] for mode in modes}
    client_cpu = {mode: {1: [], 2: []} for mode in modes}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        os.environ["SKYGAS_CACHE_DIR"] = str(tmp / "cache")  # this benchmark's own (disk_cache)
        _warm_up()  # imports and JIT, outside the timings
        api.run_one(sweep.runs[0].config.model_dump_json())  # fills the disk cache
        for k in range(args.repeats):
            for setup in serial:
                t = timed_serial(sweep, tmp, f"serial-{setup.replace(' ', '-')}-{k}", setup)
                serial[setup].append(t)
                print(f"repeat {k}, serial (set-up {setup}): {t:.1f} s", flush=True)
            for mode in modes:
                for workers in (1, 2):
                    name = f"{mode}{workers}-{k}"
                    if mode in ("first", "cold"):
                        with disk_cache(tmp, name if mode == "first" else ""):
                            t = timed(sweep, tmp, name, workers=workers)
                    else:
                        t, done, cpu = timed_on_cluster(sweep, tmp, name, workers, mode == "hot")
                        solves[mode].append(done)
                        client_cpu[mode][workers].append(cpu)
                    times[mode][workers].append(t)
                    print(f"repeat {k}, {mode}, {workers} worker(s): {t:.1f} s", flush=True)
    print(f"{n} points, {args.duration * 1e6:g} µs each, {args.repeats} repeats")
    for setup, values in serial.items():
        t = statistics.median(values)
        print(
            f"serial (in this process, set-up {setup}): median {t:.1f} s ({spread(values)}) "
            f"= {t / n:.2f} s per point"
        )
    for mode in modes:
        t1, t2 = statistics.median(times[mode][1]), statistics.median(times[mode][2])
        ratios = [a / b for a, b in zip(times[mode][1], times[mode][2], strict=True)]
        reference = statistics.median(serial[SERIAL_OF[mode]])
        print(
            f"{mode}: 1 worker median {t1:.1f} s ({spread(times[mode][1])}), 2 workers "
            f"median {t2:.1f} s ({spread(times[mode][2])}), speed-up {t1 / t2:.2f}x "
            f"(per repeat: {', '.join(f'{r:.2f}' for r in ratios)}; their median "
            f"{statistics.median(ratios):.2f}x), "
            f"Dask overhead per point {(t1 - reference) / n:.2f} s"
        )
        if solves[mode]:
            print(
                f"  current solves per worker in each sweep (1 worker, 2 workers, ...): "
                f"{solves[mode]}"
            )
            print(
                "  CPU of the client, scheduler and nannies during a sweep (this process; "
                "it competes with the workers for the cores): median "
                f"{statistics.median(client_cpu[mode][1]):.2f} s with 1 worker, "
                f"{statistics.median(client_cpu[mode][2]):.2f} s with 2"
            )
    print(steal.report())


if __name__ == "__main__":
    main()
