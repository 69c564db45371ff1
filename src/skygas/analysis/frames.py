"""Recorded positions as one flat table of entries, whatever the run recorded them as.

A run records positions either densely (``skygas simulate``: arrays (time, skyrmion) with NaN
where a skyrmion does not exist) or sparsely (the reshuffler's snapshots: for each frame the
ids present and their positions). :class:`Frames` holds both the same way, as entries
(frame, id, x, y) in frame order, so that every observable of :mod:`skygas.analysis` is
written once. Positions are in metres, times in seconds.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np


@dataclass(frozen=True)
class Frames:
    """Recorded positions as one flat table of entries (frame, id, x, y), frame after frame.

    ``time`` (F,) [s]; ``count`` (F,) skyrmions per frame; per entry (E = Σ count, frame after
    frame): ``ids``, ``x``, ``y`` [m].
    """

    time: np.ndarray
    count: np.ndarray
    ids: np.ndarray
    x: np.ndarray
    y: np.ndarray

    def __post_init__(self):
        if (
            len(self.time) != len(self.count)
            or int(np.sum(self.count)) != len(self.ids)
            or not len(self.ids) == len(self.x) == len(self.y)
        ):
            raise ValueError("inconsistent frames: sum(count) must equal the number of entries")

    # -- construction -------------------------------------------------------------------------
    @classmethod
    def from_dense(cls, time, ids, x, y) -> Frames:
        """From dense arrays, as ``skygas simulate`` records them.

        Arrays x, y (time, skyrmion) [m], NaN where a skyrmion is absent; ``ids`` the skyrmion of
        each column.
        """
        x, y = np.asarray(x, float), np.asarray(y, float)
        present = np.isfinite(x) & np.isfinite(y)
        frame, column = np.nonzero(present)  # row-major: frame after frame
        return cls(
            np.asarray(time, float),
            present.sum(axis=1).astype(np.int64),
            np.asarray(ids, np.int64)[column],
            x[frame, column],
            y[frame, column],
        )

    @classmethod
    def from_trajectories(cls, ds) -> Frames:
        """From a :meth:`~skygas.engine.Simulation.trajectories` dataset."""
        return cls.from_dense(ds.time.values, ds.skyrmion.values, ds.x.values, ds.y.values)

    # -- views ------------------------------------------------------------------------------
    @property
    def n_frames(self) -> int:
        """The number of frames F."""
        return len(self.time)

    @property
    def offsets(self) -> np.ndarray:
        """Index of the first entry of each frame, and the total at the end (F + 1,)."""
        return np.concatenate([[0], np.cumsum(self.count)]).astype(np.int64)

    @cached_property
    def frame_of_entry(self) -> np.ndarray:
        """The frame of each entry (E,)."""
        return np.repeat(np.arange(self.n_frames), self.count)

    def frame(self, f: int) -> tuple[np.ndarray, np.ndarray]:
        """Ids and positions (n, 2) [m] of frame ``f``."""
        a, b = self.offsets[f], self.offsets[f + 1]
        return self.ids[a:b], np.column_stack([self.x[a:b], self.y[a:b]])

    def select(self, frames) -> Frames:
        """The frames with the given indices (increasing), as a new :class:`Frames`."""
        frames = np.asarray(frames, dtype=np.int64)
        off = self.offsets
        take = (
            np.concatenate([np.arange(off[f], off[f + 1]) for f in frames])
            if len(frames)
            else np.empty(0, np.int64)
        )
        return Frames(
            self.time[frames], self.count[frames], self.ids[take], self.x[take], self.y[take]
        )

    def entries_where(self, keep: np.ndarray) -> Frames:
        """The same frames with only the entries where ``keep`` (E,) is true."""
        keep = np.asarray(keep, bool)
        counts = np.bincount(self.frame_of_entry[keep], minlength=self.n_frames)
        return Frames(
            self.time, counts.astype(np.int64), self.ids[keep], self.x[keep], self.y[keep]
        )

    def window(self, start: float | None = None, end: float | None = None) -> Frames:
        """The frames with start ≤ time ≤ end [s] (either bound may be None)."""
        keep = np.ones(self.n_frames, bool)
        if start is not None:
            keep &= self.time >= start
        if end is not None:
            keep &= self.time <= end
        return self.select(np.flatnonzero(keep))

    def frame_interval(self) -> float:
        """The time between consecutive frames [s].

        Raises ValueError if the spacing is not uniform (lag observables count lags in frames) or
        there are fewer than two frames.
        """
        if self.n_frames < 2:
            raise ValueError("at least two frames are needed")
        dt = np.diff(self.time)
        step = float(np.median(dt))
        if not np.allclose(dt, step, rtol=1e-6, atol=0):
            raise ValueError("frames are not evenly spaced in time")
        return step

    @cached_property
    def _by_skyrmion(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Entry keys id·F + frame, the order that sorts them, and the sorted keys.

        Sorted once, then shared by every lag.
        """
        key = self.ids.astype(np.int64) * self.n_frames + self.frame_of_entry
        order = np.argsort(key, kind="stable")
        return key, order, key[order]

    def pairs_at_lag(self, lag: int) -> tuple[np.ndarray, np.ndarray]:
        """Entries (a, b) of the same skyrmion in frames f and f + ``lag``.

        Every f is used: the overlapping time origins of windowed averages.
        """
        n = self.n_frames
        _, order, sorted_key = self._by_skyrmion
        # the wanted keys, id·F + frame + lag, are sorted too: a sorted search is fast
        wanted = sorted_key + lag
        where = np.searchsorted(sorted_key, wanted)
        ok = (sorted_key % n + lag < n) & (where < len(sorted_key))
        ok[ok] &= sorted_key[where[ok]] == wanted[ok]
        return order[ok], order[where[ok]]
