"""The Skyrmion Neuron: conservation, leak, transfer curve, saturation, validation, CLI."""

import json
import math

import numpy as np
import pytest

from skygas.cli import main
from skygas.core.errors import InputError
from skygas.neuron import (
    AnnihilationModel,
    NeuronDevice,
    measure_leak,
    neuron_config,
    saturation_curve,
    transfer_curve,
)
from skygas.neuron.gate import ReadElement

SMALL = {"chamber_diameter": 400e-9, "conduit_width": 80e-9, "conduit_length": 50e-9}


def test_closed_gate_without_annihilation_conserves_injections():
    cfg = neuron_config(
        {
            "device": SMALL,
            "duration": 120e-9,
            "current_density": 1e11,
            "rule": {"threshold": 8, "reset_level": 1},
            "annihilation": {"enabled": False},
            "inputs": [{"kind": "regular", "rate": 1e8}],
        }
    )
    device = NeuronDevice(cfg)
    run = device.build()
    run.controller.threshold = math.inf  # keep the gate closed whatever the count
    run.run()
    assert run.injector.n_injected == 12
    assert run.sim.count == run.injector.n_injected
    assert not run.sim.exits and run.annihilator.n_annihilated == 0
    assert np.all(np.diff(run.trace()["count"]) >= 0)


def test_leak_time_matches_the_annihilation_rate():
    rate = 1e7
    cfg = neuron_config(
        {
            "device": {**SMALL, "chamber_diameter": 700e-9},
            "temperature": 0.0,
            "current_density": 0.0,
            "rule": {"threshold": 5, "reset_level": 1},
            "annihilation": {
                "base_rate": rate,
                "compression_sensitivity": 0.0,
                "check_interval": 1e-9,
            },
            "inputs": [],
        }
    )
    result = measure_leak(NeuronDevice(cfg), initial_count=40, duration=300e-9, seed=3)
    assert result["n_annihilated"] > 25
    assert abs(result["leak_time_s"] - 1 / rate) < 3 * result["leak_time_error_s"]


def test_firing_rate_rises_with_input_and_vanishes_below_threshold():
    cfg = neuron_config(
        {
            "device": SMALL,
            "current_density": 1e11,
            "rule": {"threshold": 6, "reset_level": 1, "release_time": 20e-9},
            "annihilation": {
                "base_rate": 2e7,
                "compression_sensitivity": 0.0,
                "check_interval": 0.5e-9,
            },
            "sensor": {"read_interval": 1e-9},
        }
    )
    curve = transfer_curve(NeuronDevice(cfg), [1e7, 2e7, 2e8, 6e8], duration=500e-9, seed=1)
    f = np.array(curve["firing_rate_Hz"])
    assert f[0] == 0 and f[1] == 0  # r·τ = 0.5, 1 ≪ θ = 6
    assert f[2] > 0 and f[3] > f[2]
    assert np.all(np.diff(f) >= 0)


def test_saturation_count_grows_with_chamber_diameter():
    result = saturation_curve(
        [200e-9, 320e-9], repetitions=3, seed=2, trial_counts=lambda d: [4, 10, 20, 30]
    )
    assert result.max_count[1] > result.max_count[0] > 0
    assert np.all(result.max_count < result.close_packing)


def test_annihilation_off_and_compression_raise_the_rate_only_when_crowded():
    from skygas.neuron.annihilation import compression

    x = np.array([0.0, 50.0, 1000.0])
    chi = compression(x, np.zeros(3), np.full(3, 500.0), crowding_nm=100.0)
    assert chi[0] == pytest.approx(0.5) and chi[1] == pytest.approx(0.5) and chi[2] == 0
    assert not AnnihilationModel.off().enabled


def test_area_sensor_reads_the_covered_fraction():
    sensor = ReadElement((0, 0), 100.0, "area", skyrmion_diameter_nm=40.0, area_samples=4000)
    assert sensor.exact(np.array([0.0]), np.array([0.0])) == pytest.approx(0.04, abs=0.003)
    counter = ReadElement((0, 0), 100.0, "count")
    assert counter.exact(np.array([0.0, 50.0, 150.0]), np.zeros(3)) == 2


@pytest.mark.parametrize(
    "data, field",
    [
        ({"inputs": [{"kind": "poisson", "rate": -1e8}]}, "inputs[0].rate"),
        ({"annihilation": {"base_rate": -1.0}}, "annihilation.base_rate"),
    ],
)
def test_negative_rates_are_refused(data, field):
    with pytest.raises(InputError, match=field.replace("[", r"\[").replace("]", r"\]")):
        neuron_config({"device": SMALL, **data})


def test_threshold_above_saturation_and_sensor_outside_are_refused_before_running():
    with pytest.raises(InputError, match="rule.threshold"):
        NeuronDevice(neuron_config({"device": SMALL, "rule": {"threshold": 500}}))
    with pytest.raises(InputError, match="sensor"):
        NeuronDevice(
            neuron_config(
                {
                    "device": SMALL,
                    "rule": {"threshold": 3},
                    "sensor": {"center": [150e-9, 0.0], "radius": 100e-9},
                }
            )
        )


def test_cli_neuron_and_saturation(tmp_path, capsys):
    config = tmp_path / "neuron.toml"
    config.write_text(
        "duration = 60e-9\n[device]\nchamber_diameter = 400e-9\nconduit_width = 80e-9\n"
        "[rule]\nthreshold = 4\nreset_level = 1\nrelease_time = 10e-9\n"
        "[annihilation]\nbase_rate = 2e7\ncompression_sensitivity = 0.0\n"
        "[transfer]\nrates = [1e7, 3e8]\nduration = 40e-9\n"
        "[[inputs]]\nkind = 'poisson'\nrate = 3e8\n"
    )
    assert main(["neuron", str(config), "--out", str(tmp_path / "n"), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    for key in (
        "output_spikes",
        "firing_rate_Hz",
        "input_rate_Hz",
        "leak_time_s",
        "threshold",
        "max_count",
        "n_annihilated",
        "n_injected",
    ):
        assert key in summary
    assert (tmp_path / "n" / "count_trace.png").exists()
    assert (tmp_path / "n" / "transfer_curve.png").exists()
    assert (tmp_path / "n" / "device.png").exists()
    assert (
        main(
            [
                "saturation",
                "--diameters",
                "2e-7",
                "--repetitions",
                "1",
                "--out",
                str(tmp_path / "s"),
                "--json",
            ]
        )
        == 0
    )
    assert json.loads(capsys.readouterr().out)["max_count"][0] > 0
    assert (tmp_path / "s" / "max_density.png").exists()
