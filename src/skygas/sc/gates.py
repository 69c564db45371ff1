r"""Stochastic-computing gates evaluated on whole streams, and their closed-form outputs.

Combinational gates act bit by bit; sequential ones (JK flip-flop, Muller C-element) carry a
one-bit state from clock to clock. Inputs are boolean arrays of shape ``(..., N)`` of equal N;
leading shapes broadcast. For independent Bernoulli inputs the output p-values are:

=============  ==========================================  =====================================
gate           output p-value                              use
=============  ==========================================  =====================================
NOT            :math:`1 - p_a`                             complement
AND            :math:`p_a p_b`                             multiplication
OR             :math:`p_a + p_b - p_a p_b`
XOR            :math:`p_a + p_b - 2 p_a p_b`               :math:`|p_a - p_b|` when SCC = +1
MUX            :math:`(1 - p_s)\,p_a + p_s\,p_b`           scaled addition (:math:`p_s = 1/2`)
JK flip-flop   :math:`p_J / (p_J + p_K)`                   division
C-element      :math:`p_a p_b / (p_a p_b + \bar p_a \bar p_b)`  Bayesian fusion
=============  ==========================================  =====================================

For correlated inputs, :func:`and_probability`, :func:`or_probability` and
:func:`xor_probability` give the output as a function of the SCC (Alaghi & Hayes 2013).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from skygas.core import validate as v
from skygas.core.errors import InputError


def _two(a: Any, b: Any) -> tuple[np.ndarray, np.ndarray]:
    a = v.as_stream(a, "a")
    b = v.as_stream(b, "b")
    v.same_length(a=a, b=b)
    return a, b


def not_(a: Any) -> np.ndarray:
    """NOT: :math:`p = 1 - p_a`."""
    return ~v.as_stream(a, "a")


def and_(a: Any, b: Any) -> np.ndarray:
    """AND: :math:`p = p_a p_b` for independent inputs (stochastic multiplication)."""
    a, b = _two(a, b)
    return a & b


def or_(a: Any, b: Any) -> np.ndarray:
    """OR: :math:`p = p_a + p_b - p_a p_b` for independent inputs."""
    a, b = _two(a, b)
    return a | b


def xor(a: Any, b: Any) -> np.ndarray:
    """XOR: :math:`p_a + p_b - 2p_a p_b` if independent; :math:`|p_a - p_b|` if SCC = +1."""
    a, b = _two(a, b)
    return a ^ b


def mux(a: Any, b: Any, select: Any) -> np.ndarray:
    r"""2-to-1 multiplexer: ``b`` where ``select`` is 1, ``a`` elsewhere.

    For a select stream independent of the data, :math:`p = (1-p_s)p_a + p_s p_b`; with
    :math:`p_s = 1/2` this is the scaled addition :math:`(p_a + p_b)/2`. The data inputs may
    be correlated with each other without harm.
    """
    a, b = _two(a, b)
    select = v.as_stream(select, "select")
    v.same_length(a=a, select=select)
    return np.where(select, b, a)


def jk_flip_flop(j: Any, k: Any, initial: bool = False) -> np.ndarray:
    r"""JK flip-flop output :math:`Q_t` (set, reset, toggle, hold).

    :math:`Q_0` = ``initial`` and :math:`Q_{t+1} = J_t \bar Q_t + \bar K_t Q_t`.

    The output at clock t is the registered state *before* the update with :math:`J_t, K_t`.
    For independent Bernoulli inputs the state is a Markov chain with
    :math:`P(0\to1) = p_J`, :math:`P(1\to0) = p_K`, so its stationary p-value is
    :math:`p_J / (p_J + p_K)` -- the stochastic divider. The output is autocorrelated
    (lag-1 autocorrelation :math:`1 - p_J - p_K`).
    """
    j, k = _two(j, k)
    lead = np.broadcast_shapes(j.shape[:-1], k.shape[:-1])
    n_bits = j.shape[-1]
    j = np.broadcast_to(j, lead + (n_bits,))
    k = np.broadcast_to(k, lead + (n_bits,))
    out = np.empty(lead + (n_bits,), dtype=bool)
    if lead == () or int(np.prod(lead)) == 1:
        # A plain Python loop over bools is far faster than per-clock NumPy calls on scalars.
        j_bits, k_bits = j.reshape(-1).tolist(), k.reshape(-1).tolist()
        state = bool(initial)
        bits = []
        for jt, kt in zip(j_bits, k_bits, strict=False):
            bits.append(state)
            state = (jt and not state) or (not kt and state)
        out[...] = np.asarray(bits, dtype=bool).reshape(out.shape)
        return out
    states = np.full(lead, bool(initial))
    for t in range(n_bits):
        out[..., t] = states
        states = (j[..., t] & ~states) | (~k[..., t] & states)
    return out


def c_element(a: Any, b: Any, initial: bool = False) -> np.ndarray:
    r"""Muller C-element: the output follows the inputs when they agree and holds otherwise.

    :math:`Q_t = a_t` if :math:`a_t = b_t`, else :math:`Q_{t-1}` (:math:`Q_{-1}` =
    ``initial``). For independent Bernoulli inputs the stationary p-value is

    .. math::  p = \frac{p_a p_b}{p_a p_b + (1-p_a)(1-p_b)},

    Bayes' rule for fusing two independent binary observations (Friedman et al. 2016, cited in
    the paper's "Motivation").
    """
    a, b = _two(a, b)
    lead = np.broadcast_shapes(a.shape[:-1], b.shape[:-1])
    n_bits = a.shape[-1]
    a = np.broadcast_to(a, lead + (n_bits,))
    b = np.broadcast_to(b, lead + (n_bits,))
    agree = a == b
    # Each output bit is the input at the last clock where both inputs agreed.
    last = np.where(agree, np.arange(n_bits), -1)
    np.maximum.accumulate(last, axis=-1, out=last)
    held = np.take_along_axis(a, np.maximum(last, 0), axis=-1)
    return np.where(last >= 0, held, bool(initial))


# -- closed forms --------------------------------------------------------------------------


def _scc_args(p_a: Any, p_b: Any, scc: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    pa = v.probability(p_a, "p_a")
    pb = v.probability(p_b, "p_b")
    s = np.asarray(scc, dtype=float)
    if not np.all(np.isfinite(s)) or np.any(np.abs(s) > 1.0):
        raise InputError("scc", scc, "a number in [-1, 1]")
    return pa, pb, s


def and_probability(p_a: Any, p_b: Any, scc: Any = 0.0) -> np.ndarray:
    r"""AND output p-value for inputs with p-values :math:`p_a, p_b` and correlation SCC = s.

    Inverting the SCC definition (:func:`skygas.sc.metrics.scc`):

    .. math::

        p_{a \wedge b} = \begin{cases}
          p_a p_b + s\,[\min(p_a, p_b) - p_a p_b] & s \ge 0 \\
          p_a p_b + s\,[p_a p_b - \max(p_a + p_b - 1, 0)] & s < 0
        \end{cases}

    so s = 0 gives the product, s = +1 gives :math:`\min(p_a, p_b)` (:math:`p` instead of
    :math:`p^2` for a stream ANDed with itself) and s = -1 gives :math:`\max(p_a + p_b - 1, 0)`.
    """
    pa, pb, s = _scc_args(p_a, p_b, scc)
    product = pa * pb
    upper = np.minimum(pa, pb) - product
    lower = product - np.maximum(pa + pb - 1.0, 0.0)
    return product + np.where(s >= 0, s * upper, s * lower)


def or_probability(p_a: Any, p_b: Any, scc: Any = 0.0) -> np.ndarray:
    r"""OR output: :math:`p_a + p_b - p_{a\wedge b}(s)`; :math:`\max(p_a,p_b)` at s = +1."""
    pa, pb, _ = _scc_args(p_a, p_b, scc)
    return pa + pb - and_probability(pa, pb, scc)


def xor_probability(p_a: Any, p_b: Any, scc: Any = 0.0) -> np.ndarray:
    r"""XOR output: :math:`p_a + p_b - 2p_{a\wedge b}(s)`.

    :math:`|p_a - p_b|` at s = +1 (stochastic absolute difference) and :math:`\min(p_a + p_b, 2 -
    p_a - p_b)` at s = -1.
    """
    pa, pb, _ = _scc_args(p_a, p_b, scc)
    return pa + pb - 2.0 * and_probability(pa, pb, scc)
