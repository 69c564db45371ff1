"""Input-output correlation and chamber bookkeeping against exact constructions."""

import numpy as np
import pytest

from skygas.core.errors import InputError
from skygas.reshuffler.correlation import (
    occupancy,
    output_signal_from_events,
    p_out_vs_p_in,
    pearson_by_index,
    pearson_error_by_index,
    pearson_vs_lag,
    running_correlation,
    scc_by_index,
    transit_times,
)

N = 50_000


def bernoulli(p, n, seed):
    return np.random.default_rng(seed).random(n) < p


def refreshed_copy(b, p, q, seed):
    """c = b, each bit independently replaced with probability q by a fresh Bernoulli(p) bit.
    Then cov(b, c) = (1-q) p(1-p) and var(c) = p(1-p): rho = 1 - q exactly."""
    rng = np.random.default_rng(seed)
    fresh = rng.random(b.size) < p
    return np.where(rng.random(b.size) < q, fresh, b)


def pearson_std(p, q, n):
    """Delta-method standard deviation of the sample Pearson coefficient of n i.i.d. pairs
    (Kendall & Stuart), from the exact central moments of the pair's 2x2 distribution."""
    lam = 1 - q
    p11 = p * p + lam * p * (1 - p)
    pmf = [(1, 1, p11), (1, 0, p - p11), (0, 1, p - p11), (0, 0, 1 - 2 * p + p11)]

    def mu(i, j):
        return sum(w * (x - p) ** i * (y - p) ** j for x, y, w in pmf)

    rho = mu(1, 1) / np.sqrt(mu(2, 0) * mu(0, 2))
    var = (
        rho**2
        / n
        * (
            mu(2, 2) / mu(1, 1) ** 2
            + 0.25
            * (
                mu(4, 0) / mu(2, 0) ** 2
                + mu(0, 4) / mu(0, 2) ** 2
                + 2 * mu(2, 2) / (mu(2, 0) * mu(0, 2))
            )
            - (mu(3, 1) / (mu(1, 1) * mu(2, 0)) + mu(1, 3) / (mu(1, 1) * mu(0, 2)))
        )
    )
    return np.sqrt(var)


def test_identical_sequences_give_one():
    b = bernoulli(0.3, 1000, 1)
    assert pearson_by_index(b, b) == pytest.approx(1.0, abs=1e-12)
    assert scc_by_index(b, b) == pytest.approx(1.0, abs=1e-12)
    assert pearson_by_index(b, ~b) == pytest.approx(-1.0, abs=1e-12)


def test_index_alignment_truncates_to_the_common_length():
    b = bernoulli(0.5, 500, 2)
    c = np.concatenate([b, bernoulli(0.5, 300, 3)])  # extra output events are ignored
    assert pearson_by_index(b, c) == pytest.approx(1.0, abs=1e-12)
    assert pearson_by_index(c, b) == pytest.approx(1.0, abs=1e-12)
    assert pearson_by_index([1, 0, 1, 1], [1, 0, 0, 1, 1]) == pytest.approx(np.sqrt(1 / 3))


@pytest.mark.parametrize("shift", [3, -5, 0])
def test_lag_scan_finds_a_shift(shift):
    b = bernoulli(0.4, 5000, 4)
    if shift >= 0:  # c_{k+shift} = b_k: the output is late by `shift` events
        c = np.concatenate([bernoulli(0.4, shift, 5), b])
    else:
        c = b[-shift:]
    scan = pearson_vs_lag(b, c, max_lag=10)
    assert scan.best_lag == shift
    assert scan.best_rho == pytest.approx(1.0, abs=1e-12)
    others = np.abs(scan.rho[scan.lags != shift])
    assert others.max() < 4 / np.sqrt(4900)
    assert scan.rho[scan.lags == 0][0] == pytest.approx(pearson_by_index(b, c))


def test_independent_sequences_are_uncorrelated():
    b, c = bernoulli(0.62, N, 6), bernoulli(0.62, N, 7)
    assert abs(pearson_by_index(b, c)) < 4 / np.sqrt(N)


@pytest.mark.parametrize("p, q", [(0.3, 0.4), (0.62, 0.8), (0.5, 0.1)])
def test_partially_refreshed_copy_has_rho_one_minus_q(p, q):
    b = bernoulli(p, N, 8)
    c = refreshed_copy(b, p, q, 9)
    assert abs(pearson_by_index(b, c) - (1 - q)) < 4 * pearson_std(p, q, N)
    # With positive overlap SCC and rho differ only in normalisation: for sample p-values
    # lo <= hi, SCC = rho * sqrt(hi (1 - lo) / (lo (1 - hi))) exactly.
    lo, hi = sorted([b.mean(), c.mean()])
    expected_scc = pearson_by_index(b, c) * np.sqrt(hi * (1 - lo) / (lo * (1 - hi)))
    assert scc_by_index(b, c) == pytest.approx(expected_scc, rel=1e-12)


@pytest.mark.parametrize("p, q", [(0.62, 0.8), (0.5, 0.1)])
def test_block_jackknife_error_of_rho_matches_the_exact_spread(p, q):
    # the mean of ten jackknife errors (each within about 16 % for 20 blocks) is within 15 %
    # (about 3 standard deviations) of the exact standard deviation of rho for independent pairs
    errors = []
    for seed in range(10):
        b = bernoulli(p, N, 100 + seed)
        errors.append(pearson_error_by_index(b, refreshed_copy(b, p, q, 200 + seed)))
    assert np.mean(errors) == pytest.approx(pearson_std(p, q, N), rel=0.15)
    assert np.isnan(pearson_error_by_index([1, 0, 1], [1, 1, 0]))  # too few pairs per block


def test_p_out_vs_p_in_intervals_contain_the_truth():
    p = 0.62
    b = bernoulli(p, N, 10)
    c = refreshed_copy(b, p, 0.5, 11)[: N - 123]  # the output may be shorter
    result = p_out_vs_p_in(b, c, confidence=0.999)
    assert result.p_in.low <= p <= result.p_in.high
    assert result.p_out.low <= p <= result.p_out.high
    assert result.p_in_within_output_interval
    assert result.p_out.n_bits == N - 123 and result.p_in.n_bits == N
    assert result.difference == pytest.approx(c.mean() - b.mean())
    # A biased output is flagged.
    assert not p_out_vs_p_in(b, bernoulli(0.5, N, 12)).p_in_within_output_interval


def test_running_correlation_ends_at_the_full_rho():
    b = bernoulli(0.5, 3000, 13)
    c = refreshed_copy(b, 0.5, 0.3, 14)[:2500]
    times = np.sort(np.random.default_rng(15).uniform(0, 1e-5, c.size))
    run = running_correlation(b, c, times, n_points=50)
    assert run.n_events[-1] == 2500 and run.times[-1] == times[-1]
    assert run.rho[-1] == pytest.approx(pearson_by_index(b, c), rel=1e-12)
    for i in (0, 17, 31):  # every prefix is the Pearson of that prefix
        m = run.n_events[i]
        assert run.rho[i] == pytest.approx(pearson_by_index(b[:m], c[:m]), abs=1e-12)
        assert run.times[i] == times[m - 1]
    assert np.all(np.diff(run.n_events) > 0)
    with pytest.raises(InputError) as err:
        running_correlation(b, c, times[::-1], n_points=10)
    assert err.value.field.startswith("detection_times")


def test_output_signal_orders_detections_by_time():
    out = output_signal_from_events([3.0, 1.0, 2.0, 1.0], ["UP", "down", "up", "Up"])
    assert out.bits.tolist() == [False, True, True, True]
    assert out.times.tolist() == [1.0, 1.0, 2.0, 3.0]
    assert out.order.tolist() == [1, 3, 2, 0]  # simultaneous events keep their given order
    with pytest.raises(InputError) as err:
        output_signal_from_events([1.0, 2.0], ["up", "left"])
    assert err.value.field == "chambers[1]"
    with pytest.raises(InputError) as err:
        output_signal_from_events([1.0, 2.0], [1])
    assert err.value.field == "chambers"


def test_occupancy_from_a_hand_made_event_list():
    # UP: injected at 0, 10, 20; detected at 15 and 30. DOWN: injected at 5, 25;
    # one annihilated at 12, none detected.
    inj_t = [0, 5, 10, 20, 25]
    inj_c = [1, 0, 1, 1, 0]
    result = occupancy(
        inj_t,
        inj_c,
        [15, 30],
        [True, True],
        times=[-1, 0, 7, 12, 15, 22, 40],
        annihilation_times=[12],
        annihilation_chambers=["down"],
    )
    assert result.up.tolist() == [0, 1, 1, 2, 1, 2, 1]
    assert result.down.tolist() == [0, 0, 1, 0, 0, 0, 1]
    every_event = occupancy(
        inj_t, inj_c, [15, 30], [1, 1], annihilation_times=[12], annihilation_chambers=[0]
    )
    assert every_event.times.tolist() == [0, 5, 10, 12, 15, 20, 25, 30]
    assert every_event.up.max() == 2 and every_event.down.max() == 1


def test_transit_times_match_by_id():
    inj_ids = [7, 3, 11, 5]
    inj_t = [0.0, 5.0, 10.0, 15.0]
    det_ids = [11, 7, 5]  # id 3 was never detected
    det_t = [40.0, 42.0, 30.0]
    result = transit_times(inj_ids, inj_t, det_ids, det_t, quantiles=(0.5,))
    assert result.ids.tolist() == [11, 7, 5]
    assert result.transit.tolist() == [30.0, 42.0, 15.0]
    assert result.mean == pytest.approx(29.0) and result.median == 30.0
    assert result.quantiles == {0.5: 30.0}
    assert result.n_undetected == 1
    with pytest.raises(InputError) as err:
        transit_times(inj_ids, inj_t, [4], [50.0])
    assert err.value.field == "detection_ids[0]"
    with pytest.raises(InputError) as err:
        transit_times(inj_ids, inj_t, [5], [1.0])
    assert err.value.field == "detection_times[0]"
    with pytest.raises(InputError) as err:
        transit_times([1, 1], [0.0, 1.0], [], [])
    assert err.value.field == "injection_ids"


def test_bad_inputs_name_the_field():
    with pytest.raises(InputError) as err:
        pearson_by_index([], [1, 0])
    assert err.value.field == "b"
    with pytest.raises(InputError) as err:
        pearson_by_index([1, 0], [1, 2])
    assert err.value.field == "c[1]"
    with pytest.raises(InputError) as err:
        pearson_vs_lag([1, 0, 1], [1, 0, 1], max_lag=2)
    assert err.value.field == "max_lag"
    with pytest.raises(InputError) as err:
        running_correlation([1, 0, 1], [1, 0, 1], [0.0, 1.0], n_points=5)
    assert err.value.field == "detection_times"
