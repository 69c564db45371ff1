r"""How well the reshuffler decorrelates: input against output, occupancy and transit times.

Signals as event sequences
--------------------------
The input is the bit sequence :math:`b_k` of the injection events :math:`k = 0, 1, \dots`
(times :math:`t_k`, see :mod:`skygas.sc.signals`): 1 for a skyrmion injected into the UP chamber,
0 for DOWN. The output is the bit sequence :math:`c_m` of the detection events ordered by
detection time :math:`s_0 \le s_1 \le \dots` (1 when the read-out of the UP chamber fires, 0 for
DOWN), built by :func:`output_signal_from_events`.

Alignment convention: by event index
------------------------------------
Every input-output comparison here pairs the :math:`k`-th injected bit with the :math:`k`-th
detected bit, :math:`(b_k, c_k)` for :math:`k < n = \min(N_\mathrm{in}, N_\mathrm{out})`; the
longer sequence is truncated. Why:

* the output has no clock, only an order of events. The paper's output signal is a level that
  switches up (down) at each read-out of the UP (DOWN) chamber, so its value just after the
  :math:`m`-th read-out is :math:`c_m`. Likewise the input signal, sampled at its injection
  instants, is :math:`b_k`. Comparing the two signals sampled on their own events is comparing
  the two event sequences;
* a reshuffler that keeps the order (first in, first out, no losses) gives :math:`c_k = b_k`
  exactly, whatever the transit time, and :math:`\rho = 1`; any reordering lowers
  :math:`\rho`. Comparing in time instead would mix this with the transit delay;
* pairing by skyrmion identity is meaningless: the skyrmion detected from the UP chamber was
  injected with :math:`b = 1`, so that pairing always gives :math:`\rho = 1`.

A skyrmion lost inside a chamber (annihilation) or still inside at the end shifts all later
indices by one; :func:`pearson_vs_lag` scans index lags :math:`\ell` to show such shifts.

The correlation coefficient is the paper's product-moment (Pearson) coefficient
:math:`\rho = \mathrm{cov}(b, c)/(\sigma_b \sigma_c)` over the aligned pairs (for bits, the phi
coefficient, :func:`skygas.sc.metrics.pearson`; 0 when either sequence is constant). The
stochastic-computing correlation SCC (Alaghi & Hayes 2013) is offered as well
(:func:`scc_by_index`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from skygas.core import validate as v
from skygas.core.errors import InputError
from skygas.sc.metrics import PValueEstimate, p_value_interval, pearson, scc
from skygas.sc.signals import as_bits

_UP_LABELS = ("up", "1", "true")
_DOWN_LABELS = ("down", "0", "false")


# ----------------------------------------------------------------------------------- helpers


def _aligned(b: Any, c: Any) -> tuple[np.ndarray, np.ndarray]:
    """Both sequences as booleans, truncated to their common length (index alignment)."""
    b = as_bits(b, "b")
    c = as_bits(c, "c")
    n = min(b.size, c.size)
    return b[:n], c[:n]


def _times(
    values: Any, field: str, *, sorted_: bool = False, allow_empty: bool = True
) -> np.ndarray:
    try:
        array = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise InputError(field, values, "a 1-D sequence of times (seconds)") from None
    if array.ndim != 1:
        raise InputError(field, f"array of shape {array.shape}", "a 1-D sequence of times")
    if not allow_empty and array.size == 0:
        raise InputError(field, "an empty sequence", "at least one time")
    if not np.all(np.isfinite(array)):
        raise InputError(field, values, "finite times (seconds)")
    if sorted_ and np.any(np.diff(array) < 0):
        bad = int(np.flatnonzero(np.diff(array) < 0)[0]) + 1
        raise InputError(
            f"{field}[{bad}]",
            array[bad].item(),
            "times in non-decreasing order (the order of the output events)",
        )
    return array


def as_chambers(labels: Any, field: str = "chambers") -> np.ndarray:
    """Chamber labels as booleans, True for UP: accepts booleans, 0/1 or "up"/"down"."""
    array = np.asarray(labels)
    if array.ndim != 1:
        raise InputError(field, f"array of shape {array.shape}", "a 1-D sequence of chambers")
    if array.size == 0:
        return np.zeros(0, dtype=bool)
    if array.dtype.kind in "US":
        lowered = np.char.lower(np.char.strip(array.astype(str)))
        up = np.isin(lowered, _UP_LABELS)
        bad = np.flatnonzero(~(up | np.isin(lowered, _DOWN_LABELS)))
        if bad.size:
            raise InputError(f"{field}[{bad[0]}]", str(array[bad[0]]), "'up' or 'down'")
        return up
    return as_bits(array, field)


def _same_size(**arrays: np.ndarray) -> None:
    names = list(arrays)
    for name in names[1:]:
        if arrays[name].size != arrays[names[0]].size:
            raise InputError(
                name,
                f"{arrays[name].size} entries",
                f"{arrays[names[0]].size}, one per entry of {names[0]}",
            )


# ----------------------------------------------------------------------- building the output


@dataclass(frozen=True)
class OutputSignal:
    """The output bit sequence :math:`c_m` (True for UP) and its detection times :math:`s_m` [s].

    In detection order; ``order`` maps back to the indices of the given events.
    """

    bits: np.ndarray
    times: np.ndarray
    order: np.ndarray


def output_signal_from_events(detection_times: Any, chambers: Any) -> OutputSignal:
    """Order the detection events by time and read the chambers as bits (UP = 1).

    Simultaneous detections keep the order in which they were given (stable sort).
    """
    times = _times(detection_times, "detection_times", allow_empty=False)
    ups = as_chambers(chambers, "chambers")
    _same_size(detection_times=times, chambers=ups)
    order = np.argsort(times, kind="stable")
    return OutputSignal(ups[order], times[order], order)


# ------------------------------------------------------------------------------ correlations


def pearson_by_index(b: Any, c: Any) -> float:
    r"""Pearson :math:`\rho` between :math:`b_k` and :math:`c_k`, :math:`k < \min(N_b, N_c)`.

    The paper's "product-moment correlation coefficient" of input and output, with the index
    alignment of the module docstring: :math:`\rho = (p_{bc} - p_b p_c)/
    \sqrt{p_b(1-p_b)p_c(1-p_c)}` on the aligned pairs; 0 if either is constant.
    """
    b, c = _aligned(b, c)
    return float(pearson(b, c))


#: contiguous blocks of the aligned pairs left out one at a time by :func:`pearson_error_by_index`
JACKKNIFE_BLOCKS = 20


def pearson_error_by_index(b: Any, c: Any, blocks: int = JACKKNIFE_BLOCKS) -> float:
    r"""Standard error of :func:`pearson_by_index` by the delete-one-block jackknife.

    The aligned pairs are cut into ``blocks`` contiguous blocks; :math:`\rho_{-j}` is the
    coefficient of all pairs but block :math:`j`, and
    :math:`\mathrm{SE}^2 = (B-1)/B \sum_j (\rho_{-j} - \bar\rho_{-})^2` (Efron & Stein).
    Blocks rather than single pairs because neighbouring output bits are correlated (skyrmions
    leave a chamber in bunches): a block much longer than that correlation keeps the error
    honest where the pair-by-pair :math:`1/\sqrt{n}` would be too small.

    Returns
    -------
    float
        The standard error; NaN with fewer than two pairs per block, or when a left-out
        coefficient is undefined (a constant sequence).
    """
    b, c = _aligned(b, c)
    n = b.size
    if blocks < 2 or n < 2 * blocks:
        return float("nan")
    edges = np.linspace(0, n, blocks + 1).astype(int)
    x = np.stack([np.ones(n), b, c, b & c]).astype(float)
    sums = np.add.reduceat(x, edges[:-1], axis=1)  # (4, blocks): n, Σb, Σc, Σbc per block
    left = sums.sum(axis=1, keepdims=True) - sums
    m, pb, pc, pbc = left[0], left[1] / left[0], left[2] / left[0], left[3] / left[0]
    variance = pb * (1 - pb) * pc * (1 - pc)
    if np.any(variance <= 0) or np.any(m < 2):
        return float("nan")
    rho = (pbc - pb * pc) / np.sqrt(variance)
    return float(np.sqrt((blocks - 1) / blocks * np.sum((rho - rho.mean()) ** 2)))


def scc_by_index(b: Any, c: Any) -> float:
    """Stochastic computing correlation (:func:`skygas.sc.metrics.scc`) of the aligned pairs."""
    b, c = _aligned(b, c)
    return float(scc(b, c))


@dataclass(frozen=True)
class LagScan:
    r""":math:`\rho(\ell)` for each lag, and the lag with the largest :math:`|\rho|`."""

    lags: np.ndarray
    rho: np.ndarray
    n_pairs: np.ndarray
    best_lag: int
    best_rho: float


def pearson_vs_lag(b: Any, c: Any, max_lag: int) -> LagScan:
    r"""Pearson :math:`\rho(\ell)` between :math:`b_k` and :math:`c_{k+\ell}`.

    At lags :math:`\ell = -L \dots L`. For each lag all pairs with :math:`0 \le k < N_b` and
    :math:`0 \le k + \ell < N_c` are used (no wrap-around; ``n_pairs`` holds their number).
    :math:`\ell = 0` is :func:`pearson_by_index`. A positive best lag means the output repeats the
    input :math:`\ell` events late (e.g. :math:`\ell` skyrmions were detected that had been
    injected before the input record began). Ties in :math:`|\rho|` go to the smallest
    :math:`|\ell|`.
    """
    b = as_bits(b, "b")
    c = as_bits(c, "c")
    max_lag = v.positive_int(max_lag, "max_lag", minimum=0)
    limit = min(b.size, c.size) - 2
    if max_lag > limit:
        raise InputError(
            "max_lag", max_lag, f"an integer <= {max(limit, 0)} (at least 2 pairs at every lag)"
        )
    lags = np.arange(-max_lag, max_lag + 1)
    rho = np.empty(lags.size)
    n_pairs = np.empty(lags.size, dtype=np.int64)
    for i, lag in enumerate(lags.tolist()):  # Python ints
        first = max(0, -lag)
        stop = min(b.size, c.size - lag)
        rho[i] = pearson(b[first:stop], c[first + lag : stop + lag])
        n_pairs[i] = stop - first
    best = int(np.lexsort((np.abs(lags), -np.abs(rho)))[0])
    return LagScan(lags, rho, n_pairs, int(lags[best]), float(rho[best]))


@dataclass(frozen=True)
class PValueComparison:
    """Input and output p-values with their Clopper-Pearson intervals."""

    p_in: PValueEstimate
    p_out: PValueEstimate
    difference: float
    p_in_within_output_interval: bool


def p_out_vs_p_in(b: Any, c: Any, confidence: float = 0.95) -> PValueComparison:
    r"""Compare the fraction of ones of all input bits and of all output bits.

    Both sequences are used whole (not truncated): the input's p over every injection, the
    output's over every detection. Intervals are exact Clopper-Pearson
    (:func:`skygas.sc.metrics.p_value_interval`); they assume independent bits and are too
    narrow for a correlated (telegraph) input by about :math:`\sqrt{2\tau_c/\Delta}`.
    ``difference`` is :math:`\hat p_\mathrm{out} - \hat p_\mathrm{in}`.
    """
    b = as_bits(b, "b")
    c = as_bits(c, "c")
    est_in = _scalar_estimate(p_value_interval(b, confidence))
    est_out = _scalar_estimate(p_value_interval(c, confidence))
    inside = bool(est_out.low <= est_in.estimate <= est_out.high)
    return PValueComparison(est_in, est_out, float(est_out.estimate - est_in.estimate), inside)


def _scalar_estimate(estimate: PValueEstimate) -> PValueEstimate:
    return PValueEstimate(
        float(estimate.estimate),
        float(estimate.low),
        float(estimate.high),
        estimate.n_bits,
        estimate.confidence,
    )


@dataclass(frozen=True)
class RunningCorrelation:
    r""":math:`\rho` of the first ``n_events`` aligned pairs, at the detection ``times`` [s].

    The detection time of the last of them.
    """

    n_events: np.ndarray
    times: np.ndarray
    rho: np.ndarray


def running_correlation(
    b: Any, c: Any, detection_times: Any, n_points: int = 200
) -> RunningCorrelation:
    r"""Pearson :math:`\rho` of the first :math:`m` index-aligned pairs as the output grows.

    The paper's reshuffler figure (right panel) plots the correlation against time "as the
    output stream is generated": :math:`\rho_m` uses the pairs :math:`(b_k, c_k)`,
    :math:`k < m`, and is plotted at :math:`s_{m-1}`, the detection time of the :math:`m`-th
    output event. ``n_points`` values of :math:`m` are spread evenly over :math:`[2, n]`
    (duplicates dropped); the last is always :math:`m = n`, which equals
    :func:`pearson_by_index`. ``detection_times`` are the output events' times in order
    (:attr:`OutputSignal.times`), one per bit of ``c``.
    """
    b_all = as_bits(b, "b")
    c_all = as_bits(c, "c")
    times = _times(detection_times, "detection_times", sorted_=True)
    _same_size(c=c_all, detection_times=times)
    n_points = v.positive_int(n_points, "n_points")
    b_seq, c_seq = _aligned(b_all, c_all)
    n = b_seq.size
    if n < 2:
        raise InputError("c", f"{n} aligned event(s)", "at least 2 aligned input/output events")
    m = (
        np.unique(np.rint(np.linspace(2, n, n_points)).astype(np.int64))
        if n_points > 1
        else np.array([n])
    )
    # Cumulative counts give every prefix at once with the same formula as sc.metrics.pearson.
    ones_b = np.cumsum(b_seq)[m - 1]
    ones_c = np.cumsum(c_seq)[m - 1]
    ones_bc = np.cumsum(b_seq & c_seq)[m - 1]
    pb, pc, pbc = ones_b / m, ones_c / m, ones_bc / m
    variance = pb * (1 - pb) * pc * (1 - pc)
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = np.sqrt(np.where(variance > 0, variance, 1.0))
        rho = np.where(variance > 0, (pbc - pb * pc) / scale, 0.0)
    return RunningCorrelation(m, times[m - 1], rho)


# ---------------------------------------------------------------------- chamber bookkeeping


@dataclass(frozen=True)
class Occupancy:
    """Number of skyrmions in each chamber at ``times`` [s]."""

    times: np.ndarray
    up: np.ndarray
    down: np.ndarray


def occupancy(
    injection_times: Any,
    injection_chambers: Any,
    detection_times: Any,
    detection_chambers: Any,
    times: Any = None,
    *,
    annihilation_times: Any = (),
    annihilation_chambers: Any = (),
) -> Occupancy:
    r"""Skyrmions present in the UP and DOWN chambers, counted from the event lists.

    :math:`N_X(t) = \#\{\text{injections into } X \text{ at} \le t\}
    - \#\{\text{detections from } X \le t\} - \#\{\text{annihilations in } X \le t\}`:
    an event at exactly :math:`t` has already happened. Chambers are booleans (True = UP),
    0/1 or ``"up"``/``"down"``. With ``times=None`` the counts are given at every event time
    (sorted, unique), so ``up.max()`` is the exact peak occupancy (the paper quotes at most 51
    skyrmions per chamber at its lowest current).
    """

    def events(kind: str, times_: Any, chambers: Any) -> tuple[np.ndarray, np.ndarray]:
        """Validated (times, chambers) of one kind of event (injection, detection, …)."""
        t = _times(times_, f"{kind}_times")
        ch = as_chambers(chambers, f"{kind}_chambers")
        _same_size(**{f"{kind}_times": t, f"{kind}_chambers": ch})
        return t, ch

    t_inj, ch_inj = events("injection", injection_times, injection_chambers)
    t_det, ch_det = events("detection", detection_times, detection_chambers)
    t_ann, ch_ann = events("annihilation", annihilation_times, annihilation_chambers)
    if times is None:
        query = np.unique(np.concatenate([t_inj, t_det, t_ann]))
    else:
        query = _times(np.atleast_1d(times), "times")

    def count(event_times: np.ndarray) -> np.ndarray:
        return np.searchsorted(np.sort(event_times), query, side="right")

    counts = {}
    for label, is_up in (("up", True), ("down", False)):
        counts[label] = (
            count(t_inj[ch_inj == is_up])
            - count(t_det[ch_det == is_up])
            - count(t_ann[ch_ann == is_up])
        )
    return Occupancy(query, counts["up"], counts["down"])


@dataclass(frozen=True)
class TransitTimes:
    """Per-skyrmion transit times [s] of the detected skyrmions, and their summary.

    ``quantiles`` maps each requested probability to its quantile; summary values are NaN when
    no skyrmion was detected. ``n_undetected`` counts injected skyrmions never detected (lost or
    still inside).
    """

    ids: np.ndarray
    transit: np.ndarray
    mean: float
    median: float
    quantiles: dict[float, float]
    n_undetected: int


def _ids(values: Any, field: str) -> np.ndarray:
    array = np.asarray(values)
    if array.ndim != 1 or (array.size and not np.issubdtype(array.dtype, np.integer)):
        raise InputError(field, values, "a 1-D sequence of integer skyrmion ids")
    unique, counts = np.unique(array, return_counts=True)
    if np.any(counts > 1):
        raise InputError(field, int(unique[counts > 1][0]), "each skyrmion id at most once")
    return array.astype(np.int64)


def transit_times(
    injection_ids: Any,
    injection_times: Any,
    detection_ids: Any,
    detection_times: Any,
    quantiles: tuple[float, ...] = (0.05, 0.25, 0.5, 0.75, 0.95),
) -> TransitTimes:
    """Time from injection to detection of each skyrmion, matched by skyrmion id.

    Results follow the order of the detection lists. Every detected id must have been injected,
    and no skyrmion may be detected before it was injected.
    """
    inj_ids = _ids(injection_ids, "injection_ids")
    inj_t = _times(injection_times, "injection_times")
    _same_size(injection_ids=inj_ids, injection_times=inj_t)
    det_ids = _ids(detection_ids, "detection_ids")
    det_t = _times(detection_times, "detection_times")
    _same_size(detection_ids=det_ids, detection_times=det_t)
    probabilities = v.probability(quantiles, "quantiles").ravel()
    order = np.argsort(inj_ids)
    position = np.searchsorted(inj_ids[order], det_ids)
    position = np.minimum(position, max(inj_ids.size - 1, 0))
    if inj_ids.size:
        found = inj_ids[order][position] == det_ids
    else:
        found = np.zeros(det_ids.size, dtype=bool)
    missing = np.flatnonzero(~found)
    if missing.size:
        raise InputError(
            f"detection_ids[{missing[0]}]",
            int(det_ids[missing[0]]),
            "ids that appear in injection_ids",
        )
    transit = det_t - inj_t[order][position]
    early = np.flatnonzero(transit < 0)
    if early.size:
        raise InputError(
            f"detection_times[{early[0]}]",
            det_t[early[0]].item(),
            f"a time no earlier than the skyrmion's injection ({inj_t[order][position][early[0]]})",
        )
    if transit.size:
        mean, median = float(transit.mean()), float(np.median(transit))
        values = np.quantile(transit, probabilities)
    else:
        mean = median = float("nan")
        values = np.full(probabilities.size, np.nan)
    return TransitTimes(
        det_ids,
        transit,
        mean,
        median,
        {float(q): float(x) for q, x in zip(probabilities, values, strict=True)},
        int(inj_ids.size - det_ids.size),
    )
