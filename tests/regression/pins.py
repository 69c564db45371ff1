"""The runs whose results are pinned across refactors of the engine (see test_pins.py).

Each function runs a small, fixed-seed case through the public API and returns named arrays.
``python tests/regression/pins.py`` rewrites ``pins.npz`` from the current code; do that only
for a change that is meant to alter results, and say so in the commit.
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

PINS = Path(__file__).with_name("pins.npz")


def after_start(ds):
    """The frames after t = 0: the pins were written before a run recorded its start."""
    assert ds.time.values[0] == 0.0
    return ds.isel(time=slice(1, None))


def gas_in_chamber() -> dict[str, np.ndarray]:
    """25 interacting skyrmions in the paper's chamber at 300 K, Heun, 600 steps."""
    import skygas
    from skygas.physics.geometry import _random_positions_nm

    outline = skygas.chamber_with_conduits(chamber_diameter=1024e-9)
    sim = skygas.Simulation(outline, "S2", temperature=300.0, seed=3)
    rng = np.random.default_rng(5)
    d_sk = sim.thiele.skyrmion_diameter_internal
    pts = _random_positions_nm(sim.outline, 25, 1.2 * d_sk, 1.2 * d_sk, rng)
    sim.add_skyrmions(pts * 1e-9)
    sim.run(600 * sim.time_step, record_interval=20 * sim.time_step)
    ds = after_start(sim.trajectories())
    return {
        "gas_x": ds.x.values,
        "gas_y": ds.y.values,
        "gas_counters": np.array([sim.step, sim.wall_escapes, sim.pair_evaluations]),
    }


def drifting_gas() -> dict[str, np.ndarray]:
    """Skyrmions pushed out of an open rectangle by a uniform drift (η ≠ α: Hall angle), with
    exits; Euler–Maruyama with two Brownian sub-steps and the Lin–Reichhardt pair law."""
    import skygas
    from skygas.physics.geometry import rectangle
    from skygas.physics.materials import derive_thiele, preset

    material = preset("S2")
    thiele = replace(derive_thiele(material), eta=0.3)
    outline = rectangle(800e-9, 300e-9).with_port("exit", (400e-9, -150e-9), (400e-9, 150e-9))
    sim = skygas.Simulation(
        outline,
        material,
        temperature=300.0,
        seed=9,
        thiele=thiele,
        drift_velocity=(40.0, 0.0),
        integrator="euler-maruyama",
        brownian_substeps=2,
        pair_law="lin-reichhardt",
    )
    xs = np.linspace(-300e-9, 100e-9, 6)
    sim.add_skyrmions(np.column_stack([xs, np.zeros_like(xs)]))
    sim.run(2000 * sim.time_step, record_interval=50 * sim.time_step)
    ds = after_start(sim.trajectories())
    return {
        "drift_x": ds.x.values,
        "drift_y": ds.y.values,
        "drift_exit_time": ds.exit_time.values,
        "drift_exit_skyrmion": ds.exit_skyrmion.values,
    }


def reshuffler() -> dict[str, np.ndarray]:
    """Two short runs of the paper's reshuffler: ρ, p_out and the read-out record."""
    from skygas.reshuffler.config import load_reshuffler_config
    from skygas.reshuffler.files import run_reshuffler

    out = {}
    for seed, current in ((0, 3.8e11), (1, 1.7e11)):
        config = load_reshuffler_config(
            None,
            preset="paper",
            overrides={"seed": seed, "current_density": current, "duration": 3e-6},
        )
        result = run_reshuffler(config, None, progress=False, figures=False)
        s = result.summary
        out[f"reshuffler{seed}_numbers"] = np.array(
            [s["correlation"], s["p_out"], s["n_detected"], s["n_present"], s["max_occupancy"]],
            dtype=float,
        )
        out[f"reshuffler{seed}_detection_time"] = result.dataset["detection_time"].values
    return out


def neuron() -> dict[str, np.ndarray]:
    """The default neuron for 2 µs: spikes, annihilations, emissions."""
    from skygas.neuron.config import load_neuron_config
    from skygas.neuron.device import NeuronDevice

    config = load_neuron_config(None, seed=4, duration=2e-6)
    run = NeuronDevice(config).build().run()
    return {
        "neuron_spikes": run.spike_times(),
        "neuron_emissions": run.emission_times(),
        "neuron_counts": np.array(
            [run.annihilator.n_annihilated, run.injector.n_injected, run.sim.count]
        ),
        "neuron_trace_count": run.trace()["count"],
    }


CASES = (gas_in_chamber, drifting_gas, reshuffler, neuron)


def compute() -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {}
    for case in CASES:
        out.update(case())
    return out


if __name__ == "__main__":
    import llvmlite.binding as llvm

    data = compute()
    data["host_cpu"] = np.array(llvm.get_host_cpu_name())
    np.savez(PINS, **data)
    print(f"wrote {PINS} ({len(data)} arrays)", file=sys.stderr)
