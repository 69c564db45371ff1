"""The engine's public state API (``sim.state``) and checkpoints of the whole engine state."""

from __future__ import annotations

import numpy as np
import pytest

from skygas.core.errors import InputError
from skygas.engine import Simulation
from skygas.physics.geometry import chamber_with_conduits, disk


def _sim(seed=2) -> Simulation:
    sim = Simulation(disk(diameter=800e-9), "S2", temperature=300.0, seed=seed)
    sim.add_skyrmions([[-150e-9, 0.0], [0.0, 120e-9], [150e-9, -40e-9]])
    return sim


def test_view_reads_positions_in_metres_ordered_by_id_and_cannot_write():
    sim = _sim()
    np.testing.assert_array_equal(sim.state.ids, [0, 1, 2])
    np.testing.assert_allclose(
        sim.state.positions, [[-150e-9, 0.0], [0.0, 120e-9], [150e-9, -40e-9]], rtol=1e-15
    )
    arrays = sim.state.arrays_nm()
    assert arrays.alive.sum() == 3 and arrays.x[arrays.alive].max() == pytest.approx(150.0)
    for array in arrays:
        with pytest.raises(ValueError):
            array[0] = 1


def test_insert_issues_new_ids_and_is_site_clear_measures_the_clearance():
    sim = _sim()
    assert not sim.state.is_site_clear([0.0, 100e-9], 30e-9)  # 20 nm from skyrmion 1
    assert sim.state.is_site_clear([0.0, 100e-9], 15e-9)
    new = sim.state.insert([[0.0, -200e-9]])
    np.testing.assert_array_equal(new, [3])
    assert sim.count == 4 and sim.ids_issued == 4
    with pytest.raises(InputError, match="inside the device"):
        sim.state.insert([[1e-6, 0.0]], validate=True)


def test_annihilate_removes_by_id_and_records_time_place_and_reason():
    sim = _sim()
    sim.run(5 * sim.time_step)
    _, before = sim.positions()
    sim.state.annihilate([1], "test")
    np.testing.assert_array_equal(sim.state.ids, [0, 2])
    log = sim.annihilations.arrays()
    np.testing.assert_array_equal(log["skyrmion"], [1])
    assert log["time"][0] == sim.time and log["reason"][0] == "test"
    assert (log["x"][0], log["y"][0]) == (before[1, 0], before[1, 1])
    with pytest.raises(InputError, match="skyrmion id"):
        sim.state.annihilate([1], "again")


def test_resume_from_a_checkpoint_is_bit_identical_and_keeps_every_counter():
    """Half a run, a checkpoint into a new simulation, the other half: positions, frames,
    exits, annihilations and every counter equal those of the run left alone."""
    outline = chamber_with_conduits(chamber_diameter=400e-9)

    def build():
        sim = Simulation(outline, "S2", temperature=300.0, seed=8, drift_velocity=(15.0, 0.0))
        sim.add_skyrmions(
            [[-100e-9, 0.0], [0.0, 80e-9], [50e-9, -60e-9], [120e-9, 40e-9], [-60e-9, -90e-9]]
        )
        return sim

    def half_run(sim):
        sim.run(1500 * sim.time_step, record_interval=7 * sim.time_step)
        if sim.count:
            sim.state.annihilate(sim.state.ids[:1], "test")

    alone = build()
    half_run(alone)
    half_run(alone)
    first = build()
    half_run(first)
    resumed = build()
    resumed.load_state_dict(first.state_dict())
    half_run(resumed)
    assert len(alone.exits) > 0 and len(alone.annihilations) == 2 and alone.count > 0
    for name in ("step", "wall_escapes", "pair_evaluations", "neighbor_rebuilds", "ids_issued"):
        assert getattr(resumed, name) == getattr(alone, name), name
    for a, b in zip(alone.positions(), resumed.positions(), strict=True):
        np.testing.assert_array_equal(a, b)
    ta, tb = alone.trajectories(), resumed.trajectories()
    for var in ("x", "y", "time", "exit_time", "exit_skyrmion"):
        np.testing.assert_array_equal(ta[var].values, tb[var].values, err_msg=var)
    for key, column in alone.annihilations.arrays().items():
        np.testing.assert_array_equal(column, resumed.annihilations.arrays()[key])


def test_add_random_places_skyrmions_apart_from_each_other_the_present_and_the_walls():

    def build():
        return Simulation(disk(diameter=1200e-9), "S2", temperature=300.0, seed=4)

    sim = build()
    d = sim.thiele.skyrmion_diameter
    first = sim.add_random(10, 1.5)
    second = sim.add_random(10, 1.5)
    assert list(first) == list(range(10)) and list(second) == list(range(10, 20))
    _, pos = sim.positions()
    gaps = np.hypot(*(pos[:, None] - pos[None]).transpose(2, 0, 1))
    assert gaps[~np.eye(20, dtype=bool)].min() >= 1.5 * d * (1 - 1e-12)
    walls = sim.outline._wall_distance_nm(pos[:, 0] * 1e9, pos[:, 1] * 1e9)
    assert walls.min() >= 1.5 * d * 1e9 * (1 - 1e-12)
    again = build()
    again.add_random(10, 1.5)
    again.add_random(10, 1.5)
    np.testing.assert_array_equal(again.positions()[1], pos)  # reproducible from the seed
    with pytest.raises(InputError, match="fewer skyrmions"):
        build().add_random(10_000, 1.5)
    with pytest.raises(InputError, match="count"):
        build().add_random(-1)


def test_validate_positions_takes_metres():
    sim = Simulation(disk(diameter=400e-9), "S2", temperature=300.0, seed=1)
    sim.validate_positions([[0.0, 0.0], [100e-9, 0.0]])  # inside, apart: accepted
    with pytest.raises(InputError) as err:
        sim.validate_positions([[0.0, 0.0], [250e-9, 0.0]])  # the second outside
    assert err.value.field == "skyrmions[1]"
    with pytest.raises(InputError):
        sim.validate_positions([[0.0, 0.0], [1e-9, 0.0]])  # on top of each other


def test_an_operation_whose_schedule_does_not_move_forward_is_refused_by_name():
    """An operation may act now (next_step ≤ step), but one that asks for a past step for ever
    would hold the run: it is refused, named, instead of hanging."""

    class Stuck:
        name = "stuck-sensor"
        acted = 0

        def next_step(self, step):
            return step - 5

        def act(self, sim):
            self.acted += 1

    class Twice:  # acts twice at its step, then moves on: allowed
        name = "twice"
        acted = 0

        def next_step(self, step):
            return step if self.acted % 2 else step + 10

        def act(self, sim):
            self.acted += 1

    sim = Simulation(disk(diameter=800e-9), "S2", temperature=300.0, seed=1)
    twice = Twice()
    sim.operations.append(twice)
    sim.run(50 * sim.time_step)
    # twice at steps 10, 20, 30 and 40; once at 50, where the run ends
    assert sim.step == 50 and twice.acted == 9
    sim.operations.append(Stuck())
    with pytest.raises(InputError, match="stuck-sensor.*must move forward"):
        sim.run(10 * sim.time_step)
