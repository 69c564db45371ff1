"""The output options every run command shares.

No numerics imported: building the command line stays fast.
"""

from __future__ import annotations


def add_output_flags(parser) -> None:
    """Add ``--animate`` and ``--no-report`` to ``parser``.

    ``--animate`` writes OUT/movie.mp4, recording frames often enough for it; ``--no-report`` skips
    OUT/report.html.
    """
    parser.add_argument(
        "--animate",
        action="store_true",
        help="record frames often enough for a smooth movie and write "
        "OUT/movie.mp4 (see `skygas animate` for other choices)",
    )
    parser.add_argument("--no-report", action="store_true", help="do not write OUT/report.html")
