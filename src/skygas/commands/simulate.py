"""``skygas simulate CONFIG.toml --out DIR`` and ``skygas demo --out DIR``.

The handlers import the simulation when they run: building the command line (every ``skygas``
call, ``--help`` included) then imports no numerics.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from skygas.commands.json_output import print_json
from skygas.commands.run_options import add_run_options, limits_from_flags, run_options
from skygas.outputs.flags import add_output_flags


def _simulate(args) -> int:
    from skygas.runs.config import load_config
    from skygas.runs.runner import run_simulation

    config = load_config(args.config)
    with limits_from_flags(args):
        summary = run_simulation(config, args.out, **run_options(args), then=_outputs(args))
    _report(summary, args.out)
    return 0


def _check_timestep(args) -> int:
    from skygas.runs.config import load_config
    from skygas.runs.timestep import check_config_time_step

    report = check_config_time_step(
        load_config(args.config),
        duration=args.duration,
        time_step=args.time_step,
        tolerance_diameters=args.tolerance,
    )
    if args.json:
        print_json(report.as_dict())
    else:
        print(report.summary())
    return 0 if report.passed else 1


def default_demo_config():
    """The closed-chamber demonstration configuration shipped with the package."""
    import tomllib

    from skygas.runs.config import parse_config

    text = resources.files("skygas").joinpath("data/demo-closed-chamber.toml").read_text()
    return parse_config(tomllib.loads(text), source="demo config: ")


def _demo(args) -> int:
    from skygas.runs.runner import run_simulation

    with limits_from_flags(args):
        summary = run_simulation(
            default_demo_config(), args.out, **run_options(args), then=_outputs(args)
        )
    _report(summary, args.out)
    return 0


def _outputs(args):
    """The movie and report a run writes once its results are there.

    They are part of its final write: a kill during them is completed by ``--resume``.
    """
    from skygas.outputs.finish import finish_outputs

    return lambda out: finish_outputs(out, animate=args.animate, report=not args.no_report)


def _report(summary: dict, out) -> None:
    brief = {k: v for k, v in summary.items() if k != "config"}
    print_json(brief)
    print(f"results in {Path(out).resolve()}")


def register(subparsers) -> None:
    """Add ``skygas simulate``, ``skygas check-timestep`` and ``skygas demo`` to ``subparsers``."""
    p = subparsers.add_parser("simulate", help="run a simulation described by a TOML file")
    p.add_argument("config", help="TOML configuration (see examples/)")
    p.add_argument("--out", required=True, help="output directory")
    add_run_options(p)
    add_output_flags(p)
    p.set_defaults(func=_simulate)

    c = subparsers.add_parser(
        "check-timestep", help="compare a configuration's time step with its half"
    )
    c.add_argument("config", help="TOML configuration")
    c.add_argument("--time-step", type=float, default=None, help="step to check [s]")
    c.add_argument("--duration", type=float, default=2e-9, help="compared duration [s]")
    c.add_argument(
        "--tolerance",
        type=float,
        default=0.01,
        help="largest accepted difference [skyrmion diameters]",
    )
    c.add_argument("--json", action="store_true", help="print the report as JSON")
    c.set_defaults(func=_check_timestep)

    d = subparsers.add_parser("demo", help="run the default demonstration")
    d.add_argument("--out", default="demo-output", help="output directory")
    add_run_options(d)
    add_output_flags(d)
    d.set_defaults(func=_demo)
