"""Figures and tables of any sweep: each quantity's replica mean against the swept fields.

What ``skygas plot`` draws for a sweep of a kind with no figures of its own (a neuron, a
reservoir, a plain simulation), or of the reshuffler over fields other than the current and the
chamber's size:

- ``quantities.png``: one panel per quantity (the kind's plotted quantities,
  :attr:`~skygas.devices.study_hooks.StudyPoints.plotted`), its replica mean against the first
  swept field with the standard error of the mean as bars (with two replicas or more), one
  line per value of the other swept fields;
- ``points.csv``: one row per point with a finished run: its coordinates, the replicas done,
  and each quantity's mean and standard error.

A list of points (``[[points]]``) is drawn against its first field when that field's values
are distinct numbers, else against the point's number.
"""

from __future__ import annotations

import csv
import itertools
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from skygas.core.quantities import quantity

#: The figure's file name.
GENERIC_FIGURE = "quantities.png"
#: Most panels in it (the kind's first plotted quantities).
MAX_PANELS = 9
#: Most lines per panel (the other fields' first combinations).
MAX_LINES = 8
#: Bookkeeping numbers a run stores that are not drawn: how long it took.
BOOKKEEPING = {"wall_time_s", "simulated_time_s", "time_step_s", "steps"}


def swept_fields(ds: xr.Dataset) -> dict[str, str]:
    """The store's swept fields: dimension (or coordinate) name → dotted configuration field."""
    return json.loads(ds.attrs.get("fields_json", "{}"))


def quantities(ds: xr.Dataset) -> list[str]:
    """The stored numbers of the sweep's runs, in the store's order (curves left out)."""
    bookkeeping = {"seed", "done", "session", "finished_at"}
    return [
        str(name)
        for name in ds.data_vars
        if "replica" in ds[name].dims
        and name not in bookkeeping
        and ds[name].ndim == ds["done"].ndim  # a curve has one more dimension
    ]


def plotted(ds: xr.Dataset) -> list[str]:
    """The quantities :data:`GENERIC_FIGURE` draws (at most :data:`MAX_PANELS`).

    The kind's plotted ones first, then numbers the kind does not know of (a census's counts).
    """
    from skygas.devices.registry import study_kind

    stored = quantities(ds)
    try:
        preferred = list(study_kind(ds.attrs.get("device", "")).study.plotted)  # type: ignore[union-attr]
    except Exception:  # noqa: BLE001 - a store of a kind this version does not know
        preferred = []
    names = [q for q in preferred if q in stored]  # the kind's choice, when it made one
    # and what the kind does not know of (a census operation's counts)
    extra = [q for q in stored if q not in names and q not in BOOKKEEPING]
    if names:
        extra = [q for q in extra if q not in _kind_quantities(ds)]
    return (names + extra)[:MAX_PANELS]


def _kind_quantities(ds: xr.Dataset) -> set[str]:
    from skygas.devices.registry import study_kind

    try:
        return set(study_kind(ds.attrs.get("device", "")).study.quantities)  # type: ignore[union-attr]
    except Exception:  # noqa: BLE001 - a store of a kind this version does not know
        return set()


def replica_stats(ds: xr.Dataset, name: str) -> tuple[xr.DataArray, xr.DataArray, xr.DataArray]:
    """Mean, standard error (NaN with fewer than 2) and count over ``replica`` of runs done."""
    values = ds[name].where(ds["done"] == 1)
    n = values.count("replica")
    mean = values.mean("replica", skipna=True)
    sem = (values.std("replica", ddof=1, skipna=True) / np.sqrt(n)).where(n > 1)
    return mean, sem, n


def _point_dims(ds: xr.Dataset) -> list[str]:
    """The store's point dimensions (all but ``replica``)."""
    return [str(d) for d in ds["done"].dims if d != "replica"]


def _numeric(values) -> bool:
    return all(isinstance(v, (int, float, np.number)) and not isinstance(v, bool) for v in values)


def _x_axis(ds: xr.Dataset) -> tuple[str, np.ndarray, str, list[str] | None]:
    """The dimension drawn along x, its values (scaled), its label and tick labels (or None).

    Numbers are drawn as numbers, in the unit of the field (an SI prefix: ``MHz``); names and
    tables are drawn one after the other, each labelled.
    """
    fields = swept_fields(ds)
    dims = _point_dims(ds)
    if dims == ["point"]:  # a list of points
        first = next(iter(fields), None)
        if first is not None and first in ds.coords:
            values = ds[first].values
            if _numeric(values.tolist()) and len(set(values.tolist())) == len(values):
                return ("point", *_scaled(values.astype(float), fields[first]), None)
        return "point", np.arange(ds.sizes["point"], dtype=float), "point", None
    x = dims[0]
    values = ds[x].values
    if _numeric(values.tolist()):
        return (x, *_scaled(values.astype(float), fields.get(x, x)), None)
    ticks = [str(v) for v in values.tolist()]
    return x, np.arange(len(values), dtype=float), fields.get(x, x), ticks


def _scaled(values: np.ndarray, field: str) -> tuple[np.ndarray, str]:
    """``values`` in the axis unit of ``field`` and the axis label (the dotted field, unit)."""
    from skygas.figures.plotting import axis_scale

    scale, unit = axis_scale([float(v) for v in values], quantity(field).unit)
    return values / scale, f"{field} ({unit})" if unit else field


def _log(values: np.ndarray) -> bool:
    finite = values[np.isfinite(values)]
    return bool(finite.size > 2 and (finite > 0).all() and finite.max() / finite.min() >= 20)


def plot_generic(ds: xr.Dataset, path: Path) -> Path:
    """:data:`GENERIC_FIGURE` (see the module docstring) at ``path``."""
    from matplotlib.figure import Figure

    from skygas.figures.plotting import axis_scale

    names = plotted(ds)
    x_dim, x, x_label, ticks = _x_axis(ds)
    others = [d for d in _point_dims(ds) if d != x_dim]
    combos = list(itertools.product(*[range(ds.sizes[d]) for d in others]))[:MAX_LINES]
    cols = min(3, max(1, len(names)))
    rows = max(1, math.ceil(len(names) / cols))
    fig = Figure(figsize=(4.2 * cols, 3.2 * rows + 0.6), dpi=100)
    axes = np.atleast_1d(fig.subplots(rows, cols)).ravel()
    for ax, name in zip(axes, names, strict=False):
        mean, sem, _ = replica_stats(ds, name)
        q = quantity(name)
        scale, unit = axis_scale([float(v) for v in np.ravel(mean.values)], q.unit)
        for combo in combos:
            at = dict(zip(others, combo, strict=True))
            m = mean.isel(at).values / scale
            e = sem.isel(at).values / scale
            tag = ", ".join(
                f"{swept_fields(ds).get(d, d)} = {_value(ds, d, i)}" for d, i in at.items()
            )
            ax.errorbar(x, m, yerr=np.nan_to_num(e), fmt="o-", ms=3, capsize=2, label=tag or None)
        ax.set_title(f"{q.label} ({unit})" if unit else q.label, fontsize=9)
        ax.set_xlabel(x_label, fontsize=8)
        if ticks is not None:
            ax.set_xticks(x, ticks, rotation=30, ha="right")
        elif _log(x):
            ax.set_xscale("log")
        ax.tick_params(labelsize=7)
    for ax in axes[len(names) :]:
        ax.set_visible(False)
    handles, labels = axes[0].get_legend_handles_labels()
    top = 1.0
    if handles:
        fig.legend(handles, labels, loc="upper center", ncols=min(4, len(labels)), fontsize=7)
        top = 1.0 - 0.35 / (3.2 * rows + 0.6)
    replicas = ds.sizes.get("replica", 1)
    fig.suptitle(
        f"replica means ± standard error ({replicas} replica(s) per point)",
        fontsize=8,
        y=0.005,
        va="bottom",
    )
    fig.tight_layout(rect=(0, 0.03, 1, top))
    fig.savefig(path)
    return path


def generic_caption(ds: xr.Dataset) -> str:
    """The caption of :data:`GENERIC_FIGURE`: what is drawn against what."""
    fields = swept_fields(ds)
    x_dim, _, x_label, _ = _x_axis(ds)
    others = [fields.get(d, d) for d in _point_dims(ds) if d != x_dim]
    text = (
        f"Each quantity's mean over the replicas of a point against {x_label}, with the "
        "standard error of the mean as bars (two replicas or more)"
    )
    if others:
        text += f"; one line per value of {', '.join(others)}"
    return text + "."


def _value(ds: xr.Dataset, dim: str, index: int) -> str:
    """The value of swept dimension ``dim`` at ``index``, with its unit (``1 µs``)."""
    from skygas.core.quantities import format_quantity

    value = ds[dim].values[index]
    if isinstance(value, (float, np.floating)):
        field = swept_fields(ds).get(dim, dim)
        return format_quantity(field, float(value)) or f"{value:g}"
    return str(value)


def point_rows(ds: xr.Dataset) -> list[dict]:
    """One row per point with a finished run (see the module docstring).

    Keyed by the swept dotted fields, ``replicas``, and each quantity and ``<quantity>_sem``.
    """
    names = quantities(ds)
    dims = _point_dims(ds)
    fields = swept_fields(ds)
    coords = [c for c in fields if c in ds.coords]
    stats = {name: replica_stats(ds, name) for name in names}
    rows = []
    for index in itertools.product(*[range(ds.sizes[d]) for d in dims]):
        at = dict(zip(dims, index, strict=True))
        n = int(stats[names[0]][2].isel(at)) if names else 0
        if n == 0:
            continue
        row: dict[str, Any] = {}
        for c in coords:
            value = ds[c].isel({d: i for d, i in at.items() if d in ds[c].dims}).values
            row[fields[c]] = value.item() if hasattr(value, "item") else value
        row["replicas"] = n
        for name, (mean, sem, _) in stats.items():
            row[name] = float(mean.isel(at))
            row[f"{name}_sem"] = float(sem.isel(at))
        rows.append(row)
    return rows


def write_points(ds: xr.Dataset, path: Path, header: str) -> Path:
    """``points.csv``: :func:`point_rows` under the provenance ``header``, atomically."""
    from skygas.runs.run_driver import write_atomic

    rows = point_rows(ds)

    def write(tmp: Path) -> None:
        with open(tmp, "w", newline="") as f:
            f.write(header)
            if not rows:
                return
            writer = csv.DictWriter(f, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(
                {k: f"{v:.6g}" if isinstance(v, float) else v for k, v in row.items()}
                for row in rows
            )

    return write_atomic(path, write)
