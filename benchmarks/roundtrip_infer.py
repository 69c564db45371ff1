"""Round trip of ``skygas infer``: simulate a known gas, write its tracks, infer, compare.

For each (frames, skyrmions) of the table a walled 1.2 µm square of S2 at 300 K with a random
landscape (disorder, rms 1.5 k_BT, correlation length 60 nm), its paper pair and wall laws, and a
3 nm localisation error per coordinate is simulated
(:func:`skygas.inference.synthetic.simulated_tracks`),
then inferred (:func:`skygas.inference.infer`). Printed per row:

- D read: (D of the MSD fit − true)/true, before the crowding correction;
- D: (inferred − true)/true and in standard errors;
- Hall angle: inferred and true [deg];
- landscape: RMS of (inferred − true pinning) over the well-sampled nodes at least 150 nm from
  the walls, relative to the true pinning's rms there (both with their mean removed); and over
  those of them fixed across skyrmions (with their share);
- pair force: the largest relative error of −dV/dr over the range the data fix, the largest
  error in units of the inference's own standard error there, that standard error (median
  over the range, relative), and the largest relative error where that error is at most 10 %;
- wall potential: the largest error of W(d) relative to W at the first sampled distance.

Usage: python benchmarks/roundtrip_infer.py [--frames 1000 4000] [--skyrmions 15 30] [--ibi 6]
"""

from __future__ import annotations

import argparse
import math

import numpy as np
from scipy.integrate import quad
from scipy.interpolate import RegularGridInterpolator

from skygas.core import units
from skygas.inference.pair import ITERATIONS
from skygas.inference.synthetic import simulated_tracks
from skygas.physics.forces import paper_pair_force, paper_wall_force


def row(frames: int, skyrmions: int, ibi: int, seed: int) -> dict:
    gas = simulated_tracks(skyrmions=skyrmions, frames=frames, seed=seed)
    outline = gas.outline
    res = gas.infer(ibi_iterations=ibi, seed=seed)
    s = res.summary
    t = gas.thiele
    d_true = t.diffusion_constant(gas.temperature)
    hall_true = math.atan2(t.gyrocoupling, t.friction)
    # landscape
    g = res.landscape.grid
    truth = RegularGridInterpolator((gas.landscape_y, gas.landscape_x), gas.landscape_kt)
    gx, gy = np.meshgrid(g.x, g.y)
    true_u = truth(np.column_stack([gy.ravel(), gx.ravel()])).reshape(gx.shape)
    from skygas.inference.wall import wall_distance

    far = wall_distance(outline, gx, gy) >= 150e-9
    area = res.landscape.well_sampled & far
    a = res.pinning[area] - np.mean(res.pinning[area])
    b = true_u[area] - np.mean(true_u[area])
    land_rel = float(np.sqrt(np.mean((a - b) ** 2)) / np.std(b)) if area.any() else float("nan")
    fixed = res.landscape.fixed_across_skyrmions & far
    fixed_rel, fixed_share = float("nan"), float(fixed.sum() / max(area.sum(), 1))
    if fixed.sum() > 10:
        a2 = res.pinning[fixed] - np.mean(res.pinning[fixed])
        b2 = true_u[fixed] - np.mean(true_u[fixed])
        fixed_rel = float(np.sqrt(np.mean((a2 - b2) ** 2)) / np.std(b2))
    kt = units.BOLTZMANN * gas.temperature
    d_sk, f0 = t.skyrmion_diameter, t.force_scale
    # pair force over the fixed range
    pair_err, pair_se, pair_rel_se = float("nan"), float("nan"), float("nan")
    pair_tight, pair_tight_range = float("nan"), None
    if res.ibi.coef is not None and res.ibi.fixed_range:
        r = np.linspace(*res.ibi.fixed_range, 20)
        f_inf, f_se = (v * kt for v in res.ibi.force(r))
        f_true = paper_pair_force(r / d_sk, *gas.material.pair_law) * f0
        pair_err = float(np.max(np.abs(f_inf / f_true - 1)))
        pair_se = float(np.max(np.abs(f_inf - f_true) / f_se))
        pair_rel_se = float(np.median(f_se / f_inf))
        tight = f_se <= 0.1 * f_inf
        if tight.any():
            pair_tight = float(np.max(np.abs(f_inf[tight] / f_true[tight] - 1)))
            pair_tight_range = [round(r[tight][0] * 1e9), round(r[tight][-1] * 1e9)]
    wall_err = float("nan")
    w = res.wall
    if w.coef is not None and w.sampled_range:
        from skygas.inference.laws import potential

        d = np.linspace(w.sampled_range[0], w.bulk_from, 20)
        cut = w.bulk_from  # the inference sets W = 0 there; compare W(d) − W(bulk) for both

        def w_true(x):
            return (
                quad(lambda z: paper_wall_force(z / d_sk, gas.material.wall_law) * f0, x, cut)[0]
                / kt
            )

        wt = np.array([w_true(x) for x in d])
        wi = potential(w.coef, d * 1e9) - potential(w.coef, cut * 1e9)
        wall_err = float(np.max(np.abs(wi - wt)) / wt[0])
    return {
        "frames": frames,
        "skyrmions": skyrmions,
        "D_rel": s["diffusion_constant"] / d_true - 1,
        "D_read_rel": s["diffusion_constant_as_read"] / d_true - 1,
        "D_se": (s["diffusion_constant"] - d_true) / s["diffusion_constant_error"],
        "hall_deg": math.degrees(s["hall_angle"]),
        "hall_true_deg": math.degrees(hall_true),
        "landscape_rel_rms": land_rel,
        "landscape_fixed_rel_rms": fixed_rel,
        "landscape_fixed_share": fixed_share,
        "pair_force_max_rel": pair_err,
        "pair_force_max_se": pair_se,
        "pair_force_median_rel_se": pair_rel_se,
        "pair_force_tight_max_rel": pair_tight,
        "pair_force_tight_range_nm": pair_tight_range,
        "pair_range_nm": None
        if not res.ibi.fixed_range
        else [round(v * 1e9) for v in res.ibi.fixed_range],
        "wall_max_rel": wall_err,
        "ibi_chi2": [round(c, 2) for c in res.ibi.chi2],
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--frames", type=int, nargs="+", default=[1000, 4000])
    p.add_argument("--skyrmions", type=int, nargs="+", default=[15, 30])
    p.add_argument(
        "--ibi", type=int, default=ITERATIONS, help="IBI iterations (default: infer's own)"
    )
    p.add_argument("--seed", type=int, default=1)
    args = p.parse_args()
    print(
        "| frames | skyrmions | D read | D − D_true | in SE | Hall angle (true) | landscape RMS "
        "| fixed across skyrmions: share, RMS | pair range | pair force max | in SE | its SE "
        "| where SE ≤ 10 %: range, max | wall max | IBI χ² |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for frames in args.frames:
        for n in args.skyrmions:
            r = row(frames, n, args.ibi, args.seed)
            print(
                f"| {frames} | {n} | {100 * r['D_read_rel']:+.1f} % | {100 * r['D_rel']:+.1f} % | "
                f"{r['D_se']:+.1f} | "
                f"{r['hall_deg']:.1f}° ({r['hall_true_deg']:.1f}°) | "
                f"{100 * r['landscape_rel_rms']:.0f} % | "
                f"{100 * r['landscape_fixed_share']:.0f} %, "
                f"{100 * r['landscape_fixed_rel_rms']:.0f} % | "
                f"{r['pair_range_nm']} nm | "
                f"{100 * r['pair_force_max_rel']:.0f} % | {r['pair_force_max_se']:.1f} | "
                f"{100 * r['pair_force_median_rel_se']:.0f} % | "
                f"{r['pair_force_tight_range_nm']} nm, "
                f"{100 * r['pair_force_tight_max_rel']:.0f} % | "
                f"{100 * r['wall_max_rel']:.0f} % | {r['ibi_chi2']} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
