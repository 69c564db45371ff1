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
U(t, u) = Σ_ab α_ab tᵃ uᵇ (:func:`cell_coefficients`, α = M F Mᵀ with F the corners' values and
derivatives and M the Hermite matrix), in float32, so the kernel reads one 64-byte cache line
per evaluation and evaluates the gradient by Horner's rule instead of combining sixteen basis
products. They are stored by power of u, ``c[4b + a]`` = α_ab, so that the four polynomials
P_a(u) = Σ_b α_ab uᵇ (a = 0…3) are evaluated together, as one Horner scheme on vectors of four
(see "the cell polynomial in LLVM vector IR" below). The coefficients are recomputed whenever
the nodes change. float32 coefficients halve the memory of a large grid (page-table misses, not
arithmetic, set the cost of reading a 184 MB float64 array: 27 ns per evaluation at random
points of a 1 200² grid, against 9 ns in float32 with the scalar code of an earlier
version); float32 rounding moves the interpolant by ~10⁻⁷ of its scale, far below the
interpolation error below.

Interpolation error: for a smooth U, O(h⁴) in U and O(h³) in ∇U. Measured for a Gaussian well
of depth A and width σ at the default spacing h = d_sk/16 (2.39 nm for S2), as the largest error
over 20 000 random points within 5σ, relative to A (in U) and to the largest force A e^{-1/2}/σ
(in ∇U):

    σ = 2h:  8.9×10⁻⁴ and 4.9×10⁻³      σ = 8h (19 nm):  3.7×10⁻⁶ and 7.6×10⁻⁵
    σ = 4h:  5.4×10⁻⁵ and 6.2×10⁻⁴      σ = 16h (38 nm): 2.3×10⁻⁷ and 9.5×10⁻⁶

(each doubling of σ/h divides them by 16 and 8; ``tests/fields/landscape/
test_force_and_interpolation.py`` checks these figures).
"""

from __future__ import annotations

import numba
import numpy as np
from llvmlite import ir
from numba.core import types
from numba.extending import intrinsic

from skygas.fields._field_lookup import _prefetch

#: The cubic Hermite matrix: the coefficients (a₀…a₃) of p(t) = Σ aᵢ tⁱ from
#: (p(0), p(1), p'(0), p'(1)).
HERMITE = np.array(
    [[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [-3.0, 3.0, -2.0, -1.0], [2.0, -2.0, 1.0, 1.0]]
)


def cell_coefficients(nodes: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """The polynomial coefficients of every cell (ny − 1, nx − 1, 16) from the nodes.

    c[j, i, 4b + a] = α_ab (of tᵃ uᵇ), from the nodes (ny, nx, 4) = (U, h ∂U/∂x, h ∂U/∂y, h²
    ∂²U/∂x∂y).
    """
    n00, n10 = nodes[:-1, :-1], nodes[:-1, 1:]  # corners (t, u) = (0, 0), (1, 0)
    n01, n11 = nodes[1:, :-1], nodes[1:, 1:]  # (0, 1), (1, 1)
    # F[a-row, b-column]: rows p(t=0), p(t=1), ∂t p(0), ∂t p(1); columns u = 0, 1, ∂u at 0, 1
    F = np.stack(
        [
            np.stack([n00[..., 0], n01[..., 0], n00[..., 2], n01[..., 2]], axis=-1),
            np.stack([n10[..., 0], n11[..., 0], n10[..., 2], n11[..., 2]], axis=-1),
            np.stack([n00[..., 1], n01[..., 1], n00[..., 3], n01[..., 3]], axis=-1),
            np.stack([n10[..., 1], n11[..., 1], n10[..., 3], n11[..., 3]], axis=-1),
        ],
        axis=-2,
    )
    alpha = np.einsum("ak,...kl,bl->...ba", HERMITE, F, HERMITE)  # [..., b, a] = α_ab
    shape = alpha.shape[:2] + (16,)
    if out is None:
        return np.ascontiguousarray(alpha.reshape(shape))
    out[...] = alpha.reshape(shape)
    return out


@numba.njit(inline="always")
def _cell(coefficients, fx, fy):
    """Cell (i, j) holding fractional node indices (fx, fy), clamped to the grid, and (t, u).

    (t, u) are the fractions within the cell.
    """
    ny, nx = coefficients.shape[0], coefficients.shape[1]  # cells
    fx = min(max(fx, 0.0), nx - 0.000001)
    fy = min(max(fy, 0.0), ny - 0.000001)
    i = np.int64(fx)
    j = np.int64(fy)
    return i, j, fx - i, fy - j


@numba.njit(inline="always")
def prefetch_cell(coefficients, fx, fy):
    """Start loading the cache line of the cell holding fractional node indices (fx, fy).

    :func:`hermite_gradient` will read it.
    """
    i, j, _, _ = _cell(coefficients, fx, fy)
    _prefetch(coefficients, (j * coefficients.shape[1] + i) * 16)


# -- the cell polynomial in LLVM vector IR ----------------------------------------------------
# The coefficients of one power of u for the four powers of t are contiguous (c[4b + a]), so
# the four polynomials P_a(u) = Σ_b α_ab uᵇ and their derivatives D_a = dP_a/du come out of two
# Horner schemes on vectors of four float64,
#
#     P = ((C₃ u + C₂) u + C₁) u + C₀,   D = ((3 C₃) u + 2 C₂) u + C₁,
#
# four loads, four conversions and eleven vector operations where the scalar form takes a load,
# a conversion and an operation per coefficient; the gradient then needs two dot products,
#
#     ∂U/∂t = P · (0, 1, 2t, 3t²),   ∂U/∂u = D · (1, t, t², t³),
#
# summed pairwise across the two vectors at once. Measured, per evaluation at random points of
# a 1 200² grid: 14.5 ns as scalar Horner code, 7.3 ns with the vector P and D, 6.4 ns with the
# dot products too (benchmarks/bench_landscape.py gives the cost within a step).


def _check_cells(coefficients):
    return (
        isinstance(coefficients, types.Array)
        and coefficients.dtype == types.float32
        and coefficients.layout == "C"
    )


def _polynomials(context, builder, coefficients_type, args):
    """IR of the vectors (P, D) at u = ``args[2]`` of the cell at flat offset ``args[1]``."""
    data = context.make_array(coefficients_type)(context, builder, value=args[0]).data
    f32x4 = ir.VectorType(ir.FloatType(), 4)

    def power(b):  # (α_0b, α_1b, α_2b, α_3b) as float64
        pointer = builder.gep(data, [builder.add(args[1], ir.Constant(args[1].type, 4 * b))])
        vector = builder.load(builder.bitcast(pointer, f32x4.as_pointer()), align=16)
        return builder.fpext(vector, _F64X4)

    c0, c1, c2, c3 = (power(b) for b in range(4))
    u = _vector(builder, [args[2]] * 4)
    p = builder.fadd(builder.fmul(c3, u), c2)
    p = builder.fadd(builder.fmul(p, u), c1)
    p = builder.fadd(builder.fmul(p, u), c0)
    d = builder.fadd(
        builder.fmul(builder.fmul(c3, ir.Constant(_F64X4, [3.0] * 4)), u),
        builder.fmul(c2, ir.Constant(_F64X4, [2.0] * 4)),
    )
    d = builder.fadd(builder.fmul(d, u), c1)
    return p, d


_F64X4 = ir.VectorType(ir.DoubleType(), 4)
_I32 = ir.IntType(32)


def _vector(builder, values):
    vector = ir.Constant(_F64X4, ir.Undefined)
    for k, value in enumerate(values):
        vector = builder.insert_element(vector, value, ir.Constant(_I32, k))
    return vector


@intrinsic
def _polynomials_at(typingctx, coefficients, offset, u):
    """(P₀, P₁, P₂, P₃) at ``u`` of the cell at flat element ``offset``, as float64."""
    if not _check_cells(coefficients):
        return None
    signature = types.UniTuple(types.float64, 4)(coefficients, offset, u)

    def codegen(context, builder, sig, args):
        p, _ = _polynomials(context, builder, sig.args[0], args)
        return context.make_tuple(
            builder,
            sig.return_type,
            [builder.extract_element(p, ir.Constant(_I32, k)) for k in range(4)],
        )

    return signature, codegen


@intrinsic
def _gradient_at(typingctx, coefficients, offset, t, u):
    """(∂U/∂t, ∂U/∂u) at (t, u) of the cell at flat element ``offset``, as float64."""
    if not _check_cells(coefficients):
        return None
    signature = types.UniTuple(types.float64, 2)(coefficients, offset, t, u)

    def codegen(context, builder, sig, args):
        p, d = _polynomials(context, builder, sig.args[0], (args[0], args[1], args[3]))
        f64 = ir.DoubleType()
        t = args[2]
        t2 = builder.fmul(t, t)
        one = ir.Constant(f64, 1.0)
        along_t = builder.fmul(
            p,
            _vector(
                builder,
                [
                    ir.Constant(f64, 0.0),
                    one,
                    builder.fmul(ir.Constant(f64, 2.0), t),
                    builder.fmul(ir.Constant(f64, 3.0), t2),
                ],
            ),
        )
        along_u = builder.fmul(d, _vector(builder, [one, t, t2, builder.fmul(t2, t)]))
        # (t₀ + t₁, u₀ + u₁, t₂ + t₃, u₂ + u₃), then the two halves added
        mask = ir.VectorType(_I32, 4)
        pairs = builder.fadd(
            builder.shuffle_vector(along_t, along_u, ir.Constant(mask, [0, 4, 2, 6])),
            builder.shuffle_vector(along_t, along_u, ir.Constant(mask, [1, 5, 3, 7])),
        )

        def lane(k):
            return builder.extract_element(pairs, ir.Constant(_I32, k))

        return context.make_tuple(
            builder,
            sig.return_type,
            [builder.fadd(lane(0), lane(2)), builder.fadd(lane(1), lane(3))],
        )

    return signature, codegen


@numba.njit(inline="always")
def hermite_gradient(coefficients, fx, fy, inv_h):
    """(∂U/∂x, ∂U/∂y) [pN] of the interpolant at fractional node indices (fx, fy).

    ``inv_h`` = 1/h.
    """
    i, j, t, u = _cell(coefficients, fx, fy)
    gt, gu = _gradient_at(coefficients, (j * coefficients.shape[1] + i) * 16, t, u)
    return gt * inv_h, gu * inv_h


@numba.njit(inline="always")
def hermite_value(coefficients, fx, fy):
    """U [pN·nm] of the interpolant at fractional node indices (fx, fy): Σ_a P_a(u) tᵃ."""
    i, j, t, u = _cell(coefficients, fx, fy)
    p0, p1, p2, p3 = _polynomials_at(coefficients, (j * coefficients.shape[1] + i) * 16, u)
    return ((p3 * t + p2) * t + p1) * t + p0


@numba.njit(cache=True)
def energy_and_gradient(coefficients, x0, y0, spacing, x, y, energy, grad_x, grad_y):
    """U [pN·nm] and ∇U [pN] of the interpolant at points (x, y) [nm], vectorised.

    For analysis and tests; the engine calls :func:`hermite_gradient` inline.
    """
    inv_h = 1.0 / spacing
    for k in range(x.shape[0]):
        fx = (x[k] - x0) * inv_h
        fy = (y[k] - y0) * inv_h
        energy[k] = hermite_value(coefficients, fx, fy)
        grad_x[k], grad_y[k] = hermite_gradient(coefficients, fx, fy, inv_h)
