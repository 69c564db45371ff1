"""Keep numba's on-disk cache of compiled kernels in step with the package's source.

numba caches a compiled function (``cache=True``) beside its module, in ``__pycache__``, and
checks only that module's file to know whether the cache is still valid. The engine's kernel
inlines functions of other modules (the stages, the neighbour list, the field lookup, the
landscape's interpolant): after an edit of one of those, or an update of an editable install,
numba would load the old machine code, and a run would silently use the old physics.

:func:`drop_stale_kernels`, called before the first kernel is compiled or loaded, compares the
package's source fingerprint (:func:`skygas.core.disk_cache.code_fingerprint`) with the one
the cached kernels were built from, and deletes every cached kernel of the package when they
differ. Kernels are then compiled afresh once (tens of seconds) and cached again.
"""

from __future__ import annotations

import contextlib
import os
from pathlib import Path

from skygas.core.disk_cache import code_fingerprint

#: the file, in the package's top ``__pycache__``, that names the source the kernels are from
STAMP = "skygas-kernels.fingerprint"

_checked = False


def _package() -> Path:
    return Path(__file__).resolve().parents[1]


def drop_stale_kernels() -> None:
    """Delete the package's cached kernels if they were compiled from other source.

    Done once per process. A kernel cache elsewhere (``NUMBA_CACHE_DIR``) is not looked at.
    """
    global _checked
    if _checked:
        return
    _checked = True
    root = _package()
    stamp = root / "__pycache__" / STAMP
    fingerprint = code_fingerprint()
    try:
        if stamp.read_text() == fingerprint:
            return
    except OSError:
        pass
    for folder in root.rglob("__pycache__"):
        for path in (*folder.glob("*.nbi"), *folder.glob("*.nbc")):
            with contextlib.suppress(OSError):  # another process may have removed it already
                path.unlink()
    try:
        stamp.parent.mkdir(exist_ok=True)
        partial = stamp.with_suffix(f".{os.getpid()}.tmp")
        partial.write_text(fingerprint)
        partial.replace(stamp)  # atomic: a concurrent reader sees the old stamp or the new one
    except OSError:
        pass  # a read-only installation: numba then caches elsewhere or not at all


def engine_compiled() -> bool:
    """Whether the engine's time loop is in the cache (else the first run compiles it).

    Looked at after :func:`drop_stale_kernels`, so a stale cache counts as absent. Compiling
    the kernels takes about a minute on one core; the run driver says so before it, and
    measures the progress bar's rate from the end of the first piece.
    """
    drop_stale_kernels()
    return any((_package() / "engine" / "__pycache__").glob("kernel.advance-*.nbi"))
