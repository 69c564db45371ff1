"""Calibration of the `paper-figures` preset from its calibration sweeps.

    python examples/paper-figures/calibration.py runs/calibration-high.zarr \
        runs/calibration-s100.zarr --out docs/figures

For each dynamics time scale s (and time step) in the stores: ρ at J = 3.8×10¹¹ A/m² against ξ
(replica mean ± standard error), ξ(s) where ρ crosses the paper's 0.64 (linear interpolation between
the two
bracketing points; its uncertainty from ρ's standard errors through the local slope), and the
low-current statements (ρ, fullest chamber, p_out against its 95 % interval) at 10¹⁰ A/m².
Writes ``calibration.json`` and ``calibration.png`` (left: ρ(ξ) per s; right: the running ρ of
each run at J = 3.8×10¹¹, which shows the ballistic state and its collapse).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from skygas.reshuffler.config import parse_reshuffler_config
from skygas.sweep import open_sweep
from skygas.sweep.analysis import point_table

TARGET, HIGH, LOW = 0.64, 3.8e11, 1e10
S_KEY, XI_KEY, J_KEY = "hypothesis_dynamics_time_scale", "spin_drift_coefficient", "current_density"


def base_config(ds):
    """The store's ``[base]`` configuration, resolved (preset applied)."""
    return parse_reshuffler_config(json.loads(ds.attrs["base_config_json"]))


def rows_of(stores: list[str]) -> list[dict]:
    rows = []
    for store in stores:
        ds = open_sweep(store)
        base = base_config(ds)  # the values of the fields not swept
        for row in point_table(ds):
            row.setdefault(S_KEY, base.hypothesis.dynamics_time_scale)
            row.setdefault(J_KEY, base.current_density)
            row["store"] = store
            rows.append(row)
    return rows


def crossing(xi: np.ndarray, rho: np.ndarray, sem: np.ndarray) -> dict:
    """ξ where ρ(ξ) first crosses TARGET upwards, with the error ρ's s.e. gives it."""
    if len(xi) == 0:
        return {"xi": float("nan"), "note": "no run at 3.8e11 A/m^2"}
    order = np.argsort(xi)
    xi, rho, sem = xi[order], rho[order], sem[order]
    for i in range(len(xi) - 1):
        if rho[i] < TARGET <= rho[i + 1]:
            slope = (rho[i + 1] - rho[i]) / (xi[i + 1] - xi[i])
            value = xi[i] + (TARGET - rho[i]) / slope
            error = float(np.hypot(sem[i], sem[i + 1]) / slope)
            return {"xi": float(value), "xi_error": error, "bracket": [xi[i], xi[i + 1]]}
    return {
        "xi": float("nan"),
        "note": "rho does not cross 0.64 in the scanned xi",
        "rho_range": [float(np.nanmin(rho)), float(np.nanmax(rho))],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("stores", nargs="+")
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    rows = rows_of(args.stores)
    result = {"target_rho": TARGET, "per_s": {}}
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11, 4.2), dpi=110)
    left, right = fig.subplots(1, 2)
    for s, dt in sorted({(r[S_KEY], r["time_step_s"]) for r in rows}):
        high = [r for r in rows if (r[S_KEY], r["time_step_s"]) == (s, dt) and r[J_KEY] == HIGH]
        low = [r for r in rows if (r[S_KEY], r["time_step_s"]) == (s, dt) and r[J_KEY] == LOW]
        xi = np.array([r[XI_KEY] for r in high])
        rho = np.array([r["rho"] for r in high])
        sem = np.array([r["rho_sem"] for r in high])
        entry = {
            "high_current": [
                {
                    k: r[k]
                    for k in (
                        XI_KEY,
                        "rho",
                        "rho_sem",
                        "correlation_max_lag",
                        "max_occupancy",
                        "mean_transit_s",
                    )
                }
                for r in high
            ],
            "crossing": crossing(xi, rho, sem),
            "low_current": [
                {
                    k: r[k]
                    for k in (
                        XI_KEY,
                        "rho",
                        "rho_sem",
                        "max_occupancy",
                        "p_in",
                        "p_out",
                        "p_out_worst_z",
                        "mean_transit_s",
                    )
                }
                for r in low
            ],
        }
        result["per_s"][f"s={s:g}, dt={dt * 1e12:.3g} ps"] = entry
        if not high:
            continue
        order = np.argsort(xi)
        left.errorbar(
            xi[order],
            rho[order],
            yerr=np.nan_to_num(sem[order]),
            fmt="o-",
            capsize=2,
            label=f"s = {s:g}, step {dt * 1e12:.3g} ps",
        )
    left.axhline(TARGET, color="k", ls=":", label="paper: 0.64")
    left.set_xscale("log")
    ticks = [1.5e-9, 3e-9, 6e-9, 1.2e-8]
    left.set_xticks(ticks, labels=[f"{t:.2g}" for t in ticks])
    left.minorticks_off()
    left.set_xlabel("spin-drift coefficient ξ (m³/C)")
    left.set_ylabel("ρ at J = 3.8×10¹¹ A/m²")
    left.legend(fontsize=8)
    colours, labelled = {}, set()
    for store in args.stores:
        ds = open_sweep(store)
        if "point" not in ds.dims:
            continue
        for i in range(ds.sizes["point"]):
            pt = ds.isel(point=i)
            j = float(pt[J_KEY]) if J_KEY in pt else base_config(ds).current_density
            if j != HIGH:
                continue
            s = float(pt[S_KEY]) if S_KEY in pt else base_config(ds).hypothesis.dynamics_time_scale
            xi = float(pt[XI_KEY])
            for r in range(ds.sizes["replica"]):
                t = pt["running_time"].isel(replica=r).values
                y = pt["running_rho"].isel(replica=r).values
                ok = np.isfinite(t) & np.isfinite(y)
                colour = colours.setdefault(s, f"C{len(colours)}")
                right.plot(
                    t[ok] * 1e6,
                    y[ok],
                    lw=0.7,
                    color=colour,
                    alpha=0.8,
                    label=None if s in labelled else f"s = {s:g} (each run, all ξ)",
                )
                labelled.add(s)
    right.set_xlabel("time (µs)")
    right.set_ylabel("running ρ at J = 3.8×10¹¹ A/m²")
    if right.get_legend_handles_labels()[0]:
        right.legend(fontsize=7)
    fig.tight_layout()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    fig.savefig(out / "calibration.png")
    (out / "calibration.json").write_text(json.dumps(result, indent=2))
    print(json.dumps({s: e["crossing"] for s, e in result["per_s"].items()}, indent=1))


if __name__ == "__main__":
    main()
