"""The radial distribution function g(r) of a gas confined to a region.

In a bounded region, pairs at distance r are rarer than in the bulk even for an ideal gas,
because fewer displacements of length r keep both points inside. The estimator divides the
observed pair counts by those of uniform, independent points in the same region:

    g(r) = C(r) / (Σ_frames n_f(n_f − 1)/2 · P(r)),
    P(r) dr = 2π r γ̄(r) dr / A²,

where A is the area and γ̄(r) the isotropic set covariogram: the area of region ∩ (region
shifted by r) averaged over directions. So g(r) = 1 at every r for an ideal gas, walls or not
(Ripley's isotropic correction, in its covariogram form).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from shapely import affinity

from skygas.analysis.frames import Frames
from skygas.core.units import M_TO_NM

#: contiguous blocks of frames for the jackknife error of g(r)
ERROR_BLOCKS = 20


@dataclass(frozen=True)
class PairCorrelation:
    """The pair correlation function g(r), normalised for the confinement.

    Bin ``edges`` [m], ``r`` centres [m], ``g`` and its standard ``error``; ``pairs`` counted and
    ``expected`` for an ideal gas per bin. The error is a jackknife over :data:`ERROR_BLOCKS`
    contiguous blocks of frames (pairs that share a skyrmion are correlated, and so are nearby
    frames, so Poisson errors would be too small).
    """

    edges: np.ndarray
    r: np.ndarray
    g: np.ndarray
    error: np.ndarray
    pairs: np.ndarray
    expected: np.ndarray

    def as_dict(self) -> dict:
        """The result as a JSON-able dict, SI units in the keys (what ``skygas analyze`` prints)."""
        return {
            "r_m": self.r.tolist(),
            "g": self.g.tolist(),
            "g_error": self.error.tolist(),
            "pairs": self.pairs.tolist(),
            "expected_ideal_pairs": self.expected.tolist(),
        }


def isotropic_covariogram(region, r_nm, n_angles: int = 12) -> np.ndarray:
    """The isotropic covariogram γ̄(r) [nm²] of ``region`` (a shapely geometry in nm).

    γ̄(r) is the area of ``region`` ∩ (``region`` + r·e_θ) averaged over θ ∈ [0, π) (the covariogram
    is even in θ).
    """
    angles = (np.arange(n_angles) + 0.5) * np.pi / n_angles
    out = np.empty(len(r_nm))
    for i, r in enumerate(np.asarray(r_nm, float)):
        out[i] = np.mean(
            [
                region.intersection(affinity.translate(region, r * np.cos(a), r * np.sin(a))).area
                for a in angles
            ]
        )
    return out


def ideal_pair_probability(region, edges_nm, sub: int = 2, n_angles: int = 12) -> np.ndarray:
    """Probability per distance bin that two uniform points of ``region`` lie that far apart.

    Two independent uniform points: ∫ 2π r γ̄(r) dr / A² over each bin (midpoint rule on
    ``sub`` points per bin).
    """
    edges_nm = np.asarray(edges_nm, float)
    width = np.diff(edges_nm)
    t = (np.arange(sub) + 0.5) / sub
    r = (edges_nm[:-1, None] + width[:, None] * t[None, :]).ravel()
    gamma = isotropic_covariogram(region, r, n_angles).reshape(len(width), sub)
    density = 2 * np.pi * r.reshape(len(width), sub) * gamma
    return density.mean(axis=1) * width / region.area**2


def pair_correlation(
    frames: Frames,
    region,
    r_max: float,
    bins: int = 40,
    max_frames: int = 400,
    error_blocks: int = ERROR_BLOCKS,
) -> PairCorrelation:
    """The pair correlation function g(r) for 0 ≤ r ≤ ``r_max``.

    Parameters
    ----------
    frames : Frames
        The recorded positions.
    region : Outline or shapely geometry
        The area the skyrmions' centres explore: an :class:`~skygas.physics.geometry.Outline` (its
        region) or a shapely geometry in nm.
    r_max : float
        The largest distance [m].
    bins : int
        Bins of equal width over [0, ``r_max``].
    max_frames : int
        At most this many frames are used, evenly chosen.
    error_blocks : int
        Contiguous blocks of frames for the jackknife error (fewer, longer blocks where pairs
        last long: blocks shorter than that are correlated, and the error too small).

    Returns
    -------
    PairCorrelation
        g per bin, with its jackknife error, normalised by the ideal gas in ``region``.
    """
    from scipy.spatial.distance import pdist

    region = getattr(region, "region", region)
    edges_nm = np.linspace(0.0, r_max * M_TO_NM, bins + 1)
    chosen = (
        np.unique(np.linspace(0, frames.n_frames - 1, min(max_frames, frames.n_frames)).astype(int))
        if frames.n_frames
        else np.empty(0, int)
    )
    block_of = (np.arange(len(chosen)) * error_blocks) // max(len(chosen), 1)
    counts = np.zeros((error_blocks, bins))
    pairs = np.zeros(error_blocks)
    off = frames.offsets
    for f, block in zip(chosen, block_of, strict=True):
        a, b = off[f], off[f + 1]
        n = b - a
        if n < 2:
            continue
        xy = np.column_stack([frames.x[a:b], frames.y[a:b]]) * M_TO_NM
        counts[block] += np.histogram(pdist(xy), edges_nm)[0]
        pairs[block] += n * (n - 1) / 2
    probability = ideal_pair_probability(region, edges_nm)
    expected = pairs.sum() * probability
    with np.errstate(invalid="ignore", divide="ignore"):
        g = counts.sum(axis=0) / expected
        used = pairs > 0
        k = int(used.sum())
        left_out = (counts.sum(axis=0) - counts[used]) / (
            (pairs.sum() - pairs[used])[:, None] * probability
        )
        error = (
            np.sqrt((k - 1) / k * np.sum((left_out - left_out.mean(axis=0)) ** 2, axis=0))
            if k >= 2
            else np.full(bins, np.nan)
        )
    counts = counts.sum(axis=0)
    return PairCorrelation(
        edges_nm / M_TO_NM,
        0.5 * (edges_nm[1:] + edges_nm[:-1]) / M_TO_NM,
        g,
        error,
        counts,
        expected,
    )
