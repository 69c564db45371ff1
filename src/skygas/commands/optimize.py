"""``skygas optimize STUDY.toml --out DIR``: search a device's design with optuna, on Dask.

``skygas optimize STUDY.toml --out DIR [--workers N | --scheduler ADDRESS | --serial]
[--trials K] [--seed S]`` runs the study until K trials have finished (resuming a study folder
that holds fewer), re-evaluates its best candidates and writes trials.csv, best.json, the Pareto
front, the figures and report.html into DIR (``docs/optimize.md``). It then prints what
best.json says, the rows that open the report (:func:`skygas.optimize.verdict.statement`): the
best trial, its value after re-evaluation, the candidates within noise of it, its parameters on
a search bound.
"""

from __future__ import annotations

import sys

from skygas.commands.json_output import add_json_option, print_json
from skygas.commands.run_options import add_dask_options, add_force_option


def _optimize(args) -> int:
    import json
    import time
    from pathlib import Path

    from skygas.commands.run_options import limits_from_flags
    from skygas.optimize.execute import run_study
    from skygas.optimize.results import write_results
    from skygas.optimize.spec import load_study
    from skygas.runs import manifest

    started = time.time()
    study = load_study(args.study, seed=args.seed)  # everything is checked before any run
    with limits_from_flags(args):
        report = run_study(
            study,
            args.out,
            args.trials,
            scheduler=args.scheduler,
            workers=args.workers,
            serial=args.serial,
            progress=not args.quiet,
        )
    # this invocation's command line and start, for the report's "Made by" line
    manifest.write(args.out, "optimize", study.fingerprint(), started_at=started)
    result = write_results(args.out)
    manifest.write(
        args.out, "optimize", study.fingerprint(), started_at=started, finished_at=time.time()
    )
    # what best.json says, as the report shows it: the file is the one answer
    best = json.loads((Path(args.out) / "best.json").read_text())
    if args.json:
        print_json({**result, "finished_now": report.finished_now, "already": report.already})
    else:
        print(
            f"{report.finished_now} trials finished now, {report.already} already done"
            + (f" ({report.recovered} interrupted trials asked again)" if report.recovered else "")
            + (f", {report.reevaluated} re-evaluation runs" if report.reevaluated else "")
            + f" in {report.wall_time_s:.1f} s; results in {report.out.resolve()}"
        )
        _print_best(best)
    for number, error in report.failed:
        print(f"skygas: trial {number} failed: {error}", file=sys.stderr)
    return 0


def _print_best(best: dict) -> None:
    """The rows of :func:`skygas.optimize.verdict.statement`, as the report's headline has them."""
    from skygas.optimize.verdict import statement

    for label, text in statement(best):
        print(f"{label}: {text}")


def register(subparsers) -> None:
    """Add ``skygas optimize`` to ``subparsers``."""
    p = subparsers.add_parser(
        "optimize", help="search a device's design with optuna (Dask, resumable)"
    )
    p.add_argument("study", help="study file (TOML; see docs/optimize.md)")
    p.add_argument(
        "--out", required=True, help="study folder (created, or resumed if it holds this study)"
    )
    p.add_argument(
        "--trials",
        type=int,
        default=40,
        help="finished trials in all (a resumed study runs only the missing ones)",
    )
    p.add_argument(
        "--seed", type=int, default=None, help="root seed (default: [study] seed, else 0)"
    )
    add_dask_options(p)
    add_json_option(p, "the best trial (or the Pareto set) and the trials run")
    add_force_option(p)
    p.set_defaults(func=_optimize)
