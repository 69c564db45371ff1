"""The files of ``skygas infer``: inference.json, landscape.nc, model.toml, report.html.

Each is written atomically (:func:`skygas.runs.run_driver.write_atomic`), so an interrupted
inference leaves no partial file; each carries the provenance record (version, command line,
the input's hash).
"""

from __future__ import annotations

import html
import io
import math
from pathlib import Path

import numpy as np

from skygas.inference.laws import potential
from skygas.inference.pipeline import Inference
from skygas.runs.provenance import provenance


def _record(result: Inference) -> dict:
    return provenance(
        seed=result.summary["input"]["seed"],
        config_hash=result.summary["input"]["sha256"][:16],
        source=result.tracks.source,
    )


def landscape_dataset(result: Inference):
    """U = −ln ρ and its uncertainty [k_BT] on x, y [m], Φ, the pinning and the sampled mask."""
    import xarray as xr

    g = result.landscape.grid
    record = _record(result)
    return xr.Dataset(
        {
            "U": (("y", "x"), result.landscape.u, {"units": "k_BT", "long_name": "U = -ln rho"}),
            "U_error": (
                ("y", "x"),
                result.landscape.error,
                {"units": "k_BT", "long_name": "bootstrap standard error of U"},
            ),
            "crowding": (
                ("y", "x"),
                result.crowding,
                {"units": "k_BT", "long_name": "Phi, the neighbours' mean push (force balance)"},
            ),
            "pinning": (
                ("y", "x"),
                result.pinning,
                {"units": "k_BT", "long_name": "U + Phi minus the wall profile W(d)"},
            ),
            "U_error_across_skyrmions": (
                ("y", "x"),
                result.landscape.error_across_skyrmions
                if result.landscape.error_across_skyrmions is not None
                else np.full(result.landscape.u.shape, np.nan),
                {"units": "k_BT", "long_name": "standard error of U, bootstrap over the tracks"},
            ),
            "well_sampled": (("y", "x"), result.landscape.well_sampled.astype(np.int8)),
            "fixed_across_skyrmions": (
                ("y", "x"),
                result.landscape.fixed_across_skyrmions.astype(np.int8),
            ),
        },
        coords={"x": ("x", g.x, {"units": "m"}), "y": ("y", g.y, {"units": "m"})},
        attrs={
            **record,
            "kernel_width_m": result.landscape.bandwidth,
            "temperature_K": result.summary["input"]["temperature_K"],
        },
    )


def model_text_sections(result: Inference) -> tuple[dict, list[str], dict[str, str]]:
    """The model file's extra tables, header lines and comments."""
    s = result.summary
    record = _record(result)
    sections = {
        "pinning": dict(s["model"]["pinning_as_disorder"]),
        "inference": {
            "diffusion_constant": s["diffusion_constant"],
            "diffusion_constant_error": s["diffusion_constant_error"],
            "hall_angle": s["hall_angle"],
            "hall_angle_error": s["hall_angle_error"],
            "temperature": s["input"]["temperature_K"],
            "pair_range_fixed_by_data": list(s["pair"]["range_fixed_by_data_m"] or []),
            "wall_range_fixed_by_data": list(s["wall"]["sampled_range_m"] or []),
        },
        "provenance": {k: v for k, v in record.items() if k != "config_json"},
    }
    header = [
        "A particle model inferred from tracked skyrmions by `skygas infer` (docs/inference.md).",
        'Use it as --material FILE or material = "FILE" in any device.',
    ]
    comments = {
        "pinning": "The pinning landscape as a random landscape of the rms and correlation\n"
        "length of the inferred map (the map whose model density matches the movie's), for\n"
        "a device of any geometry: copy this table as a [[potentials]] table into a\n"
        "configuration. The map itself is landscape.nc (variable pinning).",
        "inference": "What the data measured (SI; angle in rad).",
    }
    return sections, header, comments


def write_outputs(result: Inference, out) -> list[Path]:
    """Write the four files into ``out``; returns their paths."""
    from skygas.calibration.model_file import write_model
    from skygas.runs.run_driver import write_atomic, write_json, write_netcdf

    out = Path(out)
    # everything is made before the first file is written: a failure leaves no file behind
    summary = {**result.summary, "provenance": _record(result)}
    dataset = landscape_dataset(result)
    text = report_html(result)
    sections, header, comments = model_text_sections(result)
    out.mkdir(parents=True, exist_ok=True)
    paths = [write_model(out / "model.toml", result.material, sections, header, comments)]
    paths.append(write_json(out / "inference.json", summary))
    paths.append(write_netcdf(dataset, out / "landscape.nc"))
    paths.append(
        write_atomic(out / "report.html", lambda tmp: tmp.write_text(text, encoding="utf-8"))
    )
    return paths


def _png(fig) -> bytes:
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90, bbox_inches="tight")
    return buf.getvalue()


def _fmt(value, error, scale: float, unit: str) -> str:
    """``value`` (± ``error``) × ``scale`` in ``unit``, as the reports write numbers."""
    from skygas.core.quantities import format_value
    from skygas.outputs import headlines as H

    if value is None or not math.isfinite(value):
        return H.none("the data do not fix it")
    err = None if error is None or not math.isfinite(error) else error * scale
    return format_value(value * scale, err, unit) or H.none("the data do not fix it")


def _mid_range(table: dict | None) -> str:
    """The pair force ± its error in the middle of the range the data fix, as a headline."""
    if not table:
        return "—"
    k = len(table["r_m"]) // 2
    return _fmt(
        table["force_N"][k],
        table["force_error_N"][k],
        1e12,
        f"pN at {table['r_m'][k] * 1e9:.0f} nm",
    )


def report_html(result: Inference) -> str:
    """One self-contained HTML page: headline numbers and the figures."""
    from matplotlib.figure import Figure
    from matplotlib.ticker import NullFormatter

    s = result.summary
    figs = []
    # MSD/4τ
    fig = Figure(figsize=(5, 3.4))
    ax = fig.add_subplot()
    ax.errorbar(
        result.msd_lag_time,
        result.msd_over_4tau,
        result.msd_over_4tau_error,
        fmt="o",
        label="measured",
    )
    if result.model_msd_over_4tau is not None:
        ax.plot(result.msd_lag_time, result.model_msd_over_4tau, "s--", label="model (skygas run)")
    ax.axhline(s["diffusion_constant"], color="k", lw=0.8, label="D (short-lag fit)")
    ax.set_xscale("log")
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel("lag τ [s]")
    ax.set_ylabel("MSD/4τ [m²/s]")
    ax.legend(fontsize=7)
    figs.append(("Mean-squared displacement", _png(fig)))
    # landscape and uncertainty
    g = result.landscape.grid
    fig = Figure(figsize=(9, 3.6))
    ext = (g.x[0] * 1e6, g.x[-1] * 1e6, g.y[0] * 1e6, g.y[-1] * 1e6)
    for k, (data, title) in enumerate(
        (
            (
                np.where(result.landscape.well_sampled, result.pinning, np.nan),
                "pinning U − W(d) [k_BT], well sampled",
            ),
            (result.landscape.error, "standard error of U [k_BT]"),
        )
    ):
        ax = fig.add_subplot(1, 2, k + 1)
        im = ax.imshow(data, origin="lower", extent=ext, cmap="viridis")
        fig.colorbar(im, ax=ax)
        ax.set_title(title, fontsize=8)
        ax.set_xlabel("x [µm]")
        ax.set_ylabel("y [µm]")
    figs.append(("Landscape", _png(fig)))
    # g(r)
    ibi = result.ibi
    fig = Figure(figsize=(9, 3.4))
    ax = fig.add_subplot(1, 2, 1)
    ax.errorbar(ibi.r * 1e9, ibi.g, ibi.g_error, fmt="ko", ms=3, label="measured")
    for n, (gs, _) in enumerate(ibi.simulated):
        ax.plot(ibi.r * 1e9, gs, label=f"model, iteration {n + 1}")
    if ibi.fixed_range:
        ax.axvspan(ibi.fixed_range[0] * 1e9, ibi.fixed_range[1] * 1e9, color="0.9")
    ax.set_xlabel("r [nm]")
    ax.set_ylabel("g(r)")
    ax.legend(fontsize=6)
    ax = fig.add_subplot(1, 2, 2)
    if ibi.coef is not None and ibi.fixed_range:
        r = np.linspace(ibi.fixed_range[0], ibi.fixed_range[1], 100)
        f, f_err = ibi.force(r)
        r = r * 1e9
        ax.plot(r, potential(ibi.coef, r), label="pair V(r) [k_BT]")
        # per 10 nm, so that force and potential share the axis; the band is ±1 standard error
        (line,) = ax.plot(r, f * 1e-8, label="pair force ± SE [k_BT/10 nm]")
        ax.fill_between(
            r, (f - f_err) * 1e-8, (f + f_err) * 1e-8, color=line.get_color(), alpha=0.25
        )
    w = result.wall
    if w.coef is not None and w.sampled_range:
        d = np.linspace(w.sampled_range[0], w.sampled_range[1], 100) * 1e9
        ax.plot(d, potential(w.coef, d), "--", label="wall W(d) [k_BT]")
        ax.errorbar(
            w.d[w.sampled] * 1e9,
            w.w[w.sampled],
            w.error[w.sampled],
            fmt=".",
            ms=3,
            label="wall, measured",
        )
    ax.set_xlabel("distance [nm] (sampled range only)")
    ax.legend(fontsize=6)
    figs.append(("Pair and wall potentials", _png(fig)))
    land = s["landscape"]
    rows = [
        (
            "diffusion constant D",
            _fmt(s["diffusion_constant"], s["diffusion_constant_error"], 1, "m²/s"),
        ),
        (
            "systematic error of D (30 % of the crowding correction)",
            _fmt(s["diffusion_constant_systematic_error"], None, 1, "m²/s"),
        ),
        (
            "D as the MSD fit reads it, before the crowding correction",
            _fmt(s["diffusion_constant_as_read"], s["diffusion_constant_as_read_error"], 1, "m²/s"),
        ),
        ("Hall angle", _fmt(s["hall_angle"], s["hall_angle_error"], 180 / math.pi, "°")),
        (
            "localisation error",
            _fmt(s["localisation_error_m"], s["localisation_error_error_m"], 1e9, "nm"),
        ),
        ("pinning rms", _fmt(s["landscape"]["pinning_rms_kT"], None, 1, "k_BT")),
        (
            "pinning correlation length",
            _fmt(s["landscape"]["pinning_correlation_length_m"], None, 1e9, "nm"),
        ),
        ("kernel width", _fmt(s["landscape"]["kernel_width_m"], None, 1e9, "nm")),
        (
            "share of the film well sampled; fixed across skyrmions",
            f"{100 * land['well_sampled_area_m2'] / land['film_area_m2']:.0f} %; "
            f"{100 * land['area_fixed_across_skyrmions_m2'] / land['film_area_m2']:.0f} %",
        ),
        (
            "pair range fixed by data",
            "—"
            if not ibi.fixed_range
            else f"{ibi.fixed_range[0] * 1e9:.0f}–{ibi.fixed_range[1] * 1e9:.0f} nm",
        ),
        ("pair force mid-range", _mid_range(s["pair"]["force_over_fixed_range"])),
        (
            "wall range fixed by data",
            "—"
            if not w.sampled_range
            else f"{w.sampled_range[0] * 1e9:.0f}–{w.sampled_range[1] * 1e9:.0f} nm",
        ),
        ("IBI χ² per iteration", ", ".join(f"{c:.2f}" for c in ibi.chi2) or "—"),
    ]
    from skygas.outputs import headlines as H
    from skygas.outputs.report import Page

    page = Page("skygas infer — inferred particle model")
    record = _record(result)
    page.raw(
        f"<p>Made by <code class=command>{html.escape(record['command_line'])}</code> from "
        f"{html.escape(str(result.tracks.source))}, with {html.escape(record['written_by'])}.</p>"
    )
    headline = H.Results()
    headline.rows += rows
    page.headline(headline)
    page.heading("Figures")
    captions = {
        "Mean-squared displacement": "MSD(τ)/4τ of the tracks against the lag, with the "
        "short-lag D and the model's own MSD(τ)/4τ (the consistency check).",
        "Landscape": "The inferred pinning landscape where it is well sampled, and its "
        "standard error (block bootstrap), in k_BT.",
        "Pair and wall potentials": "g(r) measured and simulated at each IBI iteration (the range "
        "the data fix shaded), and the pair and wall potentials over the distances sampled.",
    }
    for title, png in figs:
        page.image(png, captions.get(title, title))
    page.heading("Provenance")
    page.table(
        (k.replace("_", " "), f"<code>{html.escape(str(v))}</code>") for k, v in record.items()
    )
    return page.html()
