"""The constant external force: exact motion of a free skyrmion, the neighbour-list margins and
the sanity check it sizes, and its `[forces] external_force` section in every device."""

from __future__ import annotations

import math
import textwrap

import numpy as np
import pytest

from skygas import Simulation, disk
from skygas.core.errors import InputError
from skygas.runs import sanity

FORCE = (3e-12, -1.5e-12)  # [N]


def test_a_free_skyrmion_moves_at_the_mobility_times_the_force_exactly():
    """T = 0, one skyrmion far from every wall: dx/dt = M·F with the Thiele mobility
    M = (a I − g ε)/(a² + g²), a = α𝒟k, g = G (docs/physics.md §1). Heun integrates a constant
    velocity exactly, so the displacement is n dt M·F to rounding."""
    sim = Simulation(disk(diameter=8e-6), "S2", temperature=0.0, external_force=FORCE)
    sim.add_skyrmions(np.array([[0.0, 0.0]]))
    steps = 500
    sim.run(steps * sim.time_step)
    _, xy = sim.positions()
    th = sim.thiele
    a, g = th.damping * th.dissipation * th.k, th.gyrocoupling
    fx, fy = FORCE
    v = np.array([a * fx - g * fy, a * fy + g * fx]) / (a * a + g * g)
    expected = steps * sim.time_step * v
    assert np.linalg.norm(expected) > 0.3 * th.skyrmion_diameter  # a real displacement
    np.testing.assert_allclose(xy[0], expected, rtol=1e-9, atol=1e-18)
    # the skyrmion Hall angle between F and v
    angle = math.atan2(v[1], v[0]) - math.atan2(fy, fx)
    assert math.isclose(math.tan(angle), g / a, rel_tol=1e-9)


def test_no_force_leaves_every_bit_of_a_run_unchanged():
    def run(**kw):
        sim = Simulation(disk(diameter=1e-6), "S2", temperature=300.0, seed=3, **kw)
        sim.add_skyrmions(np.array([[0.0, 0.0], [1.2e-7, 0.0], [0.0, -1.5e-7]]))
        sim.run(300 * sim.time_step)
        return sim.positions()[1]

    assert np.array_equal(run(), run(external_force=(0.0, 0.0)))


def test_the_force_widens_the_neighbour_margins_as_a_drift_of_the_same_speed():
    still = Simulation(disk(diameter=2e-6), "S2", temperature=0.0)
    pushed = Simulation(disk(diameter=2e-6), "S2", temperature=0.0, external_force=FORCE)
    th = pushed.thiele
    a, g = th.damping * th.dissipation * th.k, th.gyrocoupling
    speed = math.hypot(*FORCE) / math.hypot(a, g)  # |M·F| [m/s] = [nm/ns]
    base, cells = still.neighbor_cells.margin_max, pushed.neighbor_cells
    expected = base + cells.margin_steps * pushed.time_step * 1e9 * speed  # [nm]
    cap = 1.25 * th.skyrmion_diameter_internal  # NEIGHBOR_MARGIN_MAX diameters
    assert base < expected < cap  # the force's own margin, not the cap
    assert cells.margin_max == pytest.approx(expected, rel=1e-9)


def test_a_force_too_strong_for_the_time_step_is_named_by_the_sanity_check():
    sim = Simulation(disk(diameter=2e-6), "S2", temperature=0.0, external_force=(2e-9, 0.0))
    found = sanity.findings_before_run(object(), sim)
    assert [e.field for e in found] == ["forces.external_force"]
    assert "diameters per step" in str(found[0])
    quiet = Simulation(disk(diameter=2e-6), "S2", temperature=0.0, external_force=FORCE)
    assert sanity.findings_before_run(object(), quiet) == []


@pytest.mark.parametrize("bad", [(1e-12,), (float("nan"), 0.0), (0.0, float("inf"))])
def test_a_bad_force_is_one_line(bad):
    with pytest.raises(InputError, match="external_force"):
        Simulation(disk(diameter=2e-6), "S2", external_force=bad)


FORCES_TOML = "[forces]\nexternal_force = [3e-12, -1.5e-12]\n"


def _recorded(sim) -> list[float]:
    return sim.parameters()["external_force_N"]


def test_simulate_takes_the_force_from_toml(tmp_path):
    from skygas.runs.config import load_config

    path = tmp_path / "run.toml"
    path.write_text(
        textwrap.dedent(
            """
            duration = 1e-9
            [geometry]
            kind = "chamber"
            closed = true
            [skyrmions]
            random_count = 3
            """
        )
        + FORCES_TOML
    )
    assert _recorded(load_config(path).build()) == list(FORCE)


def test_the_reshuffler_takes_the_force_from_toml(tmp_path):
    from skygas.reshuffler import ReshufflerRun, load_reshuffler_config

    path = tmp_path / "r.toml"
    path.write_text("duration = 1e-8\n" + FORCES_TOML)
    run = ReshufflerRun.build(load_reshuffler_config(path))
    assert _recorded(run.sim) == list(FORCE)


def test_the_neuron_takes_the_force_from_toml(tmp_path):
    from skygas.neuron import NeuronDevice, load_neuron_config

    path = tmp_path / "n.toml"
    path.write_text(FORCES_TOML)
    run = NeuronDevice(load_neuron_config(path)).build(duration=1e-9)
    assert _recorded(run.sim) == list(FORCE)


def test_the_reservoir_takes_the_force_from_toml(tmp_path):
    from skygas.reservoir.config import load_reservoir_config
    from skygas.reservoir.device import ReservoirDevice

    path = tmp_path / "c.toml"
    path.write_text(FORCES_TOML)
    sim = ReservoirDevice(load_reservoir_config(path)).simulation(seed=1)
    assert _recorded(sim) == list(FORCE)
