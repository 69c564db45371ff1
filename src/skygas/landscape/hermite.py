"""Bicubic Hermite interpolation of an energy landscape sampled on a grid (compiled).

Each node (i, j) holds four numbers: U, h·∂U/∂x, h·∂U/∂y and h²·∂²U/∂x∂y (energies in pN·nm,
h the spacing in nm). Inside a cell, with fractional coordinates t, u ∈ [0, 1],

    U(t, u) = Σ_ab [U_ab V_a(t) V_b(u) + U^x_ab D_a(t) V_b(u) + U^y_ab V_a(t) D_b(u)
                    + U^xy_ab D_a(t) D_b(u)],

with the cubic Hermite basis V_0 = 2t³ − 3t² + 1, V_1 = −2t³ + 3t², D_0 = t³ − 2t² + t,
D_1 = t³ − t². The interpolant matches U and its first derivatives at every node, so it and its
gradient are continuous across cell edges (C¹): a skyrmion's force −∇U has no jumps, which the
Heun integrator's second order needs. The force the engine applies is the exact gradient of this
interpolant, so the work done along any closed path is zero to rounding.

Each cell's interpolant is stored as the 16 coefficients of its polynomial,
U(t, u) = Σ_ij α_ij tⁱ uʲ (:func:`cell_coefficients`, α = M F Mᵀ with F the corners' values and
derivatives and M the Hermite matrix), in float32, so the kernel reads one 64-byte cache line
per evaluation and evaluates the gradient by Horner's rule instead of combining sixteen basis
products. The coefficients are recomputed whenever the nodes change. An evaluation at 1 000
random points took 7-9 ns in a grid of 380² cells and 9 ns in one of 1 200² (27 ns with
float64 coefficients there, the page-table misses of a 184 MB array); float32 rounding moves
the interpolant by ~10⁻⁷ of its scale, far below the interpolation error above.

Interpolation error: for a smooth U, O(h⁴) in U and O(h³) in ∇U. Measured for a Gaussian well
of depth A and width σ at the default spacing h = d_sk/16 (2.39 nm for S2), as the largest error
over 20 000 random points within 5σ, relative to A (in U) and to the largest force A e^{-1/2}/σ
(in ∇U):

    σ = 2h:  8.9×10⁻⁴ and 4.9×10⁻³      σ = 8h (19 nm):  3.7×10⁻⁶ and 7.6×10⁻⁵
    σ = 4h:  5.4×10⁻⁵ and 6.2×10⁻⁴      σ = 16h (38 nm): 2.3×10⁻⁷ and 9.5×10⁻⁶

(each doubling of σ/h divides them by 16 and 8; ``tests/landscape/
test_force_and_interpolation.py`` checks these figures).
"""

from __future__ import annotations

import numba
import numpy as np

from skygas._field_lookup import _prefetch

#: The cubic Hermite matrix: the coefficients (a₀…a₃) of p(t) = Σ aᵢ tⁱ from
#: (p(0), p(1), p'(0), p'(1)).
HERMITE = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [-3.0, 3.0, -2.0, -1.0],
                    [2.0, -2.0, 1.0, 1.0]])


def cell_coefficients(nodes: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """The polynomial coefficients α[j, i, 4a + b] (of tᵃ uᵇ) of every cell (ny − 1, nx − 1,
    16) from the nodes (ny, nx, 4) = (U, h ∂U/∂x, h ∂U/∂y, h² ∂²U/∂x∂y)."""
    n00, n10 = nodes[:-1, :-1], nodes[:-1, 1:]   # corners (t, u) = (0, 0), (1, 0)
    n01, n11 = nodes[1:, :-1], nodes[1:, 1:]     # (0, 1), (1, 1)
    # F[a-row, b-column]: rows p(t=0), p(t=1), ∂t p(0), ∂t p(1); columns u = 0, 1, ∂u at 0, 1
    F = np.stack([
        np.stack([n00[..., 0], n01[..., 0], n00[..., 2], n01[..., 2]], axis=-1),
        np.stack([n10[..., 0], n11[..., 0], n10[..., 2], n11[..., 2]], axis=-1),
        np.stack([n00[..., 1], n01[..., 1], n00[..., 3], n01[..., 3]], axis=-1),
        np.stack([n10[..., 1], n11[..., 1], n10[..., 3], n11[..., 3]], axis=-1),
    ], axis=-2)
    alpha = np.einsum("ak,...kl,bl->...ab", HERMITE, F, HERMITE)
    shape = alpha.shape[:2] + (16,)
    if out is None:
        return np.ascontiguousarray(alpha.reshape(shape))
    out[...] = alpha.reshape(shape)
    return out


@numba.njit(inline="always")
def _cell(coefficients, fx, fy):
    """Cell (i, j) holding fractional node indices (fx, fy), clamped to the grid, and the
    fractions (t, u)."""
    ny, nx = coefficients.shape[0], coefficients.shape[1]  # cells
    fx = min(max(fx, 0.0), nx - 0.000001)
    fy = min(max(fy, 0.0), ny - 0.000001)
    i = np.int64(fx)
    j = np.int64(fy)
    return i, j, fx - i, fy - j


@numba.njit(inline="always")
def prefetch_cell(coefficients, fx, fy):
    """Start loading the cache line of the cell holding fractional node indices (fx, fy)
    (:func:`hermite_gradient` will read it)."""
    i, j, _, _ = _cell(coefficients, fx, fy)
    _prefetch(coefficients, (j * coefficients.shape[1] + i) * 16)


@numba.njit(inline="always")
def hermite_gradient(coefficients, fx, fy, inv_h):
    """(∂U/∂x, ∂U/∂y) [pN] of the interpolant at fractional node indices (fx, fy);
    ``inv_h`` = 1/h."""
    i, j, t, u = _cell(coefficients, fx, fy)
    c = coefficients[j, i]
    # P_a(u) = Σ_b α_ab uᵇ and its derivative, for each power a of t
    p1 = ((c[7] * u + c[6]) * u + c[5]) * u + c[4]
    p2 = ((c[11] * u + c[10]) * u + c[9]) * u + c[8]
    p3 = ((c[15] * u + c[14]) * u + c[13]) * u + c[12]
    d0 = (3.0 * c[3] * u + 2.0 * c[2]) * u + c[1]
    d1 = (3.0 * c[7] * u + 2.0 * c[6]) * u + c[5]
    d2 = (3.0 * c[11] * u + 2.0 * c[10]) * u + c[9]
    d3 = (3.0 * c[15] * u + 2.0 * c[14]) * u + c[13]
    gt = (3.0 * p3 * t + 2.0 * p2) * t + p1
    gu = ((d3 * t + d2) * t + d1) * t + d0
    return gt * inv_h, gu * inv_h


@numba.njit(inline="always")
def hermite_value(coefficients, fx, fy):
    """U [pN·nm] of the interpolant at fractional node indices (fx, fy)."""
    i, j, t, u = _cell(coefficients, fx, fy)
    c = coefficients[j, i]
    p = np.empty(4)
    for a in range(4):
        p[a] = ((c[4 * a + 3] * u + c[4 * a + 2]) * u + c[4 * a + 1]) * u + c[4 * a]
    return ((p[3] * t + p[2]) * t + p[1]) * t + p[0]


@numba.njit(cache=True)
def energy_and_gradient(coefficients, x0, y0, spacing, x, y, energy, grad_x, grad_y):
    """U [pN·nm] and ∇U [pN] of the interpolant at points (x, y) [nm] (vectorised, for
    analysis and tests; the engine calls :func:`hermite_gradient` inline)."""
    inv_h = 1.0 / spacing
    for k in range(x.shape[0]):
        fx = (x[k] - x0) * inv_h
        fy = (y[k] - y0) * inv_h
        energy[k] = hermite_value(coefficients, fx, fy)
        grad_x[k], grad_y[k] = hermite_gradient(coefficients, fx, fy, inv_h)
