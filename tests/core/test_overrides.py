"""One way to override a configuration: dotted keys, for every device."""

from __future__ import annotations

import pytest

from skygas.core.config_types import apply_overrides
from skygas.core.errors import InputError


def test_dotted_keys_reach_nested_tables_and_lists_without_touching_the_original():
    data = {"seed": 1, "signal": {"p": 0.5, "kind": "bernoulli"}, "potentials": [{"rms": 1.0}]}
    out = apply_overrides(
        data, {"seed": 2, "signal.p": 0.3, "potentials.0.rms": 2.0, "gate.on": None}
    )
    assert out == {
        "seed": 2,
        "signal": {"p": 0.3, "kind": "bernoulli"},
        "potentials": [{"rms": 2.0}],
    }
    assert data["signal"]["p"] == 0.5 and data["potentials"][0]["rms"] == 1.0


def test_an_index_past_a_list_is_one_line():
    with pytest.raises(InputError, match="an index below 1"):
        apply_overrides({"potentials": [{"rms": 1.0}]}, {"potentials.3.rms": 2.0})


@pytest.mark.parametrize(
    ("key", "words"),
    [
        ("seed.x", "seed is a value"),  # through a number
        ("signal.p.q", "signal.p is a value"),
        ("vertices.5", "an index below 2"),  # past the end of a list of numbers
        ("vertices.x", "an index below 2"),
        ("potentials.0.rms.x", "potentials.0.rms is a value"),
    ],
)
def test_a_key_that_does_not_fit_the_data_is_one_line(key, words):
    data = {"seed": 1, "signal": {"p": 0.5}, "vertices": [1.0, 2.0], "potentials": [{"rms": 1}]}
    with pytest.raises(InputError, match=words):
        apply_overrides(data, {key: 3.0})
    assert data == {
        "seed": 1,
        "signal": {"p": 0.5},
        "vertices": [1.0, 2.0],
        "potentials": [{"rms": 1}],
    }


def test_an_element_of_a_list_of_numbers_can_be_set():
    assert apply_overrides({"center": [1.0, 2.0]}, {"center.1": 5.0}) == {"center": [1.0, 5.0]}


def test_the_neuron_and_the_reservoir_take_dotted_overrides():
    from skygas.neuron.config import neuron_config
    from skygas.reservoir.config import reservoir_config

    assert neuron_config(**{"gate.barrier_height": 12.0}).gate.barrier_height == 12.0
    assert reservoir_config(**{"seed": 9}).seed == 9
