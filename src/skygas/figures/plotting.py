"""Figures of geometries, trajectories and current flow (matplotlib, Agg backend).

No display needed. The physics modules compute; the figures of their results live here.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import xarray as xr

from skygas.core.quantities import PREFIXED_UNITS, PREFIXES, power_of_ten
from skygas.fields.current import CurrentSolution
from skygas.physics.geometry import Outline


def draw_outline(ax, outline: Outline, scale: float = 1e-3, labels: bool = True) -> None:
    """Walls in black, ports in red; coordinates shown in µm (``scale`` µm per nm).

    With ``labels``, each port's name sits just outside the device, beside the port, on a white
    ground, so it covers neither the wall nor a colour bar beside the axes.
    """
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
    if outline._contains_nm(probe[0], probe[1]):
        normal = -normal  # point away from the device
    ax.annotate(
        name,
        mid,
        xytext=12 * normal,
        textcoords="offset points",
        color="tab:red",
        fontsize=7,
        ha="left" if normal[0] > 0.5 else "right" if normal[0] < -0.5 else "center",
        va="center",
        bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.8},
    )


def landscape_energy(
    field, outline: Outline | None = None, all_terms: bool = True
) -> tuple[np.ndarray, str] | None:
    """The landscape's energy U on its grid (ny, nx) in plotting units, and their label.

    U/k_BT at the field's temperature (zJ at T = 0), NaN outside ``outline``. ``all_terms`` draws
    every term, switched-off ones (an open gate) included. None without terms.
    """
    from skygas.core import units

    if field is None or not field.terms:
        return None
    enabled = list(field.enabled)
    try:
        for k in range(len(enabled)):
            field.set_enabled(k, True if all_terms else enabled[k])
        u = field.nodes[..., 0].copy()  # pN·nm
    finally:
        for k, on in enumerate(enabled):
            field.set_enabled(k, on)
    if field.temperature > 0:
        u /= units.thermal_energy_internal(field.temperature)
        label = f"U (k_BT, T = {field.temperature:g} K)"
    else:
        u *= 1e21 / units.J_TO_PN_NM
        label = "U (zJ)"
    if outline is not None:
        gx, gy = field.grid.nodes()
        u = np.where(outline._contains_nm(gx, gy), u, np.nan)
    return u, label


def draw_landscape(
    ax,
    field,
    outline: Outline | None = None,
    all_terms: bool = True,
    cmap: str = "cividis",
    colorbar: bool = True,
):
    """Draw an energy landscape on ``ax`` as an image in µm, coloured by U/k_BT.

    The landscape is a :class:`~skygas.fields.landscape.LandscapeField`, its values those of
    :func:`landscape_energy`, with a labelled colour bar. Returns the image, or None when there is
    no landscape to draw.
    """
    energy = landscape_energy(field, outline, all_terms)
    if energy is None:
        return None
    u, label = energy
    grid = field.grid
    extent = np.array(
        [
            grid.x0 - grid.spacing / 2,
            grid.x0 + grid.spacing * (grid.nx - 0.5),
            grid.y0 - grid.spacing / 2,
            grid.y0 + grid.spacing * (grid.ny - 0.5),
        ]
    )
    image = ax.imshow(u, origin="lower", extent=extent * 1e-3, cmap=cmap, interpolation="nearest")
    if colorbar:
        ax.figure.colorbar(image, ax=ax, label=label, shrink=0.7)
    return image


def draw_tracks(ax, ds: xr.Dataset, max_tracks: int, color=None, ends: bool = True) -> None:
    """Recorded trajectories in µm, one line each (start ○, end ● when ``ends``)."""
    x = ds.x.values * 1e6
    y = ds.y.values * 1e6
    for k in range(min(x.shape[1], max_tracks)):
        ok = np.isfinite(x[:, k])
        if ok.sum() < 1:
            continue
        (line,) = ax.plot(x[ok, k], y[ok, k], lw=0.7, alpha=0.8, color=color)
        if ends:
            ax.plot(x[ok, k][0], y[ok, k][0], "o", mfc="none", color=line.get_color(), ms=3)
            ax.plot(x[ok, k][-1], y[ok, k][-1], "o", color=line.get_color(), ms=3)


def _tick_label(value: float, _position=None) -> str:
    """A log-axis tick: ``200``, ``0.5``; ``10¹¹`` or ``2×10¹¹`` beyond 10⁴ or below 10⁻²."""
    if value <= 0:
        return ""
    if 1e-2 <= value < 1e4:
        return f"{value:g}"
    exponent = int(np.floor(np.log10(value) + 1e-9))
    mantissa = value / 10.0**exponent
    power = "10" + str(exponent).translate(str.maketrans("0123456789-", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻"))
    return power if abs(mantissa - 1) < 1e-6 else f"{mantissa:g}×{power}"


def log_ticks(axis, low: float, high: float) -> None:
    """Labels of a log ``axis`` over [low, high] that stand apart.

    Matplotlib labels the minor ticks of an axis narrower than a decade, and their long labels
    (``1.4×10¹¹``) run into each other: here the labelled ticks are 1, 2 and 5 times the powers
    of ten (1, 1.5, 2, 3, 5 and 7 times them over less than a decade), the others unlabelled.
    """
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    narrow = high <= 10 * low
    axis.set_major_locator(LogLocator(subs=(1.0, 1.5, 2.0, 3.0, 5.0, 7.0) if narrow else (1, 2, 5)))
    axis.set_major_formatter(FuncFormatter(_tick_label))
    axis.set_minor_formatter(NullFormatter())


def draw_skyrmions(ax, positions, diameter: float, color="tab:blue") -> None:
    """Skyrmions as discs of their ``diameter`` [m] at ``positions`` [m] (n, 2), in µm."""
    from matplotlib.collections import EllipseCollection

    xy = np.asarray(positions, dtype=float).reshape(-1, 2) * 1e6
    if not len(xy):
        return
    size = np.full(len(xy), diameter * 1e6)
    ax.add_collection(
        EllipseCollection(
            size,
            size,
            np.zeros(len(xy)),
            units="xy",
            offsets=xy,
            offset_transform=ax.transData,
            facecolors=color,
            edgecolors="none",
            alpha=0.7,
        )
    )


def _figure_and_axes(ax, landscape):
    """``ax`` and its figure, or a new figure (wider beside a landscape's colour bar)."""
    if ax is not None:
        return ax.figure, ax
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.5 if landscape is not None and landscape.terms else 6, 5.5), dpi=120)
    return fig, fig.add_subplot()


def trajectories_figure(
    ds: xr.Dataset,
    outline: Outline,
    ax=None,
    max_tracks: int = 200,
    title: str | None = None,
    landscape=None,
):
    """The outline with the recorded trajectories (start ○, end ●), in µm.

    Over the energy ``landscape`` (a :class:`~skygas.fields.landscape.LandscapeField`) when there is
    one. Drawn on ``ax`` if given, else on a new figure; returns the figure.
    """
    fig, ax = _figure_and_axes(ax, landscape)
    draw_landscape(ax, landscape, outline)
    draw_outline(ax, outline)
    draw_tracks(ax, ds, max_tracks)
    ax.set_title(title or _trajectories_title(ds, max_tracks))
    fig.tight_layout()
    return fig


def _trajectories_title(ds: xr.Dataset, max_tracks: int) -> str:
    """How many skyrmions, the temperature and the time span; which tracks are drawn."""
    if not len(ds.time):
        return "no frames"
    n = ds.sizes.get("skyrmion", 0)
    drawn = f" (the first {max_tracks} drawn)" if n > max_tracks else ""
    temperature = ds.attrs.get("temperature_K")
    kelvin = "?" if temperature is None else f"{float(temperature):g}"
    return f"{n} skyrmions{drawn}, {kelvin} K, {ds.time.values[-1] * 1e9:.0f} ns"


def plot_trajectories(
    ds: xr.Dataset,
    outline: Outline,
    path: str | Path,
    max_tracks: int = 200,
    title: str | None = None,
    landscape=None,
) -> Path:
    """Save a PNG of :func:`trajectories_figure` at ``path``; returns the path."""
    fig = trajectories_figure(ds, outline, None, max_tracks, title, landscape)
    path = Path(path)
    fig.savefig(path)
    return path


def state_figure(sim, ax=None, landscape: bool = True, title: str | None = None):
    """The skyrmions of ``sim`` now, as discs of their diameter over its outline, in µm.

    Over its energy landscape when ``landscape`` and it has one (every term drawn). Drawn on
    ``ax`` if given, else on a new figure; returns the figure. See
    :meth:`skygas.engine.Simulation.plot`.
    """
    field = sim.landscape if landscape else None
    fig, ax = _figure_and_axes(ax, field)
    draw_landscape(ax, field, sim.outline)
    draw_outline(ax, sim.outline)
    draw_skyrmions(ax, sim.positions()[1], sim.thiele.skyrmion_diameter)
    ax.set_title(
        title or f"{sim.count} skyrmions, {sim.temperature:g} K, t = {sim.time * 1e9:.4g} ns"
    )
    fig.tight_layout()
    return fig


def dataset_outline(ds: xr.Dataset) -> Outline:
    """The outline a trajectories Dataset records (its parameters' ``geometry``).

    Raises
    ------
    InputError
        If the Dataset records no outline (not one of :meth:`Simulation.trajectories
        <skygas.engine.Simulation.trajectories>` or of a result file holding one).
    """
    import json

    from skygas.core.errors import InputError

    for key in ("parameters_json", "engine_parameters_json"):
        if key in ds.attrs:
            geometry = json.loads(ds.attrs[key]).get("geometry")
            if geometry:
                return Outline.from_record(geometry)
    raise InputError(
        "dataset",
        ds.attrs.get("title", "a Dataset"),
        "a trajectories Dataset whose attributes record the outline (parameters_json), as "
        "Simulation.trajectories() and trajectories.nc give",
    )


def plot(ds: xr.Dataset, ax=None, max_tracks: int = 200, title: str | None = None):
    """Plot a trajectories Dataset: the tracks over the device's outline, in µm.

    Parameters
    ----------
    ds : xarray.Dataset
        Recorded trajectories, as :meth:`Simulation.trajectories
        <skygas.engine.Simulation.trajectories>` returns or ``skygas simulate`` writes
        (``trajectories.nc``): ``x``, ``y`` [m] on (time, skyrmion), the outline in its
        attributes.
    ax : matplotlib.axes.Axes, optional
        Draw on it (default: a new figure).
    max_tracks : int
        Draw at most this many skyrmions' tracks.
    title : str, optional
        The title (default: skyrmions, temperature and duration).

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on; save it with ``fig.savefig(path)``.

    Raises
    ------
    InputError
        If ``ds`` holds no ``x`` and ``y`` or records no outline.

    Examples
    --------
    >>> import skygas
    >>> sim = skygas.Simulation(skygas.disk(diameter=400e-9), seed=1, step_interval=0.5e-9)
    >>> ids = sim.add_random(3)
    >>> sim.run(2e-9, record_interval=0.5e-9)
    >>> fig = skygas.plot(sim.trajectories())
    """
    from skygas.core.errors import InputError

    if not isinstance(ds, xr.Dataset) or "x" not in ds or "y" not in ds:
        raise InputError(
            "dataset",
            type(ds).__name__,
            "a trajectories Dataset with x and y [m] on (time, skyrmion), as "
            "Simulation.trajectories() returns",
        )
    return trajectories_figure(ds, dataset_outline(ds), ax, max_tracks, title)


def draw_current(
    ax, solution: CurrentSolution, outline: Outline, scale: float = 1e-3, streamlines: bool = True
):
    """|j| map (A/m², log colour scale) with stream lines and the outline, in µm.

    ``scale`` µm per nm. Returns the image for a colour bar.
    """
    from matplotlib.colors import LogNorm

    jx, jy, inside, (x0, x1, y0, y1) = solution.cell_current_density
    magnitude = np.where(inside, np.hypot(jx, jy), np.nan)
    positive = magnitude[np.isfinite(magnitude) & (magnitude > 0)]
    norm = None
    if positive.size:
        top = float(positive.max())
        norm = LogNorm(vmin=max(float(positive.min()), top * 1e-3), vmax=top)
    image = ax.imshow(
        magnitude,
        origin="lower",
        extent=(x0 * scale, x1 * scale, y0 * scale, y1 * scale),
        cmap="viridis",
        norm=norm,
        interpolation="nearest",
    )
    if streamlines and positive.size:
        ny, nx = magnitude.shape
        xs = (x0 + (x1 - x0) / nx * (np.arange(nx) + 0.5)) * scale  # cell centres
        ys = (y0 + (y1 - y0) / ny * (np.arange(ny) + 0.5)) * scale
        ax.streamplot(
            xs,
            ys,
            np.where(inside, jx, np.nan),
            np.where(inside, jy, np.nan),
            color="white",
            linewidth=0.5,
            density=1.2,
            arrowsize=0.6,
        )
    draw_outline(ax, outline, scale)
    return image


def plot_current(
    solution: CurrentSolution, outline: Outline, path: str | Path, title: str | None = None
) -> Path:
    """Save a PNG of the current density map (:func:`draw_current`); returns the path."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.5, 5.5), dpi=120)
    ax = fig.add_subplot()
    image = draw_current(ax, solution, outline)
    fig.colorbar(image, ax=ax, label="|j| (A/m²)")
    ax.set_title(
        title
        or (
            f"J = {solution.current_density:.3g} A/m², "
            f"R = {solution.resistance:.3g} Ω, P = {solution.power:.3g} W"
        ),
        fontsize=9,
    )
    path = Path(path)
    fig.savefig(path)
    return path


def axis_scale(values: list[float], unit: str | None) -> tuple[float, str]:
    """The factor to divide ``values`` by on an axis, and the unit the axis then reads in.

    An SI prefix for the units that take one (``nm``, ``µs``), a power of ten for the others
    beyond 10⁻³–10⁴ (``10¹¹ A/m²``); ``unit`` None (not derived) reads as a pure number.
    """
    unit = unit or ""
    finite = [abs(v) for v in values if v is not None and math.isfinite(v) and v != 0]
    if not finite:
        return 1.0, unit
    exponent = math.floor(math.log10(max(finite)))
    if unit in PREFIXED_UNITS:
        power = max(-18, min(9, 3 * math.floor(exponent / 3)))
        return 10.0**power, PREFIXES[power] + unit
    if -3 <= exponent < 4:
        return 1.0, unit
    return 10.0**exponent, f"{power_of_ten(exponent).lstrip('×')} {unit}".strip()
