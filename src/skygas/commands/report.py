"""``skygas report RUN_DIR_OR_STORE [--out report.html]``: one self-contained HTML report.

Of a run or a sweep store (see :mod:`skygas.outputs.report`).
"""

from __future__ import annotations

from pathlib import Path


def _report(args) -> int:
    from skygas.outputs.report import check_report_path

    source = Path(args.source)
    out = check_report_path(
        args.out or (source if source.is_dir() else source.parent) / "report.html"
    )
    from skygas.outputs.report import SUMMARY_FILES, write_report

    summary_only = source.is_dir() and any((source / n).exists() for n in SUMMARY_FILES)
    if not (source / "zarr.json").exists() and not summary_only:
        from skygas.outputs.records import find_result_file

        find_result_file(source)  # a clear error before any work

    path = write_report(source, out)
    print(f"wrote {path} ({path.stat().st_size / 1e6:.2f} MB)")
    return 0


def register(subparsers) -> None:
    """Add ``skygas report`` to ``subparsers``."""
    p = subparsers.add_parser("report", help="self-contained HTML report of a run or a sweep")
    p.add_argument("source", help="run directory, result file or sweep store")
    p.add_argument(
        "--out", default=None, help="HTML file (default: report.html in the run directory)"
    )
    p.set_defaults(func=_report)
