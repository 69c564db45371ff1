"""``skygas export RUN --format gsd|extxyz --out FILE``: trajectories for particle viewers.

For OVITO, VMD, HOOMD's tools or ASE (see :mod:`skygas.outputs.export`).
"""

from __future__ import annotations

from pathlib import Path

from skygas.core.errors import InputError

FORMATS = ("gsd", "extxyz")


#: the suffixes of export files (the only files written into a run folder)
KINDS = (".gsd", ".xyz", ".extxyz")


def _check_out(args) -> None:
    """Refuse, before any work, an ``--out`` over the run's files or into a store."""
    from skygas.outputs.out_paths import check_file_out
    from skygas.outputs.records import find_result_file

    out = Path(args.out)
    result = find_result_file(args.run)
    check_file_out(out, [args.run, result], kinds=KINDS, overwrite=args.overwrite)
    if not out.parent.is_dir():
        raise InputError("--out", str(out), "a file in an existing directory")


def _export(args) -> int:
    _check_out(args)  # before any work
    out = Path(args.out)
    from skygas.outputs.export import export_run
    from skygas.outputs.records import load_run

    record = load_run(args.run)
    export_run(record, args.format, out)
    print(f"wrote {out} ({record.frames.n_frames} frames, positions in nm)")
    return 0


def register(subparsers) -> None:
    """Add ``skygas export`` to ``subparsers``."""
    p = subparsers.add_parser("export", help="trajectories as GSD or extended XYZ")
    p.add_argument("run", help="run directory or result file")
    p.add_argument(
        "--format",
        required=True,
        choices=FORMATS,
        help="gsd (HOOMD, OVITO) or extxyz (OVITO, ASE, VMD)",
    )
    p.add_argument(
        "--out",
        required=True,
        help="output file (.gsd, .xyz; never one of the run's files, never in a sweep store)",
    )
    p.set_defaults(func=_export)
