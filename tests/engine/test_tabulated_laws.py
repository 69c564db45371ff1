"""Tabulated force laws of a calibrated model (docs/physics.md §2, "Tabulated laws and the edge
stray field"): the PCHIP law, its extrapolation, its tabulation by ForceModel, and which law a
run uses."""

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator
from tests.engine.calibrated_model import calibrated_data, calibrated_material

from skygas.core.errors import InputError
from skygas.engine import ForceModel, Simulation
from skygas.engine.force_model import resolve_law_names
from skygas.physics.forces import (
    DEFAULT_CUTOFF_FRACTION,
    paper_pair_force,
    paper_wall_force,
    tabulated_force,
    tabulated_law,
)
from skygas.physics.geometry import disk
from skygas.physics.materials import Material, derive_thiele, preset

D_SK = 38.2e-9  # [m]
F0 = 1.44e-12  # [N]
# an irregular table: a rise, a plateau, a fall (PCHIP keeps each interval monotone)
DIST = np.array([10.0, 14.0, 20.0, 31.0, 45.0, 70.0, 90.0]) * 1e-9
FORCE = np.array([2.0, 3.5, 3.5, 1.2, 0.4, 0.05, 0.01]) * 1e-12


def test_table_law_reproduces_its_nodes_and_is_pchip_between():
    law = tabulated_law(DIST, FORCE, D_SK, F0)
    # at the nodes: the table itself (1e-12 relative: only the unit conversions round)
    np.testing.assert_allclose(law(DIST / D_SK) * F0, FORCE, rtol=1e-12)
    # between them: scipy's PCHIP of the same table (in any units; PCHIP is scale-free)
    r = np.linspace(DIST[0], DIST[-1], 1001)
    expected = PchipInterpolator(DIST, FORCE)(r)
    np.testing.assert_allclose(law(r / D_SK) * F0, expected, rtol=1e-10, atol=1e-28)
    # shape-preserving: within [min, max] of each interval, never negative
    assert np.all(law(r / D_SK) >= 0)


def test_table_law_is_constant_below_and_zero_beyond():
    law = tabulated_law(DIST, FORCE, D_SK, F0)
    below = np.array([0.0, 1e-9, 9.999e-9]) / D_SK
    np.testing.assert_allclose(law(below), FORCE[0] / F0, rtol=1e-12)
    beyond = np.array([90.0001e-9, 100e-9, 1e-6]) / D_SK
    assert np.all(law(beyond) == 0.0)
    # scalar input, and the one-call form
    assert float(tabulated_force(DIST[3] / D_SK, DIST, FORCE, D_SK, F0)) == pytest.approx(
        FORCE[3] / F0, rel=1e-12, abs=0
    )


def test_table_law_is_physical_whatever_d_sk_and_f0():
    """The table is in SI: another d_sk or F₀ changes the law's units, not the force."""
    r = np.linspace(0.0, 120e-9, 301)
    a = tabulated_law(DIST, FORCE, D_SK, F0)(r / D_SK) * F0
    b = tabulated_law(DIST, FORCE, 2.5 * D_SK, 0.3 * F0)(r / (2.5 * D_SK)) * (0.3 * F0)
    np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-30)


@pytest.mark.parametrize(
    "field, value",
    [
        ("distance", [1e-9, 2e-9, 3e-9]),  # fewer than 4 points
        ("distance", [1e-9, 3e-9, 2e-9, 4e-9]),  # not increasing
        ("distance", [-1e-9, 1e-9, 2e-9, 3e-9]),  # negative
        ("force", [1e-12, -1e-12, 1e-12, 0.0]),  # negative force
        ("force", [1e-12, 1e-12, 1e-12]),  # one per distance
        ("force", [1e-12, float("nan"), 1e-12, 0.0]),  # not finite
    ],
)
def test_bad_tables_are_refused_with_the_field_named(field, value):
    table = {
        "distance": [1e-9, 2e-9, 3e-9, 4e-9],
        "force": [3e-12, 2e-12, 1e-12, 0.0],
        field: value,
    }
    with pytest.raises(InputError) as err:
        from skygas.physics.materials import material_from_mapping

        material_from_mapping({**calibrated_data(), "pair_table": table})
    assert err.value.field.startswith("material.pair_table")
    assert "\n" not in str(err.value)


def test_force_model_of_tables_that_sample_the_paper_laws_matches_the_paper_laws():
    """Tables of the S2 laws at 400 points: the engine's forces within 1e-3 F₀ of the paper
    laws' (from 0.5 d_sk, where the laws hold) and equal cutoffs within one search step."""
    s2, model = preset("S2"), calibrated_material()
    thiele = derive_thiele(s2)
    paper = ForceModel.build(s2, thiele)
    table = ForceModel.build(model, derive_thiele(model))
    assert (table.pair_law, table.wall_law) == ("table", "table")
    assert (paper.pair_law, paper.wall_law) == ("paper", "paper")
    f0 = thiele.force_scale_internal
    d_sk = thiele.skyrmion_diameter_internal
    for name in ("pair", "wall"):
        a, b = getattr(paper, name), getattr(table, name)
        assert abs(b.cutoff - a.cutoff) <= 50 / 200_000 * d_sk
        r = np.linspace(0.5 * d_sk, 0.999 * min(a.cutoff, b.cutoff), 4001)
        assert np.max(np.abs(a(r) - b(r))) < 1e-3 * f0
    # and the exact laws (not only the engine's tables) agree as closely
    r = np.linspace(0.5, 5.0, 500)
    pair = tabulated_law(
        model.pair_table.distance,
        model.pair_table.force,
        thiele.skyrmion_diameter,
        thiele.force_scale,
    )
    wall = tabulated_law(
        model.wall_table.distance,
        model.wall_table.force,
        thiele.skyrmion_diameter,
        thiele.force_scale,
    )
    assert np.max(np.abs(pair(r) - paper_pair_force(r, *s2.pair_law))) < 1e-3
    assert np.max(np.abs(wall(r) - paper_wall_force(r, s2.wall_law))) < 1e-3


def test_a_table_that_ends_above_the_cutoff_fraction_is_cut_at_its_end():
    data = calibrated_data()
    end = 3.0 * D_SK  # the S2 wall law is 0.08 F0 there, far above 1e-3 F0
    keep = np.asarray(data["wall_table"]["distance"]) <= end
    data["wall_table"] = {k: list(np.asarray(v)[keep]) for k, v in data["wall_table"].items()}
    model = Material(**data)
    thiele = derive_thiele(model)
    forces = ForceModel.build(model, thiele)
    last = max(data["wall_table"]["distance"]) * 1e9
    step = 50.0 / 200_000 * thiele.skyrmion_diameter_internal  # the cutoff search's grid
    assert last < forces.wall.cutoff <= last + step
    assert forces.wall(last + 1.01 * step) == 0.0
    # the drop to 0 at the table's end is no stiffness: the limit is set by the laws' slopes
    assert forces.max_stiffness(0.5 * thiele.skyrmion_diameter_internal) < 1.0


def test_the_memo_key_holds_the_table_d_sk_and_f0():
    data = calibrated_data()
    thiele = derive_thiele(Material(**data))
    first = ForceModel.build(Material(**data), thiele)
    data["wall_table"] = {
        **data["wall_table"],
        "force": [2 * f for f in data["wall_table"]["force"]],
    }
    doubled = ForceModel.build(Material(**data), thiele)
    # twice the force (the tables' nodes differ: the doubled law reaches 1e-3 F0 later)
    r = np.linspace(0.0, 200.0, 101)
    assert doubled.wall.cutoff > first.wall.cutoff
    np.testing.assert_allclose(doubled.wall(r), 2 * first.wall(r), rtol=1e-4, atol=1e-6)
    from dataclasses import replace

    other = ForceModel.build(
        Material(**data),
        replace(thiele, force_scale=2 * thiele.force_scale, skyrmion_diameter=1.1e-7),
    )
    # the same physical table whatever F0 and d_sk: |F| at a distance is unchanged
    r = np.linspace(20.0, 150.0, 50)
    np.testing.assert_allclose(other.wall(r), doubled.wall(r), rtol=2e-3)


def test_law_names_resolve_to_the_materials_own():
    s2, model = preset("S2"), calibrated_material()
    assert resolve_law_names(s2) == ("paper", "paper")
    assert resolve_law_names(model) == ("table", "table")
    assert resolve_law_names(model, "lin-reichhardt", "paper") == ("lin-reichhardt", "paper")
    for pair, wall, field in (
        ("table", None, "forces.pair_law"),
        (None, "table", "forces.wall_law"),
        ("spline", None, "forces.pair_law"),
        (None, "lin-reichhardt", "forces.wall_law"),
    ):
        with pytest.raises(InputError) as err:
            resolve_law_names(s2, pair, wall)
        assert err.value.field == field
        assert "\n" not in str(err.value)
    with pytest.raises(InputError, match="has no pair_table"):
        Simulation(disk(diameter=400e-9), "S2", pair_law="table")


def test_recorded_law_names_are_the_resolved_ones():
    outline = disk(diameter=400e-9)
    s2 = Simulation(outline, "S2").parameters()
    assert (s2["pair_law"], s2["wall_law"], s2["edge_stray_field"]) == ("paper", "paper", False)
    model = calibrated_material(stray=False)
    p = Simulation(outline, model).parameters()
    assert (p["pair_law"], p["wall_law"]) == ("table", "table")
    p = Simulation(outline, model, pair_law="paper", wall_law="paper").parameters()
    assert (p["pair_law"], p["wall_law"]) == ("paper", "paper")
    assert DEFAULT_CUTOFF_FRACTION == p["cutoff_fraction"]
