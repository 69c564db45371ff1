"""A plain simulation (``skygas simulate``) in a study: its points, their price, a run, its numbers.

The hooks :class:`~skygas.devices.study_hooks.StudyPoints` reads. A run returns its counts
and times (:data:`QUANTITIES`) and, for each ``census`` operation of its configuration, the
mean, least and largest count (``<name>_mean_count``, …: :func:`extra_quantities`); a
``python`` operation's numbers are its own and are not stored.
"""

from __future__ import annotations

import math
from typing import Any

#: The plain simulation's name in study files.
NAME = "simulate"
#: A study file without ``[base]``: the simulation's defaults.
DEFAULT_BASE: dict = {}
#: Fields a study typically varies (for messages).
EXAMPLE_FIELDS = "temperature, duration, material"
#: The quantities a sweep's figure draws first.
PLOTTED = ("skyrmions_present", "exits", "wall_escapes")
#: Summary numbers of each run: skyrmions at the start and the end, those that left through a
#: port or escaped a wall, the steps, the simulated and wall times [s] and the step [s].
QUANTITIES = (
    "skyrmions_initial",
    "skyrmions_present",
    "exits",
    "wall_escapes",
    "steps",
    "simulated_time_s",
    "time_step_s",
    "wall_time_s",
)
#: A census operation's numbers, each stored as ``<name>_<number>``.
CENSUS_NUMBERS = ("mean_count", "min_count", "max_count")


def model() -> type:
    """:class:`~skygas.runs.config.SimulationConfig`."""
    from skygas.runs.config import SimulationConfig

    return SimulationConfig


def point(base: dict, overrides: dict[str, Any], what: str = "sweep point") -> Any:
    """The validated configuration of one point: ``base`` with the dotted ``overrides`` set."""
    from skygas.core.config_types import apply_overrides
    from skygas.runs.config import parse_config

    label = ", ".join(f"{f} = {v!r}" for f, v in overrides.items())
    return parse_config(apply_overrides(base, overrides), source=f"{what} ({label}): ")


def _census_names(config) -> list[str]:
    return [op.name for op in config.operations if getattr(op, "kind", None) == "census"]


def extra_quantities(config) -> tuple[str, ...]:
    """``<name>_mean_count``, ``<name>_min_count``, ``<name>_max_count`` of each census."""
    return tuple(f"{name}_{n}" for name in _census_names(config) for n in CENSUS_NUMBERS)


def estimate(config) -> Any:
    """As :class:`~skygas.runs.runner.SimulationRun` prices a run before building it.

    Its steps at least its recorded frames (the default step divides the record interval).
    """
    from skygas.core.resources import step_count
    from skygas.runs.machine_speed import optimistic_estimate
    from skygas.runs.runner import simulation_memory

    lower = step_count(config.duration, config.time_step or config.record_interval)
    skyrmions = len(config.skyrmions.positions) + config.skyrmions.random_count
    return optimistic_estimate(lower, skyrmions, simulation_memory(config, skyrmions))


def run(config_json: str) -> dict[str, float]:
    """Run one simulation (:class:`~skygas.runs.runner.SimulationRun`) and return its numbers."""
    from skygas.core.estimates import run_limits
    from skygas.runs.config import SimulationConfig
    from skygas.runs.runner import SimulationJob

    config = SimulationConfig.model_validate_json(config_json)
    with run_limits(force=True):  # the study checked its runs before submitting them
        job = SimulationJob(config)
    job.run.advance()
    summary = job.summary()
    out = {name: float(summary[name]) for name in QUANTITIES}
    operations = summary.get("operations", {})
    for name in _census_names(config):
        numbers = operations.get(name, {})
        for n in CENSUS_NUMBERS:
            value = numbers.get(n)
            out[f"{name}_{n}"] = math.nan if value is None else float(value)
    return out
