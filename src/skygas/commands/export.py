"""``skygas export RUN --format gsd|extxyz --out FILE``: trajectories for particle viewers.

For OVITO, VMD, HOOMD's tools or ASE (see :mod:`skygas.outputs.export`).
"""

from __future__ import annotations

from pathlib import Path

from skygas.core.errors import InputError

FORMATS = ("gsd", "extxyz")


def _export(args) -> int:
    from skygas.outputs.records import find_result_file

    out = Path(args.out)
    if not out.parent.is_dir():
        raise InputError("--out", str(out), "a file in an existing directory")
    find_result_file(args.run)
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
    p.add_argument("--out", required=True, help="output file")
    p.set_defaults(func=_export)
