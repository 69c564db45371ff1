"""The compiled annihilation rule against exact results: binomial survival of isolated
skyrmions, the compression χ of the reference formula, immediate collapse of close pairs and
of skyrmions at a wall."""

import math

import numpy as np
import pytest

from skygas.neuron._compiled import annihilation_check, total_rate
from skygas.neuron.annihilation import compression

SPACING = 10.0  # nm, grid of the (constant) wall-distance field
FAR_FROM_WALLS = 1e4  # nm


def _far_wall_field(extent_nm: float) -> tuple:
    """A wall-distance grid covering [−extent, extent]² that puts every wall far away."""
    n = int(2 * extent_nm / SPACING) + 3
    return np.full((n, n), FAR_FROM_WALLS), -extent_nm - SPACING, -extent_nm - SPACING, SPACING


def _check(
    x,
    y,
    *,
    base_rate,
    sensitivity=0.0,
    crowding=100.0,
    collapse=40.0,
    interval=1e-9,
    rng,
    wall=None,
):
    field, x0, y0, h = wall if wall is not None else _far_wall_field(np.abs([*x, *y]).max())
    alive = np.ones(len(x), np.bool_)
    victims = np.empty(len(x), np.int64)
    n = annihilation_check(
        np.asarray(x, float),
        np.asarray(y, float),
        alive,
        field,
        x0,
        y0,
        h,
        crowding,
        collapse,
        base_rate,
        sensitivity,
        interval,
        rng,
        -1.0,
        victims,
    )
    return victims[:n]


def test_isolated_skyrmions_die_with_the_exponential_probability():
    # 2000 skyrmions 200 nm apart (beyond r_c = 100 nm): each dies within Δt with probability
    # 1 − exp(−Γ0 Δt) = 0.3, independently, so the deaths are Binomial(2000, 0.3).
    side = 45
    gx, gy = np.meshgrid(np.arange(side) * 200.0, np.arange(side) * 200.0)
    x, y = gx.ravel()[:2000] - 4400, gy.ravel()[:2000] - 4400
    interval, p = 1e-9, 0.3
    rate = -math.log(1 - p) / interval
    deaths = len(
        _check(
            x, y, base_rate=rate, sensitivity=8.0, interval=interval, rng=np.random.default_rng(1)
        )
    )
    mean, sigma = 2000 * p, math.sqrt(2000 * p * (1 - p))
    assert abs(deaths - mean) < 4 * sigma


def test_total_rate_uses_the_reference_compression():
    rng = np.random.default_rng(3)
    # a random gas with no pair closer than the collapse distance (40 nm)
    pts = []
    while len(pts) < 60:
        p = rng.uniform(-400, 400, 2)
        if all(np.hypot(*(p - q)) > 45 for q in pts):
            pts.append(p)
    x, y = np.array(pts).T
    # every skyrmion 30 nm from a wall: wall term 1 − 2·30/100 = 0.4, no wall collapse (< 20)
    field, x0, y0, h = _far_wall_field(500.0)
    field = np.full_like(field, 30.0)
    total, candidates = total_rate(
        x, y, np.ones(len(x), np.bool_), field, x0, y0, h, 100.0, 40.0, 1e6, 8.0
    )
    chi = compression(x, y, np.full(len(x), 30.0), crowding_nm=100.0)
    assert candidates == 0
    assert chi.max() > 1.0  # crowded enough for the pair terms to matter
    assert total == pytest.approx(np.sum(1e6 * np.exp(8.0 * chi)), rel=1e-12)


def test_each_pair_closer_than_the_collapse_distance_loses_exactly_one_member():
    rng = np.random.default_rng(5)
    first = 0
    for _ in range(400):
        dead = _check([0.0, 20.0, 500.0], [0.0, 0.0, 0.0], base_rate=0.0, rng=rng)
        assert len(dead) == 1 and dead[0] in (0, 1)  # the far one never, one of the pair
        first += dead[0] == 0
    assert abs(first - 200) < 4 * math.sqrt(100)  # each member with probability ½


def test_a_skyrmion_within_half_the_collapse_distance_of_a_wall_collapses():
    field, x0, y0, h = _far_wall_field(200.0)
    gx = x0 + h * np.arange(field.shape[1])
    field = np.broadcast_to(np.clip(gx + 100.0, -50, None), field.shape).copy()  # wall at −100
    dead = _check(
        [-85.0, -70.0, 0.0],
        [0.0, 0.0, 0.0],
        base_rate=0.0,
        rng=np.random.default_rng(0),
        wall=(field, x0, y0, h),
    )
    assert dead.tolist() == [0]  # 15 nm < 20 nm from the wall; 30 nm is not
