"""``skygas analyze RUN [--json]``: the standard observables of a run (:mod:`skygas.analysis`).

MSD and the diffusion constants it supports, g(r), velocity and Hall angle, occupancy, density
and velocity maps; an observable the run cannot support is absent, with the reason.
"""

from __future__ import annotations

import math

from skygas.commands.json_output import add_json_option, print_json


def _pm(value, error, scale=1.0) -> str:
    if value is None or not math.isfinite(value):
        return "n/a"
    return (
        f"{value * scale:.4g} ± {error * scale:.2g}"
        if error is not None and math.isfinite(error)
        else f"{value * scale:.4g}"
    )


def _analyze(args) -> int:
    from skygas.outputs.records import find_result_file

    find_result_file(args.run)
    from skygas.analysis import analyze
    from skygas.outputs.records import load_run

    result = analyze(load_run(args.run), maps=not args.no_maps, burn_in=args.burn_in)
    if args.json:
        print_json(result)
        return 0
    print(f"{result['kind']} run, {result['frames']} frames, {result['entries']} positions")
    diffusion = result.get("diffusion")
    if diffusion:
        free = result.get("free_diffusion_constant_m2_s")
        for key, label in (("short_time", "short-time D₀"), ("long_time", "long-time D_eff")):
            value = diffusion.get(f"{key}_diffusion_m2_s")
            if value is not None:
                error = diffusion[f"{key}_diffusion_error_m2_s"]
                print(f"  {label} = {_pm(value, error)} m²/s")
            else:
                print(f"  {label}: none ({diffusion.get(f'{key}_reason')})")
        if free:
            print(f"  free skyrmion of the material: D₀ = {free:.4g} m²/s")
    v = result.get("velocity")
    if v:
        print(
            f"  mean velocity = ({_pm(v['velocity_m_s'][0], v['velocity_error_m_s'][0])}, "
            f"{_pm(v['velocity_m_s'][1], v['velocity_error_m_s'][1])}) m/s"
        )
        if "hall_angle_rad" in v:
            angle = _pm(v["hall_angle_rad"], v["hall_angle_error_rad"], 180 / math.pi)
            print(f"  Hall angle = {angle}° (skyrmions away from the walls)")
        elif v.get("hall_angle_reason"):
            print(f"  Hall angle: none ({v['hall_angle_reason']})")
    occ = result["occupancy"]
    print(f"  skyrmions present: mean {occ['mean_total']:.3g}, largest {occ['max_total']}")
    g = result.get("pair_correlation")
    if g:
        k = max(range(len(g["g"])), key=lambda i: g["g"][i] if math.isfinite(g["g"][i]) else -1)
        print(f"  g(r): first peak {g['g'][k]:.3g} at r = {g['r_m'][k] * 1e9:.0f} nm")
    print("  (--json prints every number, with the maps and curves)")
    return 0


def register(subparsers) -> None:
    """Add ``skygas analyze`` to ``subparsers``."""
    p = subparsers.add_parser("analyze", help="standard observables of a run (MSD, g(r), ...)")
    p.add_argument("run", help="run directory or result file")
    add_json_option(p, "every observable, with the maps and curves,")
    p.add_argument("--no-maps", action="store_true", help="leave out the density and velocity maps")
    p.add_argument(
        "--burn-in",
        type=float,
        default=0.0,
        metavar="S",
        help="time dropped at the start of the record before the MSD [s]",
    )
    p.set_defaults(func=_analyze)
