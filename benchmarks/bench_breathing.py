"""Breathing against rigid skyrmions: the cost per step and the time step, as ratios.

The same gas (S2 at the density of a half-full 1024 nm chamber, 300 K) runs with rigid
skyrmions and with breathing ones (S2 with a harmonic E_self of curvature 6·10⁻⁴ J/m², about
what S2's field sensitivity gives, and s_p = s_w = 1), at one common time step so that the cost
per step compares like with like. Rigid and breathing alternate, repeat after repeat (this
machine's clock drifts within a session), and the script prints the median time per step of
each, their ratio (the goal: at most 1.5), and the ratio of the suggested time steps (how many
more steps a breathing run of the same duration takes). A third gas adds the centre's 𝒟(R)
(a thin wall's) to the breathing one: what a calibrated model's mobility at each radius costs.

Run: ``.venv/bin/python benchmarks/bench_breathing.py [--n 400] [--repeats 7]``.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from skygas.engine import Simulation
from skygas.physics.geometry import _random_positions_nm, disk
from skygas.physics.materials import BreathingSpec, preset

HALF_FULL_DENSITY = 45 / (np.pi * 512.0**2)  # skyrmions per nm²
#: E_self'' [J/m²]: 4π M_s t_F / |dR/dB| with S2's −6.3 % of the radius per mT
CURVATURE = 6e-4


def soft_s2(centre_dissipation: bool = False):
    """S2 with a harmonic E_self(R) over R₀(1 ± 0.4) and s_p = s_w = 1.

    With ``centre_dissipation``, also the centre's 𝒟(R) of a thin wall, 2π(R/Δ + Δ/R).
    """
    s2 = preset("S2")
    r0 = s2.skyrmion_radius
    radius = np.linspace(0.6 * r0, 1.4 * r0, 41)
    extra = {}
    if centre_dissipation:
        width = np.sqrt(s2.exchange_stiffness / s2.anisotropy)
        extra["dissipation"] = tuple(2 * np.pi * (radius / width + width / radius))
    spec = BreathingSpec(
        radius=tuple(radius), energy=tuple(0.5 * CURVATURE * (radius - r0) ** 2), **extra
    )
    return s2.model_copy(
        update={"particle_model": "breathing", "breathing": spec, "name": "S2-soft"}
    )


def make_sim(material, n: int, time_step: float, seed: int = 1) -> Simulation:
    radius_nm = np.sqrt(n / (np.pi * HALF_FULL_DENSITY))
    outline = disk(diameter=2 * radius_nm * 1e-9)
    sim = Simulation(
        outline, material, temperature=300.0, seed=seed, time_step=time_step, capacity=n
    )
    rng = np.random.default_rng(seed)
    d_sk = sim.thiele.skyrmion_diameter_internal
    sim.state.insert_nm(_random_positions_nm(outline, n, 1.2 * d_sk, 0.6 * d_sk, rng))
    sim.run(2000 * time_step)  # compile, and let the random start relax
    return sim


def seconds_per_step(sim: Simulation, steps: int) -> float:
    start = time.perf_counter()
    sim.run(steps * sim.time_step, chunk_steps=steps)
    return (time.perf_counter() - start) / steps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=400, help="skyrmions (default 400)")
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--steps", type=int, default=2000)
    args = parser.parse_args()
    rigid_material, soft = preset("S2"), soft_s2()
    probe = disk(diameter=1e-6)
    dt_rigid = Simulation(probe, rigid_material, temperature=300.0).time_step
    dt_soft = Simulation(probe, soft, temperature=300.0).time_step
    common = min(dt_rigid, dt_soft)
    sims = {
        "rigid": make_sim(rigid_material, args.n, common),
        "breathing": make_sim(soft, args.n, common),
        # the centre's mobility at each radius: one more pass over the skyrmions per stage
        "+ 𝒟(R)": make_sim(soft_s2(centre_dissipation=True), args.n, common),
    }
    times: dict[str, list[float]] = {name: [] for name in sims}
    for _ in range(args.repeats):
        for name, sim in sims.items():
            times[name].append(seconds_per_step(sim, args.steps))
    median = {name: statistics.median(t) for name, t in times.items()}
    print(f"{args.n} skyrmions, {args.repeats} alternating repeats of {args.steps} steps")
    for name, value in median.items():
        print(
            f"  {name:9s}: {value * 1e6:8.1f} µs per step "
            f"({value / args.n * 1e9:6.1f} ns per skyrmion)"
        )
    print(
        "  cost per step, breathing/rigid: "
        f"{median['breathing'] / median['rigid']:.2f} (goal ≤ 1.5)"
    )
    print(
        "  the centre's 𝒟(R) on top, (breathing + 𝒟(R))/breathing: "
        f"{median['+ 𝒟(R)'] / median['breathing']:.2f}"
    )
    print(
        f"  suggested steps: rigid {dt_rigid:.3g} s, breathing {dt_soft:.3g} s "
        f"(ratio {dt_soft / dt_rigid:.2f}); cost per simulated time, breathing/rigid: "
        f"{median['breathing'] / median['rigid'] * dt_rigid / dt_soft:.2f}"
    )


if __name__ == "__main__":
    main()
