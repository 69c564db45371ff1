"""The reshuffler behind the stochastic-computing decorrelator interface (decorrelators
compared, measured not assumed)."""

import numpy as np

from skygas.reshuffler.decorrelator import reshuffler_decorrelator
from skygas.sc import DelayIsolator, bernoulli_stream, scc, telegraph_stream

RESHUFFLER = reshuffler_decorrelator()


def test_reshuffler_keeps_every_bit_and_decorrelates_a_duplicated_stream():
    x = bernoulli_stream(0.6, 1024, seed=4)
    result = RESHUFFLER.apply(x, seed=1)
    assert result.stream.shape == x.shape
    assert result.stream.sum() == x.sum()  # every skyrmion is read out: p exactly preserved
    assert scc(x, x) == 1.0
    assert abs(scc(x, result.stream)) < 4 / np.sqrt(len(x))  # ≈ 0 within 4 standard errors
    assert result.energy_per_bit_J > 0 and result.latency_bits > 1


def test_reshuffler_beats_a_one_flip_flop_isolator_on_a_correlated_stream():
    """A telegraph stream with a 16-clock correlation time: a one-cycle delay leaves the copy
    almost identical (SCC ≈ e^(−1/16) ≈ 0.94); the reshuffler spreads each bit over the
    neighbours it overtakes and lowers SCC clearly, though not to zero at this current."""
    x = telegraph_stream(0.5, 16.0, 1024, seed=2)
    isolated = DelayIsolator(1).apply(x, seed=0).stream
    reshuffled = RESHUFFLER.apply(x, seed=0).stream
    assert scc(x, isolated) > 0.85
    assert scc(x, reshuffled) < scc(x, isolated) - 0.3
    assert reshuffled.sum() == x.sum()
