"""Bilinear lookup of the engine's packed field grid, all channels at once (private).

The engine keeps every per-node field (wall distance and normal, boundary distance, spin-drift
velocity) in one float32 array ``fields[j, i, c]`` of ``N_CHANNELS`` = 8 channels, so one grid
node is 32 bytes and its channels fill one vector register. :func:`field_at` interpolates
bilinearly,

    f(x, y) = (1−tx)(1−ty) f₀₀ + tx(1−ty) f₁₀ + (1−tx) ty f₀₁ + tx ty f₁₁,

for all eight channels with four vector loads, four float32→float64 conversions, four
multiplications and three additions, where channel-by-channel code costs a scalar load,
conversion and multiply-add per channel and corner. The compiler does not find this form by
itself (it would need to prove the eight loads consecutive), so :func:`_bilinear8` writes it in LLVM
vector IR. Arithmetic is
in float64, as in the scalar form; only the order of the four corner terms is fixed.

The grid of a device is several MB, more than a core's L2 cache, and a skyrmion reaches new
grid rows every few steps; the first lookup there waits for memory. :func:`prefetch_at` asks
for those cache lines ahead of time, so the wait overlaps with other work.
"""

from __future__ import annotations

import numba
import numpy as np
from llvmlite import ir
from numba.core import cgutils, types
from numba.extending import intrinsic

N_CHANNELS = 8  # channels per node: one 32-byte vector of float32

# The intrinsic's name carries its pointer type: "p0" with opaque pointers (llvmlite ≥ 0.45),
# "p0i8" with the typed pointers of older releases.
_PREFETCH_NAME = (
    "llvm.prefetch.p0i8"
    if getattr(ir, "ir_layer_typed_pointers_enabled", True)
    else "llvm.prefetch.p0"
)


@intrinsic
def _bilinear8(typingctx, fields, base, row, w00, w10, w01, w11):
    """The eight channels interpolated with weights (w00, w10, w01, w11) of four nodes.

    The nodes are at flat element offsets base, base + 8, base + row, base + row + 8 of the
    C-contiguous float32 ``fields``; the result is a tuple of eight float64.
    """
    if not (
        isinstance(fields, types.Array) and fields.dtype == types.float32 and fields.layout == "C"
    ):
        return None
    signature = types.UniTuple(types.float64, N_CHANNELS)(fields, base, row, w00, w10, w01, w11)

    def codegen(context, builder, sig, args):
        data = context.make_array(sig.args[0])(context, builder, value=args[0]).data
        i32 = ir.IntType(32)
        f32x8 = ir.VectorType(ir.FloatType(), N_CHANNELS)
        f64x8 = ir.VectorType(ir.DoubleType(), N_CHANNELS)

        def node(offset):
            pointer = builder.bitcast(builder.gep(data, [offset]), f32x8.as_pointer())
            return builder.fpext(builder.load(pointer, align=4), f64x8)

        def splat(value):
            one = builder.insert_element(
                ir.Constant(f64x8, ir.Undefined), value, ir.Constant(i32, 0)
            )
            return builder.shuffle_vector(
                one,
                ir.Constant(f64x8, ir.Undefined),
                ir.Constant(ir.VectorType(i32, N_CHANNELS), [0] * N_CHANNELS),
            )

        base_, row_ = args[1], args[2]
        step = ir.Constant(base_.type, N_CHANNELS)
        above = builder.add(base_, row_)
        corners = [
            node(base_),
            node(builder.add(base_, step)),
            node(above),
            node(builder.add(above, step)),
        ]
        weights = [splat(w) for w in args[3:7]]
        terms = [builder.fmul(c, w) for c, w in zip(corners, weights, strict=True)]
        total = builder.fadd(builder.fadd(terms[0], terms[1]), builder.fadd(terms[2], terms[3]))
        values = [builder.extract_element(total, ir.Constant(i32, k)) for k in range(N_CHANNELS)]
        return context.make_tuple(builder, sig.return_type, values)

    return signature, codegen


@intrinsic
def _prefetch(typingctx, array, offset):
    """Hint that element ``offset`` of the C-contiguous ``array`` will soon be read.

    LLVM's ``llvm.prefetch``, into all cache levels. Never faults, even for a bad address.
    """
    if not (isinstance(array, types.Array) and array.layout == "C"):
        return None

    def codegen(context, builder, sig, args):
        data = context.make_array(sig.args[0])(context, builder, value=args[0]).data
        pointer = builder.bitcast(builder.gep(data, [args[1]]), ir.IntType(8).as_pointer())
        i32 = ir.IntType(32)
        function = cgutils.get_or_insert_function(
            builder.module,
            ir.FunctionType(ir.VoidType(), [pointer.type, i32, i32, i32]),
            _PREFETCH_NAME,
        )
        # read access, locality 3 (keep in all levels), data cache
        builder.call(
            function, [pointer, ir.Constant(i32, 0), ir.Constant(i32, 3), ir.Constant(i32, 1)]
        )
        return context.get_dummy_value()

    return types.none(array, offset), codegen


@numba.njit(inline="always")
def _node_offset(fields, fx, fy):
    """Flat element offset of the lower-left node of the cell holding (fx, fy), and (tx, ty).

    (fx, fy) are fractional grid indices (clamped to the grid); (tx, ty) their fractional parts.
    """
    ny, nx = fields.shape[0], fields.shape[1]
    fx = min(max(fx, 0.0), nx - 1.000001)
    fy = min(max(fy, 0.0), ny - 1.000001)
    i = np.int64(fx)
    j = np.int64(fy)
    return (j * nx + i) * N_CHANNELS, fx - i, fy - j


@numba.njit(inline="always")
def prefetch_at(fields, fx, fy):
    """Start loading the cache lines that :func:`field_at` (fx, fy) will read.

    Two nodes in each of two rows (the second node's last channel may sit on the next line).
    """
    base, _, _ = _node_offset(fields, fx, fy)
    row = fields.shape[1] * N_CHANNELS
    _prefetch(fields, base)
    _prefetch(fields, base + 2 * N_CHANNELS - 1)
    _prefetch(fields, base + row)
    _prefetch(fields, base + row + 2 * N_CHANNELS - 1)


@numba.njit(inline="always")
def field_at(fields, fx, fy):
    """All channels at fractional grid indices (fx, fy), clamped to the grid.

    A tuple of eight float64.
    """
    base, tx, ty = _node_offset(fields, fx, fy)
    return _bilinear8(
        fields,
        base,
        fields.shape[1] * N_CHANNELS,
        (1.0 - tx) * (1.0 - ty),
        tx * (1.0 - ty),
        (1.0 - tx) * ty,
        tx * ty,
    )


def empty_fields(ny: int, nx: int) -> np.ndarray:
    """A zeroed (ny, nx, N_CHANNELS) float32 grid whose nodes start on 32-byte boundaries.

    So no node's vector load straddles two cache lines.
    """
    count = ny * nx * N_CHANNELS
    raw = np.zeros(count + 16, dtype=np.float32)
    skip = (-raw.ctypes.data % 64) // 4
    return raw[skip : skip + count].reshape(ny, nx, N_CHANNELS)
