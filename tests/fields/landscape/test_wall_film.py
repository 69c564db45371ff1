"""The wall law as the missing film's field (skygas.fields.landscape.wall_film).

Against the law it is built from: a straight edge gives the law's own energy, a convex corner
the two edges' energies less their shared quadrant, and the engine's force near a straight
wall is the law's.
"""

from __future__ import annotations

import numpy as np
import pytest

from skygas.fields.landscape import wall_film as wf

#: A law held at F0 below W0, then exponential with decay length LAM (pN, nm), cut at 8 LAM + W0.
F0, W0, LAM = 3.0, 10.0, 4.0
CUTOFF = W0 + 8 * LAM
SPACING = 1.0


def _table(step: float = 0.05):
    w = np.arange(0.0, CUTOFF + step, step)
    return np.where(w < W0, F0, F0 * np.exp(-(w - W0) / LAM)), step


def _exact_energy(w):
    """∫_w^cutoff F of the tapered law (the definition), by fine quadrature."""
    values, step = _table()
    law = wf.tapered_law(values, step, CUTOFF)
    s = np.linspace(w, CUTOFF, 20001)
    return np.trapezoid(law(s), s)


def _square(side: float):
    """Wall distance [nm] on a grid covering a square film of ``side`` plus the law's reach."""
    margin = CUTOFF + 4 * SPACING
    x = np.arange(-margin, side + margin + SPACING / 2, SPACING)
    xx, yy = np.meshgrid(x, x)
    inside = np.minimum(np.minimum(xx, side - xx), np.minimum(yy, side - yy))
    outside = -np.hypot(
        np.clip(-xx, 0, None) + np.clip(xx - side, 0, None),
        np.clip(-yy, 0, None) + np.clip(yy - side, 0, None),
    )
    return x, np.where(inside > 0, inside, np.minimum(outside, inside))


@pytest.fixture(scope="module")
def square():
    x, distance = _square(200.0)
    values, step = _table()
    film = wf.WallFilm(distance, SPACING, values, step, CUTOFF, [0.0, 2.0])
    return x, film


def test_straight_edge_gives_the_law(square):
    """Mid-way along an edge of a large square, U is the law's energy (within 1 %)."""
    x, film = square
    mid = int(np.argmin(np.abs(x - 100.0)))
    for w in (W0 + 2, W0 + 5, W0 + 10, W0 + 20):
        i = int(np.argmin(np.abs(x - w)))
        assert film.energies[0][mid, i] == pytest.approx(_exact_energy(x[i]), rel=1e-2)


def test_eroded_film_is_the_law_closer(square):
    """The film eroded by δ gives the law at w − δ: a breathing skyrmion's gap."""
    x, film = square
    mid = int(np.argmin(np.abs(x - 100.0)))
    for w in (W0 + 5, W0 + 10):
        i = int(np.argmin(np.abs(x - w)))
        assert film.energies[1][mid, i] == pytest.approx(_exact_energy(x[i] - 2.0), rel=1e-2)


def test_corner_is_two_edges_less_their_quadrant(square):
    """Near a corner U lies between the larger edge energy and the sum of both."""
    x, film = square
    for a, b in ((W0 + 3, W0 + 6), (W0 + 4, W0 + 4)):
        i = int(np.argmin(np.abs(x - a)))
        j = int(np.argmin(np.abs(x - b)))
        ua, ub = _exact_energy(x[i]), _exact_energy(x[j])
        u = film.energies[0][j, i]
        assert max(ua, ub) * 1.01 < u < (ua + ub) * 1.01
        # the quadrant they share is far smaller than either edge's part
        assert (ua + ub - u) < 0.2 * min(ua, ub)


def test_catmull_rom_weights_reproduce_quadratics():
    """The layers' weights are exact for a quadratic in δ (value, slope and curvature)."""
    q = np.polynomial.Polynomial([0.3, -1.2, 0.7])
    nodes = q(np.arange(-1.0, 3.0))
    for t in (0.0, 0.3, 0.77):
        value, slope, curve = (np.array(w) for w in wf.catmull_rom(t))
        assert value @ nodes == pytest.approx(q(t), abs=1e-12)
        assert slope @ nodes == pytest.approx(q.deriv()(t), abs=1e-12)
        assert curve @ nodes == pytest.approx(q.deriv(2)(t), abs=1e-12)


def test_layer_deltas_span_the_radius_range():
    """One layer beyond each end of s_w·[−shrink, growth], evenly spaced."""
    deltas = wf.layer_deltas(0.8, 2.0, 5.0, 0.5)
    step = np.diff(deltas)
    assert np.allclose(step, step[0]) and step[0] <= 0.5
    assert deltas[1] == pytest.approx(-0.8 * 5.0) and deltas[-2] == pytest.approx(0.8 * 2.0)
    assert wf.layer_deltas(0.0, 2.0, 5.0, 0.5).tolist() == [0.0]
