"""Decorrelators: p-value preservation, decorrelation, and the autocorrelated-input case."""

import numpy as np
import pytest

from skygas.sc import (
    DelayIsolator,
    FunctionDecorrelator,
    Regenerator,
    ShuffleBuffer,
    autocorrelation,
    bernoulli_stream,
    p_value,
    scc,
    telegraph_stream,
)

DECORRELATORS = [
    DelayIsolator(1),
    DelayIsolator(8),
    ShuffleBuffer(16),
    ShuffleBuffer(128),
    Regenerator(64),
]


@pytest.mark.parametrize("decorrelator", DECORRELATORS, ids=lambda d: d.name)
def test_p_value_is_preserved_within_the_stated_bias(decorrelator):
    p, n_bits, rows = 0.3, 8192, 16
    x = bernoulli_stream(p, n_bits, shape=(rows,), seed=1)
    result = decorrelator.apply(x, seed=2)
    assert result.stream.shape == x.shape and result.stream.dtype == np.bool_
    shift = np.abs(p_value(result.stream) - p_value(x))
    bound = decorrelator.p_bias_bound(n_bits)
    if isinstance(decorrelator, Regenerator):
        # Bound on the expected shift; each row adds resampling noise of about
        # sqrt(2 p (1-p) / N) (window estimates plus fresh bits): 5 sigma per row.
        assert np.all(shift <= bound + 5 * np.sqrt(2 * p * (1 - p) / n_bits))
        assert abs(np.mean(p_value(result.stream) - p_value(x))) < 5 * np.sqrt(
            2 * p * (1 - p) / (n_bits * rows)
        )
    else:
        assert np.all(shift <= bound + 1e-12)


@pytest.mark.parametrize("decorrelator", DECORRELATORS, ids=lambda d: d.name)
def test_decorrelators_lower_the_scc_of_a_duplicated_bernoulli_stream(decorrelator):
    x = bernoulli_stream(0.5, 8192, shape=(16,), seed=3)
    assert np.all(scc(x, x) == 1.0)
    copy = decorrelator(x, seed=4)
    # Independent bits: the SCC drops from 1 to 0 within sampling error (1/sqrt(N) per stream
    # at p = 0.5, so 5/sqrt(16 N) for the mean over 16 streams).
    assert abs(scc(x, copy).mean()) < 5 / np.sqrt(16 * 8192)


TAU = 50.0  # telegraph correlation time, clock cycles


@pytest.fixture(scope="module")
def telegraph():
    return telegraph_stream(0.5, TAU, 2**15, shape=(16,), seed=5)


def test_delay_isolator_fails_on_a_strongly_autocorrelated_stream(telegraph):
    copy = DelayIsolator(1)(telegraph, seed=6)
    measured = scc(telegraph, copy).mean()
    # At p_x = p_y the SCC equals the Pearson correlation, exp(-k/tau) for a k-bit delay.
    assert measured == pytest.approx(np.exp(-1 / TAU), abs=0.05)
    assert measured > 0.9


def test_shuffle_buffer_and_regenerator_do_better_than_the_isolator(telegraph):
    isolator = scc(telegraph, DelayIsolator(1)(telegraph, seed=7)).mean()
    depth = 256
    shuffled = scc(telegraph, ShuffleBuffer(depth)(telegraph, seed=8)).mean()
    # A bit leaves the buffer after a Geometric(1/D) number of clocks, so the correlation left
    # is E[exp(-age/tau)] = (q/D) / (1 - (1 - 1/D) q), q = exp(-1/tau).
    q = np.exp(-1 / TAU)
    expected = (q / depth) / (1 - (1 - 1 / depth) * q)
    assert shuffled == pytest.approx(expected, abs=0.05)
    regenerated = scc(telegraph, Regenerator(256)(telegraph, seed=9)).mean()
    assert shuffled < isolator - 0.5
    assert regenerated < isolator - 0.5


def test_shuffle_buffer_whitens_the_output_while_the_delay_keeps_its_autocorrelation(telegraph):
    lag1_in = autocorrelation(telegraph, 1)[..., 1].mean()
    lag1_delay = autocorrelation(DelayIsolator(4)(telegraph, seed=10), 1)[..., 1].mean()
    lag1_shuffle = autocorrelation(ShuffleBuffer(256)(telegraph, seed=11), 1)[..., 1].mean()
    assert lag1_delay == pytest.approx(lag1_in, abs=0.01)
    assert lag1_shuffle < lag1_in - 0.5


def test_figures_of_merit_carry_their_sources():
    assert DelayIsolator(3).latency_bits == 3
    assert DelayIsolator(3).energy.joules_per_bit is None
    assert "unknown" in DelayIsolator(3).energy.source
    for d in (ShuffleBuffer(8), Regenerator(8)):
        assert d.energy.joules_per_bit == pytest.approx(10e-12)
        assert "Tehrani" in d.energy.source
        assert d.footprint.linear_size_m == (10e-6, 100e-6)


def test_function_decorrelator_wraps_a_device_model():
    # A stand-in device that reverses the stream (a deterministic permutation) and reports
    # a fixed energy; the adapter must pass bits through row by row and report the figures.
    def device(bits, rng):
        return bits[::-1].copy(), 2e-15, 12.0

    wrapped = FunctionDecorrelator("reverser", device, energy_source="test value")
    x = bernoulli_stream(0.4, 100, shape=(3,), seed=12)
    result = wrapped.apply(x, seed=13)
    assert np.array_equal(result.stream, x[..., ::-1])
    assert result.energy_per_bit_J == 2e-15 and result.latency_bits == 12.0
    assert result.energy_source == "test value"
