"""Figures of the reservoir.

Occupation map per input, accuracies, accuracy against a swept parameter (matplotlib, Agg backend).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Circle

from skygas.runs.plotting import draw_outline


def plot_occupation(device, streams, path: Path) -> Path:
    """Where the skyrmion centres were while each input symbol was held.

    The fraction of the frames per bin, on a log colour scale, with the contacts, their
    voltages and the sensors.
    """
    from matplotlib.colors import LogNorm

    symbols = device.drive.symbols
    occupation = sum(s.occupation for s in streams)
    x0, x1, y0, y1 = streams[0].map_extent
    fig = Figure(figsize=(3.2 * len(symbols), 3.4), dpi=110)
    for k, symbol in enumerate(symbols):
        ax = fig.add_subplot(1, len(symbols), k + 1)
        frac = occupation[k] / max(occupation[k].sum(), 1)
        positive = frac[frac > 0]
        norm = (
            LogNorm(vmin=max(positive.min(), positive.max() * 1e-3), vmax=positive.max())
            if positive.size
            else None
        )
        ax.imshow(
            np.where(frac > 0, frac, np.nan),
            origin="lower",
            cmap="magma_r",
            norm=norm,
            extent=(x0 * 1e-3, x1 * 1e-3, y0 * 1e-3, y1 * 1e-3),
        )
        draw_outline(ax, device.outline)
        for cx, cy in device.sensor_centers:
            ax.add_patch(
                Circle(
                    (cx * 1e6, cy * 1e6),
                    device.config.sensors.radius * 1e6,
                    fill=False,
                    ls="--",
                    lw=0.7,
                    color="tab:blue",
                )
            )
        volts = device.drive.potentials(symbol)
        ax.set_title(
            f"(a, b) = {symbol}: " + ", ".join(f"{n} {v * 1e6:+.0f} µV" for n, v in volts.items()),
            fontsize=7,
        )
        ax.tick_params(labelsize=6)
    fig.tight_layout()
    fig.savefig(path)
    return path


def plot_accuracies(summary: dict, path: Path) -> Path:
    """Test accuracy of the 16 Boolean read-outs and of the temporal tasks.

    The chance level is marked; the temporal tasks are the recall against delay and the
    parity of the last two inputs.
    """
    t = summary["temporal"]
    fig = Figure(figsize=(10 if t else 5.5, 3.8), dpi=110)
    ax = fig.add_subplot(1, 2 if t else 1, 1)
    names = list(summary["boolean"])
    acc = [summary["boolean"][n]["accuracy"] for n in names]
    chance = [summary["boolean"][n]["chance"] for n in names]
    xs = np.arange(len(names))
    ax.bar(xs, acc, color=["tab:red"] + ["tab:blue"] * (len(names) - 1))
    ax.scatter(xs, chance, marker="_", color="k", s=120, label="chance (majority class)")
    ax.set_xticks(xs, names, rotation=70, fontsize=6)
    ax.set_ylim(0, 1.05)
    ax.set_ylabel("test accuracy")
    ax.legend(fontsize=7, loc="lower right")
    ax.set_title(
        f"Boolean functions of two inputs, hold {summary['hold_time_s'] * 1e6:g} µs", fontsize=8
    )
    if not t:
        fig.tight_layout()
        fig.savefig(path)
        return path
    ax2 = fig.add_subplot(1, 2, 2)
    delays = [int(k) for k in t["recall"]]
    ax2.plot(
        delays,
        [t["recall"][str(k)]["accuracy"] for k in delays],
        "o-",
        label="recall of input a, k steps back",
    )
    ax2.plot(delays, [t["recall"][str(k)]["chance"] for k in delays], "k--", lw=0.8, label="chance")
    ax2.axhline(
        t["parity_last_two"]["accuracy"],
        color="tab:green",
        lw=1,
        label="parity of the last two inputs",
    )
    ax2.set_xlabel("delay k (inputs)")
    ax2.set_ylabel("test accuracy")
    ax2.set_ylim(0.3, 1.05)
    ax2.legend(fontsize=7)
    ax2.set_title("fading memory", fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    return path


def plot_sweep(sweep: dict, path: Path) -> Path:
    """XOR and mean Boolean accuracy against the swept parameter (mean ± std of replicas)."""
    fig = Figure(figsize=(5, 3.5), dpi=110)
    ax = fig.add_subplot()
    v = [r["value"] for r in sweep["rows"]]
    ax.errorbar(
        v,
        [r["xor_mean"] for r in sweep["rows"]],
        yerr=[r["xor_std"] for r in sweep["rows"]],
        marker="o",
        capsize=3,
        label="XOR",
    )
    ax.plot(
        v, [r["mean_accuracy_mean"] for r in sweep["rows"]], "s--", label="mean of the 16 functions"
    )
    ax.axhline(0.5, color="k", lw=0.6, ls=":")
    units = {
        "hold_time": "hold time (s)",
        "temperature": "temperature (K)",
        "n_skyrmions": "number of skyrmions",
        "current_density": "current density (A/m²)",
        "pinning_depth_kT": "depth of the pinning wells (k_BT)",
    }
    ax.set_xlabel(units.get(sweep["parameter"], sweep["parameter"]))
    ax.set_ylabel("test accuracy")
    if sweep["parameter"] in ("hold_time", "current_density"):
        ax.set_xscale("log")
    ax.legend(fontsize=7)
    ax.set_title(f"{sweep['replicas']} replicas of {sweep['n_inputs']} inputs", fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    return path
