"""The reservoir in a study (a sweep or a search): its points, their price, a run and its numbers.

The hooks :class:`~skygas.devices.study_hooks.StudyPoints` reads. A run is the reservoir's
Boolean study (no temporal tasks) as one stream in the run's own process (``study.workers = 1``:
a study's workers are its runs).
"""

from __future__ import annotations

import math
from typing import Any

#: The reservoir's name in study files.
NAME = "reservoir"
#: A study file without ``[base]``: the reservoir's defaults.
DEFAULT_BASE: dict = {}
#: Fields a study typically varies (for messages).
EXAMPLE_FIELDS = "temperature, chamber.size, hold_time"
#: The quantities a sweep's figure draws first.
PLOTTED = ("xor_accuracy", "mean_accuracy", "energy_per_operation_J")
#: Summary numbers of each run: the XOR read-out's and the mean of the 16 Boolean functions'
#: test accuracies, and the drive's energy per held input [J].
QUANTITIES = ("xor_accuracy", "mean_accuracy", "energy_per_operation_J", "wall_time_s")
#: The reservoir derives its streams' seeds as 1000·seed + k: seeds stay below this.
SEED_LIMIT = (2**63 - 1) // 1000 - 1000


def model() -> type:
    """:class:`~skygas.reservoir.config.ReservoirConfig`."""
    from skygas.reservoir.config import ReservoirConfig

    return ReservoirConfig


def point(base: dict, overrides: dict[str, Any], what: str = "sweep point") -> Any:
    """The validated configuration of one point: ``base`` with the dotted ``overrides`` set."""
    from skygas.core.errors import InputError
    from skygas.reservoir.config import reservoir_config

    try:
        return reservoir_config(dict(base), **{**overrides, "study.workers": 1})
    except InputError as err:
        label = ", ".join(f"{f} = {v!r}" for f, v in overrides.items())
        raise InputError(f"{what} ({label}): {err.field}", err.value, err.allowed) from None


def estimate(config) -> Any:
    """As the reservoir prices its study's Boolean streams (one step per held input at least)."""
    from skygas.runs.machine_speed import optimistic_estimate, run_estimate

    st = config.study
    inputs = st.n_inputs + st.warmup_inputs
    frames = config.hold_time / config.sensors.sample_interval
    skyrmions = max(1, config.n_skyrmions)
    memory = 8.0 * len(config.drive.input_contacts) * inputs + 24.0 * (frames + 1) * skyrmions
    if config.time_step is None:  # the engine's step is known once the device is built
        return optimistic_estimate(inputs, skyrmions, memory)
    return run_estimate(inputs * config.hold_time / config.time_step, skyrmions, memory)


def run(config_json: str) -> dict[str, float]:
    """One reservoir study, Boolean tasks only (:func:`skygas.reservoir.study.run_study`)."""
    from skygas.core.estimates import run_limits
    from skygas.reservoir.config import ReservoirConfig
    from skygas.reservoir.study import run_study

    config = ReservoirConfig.model_validate_json(config_json)
    with run_limits(force=True):
        summary, _ = run_study(config, temporal_tasks=False)
    energy = summary["energy_per_operation_J"]
    return {
        "xor_accuracy": float(summary["xor"]["accuracy"]),
        "mean_accuracy": float(summary["mean_accuracy"]),
        "energy_per_operation_J": math.nan if energy is None else float(energy),
        "wall_time_s": float(summary["wall_seconds"]),
    }
