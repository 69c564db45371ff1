"""D read off the mean-squared displacement, and the blocks of time every error uses.

The model's D comes from the noise of the steps (:mod:`skygas.inference.dynamics`). This module
keeps the classic reading for comparison: a tracked position is the true one plus a static
localisation error of variance σ² per coordinate, and a skyrmion in a landscape also drifts, so
over the first frame lags

    MSD(τ) = 4 σ² + 4 D τ + ⟨v²⟩ τ² + O(τ³)

in two dimensions, fitted as a quadratic through lags 1 … :data:`FIT_LAGS`. In a crowded gas
of gyrotropic skyrmions this reads more than the free D: the neighbours' pushes within a frame,
turned by the gyrotropic mobility, add to the spread of the steps.

Frames are correlated, so standard errors come from **blocking**: the record is cut into
:data:`BLOCKS` contiguous blocks of time (:func:`time_blocks`, :func:`block_of_frame`), the
quantity is computed in each, and the error is s/√blocks (:func:`blocked`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skygas.analysis.frames import Frames

#: Frame lags 1 … FIT_LAGS fit D and σ².
FIT_LAGS = 3
#: Contiguous blocks of time for the blocking standard errors.
BLOCKS = 16
#: A skyrmion needs this many displacements at lag 1 for its own D.
MIN_TRACK = 20


@dataclass(frozen=True)
class Diffusion:
    """D [m²/s] ± ``error``; σ [m] the localisation error per coordinate ± ``sigma_error``.

    ``lag_time`` [s] and ``msd`` [m²] the fitted points; ``per_skyrmion`` (ids, D [m²/s]) of the
    skyrmions tracked long enough; ``blocks`` the number of blocks of the errors.
    """

    diffusion_constant: float
    error: float
    sigma: float
    sigma_error: float
    lag_time: np.ndarray
    msd: np.ndarray
    per_skyrmion_ids: np.ndarray
    per_skyrmion: np.ndarray
    blocks: int

    def as_dict(self) -> dict:
        """JSON-able, SI units in the keys."""
        d = self.per_skyrmion
        return {
            "diffusion_constant": self.diffusion_constant,
            "diffusion_constant_error": self.error,
            "localisation_error_m": self.sigma,
            "localisation_error_error_m": self.sigma_error,
            "fit_lag_times_s": self.lag_time.tolist(),
            "fit_msd_m2": self.msd.tolist(),
            "error_blocks": self.blocks,
            "per_skyrmion": {
                "particle": self.per_skyrmion_ids.tolist(),
                "diffusion_constant": d.tolist(),
                "median": float(np.median(d)) if len(d) else None,
                "quartiles": np.percentile(d, [25, 75]).tolist() if len(d) else None,
            },
        }


def fit_line(tau: np.ndarray, msd: np.ndarray) -> tuple[float, float]:
    """(D [m²/s], σ² [m²]) of MSD = 4σ² + 4Dτ + cτ² (least squares; a line with two lags)."""
    if len(tau) < 3:
        slope, intercept = np.polyfit(tau, msd, 1)
    else:
        _, slope, intercept = np.polyfit(tau, msd, 2)
    return float(slope / 4.0), float(intercept / 4.0)


def time_blocks(n_frames: int, blocks: int) -> list[np.ndarray]:
    """``blocks`` contiguous, nearly equal runs of frame indices covering 0 … n_frames − 1."""
    edges = np.linspace(0, n_frames, blocks + 1).round().astype(int)
    return [np.arange(a, b) for a, b in zip(edges[:-1], edges[1:], strict=True) if b > a]


def block_of_frame(n_frames: int, blocks: int) -> np.ndarray:
    """The block of :func:`time_blocks` each frame 0 … n_frames − 1 falls in."""
    out = np.zeros(n_frames, int)
    for k, frames in enumerate(time_blocks(n_frames, blocks)):
        out[frames] = k
    return out


def blocked(values: np.ndarray) -> float:
    """Standard error of the mean of per-block values (independent blocks)."""
    values = np.asarray(values, float)
    values = values[np.isfinite(values)]
    if len(values) < 2:
        return float("nan")
    return float(np.std(values, ddof=1) / np.sqrt(len(values)))


def _msd_sums(frames: Frames, lags: np.ndarray, blocks: int) -> tuple[np.ndarray, np.ndarray]:
    """Σ r² [m²] and counts (blocks, lags) of the displacements at ``lags`` [frames].

    Each displacement goes to the block of time its start falls in.
    """
    block_of = block_of_frame(frames.n_frames, blocks)
    sums = np.zeros((blocks, len(lags)))
    counts = np.zeros((blocks, len(lags)))
    for k, lag in enumerate(lags):
        a, b = frames.pairs_at_lag(int(lag))
        r2 = (frames.x[b] - frames.x[a]) ** 2 + (frames.y[b] - frames.y[a]) ** 2
        blk = block_of[frames.frame_of_entry[a]]
        sums[:, k] = np.bincount(blk, weights=r2, minlength=blocks)
        counts[:, k] = np.bincount(blk, minlength=blocks)
    return sums, counts


def estimate_diffusion(
    frames: Frames,
    *,
    fit_lags: int = FIT_LAGS,
    blocks: int = BLOCKS,
) -> Diffusion:
    """D and σ from the short-lag MSD of ``frames``, with blocked standard errors.

    Raises ValueError if the record has fewer frames than ``fit_lags + 1``.
    """
    lags = np.arange(1, min(fit_lags, frames.n_frames - 1) + 1)
    if len(lags) < 2:
        raise ValueError("at least three frames are needed to fit D and the localisation error")
    dt = frames.frame_interval()
    tau = lags * dt
    sums, counts = _msd_sums(frames, lags, blocks)
    msd = sums.sum(axis=0) / np.maximum(counts.sum(axis=0), 1)
    d, s2 = fit_line(tau, msd)
    # blocks long enough to hold the longest lag, each fitted alone
    usable = [k for k in range(blocks) if np.all(counts[k] > 0)]
    per_block = np.array([fit_line(tau, sums[k] / counts[k]) for k in usable]).reshape(-1, 2)
    d_err = blocked(per_block[:, 0]) if len(per_block) else float("nan")
    s2_err = blocked(per_block[:, 1]) if len(per_block) else float("nan")
    sigma = float(np.sqrt(max(s2, 0.0)))
    sigma_err = float(s2_err / (2 * sigma)) if sigma > 0 else float(np.sqrt(max(s2_err, 0.0)))
    ids, per = per_skyrmion_diffusion(frames, lags, s2)
    return Diffusion(d, d_err, sigma, sigma_err, tau, msd, ids, per, len(per_block))


def per_skyrmion_diffusion(
    frames: Frames, lags: np.ndarray, sigma2: float
) -> tuple[np.ndarray, np.ndarray]:
    """Each long-enough skyrmion's D [m²/s], the ensemble's σ² [m²] as the MSD's intercept.

    MSD_i(τ) − 4σ² = 4 D_i τ + c_i τ² by least squares over ``lags`` (through the origin with
    two lags).
    """
    dt = frames.frame_interval()
    ids, group = np.unique(frames.ids, return_inverse=True)
    sums = np.zeros((len(ids), len(lags)))
    counts = np.zeros((len(ids), len(lags)))
    for k, lag in enumerate(lags):
        a, b = frames.pairs_at_lag(int(lag))
        r2 = (frames.x[b] - frames.x[a]) ** 2 + (frames.y[b] - frames.y[a]) ** 2
        sums[:, k] = np.bincount(group[a], weights=r2, minlength=len(ids))
        counts[:, k] = np.bincount(group[a], minlength=len(ids))
    keep = counts[:, 0] >= MIN_TRACK
    msd = sums[keep] / np.maximum(counts[keep], 1)
    tau = lags * dt
    design = np.column_stack([4 * tau, tau**2]) if len(tau) >= 3 else (4 * tau)[:, None]
    coef = np.linalg.lstsq(design, (msd - 4 * sigma2).T, rcond=None)[0]
    return ids[keep], coef[0]
