"""Figures of the reservoir.

Occupation map per input and accuracies (matplotlib, Agg backend).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Circle
from matplotlib.ticker import LogFormatterSciNotation, LogLocator, MaxNLocator

from skygas.figures.plotting import draw_outline
from skygas.reservoir.readout import accuracy_interval


def plot_occupation(device, streams, path: Path) -> Path:
    """Where the skyrmion centres were while each input symbol was held.

    The fraction of the frames per bin, on one log colour scale for every panel (its colour bar
    below them), with the contacts, their voltages and the sensors.
    """
    from matplotlib.colors import LogNorm

    symbols = device.drive.symbols
    occupation = sum(s.occupation for s in streams)
    x0, x1, y0, y1 = streams[0].map_extent
    fractions = [occupation[k] / max(occupation[k].sum(), 1) for k in range(len(symbols))]
    positive = np.concatenate([f[f > 0] for f in fractions])
    norm = (
        LogNorm(vmin=max(positive.min(), positive.max() * 1e-3), vmax=positive.max())
        if positive.size
        else None
    )
    fig = Figure(figsize=(3.2 * len(symbols), 4.3), dpi=110)
    grid = fig.add_gridspec(2, len(symbols), height_ratios=(1, 0.05))
    image = None
    for k, symbol in enumerate(symbols):
        ax = fig.add_subplot(grid[0, k])
        frac = fractions[k]
        image = ax.imshow(
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
            f"(a, b) = {symbol}:\n" + ", ".join(f"{n} {v * 1e6:+.0f} µV" for n, v in volts.items()),
            fontsize=7,
        )
        ax.tick_params(labelsize=6)
        ax.xaxis.set_major_locator(MaxNLocator(5))
    if image is not None and norm is not None:
        ny, nx = fractions[0].shape
        side = np.sqrt((x1 - x0) / nx * (y1 - y0) / ny)  # nm
        cax = fig.add_subplot(grid[1, max(len(symbols) // 2 - 1, 0) : len(symbols) // 2 + 1])
        bar = fig.colorbar(
            image,
            cax=cax,
            orientation="horizontal",
            label=f"fraction of the frames in each {side:.3g} nm bin (dashed: sensors)",
        )
        # ticks at 1, 2 and 5 per decade: every minor tick labelled would collide
        bar.ax.xaxis.set_minor_locator(LogLocator(subs=(2.0, 5.0)))
        bar.ax.xaxis.set_minor_formatter(LogFormatterSciNotation(labelOnlyBase=False))
    fig.tight_layout()
    fig.savefig(path)
    return path


def _interval(scores: dict) -> np.ndarray:
    """The 68 % Wilson interval of a score's accuracy as error-bar lengths (below, above)."""
    low, high = accuracy_interval(scores["accuracy"], scores["n_test"])
    # at an accuracy of 0 or 1 one end is the accuracy itself: clip its rounding error
    return np.clip([scores["accuracy"] - low, high - scores["accuracy"]], 0.0, None)


def plot_accuracies(summary: dict, path: Path) -> Path:
    """Test accuracy of the 16 Boolean read-outs and of the temporal tasks, with their errors.

    Each accuracy carries its 68 % Wilson interval over the test inputs
    (:func:`~skygas.reservoir.readout.accuracy_interval`); the chance level (the majority class)
    its standard error √(c(1 − c)/n_test), the spread of a guess's accuracy. The temporal tasks
    are the recall against delay and the parity of the last two inputs.
    """
    t = summary["temporal"]
    fig = Figure(figsize=(10 if t else 5.5, 4.2), dpi=110)
    ax = fig.add_subplot(1, 2 if t else 1, 1)
    boolean = summary["boolean"]
    names = list(boolean)
    acc = [boolean[n]["accuracy"] for n in names]
    chance = [boolean[n]["chance"] for n in names]
    xs = np.arange(len(names))
    ax.bar(
        xs,
        acc,
        yerr=np.column_stack([_interval(boolean[n]) for n in names]),
        error_kw={"elinewidth": 0.8, "capsize": 2, "ecolor": "0.3"},
        color=["tab:red"] + ["tab:blue"] * (len(names) - 1),
        label="accuracy (bars: 68 % interval)",
    )
    ax.errorbar(
        xs,
        chance,
        yerr=[boolean[n]["chance_standard_error"] for n in names],
        fmt="_",
        color="k",
        ms=10,
        elinewidth=0.6,
        label="chance (majority class) ± s.e.",
    )
    n_test = boolean[names[0]]["n_test"]
    ax.set_xticks(xs, names, rotation=70, fontsize=6)
    ax.set_ylim(0, 1.25)
    ax.set_yticks(np.linspace(0, 1, 6))
    ax.set_ylabel("test accuracy")
    ax.legend(fontsize=7, loc="upper center", ncols=2)
    ax.set_title(
        f"Boolean functions of two inputs, hold {summary['hold_time_s'] * 1e6:g} µs, "
        f"{n_test} test inputs",
        fontsize=8,
    )
    if not t:
        fig.tight_layout()
        fig.savefig(path)
        return path
    ax2 = fig.add_subplot(1, 2, 2)
    recall = t["recall"]
    delays = [int(k) for k in recall]
    ax2.errorbar(
        delays,
        [recall[str(k)]["accuracy"] for k in delays],
        yerr=np.column_stack([_interval(recall[str(k)]) for k in delays]),
        fmt="o-",
        capsize=3,
        label="recall of input a, k steps back",
    )
    ax2.plot(delays, [recall[str(k)]["chance"] for k in delays], "k--", lw=0.8, label="chance")
    parity = t["parity_last_two"]
    low, high = accuracy_interval(parity["accuracy"], parity["n_test"])
    ax2.axhline(parity["accuracy"], color="tab:green", lw=1, label="parity of the last two inputs")
    ax2.axhspan(float(low), float(high), color="tab:green", alpha=0.15, lw=0)
    ax2.set_xlabel("delay k (inputs)")
    ax2.set_ylabel("test accuracy")
    ax2.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax2.set_ylim(0, 1.25)
    ax2.set_yticks(np.linspace(0, 1, 6))
    ax2.legend(fontsize=7, loc="upper right")
    ax2.set_title(
        f"fading memory, {recall[str(delays[0])]['n_test']} test inputs "
        "(bars and band: 68 % intervals)",
        fontsize=8,
    )
    fig.tight_layout()
    fig.savefig(path)
    return path
