"""``skygas sc ...`` commands: a thin layer over :mod:`skygas.sc`."""

from __future__ import annotations

import argparse

from skygas.commands.json_output import add_json_option


def _demo(args: argparse.Namespace) -> int:
    from skygas.commands.run_options import named_by_flags
    from skygas.sc.demo import run_demo

    with named_by_flags(args, {"n_bits": "n_bits", "seed": "seed"}):
        summary = run_demo(args.out, seed=args.seed, n_bits=args.n_bits)
    if args.reshuffler:
        from skygas.reshuffler.decorrelator import DEMO_SUMMARY_KEY, reshuffler_demo

        summary = {**summary, DEMO_SUMMARY_KEY: reshuffler_demo(args.out, seed=args.seed)}
    if not args.no_report:
        from pathlib import Path

        from skygas.outputs.report import write_report

        write_report(args.out, Path(args.out) / "report.html")
    if args.json:
        from skygas.commands.json_output import print_json

        print_json(summary)
    else:
        print(f"stochastic-computing demo written to {args.out}")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``sc`` command group."""
    parser = subparsers.add_parser(
        "sc", help="stochastic computing: bitstreams, gates, decorrelators"
    )
    commands = parser.add_subparsers(dest="sc_command", metavar="SC_COMMAND", required=True)
    demo = commands.add_parser(
        "demo", help="AND-gate squaring, error vs length, decorrelators compared (figures + JSON)"
    )
    demo.add_argument("--out", required=True, help="output directory")
    demo.add_argument("--seed", type=int, default=2024, help="master seed (default 2024)")
    demo.add_argument("--n-bits", type=int, default=4096, help="stream length N (default 4096)")
    demo.add_argument(
        "--reshuffler",
        action="store_true",
        help="also run the skyrmion reshuffler device (about 5 s more)",
    )
    demo.add_argument("--no-report", action="store_true", help="do not write OUT/report.html")
    add_json_option(demo, "every curve and number of the demo")
    demo.set_defaults(func=_demo)
