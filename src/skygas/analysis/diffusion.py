"""Mean-squared displacement and the diffusion constant, with standard errors.

MSD(τ) = ⟨|r(t + τ) − r(t)|²⟩, averaged over every skyrmion and every time origin t of the
record (windowed, overlapping origins). With ``subtract_drift`` the mean displacement at each
lag is removed first: ⟨|Δr − ⟨Δr⟩|²⟩, the spread of a drifting gas.

The diffusion constant follows from MSD = 4 D τ in two dimensions (free Brownian motion,
docs/physics.md): D = Σ_k τ_k MSD(τ_k) / (4 Σ_k τ_k²), the least-squares slope through the
origin over the fitted lags. Standard errors are delete-one-skyrmion jackknife errors
(:mod:`skygas.analysis.jackknife`), which account for the overlapping origins.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skygas.analysis.frames import Frames
from skygas.analysis.jackknife import jackknife_error


@dataclass(frozen=True)
class MSDResult:
    """The mean-squared displacement of a run and the diffusion constant fitted to it.

    ``lag_time`` [s], ``msd`` [m²] and ``msd_error`` [m²] per lag; ``n_pairs`` displacements per
    lag; ``diffusion_constant`` D [m²/s] ± ``diffusion_error`` fitted over the lags ``fit_lags``
    (frames).
    """

    lags: np.ndarray
    lag_time: np.ndarray
    msd: np.ndarray
    msd_error: np.ndarray
    n_pairs: np.ndarray
    diffusion_constant: float
    diffusion_error: float
    fit_lags: np.ndarray
    drift_subtracted: bool

    def as_dict(self) -> dict:
        """The result as a JSON-able dict, SI units in the keys (what ``skygas analyze`` prints)."""
        return {
            "lag_time_s": self.lag_time.tolist(),
            "msd_m2": self.msd.tolist(),
            "msd_error_m2": self.msd_error.tolist(),
            "n_pairs": self.n_pairs.tolist(),
            "diffusion_constant_m2_s": self.diffusion_constant,
            "diffusion_constant_error_m2_s": self.diffusion_error,
            "fit_lag_times_s": (self.fit_lags * self._dt).tolist(),
            "drift_subtracted": self.drift_subtracted,
        }

    @property
    def _dt(self) -> float:
        return float(self.lag_time[0] / self.lags[0]) if len(self.lags) else float("nan")


def default_lags(n_frames: int, count: int = 16) -> np.ndarray:
    """Up to ``count`` log-spaced lags from 1 to a quarter of the record (frames)."""
    top = max(1, (n_frames - 1) // 4)
    return np.unique(np.round(np.geomspace(1, top, count)).astype(np.int64))


def mean_squared_displacement(
    frames: Frames, lags=None, *, fit_lags=None, subtract_drift: bool = False
) -> MSDResult:
    """MSD over overlapping time origins, and D fitted to it, with jackknife errors.

    Frames must be evenly spaced in time.

    Parameters
    ----------
    frames : Frames
        The recorded positions.
    lags : array of int, optional
        The lags [frames] (default :func:`default_lags`); those not shorter than the record are
        dropped.
    fit_lags : array of int, optional
        The lags D is fitted over (default: the shortest lags, up to five, where the motion is still
        free in a crowded or confined gas).
    subtract_drift : bool
        Remove the mean displacement at each lag first: ⟨|Δr − ⟨Δr⟩|²⟩, the spread of a drifting
        gas.

    Returns
    -------
    MSDResult
        MSD [m²] per lag and D [m²/s], each with its standard error.

    Raises
    ------
    ValueError
        If the frames are not evenly spaced, or no lag is shorter than the record.
    """
    dt = frames.frame_interval()
    lags = default_lags(frames.n_frames) if lags is None else np.asarray(lags, np.int64)
    lags = lags[(lags >= 1) & (lags < frames.n_frames)]
    if len(lags) == 0:
        raise ValueError("no lag shorter than the record")
    fit = lags[:5] if fit_lags is None else np.intersect1d(np.asarray(fit_lags, np.int64), lags)
    _, group = np.unique(frames.ids, return_inverse=True)
    n_groups = int(group.max()) + 1 if len(group) else 0
    # per skyrmion and lag: [count, Σdx, Σdy, Σ|d|²]
    sums = np.zeros((n_groups, len(lags), 4))
    for k, lag in enumerate(lags):
        a, b = frames.pairs_at_lag(int(lag))
        dx, dy = frames.x[b] - frames.x[a], frames.y[b] - frames.y[a]
        g = group[a]
        for c, v in enumerate((np.ones_like(dx), dx, dy, dx * dx + dy * dy)):
            sums[:, k, c] = np.bincount(g, weights=v, minlength=n_groups)
    tau = lags * dt
    in_fit = np.isin(lags, fit)

    def msd_of(total):
        n = np.maximum(total[..., 0], 1)
        value = total[..., 3] / n
        if subtract_drift:
            value = value - (total[..., 1] ** 2 + total[..., 2] ** 2) / n**2
        return value

    def d_of(total):
        m = msd_of(total)[..., in_fit]
        return np.sum(tau[in_fit] * m, axis=-1) / (4.0 * np.sum(tau[in_fit] ** 2))

    total = sums.sum(axis=0)
    return MSDResult(
        lags,
        tau,
        msd_of(total),
        jackknife_error(sums, msd_of),
        total[:, 0].astype(np.int64),
        float(d_of(total)),
        float(jackknife_error(sums, d_of)),
        lags[in_fit],
        subtract_drift,
    )
