"""report.html of a calibration: a summary in sentences, the tables behind it, the figures.

One self-contained file (figures embedded, no network), built from the numbers of
summary.json only.
"""

from __future__ import annotations

import html
from pathlib import Path
from typing import Any

from skygas._version import __version__
from skygas.calibration.analysis import Calibration
from skygas.calibration.results import FIGURES, _paper_laws
from skygas.core.units import MU_0
from skygas.outputs.headlines import Results
from skygas.outputs.report import Page
from skygas.runs.run_driver import write_atomic

#: The goal of the validation: RMS centre error below this many diameters.
VALIDATION_GOAL = 0.1


def _nm(x: float) -> str:
    return f"{x * 1e9:.2f} nm"


def _pn(x: float) -> str:
    return f"{x * 1e12:.3g} pN"


def _percent(x: float) -> str:
    return f"{x * 100:+.2f} %"


def summary_sentences(cal: Calibration, data: dict[str, Any]) -> list[str]:
    """The report's summary, one paragraph per finding, every number from ``data``."""
    m = cal.config.material
    iso = cal.isolated
    d = cal.diameter
    out = [
        f"{m.name}: M_s = {m.saturation_magnetization:.4g} A/m, A = "
        f"{m.exchange_stiffness:.4g} J/m, D = {m.total_dmi:.4g} J/m², K_u = {m.anisotropy:.4g} "
        f"J/m³, B_z = {m.applied_field * 1e3:g} mT, in a {m.film_thickness * 1e9:g} nm film "
        f"on {m.cell_size * 1e9:g} nm cells, α = {m.damping:g}. The laws are those of "
        f"skyrmions in the interior of a {cal.config.reference_diameter * 1e9:g} nm device: "
        f"its edges' stray field adds {MU_0 * cal.config.reference_field * 1e3:.2f} mT to B_z "
        "there (the particle model adds the rest of the device's stray field itself)."
    ]
    paper = _paper_laws(cal)
    table = f" (the paper's table: {paper[1] / 2 * 1e9:.1f} nm)" if paper else ""
    out.append(
        f"The isolated skyrmion has a radius of {_nm(iso.radius)}{table}, a wall width of "
        f"{_nm(iso.wall_width)} and an energy {abs(iso.energy):.4g} J "
        f"{'above' if iso.energy >= 0 else 'below'} that of the uniform film; "
        f"Q = {iso.charge:+.4f}, so G = −4πQk = {iso.gyrocoupling:.4g} kg/s (k = {iso.k:.4g} "
        f"kg/s). Its dissipation is 𝒟 = {iso.dissipation:.3f}; the thin-wall estimate of the "
        f"presets, 2π(R/Δ₀ + Δ₀/R) with Δ₀ = √(A/K_u) = {_nm(m.bare_wall_width)}, gives "
        f"{iso.thin_wall_dissipation:.3f}, and the 360° wall ansatz with the fitted Δ "
        f"{iso.ansatz_dissipation:.3f}. Its diameter d_sk = {_nm(d)} is the length unit of the "
        f"fitted laws; F₀ = A t/d_sk = {_pn(cal.force_scale)}."
    )
    lo, hi = (x / d for x in cal.pair.measured)
    points = [x for x in (1.0, 1.5, 2.0, 3.0) if lo <= x <= hi]
    values = ", ".join(f"{_pn(float(cal.pair(x * d)))} at {x:g} d_sk" for x in points)
    if paper:
        p, pd, pf = paper
        from skygas.physics.forces import paper_pair_force

        compare = ", ".join(
            f"{_pn(pf * float(paper_pair_force(x * d / pd, *p.pair_law)))}" for x in points
        )
        values += f" (the paper's {p.name} law at the same distances: {compare})"
    out.append(
        f"Pair repulsion, measured from {lo:.2f} to {hi:.2f} d_sk: {values}. Beyond "
        f"{hi:.2f} d_sk the table continues with the measured decay length "
        f"{cal.pair.decay / d:.2f} d_sk."
    )
    wlo, whi = (x / d for x in cal.wall.measured)
    out.append(
        f"Edge repulsion at short range, measured from {wlo:.2f} to {whi:.2f} d_sk (closer, the "
        "skyrmion leaves through the edge): "
        + ", ".join(
            f"{_pn(float(cal.wall(x * d)))} at {x:g} d_sk"
            for x in (1.0, 1.5, 2.0)
            if wlo <= x <= whi
        )
        + ". At a straight edge of a real film the edge's stray field adds a long-range part, "
        "∝ 1/x² far from it."
    )
    checks = cal.checks
    if checks.get("enlarged"):
        e = checks["enlarged"]
        out.append(
            f"In a film {e['enlarged_side_m'] / e['film_side_m']:.2f} times larger the "
            f"isolated skyrmion's radius changes by {_percent(e['radius_change'])} and its "
            f"energy by {_percent(e['energy_change'])}."
        )
    if checks.get("mesh"):
        e = checks["mesh"]
        out.append(
            f"Halving the cells ({m.cell_size * 1e9:g} → {m.cell_size * 5e8:g} nm) "
            f"changes the pair energy at {e['coarse']['distance_m'] / d:.2f} d_sk by "
            f"{_percent(e['energy_change'])} and the radius by "
            f"{_percent(e['radius_change'])}."
        )
    if checks.get("sensitivity"):
        e = checks["sensitivity"]
        out.append(
            f"The skyrmion's size follows the field: {_percent(e['relative_change_per_mT'])}"
            " of its radius per mT. A device's stray field is stronger near its edges "
            "than in its interior, so near the edges its skyrmions are smaller than the "
            "model's."
        )
    stray = checks.get("stray_field", {}).get("points")
    if stray:
        worst = max(
            stray,
            key=lambda p: (
                abs(p["model_J"] / p["micromagnetic_J"] - 1) if p["micromagnetic_J"] else 0
            ),
        )
        out.append(
            "In a real film (no compensation) the model's edge energy, short-range law plus "
            "first-order stray-field energy, is "
            + ", ".join(
                f"{p['model_J'] / p['micromagnetic_J']:.2f}× the micromagnetic one at "
                f"{p['x_d_sk']:.2f} d_sk"
                for p in stray
                if p["micromagnetic_J"] > 0
            )
            + f"; there the skyrmions' radius is {_nm(worst['radius_m'])} "
            f"({worst['radius_m'] / iso.radius * 100:.0f} % of the model's)."
        )
    out.append(validation_sentence(cal))
    prov = data["provenance"]
    spans = prov["stage_spans_s"]
    if spans:
        out.append(
            f"The calibration took {prov['wall_seconds']:.0f} s of wall time on "
            f"{prov['workers']} worker process(es) ({prov['device']}); its stages ended "
            "at "
            + ", ".join(
                f"{k} {v[1]:.0f} s" for k, v in sorted(spans.items(), key=lambda kv: kv[1][1])
            )
            + "."
        )
    return out


def validation_sentence(cal: Calibration) -> str:
    """The report's sentences on the validation: what ran, how close the model came, and why."""
    if not cal.config.validate_dynamics:
        return "The dynamics were not validated (--no-validate)."
    v = cal.validation
    if v is None:
        return f"Validation: {cal.validation_note}."
    s = v.summary()
    text = (
        f"Validation: {s['skyrmions']} skyrmions released in a disk of radius "
        f"{_nm(v.disk_radius)} (micromagnetic LLG at T = 0 for {v.times[-1] * 1e9:.2f} ns; "
        f"each moved {min(s['path_length_d_sk']):.2f}–{max(s['path_length_d_sk']):.2f} d_sk "
        f"along its path). The particle model's RMS centre error is at most "
        f"{s['rms_error_max_d_sk']:.3f} d_sk (final {s['rms_error_final_d_sk']:.3f}, mean "
        f"{s['rms_error_mean_d_sk']:.3f}); the goal is {VALIDATION_GOAL:g} d_sk."
    )
    r = cal.validation_restarted
    if r is not None:
        start = v.times[-1] - r.times[-1]
        text += (
            f" Restarted from the micromagnetic positions {start * 1e9:.2f} ns after the "
            f"release (once the released skyrmions have taken up the shape of moving "
            f"ones), the model's error is at most {r.error.max():.3f} d_sk."
        )
    if min(s["path_length_d_sk"]) < 1.0:
        text += (
            " The run stopped before every skyrmion had travelled one diameter "
            f"(its time limit, {cal.config.validation.max_duration * 1e9:g} ns)."
        )
    if s["rms_error_max_d_sk"] > VALIDATION_GOAL:
        lo, hi = s["radius_range_m"]
        text += (
            f" Why: in the disk the micromagnetic skyrmions have radii of {_nm(lo)}–"
            f"{_nm(hi)}, {lo / cal.isolated.radius * 100:.0f}–"
            f"{hi / cal.isolated.radius * 100:.0f} % of the isolated one whose laws the "
            "model uses: their neighbours and the disk's edge compress them, and the "
            "repulsion between smaller skyrmions is weaker (many-body terms that a pair "
            "law cannot hold)."
        )
        sens = cal.checks.get("sensitivity")
        if sens:
            text += (
                f" This skyrmion is soft: its radius changes by "
                f"{abs(sens['relative_change_per_mT']) * 100:.1f} % per mT."
            )
        mean_speed = _speed_ratio(v)
        if mean_speed is not None:
            text += (
                f" Over the run the model's skyrmions travel {mean_speed:.2f} times as far "
                "as the micromagnetic ones."
            )
    return text


def _speed_ratio(v) -> float | None:
    import numpy as np

    mm = np.linalg.norm(np.diff(v.micromagnetic, axis=0), axis=-1).sum()
    pm = np.linalg.norm(np.diff(v.particle, axis=0), axis=-1).sum()
    return None if mm <= 0 else float(pm / mm)


def write_report(cal: Calibration, data: dict[str, Any], out: Path) -> Path:
    """Write ``report.html`` into ``out``, atomically.

    Summary, use of the model, isolated skyrmion, fits, figures, provenance and data.
    """
    m = cal.config.material
    page = Page(f"skygas calibration — {m.name}")
    page.paragraph(
        f"Written by skygas {__version__}. The numbers below are those of "
        "summary.json; the particle model is model.toml."
    )
    page.headline(Results(notes=summary_sentences(cal, data)))
    page.heading("Use the model")
    page.pre(
        f'material = "{out.name}/model.toml"        # in any configuration\n'
        f"skygas reshuffle --material {out.name}/model.toml --out out/reshuffle"
    )
    page.heading("Isolated skyrmion")
    iso = cal.isolated
    page.table(
        [
            ("radius (m_z = 0)", _nm(iso.radius)),
            ("wall width (ansatz fit)", _nm(iso.wall_width)),
            ("topological charge Q", f"{iso.charge:+.5f}"),
            ("G = −4πQk", f"{iso.gyrocoupling:.5g} kg/s"),
            ("𝒟 (measured)", f"{iso.dissipation:.4f}"),
            (
                "𝒟 tensor",
                html.escape(str([[round(x, 4) for x in row] for row in iso.dissipation_tensor])),
            ),
            ("𝒟 thin-wall estimate (presets)", f"{iso.thin_wall_dissipation:.4f}"),
            ("energy relative to the uniform film", f"{iso.energy:.5g} J"),
            ("moment deficit ∫(1 − m_z) dA", f"{iso.moment_deficit:.4g} m²"),
        ]
    )
    page.heading("Fits of the paper's forms")
    rows = []
    for law, fit in cal.fits.items():
        if fit.get("coefficients"):
            rows.append(
                (
                    f"{law} law",
                    f"[{', '.join(f'{c:.5g}' for c in fit['coefficients'])}]"
                    f" over {fit['range_d_sk'][0]:.2f}–{fit['range_d_sk'][1]:.2f} d_sk, "
                    f"rms ln-residual {fit['rms_log_residual']:.3g}",
                )
            )
        else:
            rows.append((f"{law} law", html.escape(fit.get("why", "no fit"))))
    page.table(rows)
    page.heading("Figures")
    for name in FIGURES:
        path = out / name
        if path.exists():
            page.image(path.read_bytes(), name)
    page.heading("Provenance")
    prov = data["provenance"]
    page.table([(k, html.escape(str(v))) for k, v in prov.items() if not isinstance(v, dict)])
    page.heading("Data")
    page.json_block("calibration", data)
    text = page.html()
    return write_atomic(out / "report.html", lambda tmp: tmp.write_text(text, encoding="utf-8"))
