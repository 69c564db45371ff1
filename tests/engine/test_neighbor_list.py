"""The Verlet neighbour list never misses an interacting pair, and the SIMD logarithm behind the
Gaussian noise is as accurate as libm's."""

from __future__ import annotations

import sys
from pathlib import Path

import numba
import numpy as np
import pytest

from skygas.engine import Simulation
from skygas.engine._rng import _log
from skygas.engine.neighbors import build_neighbor_list
from skygas.engine.stages import BRANCH_FREE_ENTRIES
from skygas.physics.geometry import _random_positions_nm, disk

# the benchmarks' pair-pass kernel (benchmarks/pair_pass.py), checked here against a direct sum
sys.path.insert(0, str(Path(__file__).parents[2] / "benchmarks"))
from pair_pass import repeated_pair_pass  # noqa: E402


def _store(sim: Simulation):
    return sim.state.arrays_nm()


def _gas(exact_list: bool) -> Simulation:
    """A dense gas in a disk at 300 K, driven by a uniform current (the drifting skyrmions get
    margins wider than the base half-skin). The drift is gentle enough that the skyrmions do
    not pile into the wall: a step undone at the wall is a discontinuity that would amplify
    rounding differences between the two runs. ``exact_list`` shrinks every margin to zero:
    the list is then rebuilt before every force evaluation and holds exactly the pairs inside
    the cutoff."""
    sim = Simulation(
        disk(diameter=800e-9),
        "S2",
        temperature=300.0,
        seed=5,
        drift_velocity=(8.0, 0.0),
        capacity=64,
    )
    rng = np.random.default_rng(3)
    d_sk = sim.thiele.skyrmion_diameter_internal
    sim.state.insert_nm(_random_positions_nm(sim.outline, 40, 1.3 * d_sk, 0.7 * d_sk, rng))
    if exact_list:
        sim.neighbor_cells = sim.neighbor_cells._replace(skin=0.0, margin_steps=0.0, margin_max=0.0)
    return sim


def test_list_with_margins_gives_the_same_trajectories_as_an_exact_list():
    fast, exact = _gas(False), _gas(True)
    cells = fast.neighbor_cells
    assert cells.margin_max > 0.5 * cells.skin  # velocity margins are on
    for sim in (fast, exact):
        sim.run(300 * sim.time_step)
    # Same noise (keyed on ids) and same forces: only the order of the pair sums may differ,
    # so positions agree to rounding (1e-12 nm seen). A missed pair would move a skyrmion by
    # ≳ 1e-3 nm.
    assert np.abs(_store(fast).x - _store(exact).x).max() < 1e-7
    assert np.abs(_store(fast).y - _store(exact).y).max() < 1e-7
    assert fast.pair_evaluations == exact.pair_evaluations
    # the margins did their job: far fewer builds than the one-per-evaluation reference
    assert exact.neighbor_rebuilds >= 2 * 300
    assert fast.neighbor_rebuilds < exact.neighbor_rebuilds / 10


def test_skipping_the_field_lookup_far_from_the_walls_changes_nothing():
    """With a uniform drift, a skyrmion certain to stay beyond the wall-force cutoff while the
    neighbour list is valid skips its grid lookup (skygas.engine.stages.interior_floor). A run
    that looks every field up (the same zero drift, given as a grid) must be bit-identical."""
    runs = []
    for grid_drift in (False, True):
        # the wall-force cutoff is ~256 nm: a 700 nm disk has an interior beyond it
        sim = Simulation(disk(diameter=1400e-9), "S2", temperature=300.0, seed=9, capacity=64)
        rng = np.random.default_rng(4)
        d_sk = sim.thiele.skyrmion_diameter_internal
        sim.state.insert_nm(_random_positions_nm(sim.outline, 60, 1.3 * d_sk, 0.3 * d_sk, rng))
        if grid_drift:
            shape = (sim.wall_field.grid.ny, sim.wall_field.grid.nx)
            sim.set_drift_field(np.zeros(shape), np.zeros(shape))
        sim.run(3000 * sim.time_step, record_interval=100 * sim.time_step)
        runs.append(sim)
    skip, lookup = runs
    assert np.array_equal(_store(skip).x, _store(lookup).x)
    assert np.array_equal(_store(skip).y, _store(lookup).y)
    assert skip.wall_escapes == lookup.wall_escapes
    # both paths were taken: skyrmions within the wall cutoff, and far inside
    ds = skip.trajectories()
    r = np.hypot(ds.x.values, ds.y.values).ravel() * 1e9
    r = r[np.isfinite(r)]
    wall_distance = 700.0 - r
    cutoff = skip.force_terms.wall.cutoff
    assert (wall_distance < cutoff).mean() > 0.1
    assert (wall_distance > cutoff + 3 * skip.neighbor_cells.margin_max).mean() > 0.2


@pytest.mark.parametrize("n", [60, 1000])
def test_pair_forces_equal_a_direct_sum_over_all_pairs(n):
    """The kernel's pair forces (neighbour list, half shell, table) against a NumPy sum over
    all N(N−1)/2 pairs with the same table. 1 000 skyrmions make a list longer than
    BRANCH_FREE_ENTRIES, so both forms of the pair loop are checked."""
    radius = 512e-9 * np.sqrt(n / 45)  # half-full chamber density, as in the benchmark
    sim = Simulation(disk(diameter=2 * radius), "S2", temperature=300.0, seed=1, capacity=n)
    d_sk = sim.thiele.skyrmion_diameter_internal
    sim.state.insert_nm(
        _random_positions_nm(sim.outline, n, 1.2 * d_sk, 0.6 * d_sk, np.random.default_rng(n))
    )
    fx, fy, evaluated = repeated_pair_pass(sim, 1)
    table = sim.forces.pair
    x, y = _store(sim).x, _store(sim).y
    dx = x[:, None] - x[None, :]
    dy = y[:, None] - y[None, :]
    r2 = dx * dx + dy * dy
    inside = (r2 < table.cutoff**2) & ~np.eye(n, dtype=bool)
    f = np.where(
        inside, np.interp(r2 / table.spacing, np.arange(len(table.values)), table.values), 0.0
    )  # |F|/r
    assert evaluated == inside.sum() // 2
    scale = np.abs(f * np.hypot(dx, dy)).max()
    assert np.abs(fx - (f * dx).sum(axis=1)).max() < 1e-12 * n * scale
    assert np.abs(fy - (f * dy).sum(axis=1)).max() < 1e-12 * n * scale
    if n == 1000:
        assert evaluated > BRANCH_FREE_ENTRIES  # the list holds at least the pairs


def test_list_build_holds_exactly_the_pairs_within_their_margins():
    """The cell-list build against a brute-force scan over all pairs, with random margins s_i:
    the pair (i, j) is listed once, under the owner met first, iff |x_i − x_j| <
    cutoff + s_i + s_j. A list array that is too small is reported (−1), not overrun."""
    n = 400
    sim = Simulation(
        disk(diameter=1024e-9 * np.sqrt(n / 45)), "S2", temperature=300.0, seed=1, capacity=n
    )
    d_sk = sim.thiele.skyrmion_diameter_internal
    sim.state.insert_nm(
        _random_positions_nm(sim.outline, n, 1.2 * d_sk, 0.6 * d_sk, np.random.default_rng(4))
    )
    cells, cutoff = sim.neighbor_cells, sim.force_terms.pair.cutoff
    margin = np.random.default_rng(5).uniform(0.0, cells.margin_max, n)
    work = (
        np.empty(cells.ncx * cells.ncy, np.int64),
        np.empty(n, np.int64),
        np.empty(n, np.int64),
        np.empty(n + 1, np.int64),
    )
    store = _store(sim)
    args = (store.x, store.y, store.alive, margin, cells, cutoff, *work)
    assert build_neighbor_list(*args, np.full(100, -7, np.int64)) == -1
    pair_j = np.empty(64 * n, np.int64)
    n_owners = build_neighbor_list(*args, pair_j)
    owner, start = work[2], work[3]
    listed = [
        tuple(sorted((owner[e], j)))
        for e in range(n_owners)
        for j in pair_j[start[e] : start[e + 1]]
    ]
    reach = cutoff + margin[:, None] + margin[None, :]
    r = np.hypot(store.x[:, None] - store.x[None, :], store.y[:, None] - store.y[None, :])
    expected = {(i, j) for i, j in zip(*np.nonzero(np.triu(r < reach, k=1)), strict=True)}
    assert len(listed) == len(set(listed)) == len(expected) > 2 * n
    assert set(listed) == expected


def test_simd_logarithm_is_within_one_ulp_of_libm():
    @numba.njit
    def logs(w):
        out = np.empty_like(w)
        for i in range(w.shape[0]):
            out[i] = _log(w[i])
        return out

    rng = np.random.default_rng(0)
    # the polar method's arguments: (0, 1), down to 2⁻⁶² (its smallest), and near 1 and √½
    w = np.concatenate(
        [
            rng.random(200_000),
            2.0 ** rng.uniform(-62, 0, 200_000),
            1 - rng.random(10_000) * 1e-6,
            np.sqrt(0.5) * (1 + rng.normal(0, 1e-9, 1000)),
            [2.0**-62, 0.5, 1 - 2**-53],
        ]
    )
    ref = np.log(w)
    ulps = np.abs(logs(w) - ref) / np.spacing(np.abs(ref))
    assert ulps.max() <= 1.0
