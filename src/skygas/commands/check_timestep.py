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
from skygas.devices.registry import KINDS, TimeStepCheck, kind
from skygas.devices.timestep import PLACEMENT_SEPARATION, with_step
from skygas.reshuffler.presets import PRESETS


def _check(device: str) -> TimeStepCheck:
    """How ``device`` is checked; :class:`InputError` for a name not in :data:`DEVICES`."""
    check = kind(device).timestep
    if check is None:
        raise InputError("--device", device, f"one of {', '.join(DEVICES)}")
    return check


#: the devices whose configurations check-timestep reads (the command that runs each), in the
#: registry's order (:mod:`skygas.devices.registry`)
DEVICES = tuple(name for name, k in KINDS.items() if k.timestep is not None)

#: TOML tables or keys that only one device's configuration has
MARKERS = {name: set(_check(name).markers) for name in DEVICES}
#: the tables of a sweep file (``skygas sweep``), whose ``[sweep]`` is not the reservoir's
SWEEP_FILE = {"base", "grid"}

__all__ = [
    "DEVICES",
    "MARKERS",
    "PLACEMENT_SEPARATION",
    "SWEEP_FILE",
    "check_device_time_step",
    "detect_device",
    "load_device_config",
    "probe",
    "register",
]


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
    if preset is not None and not _check(device).presets:
        raise InputError(
            "--preset", preset, "a preset of the reshuffler only", "leave --preset out"
        )
    return device, _check(device).load(path, preset)


def probe(device: str, config) -> tuple[Callable[[float | None, int], Any], int | None]:
    """The builder :func:`~skygas.runs.timestep.check_time_step` runs, and the skyrmions it places.

    Returns
    -------
    tuple
        ``(build, count)``: ``build(time_step, brownian_substeps)`` returns the device's
        simulation, filled; ``count`` is None for a simulation, which places its own.
    """
    return _check(device).probe(config)


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
    findings = findings_before_run(with_step(config, report.time_step), build(report.time_step, 1))
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
