"""``skygas simulate CONFIG.toml --out DIR``: a simulation described by a TOML file.

The handlers import the simulation when they run: building the command line (every ``skygas``
call, ``--help`` included) then imports no numerics.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from skygas.commands.json_output import add_json_option, print_json
from skygas.commands.run_options import (
    add_run_options,
    limits_from_flags,
    named_by_flags,
    run_options,
)
from skygas.outputs.flags import add_output_flags


def _simulate(args) -> int:
    from skygas.runs.config import load_config
    from skygas.runs.runner import run_simulation

    with named_by_flags(args, {"seed": "seed", "duration": "duration"}):
        config = load_config(args.config, seed=args.seed, duration=args.duration)
    with limits_from_flags(args, announce=not args.json):
        summary = run_simulation(
            config, args.out, **run_options(args, progress=not args.json), then=_outputs(args)
        )
    _report(summary, args.out, args.json)
    return 0


def default_demo_config():
    """The closed-chamber configuration shipped with the package (45 skyrmions, 200 ns).

    The same as ``examples/closed-chamber.toml``; the engine's speed on a machine is measured on
    it (:mod:`skygas.runs.machine_speed`).
    """
    import tomllib

    from skygas.runs.config import parse_config

    text = resources.files("skygas").joinpath("data/demo-closed-chamber.toml").read_text()
    return parse_config(tomllib.loads(text), source="demo config: ")


def _outputs(args):
    """The movie and report a run writes once its results are there.

    They are part of its final write: a kill during them is completed by ``--resume``.
    """
    from skygas.outputs.finish import finish_outputs

    return lambda out: finish_outputs(out, animate=args.animate, report=not args.no_report)


def _report(summary: dict, out, as_json: bool) -> None:
    """The run's summary: a few lines for a person, or one JSON object with ``--json``."""
    if as_json:
        print_json({k: v for k, v in summary.items() if k != "config"})
        return
    s = summary
    lines = [
        f"skygas simulate: {s['skyrmions_initial']} skyrmion(s), T = "
        f"{s['config']['temperature']:g} K, seed {s['seed']}",
        f"  simulated {s['simulated_time_s'] * 1e9:.4g} ns in {s['wall_time_s']:.1f} s "
        f"({s['steps']} steps of {s['time_step_s'] * 1e12:.3g} ps)",
        f"  {s['skyrmions_present']} present at the end, {s['exits']} left through a port, "
        f"{s['wall_escapes']} wall escape(s)",
    ]
    for name, numbers in s.get("operations", {}).items():
        shown = ", ".join(
            f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}" for k, v in numbers.items()
        )
        lines.append(f"  operation {name}: {shown}")
    lines.append(f"results in {Path(out).resolve()}")
    print("\n".join(lines))


def register_kind(subparsers, kind) -> None:
    """Add ``skygas simulate`` (the registry's ``kind``) to ``subparsers``."""
    p = subparsers.add_parser(kind.name, help=kind.help)
    p.add_argument("config", help="TOML configuration (see examples/)")
    p.add_argument("--out", required=True, help="output directory")
    add_json_option(p)
    p.add_argument("--seed", type=int, help="random seed (default: the configuration's)")
    p.add_argument(
        "--duration", type=float, help="simulated time [s] (default: the configuration's)"
    )
    add_run_options(p)
    add_output_flags(p)
    p.set_defaults(func=_simulate)
