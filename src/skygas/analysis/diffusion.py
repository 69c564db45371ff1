"""Mean-squared displacement and the diffusion constant, with standard errors.

MSD(τ) = ⟨|r(t + τ) − r(t)|²⟩, averaged over every skyrmion and every time origin t of the
record (windowed, overlapping origins). With ``subtract_drift`` the mean displacement at each
lag is removed first: ⟨|Δr − ⟨Δr⟩|²⟩, the spread of a drifting gas.

The diffusion constant follows from MSD = 4 D τ in two dimensions (free Brownian motion,
docs/physics.md): D = Σ_k τ_k MSD(τ_k) / (4 Σ_k τ_k²), the least-squares slope through the
origin over the fitted lags. Standard errors are delete-one-skyrmion jackknife errors
(:mod:`skygas.analysis.jackknife`), which account for the overlapping origins.

:func:`diffusion_estimate` decides what the MSD can support. It reports

- the **short-time** D₀, fitted over the first :data:`SHORT_LAGS` frame lags (always these,
  whatever lags were asked for), only where MSD(τ)/4τ is flat over them: where it already falls
  (a confined, pinned or crowded gas recorded too sparsely), the frames cannot resolve free
  diffusion and D₀ is absent, with the reason;
- the **long-time** D_eff, the plateau of MSD(τ)/4τ over the last half-decade of lags, only
  where it is flat there: in a closed chamber the MSD saturates and there is none;
- MSD(τ)/4τ itself with its errors, the curve on which both are read.

A burn-in [s] drops the first frames (a run that starts from random placement relaxes first).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from skygas.analysis.frames import Frames
from skygas.analysis.jackknife import jackknife_error
from skygas.core.quantities import format_value


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
    #: Each skyrmion's share of the sums per lag, (skyrmions, lags, 4): count, Σdx, Σdy, Σ|d|²
    #: (for jackknife errors of any statistic of the curve, :meth:`ratio_change`).
    per_skyrmion_sums: np.ndarray | None = field(default=None, repr=False, compare=False)

    def ratio_change(self, first: int, last: int) -> tuple[float, float]:
        """Relative change of MSD(τ)/4τ from lag index ``first`` to ``last``, and its error.

        The change c = R(τ_last)/R(τ_first) − 1 of R = MSD/4τ, with its delete-one-skyrmion
        jackknife standard error. The lags share time origins and paths, so their MSDs are
        strongly correlated: the error of the change is much smaller than the two lags' errors
        added in quadrature, and a steady rise or fall is resolved that the per-lag error bars
        would hide.
        """
        tau = self.lag_time[[first, last]]

        def change(total):
            ratio = _msd_of_sums(total[..., [first, last], :], self.drift_subtracted) / tau
            return ratio[..., 1] / ratio[..., 0] - 1.0

        if self.per_skyrmion_sums is None:
            raise ValueError("this MSD was computed without its per-skyrmion sums")
        sums = self.per_skyrmion_sums
        # a left-out skyrmion may have been the only one at a lag: its sample is NaN, and so
        # is the error (then the change counts as resolved, the cautious side)
        with np.errstate(invalid="ignore", divide="ignore"):
            return float(change(sums.sum(axis=0))), float(jackknife_error(sums, change))

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


#: Frame lags 1 … SHORT_LAGS fit the short-time diffusion constant.
SHORT_LAGS = 4
#: Largest relative change of MSD(τ)/4τ across a fit range that still counts as flat (linear
#: MSD), when the change is also significant (beyond 3 standard errors).
FLATNESS = 0.2


def _msd_of_sums(total: np.ndarray, subtract_drift: bool) -> np.ndarray:
    """MSD [m²] from sums (..., lags, 4) of count, Σdx, Σdy, Σ|d|² (drift removed if asked)."""
    n = np.maximum(total[..., 0], 1)
    value = total[..., 3] / n
    if subtract_drift:
        value = value - (total[..., 1] ** 2 + total[..., 2] ** 2) / n**2
    return value


def _seconds(t: float) -> str:
    """A time [s] as a reader writes it (``40 ns``): :func:`skygas.core.quantities.format_value`."""
    return format_value(t, unit="s", digits=3) or "?"


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
        The lags [frames] D is fitted over (default: 1 … :data:`SHORT_LAGS`, the shortest, where
        the motion is still free in a crowded or confined gas; they are computed whatever
        ``lags`` holds, so D does not depend on the lags asked for).
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
    fit = np.arange(1, SHORT_LAGS + 1) if fit_lags is None else np.asarray(fit_lags, np.int64)
    lags = np.union1d(lags, fit)
    lags = lags[(lags >= 1) & (lags < frames.n_frames)]
    if len(lags) == 0:
        raise ValueError("no lag shorter than the record")
    fit = np.intersect1d(fit, lags)
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
        return _msd_of_sums(total, subtract_drift)

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
        sums,
    )


@dataclass(frozen=True)
class DiffusionEstimate:
    """What an MSD supports: D₀ and D_eff [m²/s] where it does, the reasons where it does not.

    ``short_time`` / ``long_time`` are (D, error) or ``None``; ``short_reason`` /
    ``long_reason`` say why one is absent. ``msd_over_4tau`` and its error [m²/s] per lag of
    ``msd`` are the curve both are read on; ``burn_in`` [s] the time dropped at the start.
    """

    msd: MSDResult
    msd_over_4tau: np.ndarray
    msd_over_4tau_error: np.ndarray
    short_time: tuple[float, float] | None
    short_reason: str | None
    long_time: tuple[float, float] | None
    long_reason: str | None
    long_lag_times: np.ndarray
    burn_in: float

    def as_dict(self) -> dict:
        """JSON-able, SI units in the keys; ``None`` where a constant is not supported."""
        return {
            "short_time_diffusion_m2_s": None if self.short_time is None else self.short_time[0],
            "short_time_diffusion_error_m2_s": None
            if self.short_time is None
            else self.short_time[1],
            "short_time_lag_times_s": (self.msd.fit_lags * self.msd._dt).tolist(),
            "short_time_reason": self.short_reason,
            "long_time_diffusion_m2_s": None if self.long_time is None else self.long_time[0],
            "long_time_diffusion_error_m2_s": None if self.long_time is None else self.long_time[1],
            "long_time_lag_times_s": self.long_lag_times.tolist(),
            "long_time_reason": self.long_reason,
            "lag_time_s": self.msd.lag_time.tolist(),
            "msd_over_4tau_m2_s": self.msd_over_4tau.tolist(),
            "msd_over_4tau_error_m2_s": self.msd_over_4tau_error.tolist(),
            "burn_in_s": self.burn_in,
            "drift_subtracted": self.msd.drift_subtracted,
        }


def _flat(msd: MSDResult, where: np.ndarray) -> tuple[bool, float]:
    """Whether MSD(τ)/4τ stays flat over the lags ``where`` selects, and its relative change.

    Flat unless the change from the first to the last of those lags exceeds :data:`FLATNESS`
    and three of its standard errors (the jackknife error of the change itself,
    :meth:`MSDResult.ratio_change`, which knows that neighbouring lags are correlated).
    """
    index = np.flatnonzero(where)
    change, error = msd.ratio_change(int(index[0]), int(index[-1]))
    if not np.isfinite(change):
        return False, change
    significant = not np.isfinite(error) or abs(change) > 3 * error  # NaN: cannot tell
    return not (abs(change) > FLATNESS and significant), change


def diffusion_estimate(
    frames: Frames,
    lags=None,
    *,
    burn_in: float = 0.0,
    subtract_drift: bool = False,
    min_pairs: int = 100,
) -> DiffusionEstimate:
    """The short- and long-time diffusion constants that the MSD of ``frames`` supports.

    Parameters
    ----------
    frames : Frames
        The recorded positions, evenly spaced in time.
    lags : array of int, optional
        The lags [frames] of the MSD curve (default :func:`default_lags`); frame lags
        1 … :data:`SHORT_LAGS` are always added.
    burn_in : float
        Time [s] dropped at the start of the record (the run's relaxation from its start).
    subtract_drift : bool
        Remove the mean displacement at each lag (a drifting gas).
    min_pairs : int
        Displacements a lag needs to enter the long-time plateau.

    Returns
    -------
    DiffusionEstimate
        D₀ from the short lags where MSD(τ)/4τ is flat there, D_eff from the plateau of
        MSD(τ)/4τ over the last half-decade of lags where it has one; each absent, with the
        reason, where the record cannot support it.

    Raises
    ------
    ValueError
        If the frames are not evenly spaced, or no lag is shorter than the record after the
        burn-in.
    """
    if burn_in < 0:
        raise ValueError("burn_in must be >= 0")
    if burn_in > 0:
        frames = frames.window(start=float(frames.time[0]) + burn_in)
    msd = mean_squared_displacement(frames, lags, subtract_drift=subtract_drift)
    tau = msd.lag_time
    ratio = msd.msd / (4 * tau)
    ratio_error = msd.msd_error / (4 * tau)
    dt = msd._dt

    short = np.isin(msd.lags, msd.fit_lags)
    short_time: tuple[float, float] | None = None
    short_reason = None
    if short.sum() < 2:
        short_reason = "the record is too short for the first frame lags"
    else:
        flat, change = _flat(msd, short)
        if flat:
            short_time = (msd.diffusion_constant, msd.diffusion_error)
        else:
            span = f"between lags of {_seconds(tau[short][0])} and {_seconds(tau[short][-1])}"
            if change > 0:
                # a rise is not a resolution problem: the motion is faster than diffusive there
                short_reason = (
                    f"MSD(τ)/4τ rises by {100 * change:+.0f} % {span}: the motion is not "
                    "diffusive over these lags (a drift, or a gas still relaxing from where it "
                    "started: leave out the start with a burn-in)"
                )
            else:
                short_reason = (
                    f"MSD(τ)/4τ changes by {100 * change:+.0f} % {span}: the frames are too far "
                    "apart to resolve free diffusion (walls, pinning or neighbours act within one "
                    f"frame); record more often than every {_seconds(dt)}"
                )

    enough = msd.n_pairs >= min_pairs
    top = tau[enough].max() if enough.any() else 0.0
    long = enough & (tau >= top / np.sqrt(10))
    long_time: tuple[float, float] | None = None
    long_reason = None
    if long.sum() < 2 or top < 10 * tau[0]:
        long_reason = (
            "the record is too short: its longest well-sampled lag is less than ten frame intervals"
        )
    else:
        flat, change = _flat(msd, long)
        if flat:
            weights = 1.0 / np.maximum(ratio_error[long], 1e-300) ** 2
            value = float(np.sum(weights * ratio[long]) / np.sum(weights))
            # the lags' errors are correlated (overlapping origins): quote the largest, not
            # the error of their weighted mean
            long_time = (value, float(np.max(ratio_error[long])))
        else:
            long_reason = (
                f"MSD(τ)/4τ still changes by {100 * change:+.0f} % over the longest lags "
                f"({_seconds(tau[long][0])} to {_seconds(tau[long][-1])}): no plateau (a confined "
                "gas's MSD saturates, and a slow one has not reached its long-time regime)"
            )
    return DiffusionEstimate(
        msd,
        ratio,
        ratio_error,
        short_time,
        short_reason,
        long_time,
        long_reason,
        tau[long] if long.any() else np.empty(0),
        float(burn_in),
    )
