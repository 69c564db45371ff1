"""Where a movie was taken: a walled film, a field of view inside a larger film, or a periodic box.

The forces a model may have depend on it:

- **walls**: the outline is the film's edge; skyrmions never leave it, and a wall force is a
  candidate of the model (:mod:`skygas.inference.dynamics`);
- **open**: the outline is the edge of the field of view; tracks end where skyrmions leave it
  and start where they enter, and no force acts there. A displacement that starts near the edge
  is used only if its skyrmion could not have left within a frame (:data:`EDGE_STEPS` step
  lengths inside): otherwise the steps that stay in view are the inward ones, a selection that
  looks like a wall;
- **periodic**: positions are written wrapped into a box of sides L_x × L_y (a periodic
  simulation's output). Displacements are unwrapped by the minimum image, pair distances too,
  and the landscape is periodic.

:func:`detect_periodic` finds the box from tracks that wrap; :func:`tracks_leave` tells an
outline that tracks leave and enter through from one they never cross.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skygas.analysis.frames import Frames
from skygas.physics.geometry import Outline, rectangle

#: A displacement of an open film is used when its start lies this many rms steps (per
#: coordinate, √(2DΔt)) inside the field of view: the chance to leave within one frame is then
#: below 10⁻⁴.
EDGE_STEPS = 4.0
#: A jump between frames longer than this share of the box side is a wrap ...
WRAP_SHARE = 0.5
#: ... and longer than this many median steps.
WRAP_STEPS = 20.0
#: Tracks leave through the outline when at least this many track ends (or starts) away from
#: the movie's first and last frames lie within :data:`EDGE_STEPS` steps of it ...
LEAVING_TRACKS = 5
#: ... and they are at least this share of all such ends and starts.
LEAVING_SHARE = 0.3


@dataclass(frozen=True)
class Film:
    """The region of a movie and how its boundary behaves.

    ``kind``: ``"walls"``, ``"open"`` or ``"periodic"``. ``outline``: the film (walls), the
    field of view (open) or the box (periodic) [m]. ``period``: (L_x, L_y) [m] of a periodic
    box, whose lower-left corner is ``origin``.

    A fourth kind, ``"tiled"``, is a model's run in copies of a periodic box
    (:mod:`skygas.inference.sampling`): positions fold into the box for the landscape, but
    neighbours are where they are, in the copies around it (no minimum image).
    """

    kind: str
    outline: Outline
    period: tuple[float, float] | None = None
    origin: tuple[float, float] = (0.0, 0.0)

    @property
    def periodic(self) -> bool:
        """Whether positions wrap."""
        return self.kind == "periodic"

    def wrap(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Positions folded into the box (unchanged without one)."""
        if self.period is None:
            return x, y
        return (
            self.origin[0] + np.mod(x - self.origin[0], self.period[0]),
            self.origin[1] + np.mod(y - self.origin[1], self.period[1]),
        )

    def separation(self, dx: np.ndarray, dy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Differences of positions by the minimum image (unchanged unless periodic)."""
        if not self.periodic:
            return dx, dy
        assert self.period is not None
        lx, ly = self.period
        return dx - lx * np.round(dx / lx), dy - ly * np.round(dy / ly)


def box_film(period: tuple[float, float], origin: tuple[float, float]) -> Film:
    """A periodic box of sides ``period`` [m] from ``origin`` [m]."""
    lx, ly = period
    outline = rectangle(lx, ly, center=(origin[0] + lx / 2, origin[1] + ly / 2))
    return Film("periodic", outline, (float(lx), float(ly)), (float(origin[0]), float(origin[1])))


def field_of_view(frames: Frames, pad: float) -> Outline:
    """The rectangle the positions span, widened by ``pad`` [m] on each side."""
    x0, x1 = float(np.min(frames.x)) - pad, float(np.max(frames.x)) + pad
    y0, y1 = float(np.min(frames.y)) - pad, float(np.max(frames.y)) + pad
    return rectangle(x1 - x0, y1 - y0, center=((x0 + x1) / 2, (y0 + y1) / 2))


def detect_periodic(frames: Frames) -> tuple[tuple[float, float], tuple[float, float]] | None:
    """The box (L_x, L_y) and its origin [m] of tracks that wrap, or None if none wrap.

    A wrap is a jump between consecutive frames of more than :data:`WRAP_SHARE` of the
    positions' span along an axis and :data:`WRAP_STEPS` median steps; a box has at least
    three, their median longer than 0.8 of the span. The side is the span of the positions
    along that axis (the box is visited from edge to edge, to within the gaps between
    positions, a small fraction of a step), or the median jump if that is longer (the jumps
    are the side less the step that crossed the edge). An axis without wraps takes the span
    itself (a box no skyrmion crossed along it is indistinguishable from a film that long).
    """
    a, b = frames.pairs_at_lag(1)
    if len(a) == 0:
        return None
    sides, origins, wrapped = [], [], False
    for pos in (frames.x, frames.y):
        lo, hi = float(np.min(pos)), float(np.max(pos))
        jump = np.abs(pos[b] - pos[a])
        # a wrap is a jump across most of the span and far longer than the steps (a film a
        # few steps wide is not a box its skyrmions wrap around)
        typical = float(np.median(jump))
        wraps = (jump > WRAP_SHARE * (hi - lo)) & (jump > WRAP_STEPS * typical)
        if np.count_nonzero(wraps) >= 3 and np.median(jump[wraps]) > 0.8 * (hi - lo):
            wrapped = True
            sides.append(max(hi - lo, float(np.median(jump[wraps]))))
        else:
            sides.append(hi - lo)
        origins.append(lo)
    if not wrapped:
        return None
    return (sides[0], sides[1]), (origins[0], origins[1])


def unwrapped_steps(film: Film, frames: Frames, a: np.ndarray, b: np.ndarray):
    """Displacements (dx, dy) [m] of entries a → b, by the minimum image in a periodic box."""
    return film.separation(frames.x[b] - frames.x[a], frames.y[b] - frames.y[a])


def tracks_leave(frames: Frames, outline: Outline, step: float) -> bool:
    """Whether tracks end and start at the outline: it is a field of view, not a wall.

    Counts the track ends (starts) that are not at the movie's last (first) frame and lie
    within :data:`EDGE_STEPS` rms steps ``step`` [m] of the outline.
    """
    from skygas.inference.wall import wall_distance

    first = np.unique(frames.ids, return_index=True)[1]
    # the last entry of each track: the first in reversed order
    last = len(frames.ids) - 1 - np.unique(frames.ids[::-1], return_index=True)[1]
    f = frames.frame_of_entry
    ends = np.concatenate([first[f[first] > 0], last[f[last] < frames.n_frames - 1]])
    if len(ends) == 0:
        return False
    near = wall_distance(outline, frames.x[ends], frames.y[ends]) < EDGE_STEPS * step
    return bool(np.count_nonzero(near) >= LEAVING_TRACKS and np.mean(near) >= LEAVING_SHARE)
