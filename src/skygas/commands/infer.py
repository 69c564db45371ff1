"""``skygas infer TRACKS --out DIR``: from tracked skyrmions to a particle model.

Reads trackpy's tracks, infers diffusion, Hall angle, pinning landscape, wall and pair laws
(:mod:`skygas.inference`) and writes inference.json, landscape.nc, model.toml and report.html.
The handler imports the inference when it runs (building the command line imports no numerics).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from skygas.commands.json_output import add_json_option


def register(subparsers) -> None:
    """Add ``skygas infer`` to ``subparsers``."""
    p = subparsers.add_parser(
        "infer",
        help="tracked skyrmions (trackpy) → diffusion, landscape, pair and wall laws, a model",
        description="Infer a particle model from tracks in trackpy's format (frame, particle, x, "
        "y in pixels): D and the Hall angle, the pinning landscape by Boltzmann inversion, the "
        "wall potential, the pair potential by iterative Boltzmann inversion with skygas "
        "simulations. Writes DIR/inference.json, landscape.nc, model.toml (use it as "
        "--material DIR/model.toml) and report.html. See docs/inference.md.",
    )
    p.add_argument("tracks", metavar="TRACKS", help="a .csv, .h5 or .parquet file of tracks")
    p.add_argument("--pixel-size", type=float, default=None, help="metres per pixel (required)")
    p.add_argument(
        "--frame-interval", type=float, default=None, help="seconds between frames (required)"
    )
    p.add_argument(
        "--outline",
        required=True,
        help="the device: a CSV of x,y vertices [m] or a binary mask image on the pixel grid",
    )
    p.add_argument("--temperature", type=float, required=True, help="the film's temperature [K]")
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument(
        "--base-material",
        default="S2",
        help="preset or TOML for what tracks cannot measure (M_s, film thickness, α)",
    )
    p.add_argument(
        "--skyrmion-radius", type=float, default=None, help="R [m] (default: the base material's)"
    )
    p.add_argument(
        "--drift", choices=("auto", "yes", "no"), default="auto", help="subtract trackpy's drift"
    )
    p.add_argument("--ibi-iterations", type=int, default=6, help="IBI iterations at most")
    p.add_argument(
        "--ibi-frames",
        type=int,
        default=None,
        help="frames per IBI simulation (default: the movie's, at most 2000)",
    )
    p.add_argument("--seed", type=int, default=0, help="seed of the bootstrap and simulations")
    add_json_option(p, "the inferred model: inference.json's numbers")
    p.set_defaults(func=_infer)


def _infer(args: argparse.Namespace) -> int:
    from skygas.commands.json_output import print_json
    from skygas.core.errors import require
    from skygas.inference import infer
    from skygas.inference.files import write_outputs

    require(args.ibi_iterations >= 0, "--ibi-iterations", args.ibi_iterations, "an integer >= 0")
    require(
        args.ibi_frames is None or args.ibi_frames >= 100,
        "--ibi-frames",
        args.ibi_frames,
        "at least 100 frames",
    )
    started = time.time()

    def progress(line: str) -> None:
        if not args.json:
            print(f"[{time.time() - started:6.1f} s] {line}", file=sys.stderr, flush=True)

    result = infer(
        args.tracks,
        pixel_size=args.pixel_size,
        frame_interval=args.frame_interval,
        outline=args.outline,
        temperature=args.temperature,
        base_material=args.base_material,
        skyrmion_radius=args.skyrmion_radius,
        subtract_drift=args.drift,
        ibi_iterations=args.ibi_iterations,
        ibi_frames=args.ibi_frames,
        seed=args.seed,
        progress=progress,
    )
    write_outputs(result, args.out)
    s = result.summary
    if args.json:
        print_json(
            {
                "diffusion_constant": s["diffusion_constant"],
                "diffusion_constant_error": s["diffusion_constant_error"],
                "hall_angle": s["hall_angle"],
                "hall_angle_error": s["hall_angle_error"],
                "pair_range_fixed_by_data_m": s["pair"]["range_fixed_by_data_m"],
                "wall_range_fixed_by_data_m": s["wall"]["sampled_range_m"],
                "model": str(Path(args.out) / "model.toml"),
            }
        )
    else:
        print(
            f"D = {s['diffusion_constant']:.4g} ± {s['diffusion_constant_error']:.2g} m²/s, "
            f"Hall angle = {s['hall_angle']:.3f} ± {s['hall_angle_error']:.3f} rad"
        )
        land = s["landscape"]
        print(
            f"pinning: rms {land['pinning_rms_kT']:.2f} k_BT, correlation length "
            f"{land['pinning_correlation_length_m'] * 1e9:.0f} nm, kernel "
            f"{land['kernel_width_m'] * 1e9:.1f} nm"
        )
        print(
            f"results in {Path(args.out).resolve()}: inference.json, landscape.nc, model.toml, "
            "report.html"
        )
    return 0
