"""Correlation metrics against exact values and stated statistical tolerances."""

import numpy as np
import pytest

from skygas.sc import (
    bernoulli_stream,
    cross_correlation,
    p_value_interval,
    pearson,
    scc,
    zce,
)


def _stream(ones, n_bits, start=0):
    x = np.zeros(n_bits, dtype=bool)
    x[start : start + ones] = True
    return x


@pytest.mark.parametrize("p", [0.05, 0.3, 0.5, 0.8])
def test_scc_of_a_stream_with_itself_is_one(p):
    x = bernoulli_stream(p, 4096, seed=1)
    assert scc(x, x) == 1.0
    assert pearson(x, x) == pytest.approx(1.0)


def test_scc_of_a_stream_with_its_complement_is_minus_one_at_half():
    x = bernoulli_stream(0.5, 4096, seed=2)
    assert scc(x, ~x) == -1.0
    assert pearson(x, ~x) == pytest.approx(-1.0)


def test_scc_of_independent_streams_is_within_3_over_sqrt_n():
    # At p = 0.5 the SCC of independent streams has standard deviation 1/sqrt(N), so
    # 3/sqrt(N) is a 3-sigma band: at most ~0.3% of pairs fall outside it.
    n_bits, pairs = 4096, 400
    x = bernoulli_stream(0.5, n_bits, shape=(pairs,), seed=3)
    y = bernoulli_stream(0.5, n_bits, shape=(pairs,), seed=4)
    outside = np.mean(np.abs(scc(x, y)) > 3 / np.sqrt(n_bits))
    assert outside < 0.02
    assert abs(scc(x[0], y[0])) < 3 / np.sqrt(n_bits)


def test_scc_and_zce_on_exact_alignments():
    # p_x = 3/16, p_y = 14/16: p_x p_y = 42/256 and the best representable overlap is 3/16.
    n_bits = 16
    x = _stream(3, n_bits)
    y_full_overlap = _stream(14, n_bits)  # the 3 ones of x all meet ones of y
    y_min_overlap = np.roll(_stream(14, n_bits), 2)  # ones at 2..15: overlap with x is 1 bit
    overlap = np.count_nonzero(x & y_min_overlap)
    assert overlap == 1
    # Overlap 3: Delta = 48/256 - 42/256 = 6/256 = Delta0 -> SCC = +1, ZCE = 0.
    assert scc(x, y_full_overlap) == pytest.approx(1.0)
    assert zce(x, y_full_overlap) == 0.0
    # Overlap 1: Delta = 16/256 - 42/256 = -26/256; SCC denominator p_x p_y - (p_x+p_y-1)
    # = 42/256 - 16/256 -> SCC = -1; ZCE = -(26 - 6)/256.
    assert scc(x, y_min_overlap) == pytest.approx(-1.0)
    assert zce(x, y_min_overlap) == pytest.approx(-20 / 256)
    # Overlap 2: Delta = -10/256 -> SCC = -10/26, ZCE = -(10 - 6)/256.
    y = np.roll(_stream(14, n_bits), 1)
    assert np.count_nonzero(x & y) == 2
    assert scc(x, y) == pytest.approx(-10 / 26)
    assert zce(x, y) == pytest.approx(-4 / 256)


def test_scc_is_zero_for_constant_streams():
    x = np.ones(100, dtype=bool)
    y = bernoulli_stream(0.4, 100, seed=1)
    assert scc(x, y) == 0.0 and scc(~x, y) == 0.0 and pearson(x, y) == 0.0


def test_cross_correlation_finds_the_delay():
    x = bernoulli_stream(0.4, 5000, seed=5)
    y = np.roll(x, 7)
    result = cross_correlation(x, y, np.arange(-3, 12))
    assert result[np.arange(-3, 12) == 7][0] == pytest.approx(1.0)
    others = result[np.arange(-3, 12) != 7]
    assert np.all(np.abs(others) < 5 / np.sqrt(5000))


def test_clopper_pearson_interval_covers_at_least_nominally():
    p, n_bits, trials = 0.2, 200, 2000
    estimate = p_value_interval(bernoulli_stream(p, n_bits, shape=(trials,), seed=6), 0.95)
    coverage = np.mean((estimate.low <= p) & (p <= estimate.high))
    # Clopper-Pearson is conservative (>= 95%); 2000 trials give a standard error of 0.5%.
    assert coverage > 0.93
    edge = p_value_interval(np.zeros(50, dtype=bool))
    assert edge.low == 0.0 and 0 < edge.high < 0.1  # exact: 1 - 0.025**(1/50) = 0.071
    assert edge.high == pytest.approx(1 - 0.025 ** (1 / 50))
