"""``skygas check-timestep`` on every device's configuration, and ``--strict`` before the run.

The time-step check compares a run at dt with one at dt/2 on the same Brownian path
(:mod:`skygas.runs.timestep`); here it is run on each device's engine as the device builds it.
What ``--strict`` can decide from a configuration (drift per step, forces per step) is decided
before any step is taken.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from skygas.cli import main
from skygas.commands.check_timestep import (
    MARKERS,
    check_device_time_step,
    detect_device,
    load_device_config,
)
from skygas.core.config_types import read_toml
from skygas.core.errors import InputError
from skygas.engine import Simulation

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.mark.parametrize(
    "path, device",
    [
        ("closed-chamber.toml", "simulate"),
        ("neuron.toml", "neuron"),
        ("reservoir/default.toml", "reservoir"),
    ],
)
def test_the_device_is_recognised_from_the_tables(path, device):
    assert detect_device(read_toml(EXAMPLES / path), path) == device


def test_a_configuration_that_names_no_device_or_two_is_refused():
    assert detect_device({"preset": "paper", "current_density": 1e11}, "r.toml") == "reshuffle"
    with pytest.raises(InputError, match="--device simulate|reshuffle"):
        detect_device({"device": {"chamber_diameter": 1e-6}}, "both.toml")  # neuron or reshuffler?
    with pytest.raises(InputError, match="it has those of simulate, reservoir"):
        detect_device({"skyrmions": {}, "chamber": {}}, "mixed.toml")
    with pytest.raises(InputError, match="this is a sweep file"):
        detect_device(read_toml(EXAMPLES / "sweeps" / "quick-current.toml"), "quick-current.toml")
    assert all(not (a & b) for a in MARKERS.values() for b in MARKERS.values() if a is not b)


@pytest.mark.parametrize("device", ["reshuffle", "neuron", "reservoir"])
def test_each_devices_default_step_passes_with_its_skyrmions_compared(device):
    _, config = load_device_config(device, None, None)
    result = check_device_time_step(device, config)
    assert result["skyrmions_placed"] >= 1
    # every skyrmion placed is still there at the end of both runs (closed outlines, 2 ns)
    assert result["skyrmions_compared"] == result["skyrmions_placed"]
    assert result["max_difference_diameters"] <= 0.01 and result["findings"] == []
    assert result["passed"]


def test_a_longer_step_separates_the_paths_further_and_a_fast_drift_is_a_finding():
    _, config = load_device_config("reshuffle", None, None)
    good = check_device_time_step("reshuffle", config)
    coarse = check_device_time_step("reshuffle", config, time_step=5e-10)  # 4.5× the default
    assert coarse["max_difference"] > 2 * good["max_difference"]
    _, neuron = load_device_config("neuron", None, None)
    # the release current (3.8e11 A/m², v_s = ξJ = 70 m/s) carries a skyrmion 0.9 d_sk in 0.5 ns
    fast = check_device_time_step("neuron", neuron, time_step=5e-10)
    assert not fast["passed"]
    assert len(fast["findings"]) == 1 and fast["findings"][0].startswith("time_step = 5e-10")


def test_check_timestep_command_on_a_reshuffler_preset(capsys):
    status = main(["check-timestep", "--device", "reshuffle", "--preset", "default", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert status == 0 and out["device"] == "reshuffle" and out["passed"]
    assert main(["check-timestep", str(EXAMPLES / "reservoir" / "default.toml")]) == 0
    assert capsys.readouterr().out.startswith("reservoir configuration (")


@pytest.fixture
def no_stepping(monkeypatch):
    """Fail loudly if anything advances a simulation."""

    def refuse(*args, **kwargs):
        raise AssertionError("a simulation was stepped before --strict decided")

    monkeypatch.setattr(Simulation, "_advance", refuse)


def test_strict_refuses_a_too_long_step_before_any_stepping(no_stepping, tmp_path, capsys):
    out = tmp_path / "run"
    argv = ["reshuffle", "--strict", "--quiet", "--time-step", "1e-9", "--out", str(out)]
    assert main(argv) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("skygas: error: --time-step = 1e-09: ")
    assert "diameters per step" in lines[0]
    assert not out.exists()
    neuron = tmp_path / "neuron.toml"
    text = (EXAMPLES / "neuron.toml").read_text()
    assert "time_step = 2.5e-10" in text
    neuron.write_text(text.replace("time_step = 2.5e-10", "time_step = 5e-10"))
    assert main(["neuron", str(neuron), "--strict", "--quiet", "--out", str(out)]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("skygas: error: time_step = 5e-10: ")
    assert not out.exists()


@pytest.mark.slow
def test_the_demo_passes_strict(tmp_path, capsys):
    """``skygas demo --strict`` (100 µs of the reshuffler's defaults) runs to the end."""
    argv = ["demo", "--strict", "--json", "--no-report", "--out", str(tmp_path / "d")]
    assert main(argv) == 0
    captured = capsys.readouterr()
    assert "warning" not in captured.err
    summary = json.loads(captured.out)
    assert summary["simulated_time_s"] == pytest.approx(100e-6)


def test_a_refused_long_run_prints_its_refusal_and_no_estimate(
    no_stepping, tmp_path, capsys, monkeypatch
):
    """The estimate of a long run is held back until the run is accepted."""
    monkeypatch.setenv("SKYGAS_STEP_SECONDS", "1e-4")  # 9e5 steps: about 13 min, announced
    argv = ["reshuffle", "--strict", "--current-density", "1e20", "--out", str(tmp_path / "r")]
    assert main(argv) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("skygas: error: --current-density = 1e+20")
