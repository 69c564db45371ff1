"""Input signals against the exact statistics of the sampled telegraph chain and Bernoulli bits."""

import numpy as np
import pytest

from skygas.core.errors import InputError
from skygas.sc.metrics import pearson
from skygas.sc.signals import (
    DEFAULT_INJECTION_INTERVAL,
    SignalSpec,
    as_bits,
    generate_bits,
    injection_times,
    read_bits,
    write_bits,
)

N_EVENTS = 200_000


def markov_mean_std(p, lam, n):
    """Exact standard deviation of the mean of n samples of a stationary two-state chain whose
    lag-j autocorrelation is lam**j: Var = p(1-p)/n^2 [n + 2 sum_{j=1}^{n-1} (n-j) lam^j]."""
    tail = lam * (n * (1 - lam) - (1 - lam**n)) / (1 - lam) ** 2
    return np.sqrt(p * (1 - p) * (n + 2 * tail)) / n


def lag1_std(p, lam, n):
    """Asymptotic standard deviation of the sample lag-1 phi coefficient of the chain.

    Up to O(1/n) edge terms the phi coefficient of consecutive pairs equals 1 - a - b, with
    a = n01/n0, b = n10/n1 the estimated switching probabilities, whose errors are
    asymptotically independent binomial: Var = a(1-a)/(n(1-p)) + b(1-b)/(n p), a = p(1-lam),
    b = (1-p)(1-lam). For lam = 0 it is 1/n.
    """
    a, b = p * (1 - lam), (1 - p) * (1 - lam)
    return np.sqrt(a * (1 - a) / (n * (1 - p)) + b * (1 - b) / (n * p))


@pytest.mark.parametrize("p, correlation_time", [(0.3, 20e-9), (0.62, 2e-9)])
def test_telegraph_p_and_lag1_autocorrelation(p, correlation_time):
    interval = DEFAULT_INJECTION_INTERVAL
    bits = generate_bits(SignalSpec("telegraph", p, correlation_time), N_EVENTS, interval, seed=11)
    assert bits.dtype == np.bool_ and bits.shape == (N_EVENTS,)
    lam = np.exp(-interval / correlation_time)
    assert abs(bits.mean() - p) < 4 * markov_mean_std(p, lam, N_EVENTS)
    rho1 = float(pearson(bits[:-1], bits[1:]))
    assert abs(rho1 - lam) < 4 * lag1_std(p, lam, N_EVENTS)


def test_telegraph_run_lengths_are_geometric_with_the_exact_mean():
    # Sampled at the clock, a run of ones ends with probability (1-p)(1-lam) per step.
    p, tau, interval = 0.4, 30e-9, 5e-9
    bits = generate_bits(SignalSpec("telegraph", p, tau), N_EVENTS, interval, seed=3)
    edges = np.flatnonzero(np.diff(bits.astype(np.int8)))
    runs = np.diff(edges)[bits[edges[:-1] + 1]]  # lengths of complete runs of ones
    leave = (1 - p) * (1 - np.exp(-interval / tau))
    mean, std = 1 / leave, np.sqrt(1 - leave) / leave
    assert abs(runs.mean() - mean) < 4 * std / np.sqrt(runs.size)
    # In continuous time the mean dwell in state 1 is tau/(1-p); the clock resolves it.
    assert abs(mean * interval - tau / (1 - p)) < interval


def test_bernoulli_has_no_lag1_correlation_and_the_right_p():
    p = 0.7
    bits = generate_bits(SignalSpec("bernoulli", p), N_EVENTS, seed=5)
    assert abs(bits.mean() - p) < 4 * np.sqrt(p * (1 - p) / N_EVENTS)
    assert abs(float(pearson(bits[:-1], bits[1:]))) < 4 / np.sqrt(N_EVENTS)


def test_seed_reproducibility():
    spec = SignalSpec("telegraph", 0.5, 10e-9)
    a = generate_bits(spec, 1000, seed=np.random.SeedSequence(9))
    assert np.array_equal(a, generate_bits(spec, 1000, seed=np.random.SeedSequence(9)))
    assert not np.array_equal(a, generate_bits(spec, 1000, seed=10))


@pytest.mark.parametrize("suffix", [".csv", ".txt", ".npy"])
def test_file_round_trip(tmp_path, suffix):
    bits = np.random.default_rng(0).random(137) < 0.4
    path = write_bits(tmp_path / f"bits{suffix}", bits)
    assert np.array_equal(read_bits(path), bits)
    spec = SignalSpec("file", path=path)
    assert np.array_equal(generate_bits(spec, None), bits)
    assert np.array_equal(generate_bits(spec, 50), bits[:50])
    with pytest.raises(InputError) as err:
        generate_bits(spec, 138)
    assert err.value.field == "n_events"


def test_comma_separated_csv_and_integer_npy(tmp_path):
    text = tmp_path / "bits.csv"
    text.write_text("# input bits\n1,0,1\n0, 0 ,1\n\n1.0,0.0\n")
    assert read_bits(text).tolist() == [1, 0, 1, 0, 0, 1, 1, 0]
    npy = tmp_path / "bits.npy"
    np.save(npy, np.array([0, 1, 1], dtype=np.int64))
    assert read_bits(npy).tolist() == [False, True, True]


def test_injection_times():
    assert np.allclose(injection_times(4, 5e-9), [0, 5e-9, 10e-9, 15e-9])


@pytest.mark.parametrize("content", ["1\n0\n2\n", "1,0,x\n", "1,-1\n"])
def test_file_values_other_than_0_1_are_refused(tmp_path, content):
    path = tmp_path / "bad.csv"
    path.write_text(content)
    with pytest.raises(InputError) as err:
        generate_bits(SignalSpec("file", path=path), None)
    assert err.value.field == "path" and "line" in str(err.value.value)


def test_bad_npy_empty_and_missing_files(tmp_path):
    np.save(tmp_path / "bad.npy", np.array([0, 1, 3]))
    np.save(tmp_path / "empty.npy", np.array([], dtype=bool))
    (tmp_path / "empty.csv").write_text("# nothing\n\n")
    for name in ("bad.npy", "empty.npy", "empty.csv", "missing.csv"):
        with pytest.raises(InputError) as err:
            read_bits(tmp_path / name)
        assert err.value.field == "path"
    with pytest.raises(InputError) as err:
        SignalSpec("file")
    assert err.value.field == "path"


@pytest.mark.parametrize(
    "kwargs, field",
    [
        (dict(kind="telegraph", p=1.2), "p"),
        (dict(kind="bernoulli", p=-0.1), "p"),
        (dict(kind="bernoulli", p=float("nan")), "p"),
        (dict(kind="telegraph", p=0.0), "p"),  # a constant signal has no dwell times
        (dict(kind="telegraph", p=1.0), "p"),
        (dict(kind="telegraph", p=0.5, correlation_time=0.0), "correlation_time"),
        (dict(kind="telegraph", p=0.5, correlation_time=-1e-9), "correlation_time"),
        (dict(kind="noise"), "kind"),
    ],
)
def test_invalid_specs_name_the_field(kwargs, field):
    with pytest.raises(InputError) as err:
        SignalSpec(**kwargs)
    assert err.value.field == field


def test_bernoulli_accepts_edge_p_and_bad_lengths_are_refused():
    assert generate_bits(SignalSpec("bernoulli", 1.0), 10, seed=0).all()
    for n_events in (0, -3, 2.5):
        with pytest.raises(InputError) as err:
            generate_bits(SignalSpec(), n_events, seed=0)
        assert err.value.field == "n_events"
    with pytest.raises(InputError) as err:
        generate_bits(SignalSpec(), 10, injection_interval=0.0)
    assert err.value.field == "injection_interval"


def test_as_bits_refuses_empty_and_non_binary():
    with pytest.raises(InputError) as err:
        as_bits([], "signal")
    assert err.value.field == "signal"
    with pytest.raises(InputError) as err:
        as_bits([0, 1, 2], "signal")
    assert err.value.field == "signal[2]"
    assert as_bits([1, 0, 1]).tolist() == [True, False, True]
