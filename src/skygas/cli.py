"""Command-line interface: a thin layer over the Python API.

Each command group is a module of :mod:`skygas.commands` that exposes
``register(subparsers)``; this module only collects them. Every command is one call into the
library (imported when the command runs, so building the parser imports no numerics), and
anything the CLI does can be done from Python as well.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from skygas._version import __version__
from skygas.errors import InputError, RunInterrupted

# Modules that add sub-commands; each defines ``register(subparsers)``.
_COMMAND_MODULES = [
    "skygas.commands.simulate",
    "skygas.commands.reshuffle",
    "skygas.commands.neuron",
    "skygas.commands.sweep",
    "skygas.commands.animate",
    "skygas.commands.report",
    "skygas.commands.export",
    "skygas.commands.analyze",
    "skygas.commands.sc",
    "skygas.commands.micromag",
]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="skygas",
        description="Stochastic Thiele simulation of skyrmion gases and skyrmionic devices.",
    )
    parser.add_argument("--version", action="version", version=f"skygas {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in _COMMAND_MODULES:
        importlib.import_module(name).register(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except InputError as err:
        print(f"skygas: error: {err}", file=sys.stderr)
        return 2
    except RunInterrupted as err:
        print(f"skygas: {err}", file=sys.stderr)
        return err.exit_status
    except KeyboardInterrupt:
        print("skygas: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
