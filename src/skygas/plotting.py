"""Figures of geometries and trajectories (matplotlib, Agg backend; no display needed)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from skygas.geometry import Outline


def draw_outline(ax, outline: Outline, scale: float = 1e-3, labels: bool = True) -> None:
    """Walls in black, ports in red; coordinates shown in µm (``scale`` µm per nm). With
    ``labels``, each port's name sits just outside the device, beside the port, on a white
    ground, so it covers neither the wall nor a colour bar beside the axes."""
    walls = outline.walls
    for part in getattr(walls, "geoms", [walls]):
        xy = np.asarray(part.coords) * scale
        ax.plot(xy[:, 0], xy[:, 1], color="black", lw=1.5)
    for name, seg in outline.ports.items():
        xy = np.asarray(seg.coords) * scale
        ax.plot(xy[:, 0], xy[:, 1], color="tab:red", lw=2.5)
        if labels:
            _label_port(ax, outline, name, xy, scale)
    ax.set_aspect("equal")
    ax.set_xlabel("x (µm)")
    ax.set_ylabel("y (µm)")


def _label_port(ax, outline: Outline, name: str, xy: np.ndarray, scale: float) -> None:
    """The port's name, offset from the port's middle along its outward normal."""
    mid = xy.mean(axis=0)
    tangent = xy[-1] - xy[0]
    normal = np.array([tangent[1], -tangent[0]]) / max(np.hypot(*tangent), 1e-12)
    probe = (mid + 1e-3 * normal) / scale
    if outline.contains_nm(probe[0], probe[1]):
        normal = -normal  # point away from the device
    ax.annotate(name, mid, xytext=12 * normal, textcoords="offset points", color="tab:red",
                fontsize=7, ha="left" if normal[0] > 0.5 else "right" if normal[0] < -0.5
                else "center", va="center",
                bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.8})


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
