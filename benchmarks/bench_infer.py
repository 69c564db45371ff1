"""Time ``skygas infer`` on 100 skyrmions × 10⁴ frames, IBI included (target: < 2 min on 2 cores).

The tracks are simulated once (:func:`skygas.inference.synthetic.simulated_tracks`, a 2 µm square
of S2 at 300 K with a 1.5 k_BT random landscape) and not timed; the inference
(:func:`skygas.inference.infer`, default IBI: at most 6 iterations of 2000-frame simulations) is
timed ``--rounds`` times, wall clock and this process's CPU time (the fair figure on a shared
machine); the medians are printed with the step times of the last round.

Usage: python benchmarks/bench_infer.py [--skyrmions 100] [--frames 10000] [--rounds 3]
"""

from __future__ import annotations

import argparse
import statistics
import time

from skygas.inference.synthetic import simulated_tracks


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--skyrmions", type=int, default=100)
    p.add_argument("--frames", type=int, default=10_000)
    p.add_argument("--rounds", type=int, default=3)
    args = p.parse_args()
    side = 2e-6
    gas = simulated_tracks(skyrmions=args.skyrmions, frames=args.frames, width=side, height=side)
    times, cpu = [], []
    for _ in range(args.rounds):
        marks = []
        start = time.perf_counter()
        cpu_start = time.process_time()
        result = gas.infer(
            progress=lambda line, m=marks, s=start: m.append((time.perf_counter() - s, line))
        )
        times.append(time.perf_counter() - start)
        cpu.append(time.process_time() - cpu_start)
    print(f"{args.skyrmions} skyrmions × {args.frames} frames: {len(gas.tracks)} positions")
    print(f"inference wall time: median {statistics.median(times):.1f} s of {times}")
    print(f"inference CPU time of this process: median {statistics.median(cpu):.1f} s of {cpu}")
    print(f"IBI iterations: {len(result.ibi.chi2)}, chi2 {[round(c, 2) for c in result.ibi.chi2]}")
    for t, line in marks:
        print(f"  {t:7.1f} s  {line}")


if __name__ == "__main__":
    main()
