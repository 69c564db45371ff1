"""``skygas simulate CONFIG.toml --out DIR`` and ``skygas demo --out DIR``."""

from __future__ import annotations

import json
from importlib import resources
from pathlib import Path

from skygas.config import load_config, parse_config
from skygas.runner import run_simulation


def _simulate(args) -> int:
    config = load_config(args.config)
    summary = run_simulation(config, args.out, progress=not args.quiet, resume=args.resume)
    _report(summary, args.out)
    return 0


def default_demo_config():
    """The closed-chamber demonstration configuration shipped with the package."""
    import tomllib

    text = resources.files("skygas").joinpath("data/demo-closed-chamber.toml").read_text()
    return parse_config(tomllib.loads(text), source="demo config: ")


def _demo(args) -> int:
    summary = run_simulation(default_demo_config(), args.out, progress=not args.quiet)
    _report(summary, args.out)
    return 0


def _report(summary: dict, out) -> None:
    brief = {k: v for k, v in summary.items() if k != "config"}
    print(json.dumps(brief, indent=2))
    print(f"results in {Path(out).resolve()}")


def register(subparsers) -> None:
    p = subparsers.add_parser("simulate", help="run a simulation described by a TOML file")
    p.add_argument("config", help="TOML configuration (see examples/)")
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--resume", action="store_true", help="continue from OUT/checkpoint.npz")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_simulate)

    d = subparsers.add_parser("demo", help="run the default demonstration")
    d.add_argument("--out", default="demo-output", help="output directory")
    d.add_argument("--quiet", action="store_true", help="no progress bar")
    d.set_defaults(func=_demo)
