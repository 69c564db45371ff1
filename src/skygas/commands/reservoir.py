"""``skygas reservoir [CONFIG.toml] --out DIR [--json]``: the Brownian reservoir.

All 16 Boolean functions of two inputs and the temporal tasks from one confined chamber, with
occupation maps and a report (docs/reservoir.md). Accuracy against a parameter, with replicas,
is a ``skygas sweep`` of ``device = "reservoir"``. It runs through the run driver
(:func:`skygas.reservoir.files.run_reservoir`): progress bar, checkpoints, ``--resume`` and
``--overwrite`` as for every long command.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from skygas.commands.json_output import add_json_option, print_json
from skygas.commands.run_options import (
    add_run_options,
    add_scheduler_option,
    limits_from_flags,
    named_by_flags,
    run_options,
)

#: command-line option -> the configuration's field it overrides (a dotted key)
OVERRIDES = {
    "seed": "seed",
    "hold_time": "hold_time",
    "temperature": "temperature",
    "n_skyrmions": "n_skyrmions",
    "current_density": "drive.current_density",
    "n_inputs": "study.n_inputs",
    "workers": "study.workers",
}


def _format(s: dict, out: Path) -> str:
    """The summary as a few lines for the terminal."""
    xor = s["xor"]
    t = s["temporal"]
    lines = [
        f"Brownian reservoir: {s['n_skyrmions']} skyrmion(s), T = {s['temperature_K']:g} K, "
        f"hold {s['hold_time_s'] * 1e6:.3g} µs, {s['n_inputs']} inputs "
        f"({s['wall_seconds']:.1f} s, {s['cpu_seconds']:.1f} s CPU in {s['streams']} streams)",
        f"  XOR: {100 * xor['accuracy']:.1f} % on {xor['n_test']} test inputs "
        f"(chance {100 * xor['chance']:.0f} %, {xor['margin_standard_errors']:.1f} standard "
        f"errors above)",
        "  " + ", ".join(f"{n} {100 * a:.0f} %" for n, a in s["accuracy"].items()),
        f"  mean of the 16 functions {100 * s['mean_accuracy']:.1f} %; energy per operation "
        f"{s['energy_per_operation_J']:.3g} J",
    ]
    if t:
        lines.append(
            "  recall of input a, k back: "
            + ", ".join(f"k={k} {100 * r['accuracy']:.0f} %" for k, r in t["recall"].items())
            + f"; parity of the last two {100 * t['parity_last_two']['accuracy']:.0f} %"
        )
    lines.append(f"results in {out.resolve()}")
    return "\n".join(lines)


def _reservoir(args) -> int:
    # imported here: building the command line (every skygas call) imports no numerics
    from skygas.core.errors import InputError
    from skygas.reservoir.config import SWEEP_INSTEAD, load_reservoir_config
    from skygas.reservoir.files import run_reservoir

    if args.sweep:  # the option of earlier versions: say where it went
        raise InputError(
            "--sweep", True, "no --sweep (the reservoir's own sweep is gone)", SWEEP_INSTEAD
        )
    overrides = {field: getattr(args, option) for option, field in OVERRIDES.items()}
    # a bad value names the option that set it
    with named_by_flags(args, OVERRIDES), limits_from_flags(args, announce=not args.json):
        config = load_reservoir_config(args.config, **overrides)
        summary = run_reservoir(
            config,
            args.out,
            scheduler=args.scheduler,
            **run_options(args, progress=not args.json),
            then=None if args.no_report else _write_report,
        )
    out = Path(args.out)
    if args.json:
        print_json(summary)
    else:
        print(_format(summary, out))
    return 0


def _write_report(out: Path) -> None:
    """``report.html``, part of the run's final write (a kill during it: ``--resume``)."""
    from skygas.outputs.report import write_report

    write_report(out, out / "report.html")


def register_kind(subparsers, kind) -> None:
    """Add ``skygas reservoir`` (the registry's ``kind``) to the command line's sub-commands."""
    p = subparsers.add_parser(kind.name, help=kind.help)
    p.add_argument("config", nargs="?", default=None, help="TOML configuration")
    p.add_argument("--out", required=True, help="output directory")
    add_json_option(p)
    add_run_options(p)
    p.add_argument(
        "--no-report",
        action="store_true",
        help="do not write report.html (a self-contained page of the results)",
    )
    p.add_argument("--sweep", action="store_true", help=argparse.SUPPRESS)
    p.add_argument("--seed", type=int, help="random seed")
    p.add_argument("--hold-time", type=float, help="time each input is held [s]")
    p.add_argument("--temperature", type=float, help="temperature [K]")
    p.add_argument("--n-skyrmions", type=int, help="number of skyrmions")
    p.add_argument(
        "--current-density", type=float, help="chamber-mean |j| of the unit input pattern [A/m²]"
    )
    p.add_argument("--n-inputs", type=int, help="held inputs in the study")
    p.add_argument(
        "--workers",
        type=int,
        help="parallel streams (study.workers), each on a worker of the local Dask cluster "
        "or of --scheduler's",
    )
    add_scheduler_option(p)
    p.set_defaults(func=_reservoir)
