"""Reshuffler speed on the reference workload, and how ρ moves when the time step is halved.

Reference workload: the ``paper`` preset at J = 1.7e11 A/m² for
0.5 ms of simulated time (100 000 nucleations). Prints, for the preset's time step, the median
wall time over ``--repeats`` runs (different seeds), the simulated time per wall second and ρ;
then ρ at half the step (one run), so the step's effect on the result can be read off.

Run: ``.venv/bin/python benchmarks/bench_reshuffler.py [--duration 5e-4] [--repeats 3]``.
"""

from __future__ import annotations

import argparse
import statistics
import time

from skygas.reshuffler import ReshufflerRun, load_reshuffler_config, summarize


def one_run(duration: float, seed: int, time_step: float | None = None) -> dict:
    overrides = {
        "duration": duration,
        "seed": seed,
        "current_density": 1.7e11,
        "output.trajectory_window": 0.0,
    }
    if time_step is not None:
        overrides["time_step"] = time_step
    config = load_reshuffler_config(preset="paper", overrides=overrides)
    run = ReshufflerRun.build(config)
    start = time.perf_counter()
    run.advance()
    wall = time.perf_counter() - start
    summary = summarize(run).summary
    return {
        "wall": wall,
        "rho": summary["correlation"],
        "dt": summary["time_step_s"],
        "detected": summary["n_detected"],
        "occupancy": summary["max_occupancy"],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--duration", type=float, default=5e-4, help="simulated time [s]")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--skip-half-step", action="store_true")
    args = parser.parse_args()
    one_run(2e-7, seed=0)  # compile outside the timing
    runs = [one_run(args.duration, seed=s) for s in range(1, args.repeats + 1)]
    wall = statistics.median(r["wall"] for r in runs)
    dt = runs[0]["dt"]
    print(
        f"paper preset, J = 1.7e11 A/m², {args.duration * 1e3:g} ms simulated, "
        f"time step {dt * 1e12:.1f} ps"
    )
    walls = ", ".join(f"{r['wall']:.1f}" for r in runs)
    rhos = ", ".join(f"{r['rho']:.4f}" for r in runs)
    print(f"  wall time (median of {len(runs)}): {wall:.1f} s [{walls}]")
    print(f"  simulated time per wall second: {args.duration / wall * 1e6:.2f} µs/s")
    print(f"  ρ per run: {rhos}; peak occupancy {max(r['occupancy'] for r in runs)}")
    if not args.skip_half_step:
        half = one_run(args.duration, seed=1, time_step=dt / 2)
        print(
            f"  half step ({dt / 2 * 1e12:.1f} ps, seed 1): ρ = {half['rho']:.4f} "
            f"(vs {runs[0]['rho']:.4f}), wall {half['wall']:.1f} s"
        )


if __name__ == "__main__":
    main()
