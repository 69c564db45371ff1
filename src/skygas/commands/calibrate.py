"""``skygas calibrate MATERIAL --out DIR``: from micromagnetic parameters to a particle model.

From a film's parameters to its particle model (model.toml), checked against micromagnetic dynamics.

The handler imports the calibration when it runs (building the command line imports no
numerics); the solver (torch, magnum.np) is imported by the Dask workers only (a local
cluster's, or with ``--scheduler`` a running cluster's), or by this process with ``--workers 0``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from skygas.commands.json_output import add_json_option, print_json
from skygas.commands.run_options import (
    add_run_options,
    add_scheduler_option,
    limits_from_flags,
    named_by_flags,
    run_options,
)

#: Exit status of a calibration whose model fails a quality check under ``--strict``.
EXIT_CHECK_FAILED = 1

#: configuration fields set by an option, to name the option in an error
_FLAGS = {
    "cell_size": "cell_size",
    "temperature": "temperature",
    "reference_diameter": "reference_diameter",
    "pair_distances": "pair_distances",
    "skyrmions": "validation.skyrmions",
    "validation_duration": "validation.max_duration",
    "validation_travel": "validation.min_travel",
    "validation_shape": "validation.shape",
}


def register(subparsers) -> None:
    """Add ``skygas calibrate`` to ``subparsers``."""
    p = subparsers.add_parser(
        "calibrate",
        # --strict is added again below with calibrate's own meaning, replacing the run options'
        conflict_handler="resolve",
        help="micromagnetics (magnum.np) → a calibrated particle model",
        description="Relax the material's isolated skyrmion, pairs and skyrmions near an edge "
        "with magnum.np, tabulate the pair and edge laws, write DIR/model.toml (use it as "
        '`material = "DIR/model.toml"` or `--material DIR/model.toml`), and check the '
        "model against micromagnetic many-skyrmion dynamics. See docs/calibration.md.",
    )
    p.add_argument(
        "material",
        metavar="MATERIAL",
        help="a preset (S1 … S7) or a TOML file of micromagnetic parameters; or a study file "
        "([study], [settings], and [grid] or [[points]]: one calibration per point, "
        "docs/calibration.md)",
    )
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument(
        "--cell-size",
        type=float,
        default=None,
        help="in-plane cell size [m] (default: the material's, 2e-9)",
    )
    p.add_argument(
        "--reference-diameter",
        type=float,
        default=None,
        help="size of the device whose interior the laws are for [m] "
        "(default 1024e-9, the paper's chamber)",
    )
    p.add_argument(
        "--pair-distances",
        type=int,
        default=None,
        metavar="N",
        help="pairs relaxed for the pair law, from 1 to 6 d_sk (default 11, at least 4; "
        "fewer: a coarser pair table and a faster calibration)",
    )
    p.add_argument(
        "--no-validate", action="store_true", help="skip the micromagnetic many-skyrmion dynamics"
    )
    p.add_argument(
        "--no-mesh-check", action="store_true", help="skip the relaxations at half the cell size"
    )
    p.add_argument(
        "--skyrmions", type=int, default=None, help="skyrmions of the validation run (default 3)"
    )
    p.add_argument(
        "--validation-duration",
        type=float,
        default=None,
        help="longest validation run [s] (default 10e-9)",
    )
    p.add_argument(
        "--validation-shape",
        choices=("disk", "rectangle"),
        default=None,
        help="the validation's film: a rectangle of 4 × 3 diameters whose skyrmions start "
        "near each other and each near an edge (default), or a disk of radius 2.5 diameters",
    )
    p.add_argument(
        "--validation-travel",
        type=float,
        default=None,
        metavar="D",
        help="the validation run stops once every skyrmion has travelled D diameters along "
        "its path (default 0.5)",
    )
    p.add_argument(
        "--workers",
        type=int,
        default=None,
        help="solver processes of the local Dask cluster (default: 2 on a CPU, or the "
        "number of cores if fewer; 0 on a GPU: this process drives it); not with --scheduler",
    )
    add_scheduler_option(p)
    p.add_argument(
        "--compile",
        action="store_true",
        help="compile magnum.np's field terms (torch.compile: faster per step, "
        "about 20 s per process to compile, a C compiler needed)",
    )
    add_json_option(p, "the calibration's numbers")
    add_run_options(p)
    p.add_argument(
        "--strict",
        action="store_true",
        help="exit with status 1 when a quality check of the model fails (the mesh, the film "
        "size, the edge energy at a real edge, the validation's goal for the RMS centre "
        "error: the first lines of report.html); the files are written all the same",
    )
    p.set_defaults(func=_calibrate)


def _settings(args) -> dict:
    """The calibration's settings given on the command line (CalibrationConfig fields)."""
    settings = {
        "validate_dynamics": not args.no_validate,
        "mesh_check": not args.no_mesh_check,
        "compile": args.compile,
    }
    if args.reference_diameter is not None:
        settings["reference_diameter"] = args.reference_diameter
    if args.pair_distances is not None:
        settings["pair_distances"] = args.pair_distances
    validation = {}
    if args.skyrmions is not None:
        validation["skyrmions"] = args.skyrmions
    if args.validation_duration is not None:
        validation["max_duration"] = args.validation_duration
    if args.validation_shape is not None:
        validation["shape"] = args.validation_shape
    if args.validation_travel is not None:
        validation["min_travel"] = args.validation_travel
    if validation:
        settings["validation"] = validation
    return settings


def _calibrate_study(args: argparse.Namespace) -> int:
    """``skygas calibrate STUDY.toml``: every point of a calibration study (calibration.study)."""
    from skygas.calibration.study import load_study, run_study

    options = run_options(args, progress=not args.json)
    with named_by_flags(args, _FLAGS), limits_from_flags(args, announce=not args.json):
        study = load_study(args.material, cell_size=args.cell_size)
        record = run_study(
            study,
            args.out,
            workers=args.workers,
            scheduler=args.scheduler,
            progress=options["progress"],
            checkpoint_seconds=options.get("checkpoint_seconds"),
            settings=_settings(args),
        )
    if args.json:
        print_json(record)
        return 0
    for row in record["points"]:
        values = ", ".join(f"{k} = {v!r}" for k, v in row["values"].items())
        print(
            f"{row['folder']} ({values}): R = {row['radius_m'] * 1e9:.2f} nm, 𝒟 = "
            f"{row['dissipation']:.3f}" + ("" if row["computed_now"] else " (already done)")
        )
    print(f"results in {Path(args.out).resolve()}: study.json, report.html, point-*/")
    return 0


def _calibrate(args: argparse.Namespace) -> int:
    from skygas.calibration import calibrate
    from skygas.calibration.material import load_micromagnetic_material
    from skygas.calibration.study import is_study_file

    if is_study_file(args.material):
        return _calibrate_study(args)

    options = run_options(args, progress=not args.json)
    with named_by_flags(args, _FLAGS), limits_from_flags(args, announce=not args.json):
        material = load_micromagnetic_material(args.material, cell_size=args.cell_size)
        data = calibrate(
            material,
            args.out,
            workers=args.workers,
            scheduler=args.scheduler,
            **options,
            **_settings(args),
        )
    failed = [c for c in data.get("quality_checks", []) if not c["passed"]]
    for check in failed:
        print(
            f"skygas: warning: the model fails a quality check ({check['name']}): {check['what']}",
            file=sys.stderr,
        )
    if args.json:
        print_json(brief(data, args.out))
    else:
        for line in lines(data):
            print(line)
        print(f"results in {Path(args.out).resolve()}: model.toml, report.html, summary.json")
    return EXIT_CHECK_FAILED if failed and args.strict else 0


def brief(data: dict, out) -> dict:
    """The JSON summary of a calibration (the numbers of summary.json without arrays)."""
    from skygas.calibration.study import numbers

    iso = data["isolated"]
    out_data = {
        "model": str(Path(out) / "model.toml"),
        "report": str(Path(out) / "report.html"),
        **{k: v for k, v in numbers(data).items() if k != "rms_error_max_d_sk"},
        "charge": iso["charge"],
        "thin_wall_dissipation": iso["thin_wall_dissipation"],
        "energy_J": iso["energy"],
        "fits": {k: v.get("coefficients") for k, v in data["fits"].items()},
        "wall_seconds": data["provenance"]["wall_seconds"],
        "stage_spans_s": data["provenance"]["stage_spans_s"],
        "skygas_version": data["skygas_version"],
        "quality_checks": data.get("quality_checks", []),
    }
    validation = data.get("validation", {})
    out_data["validation"] = {
        k: v for k, v in validation.items() if not isinstance(v, list) or k == "path_length_d_sk"
    }
    return out_data


def lines(data: dict) -> list[str]:
    """Readable lines of a calibration's ``summary.json`` data.

    Its quality checks first (one line each, passed or FAILED), then the skyrmion, the laws
    and the validation.
    """
    from skygas.calibration.results import VALIDATION_GOAL

    iso = data["isolated"]
    out = [
        f"{c['name']}: {'passed' if c['passed'] else 'FAILED'}: {c['what']}"
        for c in data.get("quality_checks", [])
    ]
    out += [
        f"isolated skyrmion: R = {iso['radius'] * 1e9:.2f} nm, Δ = "
        f"{iso['wall_width'] * 1e9:.2f} nm, Q = {iso['charge']:+.4f}, G = "
        f"{iso['gyrocoupling']:.4g} kg/s, 𝒟 = {iso['dissipation']:.3f} (thin-wall "
        f"estimate {iso['thin_wall_dissipation']:.3f})"
    ]
    for key, name in (("pair", "pair law"), ("wall_short_range", "edge law (short range)")):
        lo, hi = data[key]["measured_range_d_sk"]
        line = f"{name}: measured from {lo:.2f} to {hi:.2f} d_sk"
        table = data[key].get("table_distance_m")
        first = table[0] / iso["diameter"] if table else lo
        if first < lo - 1e-9:
            line += f" (tabulated from {first:.2f}, along its tangent)"
        out.append(line)
    v = data.get("validation")
    if v and "rms_error_max_d_sk" in v:
        out.append(
            f"validation: {v['skyrmions']} skyrmions, {v['duration_s'] * 1e9:.2f} ns of "
            f"LLG; RMS centre error max {v['rms_error_max_d_sk']:.3f} d_sk (goal "
            f"{VALIDATION_GOAL:g})"
        )
    elif v:
        out.append(f"validation: {v.get('note', 'none')}")
    return out
