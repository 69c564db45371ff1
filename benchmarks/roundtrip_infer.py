"""``skygas infer`` on gases it did not make: the validation table of docs/inference.md.

Each case is simulated by a generator that shares nothing with skygas's engine: the plain NumPy
Euler–Maruyama simulator of ``tests/inference/independent_gas.py`` (its own laws: Gaussian
wells, a K₁ or the paper's S2 pair law, exponential walls, a drive; walled, periodic, or seen
through a field of view), or, with ``--peer DIR``, tracks written by an external particle code
(a folder per case with ``tracks.csv`` and ``truth.json``, see docs/inference.md). The tracks go
through :func:`skygas.inference.infer` as a user's would, and the inferred model is compared
with the truth:

- D: (inferred − true)/true, and in units of its own standard error;
- Hall angle: inferred ± error against the truth [°] (``none`` where the data cannot fix it);
- landscape: the share of the film well sampled, the RMS of (inferred − true) over it (both
  with their mean over it removed) [k_BT], and the pinning strength (rms of U over it)
  inferred / true, ± its jackknife error; for a flat truth, whether the model has a landscape;
- pair and wall: whether the model has the term, and over the range infer reports the force
  as fixed (``fixed_range_m``), the largest |F/F_true − 1|; for the wall also the
  potential W at the closest distance against the truth, in units of its error;
- self-check: passed, or what failed;
- the inference's wall time.

Usage::

    python benchmarks/roundtrip_infer.py                      # every generated case
    python benchmarks/roundtrip_infer.py --cases exp_pins_walls nano_s2
    python benchmarks/roundtrip_infer.py --peer /path/to/peer-data   # add the external code's
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "inference"))

import independent_gas as ig  # noqa: E402

W = 30e-6
EXPERIMENT = dict(
    skyrmions=60,
    frames=4000,
    frame_interval=10e-3,
    substeps=3,
    width=W,
    height=W,
    diffusion=0.31e-12,
    hall_angle=math.radians(60.0),
    localisation_error=20e-9,
    pixel_size=100e-9,
)
#: Gaussian wells of 3 k_BT and 1.5 µm, centres also beyond the film (homogeneous pinning)
WELLS = ig.random_wells(40, W, W, 3.0, 1.5e-6, seed=3, margin=-4.5e-6)
K1 = ("k1", 17.6e6, 1e-6)
S2_FORCE = 1.44e-12 / (ig.BOLTZMANN * 300.0)  # the paper's F₀ for S2, in k_BT/m
S2 = dict(
    skyrmions=30,
    frames=4000,
    frame_interval=1e-9,
    substeps=10,
    width=1.2e-6,
    height=1.2e-6,
    diffusion=4.38e-9,
    hall_angle=math.radians(77.0),
    localisation_error=2e-9,
    pixel_size=5e-9,
)

CASES = {
    "exp_free_fov": ig.GasSpec(
        **{**EXPERIMENT, "width": 60e-6, "height": 60e-6, "skyrmions": 120},
        boundary="periodic",
        field_of_view=(15e-6, 15e-6, 45e-6, 45e-6),
    ),
    "exp_pins_walls": ig.GasSpec(**EXPERIMENT, boundary="walls", wells=WELLS, wall=(5.0, 1.0e-6)),
    "exp_pair_walls": ig.GasSpec(
        **EXPERIMENT, boundary="walls", pair=K1, pair_cutoff=8e-6, wall=(5.0, 1.0e-6)
    ),
    "exp_pins_pair_periodic": ig.GasSpec(
        **EXPERIMENT, boundary="periodic", wells=WELLS, pair=K1, pair_cutoff=8e-6
    ),
    "exp_pins_pair_fov": ig.GasSpec(
        **{**EXPERIMENT, "width": 45e-6, "height": 45e-6, "skyrmions": 135},
        boundary="periodic",
        wells=ig.random_wells(68, 45e-6, 45e-6, 3.0, 1.5e-6, seed=4),
        pair=K1,
        pair_cutoff=8e-6,
        field_of_view=(7.5e-6, 7.5e-6, 37.5e-6, 37.5e-6),
    ),
    "exp_pins_drive": ig.GasSpec(
        **EXPERIMENT, boundary="periodic", wells=WELLS, drive=(0.8e6, 0.3e6)
    ),
    "exp_no_magnus": ig.GasSpec(
        **{**EXPERIMENT, "hall_angle": 0.0},
        boundary="periodic",
        wells=WELLS,
        pair=K1,
        pair_cutoff=8e-6,
    ),
    "exp_no_localisation_error": ig.GasSpec(
        **{**EXPERIMENT, "localisation_error": 0.0},
        boundary="periodic",
        wells=WELLS,
        pair=K1,
        pair_cutoff=8e-6,
    ),
    "nano_s2": ig.GasSpec(
        **S2,
        boundary="walls",
        wells=ig.random_wells(400, 1.2e-6, 1.2e-6, 1.5, 30e-9, seed=5, margin=-90e-9),
        pair=("s2", S2_FORCE, 38.2e-9),
        pair_cutoff=300e-9,
        wall=(8.0, 20e-9),
    ),
}


def _outline(spec: ig.GasSpec):
    from skygas.physics.geometry import rectangle

    if spec.boundary != "walls":
        return None
    return rectangle(spec.width, spec.height, center=(spec.width / 2, spec.height / 2))


def peer_spec(folder: Path) -> tuple[ig.GasSpec, dict]:
    """The truth of an external code's case as a spec (SI: λ = 100 nm, 1 time unit = 1 µs)."""
    truth = json.loads((folder / "truth.json").read_text())
    lam = 100e-9
    t0 = 1e-6
    pins = truth.get("pins") or {}
    wells = np.zeros((0, 4))
    if pins.get("n"):
        n = pins["n"]
        wells = np.column_stack(
            [
                np.asarray(pins["x_lambda"]) * lam,
                np.asarray(pins["y_lambda"]) * lam,
                np.full(n, pins["depth_kBT"]),
                np.full(n, pins["R0_lambda"] * lam / math.sqrt(2)),  # exp(−r²/R0²) = e^(−r²/2s²)
            ]
        )
    pair = None
    if (truth.get("pair") or {}).get("on"):
        pair = ("k1", truth["pair"]["U0_kBT_per_lambda"] / lam, lam)
    side = truth["box"]["L_lambda"] * lam
    spec = ig.GasSpec(
        skyrmions=truth["N"],
        frames=truth["frames"],
        frame_interval=truth["frame_interval_time_units"] * t0,
        width=side,
        height=side,
        boundary="periodic",
        diffusion=truth["D_free_lambda2_per_time"] * lam**2 / t0,
        hall_angle=math.radians(truth["hall_angle"]["theta_H_deg"]),
        wells=wells,
        pair=pair,
        pair_cutoff=6.0513 * lam,
        pixel_size=lam / truth["px_per_lambda"],
    )
    return spec, truth


def _jackknife(values) -> float:
    """The jackknife error of leave-one-out replicas."""
    from skygas.inference.forces import jackknife_error

    return float(jackknife_error(np.asarray(values, float)))


def compare(spec: ig.GasSpec, summary: dict, result) -> dict:
    """The table's numbers for one case."""
    s = summary
    out: dict = {}
    d = s["diffusion_constant"]
    in_se = (d - spec.diffusion) / s["diffusion_constant_error"]
    out["D"] = f"{100 * (d / spec.diffusion - 1):+.1f} % ({in_se:+.1f} SE)"
    if not s["diffusion_constant_fixed_by_data"]:
        out["D"] = f"none: frames too coarse (as read {out['D']})"
    if s["hall_angle"] is None:
        out["Hall angle"] = f"none ({math.degrees(spec.hall_angle):.1f}°)"
    else:
        out["Hall angle"] = (
            f"{math.degrees(s['hall_angle']):.1f} ± {math.degrees(s['hall_angle_error']):.1f}° "
            f"({math.degrees(spec.hall_angle):.1f}°)"
        )
    fmap = result.map
    gx, gy = np.meshgrid(fmap.grid.x, fmap.grid.y)
    offset = spec.field_of_view[:2] if spec.field_of_view is not None else (0.0, 0.0)
    true_u = ig.landscape(spec, gx + offset[0], gy + offset[1])
    flat = len(spec.wells) == 0
    terms = s["model_selection"]["terms"]
    area = fmap.well_sampled
    if flat:
        out["landscape"] = (
            "none (flat: right)" if "landscape" not in terms else "kept (flat: wrong)"
        )
    else:
        # judged over the well-sampled area, or over the sampled one where nothing is well
        # sampled (the map's errors are then relative to the sampled area's mean)
        well = area.sum() >= 4
        judged = area if well else fmap.sampled
        scale = s["model"]["landscape_scale"]
        a = scale * (fmap.u[judged] - fmap.u[judged].mean())
        b = true_u[judged] - true_u[judged].mean()
        rms = np.sqrt(np.mean((a - b) ** 2))
        in_errors = np.sqrt(np.mean(((a - b) / (scale * fmap.error[judged])) ** 2))
        # the strength's error: the larger jackknife of the rms over the area (maps.statistics)
        strength_err = (
            max(
                _jackknife([np.std(r[judged] - r[judged].mean()) for r in reps])
                for reps in fmap.replicas
            )
            * scale
            / np.std(b)
        )
        numbers = (
            f"RMS {rms:.2f} k_BT ({in_errors:.1f} of its errors), "
            f"strength {np.std(a) / np.std(b):.2f} ± {strength_err:.2f}"
        )
        share = 100 * area.mean() / max(fmap.film.mean(), 1e-12)
        out["landscape"] = (
            f"{share:.0f} % well sampled, {numbers}"
            if well
            else f"0 % well sampled (sampled: {numbers})"
        )
    kt = ig.BOLTZMANN * spec.temperature
    for term, truth_f, has in (
        ("pair", lambda r: ig.pair_force(spec, r), spec.pair is not None),
        (
            "wall",
            lambda d: ig.wall_potential(spec, d) / spec.wall[1] if spec.wall else 0 * d,
            spec.wall is not None and spec.boundary == "walls",
        ),
    ):
        fitted = s[term]["fitted"]
        kept = term in terms
        if not kept:
            out[term] = "none (right)" if not has else "none (wrong)"
            continue
        if not has:
            out[term] = "kept (wrong)"
            continue
        r = np.array(fitted["r_m"])
        f = np.array(fitted["force_N"]) / kt
        # judged where infer reports the force as fixed (none where the frames are too coarse)
        span = fitted["fixed_range_m"]
        fixed = np.zeros(len(r), bool) if span is None else (r >= span[0]) & (r <= span[1])
        text = "kept, fixed nowhere"
        if fixed.any():
            ratio = f[fixed] / truth_f(r[fixed])
            text = (
                f"kept, {r[fixed][0] * 1e9:.0f}–{r[fixed][-1] * 1e9:.0f} nm fixed, "
                f"max error {100 * np.max(np.abs(ratio - 1)):.0f} %"
            )
        if term == "wall":
            # W(d) at the closest distance: the truth relative to the wall law's end
            w = fitted["potential_kT"][0]
            w_err = fitted["potential_error_kT"][0]
            assert spec.wall is not None
            true_w = ig.wall_potential(spec, r[0]) - ig.wall_potential(
                spec, fitted["basis"]["farthest_m"]
            )
            text += f"; W({r[0] * 1e9:.0f} nm) {w:.2f} ± {w_err:.2f} k_BT ({true_w:.2f})"
        out[term] = text
    check = s["consistency_check"]
    out["self-check"] = (
        "-"
        if check is None
        else "passed"
        if check["passed"]
        else "failed: " + ", ".join(check["failed"])
    )
    return out


def run_case(name: str, spec: ig.GasSpec, tracks=None, skyrmion_radius=None) -> dict:
    from skygas.inference import infer

    if tracks is None:
        t0 = time.perf_counter()
        gas = ig.simulate(spec)
        tracks = gas.tracks
        print(f"[{name}] simulated in {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    start = time.perf_counter()
    result = infer(
        tracks,
        pixel_size=spec.pixel_size,
        frame_interval=spec.frame_interval,
        temperature=spec.temperature,
        outline=_outline(spec),
        skyrmion_radius=skyrmion_radius,
        progress=lambda line: print(
            f"[{name} {time.perf_counter() - start:6.1f} s] {line}", file=sys.stderr
        ),
    )
    row = {"case": name, **compare(spec, result.summary, result)}
    row["time"] = f"{time.perf_counter() - start:.0f} s"
    return row


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cases", nargs="*", default=list(CASES), help=f"of {list(CASES)}")
    p.add_argument(
        "--peer", type=Path, default=None, help="a folder of cases/tracks.csv+truth.json"
    )
    p.add_argument("--jsonl", type=Path, default=None, help="append each row here as JSON")
    args = p.parse_args()
    rows = []
    todo = [(name, CASES[name], None, None) for name in args.cases]
    if args.peer is not None:
        import pandas as pd

        for folder in sorted(d for d in args.peer.iterdir() if (d / "truth.json").is_file()):
            spec, _ = peer_spec(folder)
            todo.append((f"peer_{folder.name}", spec, pd.read_csv(folder / "tracks.csv"), None))
    for name, spec, tracks, radius in todo:
        row = run_case(name, spec, tracks, radius)
        rows.append(row)
        print(json.dumps(row), flush=True)
        if args.jsonl is not None:
            with args.jsonl.open("a") as fh:
                fh.write(json.dumps(row) + "\n")
    keys = list(rows[0])
    print("| " + " | ".join(keys) + " |")
    print("|" + "---|" * len(keys))
    for row in rows:
        print("| " + " | ".join(str(row[k]) for k in keys) + " |")


if __name__ == "__main__":
    main()
