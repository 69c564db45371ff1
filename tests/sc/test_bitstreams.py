"""Stream generators against their exact or closed-form statistics."""

import numpy as np
import pytest

from skygas.sc import (
    LFSR_TAPS,
    SuperparamagneticMTJ,
    autocorrelation,
    bernoulli_stream,
    correlated_pair,
    lfsr_states,
    lfsr_stream,
    p_value,
    scc,
    sobol_stream,
    telegraph_dwell_times,
    telegraph_stream,
)


def test_bernoulli_shape_dtype_and_binomial_mean():
    p = np.array([0.1, 0.5, 0.9])
    n_bits = 20_000
    x = bernoulli_stream(p[:, None], n_bits, shape=(3, 4), seed=1)
    assert x.shape == (3, 4, n_bits) and x.dtype == np.bool_
    # 5 binomial standard deviations, per stream.
    assert np.all(np.abs(p_value(x) - p[:, None]) < 5 * np.sqrt(p * (1 - p) / n_bits)[:, None])


def test_seeding_is_reproducible():
    a = telegraph_stream(0.3, 5.0, 1000, seed=7)
    b = telegraph_stream(0.3, 5.0, 1000, seed=np.random.default_rng(7))
    assert np.array_equal(a, b)
    assert not np.array_equal(a, telegraph_stream(0.3, 5.0, 1000, seed=8))


@pytest.mark.parametrize("width", sorted(w for w in LFSR_TAPS if w <= 16))
def test_lfsr_taps_give_maximal_period(width):
    states = lfsr_states(width)
    # A maximal-length register visits every nonzero state exactly once per period.
    assert states.size == 2**width - 1
    assert np.array_equal(np.sort(states), np.arange(1, 2**width))


@pytest.mark.parametrize("p", [0.0, 0.2, 0.5, 0.731, 1.0])
def test_lfsr_full_period_holds_exactly_round_pM_ones(p):
    width = 10
    period = 2**width - 1
    x = lfsr_stream(p, period, width=width, seed=3)
    assert np.count_nonzero(x) == round(p * period)


@pytest.mark.parametrize("p", [0.1, 0.37, 0.5, 0.93])
def test_sobol_power_of_two_is_balanced_to_one_bit(p):
    n_bits = 1024
    x = sobol_stream(p, n_bits, shape=(5,), seed=11)
    # (0, m, 1)-net: the count of ones is floor or ceil of pN.
    assert np.all(np.abs(np.count_nonzero(x, axis=-1) - p * n_bits) <= 1.0)


def test_telegraph_mean_and_exponential_autocorrelation():
    p, tau, n_bits, rows = 0.3, 8.0, 50_000, 8
    x = telegraph_stream(p, tau, n_bits, shape=(rows,), seed=5)
    q = np.exp(-1 / tau)
    # Variance of the mean of a telegraph signal: p(1-p)/N (1+q)/(1-q); 5 sigma on the average.
    sigma_mean = np.sqrt(p * (1 - p) / (n_bits * rows) * (1 + q) / (1 - q))
    assert abs(p_value(x).mean() - p) < 5 * sigma_mean
    lags = np.arange(0, 25, 4)
    measured = autocorrelation(x, 24).mean(axis=0)[lags]
    assert np.allclose(measured, np.exp(-lags / tau), atol=0.03)


def test_telegraph_dwell_times_reproduce_p():
    up, down = telegraph_dwell_times(0.25, 6.0)
    assert up == pytest.approx(8.0) and down == pytest.approx(24.0)
    assert up / (up + down) == pytest.approx(0.25)


def test_telegraph_with_short_correlation_time_is_bernoulli_like():
    x = telegraph_stream(0.5, 1e-3, 40_000, seed=2)
    assert abs(autocorrelation(x, 1)[1]) < 5 / np.sqrt(40_000)


@pytest.mark.parametrize("s", [-1.0, -0.4, 0.0, 0.5, 1.0])
def test_correlated_pair_has_requested_scc(s):
    x, y = correlated_pair(0.3, 0.6, s, 20_000, shape=(10,), seed=4)
    assert abs(scc(x, y).mean() - s) < 0.05


MTJ = SuperparamagneticMTJ(
    attempt_frequency_Hz=1e9, barrier_kT=10.0, critical_current_A=50e-6, clock_period_s=1e-6
)


def test_mtj_p_is_the_sigmoid_and_rates_satisfy_detailed_balance():
    current = np.linspace(-20e-6, 20e-6, 9)
    up, down = MTJ.switching_rates(current)
    reduced = current / 50e-6
    assert np.allclose(up / down, np.exp(2 * 10.0 * reduced))
    assert np.allclose(MTJ.p_value(current), 1 / (1 + np.exp(-20 * reduced)))
    assert MTJ.p_value(0.0) == pytest.approx(0.5)
    assert np.allclose(MTJ.p_value(MTJ.current_for([0.2, 0.7])), [0.2, 0.7])


def test_mtj_stream_mean_follows_the_bias_current():
    current = MTJ.current_for(0.8)
    x = MTJ.stream(current, 20_000, shape=(4,), seed=9)
    tau = float(MTJ.correlation_bits(current))
    q = np.exp(-1 / tau)
    sigma = np.sqrt(0.16 / 80_000 * (1 + q) / (1 - q))
    assert abs(p_value(x).mean() - 0.8) < 5 * sigma
