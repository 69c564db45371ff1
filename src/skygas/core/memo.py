"""A small per-process memo for device set-up that does not depend on the run's other values.

Why it exists: a sweep runs many short runs of one device that differ only in values the set-up
does not depend on (current density, p-value, temperature, seed). Rasterising the outline into
the wall-distance field and solving the current flow took 1.5-3 s per run, far more than a few
µs of simulated time. With this memo, each process (the client of a serial sweep, each Dask
worker) pays that set-up once per geometry and keeps the result for the following runs.

What is kept: the wall field (:mod:`skygas.fields.wall_field`), the unit-voltage current flow
(:mod:`skygas.fields.current`), the reshuffler's current field sampled on the engine grid for
J = 1 A/m² (:mod:`skygas.reshuffler.device`), the force tables and the packed wall channels of
the kernels' grid (:mod:`skygas.engine`). With all of them, building a 1024 nm reshuffler run
of an already-seen device takes ~30 ms (92 ms with only the first two). The three costly ones
(wall field, current flow, sampled current: ``persist=True``) are also kept on disk across
processes (:mod:`skygas.core.disk_cache`), so a new process loads them instead of building them.

Correctness rules that the users of this module follow:

- the key holds *everything* the memoised result depends on: the outline's exact coordinates
  (:func:`outline_key`, its WKB bytes, so two outlines built separately with the same numbers
  share an entry) and every parameter, as a ``float``, a string or a frozen dataclass;
- the memoised value is exactly what an uncached call computes, and whatever depends on
  per-call values (the current density J, the resistivity, …) is recomputed on every call with
  the same arithmetic, so results are bit-identical with and without the memo
  (``tests/core/test_setup_memo.py`` checks this);
- memoised arrays are made read-only, so no caller can alter a copy another run will read.

Entries are evicted least-recently-used beyond ``maxsize`` entries or ``max_bytes`` of arrays
(the newest entry is always kept; a 1024 nm reshuffler's three entries take 5-20 MB each, and
the sizes grow with the square of the chamber diameter). :func:`memo_stats` counts hits and
misses, and of the misses those loaded from disk (to check that a sweep really re-uses its
set-up); :func:`set_memo_enabled` turns memoisation off (for comparisons, and the test above);
the environment variable ``SKYGAS_MEMO=0`` does the same for new processes.
"""

from __future__ import annotations

import dataclasses
import os
import threading
from collections import OrderedDict
from collections.abc import Callable, Hashable
from typing import TypeVar

import numpy as np
import shapely

from skygas.core import disk_cache

T = TypeVar("T")

_enabled = os.environ.get("SKYGAS_MEMO", "1") not in ("0", "false", "no")


class Memo:
    """A bounded, thread-safe LRU map from a hashable key to a built value."""

    def __init__(
        self, name: str, maxsize: int = 4, max_bytes: int = 256 * 2**20, persist: bool = False
    ):
        self.name = name
        self.maxsize = maxsize
        self.max_bytes = max_bytes
        self.persist = persist
        self.hits = 0
        self.misses = 0
        self.disk_hits = 0
        self._items: OrderedDict[Hashable, object] = OrderedDict()
        self._sizes: dict[Hashable, int] = {}
        self._lock = threading.Lock()
        _MEMOS[name] = self

    def get(self, key: Hashable, build: Callable[[], T]) -> T:
        """The value stored under ``key``, building (and storing) it with ``build()`` if absent.

        With ``persist``, a miss looks in the disk cache (:mod:`skygas.core.disk_cache`) before
        building, and stores what it builds there. ``build`` runs outside the lock: two threads
        missing at once both build, and the values are equal, so either may be kept.
        """
        if not _enabled:
            return build()
        with self._lock:
            if key in self._items:
                self._items.move_to_end(key)
                self.hits += 1
                return self._items[key]  # type: ignore[return-value]
            self.misses += 1
        if self.persist:
            value, loaded = disk_cache.load_or_build(self.name, key, build)
            if loaded:
                frozen(*_arrays_in(value))
                with self._lock:
                    self.disk_hits += 1
        else:
            value = build()
        with self._lock:
            self._items[key] = value
            self._items.move_to_end(key)
            self._sizes[key] = sum(a.nbytes for a in _arrays_in(value))
            while len(self._items) > 1 and (
                len(self._items) > self.maxsize or sum(self._sizes.values()) > self.max_bytes
            ):
                old, _ = self._items.popitem(last=False)
                del self._sizes[old]
        return value

    def clear(self) -> None:
        """Drop every entry and reset the counts (not the disk cache)."""
        with self._lock:
            self._items.clear()
            self._sizes.clear()
            self.hits = self.misses = self.disk_hits = 0


def _arrays_in(value, depth: int = 3):
    """The numpy arrays in ``value``, down to ``depth`` levels.

    Looked for in dataclass fields, tuples, lists and dict values.
    """
    if isinstance(value, np.ndarray):
        yield value
        return
    if depth == 0:
        return
    items: list | tuple
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        items = [getattr(value, f.name) for f in dataclasses.fields(value)]
    elif isinstance(value, (tuple, list)):
        items = value
    elif isinstance(value, dict):
        items = list(value.values())
    else:
        return
    for item in items:
        yield from _arrays_in(item, depth - 1)


_MEMOS: dict[str, Memo] = {}


def outline_key(outline) -> tuple:
    """A hashable key of an :class:`~skygas.physics.geometry.Outline`.

    The exact bytes (WKB) of its region and of each port, in order, with the port names.
    """
    return (
        shapely.to_wkb(outline.region),
        tuple((name, shapely.to_wkb(line)) for name, line in outline.ports.items()),
    )


def frozen(*arrays: np.ndarray) -> None:
    """Make ``arrays`` read-only (they are shared by every run that hits the memo)."""
    for array in arrays:
        array.flags.writeable = False


def memo_stats() -> dict[str, dict[str, int]]:
    """Hits, misses and stored entries of every memo in this process.

    Of the misses, ``disk_hits`` were loaded from the disk cache and ``built`` were computed.
    """
    return {
        name: {
            "hits": m.hits,
            "misses": m.misses,
            "disk_hits": m.disk_hits,
            "built": m.misses - m.disk_hits,
            "entries": len(m._items),
        }
        for name, m in _MEMOS.items()
    }


def memo_bytes() -> dict[str, int]:
    """Bytes of arrays held by every memo in this process."""
    return {name: sum(m._sizes.values()) for name, m in _MEMOS.items()}


def clear_memos() -> None:
    """Forget every stored value and reset the counts."""
    for memo in _MEMOS.values():
        memo.clear()


def set_memo_enabled(enabled: bool) -> bool:
    """Turn memoisation on or off in this process; returns the previous setting."""
    global _enabled
    previous, _enabled = _enabled, bool(enabled)
    return previous
