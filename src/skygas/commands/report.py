"""``skygas report RUN_DIR_OR_STORE [--out report.html]``: one self-contained HTML report.

Of a run or a sweep store (see :mod:`skygas.outputs.report`), or of a study folder of
``skygas optimize`` (whose tables and figures are redrawn too, :mod:`skygas.optimize.results`).
A run's report goes by default into its run folder (``RUN/report.html``, refreshed each
time: everything in it is made from the run's results); a sweep store's beside the store
(``out/sweep.zarr`` → ``out/sweep-report.html``), since nothing is written into a store. An
``--out`` that is one of the inputs, a run's result or a file in a store is refused; another
existing file is replaced only with ``--overwrite`` (:mod:`skygas.outputs.out_paths`).
"""

from __future__ import annotations

from pathlib import Path

#: the suffixes of reports (the only files written into a run folder)
KINDS = (".html", ".htm")


def default_out(source: Path) -> Path:
    """Where the report of ``source`` goes without ``--out``.

    Parameters
    ----------
    source : Path
        A run folder, a result file or a sweep store.

    Returns
    -------
    Path
        ``RUN/report.html`` for a run (or its result file), ``STORE-report.html`` beside a
        sweep store.
    """
    from skygas.outputs.out_paths import beside_store, is_store

    if is_store(source):
        return beside_store(source, "-report.html")
    return (source if source.is_dir() else source.parent) / "report.html"


def _inputs(source: Path) -> list[Path]:
    """The paths the report reads: the source and, for a run, its result file."""
    from skygas.optimize.execute import is_study_folder
    from skygas.outputs.out_paths import is_store
    from skygas.outputs.report import SUMMARY_FILES

    summary_only = source.is_dir() and any((source / n).exists() for n in SUMMARY_FILES)
    if is_store(source) or is_study_folder(source):
        return [source]
    if summary_only:
        return [source, *(source / n for n in SUMMARY_FILES if (source / n).exists())]
    from skygas.outputs.records import find_result_file

    return [source, find_result_file(source)]  # a clear error before any work


def _check_out(args) -> None:
    """Refuse, before any work, an ``--out`` over the run's files or into a store."""
    from skygas.outputs.out_paths import check_file_out
    from skygas.outputs.report import check_report_path

    source = Path(args.source)
    inputs = _inputs(source)
    out = Path(args.out) if args.out else default_out(source)
    check_file_out(out, inputs, kinds=KINDS, overwrite=args.overwrite, default=args.out is None)
    check_report_path(out)


def _report(args) -> int:
    _check_out(args)  # before any work
    from skygas.optimize.execute import is_study_folder
    from skygas.outputs.report import check_report_path, write_report

    source = Path(args.source)
    out = check_report_path(Path(args.out) if args.out else default_out(source))
    if is_study_folder(source):  # a study's tables and figures are redrawn with its report
        from skygas.optimize.results import write_results
        from skygas.runs.run_driver import write_atomic

        write_results(source)
        path = source / "report.html"
        if out.resolve() != path.resolve():
            text = path.read_text(encoding="utf-8")
            path = write_atomic(out, lambda tmp: tmp.write_text(text, encoding="utf-8"))
        print(
            f"wrote {path} ({path.stat().st_size / 1e6:.2f} MB) and the study's tables and figures"
        )
        return 0
    path = write_report(source, out)
    print(f"wrote {path} ({path.stat().st_size / 1e6:.2f} MB)")
    return 0


def register(subparsers) -> None:
    """Add ``skygas report`` to ``subparsers``."""
    p = subparsers.add_parser(
        "report", help="self-contained HTML report of a run, a sweep or a study"
    )
    p.add_argument("source", help="run directory, result file, sweep store or study folder")
    p.add_argument(
        "--out",
        default=None,
        help="HTML file (default: report.html in the run directory, refreshed each time; "
        "NAME-report.html beside a sweep store NAME.zarr)",
    )
    p.set_defaults(func=_report)
