"""``skygas infer TRACKS --out DIR``: from tracked skyrmions to a particle model.

Reads trackpy's tracks, infers D, the Hall angle and the forces the data show (a landscape, a
pair law, a wall law, a drive) from the steps (:mod:`skygas.inference`), checks the model by
running it, and writes inference.json, landscape.nc, landscape-map.npy, model.toml and
report.html. The handler imports the inference when it runs (building the command line imports
no numerics).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from skygas.commands.json_output import add_json_option
from skygas.commands.track import DRIFT_CHOICES, add_drift_option

#: Exit status of a model whose self-check failed under ``--strict``.
EXIT_CHECK_FAILED = 1


def register(subparsers) -> None:
    """Add ``skygas infer`` to ``subparsers``."""
    p = subparsers.add_parser(
        "infer",
        help="tracked skyrmions (trackpy) → D, Hall angle, the forces the data show, a model",
        description="Infer a particle model from tracks in trackpy's format (frame, particle, x, "
        "y in pixels): D from the noise of the steps, the Hall angle and the forces from their "
        "drift (a landscape, a pair law, a wall law, a drive: each only where the held-out "
        "likelihood asks for it), errors by jackknife over blocks of time; then a run of the "
        "model must reproduce the movie. Writes DIR/inference.json, landscape.nc, "
        "landscape-map.npy, model.toml (use it as --material DIR/model.toml) and report.html. "
        "See docs/inference.md.",
    )
    p.add_argument(
        "tracks",
        metavar="TRACKS",
        help="a .csv, .h5 or .parquet file of tracks, or the output folder of skygas track "
        "(its tracks.csv)",
    )
    p.add_argument(
        "--pixel-size",
        type=float,
        default=None,
        help="metres per pixel (default: the one the track.json of a skygas track folder "
        "records, for that folder or its tracks.csv; required for other tracks)",
    )
    p.add_argument(
        "--frame-interval", type=float, default=None, help="seconds between frames (required)"
    )
    p.add_argument("--temperature", type=float, required=True, help="the film's temperature [K]")
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument(
        "--outline",
        default=None,
        help="the device or the field of view: a CSV of x,y vertices [m] or a binary mask image "
        "on the pixel grid (default: the field of view is the tracks' extent, with no walls)",
    )
    p.add_argument(
        "--walls",
        choices=("infer", "none", "outline"),
        default="infer",
        help="a wall force where the tracks show one (infer), never (none), or always at the "
        "outline (outline); an outline that tracks leave and enter through is a field of view, "
        "never a wall, unless 'outline' is given",
    )
    p.add_argument(
        "--pair",
        choices=("infer", "none", "material"),
        default="infer",
        help="a pair law fitted to the tracks where they show one (infer), no interaction "
        "(none), or the base material's law (material)",
    )
    p.add_argument(
        "--periodic",
        nargs="+",
        default=["auto"],
        metavar="LX LY",
        help="tracks in a periodic box: 'auto' (found from tracks that wrap), 'none', or the "
        "box's sides L_x L_y [m]",
    )
    p.add_argument(
        "--base-material",
        default="S2",
        help="preset or TOML for what tracks cannot measure (M_s, film thickness, α; the pair "
        "law of --pair material)",
    )
    p.add_argument(
        "--skyrmion-radius",
        type=float,
        default=None,
        help="R [m], the model's length unit (default: the base material's, or a quarter of the "
        "closest distance between tracked skyrmions where that is far larger)",
    )
    add_drift_option(
        p,
        ("auto", *DRIFT_CHOICES),
        "auto",
        "subtract trackpy's drift of the whole view: auto (where it is significant and "
        "sharpens the landscape), yes or no (default auto)",
    )
    p.add_argument(
        "--check-frames",
        type=int,
        default=2000,
        help="frames of the self-check's run of the model (at most the movie's; 0: no check)",
    )
    p.add_argument(
        "--strict",
        action="store_true",
        help="exit with status 1 when the self-check fails (the model's MSD(τ)/4τ, g(r) or "
        "density map outside its stated tolerance: the first rows of report.html) or the "
        "frames are too coarse to fix D",
    )
    p.add_argument("--seed", type=int, default=0, help="seed of the self-check's run")
    p.add_argument(
        "--quiet",
        action="store_true",
        help="no progress lines on stderr and no summary on stdout (warnings are still printed)",
    )
    add_json_option(p, "the inferred model: inference.json's numbers")
    p.set_defaults(func=_infer)


def _periodic(values: list[str]):
    """``--periodic``: "auto", None, or (L_x, L_y) [m]."""
    from skygas.core.errors import InputError

    if values == ["auto"]:
        return "auto"
    if values == ["none"]:
        return None
    try:
        lengths = tuple(float(v) for v in values)
    except ValueError:
        lengths = ()
    if len(lengths) != 2:
        raise InputError(
            "--periodic", " ".join(values), "auto, none, or two lengths L_x L_y [m] of the box"
        )
    from skygas.inference.tracks import metres

    return tuple(metres("--periodic", side) for side in lengths)


def _infer(args: argparse.Namespace) -> int:
    from skygas.commands.json_output import print_json
    from skygas.core.errors import require
    from skygas.inference import infer
    from skygas.inference.files import write_outputs
    from skygas.inference.selfcheck import frames_check, summary_lines

    require(args.check_frames >= 0, "--check-frames", args.check_frames, "an integer >= 0")
    periodic = _periodic(args.periodic)
    from skygas.inference.tracks import pixel_size_for

    # a skygas track folder's track.json holds the pixel size (before the outline is read)
    pixel_size, note = pixel_size_for(args.tracks, args.pixel_size)
    if note and not args.quiet:
        print(f"skygas infer: {note}", file=sys.stderr, flush=True)
    started = time.time()
    quiet = args.json or args.quiet

    def progress(line: str) -> None:
        if not quiet:
            print(f"[{time.time() - started:6.1f} s] {line}", file=sys.stderr, flush=True)

    result = infer(
        args.tracks,
        pixel_size=pixel_size,
        frame_interval=args.frame_interval,
        temperature=args.temperature,
        outline=args.outline,
        walls=args.walls,
        pair=args.pair,
        periodic=periodic,
        base_material=args.base_material,
        skyrmion_radius=args.skyrmion_radius,
        subtract_drift=args.drift,
        check_frames=args.check_frames or None,
        seed=args.seed,
        progress=progress,
    )
    write_outputs(result, args.out)
    s = result.summary
    check = s["consistency_check"]
    failed = check is not None and not check["passed"]
    if not s["diffusion_constant_fixed_by_data"]:
        failed = True
        print(f"skygas: warning: {s['diffusion_constant_note']}", file=sys.stderr)
    if check is not None and not check["passed"]:
        for line in summary_lines(check):
            print(f"skygas: warning: the model fails its self-check: {line}", file=sys.stderr)
    frames = frames_check(s)
    # coarse frames left uncorrected (--check-frames 0): D and the forces carry a bias (a
    # correction that did not converge was said above)
    if not frames["passed"] and s["diffusion_constant_fixed_by_data"]:
        failed = True
        print(f"skygas: warning: {frames['what']}", file=sys.stderr)
    if args.json:
        print_json(
            {
                "diffusion_constant": s["diffusion_constant"],
                "diffusion_constant_error": s["diffusion_constant_error"],
                "hall_angle": s["hall_angle"],
                "hall_angle_error": s["hall_angle_error"],
                "terms": s["model_selection"]["terms"],
                "film": s["film"]["kind"],
                "self_check_passed": None if check is None else check["passed"],
                "model": str(Path(args.out) / "model.toml"),
            }
        )
    elif not args.quiet:
        from skygas.inference.report import headline_rows

        for label, value in headline_rows(result):
            print(f"{label}: {value}")
        print(
            f"results in {Path(args.out).resolve()}: inference.json, landscape.nc, "
            "landscape-map.npy, model.toml, report.html"
        )
    return EXIT_CHECK_FAILED if failed and args.strict else 0
