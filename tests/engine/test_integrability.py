"""The engine refuses what it cannot integrate, from plain Python as from the command line.

A drive that moves a free skyrmion more than a diameter per step, a run in which the walls undo
more than 10 % of the skyrmion-steps (the skyrmions then sit frozen at the wall), and a run
that would last days (seconds given where nanoseconds were meant) are each one InputError,
naming the term or the duration and its value.
"""

from __future__ import annotations

import pytest

from skygas.core import estimates
from skygas.core.errors import InputError
from skygas.engine import Simulation
from skygas.engine.simulation import MAX_STEP_DIAMETERS, MAX_UNDONE_SHARE
from skygas.physics.geometry import disk


def _one(v: float = 0.0, **kw) -> Simulation:
    sim = Simulation(
        disk(diameter=500e-9), "S2", temperature=300.0, seed=1, drift_velocity=(v, 0.0), **kw
    )
    sim.add_skyrmions([(0.0, 0.0)])
    return sim


def _per_step(sim: Simulation, v: float) -> float:
    """Diameters a free skyrmion drifts in one step at |v_s| = v, from the Thiele mobility:
    |v| = |v_s| √((a b + g²)² + (g (b − a))²) / (a² + g²) (docs/physics.md §1)."""
    t = sim.thiele
    a, g, b = t.friction, t.gyrocoupling, t.eta * t.dissipation * t.k
    speed = v * ((a * b + g * g) ** 2 + (g * (b - a)) ** 2) ** 0.5 / (a * a + g * g)
    return speed * sim.time_step / t.skyrmion_diameter


def test_a_drift_of_several_diameters_per_step_is_refused_before_any_step():
    sim = _one(3000.0)  # the case: 8.7 diameters per step
    assert _per_step(sim, 3000.0) > MAX_STEP_DIAMETERS
    with pytest.raises(InputError) as err:
        sim.run(1e-6)
    assert err.value.field == "drift_velocity" and err.value.value == [3000.0, 0.0]
    assert f"it moves {_per_step(sim, 3000.0):.3g} in one step" in str(err.value)
    assert sim.step == 0


def test_a_current_density_given_as_a_velocity_is_refused():
    sim = _one(3.8e11)
    with pytest.raises(InputError, match="drift_velocity"):
        sim.run(1e-6)


def test_a_drive_the_walls_cannot_hold_is_refused_once_judged():
    sim = _one(300.0)  # 0.87 diameters per step: integrable, but pushes through the wall
    assert _per_step(sim, 300.0) < MAX_STEP_DIAMETERS
    with pytest.raises(InputError) as err:
        sim.run(4e-6)
    assert err.value.field == "drift_velocity"
    assert sim.wall_escapes > MAX_UNDONE_SHARE * sim.skyrmion_steps
    assert "would have carried a skyrmion through a wall" in str(err.value)


def test_a_gentle_drift_runs_with_thermal_motion():
    sim = _one(10.0)
    sim.run(2e-6)
    assert sim.wall_escapes <= MAX_UNDONE_SHARE * sim.skyrmion_steps
    assert sim.time == pytest.approx(2e-6, abs=sim.time_step)


def test_seconds_for_nanoseconds_is_refused_with_the_estimate():
    sim = _one()
    with pytest.raises(InputError) as err:
        sim.run(50)
    text = str(err.value)
    assert err.value.field == "duration" and "did you mean 50e-9?" in text
    steps = round(50 / sim.time_step)
    assert f"{steps:.3g} steps" in text
    assert sim.step == 0


def test_a_long_run_is_announced_before_it_starts(monkeypatch, capsys):
    monkeypatch.setattr(estimates, "ANNOUNCE_SECONDS", 0.0)
    sim = _one()
    sim.run(1e-8)
    assert capsys.readouterr().err.startswith("skygas: estimate: ")


def test_inside_a_devices_limits_the_engine_does_not_check_again(capsys, monkeypatch):
    monkeypatch.setattr(estimates, "ANNOUNCE_SECONDS", 0.0)
    sim = _one()
    with estimates.run_limits():
        sim.run(1e-8)
    assert capsys.readouterr().err == ""
