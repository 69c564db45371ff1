"""Bad neuron and saturation input is refused with an InputError that names the field, the value
and what is allowed, before anything long runs."""

import math
import time

import pytest

from skygas.cli import main
from skygas.core.errors import InputError
from skygas.neuron import NeuronDevice, neuron_config

SMALL = {"chamber_diameter": 400e-9, "conduit_width": 80e-9, "conduit_length": 50e-9}


@pytest.mark.parametrize(
    "data, field",
    [
        ({"duration": math.inf}, "duration"),
        ({"current_density": math.inf}, "current_density"),
        ({"release_current_density": -1e11}, "release_current_density"),
        ({"rule": {"release_time": math.inf}}, "rule.release_time"),
        ({"rule": {"refractory_time": -1e-9}}, "rule.refractory_time"),
        ({"sensor": {"center": [math.nan, 0.0]}}, "sensor.center"),
        ({"sensor": {"read_noise": -0.1}}, "sensor.read_noise"),
        ({"annihilation": {"check_interval": math.inf}}, "annihilation.check_interval"),
        ({"inputs": [{"kind": "bits", "bits": [0, 2]}]}, "inputs.0.bits"),
        ({"inputs": [{"kind": "bits"}]}, "inputs.0"),
        ({"inputs": [{"kind": "telegraph", "p": 1.0}]}, "inputs.0"),
        ({"transfer": {"rates": [1e7, -1e7]}}, "transfer.rates"),
    ],
)
def test_config_refuses_bad_values(data, field):
    with pytest.raises(InputError) as err:
        neuron_config({"device": SMALL, **data})
    assert field in err.value.field
    assert "expected" in str(err.value)


@pytest.mark.parametrize(
    "data, field",
    [
        ({"device": {**SMALL, "conduit_length": 20e-9}}, "device.conduit_length"),
        ({"gate": {"band_width": 80e-9}}, "gate.band_width"),
        ({"gate": {"edge_width": 1e-9}}, "gate.edge_width"),
        ({"gate": {"band_width": 20e-9, "edge_width": 15e-9}}, "gate.edge_width"),
        ({"gate": {"barrier_height": 100.0}}, "gate.barrier_height"),
        ({"rule": {"threshold": 4, "reset_level": 4}}, "rule.reset_level"),
        ({"rule": {"threshold": 500}}, "rule.threshold"),
    ],
)
def test_device_refuses_bad_values_before_building(data, field):
    start = time.perf_counter()
    with pytest.raises(InputError) as err:
        NeuronDevice(neuron_config({"device": SMALL, **data}))
    assert err.value.field == field
    assert time.perf_counter() - start < 2.0  # no simulation, no current solve


def test_cli_reports_bad_input_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "n"
    assert main(["neuron", "--out", str(out), "--duration=-1e-9"]) == 2
    assert "duration" in capsys.readouterr().err and not out.exists()
    assert main(["saturation", "--diameters", "5e-7", "abc", "--out", str(tmp_path / "s")]) == 2
    assert "diameters[1] = 'abc'" in capsys.readouterr().err
    assert (
        main(
            ["saturation", "--diameters", "5e-7", "--relax-time", "0", "--out", str(tmp_path / "s")]
        )
        == 2
    )
    assert "--relax-time = 0.0" in capsys.readouterr().err


def test_analyses_refuse_bad_arguments_before_running():
    from skygas.neuron import measure_leak, transfer_curve

    device = NeuronDevice(neuron_config({"device": SMALL}))
    with pytest.raises(InputError, match="initial_count"):
        measure_leak(device, initial_count=-3, duration=1e-8)
    with pytest.raises(InputError, match="duration"):
        measure_leak(device, initial_count=3, duration=math.inf)
    with pytest.raises(InputError, match="transfer.rates"):
        transfer_curve(device, [1e7, math.nan], duration=1e-8)
    with pytest.raises(InputError, match="duration"):
        transfer_curve(device, [1e7], duration=0.0)
