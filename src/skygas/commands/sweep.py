"""``skygas sweep`` runs a parameter sweep; ``skygas plot`` draws its figures and fits.

``skygas sweep SWEEP.toml --out STORE [--scheduler ADDRESS] [--workers N]`` runs a parameter sweep
(resuming whatever the store lacks); ``skygas plot STORE --out DIR`` draws the paper's reshuffler
figures from it and prints the fitted exponents.
"""

from __future__ import annotations

import sys

from skygas.commands.json_output import add_json_option, print_json
from skygas.commands.run_options import add_dask_options, add_force_option


def _sweep(args) -> int:
    from skygas.commands.run_options import limits_from_flags
    from skygas.sweep import load_sweep, run_sweep  # Dask and zarr load only when used

    sweep = load_sweep(args.sweep, args.set)  # every point is validated before anything runs
    with limits_from_flags(args, announce=not args.json):  # --force; the estimate unless --quiet
        report = run_sweep(
            sweep,
            args.out,
            scheduler=args.scheduler,
            workers=args.workers,
            serial=args.serial,
            progress=not (args.quiet or args.json),
        )
    if args.json:
        print_json(
            {
                "store": str(report.store.resolve()),
                "runs": len(sweep.runs),
                "points": sweep.n_points,
                "replicas": sweep.replicas,
                "computed": len(report.computed),
                "already_done": report.skipped,
                "failed": [
                    {"index": index, "replica": replica, "error": str(error)}
                    for index, replica, error in report.failed
                ],
                "wall_time_s": report.wall_time_s,
            }
        )
    else:
        print(
            f"{len(report.computed)} runs computed, {report.skipped} already done, "
            f"{len(sweep.runs)} in all ({sweep.n_points} points × {sweep.replicas} replicas) "
            f"in {report.wall_time_s:.1f} s; results in {report.store.resolve()}"
        )
    for index, replica, error in report.failed:
        print(f"skygas: run {index} replica {replica} failed: {error}", file=sys.stderr)
    if report.failed:
        print(
            f"skygas: {len(report.failed)} runs failed; run the same command again to retry them",
            file=sys.stderr,
        )
        return 1
    return 0


def _check_plot_out(args) -> None:
    """Refuse, before the folder is created or locked, an ``--out`` in a store or a run folder."""
    from skygas.outputs.out_paths import check_folder_out

    check_folder_out(args.out, args.store)


def _plot(args) -> int:
    from pathlib import Path

    from skygas.outputs.report import write_report
    from skygas.sweep import open_sweeps, plot_sweep

    stores = open_sweeps(args.store)  # one store, or several over the same fields, combined
    result = plot_sweep(stores, args.out)
    write_report(args.store, Path(args.out) / "report.html")
    result["report"] = str(Path(args.out) / "report.html")
    if args.json:
        print_json(result)
        return 0
    from skygas.sweep.figures import exponent_lines

    for line in exponent_lines(result):
        print(line)
    print("wrote " + ", ".join(result["figures"]))
    return 0


def register(subparsers) -> None:
    """Add ``skygas sweep`` and ``skygas plot`` to ``subparsers``."""
    p = subparsers.add_parser("sweep", help="run a parameter sweep of any device (Dask, resumable)")
    p.add_argument("sweep", help="sweep file (TOML; see docs/sweeps.md)")
    p.add_argument("--out", required=True, help="zarr store (created, or resumed if it exists)")
    add_dask_options(p)
    add_json_option(p, "what was computed")
    add_force_option(p)
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="TABLE.KEY=VALUE",
        help="change the sweep file before it runs (TOML value; repeatable), e.g. "
        "--set base.duration=1e-5 --set sweep.replicas=2",
    )
    p.set_defaults(func=_sweep)

    q = subparsers.add_parser("plot", help="figures and fits of a sweep store")
    q.add_argument(
        "store",
        nargs="+",
        help="zarr store written by `skygas sweep`; several stores over the same "
        "swept fields but different points are drawn and fitted together",
    )
    q.add_argument(
        "--out",
        required=True,
        help="directory for the PNG figures and fits.json (beside the store, never inside it)",
    )
    add_json_option(q, "the fits")
    q.set_defaults(func=_plot, check_out=_check_plot_out)
