"""Sweep speed on Dask: a 16-point sweep of short reshuffler runs on 1 and 2 local workers.

Workload: the ``paper`` preset (1024 nm chambers), 4 current densities × 4 p-values, one
replica, ``--duration`` of simulated time per run (default 2 µs: each run is then mostly its
~1.5-3 s of set-up, the current and wall-field solve). Prints the median wall time over
``--repeats`` sweeps for 1 and 2 workers and their ratio, in two modes:

- ``cold``: each sweep starts its own local cluster (``skygas sweep --workers N``), so the
  cluster's start and each worker's first imports and compiled-kernel loads are included;
- ``warm``: the cluster is started and its workers warmed up first, then the sweep runs on it
  through its scheduler address (``skygas sweep --scheduler ADDRESS``, a cluster that stays up).

It also runs the sweep serially in this process (warm) and prints the Dask path's overhead per
point, (T(1 worker) − T(serial)) / 16, for each mode.

Run: ``.venv/bin/python benchmarks/bench_sweep.py [--repeats 3] [--duration 2e-6]
[--mode both|cold|warm]``.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

from skygas.sweep import parse_sweep, run_one, run_sweep


def workload(duration: float):
    return parse_sweep({
        "sweep": {"seed": 1, "replicas": 1},
        "base": {"preset": "paper", "duration": duration,
                 "output": {"trajectory_window": 0.0}},
        "grid": {"current_density": [1.7e11, 2.2e11, 2.9e11, 3.8e11],
                 "signal.p": [0.2, 0.4, 0.62, 0.8]},
    })


def timed(sweep, tmp: Path, name: str, **kwargs) -> float:
    start = time.perf_counter()
    report = run_sweep(sweep, tmp / f"{name}.zarr", progress=False, **kwargs)
    assert len(report.computed) == len(sweep.runs)
    return time.perf_counter() - start


def _warm_up() -> None:
    config = parse_sweep({"base": {"preset": "paper", "duration": 5e-8,
                                   "device": {"chamber_diameter": 3e-7},
                                   "output": {"trajectory_window": 0.0}},
                          "grid": {"temperature": [300.0]}}).runs[0].config
    run_one(config.model_dump_json())


def timed_warm(sweep, tmp: Path, name: str, workers: int) -> float:
    from dask.distributed import Client, LocalCluster

    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                      dashboard_address=":0") as cluster, Client(cluster) as client:
        client.run(_warm_up)
        return timed(sweep, tmp, name, scheduler=cluster.scheduler_address)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--duration", type=float, default=2e-6, help="simulated time [s]")
    parser.add_argument("--mode", choices=("both", "cold", "warm"), default="both")
    args = parser.parse_args()
    sweep = workload(args.duration)
    n = len(sweep.runs)
    run_one(sweep.runs[0].config.model_dump_json())  # JIT and imports, outside the timings
    modes = ("cold", "warm") if args.mode == "both" else (args.mode,)
    times = {mode: {1: [], 2: []} for mode in modes}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        serial = timed(sweep, tmp, "serial", serial=True)
        for k in range(args.repeats):
            for mode in modes:
                for workers in (1, 2):
                    name = f"{mode}{workers}-{k}"
                    t = (timed(sweep, tmp, name, workers=workers) if mode == "cold"
                         else timed_warm(sweep, tmp, name, workers))
                    times[mode][workers].append(t)
                    print(f"repeat {k}, {mode}, {workers} worker(s): {t:.1f} s", flush=True)
    print(f"{n} points, {args.duration * 1e6:g} µs each")
    print(f"serial (in process, warm): {serial:.1f} s = {serial / n:.2f} s per point")
    for mode in modes:
        t1, t2 = statistics.median(times[mode][1]), statistics.median(times[mode][2])
        print(f"{mode}: 1 worker median {t1:.1f} s, 2 workers median {t2:.1f} s, "
              f"speed-up {t1 / t2:.2f}x, Dask overhead per point {(t1 - serial) / n:.2f} s")


if __name__ == "__main__":
    main()
