"""Cost of an energy landscape: the time of a Heun step with and without one.

The gas of ``bench_engine.py`` (a disk at the density of a half-full 1024 nm chamber, S2,
300 K) with N skyrmions is built twice: once with no landscape, once with a grid landscape
(a disorder of rms 3 k_BT and correlation length 40 nm plus random pinning wells of 5 k_BT,
σ = 15 nm, one per (100 nm)², so the engine interpolates the summed nodes at every force
pass), and a third time with a landscape of zeros (a disorder of rms 0: the same lookups and
arithmetic, the dynamics of the plain gas, so the pure cost of the landscape term). All use
the same time step (the suggested step without the landscape, which the landscape's curvature
allows). Each round times a block of steps of each, rotating the order, so that the shared
machine's changing clock affects all alike; the script prints the median time per step of each
and the median of the per-round ratios. Times are the process's CPU time (the engine runs on
one thread), which other processes on a shared machine disturb less than the wall clock.

A second workload is the ``paper`` reshuffler (J = 1.7×10¹¹ A/m², 20 µs), whose steps also
inject, detect and look up walls: its run with no landscape against the same run with a
disorder of rms 0 and of rms 3 k_BT (ξ = 40 nm), alternating, CPU time.

Run: ``.venv/bin/python benchmarks/bench_landscape.py [--rounds 9] [--sizes 100 1000]``.
The cost of the engine without a landscape against the code before landscapes existed is
measured with ``bench_versions.py OLD_SRC NEW_SRC``.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from skygas.engine import Simulation
from skygas.fields.landscape import Disorder, RandomPinning
from skygas.physics.geometry import _random_positions_nm, disk

HALF_FULL_DENSITY = 45 / (np.pi * 512.0**2)  # skyrmions per nm²
LANDSCAPES = {
    "none": [],
    "zeros": [Disorder(rms_kT=0.0, correlation_length=40e-9)],
    "grid": [
        Disorder(rms_kT=3.0, correlation_length=40e-9),
        RandomPinning(density=1e14, sigma=15e-9, depth_kT=5.0),
    ],
}


def make_sim(n: int, landscape, time_step=None) -> Simulation:
    radius_nm = np.sqrt(n / (np.pi * HALF_FULL_DENSITY))
    outline = disk(diameter=2 * radius_nm * 1e-9)
    sim = Simulation(
        outline,
        "S2",
        temperature=300.0,
        seed=1,
        grid_spacing=4e-9,
        capacity=n,
        time_step=time_step,
        landscape=landscape,
    )
    d_sk = sim.thiele.skyrmion_diameter_internal
    pts = _random_positions_nm(outline, n, 1.2 * d_sk, 0.6 * d_sk, np.random.default_rng(1))
    sim.state.insert_nm(pts)
    sim.run(2000 * sim.time_step)  # compile, and let the random start relax
    return sim


def seconds_per_step(sim: Simulation, steps: int) -> float:
    t0 = time.process_time()
    sim.run(steps * sim.time_step, chunk_steps=steps)
    return (time.process_time() - t0) / steps


def reshuffler_seconds(rms_kt: float | None) -> float:
    """CPU seconds of a 20 µs paper reshuffler run (after building it)."""
    from skygas.reshuffler import ReshufflerRun, load_reshuffler_config

    overrides = {
        "duration": 2e-5,
        "seed": 1,
        "current_density": 1.7e11,
        "output.trajectory_window": 0.0,
    }
    config = load_reshuffler_config(preset="paper", overrides=overrides)
    if rms_kt is not None:
        config = config.model_copy(
            update={"potentials": [Disorder(rms_kT=rms_kt, correlation_length=40e-9)]}
        )
    run = ReshufflerRun.build(config)
    t0 = time.process_time()
    run.advance()
    return time.process_time() - t0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--rounds", type=int, default=9)
    parser.add_argument("--sizes", type=int, nargs="*", default=[100, 1000])
    parser.add_argument("--reshuffler-rounds", type=int, default=5)
    args = parser.parse_args()
    for n in args.sizes:
        sims = {"none": make_sim(n, LANDSCAPES["none"])}
        dt = sims["none"].time_step
        for name in ("zeros", "grid"):
            sims[name] = make_sim(n, LANDSCAPES[name], time_step=dt)
        steps = max(200, 400_000 // n)
        times = {name: [] for name in sims}
        ratios = {"zeros": [], "grid": []}
        names = list(sims)
        for r in range(args.rounds):
            for name in names[r % 3 :] + names[: r % 3]:
                times[name].append(seconds_per_step(sims[name], steps))
            for name in ratios:
                ratios[name].append(times[name][-1] / times["none"][-1])
        per_step = {k: statistics.median(v) * 1e6 for k, v in times.items()}
        print(
            f"N = {n}: {steps} steps per timing, {args.rounds} rounds, dt = {dt:.3g} s; CPU "
            f"time per step: no landscape {per_step['none']:.1f} µs, zeros "
            f"{per_step['zeros']:.1f} µs, grid {per_step['grid']:.1f} µs",
            flush=True,
        )
        for name, values in ratios.items():
            print(
                f"  {name}/none: median {statistics.median(values):.3f} "
                f"(rounds {min(values):.3f}…{max(values):.3f})",
                flush=True,
            )
    if args.reshuffler_rounds:
        variants = {"none": None, "zeros": 0.0, "disorder 3 kT": 3.0}
        for rms in variants.values():  # compile
            reshuffler_seconds(rms)
        times = {name: [] for name in variants}
        names = list(variants)
        for r in range(args.reshuffler_rounds):
            for name in names[r % 3 :] + names[: r % 3]:
                times[name].append(reshuffler_seconds(variants[name]))
        base = statistics.median(times["none"])
        print(
            "reshuffler (paper, 1.7e11 A/m², 20 µs), CPU s: "
            + ", ".join(
                f"{name} {statistics.median(t):.2f} (×{statistics.median(t) / base:.2f})"
                for name, t in times.items()
            ),
            flush=True,
        )


if __name__ == "__main__":
    main()
