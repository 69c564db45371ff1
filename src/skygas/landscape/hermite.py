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


@numba.njit(inline="always")
def _cell(nodes, fx, fy):
    """Lower-left node (i, j) of the cell holding fractional indices (fx, fy), clamped to the
    grid, and the fractions (t, u)."""
    ny, nx = nodes.shape[0], nodes.shape[1]
    fx = min(max(fx, 0.0), nx - 1.000001)
    fy = min(max(fy, 0.0), ny - 1.000001)
    i = np.int64(fx)
    j = np.int64(fy)
    return i, j, fx - i, fy - j


@numba.njit(inline="always")
def hermite_gradient(nodes, fx, fy, inv_h):
    """(∂U/∂x, ∂U/∂y) [pN] of the interpolant at fractional indices (fx, fy); ``inv_h`` = 1/h."""
    i, j, t, u = _cell(nodes, fx, fy)
    t2 = t * t
    u2 = u * u
    # basis values in u and derivatives in t (for ∂x), values in t and derivatives in u (∂y)
    vu0 = 2.0 * u2 * u - 3.0 * u2 + 1.0
    vu1 = 3.0 * u2 - 2.0 * u2 * u
    du0 = u2 * u - 2.0 * u2 + u
    du1 = u2 * u - u2
    vt0 = 2.0 * t2 * t - 3.0 * t2 + 1.0
    vt1 = 3.0 * t2 - 2.0 * t2 * t
    dt0 = t2 * t - 2.0 * t2 + t
    dt1 = t2 * t - t2
    pvt0 = 6.0 * t2 - 6.0 * t          # dV_0/dt
    pvt1 = -pvt0                       # dV_1/dt
    pdt0 = 3.0 * t2 - 4.0 * t + 1.0    # dD_0/dt
    pdt1 = 3.0 * t2 - 2.0 * t          # dD_1/dt
    pvu0 = 6.0 * u2 - 6.0 * u
    pvu1 = -pvu0
    pdu0 = 3.0 * u2 - 4.0 * u + 1.0
    pdu1 = 3.0 * u2 - 2.0 * u
    gx = 0.0
    gy = 0.0
    for b in range(2):
        vu = vu0 if b == 0 else vu1
        du = du0 if b == 0 else du1
        pvu = pvu0 if b == 0 else pvu1
        pdu = pdu0 if b == 0 else pdu1
        for a in range(2):
            vt = vt0 if a == 0 else vt1
            dt = dt0 if a == 0 else dt1
            pvt = pvt0 if a == 0 else pvt1
            pdt = pdt0 if a == 0 else pdt1
            n = nodes[j + b, i + a]
            gx += n[0] * pvt * vu + n[1] * pdt * vu + n[2] * pvt * du + n[3] * pdt * du
            gy += n[0] * vt * pvu + n[1] * dt * pvu + n[2] * vt * pdu + n[3] * dt * pdu
    return gx * inv_h, gy * inv_h


@numba.njit(inline="always")
def hermite_value(nodes, fx, fy):
    """U [pN·nm] of the interpolant at fractional indices (fx, fy)."""
    i, j, t, u = _cell(nodes, fx, fy)
    t2 = t * t
    u2 = u * u
    total = 0.0
    for b in range(2):
        vu = 2.0 * u2 * u - 3.0 * u2 + 1.0 if b == 0 else 3.0 * u2 - 2.0 * u2 * u
        du = u2 * u - 2.0 * u2 + u if b == 0 else u2 * u - u2
        for a in range(2):
            vt = 2.0 * t2 * t - 3.0 * t2 + 1.0 if a == 0 else 3.0 * t2 - 2.0 * t2 * t
            dt = t2 * t - 2.0 * t2 + t if a == 0 else t2 * t - t2
            n = nodes[j + b, i + a]
            total += n[0] * vt * vu + n[1] * dt * vu + n[2] * vt * du + n[3] * dt * du
    return total


@numba.njit(cache=True)
def energy_and_gradient(nodes, x0, y0, spacing, x, y, energy, grad_x, grad_y):
    """U [pN·nm] and ∇U [pN] of the interpolant at points (x, y) [nm] (vectorised, for
    analysis and tests; the engine calls :func:`hermite_gradient` inline)."""
    inv_h = 1.0 / spacing
    for k in range(x.shape[0]):
        fx = (x[k] - x0) * inv_h
        fy = (y[k] - y0) * inv_h
        energy[k] = hermite_value(nodes, fx, fy)
        grad_x[k], grad_y[k] = hermite_gradient(nodes, fx, fy, inv_h)
