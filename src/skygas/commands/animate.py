"""``skygas animate RUN --out movie.mp4|movie.gif``: a movie of a finished run.

Options ``[--stride N] [--window START:END]``; see :mod:`skygas.outputs.movie`.
"""

from __future__ import annotations

from skygas.core.errors import InputError


def parse_window(text: str | None) -> tuple[float | None, float | None]:
    """``START:END`` [s], either side may be empty (``:2e-6``, ``1e-6:``)."""
    if text is None:
        return None, None
    parts = text.split(":")
    try:
        if len(parts) != 2:
            raise ValueError
        start, end = (float(p) if p.strip() else None for p in parts)
    except ValueError:
        raise InputError("--window", text, "START:END in seconds, e.g. 0:2e-6 or 1e-6:") from None
    if start is not None and end is not None and end <= start:
        raise InputError("--window", text, "an END later than START")
    return start, end


def _positive(name: str, value, allowed: str):
    if value is not None and value < 1:
        raise InputError(name, value, allowed)


def _check_out(args) -> None:
    """Refuse, before any work, an ``--out`` over the run's files or into a store."""
    from skygas.outputs.movie import FORMATS
    from skygas.outputs.out_paths import check_file_out
    from skygas.outputs.records import find_result_file

    result = find_result_file(args.run)
    check_file_out(args.out, [args.run, result], kinds=tuple(FORMATS), overwrite=args.overwrite)


def _animate(args) -> int:
    from skygas.outputs.movie import check_movie_path

    # every argument is checked before the run is read
    path = check_movie_path(args.out)
    start, end = parse_window(args.window)
    _positive("--stride", args.stride, "an integer >= 1 (every N-th recorded frame)")
    _positive("--max-frames", args.max_frames, "an integer >= 1")
    _positive("--fps", args.fps, "an integer >= 1 (frames per second)")
    if args.width < 160:
        raise InputError("--width", args.width, "a width of at least 160 pixels")
    _check_out(args)  # the run is there, and the movie goes over none of its files

    from skygas.outputs.movie import render_movie
    from skygas.outputs.records import load_run

    info = render_movie(
        load_run(args.run),
        path,
        stride=args.stride,
        start=start,
        end=end,
        max_frames=args.max_frames,
        fps=args.fps,
        width_px=args.width,
    )
    print(
        f"wrote {info.path} ({info.frames} frames, every {info.stride}. recorded frame, "
        f"{info.start * 1e6:.4g}–{info.end * 1e6:.4g} µs, {info.bytes / 1e6:.2f} MB)"
    )
    return 0


def register(subparsers) -> None:
    """Add ``skygas animate`` to ``subparsers``."""
    p = subparsers.add_parser("animate", help="movie (MP4 or GIF) of a finished run")
    p.add_argument(
        "run", help="run directory or result file (trajectories.nc, reshuffler.nc, frames.nc)"
    )
    p.add_argument("--out", required=True, help="movie file, .mp4 (H.264) or .gif")
    p.add_argument(
        "--stride",
        type=int,
        default=None,
        help="show every N-th recorded frame (default: the smallest N that keeps "
        "the movie within --max-frames)",
    )
    p.add_argument(
        "--window",
        default=None,
        metavar="START:END",
        help="time window in seconds, e.g. 0:2e-6 (default: the whole record)",
    )
    p.add_argument(
        "--max-frames",
        type=int,
        default=None,
        help="most frames when --stride is not given (default 1200 MP4, 300 GIF)",
    )
    p.add_argument("--fps", type=int, default=25, help="frames per second (default 25)")
    p.add_argument(
        "--width",
        type=int,
        default=720,
        help="width in pixels (default 720; a tall device is drawn narrower, at most 1024 "
        "pixels high, and a width too small for the axes and the colour bar is widened)",
    )
    p.set_defaults(func=_animate)
