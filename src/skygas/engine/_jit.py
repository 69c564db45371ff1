"""Compilation settings shared by the engine's kernels (private)."""

from __future__ import annotations

from typing import Literal, TypedDict

import numba

from skygas.core.kernel_cache import drop_stale_kernels

# The kernels inline functions of other modules, which numba's cache does not watch: compiled
# kernels of other source are deleted before any is loaded (skygas.core.kernel_cache).
drop_stale_kernels()

# Let LLVM fuse multiply-adds, reassociate and use reciprocals, but keep NaN/Inf semantics
# (NaN marks absent skyrmions in recorded frames). Results stay bit-reproducible for a given
# build of the package on a given machine.
FASTMATH = {"contract", "arcp", "nsz", "reassoc", "afn"}


class _JitOptions(TypedDict):
    """The keyword arguments of ``numba.njit`` that :data:`JIT` sets (typed for ``**JIT``)."""

    cache: bool
    fastmath: set[str]
    error_model: Literal["python", "numpy"]


# NumPy's error model: a division by zero gives inf/NaN instead of raising, so a loop holds no
# hidden exception branch and the compiler can turn it into SIMD instructions.
JIT: _JitOptions = {"cache": True, "fastmath": FASTMATH, "error_model": "numpy"}

# Array indices in the hot loops are unsigned: NumPy-style negative-index wrap-around then
# needs no extra instructions, which matters in loops of a few dozen instructions.
U = numba.uint64
