"""The wall potential from the density against the distance to the outline.

Positions are binned by their distance d to the outline's boundary (shapely); each bin's density
is its share of positions over the area of the band of the film at that distance (the exact
area between the outline shrunk by d₁ and by d₂), so the geometry does not enter. Then

    W(d) = −k_BT ln(ρ(d) / ρ_bulk),

with ρ_bulk the density over the distances beyond :data:`BULK_FRACTION` of the film's inradius
(the pinning averages out along the boundary, W → 0 there). Errors are blocked over contiguous
blocks of time. The wall law for the engine is the force −dW/dd of a smooth fit
(:mod:`skygas.inference.laws`) over the distances the data fix: the bins with at least
:data:`MIN_COUNT` positions and W known within :data:`MAX_ERROR` k_BT, closer than the first
such bin where W is not above zero by more than two standard errors. Farther, W is
indistinguishable from the bulk and a fit of ln W there would only fit noise (on a dilute gas,
bins out to 300 nm pulled the fit at 60 nm to 2.4 k_BT where the bins read 5.9 ± 0.6 and the
wall law gives 5.7; fitted over 78–148 nm, 4.6).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skygas.analysis.frames import Frames
from skygas.core.units import M_TO_NM
from skygas.inference.diffusion import blocked, time_blocks
from skygas.inference.laws import first_run, fit_exp_quadratic, potential
from skygas.physics.geometry import Outline

#: The bulk starts at this fraction of the film's inradius from the boundary.
BULK_FRACTION = 0.5
#: A bin counts as sampled with at least this many positions ...
MIN_COUNT = 50
#: ... and W known within this standard error [k_BT].
MAX_ERROR = 0.5
#: Blocks of time for the errors.
BLOCKS = 16
#: Below this [k_BT] the fitted wall potential counts as zero.
NEGLIGIBLE = 0.05


@dataclass(frozen=True)
class WallProfile:
    """W(d) [k_BT] ± ``error`` at bin centres ``d`` [m]; ``sampled`` bins; the fit ``coef``.

    ``coef`` (c₀, c₁, c₂) of ln W = c₀ + c₁ d + c₂ d², d in nm (None if it cannot be fitted);
    ``bulk_from`` [m] where the bulk starts.
    """

    d: np.ndarray
    w: np.ndarray
    error: np.ndarray
    counts: np.ndarray
    sampled: np.ndarray
    coef: np.ndarray | None
    bulk_from: float

    @property
    def reach(self) -> float:
        """Where the fitted W first falls below :data:`NEGLIGIBLE` k_BT [m] (≤ ``bulk_from``).

        The wall potential is applied (to the pinning map, and as the engine's wall table) up
        to here and is 0 beyond: the fit is not carried into distances where it would only
        extrapolate.
        """
        if self.coef is None:
            return 0.0
        d = np.linspace(0.0, self.bulk_from, 400)
        weak = np.flatnonzero(potential(self.coef, d * M_TO_NM) < NEGLIGIBLE)
        return float(d[weak[0]]) if len(weak) else self.bulk_from

    def at(self, d: np.ndarray) -> np.ndarray:
        """W(d) [k_BT] of the fit at distances ``d`` [m], 0 beyond :attr:`reach` (or no fit)."""
        d = np.asarray(d, float)
        if self.coef is None:
            return np.zeros_like(d)
        return np.where(d < self.reach, potential(self.coef, d * M_TO_NM), 0.0)

    @property
    def sampled_range(self) -> tuple[float, float] | None:
        """(first, last) sampled distance [m], or None."""
        if not self.sampled.any():
            return None
        d = self.d[self.sampled]
        return float(d.min()), float(d.max())


def wall_distance(outline: Outline, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Distance [m] of each point to the outline's boundary (negative outside)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    d = np.asarray(outline.wall_distance(x, y))
    return np.where(outline.contains(x, y), d, -d)


def inradius(outline: Outline) -> float:
    """The largest distance [m] from the boundary inside the outline (to 1 % of it)."""
    import shapely

    region = outline.region
    lo, hi = 0.0, max(region.bounds[2] - region.bounds[0], region.bounds[3] - region.bounds[1])
    for _ in range(20):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if not shapely.is_empty(region.buffer(-mid)) else (lo, mid)
    return lo / M_TO_NM


def wall_profile(
    frames: Frames, outline: Outline, bin_width: float, normal_force: np.ndarray | None = None
) -> WallProfile:
    """W(d) of the tracks in ``outline``, binned by ``bin_width`` [m], with blocked errors.

    ``normal_force`` (E,) [k_BT/m]: the neighbours' pair force on each entry along the inward
    normal (:func:`skygas.inference.crowding.normal_component`). Given, their mean push is taken
    out by force balance: W(d) = −ln(ρ(d)/ρ_bulk) − ∫_d^bulk f̄_n(s) ds, with f̄_n the mean normal
    force on the skyrmions at distance s (without it a crowded gas pressed against the wall
    reads a wall softer than it is).
    """
    reach = inradius(outline)
    edges = np.arange(0.0, reach + bin_width, bin_width)
    edges_nm = edges * M_TO_NM
    region = outline.region
    shrunk = np.array([region.buffer(-e).area if e > 0 else region.area for e in edges_nm])
    band_area = -np.diff(shrunk)  # nm²
    d = wall_distance(outline, frames.x, frames.y)
    bulk_from = BULK_FRACTION * reach
    bulk = edges[:-1] >= bulk_from

    inner = np.flatnonzero(~bulk)

    def profile(sel):
        dd = np.clip(d[sel], 0, None)
        counts = np.histogram(dd, edges)[0].astype(float)
        with np.errstate(divide="ignore", invalid="ignore"):
            rho = counts / band_area
            rho_bulk = counts[bulk].sum() / band_area[bulk].sum()
            w = -np.log(rho / rho_bulk)
            if normal_force is not None:
                push = np.histogram(dd, edges, weights=normal_force[sel])[0]
                mean = np.where(counts > 0, push / np.maximum(counts, 1), 0.0)
                # ∫ from each bin's centre to the start of the bulk
                tail = np.cumsum(mean[inner][::-1])[::-1]
                w[inner] -= bin_width * (tail - 0.5 * mean[inner])
            return w, counts

    w, counts = profile(np.ones(len(d), bool))
    frame = frames.frame_of_entry
    per_block = []
    for b in time_blocks(frames.n_frames, BLOCKS):
        per_block.append(profile((frame >= b[0]) & (frame <= b[-1]))[0])
    per_block_arr = np.array(per_block)
    error = np.array(
        [blocked(per_block_arr[:, k]) if np.isfinite(w[k]) else np.inf for k in range(len(w))]
    )
    centres = 0.5 * (edges[1:] + edges[:-1])
    sampled = first_run(
        (counts >= MIN_COUNT) & np.isfinite(w) & (error <= MAX_ERROR) & (w > 2 * error) & ~bulk
    )
    coef = fit_exp_quadratic(centres[sampled] * M_TO_NM, w[sampled], error[sampled])
    return WallProfile(centres, w, error, counts, sampled, coef, bulk_from)
