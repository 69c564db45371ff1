"""report.html of a calibration: its quality checks, a summary in sentences, the figures.

One self-contained file (figures embedded, no network), built from the numbers of
summary.json only. The headline starts with the calibration's checks against their stated
tolerances (summary.json's ``quality_checks``, :func:`skygas.calibration.results.quality_checks`),
each ``passed`` or ``FAILED``; every figure has a caption that says what it draws.
"""

from __future__ import annotations

import html
from pathlib import Path
from typing import Any

import numpy as np

from skygas._version import __version__
from skygas.calibration.analysis import Calibration
from skygas.calibration.results import (
    FIGURES,
    VALIDATION_GOAL,
    _paper_laws,
    mesh_distance_words,
)
from skygas.core.quantities import format_value
from skygas.core.units import MU_0
from skygas.outputs.headlines import Results
from skygas.outputs.report import Page, _made_by
from skygas.runs.run_driver import write_atomic

__all__ = ["VALIDATION_GOAL", "check_rows", "figure_caption", "summary_sentences", "write_report"]


def _nm(x: float) -> str:
    return f"{x * 1e9:.2f} nm"


def _pn(x: float) -> str:
    return _q(x, "N", 3)


def _q(x: float, unit: str = "", digits: int = 4) -> str:
    """``x`` in ``unit`` as the reports write numbers (an SI prefix, or ×10ⁿ; no e-notation)."""
    return format_value(x, None, unit, digits=digits) or "n/a"


def _percent(x: float) -> str:
    return f"{x * 100:+.2f} %"


def summary_sentences(cal: Calibration, data: dict[str, Any]) -> list[str]:
    """The report's summary, one paragraph per finding, every number from ``data``."""
    m = cal.config.material
    iso = cal.isolated
    d = cal.diameter
    out = [
        f"{m.name}: M_s = {_q(m.saturation_magnetization, 'A/m')}, A = "
        f"{_q(m.exchange_stiffness, 'J/m')}, D = {_q(m.total_dmi, 'J/m²')}, K_u = "
        f"{_q(m.anisotropy, 'J/m³')}, B_z = {m.applied_field * 1e3:g} mT, in a "
        f"{m.film_thickness * 1e9:g} nm film on {m.cell_size * 1e9:g} nm cells, α = "
        f"{m.damping:g}. The laws are those of skyrmions in the interior of a "
        f"{cal.config.reference_diameter * 1e9:g} nm device: "
        f"its edges' stray field adds {MU_0 * cal.config.reference_field * 1e3:.2f} mT to B_z "
        "there (the particle model adds the rest of the device's stray field itself)."
    ]
    paper = _paper_laws(cal)
    table = f" (the paper's table: {paper[1] / 2 * 1e9:.1f} nm)" if paper else ""
    out.append(
        f"The isolated skyrmion has a radius of {_nm(iso.radius)}{table}, a wall width of "
        f"{_nm(iso.wall_width)} and an energy {_q(abs(iso.energy), 'J')} "
        f"{'above' if iso.energy >= 0 else 'below'} that of the uniform film; "
        f"Q = {iso.charge:+.4f}, so G = −4πQk = {_q(iso.gyrocoupling, 'kg/s')} (k = "
        f"{_q(iso.k, 'kg/s')}). Its dissipation is 𝒟 = {iso.dissipation:.3f}; the thin-wall "
        f"estimate of the presets, 2π(R/Δ₀ + Δ₀/R) with Δ₀ = √(A/K_u) = "
        f"{_nm(m.bare_wall_width)}, gives {iso.thin_wall_dissipation:.3f}, and the 360° wall "
        "ansatz with the fitted Δ "
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
        f"Edge repulsion at short range, measured from {wlo:.2f} to {whi:.2f} d_sk (a single "
        "held closer leaves through the edge; the table goes on along the law's tangent down to "
        f"{cal.wall.distance[0] / d:.2f} d_sk, where neighbours may push a skyrmion): "
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
        how = mesh_distance_words(e, d)
        how = f" ({how})" if how else ""
        out.append(
            f"Halving the cells ({m.cell_size * 1e9:g} → {m.cell_size * 5e8:g} nm) "
            f"changes the pair energy at {e['coarse']['distance_m'] / d:.2f} d_sk by "
            f"{_percent(e['energy_change'])}{how} and the radius by "
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
    breathing = breathing_sentence(cal)
    if breathing:
        out.append(breathing)
    stray = checks.get("stray_field", {}).get("points")
    if stray:
        from skygas.calibration.results import edge_model

        key, whose = edge_model(cal, stray)
        worst = max(
            stray,
            key=lambda p: abs(p[key] / p["micromagnetic_J"] - 1) if p["micromagnetic_J"] else 0,
        )
        radius = (
            f"; there the skyrmion's radius is {_nm(worst['radius_m'])}, the breathing "
            f"model's {_nm(worst['breathing_radius_m'])} (the isolated one "
            f"{_nm(iso.radius)})"
            if whose == "breathing"
            else f"; there the skyrmions' radius is {_nm(worst['radius_m'])} "
            f"({worst['radius_m'] / iso.radius * 100:.0f} % of the model's)"
        )
        out.append(
            f"In a real film (no compensation) the {whose} model's edge energy, short-range "
            "law plus first-order stray-field energy, is "
            + ", ".join(
                f"{p[key] / p['micromagnetic_J']:.2f}× the micromagnetic one at "
                f"{p['x_d_sk']:.2f} d_sk"
                for p in stray
                if p["micromagnetic_J"] > 0
            )
            + radius
            + "."
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


def breathing_sentence(cal: Calibration) -> str:
    """The report's sentences on the particle model chosen and the breathing measurement."""
    b = cal.breathing
    if not b:
        return ""
    text = f"Particle model: {b['particle_model']}, since {b['why']}."
    if "neighbour_field_T" in b:
        text += (
            f" A neighbour at 1.5 d_sk presses on the radius like "
            f"{b['neighbour_field_T'] * 1e3:.1f} mT, which changes it by "
            f"{_percent(b['neighbour_radius_change'])} at that sensitivity."
        )
    if not b.get("spec"):
        return text + f" {b.get('note', '')}".rstrip()
    lo, hi = b["radius_range_m"]
    flo, fhi = b["field_range_T"]
    d = b["radius_dissipation"]
    text += (
        f" The field scan ({flo * 1e3:+.1f} to {fhi * 1e3:+.1f} mT) gives E_self(R) from "
        f"{_nm(lo)} to {_nm(hi)}, lowest at the isolated radius {_nm(cal.isolated.radius)}; "
        f"the energies from the field's multiplier alone, −M_s t ∫ B dA_m, agree to "
        f"{b['energy_check']['relative_to_span'] * 100:.2f} % of the curve's span. "
        f"𝒟_RR = {d['value']:.3f} (the rigidly shifted profile {d['shifted_profile']:.3f}, the "
        f"360° wall ansatz {d['ansatz']:.3f}, the thin-wall 4πR/Δ {d['thin_wall']:.3f})."
    )
    centre = b.get("centre_dissipation")
    if centre:
        text += (
            f" The centre's 𝒟 is {centre['ratio'][0]:.3f} of the isolated skyrmion's at "
            f"{_nm(centre['radius_m'][0])} and {centre['ratio'][-1]:.3f} at "
            f"{_nm(centre['radius_m'][-1])} (thin wall with the isolated Δ: "
            f"{centre['thin_wall_ratio'][0]:.3f} and {centre['thin_wall_ratio'][-1]:.3f}); a "
            "squeezed skyrmion moves with its own."
        )
    spec, measure = b["spec"], b.get("shift_measure", {})
    squeezed, shifts = b.get("shifts_squeezed", {}), b.get("shifts", {})
    words = []
    for law, name in (("pair", "s_p"), ("wall", "s_w")):
        value = spec.get(f"{law}_shift")
        if value is None:
            fit = shifts.get(law, {})
            words.append(f"{name} not measured ({fit.get('why', shifts.get('why', 'no data'))})")
        elif measure.get(law) == "squeezed":
            n = len(squeezed[law]["distance_m"])
            words.append(f"{name} = {value:.2f} (from {n} solves squeezed by {_SQUEEZER[law]})")
        else:
            words.append(f"{name} = {value:.2f} (by the field: the squeezed solves gave none)")
    text += " The model's shifts: " + "; ".join(words) + "."
    if spec.get("pair_radius") is not None:
        from skygas.physics.materials import law_gap

        d0, r = float(cal.pair.distance[0]), float(spec["pair_radius"][0])
        gap = float(law_gap("pair", [d0], [r], cal.isolated.radius, spec["pair_shift"])[0])
        text += (
            " The laws were measured between squeezed skyrmions and the model reads them at "
            f"the gap: the closest pair, {d0 / cal.diameter:.2f} d_sk apart with radii of "
            f"{_nm(r)}, acts at {gap / cal.diameter:.2f} d_sk."
        )
    field = []
    for law, name in (("pair", "s_p"), ("wall", "s_w")):
        fit = shifts.get(law, {})
        if fit.get("shift") is not None:
            field.append(
                f"{name} would be {fit['shift']:.2f} (rms ln-residual "
                f"{fit['rms_log_residual']:.3f}; {fit['rms_log_residual_unshifted']:.3f} "
                "unshifted)"
            )
    if field and "radius_change_m" in shifts:
        text += (
            f" Measured by a field instead (the radius {_percent(shifts['relative_radius_change'])}"
            f" at {shifts['field_T'] * 1e3:+.1f} mT, which also steepens the tails), "
            + " and ".join(field)
            + "."
        )
    return text


#: What squeezes the skyrmions of the solves each shift is measured from.
_SQUEEZER = {"pair": "a neighbour", "wall": "the edge"}


def models_sentence(cal: Calibration) -> str:
    """Both particle models against the same micromagnetic run (empty if only one was made)."""
    models = {k: c for k, c in cal.validation_models.items() if c is not None}
    if len(models) < 2:
        return ""
    parts = []
    for name, c in models.items():
        s = c.summary()
        ratio = np.asarray(s["displacement_length_ratio"], float)
        angle = np.abs(np.asarray(s["displacement_angle_deg"], float))
        part = (
            f"{name}: RMS centre error at most {s['rms_error_max_d_sk']:.3f} d_sk, final "
            f"displacements {np.nanmin(ratio):.2f}–{np.nanmax(ratio):.2f}× the micromagnetic "
            f"ones in length and within {np.nanmax(angle):.0f}° in direction"
        )
        if "radius_rms_error_m" in s:
            part += f", mean radius within {_nm(s['radius_rms_error_m'])} (RMS)"
        parts.append(part)
    return " Both particle models against the same run: " + "; ".join(parts) + "."


def outline_phrase(v) -> str:
    """'a disk of radius 199.00 nm' or 'a rectangle of 318.00 nm × 238.00 nm' (the film)."""
    if v.size is None:
        return f"a disk of radius {_nm(v.disk_radius)}"
    return f"a rectangle of {_nm(v.size[0])} × {_nm(v.size[1])}"


def validation_sentence(cal: Calibration) -> str:
    """The report's sentences on the validation: what ran, how close the model came, and why."""
    if not cal.config.validate_dynamics:
        return "The dynamics were not validated (--no-validate)."
    v = cal.validation
    if v is None:
        return f"Validation: {cal.validation_note}."
    s = v.summary()
    text = (
        f"Validation: {s['skyrmions']} skyrmions released in {outline_phrase(v)} "
        f"(micromagnetic LLG at T = 0 for {v.times[-1] * 1e9:.2f} ns; "
        f"each moved {min(s['path_length_d_sk']):.2f}–{max(s['path_length_d_sk']):.2f} d_sk "
        f"along its path). The particle model's RMS centre error is at most "
        f"{s['rms_error_max_d_sk']:.3f} d_sk (final {s['rms_error_final_d_sk']:.3f}, mean "
        f"{s['rms_error_mean_d_sk']:.3f}); the goal is {VALIDATION_GOAL:g} d_sk."
    )
    text += models_sentence(cal)
    r = cal.validation_restarted
    if r is not None:
        start = v.times[-1] - r.times[-1]
        text += (
            f" Restarted from the micromagnetic positions {start * 1e9:.2f} ns after the "
            f"release (once the released skyrmions have taken up the shape of moving "
            f"ones), the model's error is at most {r.error.max():.3f} d_sk."
        )
    travel = cal.config.validation.min_travel
    if min(s["path_length_d_sk"]) < travel:
        text += (
            f" The run stopped before every skyrmion had travelled {travel:g} diameters "
            f"(its time limit, {cal.config.validation.max_duration * 1e9:g} ns)."
        )
    if s["rms_error_max_d_sk"] > VALIDATION_GOAL and v.particle_model == "rigid":
        lo, hi = s["radius_range_m"]
        text += (
            f" Why: in the {'disk' if v.size is None else 'rectangle'} the micromagnetic "
            f"skyrmions have radii of {_nm(lo)}–"
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


def check_rows(data: dict[str, Any]) -> list[tuple[str, str]]:
    """The headline's first rows: each quality check of summary.json, passed or FAILED."""
    return [
        (c["name"], ("passed: " if c["passed"] else "FAILED: ") + c["what"])
        for c in data.get("quality_checks", [])
    ]


def figure_caption(name: str, cal: Calibration) -> str:
    """What the figure ``name`` (one of :data:`~skygas.calibration.results.FIGURES`) draws."""
    d = cal.diameter
    paper = _paper_laws(cal)
    paper_words = (
        f"; green dash-dotted, the paper's {paper[0].name} law for the same material (its "
        f"table's d_sk = {paper[1] * 1e9:.1f} nm and F₀)"
        if paper
        else ""
    )
    if name == "profile.png":
        iso = cal.isolated
        return (
            "The isolated skyrmion's m_z against the distance r from its centre: the azimuthal "
            "mean of the relaxed texture (dots) and the 360° wall ansatz fitted to it (red, "
            f"R = {_nm(iso.radius)}, Δ = {_nm(iso.wall_width)}); the dashed vertical line marks "
            "R, where m_z = 0."
        )
    if name in ("pair.png", "wall.png"):
        law = cal.pair if name == "pair.png" else cal.wall
        lo, hi = (x / d for x in law.measured)
        fitted = bool(cal.fits["pair" if name == "pair.png" else "wall"].get("coefficients"))
        if name == "pair.png":
            first = (
                "Left: the pair law |F| against the centre distance (log scale): the calibrated "
                f"table over its measured range, {lo:.2f}–{hi:.2f} d_sk (black), and its "
                "exponential continuation (dotted)"
            )
            fit = "; red dashed, the paper's form fitted to the table" if fitted else ""
            energies = "the measured pair energies E(d)"
        else:
            first = (
                "Left: the short-range edge law |F| against the distance to the edge (log "
                f"scale): the calibrated table over its measured range, {lo:.2f}–{hi:.2f} d_sk "
                "(black), and its exponential continuation (dotted); blue, the force at a "
                "straight edge of a real film (the short-range law plus the edge's stray field)"
            )
            fit = "; red dashed, the paper's form fitted to that straight edge" if fitted else ""
            energies = "the measured edge energies E(x) relative to the film's centre"
        return (
            f"{first}{fit}{paper_words}. Right: {energies} in units of F₀ d_sk "
            f"(d_sk = {_nm(d)}, F₀ = {_pn(cal.force_scale)}; log scale)."
        )
    if name == "breathing.png" and cal.breathing.get("spec"):
        b = cal.breathing
        return (
            "Left: the isolated skyrmion's self-energy E_self against its radius R, relative "
            "to its value at the isolated radius: each point relaxed at the reference field "
            "plus an offset B and its energy taken at the reference field alone (black dots, "
            "the table the engine interpolates with PCHIP: black line), and the same energies "
            "from the field's Lagrange multiplier alone, −M_s t ∫ B dA_m along the scan (red "
            f"crosses); the dashed line marks R₀ = {_nm(cal.isolated.radius)} (the isolated "
            "radius). Right: the radius against the offset B. Particle model chosen: "
            f"{b['particle_model']}."
        )
    if name == "validation.png" and cal.validation is not None:
        v = cal.validation
        worst = float(v.error.max())
        r = cal.validation_restarted
        restarted = (
            f", and from the model restarted {(v.times[-1] - r.times[-1]) * 1e9:.2f} ns after "
            "the release (blue dashed)"
            if r is not None
            else ""
        )
        verdict = (
            "above the goal: the validation check failed"
            if worst > VALIDATION_GOAL
            else "within the goal"
        )
        return (
            f"Left: the {v.micromagnetic.shape[1]} skyrmions' paths in the validation film "
            f"(grey, {outline_phrase(v)}): micromagnetic LLG (solid) and the "
            "particle model (dashed, the same colour), dots at the start. Right: the particle "
            "model's RMS centre error [d_sk] against the time from the release (black)"
            f"{restarted}, with the goal {VALIDATION_GOAL:g} d_sk (red dashed). Its maximum, "
            f"{worst:.3f} d_sk, is {verdict}."
        )
    return name


def write_report(cal: Calibration, data: dict[str, Any], out: Path) -> Path:
    """Write ``report.html`` into ``out``, atomically.

    Who made it and when, the quality checks and the summary, use of the model, isolated
    skyrmion, fits, figures with their captions, provenance and data.
    """
    m = cal.config.material
    page = Page(f"skygas calibration — {m.name}")
    if _made_by(page, out, __version__, None) is None:  # no manifest: from Python, say when
        page.paragraph(f"Written on {data['provenance']['written_at'].replace('T', ' ')[:16]} UTC.")
    page.paragraph("The numbers below are those of summary.json; the particle model is model.toml.")
    page.headline(Results(rows=check_rows(data), notes=summary_sentences(cal, data)))
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
            ("G = −4πQk", _q(iso.gyrocoupling, "kg/s", 5)),
            ("𝒟 (measured)", f"{iso.dissipation:.4f}"),
            (
                "𝒟 tensor",
                html.escape(str([[round(x, 4) for x in row] for row in iso.dissipation_tensor])),
            ),
            ("𝒟 thin-wall estimate (presets)", f"{iso.thin_wall_dissipation:.4f}"),
            ("energy relative to the uniform film", _q(iso.energy, "J", 5)),
            ("moment deficit ∫(1 − m_z) dA", _q(iso.moment_deficit, "m²")),
        ]
    )
    b = cal.breathing
    if b.get("spec"):
        page.heading("Breathing")
        d = b["radius_dissipation"]
        rows = [
            ("particle model", html.escape(f"{b['particle_model']}: {b['why']}")),
            (
                "E_self(R) table",
                f"{len(b['points'])} radii, {_nm(b['radius_range_m'][0])}–"
                f"{_nm(b['radius_range_m'][1])}",
            ),
            ("𝒟_RR (measured)", f"{d['value']:.4f}"),
            ("𝒟_RR thin-wall 4πR/Δ", f"{d['thin_wall']:.4f}"),
        ]
        for law, name in (("pair", "s_p"), ("wall", "s_w")):
            fit = b.get("shifts", {}).get(law, {})
            if fit.get("shift") is not None:
                rows.append(
                    (
                        f"{name} ({law} law's shift)",
                        f"{fit['shift']:.3f}, rms ln-residual {fit['rms_log_residual']:.3g}",
                    )
                )
        page.table(rows)
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
            page.image(path.read_bytes(), figure_caption(name, cal))
    page.heading("Provenance")
    prov = data["provenance"]
    page.table(
        [
            (k.replace("_", " "), html.escape(str(v)))
            for k, v in prov.items()
            if not isinstance(v, dict)
        ]
    )
    page.heading("Data")
    page.json_block("calibration", data)
    text = page.html()
    return write_atomic(out / "report.html", lambda tmp: tmp.write_text(text, encoding="utf-8"))
