r"""Stochastic bitstreams: boolean arrays of shape ``(..., N)`` whose mean encodes a p-value.

In unipolar stochastic computing a number :math:`p \in [0, 1]` is carried by a stream of bits
whose probability of being 1 is :math:`p` (paper, section "Motivation: Stochastic Computing").
Every generator here returns ``numpy.bool_`` arrays of shape ``shape + (n_bits,)`` (the last axis
is time, in clock cycles) and takes ``seed``: an int, a ``numpy.random.SeedSequence``, a
``numpy.random.Generator`` or ``None``.

Generators
----------
* :func:`bernoulli_stream` -- independent bits, the ideal the others are measured against.
* :func:`lfsr_stream` -- comparator against a maximal-length linear-feedback shift register,
  the classic CMOS stochastic number generator; taps in :data:`LFSR_TAPS`.
* :func:`sobol_stream` -- comparator against a scrambled Sobol sequence (low discrepancy).
* :func:`telegraph_stream` -- random telegraph noise: a stationary two-state Markov signal with
  a p-value and a correlation (dwell) time, the input the skyrmion reshuffler is fed.
* :func:`correlated_pair` -- two Bernoulli streams with a prescribed SCC, for testing gates.

The superparamagnetic-MTJ generator lives in :mod:`skygas.sc.mtj`; it produces telegraph noise.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from skygas.core import validate as v
from skygas.core.errors import InputError

# Maximal-length Fibonacci LFSR taps, 1-indexed bit positions, from Xilinx application note
# XAPP 052 (P. Alfke, "Efficient Shift Registers, LFSR Counters, and Long Pseudo-Random
# Sequence Generators", 1996, table 3). The feedback polynomial for width w and taps
# (w, t2, ...) is x^w + x^t2 + ... + 1; every set gives period 2^w - 1 (checked in the tests).
LFSR_TAPS: dict[int, tuple[int, ...]] = {
    3: (3, 2),
    4: (4, 3),
    5: (5, 3),
    6: (6, 5),
    7: (7, 6),
    8: (8, 6, 5, 4),
    9: (9, 5),
    10: (10, 7),
    11: (11, 9),
    12: (12, 6, 4, 1),
    13: (13, 4, 3, 1),
    14: (14, 5, 3, 1),
    15: (15, 14),
    16: (16, 15, 13, 4),
    17: (17, 14),
    18: (18, 11),
    19: (19, 6, 2, 1),
    20: (20, 17),
}

# Sobol dimensions available in scipy's direction numbers (Joe & Kuo).
_SOBOL_MAX_DIMENSION = 21201


def _batch(p: Any, shape: Any) -> tuple[np.ndarray, tuple[int, ...]]:
    """Broadcast a p-value (array) against a batch shape; return (p, leading shape)."""
    prob = v.probability(p, "p")
    lead = v.leading_shape(shape)
    try:
        lead = np.broadcast_shapes(lead, prob.shape)
    except ValueError:
        raise InputError(
            "p", f"array of shape {prob.shape}", f"a shape that broadcasts to {lead}"
        ) from None
    return np.broadcast_to(prob, lead), lead


def bernoulli_stream(
    p: Any, n_bits: int, *, shape: Any = (), seed: v.SeedLike = None
) -> np.ndarray:
    """Independent Bernoulli(p) bits.

    Parameters
    ----------
    p : float or array_like
        p-value(s) in [0, 1]; scalar or an array broadcastable to ``shape``.
    n_bits : int
        Stream length N (clock cycles).
    shape : tuple of int
        Batch shape in front of the time axis.
    seed : int, SeedSequence, Generator or None
        Seed or generator.

    Returns
    -------
    numpy.ndarray
        Boolean array of shape ``broadcast(shape, p.shape) + (n_bits,)``. The estimate
        ``mean(axis=-1)`` has variance :math:`p(1-p)/N`, the binomial limit.
    """
    prob, lead = _batch(p, shape)
    n_bits = v.positive_int(n_bits, "n_bits")
    rng = v.make_rng(seed)
    return rng.random(lead + (n_bits,)) < prob[..., None]


def _lfsr_states(width: int) -> np.ndarray:
    """One full period of the Fibonacci LFSR of ``width`` bits, as integers in [1, 2^w - 1]."""
    cached = _LFSR_CACHE.get(width)
    if cached is not None:
        return cached
    taps = LFSR_TAPS[width]
    mask = (1 << width) - 1
    period = mask
    states = np.empty(period, dtype=np.int64)
    state = 1
    for i in range(period):
        states[i] = state
        feedback = 0
        for tap in taps:
            feedback ^= (state >> (tap - 1)) & 1
        state = ((state << 1) | feedback) & mask
    states.flags.writeable = False
    _LFSR_CACHE[width] = states
    return states


_LFSR_CACHE: dict[int, np.ndarray] = {}


def lfsr_states(width: int) -> np.ndarray:
    """Return one period (2^w - 1 states) of the LFSR of ``width`` bits with :data:`LFSR_TAPS`.

    The register shifts left by one each clock; the new least-significant bit is the XOR of the
    tapped bits. States start at 1 and visit every nonzero w-bit integer exactly once.
    """
    if width not in LFSR_TAPS:
        raise InputError("width", width, f"one of {sorted(LFSR_TAPS)} (bits)")
    return _lfsr_states(width)


def lfsr_stream(
    p: Any, n_bits: int, *, width: int = 16, shape: Any = (), seed: v.SeedLike = None
) -> np.ndarray:
    r"""Comparator stream driven by a maximal-length LFSR.

    With :math:`M = 2^w - 1` and the register state :math:`R_t \in [1, M]`, the bit is
    :math:`b_t = [R_t - 1 < \mathrm{round}(pM)]`. Over a whole period the stream therefore holds
    exactly :math:`\mathrm{round}(pM)` ones: the p-value is quantised to :math:`1/M`
    (error :math:`\le 1/(2M)`) with no sampling noise. Streams longer than :math:`M` repeat.

    Each batch entry starts at a random phase of the same sequence (a different seed register
    in hardware), so batch entries are shifted copies, not independent streams.

    Parameters
    ----------
    p : float or array_like
        p-value(s) in [0, 1].
    n_bits : int
        Stream length N.
    width : int
        Register width w in bits; one of :data:`LFSR_TAPS`.
    shape : tuple of int
        Batch shape.
    seed : int, SeedSequence, Generator or None
        Seed or generator; chooses the starting state (phase).
    """
    prob, lead = _batch(p, shape)
    n_bits = v.positive_int(n_bits, "n_bits")
    states = lfsr_states(width)
    rng = v.make_rng(seed)
    period = states.size
    phase = rng.integers(0, period, size=lead)
    index = (phase[..., None] + np.arange(n_bits)) % period
    threshold = np.rint(prob * period)
    return (states[index] - 1) < threshold[..., None]


def sobol_stream(p: Any, n_bits: int, *, shape: Any = (), seed: v.SeedLike = None) -> np.ndarray:
    r"""Comparator stream driven by a scrambled Sobol sequence (``scipy.stats.qmc.Sobol``).

    Batch entries use distinct Sobol dimensions, the usual way to get mutually uncorrelated
    low-discrepancy streams. When N is a power of two the first N points of each dimension
    are a (0, m, 1)-net, so the number of ones is :math:`\lfloor pN \rfloor` or
    :math:`\lceil pN \rceil`: the p-value error is at most :math:`1/N` instead of the binomial
    :math:`\sqrt{p(1-p)/N}`.
    """
    prob, lead = _batch(p, shape)
    n_bits = v.positive_int(n_bits, "n_bits")
    rng = v.make_rng(seed)
    n_streams = int(np.prod(lead, dtype=np.int64))
    if n_streams > _SOBOL_MAX_DIMENSION:
        raise InputError("shape", lead, f"at most {_SOBOL_MAX_DIMENSION} streams in one batch")
    from scipy.stats import qmc  # here: scipy.stats takes ~1 s to import

    sampler = qmc.Sobol(d=max(n_streams, 1), scramble=True, seed=rng)
    with warnings.catch_warnings():
        # scipy warns when N is not a power of two; the stream is still valid, only its
        # balance guarantee is weaker, as the docstring says.
        warnings.simplefilter("ignore", UserWarning)
        points = sampler.random(n_bits)
    points = points.T.reshape(lead + (n_bits,))
    return points < prob[..., None]


def telegraph_dwell_times(p: Any, correlation_bits: Any) -> tuple[np.ndarray, np.ndarray]:
    r"""Mean dwell times (in clock cycles) of the up and down states of telegraph noise.

    For the continuous-time two-state process of :func:`telegraph_stream`, with correlation
    time :math:`\tau` and p-value :math:`p`, the switching rates are
    :math:`r_{0\to1} = p/\tau` and :math:`r_{1\to0} = (1-p)/\tau`, so the mean dwell times are
    :math:`\tau_\uparrow = \tau/(1-p)` and :math:`\tau_\downarrow = \tau/p`, and
    :math:`p = \tau_\uparrow/(\tau_\uparrow + \tau_\downarrow)`.
    """
    prob = v.probability(p, "p")
    tau = v.positive_float(correlation_bits, "correlation_bits", "clock cycles")
    with np.errstate(divide="ignore"):
        return tau / (1.0 - prob), tau / prob


def telegraph_stream(
    p: Any,
    correlation_bits: float,
    n_bits: int,
    *,
    shape: Any = (),
    seed: v.SeedLike = None,
) -> np.ndarray:
    r"""Random telegraph noise sampled once per clock.

    A stationary continuous-time two-state Markov process with p-value :math:`p` and
    correlation time :math:`\tau` (``correlation_bits``, in clock cycles) is sampled at integer
    times. Between samples the state is *refreshed* -- replaced by a fresh Bernoulli(p) draw --
    with probability :math:`a = 1 - e^{-1/\tau}`, and kept otherwise; this is exactly the
    sampled process, with transition probabilities :math:`P(0\to1) = ap` and
    :math:`P(1\to0) = a(1-p)`. Consequences used by the tests:

    * the autocorrelation (Pearson) at lag k is :math:`e^{-k/\tau}`;
    * the p-value estimate has variance
      :math:`\frac{p(1-p)}{N}\,\frac{1+e^{-1/\tau}}{1-e^{-1/\tau}}` for large N, i.e. the stream
      carries about :math:`2\tau` times fewer independent bits than a Bernoulli stream.

    The mean dwell times are given by :func:`telegraph_dwell_times`. ``tau -> 0`` recovers
    :func:`bernoulli_stream`. The first bit is drawn from the stationary distribution.
    """
    prob, lead = _batch(p, shape)
    tau = v.positive_float(correlation_bits, "correlation_bits", "clock cycles")
    n_bits = v.positive_int(n_bits, "n_bits")
    rng = v.make_rng(seed)
    refresh_probability = -np.expm1(-1.0 / tau)
    return _refreshed_chain(prob, refresh_probability, lead + (n_bits,), rng)


def _refreshed_chain(
    prob: np.ndarray,
    refresh_probability: Any,
    full_shape: tuple[int, ...],
    rng: np.random.Generator,
) -> np.ndarray:
    """Vectorised two-state chain: each bit repeats the last fresh Bernoulli(p) draw."""
    n_bits = full_shape[-1]
    refresh_probability = np.broadcast_to(refresh_probability, full_shape[:-1])
    refresh = rng.random(full_shape) < refresh_probability[..., None]
    refresh[..., 0] = True
    fresh = rng.random(full_shape) < prob[..., None]
    last_refresh = np.where(refresh, np.arange(n_bits), 0)
    np.maximum.accumulate(last_refresh, axis=-1, out=last_refresh)
    return np.take_along_axis(fresh, last_refresh, axis=-1)


def correlated_pair(
    p_x: Any,
    p_y: Any,
    scc: float,
    n_bits: int,
    *,
    shape: Any = (),
    seed: v.SeedLike = None,
) -> tuple[np.ndarray, np.ndarray]:
    r"""Two Bernoulli streams with p-values ``p_x``, ``p_y`` and expected SCC ``scc``.

    Each clock, with probability :math:`|s|` both bits are read from one shared uniform number
    :math:`r` -- :math:`x = [r < p_x]` and :math:`y = [r < p_y]` for :math:`s > 0`
    (maximal overlap), :math:`y = [1 - r < p_y]` for :math:`s < 0` (minimal overlap) -- and
    otherwise from two independent ones. The expected joint probability is then
    :math:`p_{xy} = p_x p_y + s\,(\text{extreme} - p_x p_y)`, i.e. the SCC is :math:`s`
    by construction (see :func:`skygas.sc.metrics.scc`).
    """
    px, lead_x = _batch(p_x, shape)
    py, lead = _batch(p_y, lead_x)
    px = np.broadcast_to(px, lead)
    if not (isinstance(scc, (int, float, np.floating)) and -1.0 <= float(scc) <= 1.0):
        raise InputError("scc", scc, "a number in [-1, 1]")
    n_bits = v.positive_int(n_bits, "n_bits")
    rng = v.make_rng(seed)
    full = lead + (n_bits,)
    shared = rng.random(full)
    independent = rng.random(full)
    coupled = rng.random(full) < abs(float(scc))
    partner = (1.0 - shared) if scc < 0 else shared
    x = shared < px[..., None]
    y = np.where(coupled, partner, independent) < py[..., None]
    return x, y
