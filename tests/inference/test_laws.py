"""The smooth pair and wall laws fitted to inverted points, and the error of their force.

The standard error that :func:`~skygas.inference.laws.force_error` gives is checked against the
scatter of the force over many refits of noisy points drawn about a known law (500 draws: the
scatter's own relative error is about 3 %, the tolerance 15 %). Where the fit is a line, the
error keeps the curvature the points leave free, so it bounds the line's scatter from above.
"""

from __future__ import annotations

import numpy as np

from skygas.inference import laws

#: ln V = c₀ + c₁ r + c₂ r² (r in nm): close to S2's pair potential in k_BT over 70–105 nm.
CURVED = np.array([4.867, -0.0311, -1.24e-4])
LINE = np.array([5.0, -0.05, 0.0])


def _refits(coef, points, rng):
    """Forces at 72, 87, 103 nm of 500 fits to noisy points about ``coef``, and their errors."""
    r = np.linspace(70.0, 105.0, points)
    v = laws.potential(coef, r)
    err = 0.01 * v + 0.01
    at = np.array([72.0, 87.0, 103.0])
    fits = [laws.fit_exp_quadratic(r, v + rng.normal(0.0, err), err) for _ in range(500)]
    predicted = laws.force_error(coef, laws.coefficient_covariance(r, v, err), at)
    return fits, np.array([laws.force(f, at) for f in fits]), laws.force(coef, at), predicted


def test_the_force_error_is_the_scatter_of_refits():
    fits, forces, true, predicted = _refits(CURVED, 8, np.random.default_rng(7))
    assert all(f[2] != 0 for f in fits)  # all quadratic, as the truth
    ratio = forces.std(axis=0, ddof=1) / predicted
    assert np.all((ratio > 0.85) & (ratio < 1.15)), ratio
    # and the fit is unbiased to well within its error
    assert np.all(np.abs(forces.mean(axis=0) - true) < 0.2 * predicted)


def test_a_line_fit_keeps_the_error_of_the_curvature_it_does_not_fix():
    """Four points make a line; its error is the quadratic's, above the line's own scatter."""
    fits, forces, true, predicted = _refits(LINE, 4, np.random.default_rng(8))
    assert all(f[2] == 0 for f in fits)
    scatter = forces.std(axis=0, ddof=1)
    assert np.all(scatter < 1.1 * predicted)
    assert np.all(np.abs(forces.mean(axis=0) - true) < 0.2 * predicted)


def test_a_law_of_its_own_only_where_g_fixes_the_force():
    """The iterations keep the material's law unless −ln g fixes the force to 10 % mid-range."""
    from skygas.inference import pair

    r = np.linspace(75.0, 100.0, 6)
    v = laws.potential(CURVED, r)
    precise = pair.initial_force_error(r, v, 0.02 * v)
    noisy = pair.initial_force_error(r, v, 0.3 * v)
    assert precise < pair.MAX_FORCE_ERROR < noisy
    assert pair.initial_force_error(r[:2], v[:2], 0.02 * v[:2]) is None  # too few distances
    rising = laws.potential(np.array([0.0, 0.02, -1e-4]), r)  # V grows with r: an attraction
    assert pair.initial_force_error(r, rising, 0.02 * rising) == np.inf
