"""Figures of the neuron: device and landscape, count trace, transfer curve, maximum density.

Drawn with matplotlib (Agg).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator


def plot_device(run, path: Path, max_tracks: int = 200) -> Path:
    """The device over its energy landscape, with the trajectories or the final skyrmions.

    The landscape has the gate's band drawn closed, with the user's potentials; over it, the
    nucleation site and the recorded trajectories (start ○, end ●) or, for a run that recorded
    none, the skyrmions present at its end. A panel beside the device magnifies the output
    conduit and its gate (the grey box); the colour bar, shared by both, lies below them, so
    neither the magnified view nor the bar covers the chamber or a label.
    """
    from skygas.figures.plotting import draw_landscape, draw_outline, draw_tracks, landscape_energy

    sim = run.sim
    fig = Figure(figsize=(9, 5.8), dpi=120)
    grid = fig.add_gridspec(2, 2, width_ratios=(2.6, 1), height_ratios=(1, 0.04))
    ax, zoom = fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[0, 1])
    image = draw_landscape(ax, sim.landscape, sim.outline, colorbar=False)
    draw_outline(ax, sim.outline)
    zoom_image = draw_landscape(zoom, sim.landscape, sim.outline, colorbar=False)
    draw_outline(zoom, sim.outline, labels=False)
    ds = sim.trajectories()
    for axis in (ax, zoom):
        if ds.sizes.get("skyrmion", 0):
            draw_tracks(axis, ds, max_tracks)
        else:
            xy = sim.state.positions * 1e6
            axis.plot(xy[:, 0], xy[:, 1], "o", color="tab:red", ms=3)
    tracks = ds.sizes.get("skyrmion", 0)
    what = (
        f"{sim.count} skyrmions at the end"
        if not tracks
        else f"{tracks} trajectories"
        if tracks <= max_tracks
        else f"the first {max_tracks} of {tracks} trajectories"  # as draw_tracks draws them
    )
    # the magnified view: the output conduit and its gate, a few skyrmion diameters around them
    dev = run.device.config.device
    d_um = sim.thiele.skyrmion_diameter * 1e6
    x0 = run.device.x_meet * 1e-3 - 2 * d_um
    x1 = run.device.x_meet * 1e-3 + dev.conduit_length * 1e6 + 0.5 * d_um
    half = max(dev.conduit_width * 1e6 / 2 + 1.5 * d_um, (x1 - x0) / 2)
    zoom.set_xlim(x0, x1)
    zoom.set_ylim(-half, half)
    zoom.set_title("output conduit and gate\n(grey box, magnified)", fontsize=8)
    zoom.tick_params(labelsize=7)
    zoom.xaxis.set_major_locator(MaxNLocator(4))
    ax.indicate_inset((x0, -half, x1 - x0, 2 * half), edgecolor="grey", alpha=0.8)
    site = run.device.site * 1e-3
    ax.plot(*site, "*", color="tab:red", ms=9)
    ax.annotate(
        "nucleation",
        site,
        color="tab:red",
        fontsize=7,
        ha="center",
        va="top",
        xytext=(0, -8),
        textcoords="offset points",
        bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.8},
    )
    # room beside the device for the port labels, inside the axes
    bx0, _, bx1, _ = sim.outline._bounds_nm
    margin = 0.12 * (bx1 - bx0) * 1e-3
    ax.set_xlim(bx0 * 1e-3 - margin, bx1 * 1e-3 + margin)
    if image is not None:
        assert zoom_image is not None
        zoom_image.set_norm(image.norm)  # one colour scale for both panels: one bar
        energy = landscape_energy(sim.landscape)
        assert energy is not None  # draw_landscape drew it
        fig.colorbar(
            image, cax=fig.add_subplot(grid[1, :]), orientation="horizontal", label=energy[1]
        )
    g = run.device.config.gate
    ax.set_title(
        f"gate {g.barrier_height:g} k_BT (drawn closed), {what}, {sim.time * 1e9:.0f} ns",
        fontsize=9,
    )
    fig.tight_layout()
    fig.savefig(path)
    return path


def plot_trace(run, path: Path) -> Path:
    """The count trace to ``path``, with the reading, threshold, gate openings and spikes."""
    tr = run.trace()
    fig = Figure(figsize=(7, 3.5), dpi=110)
    ax = fig.add_subplot()
    t = tr["time"] * 1e9
    ax.plot(t, tr["count"], lw=0.8, label="skyrmions in the device")
    if run.device.config.sensor.signal == "count":
        ax.plot(t, tr["reading"], lw=0.6, alpha=0.7, label="sensor reading")
    ax.axhline(run.controller.threshold, color="tab:red", ls="--", lw=0.8, label="threshold")
    ax.fill_between(
        t,
        0,
        1,
        where=tr["gate_open"],
        transform=ax.get_xaxis_transform(),
        color="tab:orange",
        alpha=0.2,
        label="gate open",
    )
    for s in run.spike_times() * 1e9:
        ax.axvline(s, color="k", lw=0.4, alpha=0.5)
    ax.set_xlabel("time (ns)")
    ax.set_ylabel("count (membrane potential)")
    # the threshold inside the axis, not on its frame; the legend above it, off the trace
    top = max(float(np.max(tr["count"], initial=0)), run.controller.threshold)
    ax.set_ylim(-0.05 * top - 0.5, 1.1 * top + 0.5)
    ax.legend(fontsize=7, loc="lower left", bbox_to_anchor=(0.0, 1.01), ncols=4, frameon=False)
    fig.tight_layout()
    fig.savefig(path)
    return path


def plot_transfer(curve: dict, path: Path, lif: dict | None = None) -> Path:
    """The transfer curve to ``path``: firing against input rate, and the LIF's if given."""
    fig = Figure(figsize=(4.5, 3.5), dpi=110)
    ax = fig.add_subplot()
    r = np.asarray(curve["input_rate_Hz"]) / 1e6
    ax.plot(r, np.asarray(curve["firing_rate_Hz"]) / 1e6, "o-", label="device")
    if lif is not None and "predicted_Hz" in lif:
        ax.plot(r, np.asarray(lif["predicted_Hz"]) / 1e6, "--", label="LIF")
    ax.set_xlabel("input rate (MHz)")
    ax.set_ylabel("firing rate (MHz)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    return path


def plot_saturation(result, path: Path) -> Path:
    """The maximum-density figure to ``path``: saturation count against diameter.

    The saturation counts carry their standard errors; the legend gives the protocol's
    relaxation time and temperature.
    """
    fig = Figure(figsize=(4.5, 3.5), dpi=110)
    ax = fig.add_subplot()
    relax, temperature = result.parameters["relax_time_s"], result.parameters["temperature_K"]
    d = result.diameters * 1e9
    ax.errorbar(
        d,
        result.max_count,
        yerr=result.max_count_error,
        fmt="o-",
        label=f"simulated saturation ({relax * 1e9:g} ns, {temperature:g} K)",
    )
    ax.plot(d, result.close_packing, "--", label="hexagonal close packing")
    ax.set_yscale("log")
    ax.set_xlabel("chamber diameter (nm)")
    ax.set_ylabel("maximum number of skyrmions")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path)
    return path
