"""The skyrmion Hall angle from thermal motion in the inferred landscape.

The Thiele equation (docs/physics.md §1) gives a skyrmion pushed by a force F the velocity
v = M F with M = (α𝒟k I − G ε)/((α𝒟k)² + G²): along F at the rate p = α𝒟k/(…) and across it
at q = G/(…). The Hall angle is the angle from the force to the velocity,
θ_H = atan2(q, p) = atan2(G, α𝒟k) (counter-clockwise positive), the deflection of a skyrmion
driven by a force (a field gradient, a pinning site, a wall).

Thermal motion in a landscape measures it: the mean displacement of a skyrmion at r is
dt·M·F(r), with F = −∇U = k_BT ∇ln ρ from the Boltzmann inversion. The displacement regressed on
F is the one *after* the frame where F is read, from frame t + 1 to t + 2, so that the
localisation error of the position where F is read is independent of it. The smoothing of the
map shrinks F, and the displacement over the next frame lags it slightly, by the same factor
for p and q, so the angle is unbiased by both to first order (|v|/|F| is not: D is read from
the MSD instead). Standard errors by blocking over contiguous blocks of time.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skygas.analysis.frames import Frames
from skygas.inference.diffusion import blocked, time_blocks
from skygas.inference.landscape import LandscapeMap

#: Blocks of time for the errors.
BLOCKS = 16


@dataclass(frozen=True)
class HallAngle:
    """θ_H [rad] ± ``error``; ``p``, ``q`` [m/(s·k_BT/m)] the fitted mobility; ``samples`` used."""

    angle: float
    error: float
    p: float
    q: float
    samples: int

    def as_dict(self) -> dict:
        """JSON-able, SI units in the keys."""
        return {
            "hall_angle": self.angle,
            "hall_angle_error": self.error,
            "mobility_along_force": self.p,
            "mobility_across_force": self.q,
            "displacements": self.samples,
            "definition": "angle from the force to the velocity, counter-clockwise positive "
            "(atan2(G, alpha*D*k) of the Thiele equation)",
        }


def _successor(frames: Frames) -> np.ndarray:
    """The entry of the same skyrmion in the next frame, or −1 (E,)."""
    nxt = np.full(len(frames.ids), -1, np.int64)
    a, b = frames.pairs_at_lag(1)
    nxt[a] = b
    return nxt


def hall_angle(frames: Frames, landscape: LandscapeMap) -> HallAngle:
    """θ_H from the displacements over the frame after each well-sampled position."""
    gx, gy = landscape.gradient()
    grid = landscape.grid
    nxt = _successor(frames)
    first = np.flatnonzero(nxt >= 0)
    second = nxt[first]
    ok = nxt[second] >= 0
    e, s1 = first[ok], second[ok]
    s2 = nxt[s1]
    j, i = grid.node_of(frames.x[e], frames.y[e])
    use = landscape.well_sampled[j, i] & np.isfinite(gx[j, i]) & np.isfinite(gy[j, i])
    e, s1, s2, j, i = e[use], s1[use], s2[use], j[use], i[use]
    fx, fy = -gx[j, i], -gy[j, i]  # force in k_BT per metre
    dx = frames.x[s2] - frames.x[s1]
    dy = frames.y[s2] - frames.y[s1]
    dt = frames.frame_interval()
    along = dx * fx + dy * fy
    across = -dx * fy + dy * fx  # the displacement's part along ẑ × F
    norm = fx * fx + fy * fy

    def angle_of(sel):
        return float(np.arctan2(np.sum(across[sel]), np.sum(along[sel])))

    frame = frames.frame_of_entry[e]
    per_block = [
        angle_of((frame >= b[0]) & (frame <= b[-1])) for b in time_blocks(frames.n_frames, BLOCKS)
    ]
    total = float(np.sum(norm)) * dt
    p = float(np.sum(along)) / total if total > 0 else float("nan")
    q = float(np.sum(across)) / total if total > 0 else float("nan")
    return HallAngle(
        angle_of(np.ones(len(e), bool)), blocked(np.array(per_block)), p, q, int(len(e))
    )
