"""``report.html`` of ``skygas infer``: the headline numbers, the self-check, the figures.

Every number comes from the summary (inference.json) and every figure draws the same numbers:
the MSD figure's horizontal line is the D of the headline, the force bands are the jackknife
errors the headline quotes.
"""

from __future__ import annotations

import html
import io
import math

import numpy as np

from skygas.inference.pipeline import Inference

TERM_NAMES = {
    "landscape": "landscape",
    "pair": "pair force",
    "material_pair": "the base material's pair law",
    "wall": "wall force",
    "drive": "drive (uniform force)",
}


def _png(fig) -> bytes:
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90, bbox_inches="tight")
    return buf.getvalue()


def _fmt(value, error, scale: float, unit: str, reason: str = "the data do not fix it") -> str:
    """``value`` (± ``error``) × ``scale`` in ``unit``, as the reports write numbers."""
    from skygas.core.quantities import format_value
    from skygas.outputs import headlines as H

    if value is None or not math.isfinite(value):
        return H.none(reason)
    err = None if error is None or not math.isfinite(error) else error * scale
    return format_value(value * scale, err, unit) or H.none(reason)


def _terms_row(s: dict) -> str:
    parts = []
    for term, c in s["model_selection"]["candidates"].items():
        name = TERM_NAMES[term]
        if c.get("fixed_by_user"):
            parts.append(f"{name}: kept (asked for)")
            continue
        gain = _fmt(c["delta_log_likelihood"], c["error"], 1, "nats")
        parts.append(f"{name}: {'kept' if c['kept'] else 'left out'}, {gain}")
    return "; ".join(parts) or "none: a free gas"


def _mid(fitted: dict | None, what: str) -> str:
    """A force at the middle of the range where the data fix it, with its error."""
    if not fitted or not fitted.get("fixed_range_m"):
        return "—"
    lo, hi = fitted["fixed_range_m"]
    r = np.asarray(fitted["r_m"])
    k = int(np.argmin(np.abs(r - 0.5 * (lo + hi))))
    return _fmt(fitted["force_N"][k], fitted["force_error_N"][k], 1, "N") + (
        f" at {what} {_length(r[k])}"
    )


def _length(metres: float) -> str:
    from skygas.core.quantities import format_value

    return format_value(metres, None, "m", digits=3) or "?"


def headline_rows(result: Inference) -> list[tuple[str, str]]:
    """The report's headline: label, value as text."""
    s = result.summary
    land = s["landscape"]
    check = s["consistency_check"]
    rows = []
    if check is not None:
        verdict = (
            "passed: runs of the model reproduce the movie's MSD(τ), g(r) and density map"
            if check["passed"]
            else "FAILED: " + "; ".join(_check_lines(check))
        )
        rows.append(("self-check of the model", verdict))
    rows += [
        (
            "diffusion constant D (from the noise)",
            _fmt(s["diffusion_constant"], s["diffusion_constant_error"], 1, "m²/s")
            + (
                ""
                if s.get("diffusion_constant_fixed_by_data", True)
                else " as read, NOT fixed: the frames are too coarse for the forces"
            ),
        ),
        (
            "Hall angle",
            _fmt(s["hall_angle"], s["hall_angle_error"], 180 / math.pi, "°")
            if s["hall_angle"] is not None
            else f"none ({s['hall_angle_note']})",
        ),
        (
            "localisation error",
            _fmt(s["localisation_error_m"], s["localisation_error_error_m"], 1, "m"),
        ),
        ("film", s["film"]["reason"]),
        ("forces the data show (held-out log-likelihood each adds)", _terms_row(s)),
        (
            "pinning rms; correlation length",
            _fmt(land["pinning_rms_kT"], land["pinning_rms_error_kT"], 1, "k_BT")
            + "; "
            + _fmt(land["pinning_correlation_length_m"], None, 1, "m"),
        ),
        (
            "share of the film sampled; well sampled",
            f"{100 * land['sampled_area_m2'] / land['film_area_m2']:.0f} %; "
            f"{100 * land['well_sampled_area_m2'] / land['film_area_m2']:.0f} %",
        ),
        ("pair force mid-range", _mid(s["pair"]["fitted"], "r =")),
        ("wall force mid-range", _mid(s["wall"]["fitted"], "d =")),
    ]
    if s["drive"] is not None:
        v = s["drive"]["velocity_m_s"]
        rows.append(("drift velocity of the drive", _fmt(math.hypot(*v), None, 1, "m/s")))
    cross = s["boltzmann_cross_check"]
    if cross and "rms_difference_kT" in cross:
        rows.append(
            (
                "landscape: forces against Boltzmann inversion",
                _fmt(cross["rms_difference_kT"], None, 1, "k_BT")
                + " rms apart"
                + (
                    f", correlation {cross['correlation']:.2f}"
                    if cross["correlation"] is not None
                    else " (one of them flat)"
                ),
            )
        )
    return rows


def _check_lines(check: dict) -> list[str]:
    from skygas.inference.selfcheck import summary_lines

    return summary_lines(check)


def report_html(result: Inference) -> str:
    """One self-contained HTML page: headline numbers and the figures."""
    from skygas.inference.files import record
    from skygas.outputs import headlines as H
    from skygas.outputs.report import Page

    s = result.summary
    page = Page("skygas infer — inferred particle model")
    rec = record(result)
    page.raw(
        f"<p>Made by <code class=command>{html.escape(rec['command_line'])}</code> from "
        f"{html.escape(str(result.tracks.source))}, with {html.escape(rec['written_by'])}.</p>"
    )
    headline = H.Results()
    headline.rows += headline_rows(result)
    headline.notes += s["notes"]
    page.headline(headline)
    page.heading("Figures")
    for png, caption in _figures(result):
        page.image(png, caption)
    page.heading("Provenance")
    page.table((k.replace("_", " "), f"<code>{html.escape(str(v))}</code>") for k, v in rec.items())
    return page.html()


def _figures(result: Inference) -> list[tuple[bytes, str]]:
    from matplotlib.figure import Figure

    s = result.summary
    out = []
    check = s["consistency_check"]
    if check is not None:
        fig = Figure(figsize=(5, 3.4))
        ax = fig.add_subplot()
        m = check["msd"]
        tau = np.array(m["lag_time_s"])
        ax.errorbar(
            tau, m["movie_msd_over_4tau_m2_s"], m["movie_error_m2_s"], fmt="o", label="movie"
        )
        ax.errorbar(
            tau * 1.05,
            m["model_msd_over_4tau_m2_s"],
            m["model_error_m2_s"],
            fmt="s",
            label="model (skygas run)",
        )
        ax.axhline(s["diffusion_constant"], color="k", lw=0.8, label="D (from the noise)")
        ax.set_xscale("log")
        ax.set_xlabel("lag τ [s]")
        ax.set_ylabel("MSD/4τ [m²/s]")
        ax.legend(fontsize=7)
        out.append(
            (
                _png(fig),
                "MSD(τ)/4τ of the movie and of a run of the model, as the movie would have seen "
                "it (localisation error included), with the free D from the noise of the steps.",
            )
        )
    fmap = result.map
    g = fmap.grid
    ext = (g.x[0] * 1e6, g.x[-1] * 1e6, g.y[0] * 1e6, g.y[-1] * 1e6)
    panels = [
        (np.where(fmap.sampled, fmap.u, np.nan), "landscape from the forces [k_BT]"),
        (np.where(fmap.sampled, fmap.error, np.nan), "its jackknife error [k_BT]"),
    ]
    if result.boltzmann is not None:
        panels.append(
            (np.where(fmap.sampled, result.boltzmann, np.nan), "−ln ρ, Boltzmann inversion [k_BT]")
        )
    fig = Figure(figsize=(4.2 * len(panels), 3.6))
    for k, (data, title) in enumerate(panels):
        ax = fig.add_subplot(1, len(panels), k + 1)
        im = ax.imshow(data, origin="lower", extent=ext, cmap="viridis")
        if fmap.well_sampled.any():
            ax.contour(
                g.x * 1e6,
                g.y * 1e6,
                fmap.well_sampled.astype(float),
                [0.5],
                colors="w",
                linewidths=0.8,
            )
        fig.colorbar(im, ax=ax)
        ax.set_title(title, fontsize=8)
        ax.set_xlabel("x [µm]")
        ax.set_ylabel("y [µm]")
    out.append(
        (
            _png(fig),
            "The landscape where the film was sampled, its error, and (in equilibrium) −ln ρ of "
            "the positions for comparison; the white line encloses the well-sampled area.",
        )
    )
    for term, what in (("pair", "pair"), ("wall", "wall")):
        fitted = s[term]["fitted"]
        if not fitted:
            continue
        fig = Figure(figsize=(5, 3.4))
        ax = fig.add_subplot()
        r = np.array(fitted["r_m"]) * 1e9
        f = np.array(fitted["force_N"]) * 1e12
        e = np.array(fitted["force_error_N"]) * 1e12
        (line,) = ax.plot(r, f, label=f"{what} force")
        ax.fill_between(
            r, f - e, f + e, color=line.get_color(), alpha=0.25, label="± jackknife error"
        )
        if fitted["fixed_range_m"]:
            lo, hi = (v * 1e9 for v in fitted["fixed_range_m"])
            ax.axvspan(lo, hi, color="0.9", zorder=0, label="fixed by the data")
        ax.axhline(0, color="k", lw=0.5)
        ax.set_xlabel("distance [nm]" if what == "pair" else "distance to the edge [nm]")
        ax.set_ylabel("force [pN]")
        ax.legend(fontsize=7)
        out.append(
            (
                _png(fig),
                f"The {what} force the steps show, with its jackknife error; shaded: where the "
                "data fix it (the error within 5 % of it).",
            )
        )
    if check is not None and check["pair_correlation"]["bins_compared"]:
        c = check["pair_correlation"]
        fig = Figure(figsize=(5, 3.4))
        ax = fig.add_subplot()
        r = np.array(c["r_m"]) * 1e9
        ax.errorbar(r, c["movie_g"], c["movie_error"], fmt="o", ms=3, label="movie")
        ax.errorbar(r, c["model_g"], c["model_error"], fmt="s", ms=3, label="model (skygas run)")
        ax.set_xlabel("r [nm]")
        ax.set_ylabel("g(r)")
        ax.legend(fontsize=7)
        caption = "The pair correlation g(r) of the movie and of a run of the model."
        if not c.get("judged", True):
            caption += (
                " Shown, not judged: the model has no pair law, and the errors of g(r) over "
                "blocks of time are too small for skyrmions that meet again and again."
            )
        out.append((_png(fig), caption))
    return out
