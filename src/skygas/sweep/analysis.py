"""Analyses of a sweep store (paper, "Skyrmion Reshuffler", scaling after eq. (corrscale)).

- ρ against the conduit current density J, with the paper's fit ρ = c_A/(c_B + J^(−3/2)) and a
  free exponent β in ρ/(1 − ρ) ∝ J^β (the paper argues β = 3/2);
- ρ against the chamber diameter L, with ρ = c_A + c_B/√L and a free exponent γ in
  ρ/(1 − ρ) ∝ L^γ (the paper argues γ = −1/2);
- replica means with standard errors, for the points and for the running-correlation curves.

J is fitted in units of J₀ = 10¹¹ A/m² and L in µm, so c_A and c_B are O(1) numbers.
Fits weight each point by its replica standard error when every point has one; a free
exponent's uncertainty is the least-squares one, scaled by the reduced χ² when there are more
points than parameters.
"""

from __future__ import annotations

import json

import numpy as np
import xarray as xr

CURRENT = "current_density"
P_VALUE = "signal_p"
CHAMBER = "device_chamber_diameter"
CURRENT_UNIT = 1e11  # A/m²
LENGTH_UNIT = 1e-6  # m


def replica_mean(ds: xr.Dataset, name: str = "correlation") -> xr.Dataset:
    """Mean, standard error and count over ``replica`` of ``name`` (runs not done ignored)."""
    values = ds[name].where(ds["done"] == 1)
    n = values.count("replica")
    mean = values.mean("replica", skipna=True)
    sem = values.std("replica", ddof=1, skipna=True) / np.sqrt(n)
    return xr.Dataset({"mean": mean, "sem": sem.where(n > 1), "n": n})


def _table(ds: xr.Dataset, name: str = "correlation") -> dict[str, np.ndarray]:
    """One row per point (all point dimensions flattened): coordinates, mean, sem."""
    stats = replica_mean(ds, name)
    dims = list(stats["mean"].dims)
    flat = stats.stack(_row=dims)
    table = {k: np.asarray(flat[k].values) for k in ("mean", "sem", "n")}
    for dim in json.loads(ds.attrs.get("fields_json", "{}")):
        coord = ds[dim].reset_coords(drop=True).broadcast_like(stats["mean"])
        table[dim] = np.asarray(coord.stack(_row=dims).values)
    return table


def _weights(sigma: np.ndarray) -> np.ndarray | None:
    ok = np.isfinite(sigma) & (sigma > 0)
    return 1.0 / sigma if ok.all() and len(sigma) else None


def _linear_fit(x, y, sigma) -> tuple[np.ndarray, np.ndarray]:
    """Weighted least squares y = a + b x: ([a, b], their standard errors)."""
    w = _weights(sigma)
    w = np.ones_like(x) if w is None else w
    design = np.column_stack([np.ones_like(x), x]) * w[:, None]
    coef, *_ = np.linalg.lstsq(design, y * w, rcond=None)
    cov = np.linalg.pinv(design.T @ design)
    dof = len(x) - 2
    if dof > 0:
        chi2 = float(np.sum(((y - (coef[0] + coef[1] * x)) * w) ** 2)) / dof
        if _weights(sigma) is None or chi2 > 1:
            cov = cov * chi2
    return coef, np.sqrt(np.diag(cov))


#: Per-point columns of :func:`point_table`: (stored quantity, how replicas are combined).
POINT_COLUMNS = (
    ("correlation", "mean"),
    ("correlation_max_lag", "mean"),
    ("correlation_best_lag", "median"),
    ("p_in", "mean"),
    ("p_out", "mean"),
    ("p_out_low", "min"),
    ("p_out_high", "max"),
    ("max_occupancy", "max"),
    ("mean_transit_s", "mean"),
    ("median_transit_s", "mean"),
    ("n_skipped", "mean"),
    ("wall_escapes", "sum"),
    ("simulated_time_s", "mean"),
    ("time_step_s", "mean"),
    ("wall_time_s", "sum"),
)


def point_table(ds: xr.Dataset) -> list[dict]:
    """One row per swept point: its coordinates, ρ's replica mean and error, and the other figures.

    ρ's replica mean and standard error, and the other figures of :data:`POINT_COLUMNS` combined
    over the finished replicas (``max`` for the occupancy: the fullest chamber seen; ``min``/``max``
    for the ends of p_out's 95 % intervals; the largest |p_out − p_in| relative to its interval as
    ``p_out_worst_z``).
    """
    done = ds["done"] == 1
    rows = []
    stats = _table(ds)
    combined = {}
    for name, how in POINT_COLUMNS:
        if name not in ds:
            continue
        values = ds[name].where(done)
        combined[name] = (
            getattr(values, how)("replica", skipna=True)
            if how != "median"
            else values.median("replica", skipna=True)
        )
        combined[name] = (
            np.asarray(combined[name].stack(_row=list(combined[name].dims)).values)
            if combined[name].dims
            else np.atleast_1d(combined[name].values)
        )
    if {"p_in", "p_out", "p_out_low", "p_out_high"} <= set(ds.data_vars):
        half = (ds["p_out_high"] - ds["p_out_low"]) / 2
        z = (abs(ds["p_out"] - ds["p_in"]) / half).where(done).max("replica", skipna=True)
        combined["p_out_worst_z"] = (
            np.asarray(z.stack(_row=list(z.dims)).values) if z.dims else np.atleast_1d(z.values)
        )
    for i in range(len(stats["mean"])):
        row = {k: float(v[i]) for k, v in stats.items() if k not in ("mean", "sem", "n")}
        row.update(
            rho=float(stats["mean"][i]), rho_sem=float(stats["sem"][i]), replicas=int(stats["n"][i])
        )
        row.update({k: float(v[i]) for k, v in combined.items()})
        rows.append(row)
    return rows


def odds_power_law(x: np.ndarray, fit: dict) -> np.ndarray:
    """ρ of the fitted ρ/(1 − ρ) = exp(prefactor_log) x^exponent (:func:`power_law_exponent`)."""
    odds = np.exp(fit["prefactor_log"]) * np.asarray(x, float) ** fit["exponent"]
    return odds / (1 + odds)


def power_law_exponent(x: np.ndarray, rho: np.ndarray, rho_sem: np.ndarray) -> dict:
    """Free exponent in ρ/(1 − ρ) ∝ x^e from the points with 0 < ρ < 1."""
    ok = np.isfinite(rho) & (rho > 0) & (rho < 1) & np.isfinite(x) & (x > 0)
    if ok.sum() < 2:
        return {"exponent": float("nan"), "exponent_error": float("nan"), "n_points": int(ok.sum())}
    r = rho[ok]
    sigma = rho_sem[ok] / (r * (1 - r))
    coef, err = _linear_fit(np.log(x[ok]), np.log(r / (1 - r)), sigma)
    return {
        "exponent": float(coef[1]),
        "exponent_error": float(err[1]),
        "prefactor_log": float(coef[0]),
        "n_points": int(ok.sum()),
    }


def _paper_current_fit(x, rho, sem) -> dict:
    """ρ = c_A/(c_B + x^(−3/2)), x = J/J₀, with c_A, c_B ≥ 0 (no pole inside the data)."""
    from scipy.optimize import curve_fit

    ok = np.isfinite(rho) & np.isfinite(x) & (x > 0)
    if ok.sum() < 2:
        return {"c_A": float("nan"), "c_B": float("nan")}

    def model(x, c_a, c_b):
        return c_a / (c_b + x**-1.5)

    w = _weights(sem[ok])
    try:
        popt, pcov = curve_fit(
            model,
            x[ok],
            rho[ok],
            p0=(1.0, 1.0),
            sigma=None if w is None else sem[ok],
            absolute_sigma=w is not None,
            bounds=(0.0, np.inf),
            max_nfev=20000,
        )
    except (RuntimeError, ValueError):
        return {"c_A": float("nan"), "c_B": float("nan")}
    dof = int(ok.sum()) - 2
    if w is not None and dof > 0:  # as for the free exponents: scale by χ²/dof when above 1
        chi2 = float(np.sum(((rho[ok] - model(x[ok], *popt)) / sem[ok]) ** 2)) / dof
        pcov = pcov * max(chi2, 1.0)
    err = np.sqrt(np.diag(pcov))
    return {
        "c_A": float(popt[0]),
        "c_A_error": float(err[0]),
        "c_B": float(popt[1]),
        "c_B_error": float(err[1]),
        "J_unit_A_m2": CURRENT_UNIT,
        "model": "rho = c_A / (c_B + (J/J_unit)^(-3/2))",
    }


def fit_current_scaling(ds: xr.Dataset) -> dict:
    """ρ(J): the paper's fit and the free exponent β, over all points and per p-value."""
    t = _table(ds)
    x = t[CURRENT] / CURRENT_UNIT
    per_p: dict[str, dict] = {}
    out = {
        "paper_fit": _paper_current_fit(x, t["mean"], t["sem"]),
        "beta": power_law_exponent(x, t["mean"], t["sem"]),
        "paper_beta": 1.5,
        "per_p": per_p,
    }
    if P_VALUE in t:
        for p in np.unique(t[P_VALUE]):
            sel = t[P_VALUE] == p
            per_p[f"{float(p):g}"] = {
                "paper_fit": _paper_current_fit(x[sel], t["mean"][sel], t["sem"][sel]),
                "beta": power_law_exponent(x[sel], t["mean"][sel], t["sem"][sel]),
            }
    return out


def fit_chamber_scaling(ds: xr.Dataset) -> dict:
    """ρ(L): ρ = c_A + c_B/√L (L in µm) and the free exponent γ of ρ/(1 − ρ) ∝ L^γ."""
    t = _table(ds)
    length = t[CHAMBER] / LENGTH_UNIT
    ok = np.isfinite(t["mean"])
    paper: dict[str, float | str] = {"c_A": float("nan"), "c_B": float("nan")}
    if ok.sum() >= 2:
        coef, err = _linear_fit(1 / np.sqrt(length[ok]), t["mean"][ok], t["sem"][ok])
        paper = {
            "c_A": float(coef[0]),
            "c_A_error": float(err[0]),
            "c_B": float(coef[1]),
            "c_B_error": float(err[1]),
            "L_unit_m": LENGTH_UNIT,
            "model": "rho = c_A + c_B / sqrt(L/L_unit)",
        }
    return {
        "paper_fit": paper,
        "gamma": power_law_exponent(length, t["mean"], t["sem"]),
        "paper_gamma": -0.5,
    }


def running_mean(ds: xr.Dataset, where: dict | None = None, points: int = 200) -> xr.Dataset:
    """Running correlation averaged over replicas on a common time grid (mean, sem).

    ``where`` selects one point (``{"current_density": 3.8e11, "signal_p": 0.62}``); each
    replica's curve is interpolated onto ``points`` times up to the shortest curve's end.
    """
    sub = ds.sel(where or {})
    rho = np.asarray(sub["running_rho"].values).reshape(-1, sub.sizes["running"])
    times = np.asarray(sub["running_time"].values).reshape(-1, sub.sizes["running"])
    curves = [
        (t[np.isfinite(t) & np.isfinite(r)], r[np.isfinite(t) & np.isfinite(r)])
        for t, r in zip(times, rho, strict=True)
    ]
    curves = [c for c in curves if len(c[0]) >= 2]
    if not curves:
        return xr.Dataset(
            {"mean": ("time", np.empty(0)), "sem": ("time", np.empty(0))},
            coords={"time": np.empty(0)},
        )
    end = min(t[-1] for t, _ in curves)
    grid = np.linspace(max(t[0] for t, _ in curves), end, points)
    stack = np.array([np.interp(grid, t, r) for t, r in curves])
    sem = stack.std(0, ddof=1) / np.sqrt(len(stack)) if len(stack) > 1 else np.full(points, np.nan)
    return xr.Dataset(
        {"mean": ("time", stack.mean(0)), "sem": ("time", sem)},
        coords={"time": ("time", grid, {"units": "s"})},
    )
