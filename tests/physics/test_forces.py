"""Force laws (docs/physics.md §2), their cutoff, their tabulation and the wall potential."""

import math

import numpy as np
import pytest
from scipy import integrate, special

from skygas.core.errors import InputError
from skygas.physics.forces import (
    DEFAULT_CUTOFF_FRACTION,
    ForceTable,
    cutoff_distance,
    lin_reichhardt_pair_force,
    pair_law,
    paper_pair_force,
    paper_wall_force,
    wall_law,
    wall_potential,
)

S2_PAIR = (2.709, -5.643, 0.964)  # [a2, a1, a0], Appendix C row S2
WALL_B = (0.001419, -0.02631, 0.24135, -1.1609, 3.3547, -2.1786)  # Methods, highest power first
# Realistic S2 numbers (internal units): F0 = A_ex t_F / d_sk ≈ 1.44 pN, d_sk = 38.2 nm.
F0_PN = 27.5e-12 * 2e-9 / 38.2e-9 * 1e12
D_SK_NM = 38.2


def pair_closed_form(d, a2, a1, a0):
    return math.exp(-(a2 * d * d + a1 * d + a0) / (d + 1.0))


def wall_closed_form(d, b):
    """exp(−p(d)) with p = b[0] d^5 + b[1] d^4 + … + b[5] (Horner-free, term by term)."""
    n = len(b) - 1
    return math.exp(-sum(c * d ** (n - i) for i, c in enumerate(b)))


# -- laws ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("coeffs", [S2_PAIR, (1.245, 1.249, -3.449), (0.059, 10.757, -16.738)])
def test_pair_law_equals_its_closed_form(coeffs):
    d = np.array([0.0, 0.3, 0.8, 1.0, 1.7, 2.5, 4.0, 7.0])
    got = paper_pair_force(d, *coeffs)
    expected = [pair_closed_form(x, *coeffs) for x in d]
    np.testing.assert_allclose(got, expected, rtol=1e-13)
    # scalar input, and the callable built by pair_law("paper", …)
    assert float(paper_pair_force(1.3, *coeffs)) == pytest.approx(
        pair_closed_form(1.3, *coeffs), rel=1e-13
    )
    np.testing.assert_allclose(pair_law("paper", coeffs)(d), expected, rtol=1e-13)


def test_s2_pair_law_is_repulsive_and_decays_beyond_one_diameter():
    d = np.linspace(1.0, 6.0, 501)
    f = paper_pair_force(d, *S2_PAIR)
    assert np.all(f > 0) and np.all(np.diff(f) < 0)
    # at one diameter: exp(−(2.709 − 5.643 + 0.964)/2) = exp(0.985)
    assert f[0] == pytest.approx(math.exp(0.985), rel=1e-12)


def test_wall_law_equals_its_closed_form_highest_power_first():
    d = np.array([0.0, 0.25, 1.0, 2.0, 3.5, 5.0, 6.5])
    np.testing.assert_allclose(
        paper_wall_force(d, WALL_B), [wall_closed_form(x, WALL_B) for x in d], rtol=1e-12
    )
    np.testing.assert_allclose(wall_law(WALL_B)(d), paper_wall_force(d, WALL_B), rtol=0)
    # at the wall p(0) = b[-1]: |F|/F0 = exp(2.1786)
    assert float(paper_wall_force(0.0, WALL_B)) == pytest.approx(math.exp(2.1786), rel=1e-12)
    # centres beyond the wall (d < 0) get the contact value
    assert float(paper_wall_force(-0.7, WALL_B)) == float(paper_wall_force(0.0, WALL_B))


def test_wall_law_decreases_and_the_reversed_reading_grows():
    cutoff = cutoff_distance(wall_law(WALL_B))
    d = np.linspace(0.0, cutoff, 20_001)
    f = paper_wall_force(d, WALL_B)
    assert np.all(np.diff(f) < 0), "highest-power-first wall law must decrease away from the wall"
    # Read lowest power first, the same numbers give a force that grows without bound.
    with np.errstate(over="ignore", invalid="ignore"):
        g = paper_wall_force(d, WALL_B[::-1])
        assert g[-1] > 1e10 * g[0]
        assert not np.all(np.diff(g) < 0)


# -- cutoff -------------------------------------------------------------------------------------
@pytest.mark.parametrize("law_name", ["pair", "wall", "lin-reichhardt"])
@pytest.mark.parametrize("fraction", [1e-2, DEFAULT_CUTOFF_FRACTION, 1e-5])
def test_cutoff_distance_brackets_the_fraction(law_name, fraction):
    law = {
        "pair": pair_law("paper", S2_PAIR),
        "wall": wall_law(WALL_B),
        "lin-reichhardt": pair_law("lin-reichhardt", None, amplitude=2.0, decay_length=0.4),
    }[law_name]
    cutoff = cutoff_distance(law, fraction)
    small = 1e-3
    assert cutoff > 0
    assert float(law(cutoff)) < fraction
    assert float(law(cutoff - small)) >= fraction
    # and it stays below beyond the cutoff
    assert np.all(law(np.linspace(cutoff, cutoff + 20.0, 2001)) < fraction)


def test_default_cutoffs_for_s2_match_the_documented_values():
    # forces.py: pair law ≈ 5.07 d_sk (≈ 194 nm), wall law ≈ 6.7 d_sk (≈ 256 nm) at 1e-3 F0.
    # Solve law(d) = 1e-3 independently with a root finder.
    from scipy.optimize import brentq

    pair_root = brentq(lambda d: pair_closed_form(d, *S2_PAIR) - 1e-3, 2.0, 10.0)
    wall_root = brentq(lambda d: wall_closed_form(d, WALL_B) - 1e-3, 3.0, 10.0)
    assert cutoff_distance(pair_law("paper", S2_PAIR)) == pytest.approx(pair_root, abs=5e-4)
    assert cutoff_distance(wall_law(WALL_B)) == pytest.approx(wall_root, abs=5e-4)


def test_cutoff_distance_refuses_bad_fraction_and_non_decaying_law():
    for bad in (0.0, 1.0, -0.1, 2.0):
        with pytest.raises(InputError) as err:
            cutoff_distance(wall_law(WALL_B), bad)
        assert err.value.field == "cutoff_fraction"
    with pytest.raises(InputError):
        cutoff_distance(lambda d: np.ones_like(d), 0.5)


def test_law_entirely_below_the_fraction_has_zero_cutoff():
    assert cutoff_distance(lambda d: 1e-6 * np.exp(-d), 1e-3) == 0.0


# -- tabulation ---------------------------------------------------------------------------------
TABLE_CASES = [
    pytest.param("wall", False, id="wall-linear"),
    pytest.param("pair", False, id="pair-linear"),
    pytest.param("pair", True, id="pair-squared"),
]


def _law(name):
    return pair_law("paper", S2_PAIR) if name == "pair" else wall_law(WALL_B)


@pytest.mark.parametrize("law_name, squared", TABLE_CASES)
def test_force_table_is_accurate_beyond_a_quarter_diameter(law_name, squared):
    law = _law(law_name)
    # the engine tabulates the pair law with 8192 nodes in r², the wall law with 4096 in r
    n_points = 8192 if squared else 4096
    table = ForceTable.from_law(
        law, F0_PN, D_SK_NM, DEFAULT_CUTOFF_FRACTION, n_points=n_points, squared=squared
    )
    assert table.squared is squared
    assert table.cutoff == pytest.approx(cutoff_distance(law) * D_SK_NM, rel=1e-12)
    r_min = 0.25 * D_SK_NM
    assert table.max_relative_error(law, F0_PN, D_SK_NM, r_min=r_min) < 1e-4
    # independent check on a dense grid (not only at the midpoints between nodes)
    r = np.linspace(r_min, table.cutoff * (1 - 1e-9), 100_001)
    exact = F0_PN * law(r / D_SK_NM)
    assert np.max(np.abs(table(r) - exact) / exact) < 1e-4


@pytest.mark.parametrize("law_name, squared", [("pair", True), ("wall", False)])
def test_force_table_is_accurate_from_half_a_diameter(law_name, squared):
    # The layouts the engine uses (pair: squared, wall: linear) are accurate from 0.5 d_sk,
    # the closest placement the engine accepts.
    law = _law(law_name)
    # the engine tabulates the pair law with 8192 nodes in r², the wall law with 4096 in r
    n_points = 8192 if squared else 4096
    table = ForceTable.from_law(
        law, F0_PN, D_SK_NM, DEFAULT_CUTOFF_FRACTION, n_points=n_points, squared=squared
    )
    r = np.linspace(0.5 * D_SK_NM, table.cutoff * (1 - 1e-9), 50_001)
    exact = F0_PN * law(r / D_SK_NM)
    assert np.max(np.abs(table(r) - exact) / exact) < 1e-4


@pytest.mark.parametrize("law_name", ["pair", "wall"])
@pytest.mark.parametrize("squared", [False, True])
def test_force_table_is_zero_beyond_the_cutoff(law_name, squared):
    law = _law(law_name)
    # the engine tabulates the pair law with 8192 nodes in r², the wall law with 4096 in r
    n_points = 8192 if squared else 4096
    table = ForceTable.from_law(
        law, F0_PN, D_SK_NM, DEFAULT_CUTOFF_FRACTION, n_points=n_points, squared=squared
    )
    r = np.concatenate([[table.cutoff], table.cutoff + np.linspace(1e-6, 5 * D_SK_NM, 1001), [1e6]])
    assert np.all(table(r) == 0.0)
    # just inside, the force is the law's (about the cutoff fraction of F0, not zero)
    inside = table.cutoff * (1 - 1e-6)
    assert float(table(inside)) == pytest.approx(F0_PN * float(law(inside / D_SK_NM)), rel=1e-3)
    assert float(table(inside)) >= 0.5 * DEFAULT_CUTOFF_FRACTION * F0_PN


def test_squared_table_layout_stores_force_over_r_on_r_squared_nodes():
    law = _law("pair")
    table = ForceTable.from_law(
        law, F0_PN, D_SK_NM, DEFAULT_CUTOFF_FRACTION, squared=True, n_points=1001
    )
    assert table.spacing == pytest.approx(table.cutoff**2 / 1000, rel=1e-12)
    i = np.array([10, 200, 777])
    r = np.sqrt(i * table.spacing)
    np.testing.assert_allclose(table.values[i], F0_PN * law(r / D_SK_NM) / r, rtol=1e-12)
    # at a node the interpolated force is exact
    np.testing.assert_allclose(table(r), F0_PN * law(r / D_SK_NM), rtol=1e-12)


def test_linear_table_layout_stores_force_on_r_nodes():
    law = _law("wall")
    table = ForceTable.from_law(law, F0_PN, D_SK_NM, DEFAULT_CUTOFF_FRACTION, n_points=1001)
    assert table.spacing == pytest.approx(table.cutoff / 1000, rel=1e-12)
    i = np.array([0, 10, 500, 999])
    np.testing.assert_allclose(
        table.values[i], F0_PN * law(i * table.spacing / D_SK_NM), rtol=1e-12
    )


# -- potential ----------------------------------------------------------------------------------
def test_wall_potential_derivative_is_minus_the_force():
    d = np.array([0.1, 0.5, 1.0, 2.0, 3.0, 4.5, 6.0])
    h = 1e-4
    dudd = (wall_potential(d + h, WALL_B) - wall_potential(d - h, WALL_B)) / (2 * h)
    np.testing.assert_allclose(-dudd, paper_wall_force(d, WALL_B), rtol=1e-6)


def test_wall_potential_is_the_integral_of_the_force():
    cutoff = cutoff_distance(wall_law(WALL_B))
    u = wall_potential([0.0, 1.0, cutoff, cutoff + 1.0], WALL_B)
    ref0 = integrate.quad(lambda s: wall_closed_form(s, WALL_B), 0.0, cutoff)[0]
    ref1 = integrate.quad(lambda s: wall_closed_form(s, WALL_B), 1.0, cutoff)[0]
    assert u[0] == pytest.approx(ref0, rel=1e-8)
    assert u[1] == pytest.approx(ref1, rel=1e-8)
    assert u[2] == 0.0 and u[3] == 0.0
    assert np.all(np.diff(wall_potential(np.linspace(0, cutoff, 50), WALL_B)) <= 0)


# -- Lin–Reichhardt -----------------------------------------------------------------------------
@pytest.mark.parametrize("amplitude, decay", [(1.0, 0.5), (3.0, 0.25), (0.7, 1.2)])
def test_lin_reichhardt_law_is_amplitude_times_k1(amplitude, decay):
    d = np.array([0.1, 0.5, 1.0, 2.0, 3.0])
    expected = amplitude * special.k1(d / decay)
    np.testing.assert_allclose(lin_reichhardt_pair_force(d, amplitude, decay), expected, rtol=1e-13)
    np.testing.assert_allclose(
        pair_law("lin-reichhardt", S2_PAIR, amplitude=amplitude, decay_length=decay)(d),
        expected,
        rtol=1e-13,
    )
    # K1(x) ~ 1/x near contact; the law is held at d = 0.05 λ below that
    assert float(lin_reichhardt_pair_force(0.0, amplitude, decay)) == pytest.approx(
        amplitude * special.k1(0.05), rel=1e-13
    )


def test_lin_reichhardt_defaults_and_unknown_law():
    d = np.array([0.5, 1.0])
    np.testing.assert_allclose(lin_reichhardt_pair_force(d), special.k1(d / 0.5), rtol=1e-13)
    with pytest.raises(InputError) as err:
        pair_law("yukawa", S2_PAIR)
    assert err.value.field == "forces.pair_law"
