"""The reshuffler in a study (a sweep or a search): its points, their price, a run and its numbers.

The hooks :class:`~skygas.devices.study_hooks.StudyPoints` reads. A run returns
:data:`QUANTITIES` and the running correlation ρ with its times (:data:`RUNNING`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

#: The reshuffler's name in study files.
NAME = "reshuffler"
#: A study file without ``[base]``: the default preset.
DEFAULT_BASE = {"preset": "default"}
#: Fields a study typically varies (for messages).
EXAMPLE_FIELDS = (
    "current_density, signal.p, device.chamber_diameter, temperature, material, duration"
)
#: The quantities a sweep's figure draws first.
PLOTTED = (
    "correlation",
    "p_out",
    "max_occupancy",
    "mean_transit_s",
    "throughput_Hz",
    "energy_per_bit_J",
)

#: Summary numbers of each run (float64; NaN until the run is done), in this order: the
#: correlation and the read-out, counts, times, the drive's power, and ``throughput_Hz``,
#: the read-outs per second (``n_detected / simulated_time_s``).
QUANTITIES = (
    "correlation",
    "correlation_max_lag",
    "scc",
    "p_in",
    "p_out",
    "n_injected",
    "n_detected",
    "n_skipped",
    "n_present",
    "max_occupancy",
    "mean_transit_s",
    "power_W",
    "energy_per_bit_J",
    "simulated_time_s",
    "time_step_s",
    "wall_time_s",
    "correlation_best_lag",
    "median_transit_s",
    "p_out_low",
    "p_out_high",
    "wall_escapes",
    "throughput_Hz",
)
#: Curves of each run: the running correlation ρ and its times [s].
RUNNING = ("running_rho", "running_time")


def model() -> type:
    """:class:`~skygas.reshuffler.config.ReshufflerConfig`."""
    from skygas.reshuffler.config import ReshufflerConfig

    return ReshufflerConfig


def point(base: dict, overrides: dict[str, Any], what: str = "sweep point") -> Any:
    """The validated configuration of one point: ``base`` with the dotted ``overrides`` set.

    With the checks :meth:`~skygas.reshuffler.run.ReshufflerRun.build` makes first (the
    geometry against the skyrmion's size, the time step against the injection interval),
    without solving anything; an error names the point (``what (current_density = 1e11, …):
    field = value: …``).
    """
    from skygas.core.errors import InputError
    from skygas.reshuffler.config import check_time_step, parse_reshuffler_config
    from skygas.reshuffler.device import ReshufflerGeometry

    label = ", ".join(f"{f} = {v!r}" for f, v in overrides.items())
    config = parse_reshuffler_config(dict(base), f"{what} ({label}): ", overrides)
    try:
        check_time_step(config)
        thiele = config.thiele_parameters()
        d = config.device
        ReshufflerGeometry(
            d.chamber_diameter, d.conduit_width, d.conduit_length, d.chamber_gap
        ).validate(thiele.skyrmion_diameter)
    except InputError as err:
        raise InputError(f"{what} ({label}): {err.field}", err.value, err.allowed) from None
    return config


def estimate(config) -> Any:
    """As :meth:`~skygas.reshuffler.run.ReshufflerRun.build` prices a run before building it.

    Its steps at least its injection events.
    """
    from skygas.reshuffler.run import STEP_COST_FACTOR, expected_population, reshuffler_memory
    from skygas.runs.machine_speed import run_estimate

    events = config.duration / config.injection.interval
    population = expected_population(config)
    memory = sum(reshuffler_memory(config, events, population).values())
    return run_estimate(events, STEP_COST_FACTOR * population, memory)


def curves(config) -> dict[str, int]:
    """The running correlation's points (``output.running_points``), for ρ and its times."""
    return dict.fromkeys(RUNNING, config.output.running_points)


def relative_cost(config) -> float:
    """A rough relative cost of one run, used only to start the longest runs first.

    So that no worker is left finishing one long run alone at the end of a sweep (results do not
    depend on the order). Cost ∝ steps × (1 + skyrmions in the device): a skyrmion crosses a
    chamber and its conduits at about the spin-drift speed ξJ, and one enters per injection
    interval.
    """
    device = config.device
    speed = config.drift_coefficient() * config.current_density  # v_s [m/s]
    present = (
        (device.chamber_diameter + 2 * device.conduit_length) / speed / config.injection.interval
    )
    steps = config.duration / (config.time_step or 1e-10)
    return steps * (1.0 + present)


def run(config_json: str) -> dict:
    """Run one reshuffler configuration (its JSON) and return its quantities and curves.

    :data:`QUANTITIES` as floats and :data:`RUNNING` as float64 arrays (empty with fewer than 3
    aligned events).
    """
    from skygas.core.estimates import run_limits
    from skygas.reshuffler.analysis import summarize
    from skygas.reshuffler.config import ReshufflerConfig
    from skygas.reshuffler.run import ReshufflerRun

    config = ReshufflerConfig.model_validate_json(config_json)
    # the study checked every run's estimate before submitting it
    with run_limits(force=True):
        device_run = ReshufflerRun.build(config)
    device_run.advance()
    result = summarize(device_run, dataset=False)
    summary = dict(result.summary)
    # the 95 % interval of p_out (Clopper-Pearson), NaN without read-outs
    summary["p_out_low"], summary["p_out_high"] = summary["p_out_interval"] or (np.nan, np.nan)
    elapsed = float(summary["simulated_time_s"])
    summary["throughput_Hz"] = summary["n_detected"] / elapsed if elapsed > 0 else math.nan
    out: dict[str, float | np.ndarray] = {name: float(summary[name]) for name in QUANTITIES}
    running = result.running
    out["running_rho"] = np.asarray(running.rho if running else [], dtype=np.float64)
    out["running_time"] = np.asarray(running.times if running else [], dtype=np.float64)
    return out
