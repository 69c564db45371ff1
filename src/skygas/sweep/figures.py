"""The paper's reshuffler figures from a sweep store (matplotlib, Agg).

- ``reshuffler.png`` (paper, reshuffler figure): left, ρ against J for each p-value with replica
  error bars and the fit ρ = c_A/(c_B + (J/J₀)^(−3/2)), J₀ = 10¹¹ A/m²; right, the running ρ
  against time for the p-value nearest 0.62 at each J;
- ``chamber_size.png`` (paper, chamber-size figure): ρ against the chamber diameter L with the
  fit ρ = c_A + c_B/√L;
- ``reshuffler_details.png`` / ``chamber_size_details.png``: per point, p_out − p_in with
  p_out's 95 % interval (the p-values side by side), the fullest chamber (the paper's "at most
  51 at 10¹⁰ A/m²" marked where the current axis reaches 10¹⁰ A/m²), the mean transit time and
  the lag scan (ρ at lag 0 beside its largest value over lags, with that lag);
- ``fits.json``: every fitted constant and exponent with its uncertainty; ``points.csv``: one
  row per point (:func:`~skygas.sweep.analysis.point_table`).

Every file records where it comes from (:func:`sweep_provenance`: the store's skygas version,
root seed and fingerprint, the command line): the PNGs in their text chunks, ``fits.json`` in
its ``provenance`` entry, ``points.csv`` in a leading ``# key: value`` block. All are written
through a temporary file.

Both ρ figures draw the paper's fit law and the free-exponent fit ρ/(1 − ρ) ∝ x^e, each only
where the points constrain it (every coefficient's error below the coefficient, as the report's
headline requires to state it): a fit the report calls not constrained is not drawn.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import xarray as xr

from skygas.core.headline import constrained
from skygas.figures.plotting import log_ticks
from skygas.reshuffler.headline import signed
from skygas.sweep.analysis import (
    CHAMBER,
    CURRENT,
    CURRENT_UNIT,
    LENGTH_UNIT,
    P_VALUE,
    fit_chamber_scaling,
    fit_current_scaling,
    odds_power_law,
    point_table,
    replica_mean,
    running_mean,
)
from skygas.sweep.spec import DEFAULT_DEVICE
from skygas.sweep.store import open_sweep

RUNNING_P = 0.62  # the paper's running-correlation panel
PAPER_MAX_OCCUPANCY = 51  # the paper's fullest chamber at its lowest current ...
PAPER_LOWEST_CURRENT = 1e10  # ... J [A/m²]


#: χ²/dof above which a fit "misses the data" (a miss far beyond the replicas' scatter)
MISSES = 3.0
#: the paper's current law as the legends write it, J₀ defined
CURRENT_LAW = "c_A/(c_B + (J/J₀)^(−3/2)), J₀ = 10¹¹ A/m²"


def _fmt(fit: dict, key: str) -> str:
    """A fitted exponent for a title: ``1.50 ± 0.06``; "none (not constrained)" when not fixed."""
    if not constrained(fit.get(key), fit.get(key + "_error")):
        return "none (not constrained)"
    return f"{fit[key]:.2f} ± {fit[key + '_error']:.2f}"


def paper_fit_constrained(fit: dict) -> bool:
    """Whether the points fix both coefficients of the paper's fit (:func:`constrained`).

    A fit that is not constrained is neither drawn nor stated (the report says why).
    """
    return all(constrained(fit.get(c), fit.get(f"{c}_error")) for c in ("c_A", "c_B"))


def chi2_per_dof(model_at_points, mean, sem) -> float | None:
    """χ²/dof of the replica means (errors: their standard errors) about a 2-parameter model.

    None with fewer than three points that have an error.
    """
    model_at_points, mean, sem = (
        np.ravel(np.asarray(a, float)) for a in (model_at_points, mean, sem)
    )
    ok = np.isfinite(model_at_points) & np.isfinite(mean) & np.isfinite(sem) & (sem > 0)
    dof = int(ok.sum()) - 2
    if dof < 1:
        return None
    return float(np.sum(((mean[ok] - model_at_points[ok]) / sem[ok]) ** 2)) / dof


def fit_label(name: str, model_at_points, mean, sem) -> tuple[str, str]:
    """Legend text and line style of a fitted curve, saying how well it meets its points.

    The points it is drawn over: χ²/dof of the replica means (errors = their standard errors), with
    "misses the data" and a dashed line when χ²/dof > :data:`MISSES`.
    """
    chi2 = chi2_per_dof(model_at_points, mean, sem)
    if chi2 is None:
        return f"{name} (too few points to judge the fit)", "--"
    if chi2 > MISSES:
        return f"{name}: misses the data (χ²/dof = {chi2:.3g})", "--"
    return f"{name} (χ²/dof = {chi2:.2g})", "-"


def _current_model(fit: dict, current):
    """The paper's current law ρ = c_A/(c_B + (J/J₀)^(−3/2)) at ``current`` [A/m²]."""
    return fit["c_A"] / (fit["c_B"] + (current / CURRENT_UNIT) ** -1.5)


def _chamber_model(fit: dict, length):
    """The paper's chamber law ρ = c_A + c_B/√L at ``length`` [µm]."""
    return fit["c_A"] + fit["c_B"] / np.sqrt(length)


def paper_fit_chi2(ds: xr.Dataset, x_dim: str, fit: dict) -> float | None:
    """χ²/dof of the paper's fit about the replica means it is drawn over (None: cannot tell)."""
    if not np.isfinite(fit.get("c_A", np.nan)):
        return None
    stats = replica_mean(ds)
    if x_dim == CURRENT:
        model = _current_model(fit, stats[CURRENT])
    else:
        model = _chamber_model(fit, stats[CHAMBER] / LENGTH_UNIT)
    at_points = model.broadcast_like(stats["mean"]).transpose(*stats["mean"].dims)
    return chi2_per_dof(at_points, stats["mean"].values, stats["sem"].values)


def dodge(x, k: int, n: int, log: bool, width: float = 0.3) -> np.ndarray:
    """``x`` shifted for series ``k`` of ``n`` so that the series' error bars stand side by side.

    The ``n`` series spread over ``width`` of the smallest gap between neighbouring x (on a log
    axis, between their logarithms), centred on the true x; one series is not moved.
    """
    x = np.asarray(x, float)
    if n < 2 or x.size < 1:
        return x
    where = np.log10(x) if log else x
    gaps = np.diff(np.unique(where[np.isfinite(where)]))
    gap = gaps.min() if gaps.size else (0.1 if log else max(abs(float(where[0])), 1.0) * 0.1)
    shifted = where + (k - (n - 1) / 2) * width * gap / (n - 1)
    return 10**shifted if log else shifted


def _grid_only(ds: xr.Dataset, keep: tuple[str, ...]) -> xr.Dataset:
    """The first value of any other swept dimension (averaging over it would mix physics)."""
    extra = [d for d in ds["done"].dims if d not in (*keep, "replica")]
    return ds.isel({d: 0 for d in extra}) if extra else ds


def plot_current_figure(ds: xr.Dataset, path: Path, fits: dict) -> Path:
    """The reshuffler figure to ``path``: ρ against J with the fits, and the running ρ.

    ``fits`` is :func:`fit_current_scaling`'s result (the paper's fit and the power law of the odds
    ρ/(1 − ρ)).
    """
    ds = _grid_only(ds, (CURRENT, P_VALUE))
    stats = replica_mean(ds)
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11, 5.4), dpi=110)
    left, right = fig.subplots(1, 2)
    j = ds[CURRENT].values
    p_values = ds[P_VALUE].values if P_VALUE in ds.dims else [None]
    for k, p in enumerate(p_values):
        sel = stats.sel({P_VALUE: p}) if p is not None else stats
        left.errorbar(
            dodge(j, k, len(p_values), log=True),  # side by side: their bars would hide each other
            sel["mean"].values,
            yerr=np.nan_to_num(sel["sem"].values),
            fmt="o",
            ms=4,
            capsize=2,
            label=f"p = {p:g}" if p is not None else "ρ",
        )
    paper = fits["paper_fit"]
    if paper_fit_constrained(paper):  # the report states no fit the points leave free
        grid = np.geomspace(j.min(), j.max(), 200)
        at_points = (
            _current_model(paper, stats[CURRENT])
            .broadcast_like(stats["mean"])
            .transpose(*stats["mean"].dims)
        )
        label, style = fit_label(
            f"paper's fit {CURRENT_LAW}", at_points, stats["mean"].values, stats["sem"].values
        )
        left.plot(grid, _current_model(paper, grid), color="b", ls=style, label=label)
    beta = fits["beta"]
    if constrained(beta["exponent"], beta["exponent_error"]):
        grid = np.geomspace(j.min(), j.max(), 200)
        left.plot(
            grid,
            odds_power_law(grid / CURRENT_UNIT, beta),
            "k--",
            lw=1,
            label=f"free fit ρ/(1−ρ) ∝ J^{beta['exponent']:.2f}",
        )
    left.set_title(f"ρ/(1−ρ) ∝ J^β: β = {_fmt(beta, 'exponent')} (paper 3/2)", fontsize=9)
    left.set_xscale("log")
    log_ticks(left.xaxis, j.min(), j.max())
    left.set_xlabel("current density J in the conduits (A/m²)")
    left.set_ylabel("correlation ρ (output vs input)")
    # below the axes: the fits' long labels inside would cover the points and curves
    left.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.15), ncols=2)
    if p_values[0] is not None:
        p_run = p_values[int(np.argmin(np.abs(np.asarray(p_values, float) - RUNNING_P)))]
    for value in j:
        where = {CURRENT: value}
        if p_values[0] is not None:
            where[P_VALUE] = p_run
        curve = running_mean(ds, where)
        if curve.sizes["time"] == 0:
            continue
        t = curve["time"].values * 1e6
        right.plot(t, curve["mean"].values, label=f"J = {value:.2g} A/m²")
        if np.isfinite(curve["sem"].values).any():
            right.fill_between(
                t, curve["mean"] - curve["sem"], curve["mean"] + curve["sem"], alpha=0.2
            )
    right.set_xlabel("time (µs)")
    right.set_ylabel("running correlation ρ")
    right.set_title(
        "running ρ" + (f", p = {p_run:g}" if p_values[0] is not None else ""), fontsize=9
    )
    right.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.15), ncols=2)
    fig.tight_layout()
    fig.savefig(path)
    return path


def plot_chamber_figure(ds: xr.Dataset, path: Path, fits: dict) -> Path:
    """The chamber-size figure to ``path``: ρ against the chamber diameter L with the fits.

    ``fits`` is :func:`fit_chamber_scaling`'s result (the paper's fit c_A + c_B/√L and the power law
    of the odds ρ/(1 − ρ)).
    """
    ds = _grid_only(ds, (CHAMBER,))
    stats = replica_mean(ds)
    length = ds[CHAMBER].values / LENGTH_UNIT
    from matplotlib.figure import Figure

    fig = Figure(figsize=(5.5, 4.2), dpi=110)
    ax = fig.add_subplot()
    ax.errorbar(
        length * 1e3,
        stats["mean"].values,
        yerr=np.nan_to_num(stats["sem"].values),
        fmt="o",
        capsize=2,
        label="sweep (replica mean ± s.e.)",
    )
    paper = fits["paper_fit"]
    if paper_fit_constrained(paper):  # the report states no fit the points leave free
        grid = np.linspace(length.min(), length.max(), 200)
        label, style = fit_label(
            "paper's fit c_A + c_B/√(L/1 µm)",
            _chamber_model(paper, length),
            stats["mean"].values,
            stats["sem"].values,
        )
        ax.plot(grid * 1e3, _chamber_model(paper, grid), color="b", ls=style, label=label)
    gamma = fits["gamma"]
    if constrained(gamma["exponent"], gamma["exponent_error"]):
        grid = np.linspace(length.min(), length.max(), 200)
        ax.plot(
            grid * 1e3,
            odds_power_law(grid, gamma),
            "k--",
            lw=1,
            label=f"free fit ρ/(1−ρ) ∝ L^{gamma['exponent']:.2f}",
        )
    ax.set_title(f"ρ/(1−ρ) ∝ L^γ: γ = {_fmt(fits['gamma'], 'exponent')} (paper −1/2)", fontsize=9)
    ax.set_xlabel("chamber diameter L (nm)")
    ax.set_ylabel("correlation ρ")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    return path


def plot_details(ds: xr.Dataset, x_dim: str, path: Path) -> Path:
    """p_out − p_in, the fullest chamber, the transit time and the lag scan against ``x_dim``.

    One series per p-value when p is swept.
    """
    from matplotlib.figure import Figure

    series = ds[P_VALUE].values if P_VALUE in ds.dims else [None]
    scale, label, log = (
        (1.0, "current density J (A/m²)", True)
        if x_dim == CURRENT
        else (1e9, "chamber diameter L (nm)", False)
    )
    fig = Figure(figsize=(11, 7.5), dpi=110)
    (ax_p, ax_n), (ax_t, ax_lag) = fig.subplots(2, 2)
    for k, p in enumerate(series):
        sub = ds.sel({P_VALUE: p}) if p is not None else ds
        ok = sub["done"] == 1
        x = sub[x_dim].values * scale
        diff = (sub["p_out"] - sub["p_in"]).where(ok).mean("replica")
        half = ((sub["p_out_high"] - sub["p_out_low"]) / 2).where(ok).mean("replica")
        tag = f"p = {p:g}" if p is not None else None
        ax_p.errorbar(
            dodge(x, k, len(series), log),  # side by side: their bars would hide each other
            diff.values,
            yerr=np.nan_to_num(half.values),
            fmt="o",
            ms=3,
            capsize=2,
            label=tag,
        )
        ax_n.plot(x, sub["max_occupancy"].where(ok).max("replica").values, "o-", ms=3, label=tag)
        ax_t.plot(
            x, sub["mean_transit_s"].where(ok).mean("replica").values * 1e9, "o-", ms=3, label=tag
        )
        if p is None or p == series[int(np.argmin(np.abs(np.asarray(series, float) - RUNNING_P)))]:
            rho0 = replica_mean(sub)["mean"].values
            best = replica_mean(sub, "correlation_max_lag")["mean"].values
            lag = sub["correlation_best_lag"].where(ok).median("replica").values
            ax_lag.plot(x, rho0, "o-", ms=3, label="ρ at lag 0")
            ax_lag.plot(x, best, "s--", ms=3, label="ρ at the lag of the largest |ρ|")
            for xi, yi, li in zip(x, best, lag, strict=True):
                if np.isfinite(yi) and np.isfinite(li):
                    ax_lag.annotate(
                        signed(float(li)),  # the replicas' median: may be a half
                        (xi, yi),
                        fontsize=7,
                        textcoords="offset points",
                        xytext=(0, 4),
                    )
    ax_p.axhline(0, color="k", lw=0.8)
    ax_p.set_ylabel("p_out − p_in\n(bars: p_out's 95 % interval)")
    x_all = ds[x_dim].values * scale
    if x_dim == CURRENT and x_all.min() <= PAPER_LOWEST_CURRENT <= x_all.max():
        # the paper's bound holds at its lowest current: drawn there, where the axis reaches it
        ax_n.plot(
            [PAPER_LOWEST_CURRENT],
            [PAPER_MAX_OCCUPANCY],
            "rv",
            ms=8,
            label=f"paper: ≤ {PAPER_MAX_OCCUPANCY} at J = 10¹⁰ A/m²",
        )
    ax_n.set_ylabel("fullest chamber (skyrmions)")
    ax_t.set_ylabel("mean transit time (ns)")
    drawn = [np.asarray(line.get_ydata(), float) for line in ax_t.lines]
    transit = np.concatenate(drawn) if drawn else np.empty(0)
    transit = transit[np.isfinite(transit) & (transit > 0)]
    if transit.size:
        ax_t.set_yscale("log")
        log_ticks(ax_t.yaxis, transit.min(), transit.max())
    # a lag ℓ pairs input bit k with read-out k + ℓ: one bit per injection interval
    ax_lag.set_ylabel("correlation ρ (numbers: its lag ℓ, bits)")
    for ax in (ax_p, ax_n, ax_t, ax_lag):
        ax.set_xlabel(label)
        if log:
            ax.set_xscale("log")
            log_ticks(ax.xaxis, x_all.min(), x_all.max())
    # one legend above the panels for the series they share (inside, it would cover points)
    handles, labels = ax_n.get_legend_handles_labels()
    top = 1.0
    if handles:
        fig.legend(handles, labels, loc="upper center", ncols=len(labels), fontsize=8)
        top = 0.95
    ax_lag.legend(fontsize=7)
    fig.tight_layout(rect=(0, 0, 1, top))
    fig.savefig(path)
    return path


#: where the exponents of this model are compared with the paper's
PAPER_DOCS = "docs/paper-reproduction.md"


def exponent_lines(result: dict) -> list[str]:
    """The free exponents of :func:`plot_sweep`'s ``result``, one line each, for a person.

    Each beside the paper's value, with where the two are compared (:data:`PAPER_DOCS`); an
    exponent the points do not fix is said to be absent.
    """
    lines = []
    for key, name, power, paper in (
        ("current", "beta", "J^β: β", "3/2"),
        ("chamber", "gamma", "L^γ: γ", "−1/2"),
    ):
        if key not in result:
            continue
        e = result[key][name]
        value = (
            f"{e['exponent']:.3f} ± {e['exponent_error']:.3f}"
            if constrained(e["exponent"], e["exponent_error"])
            else "none (the points do not constrain it)"
        )
        lines.append(
            f"ρ/(1−ρ) ∝ {power} = {value} over {e['n_points']} points with 0 < ρ < 1 (paper "
            f"{paper}; see {PAPER_DOCS} for what this model gives)"
        )
    return lines


def sweep_provenance(ds: xr.Dataset) -> dict[str, str]:
    """The provenance record of the files made from a sweep store (or stores drawn together).

    Parameters
    ----------
    ds : xarray.Dataset
        What :func:`open_sweep` or :func:`open_sweeps` returns.

    Returns
    -------
    dict of str to str
        The store's skygas version, root seed (a list for several stores), its fingerprint as
        ``config_hash``, its sweep file and base configuration as ``config_json``, and the
        command line (:func:`skygas.runs.provenance.provenance`).
    """
    from skygas.runs.provenance import provenance
    from skygas.runs.run_driver import fingerprint

    config = json.dumps(
        {
            "sweep_file": ds.attrs.get("sweep_file", ds.attrs.get("sweep_text", "")),
            "base_config_json": ds.attrs.get("base_config_json"),
        },
        sort_keys=True,
    )
    seed = ds.attrs.get("root_seed")
    seed = json.dumps(np.asarray(seed).tolist()) if seed is not None else None
    stores = ds.attrs.get("stores")
    return provenance(
        seed=seed,
        config_json=config,
        config_hash=ds.attrs.get("fingerprint") or fingerprint(config),
        skygas_version=ds.attrs.get("skygas_version"),
        source=json.dumps(list(stores)) if stores is not None else None,
    )


def write_point_table(ds: xr.Dataset, path: Path, record: dict[str, str] | None = None) -> Path:
    """``points.csv``: one row per point with at least one run done.

    Parameters
    ----------
    ds : xarray.Dataset
        The sweep.
    path : Path
        The CSV file (written through a temporary file).
    record : dict of str to str, optional
        The provenance, written first as ``# key: value`` lines (default:
        :func:`sweep_provenance`).

    Returns
    -------
    Path
        ``path``.
    """
    from skygas.runs.provenance import csv_header
    from skygas.runs.run_driver import write_atomic

    table = point_table(ds)
    rows = [row for row in table if row["replicas"] > 0]
    header = csv_header(record if record is not None else sweep_provenance(ds))

    def write(tmp: Path) -> None:
        with open(tmp, "w", newline="") as f:
            f.write(header)
            writer = csv.DictWriter(f, fieldnames=list(table[0]))
            writer.writeheader()
            writer.writerows({k: f"{v:.6g}" for k, v in row.items()} for row in rows)

    return write_atomic(path, write)


def plot_sweep(store: str | Path | xr.Dataset, out_dir: str | Path) -> dict:
    """Write the figures that fit the store's swept fields, and ``fits.json``.

    Parameters
    ----------
    store : str, Path or xarray.Dataset
        A sweep store, or the dataset :func:`open_sweep` (or :func:`open_sweeps`) returns.
    out_dir : str or Path
        The folder of the figures (created if needed).

    Returns
    -------
    dict
        The fits, per swept field, and the paths written.
    """
    from skygas.runs.run_driver import write_figure, write_json

    ds = store if isinstance(store, xr.Dataset) else open_sweep(store)
    out = Path(out_dir)
    dims = ds["done"].dims
    out.mkdir(parents=True, exist_ok=True)
    record = sweep_provenance(ds)
    result: dict = {"figures": []}

    def figure(name: str, draw) -> None:
        result["figures"].append(str(write_figure(out / name, draw, record)))

    paper_figures = ds.attrs.get("device", DEFAULT_DEVICE) == DEFAULT_DEVICE and (
        CURRENT in dims or CHAMBER in dims
    )
    if not paper_figures:  # any other sweep: each quantity against the swept fields
        from skygas.runs.provenance import csv_header
        from skygas.sweep.generic import (
            GENERIC_FIGURE,
            generic_caption,
            plot_generic,
            plotted,
            point_rows,
            write_points,
        )

        figure(GENERIC_FIGURE, lambda tmp: plot_generic(ds, tmp))
        result["points"] = point_rows(ds)
        result["plotted"] = plotted(ds)
        result["captions"] = {GENERIC_FIGURE: generic_caption(ds)}
        write_json(out / "fits.json", {**result, "provenance": record})
        write_points(ds, out / "points.csv", csv_header(record))
        return result

    if CURRENT in dims:
        grid = _grid_only(ds, (CURRENT, P_VALUE))
        result["current"] = fit_current_scaling(grid)
        fit = result["current"]["paper_fit"]
        fit["chi2_dof"] = paper_fit_chi2(grid, CURRENT, fit)
        figure("reshuffler.png", lambda tmp: plot_current_figure(ds, tmp, result["current"]))
        if "p_out_low" in ds:
            figure("reshuffler_details.png", lambda tmp: plot_details(grid, CURRENT, tmp))
    if CHAMBER in dims:
        grid = _grid_only(ds, (CHAMBER,))
        result["chamber"] = fit_chamber_scaling(grid)
        fit = result["chamber"]["paper_fit"]
        fit["chi2_dof"] = paper_fit_chi2(grid, CHAMBER, fit)
        figure("chamber_size.png", lambda tmp: plot_chamber_figure(ds, tmp, result["chamber"]))
        if "p_out_low" in ds:
            figure("chamber_size_details.png", lambda tmp: plot_details(grid, CHAMBER, tmp))
    write_json(out / "fits.json", {**result, "provenance": record})
    write_point_table(ds, out / "points.csv", record)
    return result
