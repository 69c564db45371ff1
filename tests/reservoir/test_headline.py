"""The reservoir's headline numbers, recomputed here from the scores they state.

An accuracy is stated with its own uncertainty (the 68 % Wilson interval over the test
inputs), never with the standard error of the chance level, which once gave "98.3 ± 3.2 %":
an interval past 100 % that the accuracy figure contradicted.
"""

from __future__ import annotations

import math

from skygas.outputs.headlines import reservoir


def _wilson(a: float, n: int, z: float = 1.0) -> tuple[float, float]:
    """Wilson's score interval (E. B. Wilson, J. Am. Stat. Assoc. 22, 209 (1927))."""
    centre = (a + z * z / (2 * n)) / (1 + z * z / n)
    half = z / (1 + z * z / n) * math.sqrt(a * (1 - a) / n + z * z / (4 * n * n))
    return centre - half, centre + half


def _scores(right: int, n: int, chance: float) -> dict:
    return {
        "accuracy": right / n,
        "n_test": n,
        "chance": chance,
        "chance_standard_error": math.sqrt(chance * (1 - chance) / n),
    }


def test_each_accuracy_is_stated_with_its_own_interval_inside_0_and_100_percent():
    summary = {
        "xor": _scores(236, 240, 0.51),
        "temporal": {"recall": {"1": _scores(178, 240, 0.52)}, "parity_last_two": None},
    }
    rows = dict(reservoir(summary).rows)
    for label, (right, n) in {
        "XOR test accuracy": (236, 240),
        "recall of input a, 1 input(s) back": (178, 240),
    }.items():
        text = rows[label]
        lo, hi = _wilson(right / n, n)
        assert f"{100 * right / n:.1f} %" in text and f"({100 * lo:.1f}–{100 * hi:.1f} %)" in text
        assert "±" not in text and hi < 1.0
    assert "240 test inputs (chance 51" in rows["XOR test accuracy"]


def test_a_perfect_score_keeps_an_interval_below_it():
    rows = dict(reservoir({"xor": _scores(240, 240, 0.5)}).rows)
    lo, hi = _wilson(1.0, 240)
    assert f"({100 * lo:.1f}–{100 * hi:.1f} %)" in rows["XOR test accuracy"] and lo < 1.0
