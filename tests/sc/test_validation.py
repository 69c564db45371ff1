"""Bad input is refused early with an InputError naming the field and what is allowed."""

import numpy as np
import pytest

from skygas.core.errors import InputError
from skygas.sc import (
    Circuit,
    DelayIsolator,
    ShuffleBuffer,
    SuperparamagneticMTJ,
    and_,
    and_probability,
    bernoulli_stream,
    lfsr_stream,
    mux,
    scc,
    telegraph_stream,
)


def test_streams_of_different_lengths_are_refused():
    a = bernoulli_stream(0.5, 100, seed=1)
    b = bernoulli_stream(0.5, 99, seed=2)
    with pytest.raises(InputError) as err:
        and_(a, b)
    assert err.value.field == "b" and "100 bits" in str(err.value)
    with pytest.raises(InputError):
        scc(a, b)
    with pytest.raises(InputError):
        mux(a, a, b)


def test_non_boolean_arrays_are_refused():
    ints = np.array([0, 1, 1, 0])
    with pytest.raises(InputError) as err:
        and_(ints, ints)
    assert "boolean" in str(err.value) and "int" in str(err.value)
    with pytest.raises(InputError):
        DelayIsolator(1).apply(np.zeros(10))
    with pytest.raises(InputError):
        scc(np.zeros((3, 0), dtype=bool), np.zeros((3, 0), dtype=bool))


@pytest.mark.parametrize("p", [-0.1, 1.5, float("nan"), [0.2, 1.2]])
def test_p_outside_the_unit_interval_is_refused(p):
    with pytest.raises(InputError) as err:
        bernoulli_stream(p, 10, seed=1)
    assert err.value.field == "p" and "[0, 1]" in str(err.value)
    with pytest.raises(InputError):
        telegraph_stream(p, 3.0, 10)
    with pytest.raises(InputError):
        lfsr_stream(p, 10)
    with pytest.raises(InputError):
        and_probability(p, 0.5)


def test_other_parameters_are_checked():
    with pytest.raises(InputError):
        bernoulli_stream(0.5, 0)
    with pytest.raises(InputError):
        bernoulli_stream(0.5, 10, seed=-3)
    with pytest.raises(InputError):
        lfsr_stream(0.5, 10, width=33)
    with pytest.raises(InputError):
        telegraph_stream(0.5, 0.0, 10)
    with pytest.raises(InputError):
        and_probability(0.5, 0.5, scc=1.5)
    with pytest.raises(InputError):
        ShuffleBuffer(0)
    with pytest.raises(InputError):
        ShuffleBuffer(64).apply(np.zeros(10, dtype=bool))
    mtj = SuperparamagneticMTJ(1e9, 10.0, 1e-4, 1e-6)
    with pytest.raises(InputError):
        mtj.p_value(2e-4)  # beyond the critical current
    with pytest.raises(InputError):
        SuperparamagneticMTJ(1e9, -1.0, 1e-4, 1e-6)


def test_circuit_wiring_errors():
    circuit = Circuit(inputs=["x"])
    with pytest.raises(InputError):
        circuit.add("y", and_, "x", "nope")
    circuit.add("y", and_, "x", "x")
    with pytest.raises(InputError):
        circuit.add("y", and_, "x", "x")
    with pytest.raises(InputError):
        circuit.evaluate({"z": np.ones(4, dtype=bool)})
