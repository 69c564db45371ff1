"""The pinning landscape by Boltzmann inversion: U(x, y) = −k_BT ln ρ(x, y), with its uncertainty.

In equilibrium a skyrmion's centre visits r with probability ρ(r) ∝ exp(−U(r)/k_BT), so the
occupation of the tracks measures U up to a constant (exact for independent skyrmions; in a gas
ρ also carries the mean effect of the neighbours, a small correction at low density, which the
pair-potential step checks by simulating the whole model).

**Density.** Positions are binned on a grid of spacing ``h`` and smoothed with a Gaussian kernel
of width b, corrected for the outline: ρ_b = (K_b ∗ counts) / (K_b ∗ film), so a kernel that
reaches past a wall does not lower the density beside it.

**Kernel width from the data.** b maximises the held-out log-likelihood: the frames are cut into
:data:`CV_BLOCKS` contiguous blocks of time; for each block the density is estimated from the
others and the mean of ln ρ at the block's positions is scored (likelihood cross-validation, with
whole blocks held out because neighbouring frames are correlated).

**Uncertainty.** A bootstrap over :data:`BOOT_BLOCKS` contiguous blocks of time
(:data:`BOOT_REPLICAS` resamples of the blocks with replacement) gives the standard deviation of U
at each node. A node is **well sampled** where that standard error is at most
:data:`WELL_SAMPLED_ERROR` k_BT. That error does not see which wells the skyrmions happened to
start in (on a movie short against the time a skyrmion takes to cross the film, each region is
sampled by the few skyrmions that were near it): a second bootstrap, over the skyrmions' tracks,
gives ``error_across_skyrmions``, and the nodes where it too is at most
:data:`WELL_SAMPLED_ERROR` are **fixed across skyrmions**.

**Statistics and wells.** The rms and correlation length of the pinning part (U minus the wall
profile, :mod:`skygas.inference.wall`) over the well-sampled nodes; the correlation length ξ is
where the radially averaged autocorrelation falls to e^(−1/2) (ξ of a Gaussian covariance
rms²·exp(−r²/2ξ²), the convention of :class:`~skygas.fields.landscape.Disorder`). The deepest
local minima.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from skygas.analysis.frames import Frames
from skygas.inference.diffusion import block_of_frame
from skygas.physics.geometry import Outline

#: Blocks of time held out in the cross-validation of the kernel width.
CV_BLOCKS = 8
#: Blocks of time resampled by the bootstrap, and the number of resamples.
BOOT_BLOCKS = 20
BOOT_REPLICAS = 40
#: Tracks are pooled into at most this many groups for the bootstrap over skyrmions.
SKYRMION_GROUPS = 100
#: A node is well sampled where the bootstrap standard error of U is at most this [k_BT].
WELL_SAMPLED_ERROR = 0.25
#: Largest number of grid nodes along the longer side.
MAX_NODES = 400
#: Smallest density, relative to the mean, in the cross-validation score (a held-out position
#: where the others never went scores ln of this instead of −∞).
DENSITY_FLOOR = 1e-3


@dataclass(frozen=True)
class Grid:
    """Nodes at x0 + i·h, y0 + j·h [m]; ``inside`` (ny, nx) the film's share of each node's cell."""

    x: np.ndarray
    y: np.ndarray
    h: float
    inside: np.ndarray

    def bins(self, x: np.ndarray, y: np.ndarray, weights: np.ndarray | None = None) -> np.ndarray:
        """Counts (ny, nx) of the points in the nodes' cells (sums of ``weights``, if given)."""
        ex = np.concatenate([self.x - self.h / 2, [self.x[-1] + self.h / 2]])
        ey = np.concatenate([self.y - self.h / 2, [self.y[-1] + self.h / 2]])
        return np.histogram2d(y, x, bins=(ey, ex), weights=weights)[0]

    def node_of(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The (row, column) of the node nearest to each point, clipped to the grid."""
        i = np.clip(np.round((x - self.x[0]) / self.h).astype(int), 0, len(self.x) - 1)
        j = np.clip(np.round((y - self.y[0]) / self.h).astype(int), 0, len(self.y) - 1)
        return j, i


def make_grid(outline: Outline, spacing: float) -> Grid:
    """A grid of ``spacing`` [m] over the outline's bounds (at most :data:`MAX_NODES` a side)."""
    import shapely

    from skygas.core.units import M_TO_NM

    x0, y0, x1, y1 = (v / M_TO_NM for v in outline.region.bounds)
    h = max(spacing, max(x1 - x0, y1 - y0) / MAX_NODES)
    x = np.arange(x0 + h / 2, x1, h)
    y = np.arange(y0 + h / 2, y1, h)
    # the film's share of each cell, from 4×4 sub-points
    sub = (np.arange(4) + 0.5) / 4 - 0.5
    sx = (x[None, :, None] + h * sub[None, None, :]).repeat(len(y), 0)
    sy = (y[:, None, None] + 0 * x[None, :, None]).repeat(4, 2)
    share = np.zeros((len(y), len(x)))
    for dy in sub:
        pts = shapely.points(sx.ravel() * M_TO_NM, (sy.ravel() + h * dy) * M_TO_NM)
        share += shapely.contains(outline.region, pts).reshape(len(y), len(x), 4).mean(axis=2)
    return Grid(x, y, h, share / 4)


def smoothed_density(counts: np.ndarray, grid: Grid, bandwidth: float) -> np.ndarray:
    """ρ (ny, nx) [1/m²], normalised over the film: edge-corrected Gaussian kernel estimate."""
    s = bandwidth / grid.h
    num = ndimage.gaussian_filter(counts, s, mode="constant", truncate=4.0)
    den = ndimage.gaussian_filter(grid.inside, s, mode="constant", truncate=4.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        rho = np.where((grid.inside > 0) & (den > 1e-6), num / den, 0.0)
    total = float(np.sum(rho * grid.inside)) * grid.h**2
    return rho / total if total > 0 else rho


def _binned_by_block(frames: Frames, grid: Grid, blocks: int) -> np.ndarray:
    """Counts (blocks, ny, nx) of the positions of each contiguous block of time."""
    entry_block = block_of_frame(frames.n_frames, blocks)[frames.frame_of_entry]
    n = int(entry_block.max()) + 1 if len(entry_block) else 0
    return np.array(
        [grid.bins(frames.x[entry_block == k], frames.y[entry_block == k]) for k in range(n)]
    )


def choose_bandwidth(
    frames: Frames, grid: Grid, candidates: np.ndarray
) -> tuple[float, np.ndarray]:
    """The kernel width [m] of highest held-out log-likelihood, and the score of each candidate."""
    per_block = list(_binned_by_block(frames, grid, CV_BLOCKS))
    total = np.sum(per_block, axis=0)
    area = float(np.sum(grid.inside)) * grid.h**2
    scores = np.zeros(len(candidates))
    for c, b in enumerate(candidates):
        score, n = 0.0, 0
        for held in per_block:
            rho = smoothed_density(total - held, grid, b)
            floor = DENSITY_FLOOR / area
            score += float(np.sum(held * np.log(np.maximum(rho, floor))))
            n += int(held.sum())
        scores[c] = score / max(n, 1)
    return float(candidates[int(np.argmax(scores))]), scores


def best_density_score(frames: Frames, outline: Outline, nodes: int = 100) -> float:
    """The best held-out log-likelihood per position of the positions' kernel density.

    On a grid of about ``nodes`` a side over ``outline``, over kernel widths from 1.5 spacings
    to a fifth of the outline: how concentrated the positions are, out of sample.
    """
    from skygas.core.units import M_TO_NM

    x0, y0, x1, y1 = (v / M_TO_NM for v in outline.region.bounds)
    grid = make_grid(outline, max(x1 - x0, y1 - y0) / nodes)
    side = min(grid.x[-1] - grid.x[0], grid.y[-1] - grid.y[0])
    candidates = np.geomspace(1.5 * grid.h, max(side / 5, 3 * grid.h), 8)
    _, scores = choose_bandwidth(frames, grid, candidates)
    area = float(np.sum(grid.inside)) * grid.h**2
    # per unit area: the scores are ln ρ [1/m²]; a larger view is not a blurrier one
    return float(np.max(scores) + np.log(area))


@dataclass(frozen=True)
class LandscapeMap:
    """U [k_BT] on ``grid`` (NaN off the film) ± ``error``; ``well_sampled`` nodes; kernel width.

    ``bandwidth`` [m] and the cross-validation ``candidates`` [m] with their ``scores`` (mean
    held-out log-likelihood).
    """

    grid: Grid
    u: np.ndarray
    error: np.ndarray
    well_sampled: np.ndarray
    bandwidth: float
    candidates: np.ndarray
    scores: np.ndarray
    error_across_skyrmions: np.ndarray | None = None

    @property
    def fixed_across_skyrmions(self) -> np.ndarray:
        """Well-sampled nodes whose U is also fixed across skyrmions.

        Their error from resampling the skyrmions is at most :data:`WELL_SAMPLED_ERROR` k_BT
        (all False if it was not computed).
        """
        if self.error_across_skyrmions is None:
            return np.zeros_like(self.well_sampled)
        with np.errstate(invalid="ignore"):
            return self.well_sampled & (self.error_across_skyrmions <= WELL_SAMPLED_ERROR)

    def gradient(self) -> tuple[np.ndarray, np.ndarray]:
        """∂U/∂x, ∂U/∂y [k_BT/m] at the nodes (central differences; NaN off the film)."""
        gy, gx = np.gradient(self.u, self.grid.h)
        return gx, gy


def boltzmann_inversion(
    frames: Frames, outline: Outline, spacing: float, *, candidates=None, seed: int = 0
) -> LandscapeMap:
    """U = −ln ρ [k_BT] of the tracks' occupation, with its bootstrap uncertainty.

    Parameters
    ----------
    frames : Frames
        Positions [m].
    outline : Outline
        The film.
    spacing : float
        Grid spacing [m] (at most :data:`MAX_NODES` nodes a side).
    candidates : array, optional
        Kernel widths [m] to choose from (default: 12 from 1.5 spacings to 1/15 of the film's
        smaller side, log-spaced).
    seed : int
        Seeds the bootstrap.

    Returns
    -------
    LandscapeMap
    """
    grid = make_grid(outline, spacing)
    if candidates is None:
        side = min(grid.x[-1] - grid.x[0], grid.y[-1] - grid.y[0])
        candidates = np.geomspace(1.5 * grid.h, max(side / 15, 3 * grid.h), 12)
    bandwidth, scores = choose_bandwidth(frames, grid, np.asarray(candidates, float))
    film = grid.inside > 0
    u = _energy(smoothed_density(grid.bins(frames.x, frames.y), grid, bandwidth), film)
    # bootstrap over blocks of time
    per_block = _binned_by_block(frames, grid, BOOT_BLOCKS)
    rng = np.random.default_rng([seed, 0xB007])
    error = _bootstrap(per_block, u, grid, bandwidth, film, rng)
    well = film & np.isfinite(u) & (error <= WELL_SAMPLED_ERROR)
    if well.any():
        u = u - np.nanmean(u[well])
    across = _bootstrap(_binned_by_skyrmion(frames, grid), u, grid, bandwidth, film, rng)
    return LandscapeMap(
        grid, u, error, well, bandwidth, np.asarray(candidates, float), scores, across
    )


def _binned_by_skyrmion(frames: Frames, grid: Grid, groups: int = SKYRMION_GROUPS) -> np.ndarray:
    """Counts (G, ny, nx) of the positions of each track (tracks pooled into ≤ ``groups``)."""
    _, track = np.unique(frames.ids, return_inverse=True)
    group = track % groups
    n = int(group.max()) + 1 if len(group) else 0
    return np.array([grid.bins(frames.x[group == k], frames.y[group == k]) for k in range(n)])


def _bootstrap(
    parts: np.ndarray, u: np.ndarray, grid: Grid, bandwidth: float, film, rng
) -> np.ndarray:
    """Standard deviation of U over :data:`BOOT_REPLICAS` resamples of ``parts``' counts.

    ``parts`` (P, ny, nx): the counts of blocks of time, or of groups of tracks; each resample
    draws P of them with replacement. Inf where a resample never visited a node, NaN off the film.
    """
    if len(parts) < 2:
        return np.where(film, np.inf, np.nan)
    replicas = np.empty((BOOT_REPLICAS, *u.shape))
    for r in range(BOOT_REPLICAS):
        pick = rng.integers(0, len(parts), len(parts))
        replicas[r] = _energy(smoothed_density(parts[pick].sum(axis=0), grid, bandwidth), film)
        # the constant of each replica is arbitrary: align it to U over the nodes both sample
        ok = np.isfinite(replicas[r]) & np.isfinite(u)
        if ok.any():
            replicas[r] -= np.median(replicas[r][ok] - u[ok])
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # nodes no replica visited
        error = np.where(
            np.all(np.isfinite(replicas), axis=0), np.nanstd(replicas, axis=0, ddof=1), np.inf
        )
    return np.where(film, error, np.nan)


def _energy(rho: np.ndarray, film: np.ndarray) -> np.ndarray:
    """−ln ρ on the film, NaN off it and where the density is 0 (never visited)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        u = -np.log(rho)
    u[~film | ~np.isfinite(u)] = np.nan
    return u


def correlation_length(u: np.ndarray, mask: np.ndarray, h: float) -> tuple[float, float]:
    """(rms [k_BT], ξ [m]) of ``u`` over ``mask``: the autocorrelation falls to e^(−1/2) at ξ.

    The masked autocorrelation C(s) = Σ m u(r) m u(r + s) / Σ m(r) m(r + s), radially averaged,
    with u's mean over the mask removed; ξ by linear interpolation between the radial bins.
    """
    m = mask.astype(float)
    v = np.where(mask, u - np.mean(u[mask]), 0.0)
    shape = [2 * n for n in v.shape]
    fv, fm = np.fft.rfft2(v, shape), np.fft.rfft2(m, shape)
    num = np.fft.irfft2(fv * np.conj(fv), shape)
    den = np.fft.irfft2(fm * np.conj(fm), shape)
    oy = np.fft.fftfreq(shape[0], 1 / shape[0])
    ox = np.fft.fftfreq(shape[1], 1 / shape[1])
    r = np.hypot(oy[:, None], ox[None, :])
    ok = den > 0.5 * den.max() * 0.05
    c = np.where(ok, num / np.maximum(den, 1e-12), 0.0)
    rbin = np.round(r).astype(int)
    top = int(min(v.shape) // 3)
    sel = ok & (rbin <= top)
    radial = np.bincount(rbin[sel], weights=c[sel], minlength=top + 1) / np.maximum(
        np.bincount(rbin[sel], minlength=top + 1), 1
    )
    rms = float(np.sqrt(radial[0])) if radial[0] > 0 else 0.0
    if radial[0] <= 0:
        return 0.0, float("nan")
    target = radial[0] * np.exp(-0.5)
    below = np.flatnonzero(radial < target)
    if len(below) == 0:
        return rms, float("nan")
    k = int(below[0])
    frac = (radial[k - 1] - target) / (radial[k - 1] - radial[k])
    return rms, float((k - 1 + frac) * h)


def deepest_wells(
    u: np.ndarray, mask: np.ndarray, grid: Grid, radius: float, count: int = 3
) -> list[tuple[float, float, float]]:
    """The ``count`` deepest local minima of ``u`` within ``mask``: (x [m], y [m], depth [k_BT]).

    A minimum is the lowest node within ``radius`` [m]; its depth is measured from U's mean
    over the mask (0 by construction of the map).
    """
    size = max(3, int(2 * radius / grid.h) | 1)
    filled = np.where(mask, u, np.inf)
    low = (filled == ndimage.minimum_filter(filled, size=size, mode="constant", cval=np.inf)) & mask
    j, i = np.nonzero(low)
    order = np.argsort(u[j, i])[:count]
    mean = float(np.mean(u[mask]))
    return [(float(grid.x[i[k]]), float(grid.y[j[k]]), float(mean - u[j[k], i[k]])) for k in order]
