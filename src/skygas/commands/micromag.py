"""``skygas micromag``: inspect a magnetisation file, fit force laws from snapshots.

Each sub-command is one call into :mod:`skygas.micromag`, imported when the sub-command runs
(building the command line, for every ``skygas`` call, then imports no numerics).
"""

from __future__ import annotations

import argparse

from skygas.commands.json_output import add_json_option, print_json


def register(subparsers) -> None:
    """Add ``skygas micromag`` and its sub-commands to ``subparsers``."""
    group = subparsers.add_parser(
        "micromag",
        help="micromagnetic snapshots → skyrmions, G, 𝒟, force laws",
        description="Bridge from OOMMF/mumax3 OVF files to the particle model.",
    )
    commands = group.add_subparsers(dest="micromag_command", metavar="SUBCOMMAND", required=True)

    inspect = commands.add_parser(
        "inspect",
        help="per-skyrmion charge, centre, radius and 𝒟 of one file",
        description="Detect the skyrmions of one OVF (or .npy) file.",
    )
    inspect.add_argument("file", help="OVF 1.0/2.0 file (text, binary 4/8) or .npy array")
    add_json_option(inspect, "the skyrmions found")
    inspect.add_argument(
        "--cell-size", type=float, default=None, help="cell size [m], needed for .npy input only"
    )
    inspect.add_argument(
        "--threshold", type=float, default=0.0, help="a core is where s·m_z < THRESHOLD (default 0)"
    )
    _add_edge_band_option(inspect)
    inspect.set_defaults(func=_inspect)

    fit = commands.add_parser(
        "fit",
        help="fit the pair and/or wall law from a directory of snapshots",
        description="Detect and track skyrmions in OVF snapshots, extract F = Ĝ·ẋ, fit the "
        "paper's laws and write summary.json, tracks.csv, forces.csv, the laws tabulated over the "
        "measured range (pair_table.csv, wall_table.csv), fit.png and, when the data fix "
        "every law asked for, material.toml.",
    )
    fit.add_argument("snapshot_dir", help="directory of OVF snapshots (e.g. mumax3 m*.ovf)")
    fit.add_argument("--out", required=True, help="output directory")
    fit.add_argument("--pattern", default="*.ovf", help="file glob (default *.ovf)")
    fit.add_argument(
        "--material", default="S2", help="preset or TOML file giving M_s, A_ex, α (default S2)"
    )
    fit.add_argument("--film-thickness", type=float, default=2e-9, help="t_F [m] (default 2e-9)")
    fit.add_argument("--damping", type=float, default=None, help="α (default: the material's)")
    fit.add_argument(
        "--law",
        choices=["auto", "pair", "wall", "both"],
        default="auto",
        help="which law to fit (auto: pair if two skyrmions coexist, else wall)",
    )
    fit.add_argument(
        "--interval",
        type=float,
        default=None,
        help="snapshot interval [s] (default: each file's simulation time)",
    )
    fit.add_argument(
        "--skyrmion-diameter",
        type=float,
        default=None,
        help="length unit d_sk of the laws [m] (default: measured)",
    )
    fit.add_argument(
        "--force-scale", type=float, default=None, help="F0 [N] (default A_ex t_F / d_sk)"
    )
    fit.add_argument(
        "--window",
        type=int,
        default=9,
        help="Savitzky–Golay window for velocities, odd (default 9)",
    )
    fit.add_argument("--wall-degree", type=int, default=5, help="wall polynomial degree")
    fit.add_argument(
        "--max-step",
        type=float,
        default=None,
        help="largest displacement between snapshots [m] (default: one radius)",
    )
    fit.add_argument(
        "--table-bins",
        type=int,
        default=None,
        help="bins of the tabulated law (default: √(samples), at most 20)",
    )
    fit.add_argument(
        "--strict",
        action="store_true",
        help="stop (exit 2, nothing written) when the data do not fix a law "
        "outside their range, instead of writing the tracks, the forces and the "
        "tabulated law without material.toml",
    )
    _add_edge_band_option(fit)
    fit.add_argument("--no-report", action="store_true", help="do not write OUT/report.html")
    add_json_option(fit, "the fits (what summary.json holds)")
    fit.set_defaults(func=_fit)

    samples = commands.add_parser(
        "samples",
        help="print where the sample OVF files are and how to try them",
        description="The synthetic OVF samples shipped with skygas, for inspect and fit.",
    )
    samples.add_argument(
        "--path",
        action="store_true",
        help="print only the samples' folder, for a shell variable: "
        "SAMPLES=$(skygas micromag samples --path)",
    )
    samples.set_defaults(func=_samples)


def _samples(args: argparse.Namespace) -> int:
    from skygas.micromag.samples import folder, usage

    print(folder() if args.path else usage())
    return 0


def _add_edge_band_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--edge-band",
        choices=["exclude", "keep"],
        default="exclude",
        help="the film edge's tilted band: left out of every skyrmion (default: a curved rim's "
        "own charge stays out) or kept (each centre is then the guiding centre of all the charge "
        "near its skyrmion, the coordinate `skygas calibrate` holds and reads its runs in)",
    )


def _inspect(args: argparse.Namespace) -> int:
    from skygas.micromag.detection import inspect_field
    from skygas.micromag.ovf import load_field

    report = inspect_field(
        load_field(args.file, cell_size=args.cell_size),
        threshold=args.threshold,
        edge_band=args.edge_band == "exclude",
    )
    if args.json:
        print_json(report)
        return 0
    print(
        f"{args.file}: {len(report['skyrmions'])} skyrmion(s), total Q = "
        f"{report['total_charge']:+.4f}"
    )
    for i, s in enumerate(report["skyrmions"]):
        print(
            f"  #{i}: Q = {s['charge']:+.4f}  centre = ({s['x_m'] * 1e9:.3f}, "
            f"{s['y_m'] * 1e9:.3f}) nm  R = {s['radius_m'] * 1e9:.3f} nm  "
            f"𝒟 = {s['dissipation']:.3f}"
        )
    return 0


def _fit(args: argparse.Namespace) -> int:
    from skygas.micromag.workflow import fit_snapshots

    result = fit_snapshots(
        args.snapshot_dir,
        args.out,
        pattern=args.pattern,
        interval=args.interval,
        max_step=args.max_step,
        material=args.material,
        film_thickness=args.film_thickness,
        damping=args.damping,
        law=args.law,
        skyrmion_diameter=args.skyrmion_diameter,
        force_scale=args.force_scale,
        window=args.window,
        wall_degree=args.wall_degree,
        table_bins=args.table_bins,
        strict=args.strict,
        edge_band=args.edge_band == "exclude",
    )
    if not args.no_report:  # beside the results, whatever is printed
        from pathlib import Path

        from skygas.outputs.report import write_report

        write_report(args.out, Path(args.out) / "report.html")
    if args.json:
        print_json(result.as_record())
        return 0
    lengths = sorted((len(t) for t in result.tracks), reverse=True)
    print(
        f"{len(lengths)} track(s) of {', '.join(map(str, lengths))} frames "
        f"({result.parameters['n_snapshots']} snapshots): tracks.csv"
    )
    for fit in (result.pair, result.wall):
        if fit is not None:
            print(
                f"{fit.law} law ({fit.n_points} samples, d = {fit.distance_range[0]:.2f}"
                f"–{fit.distance_range[1]:.2f} d_sk): {fit.describe()}"
            )
    for law, table in result.tables.items():
        lo, hi = table.distance_range
        first, last = table.force[0], table.force[-1]
        print(
            f"{law} law tabulated ({int(table.count.sum())} samples in {table.count.size} "
            f"bins, d = {lo:.2f}–{hi:.2f} d_sk): |F| = {first * 1e12:.3g} pN at "
            f"{table.distance[0]:.2f} d_sk … {last * 1e12:.3g} pN at "
            f"{table.distance[-1]:.2f} d_sk: {law}_table.csv"
        )
    for warning in result.warnings:
        print(f"warning: {warning}")
    print(f"results in {args.out}")
    return 0
