"""The neuron's estimate prices what its job runs: the main run, the transfer curve's runs,
and the turns of its controller and annihilator (on the example they cost 50 times the steps)."""

from __future__ import annotations

from pathlib import Path

import pytest

from skygas.core.estimates import (
    OPERATION_TURN_SECONDS,
    REFERENCE_STEP_SECONDS,
    EstimateOnly,
    estimate_only,
    run_limits,
    step_seconds,
)
from skygas.neuron.config import load_neuron_config
from skygas.neuron.files import RHEOBASE_MULTIPLES, NeuronJob

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "neuron.toml"


def _estimate(config, transfer: bool):
    with run_limits(), estimate_only(), pytest.raises(EstimateOnly) as stopped:
        NeuronJob(config, transfer=transfer)
    return stopped.value.estimate


def test_the_estimate_prices_the_transfer_curve_and_the_operations_turns(monkeypatch):
    monkeypatch.setenv("SKYGAS_STEP_SECONDS", repr(REFERENCE_STEP_SECONDS))
    config = load_neuron_config(EXAMPLE, duration=1e-6)
    alone = _estimate(config, transfer=False)
    whole = _estimate(config, transfer=True)
    steps = 1e-6 / config.time_step
    assert alone.steps == pytest.approx(steps)
    # six transfer points, each as long as the main run (transfer.duration unset)
    assert whole.steps == pytest.approx((1 + len(RHEOBASE_MULTIPLES)) * steps)
    assert whole.seconds == pytest.approx((1 + len(RHEOBASE_MULTIPLES)) * alone.seconds)
    # the annihilator turns every check interval, the controller every sensor interval: the
    # turns, not the steps, make most of the price
    stepping = steps * step_seconds(max(1.0, config.rule.threshold))
    assert alone.seconds > stepping + 0.5 * steps * OPERATION_TURN_SECONDS
