"""Gates on whole streams against their closed-form p-values."""

import numpy as np
import pytest

from skygas.sc import (
    Circuit,
    ShuffleBuffer,
    and_,
    and_probability,
    bernoulli_stream,
    c_element,
    correlated_pair,
    jk_flip_flop,
    mux,
    not_,
    or_,
    or_probability,
    p_value,
    scc,
    xor,
    xor_probability,
)

N = 20_000


def _binomial_band(q, n_bits, sigmas=5.0):
    return sigmas * np.sqrt(q * (1 - q) / n_bits)


@pytest.mark.parametrize(("pa", "pb"), [(0.2, 0.7), (0.5, 0.5), (0.9, 0.35)])
def test_and_of_independent_streams_multiplies_within_binomial_error(pa, pb):
    a = bernoulli_stream(pa, N, seed=1)
    b = bernoulli_stream(pb, N, seed=2)
    q = pa * pb
    assert abs(p_value(and_(a, b)) - q) < _binomial_band(q, N)
    assert abs(p_value(or_(a, b)) - or_probability(pa, pb)) < _binomial_band(pa + pb - q, N)
    assert abs(p_value(xor(a, b)) - xor_probability(pa, pb)) < 0.02
    assert np.array_equal(not_(a), ~a)


@pytest.mark.parametrize("s", [-1.0, -0.5, 0.3, 1.0])
def test_and_or_xor_under_a_given_scc_match_the_closed_form(s):
    pa, pb = 0.3, 0.55
    a, b = correlated_pair(pa, pb, s, N, shape=(8,), seed=7)
    measured_scc = scc(a, b)
    # Closed form evaluated at the measured p-values and SCC of each pair: an identity, so it
    # must agree to round-off whatever the sampling noise.
    pa_hat, pb_hat = p_value(a), p_value(b)
    assert np.allclose(p_value(and_(a, b)), and_probability(pa_hat, pb_hat, measured_scc))
    assert np.allclose(p_value(or_(a, b)), or_probability(pa_hat, pb_hat, measured_scc))
    assert np.allclose(p_value(xor(a, b)), xor_probability(pa_hat, pb_hat, measured_scc))
    # And at the nominal values, within sampling error (SCC standard error ~0.02 here).
    assert abs(p_value(and_(a, b)).mean() - and_probability(pa, pb, s)) < 0.01


def test_closed_forms_at_the_extremes():
    pa, pb = 0.3, 0.8
    assert and_probability(pa, pb, 1) == pytest.approx(0.3)
    assert and_probability(pa, pb, -1) == pytest.approx(0.1)
    assert or_probability(pa, pb, 1) == pytest.approx(0.8)
    assert xor_probability(pa, pb, 1) == pytest.approx(0.5)  # |p_a - p_b|
    assert xor_probability(pa, pb, -1) == pytest.approx(0.9)  # min(p_a + p_b, 2 - p_a - p_b)


def test_xor_of_maximally_correlated_streams_is_the_absolute_difference():
    rng = np.random.default_rng(3)
    r = rng.random(N)
    a, b = r < 0.7, r < 0.25
    assert scc(a, b) == pytest.approx(1.0)
    assert p_value(xor(a, b)) == pytest.approx(p_value(a) - p_value(b))


def test_mux_scaled_addition():
    a = bernoulli_stream(0.2, N, seed=4)
    b = bernoulli_stream(0.9, N, seed=5)
    s = bernoulli_stream(0.5, N, seed=6)
    assert abs(p_value(mux(a, b, s)) - 0.55) < _binomial_band(0.55, N)


def test_jk_flip_flop_divides():
    pj, pk = 0.2, 0.3
    j = bernoulli_stream(pj, 50_000, seed=8)
    k = bernoulli_stream(pk, 50_000, seed=9)
    q = jk_flip_flop(j, k)
    # Markov chain with lag-1 autocorrelation r = 1 - pj - pk: variance of the mean is
    # p(1-p)/N (1+r)/(1-r); 5 sigma band.
    target, r = pj / (pj + pk), 1 - pj - pk
    sigma = np.sqrt(target * (1 - target) / 50_000 * (1 + r) / (1 - r))
    assert abs(p_value(q) - target) < 5 * sigma
    # The batched path gives the same bits as the scalar path.
    batch = jk_flip_flop(np.stack([j[:500], j[:500]]), np.stack([k[:500], k[:500]]))
    assert np.array_equal(batch[0], q[:500]) and np.array_equal(batch[1], q[:500])


def test_c_element_fuses_like_bayes_rule():
    pa, pb = 0.7, 0.6
    a = bernoulli_stream(pa, 50_000, seed=10)
    b = bernoulli_stream(pb, 50_000, seed=11)
    target = pa * pb / (pa * pb + (1 - pa) * (1 - pb))
    assert abs(p_value(c_element(a, b)) - target) < 0.02
    # Hold behaviour on a hand-made example.
    a = np.array([1, 0, 0, 1, 1, 0], dtype=bool)
    b = np.array([0, 0, 1, 1, 0, 1], dtype=bool)
    assert c_element(a, b, initial=True).tolist() == [True, False, False, True, True, True]


def test_circuit_squares_only_after_a_decorrelator():
    p = 0.6
    circuit = Circuit(inputs=["x"])
    circuit.add("naive", and_, "x", "x")
    circuit.add_decorrelator("copy", ShuffleBuffer(64), "x")
    circuit.add("square", and_, "x", "copy")
    x = bernoulli_stream(p, N, seed=12)
    out = circuit.evaluate({"x": x}, seed=13)
    assert p_value(out["naive"]) == p_value(x)  # p, not p^2
    # x AND copy has p-value p^2 up to binomial noise (the copy's slight dependence on x at
    # depth 64 is below this band).
    assert abs(p_value(out["square"]) - p * p) < _binomial_band(p * p, N)
    again = circuit.evaluate({"x": x}, seed=13)
    assert np.array_equal(again["square"], out["square"])
