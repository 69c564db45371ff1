"""``Simulation.run`` with a record interval: a frame at t = 0, frames on the interval's
multiples, and the end exactly at the duration asked for."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from skygas.core.errors import InputError
from skygas.engine import Simulation
from skygas.physics.geometry import disk


def _sim(**kw) -> Simulation:
    sim = Simulation(disk(diameter=600e-9), "S2", temperature=300.0, seed=2, **kw)
    sim.add_random(4)
    return sim


def test_a_chosen_step_is_fitted_to_the_record_interval_with_a_warning():
    sim = _sim()
    suggested = sim.time_step
    assert not float(1e-9 / suggested).is_integer()  # the case of the issue: 1.001 ns frames
    with pytest.warns(UserWarning, match="time step shortened"):
        sim.run(50e-9, record_interval=1e-9)
    # the longest step up to the suggested one that divides the interval
    assert sim.time_step <= suggested
    assert 1e-9 / sim.time_step == pytest.approx(math.ceil(1e-9 / suggested), abs=1e-6)
    ds = sim.trajectories()
    np.testing.assert_allclose(ds.time.values, np.arange(51) * 1e-9, rtol=1e-12, atol=0)
    assert sim.time == pytest.approx(50e-9, rel=1e-12)


def test_the_first_frame_is_the_state_at_t0_and_pieces_do_not_repeat_frames():
    sim = _sim(step_interval=1e-9)
    _, start = sim.positions()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the step already divides the interval: no warning
        sim.run(5e-9, record_interval=1e-9)
        sim.run(5e-9, record_interval=1e-9)
    ds = sim.trajectories()
    np.testing.assert_allclose(ds.time.values, np.arange(11) * 1e-9, rtol=1e-12, atol=0)
    first = np.column_stack([ds.x.values[0], ds.y.values[0]])
    np.testing.assert_array_equal(first, start)  # exactly the placed positions
    _, now = sim.positions()
    np.testing.assert_array_equal(np.column_stack([ds.x.values[-1], ds.y.values[-1]]), now)


def test_a_run_cut_in_pieces_records_what_one_run_records():
    one = _sim(step_interval=1e-9)
    one.run(6e-9, record_interval=1e-9)
    cut = _sim(step_interval=1e-9)
    for _ in range(3):
        cut.run(2e-9, record_interval=1e-9)
    a, b = one.trajectories(), cut.trajectories()
    np.testing.assert_array_equal(a.time.values, b.time.values)
    np.testing.assert_array_equal(a.x.values, b.x.values)


def test_an_explicit_step_that_does_not_divide_the_interval_is_refused():
    sim = _sim(time_step=3e-12)
    with pytest.raises(InputError) as err:
        sim.run(10e-9, record_interval=1e-9)
    assert err.value.field == "record_interval"
    assert sim.time_step == 3e-12 and sim.step == 0  # nothing changed, nothing run


def test_a_duration_that_is_not_whole_steps_is_refused_when_recording():
    sim = _sim(time_step=1e-11)
    with pytest.raises(InputError) as err:
        sim.run(10.005e-9, record_interval=1e-9)
    assert err.value.field == "duration"
    assert sim.step == 0


def test_a_run_resumed_from_its_state_continues_the_same_frames():
    first = _sim(step_interval=1e-9)
    first.run(3e-9, record_interval=1e-9)
    resumed = Simulation(disk(diameter=600e-9), "S2", temperature=300.0, seed=2, step_interval=1e-9)
    resumed.load_state_dict(first.state_dict())
    first.run(3e-9, record_interval=1e-9)
    resumed.run(3e-9, record_interval=1e-9)
    np.testing.assert_array_equal(first.trajectories().x.values, resumed.trajectories().x.values)
    assert len(resumed.trajectories().time) == 7


def test_a_burn_in_then_a_recorded_run_refits_the_chosen_step():
    """``sim.run(1 µs)`` then ``sim.run(…, record_interval=…)``: the step the library chose is
    re-chosen to divide the interval, the clock moves on by less than one new step, and the
    frames fall on the interval's multiples."""
    sim = _sim()
    suggested = sim.time_step
    sim.run(1e-6)
    burned = sim.time
    with pytest.warns(UserWarning, match="time step shortened"):
        sim.run(200e-9, record_interval=10e-9)
    assert sim.time_step <= suggested
    assert 10e-9 / sim.time_step == pytest.approx(round(10e-9 / sim.time_step), abs=1e-6)
    ds = sim.trajectories()
    frames = ds.time.values / 10e-9
    np.testing.assert_allclose(frames, np.round(frames), atol=1e-6)
    assert frames[0] * 10e-9 >= burned
    assert sim.time == pytest.approx(burned + 200e-9, abs=sim.time_step)


def test_the_refitted_run_diffuses_as_the_fluctuation_dissipation_theorem_says():
    """After the refit the noise goes on with the new step: free skyrmions spread with
    ⟨Δr²⟩ = 4 D Δt per frame, D = k_B T α𝒟 / ((α𝒟)² + G²) of the Thiele equation."""
    sim = Simulation(disk(diameter=4e-6), "S2", temperature=300.0, seed=5)
    grid = (np.arange(8) - 3.5) * 300e-9  # 8 × 8 skyrmions 300 nm apart, 0.9 µm off the wall
    sim.add_skyrmions(np.array([(x, y) for x in grid for y in grid]))
    sim.run(0.2e-6)
    with pytest.warns(UserWarning, match="time step shortened"):
        sim.run(2e-6, record_interval=0.1e-6)
    ds = sim.trajectories()
    dr2 = np.diff(ds.x.values, axis=0) ** 2 + np.diff(ds.y.values, axis=0) ** 2
    expected = 4 * sim.thiele.diffusion_constant(300.0) * 0.1e-6
    # 64 walks × 20 frames: Δr² of a 2-D Gaussian step has its mean as standard deviation, so
    # the mean of 1280 is known to 1/√1280 = 2.8 %; allowed: 4 of those
    assert float(np.mean(dr2)) == pytest.approx(expected, rel=4 / np.sqrt(dr2.size))
