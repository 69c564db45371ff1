"""Figures of a reshuffler run (matplotlib, Agg).

The device with its current density and sample trajectories, the running correlation, and the
occupancy of both chambers.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from skygas.figures.plotting import draw_landscape, draw_outline, landscape_energy, log_ticks
from skygas.reshuffler.device import drift_field_on_grid


def plot_device(run, path: Path, max_tracks: int = 40) -> Path:
    """|j| in both chambers (colour), walls, read-out lines and the first trajectories.

    With an energy landscape, the landscape is the background and |j| its contour lines.
    """
    grid = run.sim.wall_field.grid
    jx, jy = drift_field_on_grid(run.geometry, run.current, grid, 1.0)
    magnitude = np.hypot(jx, jy)
    gx, gy = grid.nodes()
    inside = run.sim.outline._contains_nm(gx, gy)
    magnitude = np.where(inside, magnitude, np.nan)
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.5, 9.2), dpi=110)
    ax = fig.add_subplot()
    extent = (
        np.array(
            [
                grid.x0,
                grid.x0 + grid.spacing * (grid.nx - 1),
                grid.y0,
                grid.y0 + grid.spacing * (grid.ny - 1),
            ]
        )
        * 1e-3
    )
    landscape_image = draw_landscape(ax, run.sim.landscape, run.sim.outline, colorbar=False)
    if landscape_image is None:
        image = ax.imshow(
            magnitude,
            origin="lower",
            extent=tuple(extent),
            cmap="viridis",
            norm=_log_norm(magnitude),
        )
        # the colour bar below the device: beside it, it would meet the read-out labels
        bar = fig.colorbar(
            image,
            ax=ax,
            label="current density |j| (A/m²)",
            orientation="horizontal",
            shrink=0.7,
            pad=0.08,
        )
        from matplotlib.ticker import NullFormatter

        bar.ax.xaxis.set_minor_formatter(NullFormatter())  # decades only: minor labels collide
        track_colour = "white"
    else:
        energy = landscape_energy(run.sim.landscape)
        assert energy is not None  # draw_landscape drew it
        fig.colorbar(
            landscape_image,
            ax=ax,
            orientation="horizontal",
            shrink=0.7,
            pad=0.08,
            label=energy[1],
        )
        norm = _log_norm(magnitude)
        if norm is not None:
            levels = np.geomspace(norm.vmin, norm.vmax, 7)
            lines = ax.contour(
                np.linspace(extent[0], extent[1], grid.nx),
                np.linspace(extent[2], extent[3], grid.ny),
                magnitude,
                levels=levels,
                colors="white",
                linewidths=0.5,
                alpha=0.6,
            )
            ax.clabel(lines, fmt="%.1e", fontsize=5)
        track_colour = "tab:red"
    draw_outline(ax, run.sim.outline)
    ds = run.sim.trajectories()
    if ds.sizes.get("skyrmion", 0):
        x, y = ds.x.values * 1e6, ds.y.values * 1e6
        for k in range(min(x.shape[1], max_tracks)):
            ok = np.isfinite(x[:, k])
            if ok.sum() > 1:
                ax.plot(x[ok, k], y[ok, k], lw=0.8, color=track_colour, alpha=0.8)
    for name, site in run.geometry.nucleation_sites().items():
        ax.plot(site[0] * 1e-3, site[1] * 1e-3, "r*", ms=8)
        # the chamber's name left of its nucleation site, outside the device
        ax.annotate(
            f"{name.upper()} input",
            (site[0] * 1e-3, site[1] * 1e-3),
            xytext=(-10, 0),
            textcoords="offset points",
            ha="right",
            va="center",
            color="tab:red",
            fontsize=8,
            bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none"},
        )
    x0, y0, x1, y1 = run.sim.outline._bounds_nm
    ax.set_xlim(x0 * 1e-3 - 0.35 * (x1 - x0) * 1e-3, x1 * 1e-3 + 0.3 * (x1 - x0) * 1e-3)
    contours = ", |j| contours (A/m²)" if run.sim.landscape.terms else ""
    ax.set_title(
        f"J = {run.config.current_density:.2g} A/m² in the conduits{contours}, "
        f"first {run.config.output.trajectory_window * 1e9:.0f} ns of trajectories",
        fontsize=9,
    )
    fig.tight_layout()
    fig.savefig(path)
    return path


def _log_norm(values):
    from matplotlib.colors import LogNorm

    finite = values[np.isfinite(values) & (values > 0)]
    if finite.size == 0:
        return None
    return LogNorm(vmin=max(finite.min(), finite.max() * 1e-3), vmax=finite.max())


def plot_running_correlation(ds, path: Path) -> Path:
    """ρ of the events read so far against time (paper's reshuffler figure, right panel)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6, 4), dpi=110)
    ax = fig.add_subplot()
    if ds.sizes.get("running", 0):
        ax.plot(ds.running_time.values * 1e6, ds.running_rho.values, color="tab:blue")
    ax.axhline(0.0, color="grey", lw=0.5)
    ax.set_xlabel("time (µs)")
    ax.set_ylabel("running correlation ρ")
    ax.set_title("input/output correlation as the output stream is generated", fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    return path


def occupancy_steps(ds) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Skyrmions in the UP and DOWN chambers after every injection and read-out, and the times [s].

    Counted from the run's event lists (the injected events' times and bits, the read-outs'
    times and chambers), so the peaks are exact: the dataset's own ``occupancy_up`` samples a
    fixed grid of 500 times, which in a long run falls between injections and misses them.
    Starts at t = 0 (empty chambers) and ends at the grid's last time, the end of the run.
    """
    from skygas.reshuffler.correlation import occupancy

    injected = ds.event_skyrmion.values >= 0
    counts = occupancy(
        ds.event_injection_time.values[injected],
        ds.input_bit.values[injected].astype(bool),
        ds.detection_time.values,
        ds.detection_up.values.astype(bool),
    )
    last = [float(ds.occupancy_time.values[-1])] if ds.sizes.get("occupancy_time", 0) else []
    end = max([0.0, *counts.times[-1:], *last])
    # empty chambers at t = 0; the last counts held to the end of the run
    times = np.concatenate([[0.0], counts.times, [end]])
    up = np.concatenate([[0], counts.up, [counts.up[-1] if len(counts.up) else 0]])
    down = np.concatenate([[0], counts.down, [counts.down[-1] if len(counts.down) else 0]])
    return times, up, down


def plot_occupancy(ds, path: Path) -> Path:
    """Skyrmions present in each chamber against time, and the transit-time distribution.

    The occupancy changes at every injection and read-out, all drawn
    (:func:`occupancy_steps`); the legend gives each chamber's peak, the report's "largest
    occupancy of a chamber".
    """
    from matplotlib.figure import Figure
    from matplotlib.ticker import MaxNLocator

    fig = Figure(figsize=(9, 3.8), dpi=110)
    ax, hx = fig.subplots(1, 2)
    times, up, down = occupancy_steps(ds)
    t = times * 1e6
    ax.step(t, up, where="post", label=f"UP (largest {int(up.max())})")
    ax.step(t, down, where="post", label=f"DOWN (largest {int(down.max())})")
    ax.set_xlabel("time (µs)")
    ax.set_ylabel("skyrmions in chamber")
    ax.legend()
    transit = ds.transit_time.values * 1e9 if ds.sizes.get("detection", 0) else np.empty(0)
    transit = transit[np.isfinite(transit) & (transit > 0)]
    if transit.size:
        # logarithmic bins: the distribution has a long tail (to tens of µs at low currents),
        # over which linear bins would put nearly every skyrmion into one bar
        lo, hi = transit.min(), transit.max()
        edges = np.geomspace(lo, hi * 1.0001, 40) if hi > lo * 1.01 else [lo * 0.9, hi * 1.1]
        hx.hist(transit, bins=edges, color="tab:gray")
        hx.set_xscale("log")
        log_ticks(hx.xaxis, lo, hi)
    hx.set_xlabel("transit time (ns, log scale)")
    hx.set_ylabel("skyrmions")
    for axis in (ax.yaxis, hx.yaxis):  # counts: whole numbers on the axes
        axis.set_major_locator(MaxNLocator(integer=True))
    fig.tight_layout()
    fig.savefig(path)
    return path
