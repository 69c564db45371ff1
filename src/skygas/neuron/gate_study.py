r"""Measurements of the neuron's gate: the crowd a closed gate holds back, and the release.

**Holding.** ``n`` skyrmions are placed as a triangular lattice (spacing 1.5 d_sk, at least one
diameter from the walls) filling the chamber from the output conduit's mouth outwards, the
lattice sites nearest the mouth first, none beyond the gate's rising edge. The gate is closed,
the holding current flows, nothing is injected, and the run lasts ``duration``. The result
counts the skyrmions that crossed the read-out line behind the gate (the leak), the
annihilated ones, and those still in the chamber. With ``annihilation=False`` only the gate
decides; with the calibrated annihilation model the crowd is also thinned by compression.

``gate="drift"`` replaces the potential by the drift barrier that stood for the gate before the
engine had energy landscapes, for comparison: in the band (the gate's half-height width w, across
the conduit) the current's drift is replaced by v = −(h D/w) x̂, D the free diffusion constant,
whose Péclet integral ∫v dx / D = h mimics a step of h k_BT for one skyrmion moving along the
conduit (:func:`drift_band_field`).

**Release.** :func:`release_statistics` reads the releases of a neuron run: for each opening,
its duration, how it ended (reset level or release-time cap), the skyrmions emitted and
annihilated while it was open, and the count before and after.

Run ``python -m skygas.neuron.gate_study`` to print the tables of docs/neuron.md.
"""

from __future__ import annotations

import math

import numpy as np

from skygas.core import units
from skygas.core.errors import require

#: Spacing of the initial crowd's lattice in skyrmion diameters.
CROWD_SPACING = 1.5


def crowd_at_gate(device, n: int, spacing_d: float = CROWD_SPACING) -> np.ndarray:
    """``n`` lattice points [nm] inside the chamber and the output conduit, before the gate.

    Spacing ``spacing_d`` d_sk, before the gate's rising edge, nearest the conduit's mouth first.
    """
    d = device.thiele.skyrmion_diameter * units.M_TO_NM
    a = spacing_d * d
    r = device.config.device.chamber_diameter / 2 * units.M_TO_NM
    rows = int(np.ceil(2 * r / (a * math.sqrt(3) / 2))) + 2
    cols = int(np.ceil(2 * r / a)) + 4
    j, i = np.mgrid[-rows // 2 : rows // 2 + 1, -cols // 2 : cols // 2 + 1]
    x = (i + 0.5 * (j % 2)) * a + device.x_meet
    y = j * a * math.sqrt(3) / 2
    x, y = x.ravel(), y.ravel()
    band = device.band
    edge = band.start[0] * units.M_TO_NM - 2 * band.edge_width * units.M_TO_NM
    outline = device.outline
    ok = (x < edge) & outline._contains_nm(x, y)
    x, y = x[ok], y[ok]
    ok = outline._wall_distance_nm(x, y) >= d
    x, y = x[ok], y[ok]
    order = np.argsort(np.hypot(x - device.x_meet, y))
    require(n <= len(order), "n", n, f"at most {len(order)} skyrmions at this spacing")
    return np.column_stack([x[order[:n]], y[order[:n]]])


def drift_band_field(device, grid, hold_vx, hold_vy, barrier_height: float, temperature: float):
    """The drift barrier (vx, vy) [m/s] on the simulation's ``grid``.

    The holding field with, in the gate's band (half-height width, across the conduit), v = −(h D/w)
    x̂ instead.
    """
    gx, gy = grid.nodes()
    band = device.band
    x0, x1 = band.start[0] * units.M_TO_NM, band.end[0] * units.M_TO_NM
    half = device.config.device.conduit_width / 2 * units.M_TO_NM
    inside = (gx >= x0) & (gx <= x1) & (np.abs(gy) <= half + 1.0)
    diffusion = device.thiele.diffusion_constant(temperature) if temperature > 0 else 0.0
    push = barrier_height * diffusion / ((x1 - x0) / units.M_TO_NM)
    return np.where(inside, -push, hold_vx), np.asarray(hold_vy, float)


def hold_crowd(
    config,
    n: int,
    duration: float = 300e-9,
    seed: int = 0,
    gate: str = "potential",
    annihilation: bool = False,
    record_interval: float | None = None,
) -> dict:
    """Closed gate, holding current, ``n`` skyrmions crowded at the output conduit's mouth.

    See the module's docstring. Returns counts and the leak (emitted) times [s]; trajectories are
    recorded every ``record_interval`` [s] if given.
    """
    from skygas.neuron.device import NeuronDevice

    require(gate in ("potential", "drift"), "gate", gate, "'potential' or 'drift'")
    data = config.model_dump()
    if not annihilation:
        data["annihilation"] = {**data["annihilation"], "enabled": False}
    data["inputs"] = []
    cfg = type(config).model_validate(data)
    device = NeuronDevice(cfg)
    run = device.build(inputs=[], duration=duration, seed=seed)
    run.controller.threshold = math.inf  # never open the gate
    if gate == "drift":
        run.sim.set_landscape_enabled(run.gate.term, False)
        run.sim.set_drift_field(
            *drift_band_field(
                device,
                run.sim.wall_field.grid,
                *run.gate.base,
                cfg.gate.barrier_height,
                cfg.temperature,
            )
        )
    run.sim.state.insert_nm(crowd_at_gate(device, n))
    dt = run.sim.time_step
    every = None if record_interval is None else max(1, round(record_interval / dt)) * dt
    run.sim.run(round(duration / dt) * dt, record_interval=every)  # the nearest whole steps
    exits = run.emission_times()
    return {
        "n": n,
        "gate": gate,
        "barrier_height_kT": cfg.gate.barrier_height,
        "annihilation": annihilation,
        "duration_s": duration,
        "seed": seed,
        "n_leaked": int(len(exits)),
        "leak_times_s": exits.tolist(),
        "n_annihilated": run.annihilator.n_annihilated,
        "n_left": run.sim.count,
        "run": run,
    }


def release_crowd(
    config, n: int, hold: float = 100e-9, limit: float = 400e-9, seed: int = 0, step: float = 1e-9
) -> dict:
    """The release on its own, from ``n`` skyrmions at random in the chamber.

    The skyrmions start 2 d_sk apart, 1.5 d_sk from the walls; ``hold`` [s] with the gate closed at
    the holding current (the crowd gathers at the gate), then the gate opens at the release current,
    with no input, until the count reaches the reset level or ``limit`` [s] has passed. Returns the
    count against the time since the opening (sampled every ``step``), the time to the reset level
    [s] (None if not reached), and the skyrmions emitted and annihilated during the release.
    """
    from skygas.neuron.device import NeuronDevice
    from skygas.physics.geometry import _random_positions_nm

    device = NeuronDevice(config)
    run = device.build(inputs=[], duration=hold, seed=seed)
    run.controller.threshold = math.inf
    d = device.thiele.skyrmion_diameter * units.M_TO_NM
    rng = np.random.default_rng(np.random.SeedSequence((seed, 0x72656C)))
    run.sim.state.insert_nm(_random_positions_nm(run.sim.outline, n, 2 * d, 1.5 * d, rng))
    run.sim.run(hold)
    run.controller.reset_level = -math.inf  # the study decides when it ends
    run.gate.set(True)
    start_count, start_exits = run.sim.count, len(run.sim.exits)
    start_deaths = run.annihilator.n_annihilated
    times, counts, t_reset = [0.0], [start_count], None
    reset = config.rule.reset_level
    while times[-1] < limit - step / 2:
        run.sim.run(step)
        times.append(times[-1] + step)
        counts.append(run.sim.count)
        if counts[-1] <= reset:
            t_reset = times[-1]
            break
    return {
        "n": n,
        "count_at_opening": start_count,
        "time_s": np.array(times),
        "count": np.array(counts),
        "time_to_reset_s": t_reset,
        "emitted": len(run.sim.exits) - start_exits,
        "annihilated": run.annihilator.n_annihilated - start_deaths,
    }


def release_statistics(run) -> list[dict]:
    """One record per gate opening of a finished neuron run.

    ``duration_s``, ``ended`` ("reset", "cap" or "run end"), ``emitted`` and ``annihilated`` while
    open, and the count at the opening and at the closing.
    """
    dt = run.sim.time_step
    openings = np.array(run.controller.openings) * dt
    closings = np.array(run.controller.closings) * dt
    tr = run.trace()
    exits = run.emission_times()
    deaths = run.annihilator.annihilation_times
    cap = run.device.config.rule.release_time
    out = []
    for k, t_open in enumerate(openings):
        t_close = closings[k] if k < len(closings) else run.sim.time
        length = t_close - t_open
        if k >= len(closings):
            ended = "run end"
        elif cap is not None and length >= cap - dt / 2:
            ended = "cap"
        else:
            ended = "reset"
        at = lambda t: int(tr["count"][np.searchsorted(tr["time"], t - dt / 2)])  # noqa: E731
        out.append(
            {
                "open_s": float(t_open),
                "duration_s": float(length),
                "ended": ended,
                "emitted": int(np.count_nonzero((exits >= t_open) & (exits < t_close))),
                "annihilated": int(np.count_nonzero((deaths >= t_open) & (deaths < t_close))),
                "count_open": at(t_open),
                "count_close": at(min(t_close, tr["time"][-1])),
            }
        )
    return out


def _main() -> None:  # pragma: no cover - prints the tables of docs/neuron.md
    import argparse

    from skygas.neuron import NeuronDevice, neuron_config

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--heights", type=float, nargs="+", default=[5, 10, 20, 40])
    parser.add_argument("--crowds", type=int, nargs="+", default=[12, 30, 60])
    parser.add_argument("--duration", type=float, default=300e-9)
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    parser.add_argument("--release-seeds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument(
        "--skip",
        choices=["hold", "release", "runs"],
        nargs="*",
        default=[],
        help="parts to leave out: the holding table, the release of a crowd, "
        "the releases of default neuron runs",
    )
    parser.add_argument(
        "--figure",
        help="PNG of a crowd of the first size at the first two "
        "heights (trajectories over the landscape), then stop",
    )
    args = parser.parse_args()
    if args.figure:
        from skygas.neuron.figures import plot_device

        for h in args.heights[:2]:
            r = hold_crowd(
                neuron_config({"gate": {"barrier_height": h}}),
                args.crowds[0],
                args.duration,
                args.seeds[0],
                record_interval=2e-9,
            )
            path = args.figure.replace(".png", f"-{h:g}kT.png")
            plot_device(r["run"], path)
            print(f"{path}: {r['n_leaked']} of {args.crowds[0]} leaked", flush=True)
        return
    if "hold" not in args.skip:
        print("gate      h(kT)  N  annihilation  leaked  annihilated  left   (per seed)")
        for gate in ("potential", "drift"):
            for h in args.heights:
                for n in args.crowds:
                    for ann in (False, True):
                        rows = [
                            hold_crowd(
                                neuron_config({"gate": {"barrier_height": h}}),
                                n,
                                args.duration,
                                s,
                                gate,
                                ann,
                            )
                            for s in args.seeds
                        ]
                        print(
                            f"{gate:9s} {h:5g} {n:3d}  {str(ann):5s}  "
                            f"{[r['n_leaked'] for r in rows]}  "
                            f"{[r['n_annihilated'] for r in rows]}  "
                            f"{[r['n_left'] for r in rows]}",
                            flush=True,
                        )
    if "release" not in args.skip:
        print(
            "release of a crowd (no input): n, count at opening, time to reset (ns), "
            "emitted, annihilated"
        )
        for n in args.crowds:
            for seed in args.release_seeds:
                r = release_crowd(neuron_config({}), n, seed=seed)
                t = r["time_to_reset_s"]
                print(
                    f"  {n:3d} {r['count_at_opening']:3d} "
                    f"{'not reached' if t is None else round(t * 1e9)} {r['emitted']:3d} "
                    f"{r['annihilated']:3d}",
                    flush=True,
                )
    if "runs" not in args.skip:
        for seed in args.release_seeds:
            run = NeuronDevice(neuron_config({"seed": seed})).build().run()
            rel = release_statistics(run)
            closed = [r for r in rel if r["ended"] != "run end"]
            print(
                f"seed {seed}: {len(rel)} spikes; durations (ns) "
                f"{[round(r['duration_s'] * 1e9) for r in rel]}; ended "
                f"{[r['ended'] for r in rel]}; emitted {[r['emitted'] for r in rel]}; "
                f"annihilated {[r['annihilated'] for r in rel]}; count open/close "
                f"{[(r['count_open'], r['count_close']) for r in rel]}; mean duration "
                f"{np.mean([r['duration_s'] for r in closed]) * 1e9:.0f} ns",
                flush=True,
            )


if __name__ == "__main__":  # pragma: no cover
    _main()
