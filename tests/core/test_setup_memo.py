"""Per-process re-use of geometry set-up (skygas.core.memo) changes no result, not even one bit.

The wall field, the current solution and the drift field's sampling are kept per process and
shared by later runs of the same device; the bucketed nearest-segment search replaced a
brute-force scan. Everything here is compared bit for bit against the uncached computation.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from skygas.core.memo import clear_memos, memo_stats, set_memo_enabled
from skygas.fields.current import solve_current
from skygas.fields.nearest_segment import nearest_segment, nearest_segment_brute
from skygas.fields.wall_field import Grid, WallField, _segments
from skygas.physics.geometry import chamber_with_conduits, rectangle
from skygas.reshuffler import ReshufflerRun, parse_reshuffler_config, summarize
from skygas.reshuffler.device import ReshufflerGeometry, drift_field_on_grid

SMALL = ReshufflerGeometry(chamber_diameter=500e-9)


@pytest.fixture
def no_memo():
    previous = set_memo_enabled(False)
    yield
    set_memo_enabled(previous)


@pytest.fixture(autouse=True)
def fresh_memos():
    clear_memos()
    yield
    clear_memos()


def counts(name: str) -> dict:
    """In-process hits, misses and entries of memo ``name`` (misses count disk loads too)."""
    stats = memo_stats()[name]
    return {k: stats[k] for k in ("hits", "misses", "entries")}


def uncached(build):
    previous = set_memo_enabled(False)
    try:
        return build()
    finally:
        set_memo_enabled(previous)


def assert_identical(a, b):
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray):
            assert x.dtype == y.dtype and np.array_equal(x, y, equal_nan=True), f.name
        elif f.name not in ("solve_seconds", "_outline"):
            assert x == y, f.name


# -- nearest wall point --------------------------------------------------------------------------
@pytest.mark.parametrize(
    "outline",
    [
        ReshufflerGeometry().device_outline(),
        SMALL.device_outline(),
        chamber_with_conduits(300e-9, 100e-9, 50e-9),
        rectangle(400e-9, 100e-9),
    ],
)
def test_bucketed_nearest_segment_equals_the_scan(outline):
    segs = _segments(outline.walls)
    x0, y0, x1, y1 = outline._bounds_nm
    rng = np.random.default_rng(3)
    gx, gy = np.meshgrid(np.arange(x0 - 10, x1 + 10, 3.7), np.arange(y0 - 10, y1 + 10, 3.7))
    # grid nodes, random points far outside, segment ends and midpoints (exact ties)
    px = np.concatenate(
        [
            gx.ravel(),
            rng.uniform(x0 - 900, x1 + 900, 5000),
            segs[:, 0],
            (segs[:, 0] + segs[:, 2]) / 2,
        ]
    )
    py = np.concatenate(
        [
            gy.ravel(),
            rng.uniform(y0 - 900, y1 + 900, 5000),
            segs[:, 1],
            (segs[:, 1] + segs[:, 3]) / 2,
        ]
    )
    for fast, slow in zip(
        nearest_segment(px, py, segs), nearest_segment_brute(px, py, segs), strict=True
    ):
        assert fast.dtype == slow.dtype and np.array_equal(fast, slow)


# -- wall field, current, drift field ------------------------------------------------------------
def test_wall_field_is_shared_and_identical():
    outline = SMALL.device_outline()
    fresh = uncached(lambda: WallField.build(outline, 2.4, 60.0))
    first = WallField.build(outline, 2.4, 60.0)
    again = WallField.build(SMALL.device_outline(), 2.4, 60.0)  # equal outline, new object
    assert again is first
    assert_identical(fresh, first)
    other = WallField.build(outline, 3.0, 60.0)  # another spacing is another field
    assert other.grid.spacing == 3.0 and other is not first
    assert counts("wall_field") == {"hits": 1, "misses": 2, "entries": 2}
    with pytest.raises(ValueError):
        first.wall_distance[0, 0] = 1.0  # shared arrays are read-only


@pytest.mark.parametrize(
    "kwargs",
    [
        {},
        {"conductor_thickness": 7e-9, "resistivity": 3e-7},
        {"source": "output", "sink": "input"},
        {"cell_size": 4e-9},
    ],
)
def test_current_solution_scaled_from_memo_is_identical(kwargs):
    chamber = SMALL.chamber()
    grid = Grid(-320.0, -300.0, 2.3, 280, 260)
    base = {"cell_size": 5e-9, **kwargs}
    solve_current(chamber, 1.0e11, cell_size=5e-9)  # another J (and maybe other ports) first
    for j in (1.7e11, -3.1e11):
        fresh = uncached(lambda j=j: solve_current(chamber, j, **base))
        memo = solve_current(SMALL.chamber(), j, **base)
        assert_identical(fresh, memo)
        for a, b in zip(fresh.sample(grid), memo.sample(grid), strict=True):
            assert np.array_equal(a, b)
    # the second J re-used the first's solve (and the very first call's, for the same key)
    same_key = kwargs in ({}, {"conductor_thickness": 7e-9, "resistivity": 3e-7})
    assert memo_stats()["current"]["hits"] == (2 if same_key else 1)


def test_solution_at_another_current_density_is_a_fresh_solve():
    chamber = SMALL.chamber()
    settings = {
        "cell_size": 5e-9,
        "conductor_thickness": 7e-9,
        "resistivity": 3e-7,
        "source": "output",
        "sink": "input",
    }
    solution = solve_current(chamber, 1.7e11, **settings)
    for j in (1.0, -2.9e11):
        assert_identical(
            solution.at_current_density(j),
            uncached(lambda j=j: solve_current(chamber, j, **settings)),
        )


def test_drift_field_from_memo_is_identical():
    grid = Grid(-400.0, -700.0, 2.4, 340, 590)
    for j in (1.2e11, 2.9e11):
        solution = solve_current(SMALL.chamber(), j, cell_size=5e-9)
        fresh = uncached(lambda s=solution: drift_field_on_grid(SMALL, s, grid, 1.3e-10))
        memo = drift_field_on_grid(SMALL, solution, grid, 1.3e-10)
        assert np.array_equal(fresh[0], memo[0]) and np.array_equal(fresh[1], memo[1])
    assert counts("drift_unit_sample") == {"hits": 1, "misses": 1, "entries": 1}


def test_drift_field_is_linear_in_the_current_density():
    """The memo scales one sampled field by ξJ: that equals sampling each J's own solution
    (to rounding), including J < 0."""
    grid = Grid(-400.0, -700.0, 2.4, 340, 590)
    gx, gy = grid.nodes()
    for j in (2.9e11, -1.2e11):
        solution = solve_current(SMALL.chamber(), j, cell_size=5e-9)
        vx, vy = drift_field_on_grid(SMALL, solution, grid, 1.3e-10)
        up = SMALL.chamber_of(gy) == 0
        cx, cy = SMALL.centres()["up"]
        jx, jy = solution.current_density_at(gx[up] * 1e-9 - cx, gy[up] * 1e-9 - cy)
        scale = 1.3e-10 * abs(j)
        np.testing.assert_allclose(vx[up], 1.3e-10 * jx, rtol=1e-12, atol=1e-12 * scale)
        np.testing.assert_allclose(vy[up], 1.3e-10 * jy, rtol=1e-12, atol=1e-12 * scale)


def test_force_tables_and_packed_wall_channels_are_shared_and_identical():
    from skygas.engine import ForceModel, Simulation
    from skygas.physics.materials import derive_thiele, load_material

    material = load_material("S2")
    thiele = derive_thiele(material, 2e-9)
    fresh = uncached(lambda: ForceModel.build(material, thiele))
    first, again = ForceModel.build(material, thiele), ForceModel.build(material, thiele)
    for table in ("pair", "wall"):
        a, b, c = (getattr(m, table) for m in (fresh, first, again))
        assert np.array_equal(a.values, b.values) and a.cutoff == b.cutoff
        assert b.values is not c.values and b.values.flags.writeable  # private copies
    assert counts("force_tables") == {"hits": 1, "misses": 1, "entries": 1}
    outline = SMALL.device_outline()
    sims = [
        uncached(lambda: Simulation(outline, "S2")),
        Simulation(outline, "S2"),
        Simulation(outline, "S2"),
    ]
    for sim in sims[1:]:
        fields = sim.force_terms.grid.fields
        assert np.array_equal(fields, sims[0].force_terms.grid.fields) and fields.flags.writeable
    assert sims[1].force_terms.grid.fields is not sims[2].force_terms.grid.fields
    assert memo_stats()["wall_channels"]["hits"] == 1


# -- a whole run ---------------------------------------------------------------------------------
def _summary(current_density: float) -> dict:
    config = parse_reshuffler_config(
        {
            "preset": "paper",
            "duration": 3e-7,
            "current_density": current_density,
            "seed": 5,
            "device": {"chamber_diameter": 5e-7},
            "current": {"cell_size": 5e-9},
            "output": {"trajectory_window": 0.0},
        }
    )
    run = ReshufflerRun.build(config)
    run.advance()
    summary = summarize(run).summary
    return {k: v for k, v in summary.items() if k != "wall_time_s"}


def test_reshuffler_runs_with_and_without_memo_are_identical():
    fresh = [uncached(lambda j=j: _summary(j)) for j in (1.2e11, 1.7e11)]
    memo = [_summary(j) for j in (1.2e11, 1.7e11)]
    assert memo == fresh
    stats = memo_stats()
    # one solve; re-used by the first run's J = 1 A/m² sample and by the second run
    assert stats["current"]["misses"] == 1 and stats["current"]["hits"] == 2
    assert stats["wall_field"]["misses"] == 1 and stats["wall_field"]["hits"] == 1
