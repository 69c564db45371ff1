"""Time of the reservoir's default study: 16 Boolean functions on 600 held inputs of 20 µs
(360 to train, 240 to test) plus the temporal stream (1200 inputs of 50 ns), in two worker
processes.

Prints, for each repeat, the wall time of ``run_study`` (streams, read-out training and scoring;
the device build is outside) and the CPU time the workers spent, the engine's steps and the
steps per CPU second. On a shared machine the wall time includes the waits for a core; the CPU
time divided by the number of workers is what two free cores would take.

Run: ``.venv/bin/python benchmarks/bench_reservoir.py [--repeats 3] [--workers 2]``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

from skygas.reservoir import ReservoirDevice, reservoir_config, run_study


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    config = reservoir_config({"study": {"workers": args.workers}})
    device = ReservoirDevice(config)
    # compile (or load the compiled kernels) outside the timing
    run_study(
        reservoir_config(
            {
                "study": {"workers": 1, "n_inputs": 8, "temporal_inputs": 8},
                "hold_time": 1e-7,
                "sensors": {"sample_interval": 2e-9},
            }
        )
    )
    walls, cpus = [], []
    for repeat in range(args.repeats):
        cfg = reservoir_config({"seed": repeat + 1, "study": {"workers": args.workers}})
        started = time.perf_counter()
        summary, _ = run_study(cfg, device)
        wall = time.perf_counter() - started
        walls.append(wall)
        cpus.append(summary["cpu_seconds"])
        xor = summary["xor"]
        print(
            f"repeat {repeat + 1}: {wall:.1f} s wall, {summary['cpu_seconds']:.1f} s CPU in "
            f"{summary['streams']} workers, {summary['steps'] / 1e6:.0f} M steps "
            f"({summary['steps'] / summary['cpu_seconds'] / 1e6:.2f} M steps per CPU s); "
            f"XOR {100 * xor['accuracy']:.1f} % ({xor['margin_standard_errors']:.1f} SE), "
            f"mean of 16 {100 * summary['mean_accuracy']:.1f} %"
        )
    print(
        f"default study: median {statistics.median(walls):.1f} s wall, "
        f"{statistics.median(cpus):.1f} s CPU ({statistics.median(cpus) / args.workers:.1f} s "
        f"per worker) with {args.workers} workers; load average "
        f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores"
    )


if __name__ == "__main__":
    main()
