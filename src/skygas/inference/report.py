"""``report.html`` of ``skygas infer``: the quality checks, the headline numbers, the figures.

The headline starts with the inference's checks against their stated tolerances
(:func:`skygas.inference.selfcheck.quality_checks`: the frames against the motion, the
self-check's comparisons), each ``passed`` or ``FAILED``. Every number comes from the summary
(inference.json) and every figure draws the same numbers: the MSD figure's horizontal lines are
the Ds of the headline (the model's, and the short-lag MSD fit's), the force bands are the
jackknife errors the headline quotes.
"""

from __future__ import annotations

import html
import io
import math

import numpy as np

from skygas.inference.diffusion import FIT_LAGS
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


def check_rows(s: dict) -> list[tuple[str, str]]:
    """The headline's first rows: each quality check, ``passed`` or ``FAILED``, with its numbers."""
    from skygas.inference.selfcheck import quality_checks

    rows = [
        (c["name"], ("passed: " if c["passed"] else "FAILED: ") + c["what"])
        for c in quality_checks(s)
    ]
    check = s["consistency_check"]
    if check is None:
        rows.append(("self-check of the model", "not run (--check-frames 0)"))
    elif not check["pair_correlation"].get("judged", True):
        rows.append(
            (
                "self-check: g(r)",
                "shown, not judged: the model has no pair law (g(r) then carries only the "
                "landscape, which the density map tests)",
            )
        )
    return rows


def _corrected(s: dict) -> bool:
    """Whether the model's D is the steps' reading corrected for the frame interval."""
    return bool(s["sampling_correction"]["applied"])


def headline_rows(result: Inference) -> list[tuple[str, str]]:
    """The report's headline: label, value as text; the quality checks first."""
    s = result.summary
    land = s["landscape"]
    rows = check_rows(s)
    rows += [
        (
            "diffusion constant D (from the noise"
            + (", corrected for the frame interval)" if _corrected(s) else ")"),
            _fmt(s["diffusion_constant"], s["diffusion_constant_error"], 1, "m²/s")
            + (
                ""
                if s.get("diffusion_constant_fixed_by_data", True)
                else " as read, NOT fixed: the frames are too coarse for the forces"
            ),
        ),
    ]
    if _corrected(s):
        rows.append(
            (
                "D as the steps read it (before the correction)",
                _fmt(
                    s["diffusion_constant_as_read"],
                    s["diffusion_constant_as_read_error"],
                    1,
                    "m²/s",
                ),
            )
        )
    rows += [
        (
            f"D of the short-lag MSD fit (lags 1–{FIT_LAGS}, 4σ² + 4Dτ + cτ²)",
            _fmt(s["diffusion_constant_msd_fit"], s["diffusion_constant_msd_fit_error"], 1, "m²/s"),
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


#: The labels of the MSD figure's horizontal lines (:func:`msd_lines`).
MSD_MODEL_LINE = "D of the model (from the noise of the steps)"
MSD_CORRECTED_LINE = "D of the model (from the noise, corrected for the frame interval)"
MSD_AS_READ_LINE = "D as the steps read it (before the correction)"
MSD_FIT_LINE = f"D of the short-lag MSD fit (lags 1–{FIT_LAGS})"


def msd_lines(s: dict) -> list[tuple[str, float, str]]:
    """The Ds the MSD figure draws as horizontal lines: (label, D [m²/s], line style).

    The model's D; where a correction for the frame interval moved it, also D as the steps
    read it; and the D of the short-lag fit of the movie's MSD, 4σ² + 4Dτ + cτ² through lags
    1 … :data:`~skygas.inference.diffusion.FIT_LAGS` (its slope, which the movie's MSD(τ)/4τ
    approaches only where the localisation error's 4σ²/4τ and the drift's cτ/4 are small).
    """
    lines = [
        (
            MSD_CORRECTED_LINE if _corrected(s) else MSD_MODEL_LINE,
            s["diffusion_constant"],
            "k-",
        )
    ]
    if _corrected(s):
        lines.append((MSD_AS_READ_LINE, s["diffusion_constant_as_read"], "k:"))
    if s.get("diffusion_constant_msd_fit") is not None:
        lines.append((MSD_FIT_LINE, s["diffusion_constant_msd_fit"], "k--"))
    return [line for line in lines if line[1] is not None and math.isfinite(line[1])]


def msd_figure(s: dict) -> tuple[bytes, str]:
    """MSD(τ)/4τ of the movie and of the model's run, the Ds as lines; its caption (verdict)."""
    from matplotlib.figure import Figure

    from skygas.inference.selfcheck import comparison_checks

    m = s["consistency_check"]["msd"]
    fig = Figure(figsize=(5.4, 3.6))
    ax = fig.add_subplot()
    tau = np.array(m["lag_time_s"])
    ax.errorbar(tau, m["movie_msd_over_4tau_m2_s"], m["movie_error_m2_s"], fmt="o", label="movie")
    # the model's points a little to the right: their error bars would hide the movie's
    ax.errorbar(
        tau * 1.05,
        m["model_msd_over_4tau_m2_s"],
        m["model_error_m2_s"],
        fmt="s",
        label="model (skygas run)",
    )
    for label, value, style in msd_lines(s):
        ax.axhline(value, color=style[0], ls=style[1:], lw=0.8, label=label)
    ax.set_xscale("log")
    ax.set_xlabel("lag τ [s]")
    ax.set_ylabel("MSD/4τ [m²/s]")
    ax.legend(fontsize=6)
    msd_checks = [c for c in comparison_checks(s["consistency_check"]) if "MSD" in c["name"]]
    verdict = " ".join(
        ("Passed" if c["passed"] else "FAILED") + f" ({c['name'][len('self-check: ') :]}): "
        f"{c['what']}."
        for c in msd_checks
    )
    lines = "; ".join(_line_words(label) for label, _, _ in msd_lines(s))
    caption = (
        "MSD(τ)/4τ of the movie and of a run of the model, as the movie would have seen it "
        "(localisation error included), with blocked standard errors. Horizontal lines: "
        f"{lines}. {verdict}"
    )
    return _png(fig), caption


def _line_words(label: str) -> str:
    """What a horizontal line of the MSD figure is, for its caption."""
    words = {
        MSD_MODEL_LINE: "solid, the model's D, from the noise of the steps (the free D the "
        "model's skyrmions have)",
        MSD_CORRECTED_LINE: "solid, the model's D, from the noise of the steps corrected for "
        "the frame interval (the free D the model's skyrmions have)",
        MSD_AS_READ_LINE: "dotted, D as the steps read it before that correction",
        MSD_FIT_LINE: f"dashed, the slope D of the quadratic fit 4σ² + 4Dτ + cτ² to the "
        f"movie's MSD at lags 1–{FIT_LAGS} (the movie's MSD(τ)/4τ approaches it where the "
        "localisation error's σ²/τ and the drift's cτ/4 are small)",
    }
    return words[label]


def _figures(result: Inference) -> list[tuple[bytes, str]]:
    from matplotlib.figure import Figure

    s = result.summary
    out = []
    check = s["consistency_check"]
    if check is not None:
        out.append(msd_figure(s))
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
