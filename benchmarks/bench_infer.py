"""Time ``skygas infer`` on an experiment-sized movie (target: at most 2 minutes on 2 cores).

The movie: 100 micrometre skyrmions × 10⁴ frames of 10 ms (10⁶ positions) in a periodic
50 µm film with Gaussian wells of 3 k_BT, a K₁ pair law, a Hall angle of 60° and 20 nm of
localisation error, made by the plain NumPy simulator of ``tests/inference/independent_gas.py``
(not skygas's engine). It is simulated once and not timed. The inference
(:func:`skygas.inference.infer`, with its self-check run of 2000 frames and, where the frames
ask for it, the sampling correction's runs) is timed ``--rounds`` times, wall clock and this
process's CPU time; the medians are printed with the step times of the last round.

Usage: python benchmarks/bench_infer.py [--skyrmions 100] [--frames 10000] [--rounds 3]
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "inference"))

import independent_gas as ig  # noqa: E402


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--skyrmions", type=int, default=100)
    p.add_argument("--frames", type=int, default=10_000)
    p.add_argument("--rounds", type=int, default=3)
    args = p.parse_args()
    side = 50e-6
    spec = ig.GasSpec(
        skyrmions=args.skyrmions,
        frames=args.frames,
        frame_interval=10e-3,
        substeps=3,
        width=side,
        height=side,
        boundary="periodic",
        diffusion=0.31e-12,
        hall_angle=math.radians(60.0),
        wells=ig.random_wells(110, side, side, 3.0, 1.5e-6, seed=7),
        pair=("k1", 17.6e6, 1e-6),
        pair_cutoff=8e-6,
        localisation_error=20e-9,
        pixel_size=100e-9,
    )
    start = time.perf_counter()
    gas = ig.simulate(spec)
    print(f"simulated in {time.perf_counter() - start:.0f} s (not timed)", file=sys.stderr)
    times, cpu = [], []
    marks: list[tuple[float, str]] = []
    for _ in range(args.rounds):
        marks = []
        start = time.perf_counter()
        cpu_start = time.process_time()
        gas.infer(progress=lambda line, m=marks, s=start: m.append((time.perf_counter() - s, line)))
        times.append(time.perf_counter() - start)
        cpu.append(time.process_time() - cpu_start)
    print(f"{args.skyrmions} skyrmions × {args.frames} frames: {len(gas.tracks)} positions")
    print(f"inference wall time: median {statistics.median(times):.1f} s of {times}")
    print(f"inference CPU time of this process: median {statistics.median(cpu):.1f} s of {cpu}")
    for t, line in marks:
        print(f"  {t:7.1f} s  {line}")


if __name__ == "__main__":
    main()
