"""Figure and table of the disorder study (docs/landscapes.md): ρ, the largest lagged |ρ|,
mean transit time and maximum chamber occupancy against the disorder's rms, with standard
errors from the replicas, from the stores of the two sweeps

    skygas sweep examples/sweeps/landscape-disorder.toml --out runs/disorder.zarr --workers 1
    skygas sweep examples/sweeps/landscape-depinning.toml --out runs/depinning.zarr --workers 1
    python examples/landscape_study.py runs/disorder.zarr runs/depinning.zarr --out docs/figures

writes ``landscape_disorder.png`` and ``landscape_disorder.json`` (the numbers of the table).
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from skygas.sweep import open_sweep  # noqa: E402

RMS = "potentials_0_rms_kT"
QUANTITIES = {
    "correlation": "ρ (lag 0)",
    "correlation_max_lag": "largest |ρ| over lags",
    "mean_transit_s": "mean transit [ns]",
    "max_occupancy": "max occupancy",
}


def stats(ds, name):
    """Mean and standard error over replicas, per remaining coordinate."""
    values = ds[name]
    n = ds.sizes["replica"]
    return values.mean("replica"), values.std("replica", ddof=1) / math.sqrt(n)


def summary(ds) -> list[dict]:
    rows = []
    currents = (
        ds["current_density"].values
        if "current_density" in ds.dims
        else [float(json.loads(ds.attrs["base_config_json"])["current_density"])]
    )
    for j in currents:
        sub = ds.sel(current_density=j) if "current_density" in ds.dims else ds
        for rms in sub[RMS].values:
            point = sub.sel({RMS: rms})
            row = {
                "current_density_A_m2": float(j),
                "rms_kT": float(rms),
                "replicas": int(ds.sizes["replica"]),
                "duration_s": float(point["simulated_time_s"].values[0]),
            }
            for name in (*QUANTITIES, "n_injected", "n_detected", "n_present", "n_skipped"):
                m, s = stats(point, name)
                row[name] = float(m)
                row[f"{name}_se"] = float(s)
            rows.append(row)
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("stores", nargs="+")
    parser.add_argument("--out", default="docs/figures")
    args = parser.parse_args()
    rows = [r for store in args.stores for r in summary(open_sweep(store))]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "landscape_disorder.json").write_text(json.dumps(rows, indent=1))
    fig, axes = plt.subplots(1, 4, figsize=(15, 3.6))
    for j in sorted({r["current_density_A_m2"] for r in rows}):
        part = [r for r in rows if r["current_density_A_m2"] == j]
        x = [r["rms_kT"] for r in part]
        for ax, (name, label) in zip(axes, QUANTITIES.items(), strict=False):
            scale = 1e9 if name.endswith("_s") else 1.0
            ax.errorbar(
                x,
                [r[name] * scale for r in part],
                yerr=[r[f"{name}_se"] * scale for r in part],
                marker="o",
                capsize=3,
                label=f"J = {j:.2g} A/m²",
            )
            ax.set_xscale("symlog", linthresh=1.0)
            ax.set_xlabel("disorder rms [k_BT] (ξ = 40 nm)")
            ax.set_ylabel(label)
    axes[2].set_yscale("log")
    axes[0].axhline(0, color="grey", lw=0.5)
    axes[0].legend(fontsize=8)
    fig.suptitle(
        "Reshuffler (paper preset, p = 0.62) with a Gaussian random landscape; "
        "error bars: standard errors over replicas",
        fontsize=10,
    )
    fig.tight_layout()
    fig.savefig(out / "landscape_disorder.png", dpi=120)
    for r in rows:
        print(
            f"J = {r['current_density_A_m2']:.2g}  rms {r['rms_kT']:>4g} kT:  "
            f"ρ = {r['correlation']:+.4f} ± {r['correlation_se']:.4f}   "
            f"max-lag |ρ| = {r['correlation_max_lag']:.3f} ± {r['correlation_max_lag_se']:.3f}"
            f"   transit {r['mean_transit_s'] * 1e9:.0f} ± {r['mean_transit_s_se'] * 1e9:.0f} ns"
            f"   max occ. {r['max_occupancy']:.1f} ± {r['max_occupancy_se']:.1f}   "
            f"detected {r['n_detected']:.0f}/{r['n_injected']:.0f}, left "
            f"{r['n_present']:.0f}"
        )


if __name__ == "__main__":
    main()
