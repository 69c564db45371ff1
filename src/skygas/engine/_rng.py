"""Counter-based random numbers: Philox4x32-10 (Salmon et al., SC'11; Random123).

A counter-based generator is a pure function ``(key, counter) → 4 × 32 random bits``. The engine
keys it on the run's seed and counts with (skyrmion id, step, sub-stream), so the noise a
skyrmion receives at a step does not depend on how many other skyrmions exist, in which order
they are stored, on thread count, or on insertions and removals, and a run restarted from a
checkpoint continues exactly (HOOMD-blue's ``RandomNumbers.h`` does the same).

Counter layout (four 32-bit words): c0 = id low word, c1 = id high 16 bits | (sub-stream +
256 × attempt) << 16, c2 = step low word, c3 = step high word. Key: the 64-bit seed split into
two words. Sub-streams 0–255 are available; "attempt" counts the rejections of the polar method.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from llvmlite import ir
from numba.core import types
from numba.extending import intrinsic

_M0 = np.uint64(0xD2511F53)
_M1 = np.uint64(0xCD9E8D57)
_W0 = np.uint64(0x9E3779B9)
_W1 = np.uint64(0xBB67AE85)
_MASK32 = np.uint64(0xFFFFFFFF)
_INV_2_31 = 1.0 / 2147483648.0

#: Sub-stream used for the thermal noise.
STREAM_THERMAL = 0
#: Sub-stream of the noise on a breathing skyrmion's radius.
STREAM_RADIUS = 1


@numba.njit(inline="always")
def philox4x32_10(c0, c1, c2, c3, k0, k1):
    """Ten Philox rounds on a 4×32-bit counter with a 2×32-bit key (values held in uint64)."""
    for _ in range(10):
        p0 = _M0 * c0
        p1 = _M1 * c2
        c0, c1, c2, c3 = (
            (p1 >> np.uint64(32)) ^ c1 ^ k0,
            p1 & _MASK32,
            (p0 >> np.uint64(32)) ^ c3 ^ k1,
            p0 & _MASK32,
        )
        k0 = (k0 + _W0) & _MASK32
        k1 = (k1 + _W1) & _MASK32
    return c0, c1, c2, c3


@numba.njit(inline="always")
def _candidates(seed, ident, step, stream, attempt):
    """Two candidate points (u, v) uniform in [−1, 1)², as four floats.

    For attempt ``attempt`` of the polar method.
    """
    s = np.uint64(seed)
    i = np.uint64(ident)
    t = np.uint64(step)
    sub = (np.uint64(stream) + np.uint64(256) * np.uint64(attempt)) << np.uint64(16)
    r0, r1, r2, r3 = philox4x32_10(
        i & _MASK32,
        ((i >> np.uint64(32)) & np.uint64(0xFFFF)) | sub,
        t & _MASK32,
        t >> np.uint64(32),
        s & _MASK32,
        s >> np.uint64(32),
    )
    # via int64: the words are < 2³², and signed conversion is a single instruction on x86
    return (
        float(np.int64(r0)) * _INV_2_31 - 1.0,
        float(np.int64(r1)) * _INV_2_31 - 1.0,
        float(np.int64(r2)) * _INV_2_31 - 1.0,
        float(np.int64(r3)) * _INV_2_31 - 1.0,
    )


@intrinsic
def _float_bits(typingctx, value):
    """The IEEE-754 bits of a float64 as an int64 (a register move, no memory)."""

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.IntType(64))

    return types.int64(types.float64), codegen


@intrinsic
def _bits_float(typingctx, bits):
    """The float64 whose IEEE-754 bits are the int64 ``bits``."""

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.DoubleType())

    return types.float64(types.int64), codegen


# fdlibm's e_log.c: log(1 + f) = f − f²/2 + s(f²/2 + R(s²)), s = f/(2 + f), |R error| < 2⁻⁵⁸·⁴⁵
_LN2_HI = 6.93147180369123816490e-01
_LN2_LO = 1.90821492927058770002e-10
_LG1 = 6.666666666666735130e-01
_LG2 = 3.999999999940941908e-01
_LG3 = 2.857142874366239149e-01
_LG4 = 2.222219843214978396e-01
_LG5 = 1.818357216161805012e-01
_LG6 = 1.531383769920937332e-01
_LG7 = 1.479819860511658591e-01


@numba.njit(inline="always")
def _log(w):
    """Natural logarithm of a positive normal float64, in straight-line arithmetic.

    libm's ``log`` is a call the compiler cannot vectorise; this is fdlibm's algorithm (error
    < 1 ulp) without its branches: w = 2ᵏ·m with m in [√2/2, √2), then log w = k ln 2 + log m.
    Loops over many ``w`` compile to SIMD instructions. Zero, negative, subnormal, infinite and
    NaN inputs give meaningless finite results (the caller masks them).
    """
    bits = _float_bits(w)
    k = (bits >> 52) - 1023
    m = _bits_float((bits & 0x000FFFFFFFFFFFFF) | 0x3FF0000000000000)  # in [1, 2)
    big = m > 1.4142135623730951
    m = 0.5 * m if big else m
    k = k + 1 if big else k
    f = m - 1.0
    s = f / (2.0 + f)
    z = s * s
    w2 = z * z
    t1 = w2 * (_LG2 + w2 * (_LG4 + w2 * _LG6))
    t2 = z * (_LG1 + w2 * (_LG3 + w2 * (_LG5 + w2 * _LG7)))
    hfsq = 0.5 * f * f
    dk = float(k)
    return dk * _LN2_HI - ((hfsq - (s * (hfsq + t1 + t2) + dk * _LN2_LO)) - f)


@numba.njit(inline="always")
def _polar_scale(w):
    """√(−2 ln w / w), the factor of Marsaglia's polar transform (0 < w < 1)."""
    return math.sqrt(-2.0 * _log(w) / w)


@numba.njit(inline="always")
def _polar(u, v):
    """Marsaglia's polar transform of an accepted point: (z1, z2), or (nan, nan) if rejected."""
    w = u * u + v * v
    if 0.0 < w < 1.0:
        scale = _polar_scale(w)
        return u * scale, v * scale
    return np.nan, np.nan


@numba.njit(inline="always")
def gaussian_pair(seed, ident, step, stream):
    """Two independent standard normal numbers for (seed, ident, step, stream).

    Marsaglia's polar method: a point (u, v) uniform in the square [−1, 1)² is accepted when
    s = u² + v² lies in (0, 1), and then u·√(−2 ln s / s), v·√(−2 ln s / s) are independent
    standard normals. One Philox call gives two candidate points; in the rare case (4.6 %)
    that both are rejected, further calls use the next attempt number in the counter's
    sub-stream field, so the result stays a pure function of (seed, ident, step, stream).
    """
    attempt = 0
    while True:
        u0, v0, u1, v1 = _candidates(seed, ident, step, stream, attempt)
        z1, z2 = _polar(u0, v0)
        if z1 == z1:  # not NaN: accepted
            return z1, z2
        z1, z2 = _polar(u1, v1)
        if z1 == z1:
            return z1, z2
        attempt += 1


@numba.njit(inline="always")
def fill_gaussian_pairs(seed, ids, alive, step, stream, cand, out_x, out_y):
    """``gaussian_pair`` for every alive slot, batched for SIMD.

    ``cand`` is a (4, n) work array. Three branch-free loops that the compiler vectorises:
    the Philox words of every slot into ``cand``; then each slot's first accepted candidate
    point of the two, through the polar transform. The rare slots (4.6 %) whose two candidates
    are both rejected take the scalar path. Results equal ``gaussian_pair`` exactly.
    """
    n = ids.shape[0]
    for i in range(n):
        cand[0, i], cand[1, i], cand[2, i], cand[3, i] = _candidates(seed, ids[i], step, stream, 0)
    for i in range(n):
        u0 = cand[0, i]
        v0 = cand[1, i]
        u1 = cand[2, i]
        v1 = cand[3, i]
        w0 = u0 * u0 + v0 * v0
        first = 0.0 < w0 < 1.0
        u = u0 if first else u1
        v = v0 if first else v1
        w = w0 if first else u1 * u1 + v1 * v1
        valid = 0.0 < w < 1.0
        scale = _polar_scale(w if valid else 0.5)
        out_x[i] = u * scale if valid else np.nan
        out_y[i] = v * scale
    for i in range(n):
        if alive[i] and out_x[i] != out_x[i]:  # both rejected: the exact slow path
            out_x[i], out_y[i] = gaussian_pair(seed, ids[i], step, stream)


@numba.njit(cache=True)
def _philox_words(c, k):
    out = np.empty(4, dtype=np.uint64)
    out[0], out[1], out[2], out[3] = philox4x32_10(
        np.uint64(c[0]),
        np.uint64(c[1]),
        np.uint64(c[2]),
        np.uint64(c[3]),
        np.uint64(k[0]),
        np.uint64(k[1]),
    )
    return out


def philox_words(counter, key) -> list[int]:
    """Philox4x32-10 of a 4-word ``counter`` and 2-word ``key`` (for tests and tools)."""
    return [
        int(v) for v in _philox_words(np.asarray(counter, np.uint64), np.asarray(key, np.uint64))
    ]


@numba.njit(cache=True)
def _gaussians(seed, ident, steps, stream):
    out = np.empty((steps.shape[0], 2))
    for n in range(steps.shape[0]):
        out[n, 0], out[n, 1] = gaussian_pair(seed, ident, steps[n], stream)
    return out


def gaussians(seed: int, ident: int, steps, stream: int = STREAM_THERMAL) -> np.ndarray:
    """The (len(steps), 2) normal numbers the engine draws for skyrmion ``ident``."""
    return _gaussians(np.uint64(seed), np.int64(ident), np.asarray(steps, np.int64), stream)
