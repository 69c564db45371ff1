"""A smooth repulsive potential fitted to inverted points, and its force as an engine table.

Boltzmann inversion gives a potential V [k_BT] at sampled distances, noisy, and only where the
data reach. Differentiating those points would amplify the noise, so V is fitted with the
positive, decaying form

    V(r) = k_BT exp(c₀ + c₁ r + c₂ r²)

(weighted least squares on ln V where V is clearly positive), whose force
F(r) = −dV/dr = −(c₁ + 2c₂ r) V(r) is smooth and, where c₁ + 2c₂r < 0, repulsive. The engine's
tables (:class:`~skygas.physics.materials.ForceTableSpec`) hold |F| ≥ 0 [N] on increasing
distances [m]; :func:`force_table` samples the fit from the closest sampled distance to where
the force has fallen below 10⁻³ of its value there (the engine holds the first value below the
table and sets the force to zero beyond its end).

How well the points fix the force: :func:`coefficient_covariance` is the covariance of the
quadratic's coefficients (the points' errors taken as their standard errors, also where the fit
fell back to a line), and :func:`force_error` carries it to F(r) to first order.
"""

from __future__ import annotations

import numpy as np

#: Points of a force table.
TABLE_POINTS = 24
#: The table ends where the force has fallen to this fraction of its value at the first point.
TABLE_TAIL = 1e-3
#: Points with V below this [k_BT] are left out of the fit (ln V is noise there).
FIT_FLOOR = 0.05


def fit_exp_quadratic(r: np.ndarray, v: np.ndarray, err: np.ndarray) -> np.ndarray | None:
    """(c₀, c₁, c₂) of ln V = c₀ + c₁ r + c₂ r² (r in the units given), or None if unfittable.

    Weights 1/σ(ln V)² = (V/σ_V)²; points with V ≤ :data:`FIT_FLOOR` or no finite error are
    left out; a line (c₂ = 0) when fewer than five points remain or the quadratic curves
    upwards (c₂ > 0, a V that would grow again beyond the data).
    """
    r, v, err = _selected(r, v, err)
    if len(r) < 3:
        return None
    w = v / err
    coef = np.polyfit(r, np.log(v), 2, w=w) if len(r) >= 5 else None
    if coef is None or coef[0] > 0:
        # a line when ln V curves upwards: V would grow again beyond the data
        coef = np.polyfit(r, np.log(v), 1, w=w)
    return np.concatenate([np.zeros(3 - len(coef)), coef])[::-1]


def first_run(ok: np.ndarray) -> np.ndarray:
    """The first run of consecutive True in ``ok`` (all False if there is none).

    The distances a law is fitted over: from the first usable bin to the first unusable one
    after it (bins beyond a gap would fit a range the data do not join up).
    """
    ok = np.asarray(ok, bool)
    out = np.zeros(len(ok), bool)
    start = np.flatnonzero(ok)
    if len(start):
        gap = np.flatnonzero(~ok[start[0] :])
        out[start[0] : start[0] + (gap[0] if len(gap) else len(ok))] = True
    return out


def _selected(r, v, err):
    """The points the fit uses: finite, V above :data:`FIT_FLOOR`, a positive error."""
    r, v, err = (np.asarray(a, float) for a in (r, v, err))
    ok = np.isfinite(v) & np.isfinite(err) & (v > FIT_FLOOR) & (err > 0)
    return r[ok], v[ok], err[ok]


def coefficient_covariance(r, v, err) -> np.ndarray:
    """The 3×3 covariance of (c₀, c₁, c₂) of a weighted fit of ln V = c₀ + c₁r + c₂r² to the points.

    Weighted least squares on ln V with σ(ln V) = σ_V/V over the points
    :func:`fit_exp_quadratic` uses: cov = (Xᵀ Σ⁻¹ X)⁻¹, X = [1, r, r²]. Always the quadratic's,
    also where the fit fell back to a line: the line is a choice (no upward curvature), not
    something the points fix, and the curvature they leave free belongs in the error.
    """
    r, v, err = _selected(r, v, err)
    x = np.vander(r, 3, increasing=True)
    w = (v / err) ** 2
    return np.linalg.pinv(x.T @ (w[:, None] * x))


def force_error(coef: np.ndarray, cov: np.ndarray, r) -> np.ndarray:
    """The standard error of F(r) = −dV/dr of the fit, from the coefficients' covariance.

    To first order, σ_F² = J cov Jᵀ with J = ∂F/∂c = (F, F r − V, F r² − 2rV).
    """
    r = np.asarray(r, float)
    v, f = potential(coef, r), force(coef, r)
    jac = np.stack([f, f * r - v, f * r * r - 2 * r * v], axis=-1)
    return np.sqrt(np.einsum("...i,ij,...j->...", jac, cov, jac))


def potential(coef: np.ndarray, r) -> np.ndarray:
    """V(r) [k_BT] of the fit."""
    c0, c1, c2 = coef
    r = np.asarray(r, float)
    return np.exp(c0 + c1 * r + c2 * r * r)


def force(coef: np.ndarray, r) -> np.ndarray:
    """F(r) = −dV/dr [k_BT per unit of r] of the fit (positive: repulsive)."""
    c0, c1, c2 = coef
    return -(c1 + 2 * c2 * np.asarray(r, float)) * potential(coef, r)


def force_table(coef: np.ndarray, r_first: float, r_limit: float, kt: float, unit: float) -> dict:
    """The fit's |F| as a table: ``distance`` [m], ``force`` [N] (≥ 0, at least 4 points).

    From ``r_first`` to where F falls below :data:`TABLE_TAIL` of F(r_first) (at most
    ``r_limit``), r in units of ``unit`` [m]; ``kt`` [J]. Negative forces (an attraction the
    fit may show beyond the data) are set to 0: the engine's tables are repulsions.
    """
    grid = np.linspace(r_first, r_limit, 400)
    f = force(coef, grid)
    top = f[0] if f[0] > 0 else np.max(f)
    below = np.flatnonzero(f < TABLE_TAIL * max(top, 1e-300))
    end = grid[below[0]] if len(below) and below[0] > 3 else r_limit
    r = np.linspace(r_first, end, TABLE_POINTS)
    return {
        "distance": (r * unit).tolist(),
        "force": np.maximum(force(coef, r) * kt / unit, 0.0).tolist(),
    }
