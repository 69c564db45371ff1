"""The neuron in a study (a sweep or a search): its points, their price, a run and its numbers.

The hooks :class:`skygas.devices.study_hooks.StudyPoints` reads (see there).
"""

from __future__ import annotations

import math
from typing import Any

#: The neuron's name in study files.
NAME = "neuron"
#: A study file without ``[base]``: the neuron's defaults.
DEFAULT_BASE: dict = {}
#: Fields a study typically varies (for messages).
EXAMPLE_FIELDS = "gate.barrier_height, annihilation.base_rate, temperature, duration"
#: The quantities a sweep's figure draws first.
PLOTTED = ("firing_rate_Hz", "isi_cv", "max_count", "n_annihilated", "n_emitted", "leak_time_s")
#: Summary numbers of each run (``isi_*``: inter-spike intervals; NaN with fewer than 2).
QUANTITIES = (
    "firing_rate_Hz",
    "n_output_spikes",
    "input_rate_Hz",
    "injection_rate_Hz",
    "leak_time_s",
    "max_count",
    "final_count",
    "n_injected",
    "n_annihilated",
    "n_emitted",
    "isi_mean_s",
    "isi_std_s",
    "isi_cv",
    "simulated_time_s",
    "wall_time_s",
)
#: The step [s] a run is priced at when its configuration leaves the step to the engine
#: (``time_step = None``; the configuration's default).
PRICED_TIME_STEP = 2.5e-10


def model() -> type:
    """:class:`~skygas.neuron.config.NeuronConfig`."""
    from skygas.neuron.config import NeuronConfig

    return NeuronConfig


def point(base: dict, overrides: dict[str, Any], what: str = "sweep point") -> Any:
    """The validated configuration of one point: ``base`` with the dotted ``overrides`` set."""
    from skygas.core.errors import InputError
    from skygas.neuron.config import neuron_config

    try:
        return neuron_config(dict(base), **overrides)
    except InputError as err:
        label = ", ".join(f"{f} = {v!r}" for f, v in overrides.items())
        raise InputError(f"{what} ({label}): {err.field}", err.value, err.allowed) from None


def estimate(config) -> Any:
    """As the neuron prices its run.

    Its steps with at most ``rule.threshold`` skyrmions, the turns of its controller (every
    sensor read) and annihilator (every check), and its build; a study records no frames.
    """
    from skygas.runs.machine_speed import run_estimate

    skyrmions = max(1.0, float(config.rule.threshold))
    dt = config.time_step or PRICED_TIME_STEP
    steps = config.duration / dt
    annihilation = config.annihilation_model()
    turns = steps / max(1.0, round(config.sensor.read_interval / dt))
    if annihilation.enabled:
        turns += steps / max(1.0, round(annihilation.check_interval / dt))
    return run_estimate(steps, skyrmions, 24.0 * skyrmions, turns=turns, builds=1)


def _number(value) -> float:
    return math.nan if value is None else float(value)


def run(config_json: str) -> dict[str, float]:
    """One neuron run (:func:`skygas.neuron.device.run_neuron`) and its summary numbers."""
    from skygas.core.estimates import run_limits
    from skygas.neuron.config import NeuronConfig
    from skygas.neuron.device import run_neuron

    config = NeuronConfig.model_validate_json(config_json)
    with run_limits(force=True):  # the study checked its runs before submitting them
        summary = run_neuron(config).summary()
    for key in ("mean_s", "std_s", "cv"):
        summary[f"isi_{key}"] = summary["isi"][key]
    return {name: _number(summary[name]) for name in QUANTITIES}
