"""Independent skyrmions followed over long runs in a small device (used by the tests).

With a pair law of zero amplitude skyrmions do not interact, so many of them can share one
small rectangle. In a landscape that does not depend on y (or is periodic in x) a skyrmion
that wanders far is taken out and put back nearer the centre, shifted by whole periods in x
and by any amount in y: the landscape it sees is the same, its unwrapped path continues. The
new skyrmion has a new id and so fresh, independent noise, which the statistics do not mind.
"""

from __future__ import annotations

import numpy as np

from skygas.engine import Simulation


class Tracks:
    """Unwrapped positions [m] of skyrmions started at ``starts`` [m] (n, 2), kept within
    |x| ≤ ``box[0]``, |y| ≤ ``box[1]`` [m] by shifts of ``period_x`` [m] in x (``None``: x is
    never shifted) and of y back to its start."""

    def __init__(self, sim: Simulation, starts, box, period_x=None):
        self.sim = sim
        self.starts = np.asarray(starts, float)
        self.box = box
        self.period_x = period_x
        self.offset = np.zeros_like(self.starts)  # unwrapped = present + offset
        ids = sim.add_skyrmions(self.starts, validate=False)
        self.track_of = {int(i): k for k, i in enumerate(ids)}

    def positions(self) -> np.ndarray:
        """Present positions (n, 2) [m] in track order (NaN for ended tracks)."""
        ids, pos = self.sim.positions()
        out = np.full_like(self.starts, np.nan)
        out[[self.track_of[int(i)] for i in ids]] = pos
        return out

    def end(self, tracks) -> None:
        """Remove the skyrmions of ``tracks`` for good."""
        by_track = {k: i for i, k in self.track_of.items()}
        self.sim.remove_skyrmions([by_track[k] for k in tracks], reason="track ended")
        for k in tracks:
            del self.track_of[by_track[k]]

    def unwrapped(self) -> np.ndarray:
        return self.positions() + self.offset

    def replace(self, tracks, new_positions) -> None:
        """Move the skyrmions of ``tracks`` to ``new_positions`` [m] (a remove and an insert),
        keeping their unwrapped paths."""
        if len(tracks) == 0:
            return
        present = self.positions()
        by_track = {k: i for i, k in self.track_of.items()}
        self.sim.remove_skyrmions([by_track[k] for k in tracks], reason="recentred")
        for k in tracks:
            del self.track_of[by_track[k]]
        self.offset[tracks] += present[tracks] - new_positions
        for k, i in zip(tracks, self.sim.add_skyrmions(new_positions, validate=False), strict=True):
            self.track_of[int(i)] = int(k)

    def recentre(self) -> None:
        """Bring back the skyrmions that left the box."""
        p = self.positions()
        with np.errstate(invalid="ignore"):  # NaN: ended tracks
            far = np.nonzero((np.abs(p[:, 0]) > self.box[0]) | (np.abs(p[:, 1]) > self.box[1]))[0]
        if len(far) == 0:
            return
        new = p[far].copy()
        new[:, 1] = self.starts[far, 1]
        if self.period_x is not None:
            new[:, 0] -= np.round((new[:, 0] - self.starts[far, 0]) / self.period_x) * self.period_x
        else:
            new[:, 0] = p[far, 0]
        self.replace(far, new)
