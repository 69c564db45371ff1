"""What a study's worker runs: one device configuration in, its summary quantities out.

Kept apart from the rest of :mod:`skygas.optimize` so that a Dask worker imports only the
device it runs (not optuna, pandas or matplotlib), as a sweep's worker does.
"""

from __future__ import annotations

import math


def _number(value) -> float:
    return math.nan if value is None else float(value)


def run_reshuffler(config_json: str) -> dict[str, float]:
    """A sweep's run (:func:`skygas.sweep.worker.run_one`), its numbers and the read-out rate."""
    from skygas.sweep.worker import QUANTITIES, run_one

    result = run_one(config_json)
    out = {name: float(result[name]) for name in QUANTITIES}
    time = out["simulated_time_s"]
    out["throughput_Hz"] = out["n_detected"] / time if time > 0 else math.nan
    return out


def run_neuron(config_json: str) -> dict[str, float]:
    """One neuron run (:func:`skygas.neuron.device.run_neuron`) and its summary numbers."""
    from skygas.core.estimates import run_limits
    from skygas.neuron.config import NeuronConfig
    from skygas.neuron.device import run_neuron as run
    from skygas.optimize.devices import NEURON_QUANTITIES

    config = NeuronConfig.model_validate_json(config_json)
    with run_limits(force=True):  # the study checked its runs before submitting them
        summary = run(config).summary()
    for key in ("mean_s", "std_s", "cv"):
        summary[f"isi_{key}"] = summary["isi"][key]
    return {name: _number(summary[name]) for name in NEURON_QUANTITIES}


def run_reservoir(config_json: str) -> dict[str, float]:
    """One reservoir study, Boolean tasks only (:func:`skygas.reservoir.study.run_study`)."""
    from skygas.core.estimates import run_limits
    from skygas.reservoir.config import ReservoirConfig
    from skygas.reservoir.study import run_study

    config = ReservoirConfig.model_validate_json(config_json)
    with run_limits(force=True):
        summary, _ = run_study(config, temporal_tasks=False)
    return {
        "xor_accuracy": float(summary["xor"]["accuracy"]),
        "mean_accuracy": float(summary["mean_accuracy"]),
        "energy_per_operation_J": _number(summary["energy_per_operation_J"]),
        "wall_time_s": float(summary["wall_seconds"]),
    }


def run_analytic(config_json: str) -> dict[str, float]:
    """The analytic test function (:mod:`skygas.optimize.analytic`)."""
    from skygas.optimize.analytic import AnalyticConfig, evaluate

    return evaluate(AnalyticConfig.model_validate_json(config_json))


_RUNNERS = {
    "reshuffler": run_reshuffler,
    "neuron": run_neuron,
    "reservoir": run_reservoir,
    "analytic": run_analytic,
}


def run_trial(device: str, config_json: str) -> dict[str, float]:
    """Run one configuration of ``device`` and return its summary quantities (floats)."""
    return _RUNNERS[device](config_json)
