"""``skygas track MOVIE --out DIR`` and ``skygas render RUN --out movie.tif``.

``track`` locates and links the skyrmions of a microscope movie (:mod:`skygas.movies`);
``render`` draws a simulated run as such a movie. docs/tracking.md.
"""

from __future__ import annotations

import argparse
import sys

from skygas.commands.json_output import add_json_option

#: ``--drift``'s answers in ``skygas track`` (subtract the picture's drift: yes or no);
#: ``skygas infer`` adds ``auto``
DRIFT_CHOICES = ("yes", "no")
#: older spellings of ``--drift`` (``skygas track``'s before), still read as their answer
DRIFT_ALIASES = {"on": "yes", "off": "no"}


def drift_word(text: str) -> str:
    """A ``--drift`` answer as typed, the older ``on``/``off`` read as ``yes``/``no``."""
    word = text.strip().lower()
    return DRIFT_ALIASES.get(word, word)


def add_drift_option(parser, choices: tuple[str, ...], default: str, what: str) -> None:
    """Add ``--drift`` (one vocabulary for ``skygas track`` and ``skygas infer``) to ``parser``.

    ``choices``: the answers, from ``auto``, ``yes`` and ``no``; ``what``: the help text, which
    gives the default. ``on`` and ``off`` are read as ``yes`` and ``no``.
    """
    parser.add_argument(
        "--drift",
        type=drift_word,
        choices=choices,
        default=default,
        metavar="{" + ",".join(choices) + "}",
        help=f"{what}; on and off, the older spellings, are read as yes and no",
    )


def _q(value: float | None, unit: str = "", digits: int = 4) -> str:
    """A number as skygas writes it for a person: SI prefix or ×10ⁿ, never e-notation."""
    from skygas.core.quantities import format_value

    return format_value(value, unit=unit, digits=digits) or "not known"


def _check_track_out(args) -> None:
    """Refuse an ``--out`` that is the movie's folder or inside it, before anything is made."""
    from pathlib import Path

    from skygas.outputs.out_paths import check_folder_out

    movie = Path(args.movie)
    check_folder_out(args.out, [movie] if movie.is_dir() else [])


def _track(args: argparse.Namespace) -> int:
    from skygas.commands.json_output import print_json
    from skygas.commands.run_options import limits_from_flags
    from skygas.movies.track_run import track_movie

    # --force: a movie expected to take over a day; --json: no estimate line, no progress bar
    with limits_from_flags(args, announce=not args.json):
        result = track_movie(
            args.movie,
            args.out,
            pixel_size=args.pixel_size,
            frame_interval=args.frame_interval,
            contrast=args.contrast,
            diameter=args.diameter,
            minmass=args.minmass,
            search_range=args.search_range,
            memory=args.memory,
            drift=args.drift == "yes",
            progress=not (args.quiet or args.json),
        )
    s = result.summary
    for warning in s["warnings"]:
        print(f"skygas: warning: {warning}", file=sys.stderr)
    if args.json:  # what track.json holds
        print_json(s)
        return 0
    c, n = s["choices"], s["counts"]
    print(
        f"skygas track: {s['frames']} frames of {s['frame_shape_px'][1]} × "
        f"{s['frame_shape_px'][0]} px; {c['contrast']} skyrmions ({c['sources']['contrast']}), "
        f"diameter {c['diameter']} px, minmass {_q(c['minmass'])}, search range "
        f"{_q(c['search_range'], digits=3)} px, memory {c['memory']}"
    )
    print(
        f"  {n['features']} features, {n['per_frame_mean']:.1f} per frame; {n['tracks']} tracks, "
        f"median length {n['track_length_median_frames']:.0f} frames, "
        f"{n['tracks_spanning_whole_movie']} spanning the whole movie"
    )
    print(
        f"  pixel size {_q(s['pixel_size_m'], 'm')}, frame interval "
        f"{_q(s['frame_interval_s'], 's')}"
    )
    print(f"results in {args.out} (tracks.csv, track.json, overlay.mp4, report.html)")
    return 0


def _check_render_out(args) -> None:
    from skygas.outputs.out_paths import check_file_out
    from skygas.outputs.records import find_result_file

    result = find_result_file(args.run)
    check_file_out(args.out, [args.run, result], kinds=(".tif", ".tiff"), overwrite=args.overwrite)


def _render(args: argparse.Namespace) -> int:
    from pathlib import Path

    from skygas.core.errors import InputError
    from skygas.movies.render import (
        RenderSettings,
        render_run,
        write_movie,
        write_outline,
        write_true_landscape,
    )

    out = Path(args.out)
    if out.suffix.lower() not in (".tif", ".tiff"):
        raise InputError("--out", str(out), "a file name ending in .tif or .tiff")
    if not out.parent.is_dir():
        raise InputError("--out", str(out), "a file in an existing directory")
    settings = RenderSettings(
        pixel_size=args.pixel_size,
        psf_sigma=args.psf_sigma,
        contrast=args.contrast,
        background=args.background,
        depth=args.depth,
        noise=args.noise,
        photons=args.photons,
        illumination_drift=args.illumination_drift,
        margin=args.margin,
        dtype=args.dtype,
        seed=args.seed,
    ).checked()
    from skygas.movies.render import Grid, true_model
    from skygas.outputs.records import load_run

    record = load_run(args.run)
    frames, metadata = render_run(
        record,
        settings,
        stride=args.stride,
        max_frames=args.max_frames,
        start=args.start,
        progress=not args.quiet,
    )
    truth = true_model(record)
    if truth is not None:
        metadata["true_model"] = truth
    write_movie(out, frames, metadata)
    grid = Grid(tuple(metadata["origin_m"]), settings.pixel_size, frames.shape[1:])
    png, csv = write_outline(out, record.outline, grid)
    landscape = write_true_landscape(out, record, grid)
    t, ny, nx = frames.shape
    print(
        f"wrote {out} ({t} frames of {nx} × {ny} px, {frames.dtype}, pixel size "
        f"{_q(settings.pixel_size, 'm')}, frame interval {_q(metadata['frame_interval_s'], 's')}, "
        f"{out.stat().st_size / 1e6:.2f} MB)"
    )
    written = [out.with_suffix(".json"), png, csv, *([landscape] if landscape else [])]
    print(f"  and {', '.join(p.name for p in written)}")
    return 0


def register(subparsers) -> None:
    """Add ``skygas track`` and ``skygas render`` to ``subparsers``."""
    from skygas.commands.run_options import add_force_option

    p = subparsers.add_parser(
        "track",
        help="locate and link the skyrmions of a microscope movie (trackpy)",
        description="Locate skyrmions in an image sequence (a TIFF stack or a folder of "
        "images), link them into tracks with trackpy and write tracks.csv (trackpy's format), "
        "track.json (the choices made), overlay.mp4 and report.html. Settings not given are "
        "chosen from the movie (docs/tracking.md).",
    )
    p.add_argument("movie", help="TIFF stack (.tif) or folder of images")
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument(
        "--pixel-size",
        type=float,
        default=None,
        help="metres per pixel (default: the movie's sidecar JSON or TIFF tags, if any)",
    )
    p.add_argument(
        "--frame-interval",
        type=float,
        default=None,
        help="seconds between frames (default: the movie's sidecar JSON or TIFF tags, if any)",
    )
    p.add_argument(
        "--contrast",
        choices=["auto", "dark", "bright"],
        default="auto",
        help="skyrmions darker or brighter than the film (default: auto, from the data)",
    )
    p.add_argument(
        "--diameter",
        type=int,
        default=None,
        help="trackpy's feature diameter [px], odd (default: from the autocorrelation)",
    )
    p.add_argument(
        "--minmass",
        "--threshold",
        dest="minmass",
        type=float,
        default=None,
        help="the smallest integrated brightness of a skyrmion (default: from the noise level)",
    )
    p.add_argument(
        "--search-range",
        type=float,
        default=None,
        help="the farthest a skyrmion moves between frames [px] (default: from the data)",
    )
    p.add_argument(
        "--memory",
        type=int,
        default=None,
        help="frames a skyrmion may be missed and keep its track (default 3)",
    )
    add_drift_option(
        p,
        DRIFT_CHOICES,
        "no",
        "subtract the drift of the whole picture, e.g. a stage's (default no: in a closed "
        "device the gas's mean position moves for real)",
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    add_json_option(p, "the summary (what track.json holds)")
    add_force_option(p)
    p.set_defaults(func=_track, check_out=_check_track_out)

    r = subparsers.add_parser(
        "render",
        help="draw a simulated run as a microscope movie (TIFF stack)",
        description="Draw the skyrmions of a finished run as a microscope would see them: "
        "discs of their diameter blurred by a Gaussian PSF, on a background, with shot and "
        "read noise and a slow illumination drift. Writes the TIFF stack (pixel size and "
        "frame interval in its tags), a sidecar JSON (the same, the settings and the run's "
        "true parameters) and the outline as a mask PNG and a polygon CSV (docs/tracking.md).",
    )
    r.add_argument("run", help="run directory or trajectories.nc")
    r.add_argument("--out", required=True, help="movie file, .tif")
    r.add_argument("--pixel-size", type=float, required=True, help="metres per pixel")
    r.add_argument(
        "--psf-sigma",
        type=float,
        default=None,
        help="standard deviation of the Gaussian PSF [m] (default: a quarter of the diameter)",
    )
    r.add_argument(
        "--contrast", choices=["dark", "bright"], default="dark", help="skyrmions' contrast"
    )
    r.add_argument(
        "--background",
        type=float,
        default=None,
        help="film level [counts] (default 60 %% of the range)",
    )
    r.add_argument(
        "--depth",
        type=float,
        default=None,
        help="skyrmion contrast [counts] (default 35 %% of the range)",
    )
    r.add_argument("--noise", type=float, default=2.0, help="Gaussian read noise [counts]")
    r.add_argument(
        "--photons",
        type=float,
        default=0.0,
        help="photons at the film level for shot noise (0: none)",
    )
    r.add_argument(
        "--illumination-drift",
        type=float,
        default=0.0,
        help="illumination gradient across the field, a fraction, turning once over the movie",
    )
    r.add_argument(
        "--margin",
        type=float,
        default=None,
        help="field beyond the device [m] (default: two diameters)",
    )
    r.add_argument("--dtype", choices=["uint8", "uint16"], default="uint8", help="pixel type")
    r.add_argument(
        "--start",
        type=float,
        default=0.0,
        help="the first time shown [s]: a burn-in while a gas placed at random relaxes",
    )
    r.add_argument("--stride", type=int, default=1, help="every N-th recorded frame")
    r.add_argument("--max-frames", type=int, default=None, help="the most frames (default: all)")
    r.add_argument("--seed", type=int, default=0, help="seed of the noise")
    r.add_argument("--quiet", action="store_true", help="no progress bar")
    r.set_defaults(func=_render, check_out=_check_render_out)
