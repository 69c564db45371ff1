"""Figures of geometries, trajectories and current flow (matplotlib, Agg backend; no display
needed). The physics modules compute; the figures of their results live here."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from skygas.current import CurrentSolution
from skygas.geometry import Outline


def draw_outline(ax, outline: Outline, scale: float = 1e-3) -> None:
    """Walls in black, ports in red; coordinates shown in µm (``scale`` µm per nm)."""
    walls = outline.walls
    for part in getattr(walls, "geoms", [walls]):
        xy = np.asarray(part.coords) * scale
        ax.plot(xy[:, 0], xy[:, 1], color="black", lw=1.5)
    for name, seg in outline.ports.items():
        xy = np.asarray(seg.coords) * scale
        ax.plot(xy[:, 0], xy[:, 1], color="tab:red", lw=2.5)
        ax.annotate(name, xy.mean(axis=0), color="tab:red", fontsize=8, ha="center",
                    va="bottom")
    ax.set_aspect("equal")
    ax.set_xlabel("x (µm)")
    ax.set_ylabel("y (µm)")


def plot_trajectories(ds: xr.Dataset, outline: Outline, path: str | Path,
                      max_tracks: int = 200, title: str | None = None) -> Path:
    """Save a PNG of the outline with the recorded trajectories (start ○, end ●)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6, 5.5), dpi=120)
    ax = fig.add_subplot()
    draw_outline(ax, outline)
    x = ds.x.values * 1e6
    y = ds.y.values * 1e6
    for k in range(min(x.shape[1], max_tracks)):
        ok = np.isfinite(x[:, k])
        if not ok.any():
            continue
        line, = ax.plot(x[ok, k], y[ok, k], lw=0.7, alpha=0.8)
        ax.plot(x[ok, k][0], y[ok, k][0], "o", mfc="none", color=line.get_color(), ms=3)
        ax.plot(x[ok, k][-1], y[ok, k][-1], "o", color=line.get_color(), ms=3)
    ax.set_title(title or f"{x.shape[1]} skyrmions, {ds.attrs.get('temperature_K', '?')} K, "
                 f"{ds.time.values[-1] * 1e9:.0f} ns" if len(ds.time) else "no frames")
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path)
    return path


def draw_current(ax, solution: CurrentSolution, outline: Outline, scale: float = 1e-3,
                 streamlines: bool = True):
    """|j| map (A/m², log colour scale) with stream lines and the outline, in µm (``scale`` µm
    per nm). Returns the image for a colour bar."""
    from matplotlib.colors import LogNorm

    jx, jy, inside, (x0, x1, y0, y1) = solution.cell_current_density
    magnitude = np.where(inside, np.hypot(jx, jy), np.nan)
    positive = magnitude[np.isfinite(magnitude) & (magnitude > 0)]
    norm = None
    if positive.size:
        top = float(positive.max())
        norm = LogNorm(vmin=max(float(positive.min()), top * 1e-3), vmax=top)
    image = ax.imshow(magnitude, origin="lower", extent=(x0 * scale, x1 * scale, y0 * scale,
                                                         y1 * scale),
                      cmap="viridis", norm=norm, interpolation="nearest")
    if streamlines and positive.size:
        ny, nx = magnitude.shape
        xs = (x0 + (x1 - x0) / nx * (np.arange(nx) + 0.5)) * scale  # cell centres
        ys = (y0 + (y1 - y0) / ny * (np.arange(ny) + 0.5)) * scale
        ax.streamplot(xs, ys, np.where(inside, jx, np.nan), np.where(inside, jy, np.nan),
                      color="white", linewidth=0.5, density=1.2, arrowsize=0.6)
    draw_outline(ax, outline, scale)
    return image


def plot_current(solution: CurrentSolution, outline: Outline, path: str | Path,
                 title: str | None = None) -> Path:
    """Save a PNG of the current density map (:func:`draw_current`); returns the path."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.5, 5.5), dpi=120)
    ax = fig.add_subplot()
    image = draw_current(ax, solution, outline)
    fig.colorbar(image, ax=ax, label="|j| (A/m²)")
    ax.set_title(title or (f"J = {solution.current_density:.3g} A/m², "
                           f"R = {solution.resistance:.3g} Ω, P = {solution.power:.3g} W"),
                 fontsize=9)
    path = Path(path)
    fig.savefig(path)
    return path
