"""``skygas check-timestep [CONFIG.toml] [--device DEVICE]``: is a time step small enough.

Every device's configuration is read as its own command reads it: a ``skygas simulate`` TOML,
a reshuffler configuration or preset (``skygas reshuffle``), a neuron's (``skygas neuron``) or
a reservoir's (``skygas reservoir``). The device is named with ``--device`` or recognised from
the tables only its configuration has (:data:`MARKERS`).

The check is :func:`skygas.runs.timestep.check_time_step`: the device's engine (its outline,
material, landscape and drift field, built as its run builds it, without the device's
operations) runs twice over a short ``duration``, at dt and at dt/2 on the same Brownian path,
from the same skyrmions, and the trajectories' difference is compared with a tolerance in
skyrmion diameters. A simulation places its own skyrmions; a device is filled as it is in use:
the reshuffler's chambers half full (the demonstration's crowd, or more when the current is
too weak to carry the injected skyrmions through), the neuron's chamber with its threshold's
crowd, the reservoir's with its skyrmions. The checks ``--strict`` decides before a run
(:func:`skygas.runs.sanity.findings_before_run`: drift and forces per step, temperature,
current) are reported with it.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from typing import Any

from skygas.commands.json_output import add_json_option, print_json
from skygas.core.errors import InputError, require
from skygas.reshuffler.presets import PRESETS

#: the devices whose configurations check-timestep reads (the command that runs each)
DEVICES = ("simulate", "reshuffle", "neuron", "reservoir")

#: TOML tables or keys that only one device's configuration has
MARKERS = {
    "simulate": {"geometry", "skyrmions", "record_interval", "drift", "integrator"},
    "reshuffle": {"preset", "signal", "output", "current", "hypothesis", "spin_polarization"},
    "neuron": {
        "gate",
        "sensor",
        "rule",
        "annihilation",
        "inputs",
        "transfer",
        "release_current_density",
    },
    "reservoir": {
        "chamber",
        "drive",
        "sensors",
        "readout",
        "study",
        "sweep",
        "n_skyrmions",
        "hold_time",
    },
}
#: the tables of a sweep file (``skygas sweep``), whose ``[sweep]`` is not the reservoir's
SWEEP_FILE = {"base", "grid"}

#: least distance of the skyrmions placed in a device, from each other and from the walls
#: [skyrmion diameters] (the reservoir's own placement)
PLACEMENT_SEPARATION = 1.2


def detect_device(data: dict, source: str) -> str:
    """The device whose configuration ``data`` (a TOML file's tables) is.

    Raises
    ------
    InputError
        If no device's tables, or several devices', are in ``data``.
    """
    keys = set(data)
    if keys & SWEEP_FILE:
        raise InputError(
            "config",
            source,
            "a device's configuration (this is a sweep file, with [base] and [grid])",
            "check the sweep's base configuration in a file of its own",
        )
    found = [device for device, marks in MARKERS.items() if keys & marks]
    if len(found) == 1:
        return found[0]
    what = (
        f"tables of only one device (it has those of {', '.join(found)})"
        if found
        else "tables that say which device it is, such as [skyrmions] (simulate), [signal] "
        "(reshuffle), [gate] (neuron) or [drive] (reservoir)"
    )
    raise InputError("config", source, what, f"name the device: --device {'|'.join(DEVICES)}")


def load_device_config(device: str | None, path: str | None, preset: str | None):
    """The validated configuration of ``device`` from ``path`` (its defaults without a path).

    Returns
    -------
    tuple
        ``(device, config)``: the device (detected from the file when ``device`` is None).
    """
    if device is None:
        if path is None:
            raise InputError(
                "config",
                None,
                "a TOML configuration, or --device for a device's defaults",
                "give a configuration file, or e.g. --device reshuffle",
            )
        from skygas.core.config_types import read_toml

        device = detect_device(read_toml(path), str(path))
    if preset is not None and device != "reshuffle":
        raise InputError(
            "--preset", preset, "a preset of the reshuffler only", "leave --preset out"
        )
    if device == "simulate":
        if path is None:
            raise InputError(
                "config",
                None,
                "a simulation's TOML file (a simulation has no defaults to check)",
                "give the file, e.g. examples/closed-chamber.toml",
            )
        from skygas.runs.config import load_config

        return device, load_config(path)
    if device == "reshuffle":
        from skygas.reshuffler.config import load_reshuffler_config

        return device, load_reshuffler_config(path, preset=preset)
    if device == "neuron":
        from skygas.neuron.config import load_neuron_config

        return device, load_neuron_config(path)
    from skygas.reservoir.config import load_reservoir_config

    return device, load_reservoir_config(path)


def _with_step(config, time_step: float | None):
    """``config`` with its time step replaced (``None``: the configuration's own)."""
    return config if time_step is None else config.model_copy(update={"time_step": time_step})


def _reshuffler_population(config) -> int:
    """Skyrmions in the reshuffler while in use.

    :func:`~skygas.reshuffler.run.expected_population`, capped at a third of the chambers'
    close packing, which random placement reaches.
    """
    from skygas.reshuffler.run import expected_population

    d_sk = config.thiele_parameters().skyrmion_diameter
    packing = 2 * (config.device.chamber_diameter / d_sk) ** 2
    return max(1, round(min(expected_population(config), packing / 3)))


def _neuron_population(config) -> int:
    """Skyrmions in the neuron's chamber at its threshold (the crowd before it fires)."""
    rule = config.rule
    if config.sensor.signal == "count":
        return max(1, math.ceil(rule.threshold))
    d_sk = config.thiele_parameters().skyrmion_diameter
    return max(1, math.ceil(rule.threshold * (config.device.chamber_diameter / d_sk) ** 2))


def _filled(sim, count: int, seed: int):
    """``sim`` without its device's operations, filled with ``count`` skyrmions at random."""
    sim.operations.clear()  # only the engine's forces are compared: no injection, no gate logic
    sim.add_random(count, min_separation=PLACEMENT_SEPARATION, seed=seed)
    return sim


def probe(device: str, config) -> tuple[Callable[[float | None, int], Any], int | None]:
    """The builder :func:`~skygas.runs.timestep.check_time_step` runs, and the skyrmions it places.

    Returns
    -------
    tuple
        ``(build, count)``: ``build(time_step, brownian_substeps)`` returns the device's
        simulation, filled; ``count`` is None for a simulation, which places its own.
    """
    if device == "simulate":

        def build_simulation(dt, substeps):
            return config.build(
                time_step=dt if dt is not None else config.time_step, brownian_substeps=substeps
            )

        return build_simulation, None
    if device == "reshuffle":
        from skygas.reshuffler.run import ReshufflerRun

        count = _reshuffler_population(config)

        def build_reshuffler(dt, substeps):
            run = ReshufflerRun.build(_with_step(config, dt), brownian_substeps=substeps)
            return _filled(run.sim, count, config.seed)

        return build_reshuffler, count
    if device == "neuron":
        from skygas.neuron.device import NeuronDevice

        count = _neuron_population(config)

        def build_neuron(dt, substeps):
            run = NeuronDevice(_with_step(config, dt)).build(brownian_substeps=substeps)
            return _filled(run.sim, count, config.seed)  # the gate closed, as a run starts

        return build_neuron, count
    from skygas.reservoir.device import ReservoirDevice

    count = config.n_skyrmions

    def build_reservoir(dt, substeps):
        device = ReservoirDevice(_with_step(config, dt))
        sim = device.simulation(config.seed, brownian_substeps=substeps)
        fields = device.drive.drift_fields(sim.wall_field.grid)
        # the input whose current drives fastest: the most demanding for the step
        vx, vy = max(fields.values(), key=lambda v: float((v[0] ** 2 + v[1] ** 2).max()))
        sim.set_drift_field(vx, vy)
        return _filled(sim, count, config.seed)

    return build_reservoir, count


def check_device_time_step(
    device: str,
    config,
    duration: float = 2e-9,
    time_step: float | None = None,
    tolerance_diameters: float = 0.01,
) -> dict:
    """The time-step check of a device's configuration, with the findings ``--strict`` refuses.

    Returns
    -------
    dict
        ``device``; ``skyrmions_placed`` (None for a simulation, which places its own); the
        :class:`~skygas.runs.timestep.TimeStepReport`'s fields; ``findings``, one line each
        (:func:`~skygas.runs.sanity.findings_before_run` on the checked step); ``passed``,
        whether the step passes the comparison and has no finding.
    """
    from skygas.runs.sanity import findings_before_run
    from skygas.runs.timestep import check_time_step

    build, count = probe(device, config)
    report = check_time_step(build, duration, time_step, tolerance_diameters)
    findings = findings_before_run(_with_step(config, report.time_step), build(report.time_step, 1))
    return {
        "device": device,
        "skyrmions_placed": count,
        **report.as_dict(),
        "findings": [str(f) for f in findings],
        "passed": report.passed and not findings,
        "summary": report.summary(),
    }


def _check_timestep(args) -> int:
    for flag, value in (("--duration", args.duration), ("--tolerance", args.tolerance)):
        require(math.isfinite(value) and value > 0, flag, value, "a finite number > 0")
    device, config = load_device_config(args.device, args.config, args.preset)
    result = check_device_time_step(
        device,
        config,
        duration=args.duration,
        time_step=args.time_step,
        tolerance_diameters=args.tolerance,
    )
    if args.json:
        print_json(result)
    else:
        where = args.config or (f"preset {args.preset}" if args.preset else "defaults")
        placed = (
            f", {result['skyrmions_placed']} skyrmion(s) placed"
            if result["skyrmions_placed"] is not None
            else ""
        )
        print(f"{device} configuration ({where}{placed}): {result['summary']}")
        for finding in result["findings"]:
            print(f"skygas: warning: {finding}", file=sys.stderr)
    return 0 if result["passed"] else 1


def register(subparsers) -> None:
    """Add ``skygas check-timestep`` to ``subparsers``."""
    c = subparsers.add_parser(
        "check-timestep",
        help="compare a configuration's time step with its half (any device's configuration)",
        description="Run the configuration's device twice over a short duration, at its time\n"
        "step and at half of it on the same Brownian path, and compare the trajectories.\n"
        "Exit status 0: the step passes; 1: it does not (or --strict would refuse it).",
    )
    c.add_argument(
        "config",
        nargs="?",
        default=None,
        help="TOML configuration of simulate, reshuffle, neuron or reservoir (default: the "
        "defaults of --device)",
    )
    c.add_argument(
        "--device",
        choices=DEVICES,
        default=None,
        help="the command whose configuration CONFIG is (default: recognised from its tables)",
    )
    c.add_argument(
        "--preset",
        choices=PRESETS,
        default=None,
        help="the reshuffler's preset (the config file's values override it)",
    )
    c.add_argument(
        "--time-step",
        type=float,
        default=None,
        help="step to check [s] (default: the configuration's)",
    )
    c.add_argument(
        "--duration", type=float, default=2e-9, help="simulated time of the comparison [s]"
    )
    c.add_argument(
        "--tolerance",
        type=float,
        default=0.01,
        help="largest accepted difference [skyrmion diameters]",
    )
    add_json_option(c, "the report")
    c.set_defaults(func=_check_timestep)
