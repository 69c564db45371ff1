"""The table of quantity names and the way every report writes a number."""

from __future__ import annotations

import math

import pytest

from skygas.core.quantities import QUANTITIES, format_quantity, format_value, label, quantity


@pytest.mark.parametrize(
    "key, value, error, text",
    [
        ("correlation", 0.2806, 0.046, "0.281 ± 0.046"),
        ("energy_per_bit_J", 9.624e-15, None, "9.624 fJ"),
        ("mean_transit_s", 2.104e-7, None, "210.4 ns"),
        ("free_diffusion_m2_s", 4.38e-9, None, "4.38×10⁻⁹ m²/s"),
        ("free_diffusion_m2_s", 2.91e-8, 0.16e-8, "(2.91 ± 0.16)×10⁻⁸ m²/s"),
        ("current_density_A_m2", 1.7e11, None, "1.7×10¹¹ A/m²"),
        ("n_detected", 153, None, "153"),
        ("n_detected", 153.0, None, "153"),  # a count is an integer, however it was stored
        ("steps", 1234567, None, "1234567"),
        ("accuracy", 0.7, 0.158, "70 ± 16 %"),
        ("temperature_K", 300.0, None, "300 K"),
        ("tau_s", 9.06e-8, 3.2e-8, "91 ± 32 ns"),
        ("counts_conserved", True, None, "yes"),
        ("material", "S2", None, "S2"),
    ],
)
def test_values_are_written_with_units_prefixes_and_superscripts(key, value, error, text):
    assert format_quantity(key, value, error) == text


@pytest.mark.parametrize("value", [None, math.nan, math.inf, -math.inf])
def test_a_missing_value_has_no_writing(value):
    assert format_value(value) is None
    assert format_quantity("correlation", value, 0.1) is None


def test_no_writing_has_an_exponent_or_a_caret():
    for exponent in range(-20, 15):
        for unit in ("", "m²/s", "s", "A/m²"):
            text = format_value(1.234 * 10.0**exponent, 0.05 * 10.0**exponent, unit)
            assert text is not None and "e" not in text.replace("m²", "") and "^" not in text


def test_a_list_is_written_element_by_element_with_its_unit():
    assert format_quantity("diameters_m", [2e-7, 3e-7]) == "200 nm, 300 nm"


def test_keys_outside_the_table_get_a_label_and_unit_from_their_name():
    assert quantity("mean_speed_m_s").unit == "m/s" and label("mean_speed_m_s") == "mean speed"
    assert quantity("n_loops").kind == "count" and label("n_loops") == "number of loops"
    # a dotted configuration key is found by its last part
    assert quantity("device.chamber_diameter") == QUANTITIES["chamber_diameter"]


#: symbols written with an underscore, as physicists write them (no key names)
SYMBOLS = ("p_in", "p_out", "V_r", "k_BT", "D_eff", "c_A", "c_B", "d_sk")


def test_every_label_reads_as_words():
    for key, q in QUANTITIES.items():
        text = q.label
        for symbol in SYMBOLS:
            text = text.replace(symbol, "")
        assert "_" not in text, key
