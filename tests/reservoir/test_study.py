"""The default study: XOR from one device, and a fading memory."""

from __future__ import annotations

import pytest

from skygas.reservoir.config import reservoir_config
from skygas.reservoir.study import run_study


@pytest.mark.slow
def test_default_study_beats_chance_on_xor_and_remembers_the_last_input():
    config = reservoir_config({"study": {"workers": 1}})  # the default settings, one process
    summary, _ = run_study(config)
    xor = summary["xor"]
    assert xor["n_test"] == 240
    # statistical: the trained read-out beats chance by at least 10 standard errors
    assert (xor["accuracy"] - 0.5) / (0.5 / xor["n_test"] ** 0.5) >= 10, xor
    recall = summary["temporal"]["recall"]
    first, third = recall["1"], recall["3"]
    # the state still holds the previous input (3 standard errors above chance) ...
    assert first["margin_standard_errors"] > 3, recall
    # ... and forgets older ones (fading memory)
    assert third["accuracy"] < first["accuracy"], recall
