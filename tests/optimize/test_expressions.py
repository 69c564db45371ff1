"""Objectives and constraints: a whitelist of arithmetic, never Python's eval."""

from __future__ import annotations

import math

import pytest

from skygas.core.errors import InputError
from skygas.optimize.expressions import check_consistent, parse_constraint, parse_expression

NAMES = ("correlation", "n_detected", "simulated_time_s", "energy_per_bit_J")


def test_arithmetic_of_quantities_is_evaluated_exactly():
    e = parse_expression("n_detected / simulated_time_s - 2 ** 3 * abs(-correlation)", "o", NAMES)
    values = {"n_detected": 800.0, "simulated_time_s": 4e-6, "correlation": 0.25}
    assert e(values) == pytest.approx(800 / 4e-6 - 8 * 0.25, rel=1e-15)
    assert e.names == {"n_detected", "simulated_time_s", "correlation"}
    assert parse_expression("log10(energy_per_bit_J)", "o", NAMES)({"energy_per_bit_J": 1e-15}) == (
        pytest.approx(-15.0)
    )
    assert parse_expression("max(correlation, 0.5)", "o", NAMES)({"correlation": 0.2}) == 0.5
    # undefined arithmetic is NaN (a trial without a value), never an exception
    assert math.isnan(parse_expression("log(correlation)", "o", NAMES)({"correlation": -1.0}))
    assert math.isnan(parse_expression("correlation / 0", "o", NAMES)({"correlation": 0.0}))


@pytest.mark.parametrize(
    "text",
    [
        "__import__('os').getcwd()",
        "correlation.real",
        "[correlation][0]",
        "'correlation'",
        "open('x')",
        "correlation if True else 0",
        "lambda: 1",
        "rho",
        "1 + 2",  # no quantity at all
        "",
        "correlation <",
    ],
)
def test_anything_but_arithmetic_of_known_quantities_is_refused(text):
    with pytest.raises(InputError, match="objectives"):
        parse_expression(text, "objectives[0].expression", NAMES)


def test_constraints_give_their_violation_and_contradictions_are_refused():
    upper = parse_constraint("correlation < 0.05", "c", NAMES)
    lower = parse_constraint("n_detected / simulated_time_s >= 1.8e8", "c", NAMES)
    assert upper.violation({"correlation": 0.02}) == pytest.approx(-0.03)
    assert lower.violation({"n_detected": 700.0, "simulated_time_s": 4e-6}) == pytest.approx(5e6)
    check_consistent([upper, lower])  # different expressions
    check_consistent(
        [
            parse_constraint("correlation <= 0.1", "c", NAMES),
            parse_constraint("correlation >= 0.1", "c", NAMES),
        ]
    )  # the single value 0.1 meets both
    with pytest.raises(InputError, match="contradict"):
        check_consistent(
            [
                parse_constraint("correlation<0.1", "c", NAMES),
                parse_constraint("correlation > 0.2", "c", NAMES),
            ]
        )
    with pytest.raises(InputError, match="contradict"):
        check_consistent(
            [
                parse_constraint("correlation < 0.1", "c", NAMES),
                parse_constraint("correlation >= 0.1", "c", NAMES),
            ]
        )
    for bad in (
        "correlation",
        "0.1 > correlation > 0",
        "correlation < n_detected",
        "correlation == 1",
    ):
        with pytest.raises(InputError):
            parse_constraint(bad, "c", NAMES)


@pytest.mark.parametrize(
    ("text", "unit"),
    [
        ("throughput_Hz", "Hz"),
        ("abs(correlation)", ""),
        ("mean_transit_s - median_transit_s", "s"),
        ("max(mean_transit_s, median_transit_s)", "s"),
        ("power_W / power_W", ""),
        ("-log10(abs(correlation))", ""),
        ("2 * correlation - 1", ""),
        # not derived: a change of unit, a count per second, a time against a bare number, the
        # root of a power, a sum of two units
        ("energy_per_bit_J * 1e15", None),
        ("n_detected / simulated_time_s", None),
        ("min(mean_transit_s, 1e-6)", None),
        ("sqrt(power_W)", None),
        ("mean_transit_s + power_W", None),
    ],
)
def test_the_unit_of_an_objective_follows_from_its_quantities(text, unit):
    from skygas.core.quantities import quantity
    from skygas.optimize.devices import device
    from skygas.optimize.expressions import unit_of

    expression = parse_expression(text, "objective", device("reshuffler").quantities)
    assert unit_of(expression, lambda name: quantity(name).unit) == unit
