"""Engine speed: steps/s and pair-force evaluations/s versus the number of skyrmions.

Skyrmions fill a disk at the density of a half-full 1024 nm chamber (45 skyrmions in the
chamber, half the paper's saturation of ~90), at 300 K with material S2 and the suggested time
step, relaxed for 2000 steps after random placement. For each N the script prints the median
over several repeats of:
- the time per Heun step (µs) and steps per second,
- pair-force evaluations per second inside the cutoff, timing the pair-force loop alone (the
  wall and drive forces and the conversion to velocities are not part of it),
and finally the exponent of cost versus N from a log–log fit. Before and after each N it
measures the core's clock (:mod:`machine_clock`) and prints the time per step in thousands of
cycles at their mean: this shared machine changes clock from hour to hour, and cycles compare
across those states where microseconds do not.

Run: ``make bench`` or ``.venv/bin/python benchmarks/bench_engine.py [--quick]``.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from machine_clock import clock_ghz
from machine_steal import StealMeter
from pair_pass import repeated_pair_pass
from skygas.engine import Simulation
from skygas.physics.geometry import _random_positions_nm, disk

HALF_FULL_DENSITY = 45 / (np.pi * 512.0**2)  # skyrmions per nm²


def make_sim(n: int, seed: int = 1) -> Simulation:
    radius_nm = np.sqrt(n / (np.pi * HALF_FULL_DENSITY))
    outline = disk(diameter=2 * radius_nm * 1e-9)
    sim = Simulation(outline, "S2", temperature=300.0, seed=seed, grid_spacing=4e-9, capacity=n)
    rng = np.random.default_rng(seed)
    d_sk = sim.thiele.skyrmion_diameter_internal
    pts = _random_positions_nm(outline, n, 1.2 * d_sk, 0.6 * d_sk, rng)
    sim.state.insert_nm(pts)
    # Compile, then let the random start relax (≈ 0.2 µs): right after random placement the
    # skyrmions push each other apart fast and the neighbour list is rebuilt far more often
    # than in the steady gas whose cost is being measured.
    sim.run(2000 * sim.time_step)
    return sim


def time_steps(sim: Simulation, n_steps: int, repeats: int) -> list[float]:
    out = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        sim.run(n_steps * sim.time_step, chunk_steps=n_steps)
        out.append((time.perf_counter() - t0) / n_steps)
    return out


def time_pairs(sim: Simulation, repeats: int, calls: int) -> tuple[float, float]:
    """Median seconds of one pass of the pair-force loop over one neighbour list (compiled,
    ``calls`` passes per timing), and the pairs inside the cutoff per pass."""
    _, _, pairs = repeated_pair_pass(sim, 1)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        repeated_pair_pass(sim, calls)
        times.append((time.perf_counter() - t0) / calls)
    return statistics.median(times), pairs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats")
    parser.add_argument("--sizes", type=int, nargs="*", default=[50, 200, 1000, 10000])
    args = parser.parse_args()
    steal = StealMeter()
    repeats = 3 if args.quick else 7
    print(
        f"{'N':>6} {'µs/step':>10} {'steps/s':>10} {'pairs/eval':>11} {'pair evals/s':>13}"
        f" {'GHz':>10} {'kcycles/step':>13}"
    )
    costs = []
    for n in args.sizes:
        sim = make_sim(n)
        n_steps = max(50, int(2e5 / n))
        before = clock_ghz()
        per_step = statistics.median(time_steps(sim, n_steps, repeats))
        t_pairs, pairs = time_pairs(sim, repeats, calls=max(20, int(1e5 / n)))
        after = clock_ghz()
        costs.append(per_step)
        ghz = 0.5 * (before + after)
        print(
            f"{n:>6} {per_step * 1e6:>10.2f} {1 / per_step:>10.0f} {pairs:>11.0f} "
            f"{pairs / t_pairs:>13.3g} {before:>4.2f}-{after:<4.2f} "
            f"{per_step * ghz * 1e6:>13.1f}",
            flush=True,
        )
    slope = np.polyfit(np.log(args.sizes), np.log(costs), 1)[0]
    print(f"cost exponent (time per step ∝ N^b): b = {slope:.3f}")
    print(steal.report())


if __name__ == "__main__":
    main()
