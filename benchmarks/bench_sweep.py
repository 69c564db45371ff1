"""Sweep speed on Dask: a 16-point sweep of short reshuffler runs on 1 and 2 local workers.

Workload: the ``paper`` preset (1024 nm chambers), 4 current densities × 4 p-values, one
replica, ``--duration`` of simulated time per run (default 2 µs). Every point of this sweep
shares one device, so each process solves the current and builds the wall field once (about
2 s, :mod:`skygas.memo`); a point then costs its simulation, ~0.2 s at 2 µs. Prints the median
wall time (and the range) over ``--repeats`` sweeps for 1 and 2 workers and their ratio, in
three modes:

- ``cold``: each sweep starts its own local cluster (``skygas sweep --workers N``), so the
  cluster's start, each worker's imports and compiled-kernel loads, and each worker's device
  set-up are included;
- ``warm``: the cluster is started (with the settings ``skygas sweep`` gives its own,
  :func:`skygas.sweep.start_local_cluster`) and its workers warmed up first (imports and
  kernels, on another, small device), then the sweep runs on it through its scheduler address
  (``skygas sweep --scheduler ADDRESS``, a cluster that stays up); each worker's device set-up
  is included;
- ``hot``: as ``warm``, but every worker has already run this device once (a cluster that ran
  an earlier sweep of the same device): only the runs themselves and the Dask path remain.

It also runs the sweep serially in this process, from a fresh set-up (``cold``/``warm``) and
with the set-up already done (``hot``), and prints the Dask path's overhead per point,
(T(1 worker) − T(serial)) / 16, for each mode. In ``warm``/``hot`` it prints how many current
solves each worker did (``skygas.memo`` counts), to show the set-up was not repeated per point,
and the CPU time this process (the client, the scheduler and the nannies of the local cluster)
used during a sweep: on a machine with as many cores as workers, that time is taken from them.

Run: ``.venv/bin/python benchmarks/bench_sweep.py [--repeats 3] [--duration 2e-6]
[--mode all|cold|warm|hot]``.
"""

from __future__ import annotations

import argparse
import resource
import statistics
import tempfile
import time
from pathlib import Path

from machine_steal import StealMeter
from skygas.memo import clear_memos, memo_stats
from skygas.sweep import parse_sweep, run_one, run_sweep, start_local_cluster

MODES = ("cold", "warm", "hot")


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
    assert len(report.computed) == len(sweep.runs) and not report.failed, report.failed
    return time.perf_counter() - start


def _warm_up() -> None:
    """Imports and compiled kernels, on a small device (not the benchmark's)."""
    config = parse_sweep({"base": {"preset": "paper", "duration": 5e-8,
                                   "device": {"chamber_diameter": 3e-7},
                                   "output": {"trajectory_window": 0.0}},
                          "grid": {"temperature": [300.0]}}).runs[0].config
    run_one(config.model_dump_json())


def _current_solves() -> int:
    return memo_stats()["current"]["misses"]


def _process_cpu() -> float:
    """CPU seconds used so far by this process (all its threads)."""
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def timed_on_cluster(sweep, tmp: Path, name: str, workers: int,
                     hot: bool) -> tuple[float, list, float]:
    """Wall time of the sweep on a running local cluster, the current solves each worker did,
    and the CPU time this process (client, scheduler and nannies) used meanwhile."""
    from dask.distributed import Client

    with start_local_cluster(workers) as cluster, Client(cluster) as client:
        client.run(_warm_up)
        if hot:  # every worker runs this device once: its set-up is then kept
            client.run(run_one, sweep.runs[0].config.model_dump_json())
        before = client.run(_current_solves)
        cpu = _process_cpu()
        t = timed(sweep, tmp, name, scheduler=cluster.scheduler_address)
        cpu = _process_cpu() - cpu
        after = client.run(_current_solves)
        return t, [after[w] - before[w] for w in sorted(after)], cpu


def timed_serial(sweep, tmp: Path, name: str, hot: bool) -> float:
    clear_memos()
    if hot:
        run_one(sweep.runs[0].config.model_dump_json())
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
    _warm_up()  # imports and JIT, outside the timings
    modes = MODES if args.mode == "all" else (args.mode,)
    times = {mode: {1: [], 2: []} for mode in modes}
    serial = {"fresh": [], "hot": []}
    solves = {mode: [] for mode in modes}
    client_cpu = {mode: {1: [], 2: []} for mode in modes}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for k in range(args.repeats):
            for kind in ("fresh", "hot") if "hot" in modes else ("fresh",):
                if kind == "fresh" and modes == ("hot",):
                    continue
                t = timed_serial(sweep, tmp, f"serial-{kind}-{k}", hot=kind == "hot")
                serial[kind].append(t)
                print(f"repeat {k}, serial ({kind} set-up): {t:.1f} s", flush=True)
            for mode in modes:
                for workers in (1, 2):
                    name = f"{mode}{workers}-{k}"
                    if mode == "cold":
                        t = timed(sweep, tmp, name, workers=workers)
                    else:
                        t, done, cpu = timed_on_cluster(sweep, tmp, name, workers,
                                                        mode == "hot")
                        solves[mode].append(done)
                        client_cpu[mode][workers].append(cpu)
                    times[mode][workers].append(t)
                    print(f"repeat {k}, {mode}, {workers} worker(s): {t:.1f} s", flush=True)
    print(f"{n} points, {args.duration * 1e6:g} µs each, {args.repeats} repeats")
    for kind, values in serial.items():
        if values:
            t = statistics.median(values)
            print(f"serial ({kind} set-up, in process): median {t:.1f} s ({spread(values)}) "
                  f"= {t / n:.2f} s per point")
    for mode in modes:
        t1, t2 = statistics.median(times[mode][1]), statistics.median(times[mode][2])
        reference = statistics.median(serial["hot" if mode == "hot" else "fresh"])
        print(f"{mode}: 1 worker median {t1:.1f} s ({spread(times[mode][1])}), 2 workers "
              f"median {t2:.1f} s ({spread(times[mode][2])}), speed-up {t1 / t2:.2f}x "
              f"(per repeat: {', '.join(f'{a / b:.2f}' for a, b in zip(times[mode][1], times[mode][2]))}), "
              f"Dask overhead per point {(t1 - reference) / n:.2f} s")
        if solves[mode]:
            print(f"  current solves per worker in each sweep (1 worker, 2 workers, ...): "
                  f"{solves[mode]}")
            print("  CPU of the client, scheduler and nannies during a sweep (this process; "
                  "it competes with the workers for the cores): median "
                  f"{statistics.median(client_cpu[mode][1]):.2f} s with 1 worker, "
                  f"{statistics.median(client_cpu[mode][2]):.2f} s with 2")
    print(steal.report())


if __name__ == "__main__":
    main()
