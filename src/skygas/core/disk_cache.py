"""The on-disk layer of the device set-up memo: set-up kept across processes.

Why it exists: :mod:`skygas.core.memo` keeps a device's set-up for the runs of one process, but
every new process pays it again: each Dask worker of a sweep, each ``skygas reshuffle`` or
``skygas simulate``. For the paper's 1024 nm reshuffler that is ~0.9 s to solve the current
flow, ~0.3 s to build the wall field and ~0.1 s to sample the current on the engine's grid;
loading the three from disk takes a few tens of milliseconds. A 16-point sweep on 2 workers that
start fresh pays it once per worker, in parallel, so it adds the same wall time to 1 and 2
workers and lowers the speed-up (``docs/sweeps.md``).

Where: ``$SKYGAS_CACHE_DIR`` if set, else ``$XDG_CACHE_HOME/skygas``, else ``~/.cache/skygas``.
``SKYGAS_DISK_CACHE=0`` turns it off (every new process then builds its set-up again). The
cache holds at most :data:`MAX_BYTES`; beyond that the least recently used entries are removed.
A cache that cannot be created or written is skipped with one warning: the run goes on.

How: :class:`joblib.Memory` stores each built value under a hash of (memo name, the memo's key,
:func:`code_fingerprint`), writing it to a temporary name first and renaming it into place, so
processes that build the same entry at once never leave a half-written one; an entry that cannot
be read is built again.

Correctness rules (those of :mod:`skygas.core.memo`, plus one):

- an entry is used only by a process whose :func:`code_fingerprint` is the one that wrote it:
  the fingerprint hashes the source of every module of the installed package and the versions of
  the libraries the set-up is computed with, so after any change of code or library the cache
  starts empty instead of returning what an uncached call would no longer compute;
- a loaded value is bit-identical to the built one (pickle round trip) and made read-only, like
  every memoised value (``tests/core/test_disk_cache.py`` checks both).
"""

from __future__ import annotations

import hashlib
import importlib.metadata
import os
import threading
import warnings
from collections.abc import Callable, Hashable
from pathlib import Path
from typing import TypeVar

T = TypeVar("T")

#: Largest size of the cache directory [bytes]. A 1024 nm reshuffler's three entries take
#: ~15-40 MB; the sizes grow with the square of the chamber diameter.
MAX_BYTES = 2 * 2**30

#: Libraries whose version is part of :func:`code_fingerprint`: the set-up is computed with them
#: (sparse solve, rasterisation, geometry, kernels) and a new version may change its last bits.
_LIBRARIES = ("numpy", "scipy", "shapely", "numba", "joblib")

_lock = threading.Lock()
_caches: dict[Path, tuple] = {}  # directory → (joblib.Memory, the cached function)
_fingerprint: str | None = None
_warned = False


def location() -> Path | None:
    """The cache directory, or None when the disk cache is turned off.

    Read from the environment on every call, so a test or a worker can point it elsewhere.
    """
    if os.environ.get("SKYGAS_DISK_CACHE", "1").strip().lower() in ("0", "false", "no", "off"):
        return None
    explicit = os.environ.get("SKYGAS_CACHE_DIR")
    if explicit:
        return Path(explicit).expanduser()
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "skygas"


def code_fingerprint() -> str:
    """A SHA-256 of the package's source and of the versions in :data:`_LIBRARIES`.

    The source: every ``.py`` and ``.toml`` file under the package, by relative path. Computed once
    per process (~10 ms).
    """
    global _fingerprint
    if _fingerprint is None:
        digest = hashlib.sha256()
        root = Path(__file__).resolve().parents[1]  # the package: skygas/core/disk_cache.py
        files = sorted(p for pattern in ("*.py", "*.toml") for p in root.rglob(pattern))
        for path in files:
            digest.update(str(path.relative_to(root)).encode())
            digest.update(b"\0")
            digest.update(path.read_bytes())
            digest.update(b"\0")
        for name in _LIBRARIES:
            digest.update(f"{name}={importlib.metadata.version(name)}\0".encode())
        _fingerprint = digest.hexdigest()
    return _fingerprint


def _warn_once(message: str) -> None:
    global _warned
    if not _warned:
        _warned = True
        warnings.warn(
            f"skygas disk cache off for this process: {message}", RuntimeWarning, stacklevel=3
        )


def _cache_at(where: Path):
    with _lock:
        if where not in _caches:
            import joblib  # imported here: processes that never miss the memo do not pay it

            def built(memo: str, key: Hashable, fingerprint: str, build: Callable[[], T]) -> T:
                """What joblib caches: ``build()``, under the hash of the other arguments."""
                return build()

            # A new function object for each directory: joblib remembers, per function object,
            # that it has checked the function's code, and then skips writing that code into
            # a second directory, where another process would take its absence for a change
            # of code and empty the directory.
            memory = joblib.Memory(where, verbose=0)
            _caches[where] = memory, memory.cache(built, ignore=["build"])
        return _caches[where]


def load_or_build(memo: str, key: Hashable, build: Callable[[], T]) -> tuple[T, bool]:
    """The value of ``build()`` for ``(memo, key)``, loaded from the disk cache if it is there.

    Else built and stored. Returns the value and whether it was loaded.
    """
    where = location()
    if where is None:
        return build(), False
    try:
        memory, cached = _cache_at(where)
        fingerprint = code_fingerprint()
    except OSError as err:  # directory not creatable or readable: run without the cache
        _warn_once(f"{where}: {err}")
        return build(), False
    built = []  # joblib calls this only when it has no readable entry

    def build_and_note() -> T:
        built.append(True)
        return build()

    # joblib logs (logger "joblib.memory") and builds again when an entry cannot be read
    value = cached(memo, key, fingerprint, build_and_note)
    if built:
        try:
            memory.reduce_size(bytes_limit=MAX_BYTES)
        except OSError as err:
            _warn_once(f"{where}: {err}")
    return value, not built
