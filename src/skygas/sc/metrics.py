r"""Correlation and accuracy metrics for bitstreams of shape ``(..., N)``.

All functions reduce over the last (time) axis and broadcast over the leading ones. With
:math:`p_x, p_y` the fractions of ones and :math:`p_{xy}` the fraction of clocks where both
streams are 1, the *overlap* :math:`\Delta = p_{xy} - p_x p_y` is what every correlation
measure below normalises differently:

* :func:`scc` -- stochastic computing correlation (Alaghi & Hayes 2013), +1 at maximal overlap,
  -1 at minimal overlap;
* :func:`pearson` -- the phi coefficient, the paper's :math:`\rho_{X,Y}` (section "Skyrmion
  Reshuffler");
* :func:`zce` -- zero correlation error, which is 0 whenever the alignment is as independent as
  N bits allow.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import special

from skygas.core import validate as v
from skygas.core.errors import InputError


def _pair(x: Any, y: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    x = v.as_stream(x, "x")
    y = v.as_stream(y, "y")
    v.same_length(x=x, y=y)
    n_bits = x.shape[-1]
    px = np.count_nonzero(x, axis=-1) / n_bits
    py = np.count_nonzero(y, axis=-1) / n_bits
    pxy = np.count_nonzero(x & y, axis=-1) / n_bits
    return x, y, px, py, pxy


def p_value(stream: Any) -> np.ndarray:
    """Fraction of ones along the last axis (the encoded value)."""
    stream = v.as_stream(stream, "stream")
    return np.count_nonzero(stream, axis=-1) / stream.shape[-1]


@dataclass(frozen=True)
class PValueEstimate:
    """A p-value estimate with its two-sided confidence interval.

    Arrays of the batch shape; floats for one stream, as :mod:`skygas.reshuffler.correlation`
    reports them.
    """

    estimate: np.ndarray | float
    low: np.ndarray | float
    high: np.ndarray | float
    n_bits: int
    confidence: float


def p_value_interval(stream: Any, confidence: float = 0.95) -> PValueEstimate:
    r"""p-value estimate with the exact Clopper-Pearson binomial confidence interval.

    With :math:`k` ones in :math:`N` bits and :math:`\alpha = 1 - \text{confidence}`:
    :math:`\text{low} = B^{-1}(\alpha/2; k, N-k+1)`,
    :math:`\text{high} = B^{-1}(1-\alpha/2; k+1, N-k)` (beta quantiles; 0 and 1 at the edges).
    The interval covers the true p with probability at least ``confidence`` *for independent
    bits*; for autocorrelated streams (telegraph noise) it is too narrow by the factor in
    :func:`skygas.sc.bitstreams.telegraph_stream`.
    """
    stream = v.as_stream(stream, "stream")
    if not (isinstance(confidence, (int, float)) and 0.0 < confidence < 1.0):
        raise InputError("confidence", confidence, "a number strictly between 0 and 1")
    n_bits = stream.shape[-1]
    ones = np.count_nonzero(stream, axis=-1)
    alpha = 1.0 - confidence
    # B⁻¹ through scipy.special (scipy.stats.beta.ppf calls the same function, but importing
    # scipy.stats costs ~1 s in every new process, a Dask worker's included)
    with np.errstate(invalid="ignore"):
        low = np.where(ones == 0, 0.0, special.betaincinv(ones, n_bits - ones + 1, alpha / 2))
        high = np.where(
            ones == n_bits, 1.0, special.betaincinv(ones + 1, n_bits - ones, 1 - alpha / 2)
        )
    return PValueEstimate(ones / n_bits, low, high, n_bits, float(confidence))


def binomial_std(p: Any, n_bits: Any) -> np.ndarray:
    r"""Standard deviation :math:`\sqrt{p(1-p)/N}` of the p-value of N independent bits."""
    prob = v.probability(p, "p")
    n = np.asarray(n_bits, dtype=float)
    if np.any(n < 1):
        raise InputError("n_bits", n_bits, "integers >= 1")
    return np.sqrt(prob * (1.0 - prob) / n)


def scc(x: Any, y: Any) -> np.ndarray:
    r"""Stochastic computing correlation (SCC) of two streams.

    Alaghi & Hayes, ICCD 2013, "Exploiting correlation in stochastic circuit design":

    .. math::

        \mathrm{SCC} = \begin{cases}
          \dfrac{p_{xy} - p_x p_y}{\min(p_x, p_y) - p_x p_y} & p_{xy} > p_x p_y \\[1ex]
          \dfrac{p_{xy} - p_x p_y}{p_x p_y - \max(p_x + p_y - 1, 0)} & \text{otherwise}
        \end{cases}

    +1 means the ones overlap as much as possible (identical streams), -1 as little as possible
    (a stream and its complement), 0 means :math:`p_{xy} = p_x p_y`. When a stream is constant
    (:math:`p \in \{0, 1\}`) both denominators vanish, but then :math:`p_{xy} = p_x p_y`
    necessarily, and 0 is returned.
    """
    _, _, px, py, pxy = _pair(x, y)
    delta = pxy - px * py
    positive = np.minimum(px, py) - px * py
    negative = px * py - np.maximum(px + py - 1.0, 0.0)
    denominator = np.where(delta > 0, positive, negative)
    with np.errstate(invalid="ignore", divide="ignore"):
        value = np.where(denominator > 0, delta / np.where(denominator > 0, denominator, 1.0), 0.0)
    return np.clip(value, -1.0, 1.0)


def pearson(x: Any, y: Any) -> np.ndarray:
    r"""Pearson correlation (phi coefficient) of two bitstreams.

    :math:`\rho = (p_{xy} - p_x p_y)/\sqrt{p_x(1-p_x)\,p_y(1-p_y)}`; 0 for a constant stream.
    Unlike the SCC it reaches :math:`\pm 1` only when :math:`p_x = p_y` (resp.
    :math:`p_x = 1 - p_y`).
    """
    _, _, px, py, pxy = _pair(x, y)
    variance = px * (1 - px) * py * (1 - py)
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = np.sqrt(np.where(variance > 0, variance, 1.0))
        return np.where(variance > 0, (pxy - px * py) / scale, 0.0)


def zce(x: Any, y: Any) -> np.ndarray:
    r"""Zero correlation error (ZCE) of two streams.

    Hsiao et al., "Zero Correlation Error: A Metric for Finite-Length Bitstream Independence in
    Stochastic Computing".

    N bits can only represent :math:`p_{xy}` in steps of :math:`1/N`, so even the most
    independent alignment misses :math:`p_x p_y` by
    :math:`\Delta_0 = \mathrm{round}(N p_x p_y)/N - p_x p_y`. With
    :math:`\Delta = p_{xy} - p_x p_y`,

    .. math::  \mathrm{ZCE} = \operatorname{sign}(\Delta)\,\bigl(|\Delta| - |\Delta_0|\bigr),

    which is 0 exactly for the most independent alignments, keeps the sign of the correlation,
    and has the units of a p-value error (the AND-gate multiplication error beyond quantisation).
    """
    x, _, px, py, pxy = _pair(x, y)
    n_bits = x.shape[-1]
    product = px * py
    delta = pxy - product
    # |Delta0| does not depend on how ties round: both neighbours are 1/(2N) away.
    delta0 = np.abs(np.floor(n_bits * product + 0.5) / n_bits - product)
    excess = np.maximum(np.abs(delta) - delta0, 0.0)
    # Remove float round-off so that optimal alignments give exactly 0.
    excess = np.where(excess < 1e-12, 0.0, excess)
    return np.sign(delta) * excess


def cross_correlation(x: Any, y: Any, lags: Any) -> np.ndarray:
    r"""Pearson correlation between :math:`x_t` and :math:`y_{t+k}` for each lag :math:`k`.

    Computed on the overlapping part (:math:`N - |k|` bits, no wrap-around), so the result for
    lag k is exactly 1 when ``y`` is ``x`` delayed by k clocks. Returns an array of shape
    ``batch + (len(lags),)``.
    """
    x = v.as_stream(x, "x")
    y = v.as_stream(y, "y")
    lead = v.same_length(x=x, y=y)
    n_bits = x.shape[-1]
    lag_list = np.atleast_1d(np.asarray(lags))
    if lag_list.ndim != 1 or not np.issubdtype(lag_list.dtype, np.integer):
        raise InputError("lags", lags, "a sequence of integers")
    if np.any(np.abs(lag_list) >= n_bits - 1):
        raise InputError("lags", lags, f"integers with |lag| < N - 1 = {n_bits - 1}")
    x = np.broadcast_to(x, lead + (n_bits,))
    y = np.broadcast_to(y, lead + (n_bits,))
    result = np.empty(lead + (lag_list.size,))
    for i, lag in enumerate(lag_list):
        if lag >= 0:
            a, b = x[..., : n_bits - lag], y[..., lag:]
        else:
            a, b = x[..., -lag:], y[..., : n_bits + lag]
        result[..., i] = pearson(a, b)
    return result


def autocorrelation(stream: Any, max_lag: int) -> np.ndarray:
    """Pearson autocorrelation at lags ``0 .. max_lag`` (shape ``batch + (max_lag + 1,)``)."""
    stream = v.as_stream(stream, "stream")
    max_lag = v.positive_int(max_lag, "max_lag", minimum=0)
    return cross_correlation(stream, stream, np.arange(max_lag + 1))
