"""A finished calibration's files: model.toml, summary.json, figures, report.html.

Every file records the skygas version, the material and the calibration's settings (in its
body, or for a PNG in its text chunks); every file is written atomically. The numbers shown in
the report are the ones in summary.json; none is drawn from anywhere else.
"""

from __future__ import annotations

import json
import math
import time
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np

from skygas._version import __version__
from skygas.calibration.analysis import Calibration, analyse
from skygas.calibration.model_file import write_model
from skygas.core.units import MU_0
from skygas.runs.run_driver import write_figure, write_json

FIGURES = ("profile.png", "pair.png", "wall.png", "validation.png", "breathing.png")

# -- the quality checks' tolerances --------------------------------------------------------------
#: The validation's goal: the particle model's RMS centre error at most this many d_sk.
VALIDATION_GOAL = 0.1
#: Halving the cells may change the pair energy at ≈ 1.5 d_sk, and the isolated skyrmion's
#: radius, by at most this share. A law F ∝ exp(−d/λ) scaled by 1 + ε takes each value at a
#: distance shifted by λε: for the S2 law's λ = 1.46 d_sk, 5 % is 0.07 d_sk, within the
#: validation's goal.
MESH_TOLERANCE = 0.05
#: A film 1.25 times larger may change the isolated skyrmion's radius by at most this share (a
#: larger change: the film's edges still squeeze the skyrmion whose diameter is the model's
#: length unit and whose profile its stray-field energy uses). Its energy is reported, not
#: judged: the model uses energy differences measured in the calibration film, never it.
FILM_SIZE_TOLERANCE = 0.02
#: At a real straight edge the model's edge energy (short-range law plus first-order
#: stray-field energy) may differ from the micromagnetic one by at most this share: the wall
#: law decays over a fraction of d_sk, so a quarter off moves a skyrmion's distance from an
#: edge by well under the validation's goal (the same λε argument as above).
STRAY_TOLERANCE = 0.25


def _version(package: str) -> str:
    try:
        return metadata.version(package)
    except metadata.PackageNotFoundError:
        return "not installed"


def provenance(job) -> dict[str, Any]:
    """What made the model: solver and versions, device, mesh, convergence, wall times."""
    devices = sorted({r.get("device", "cpu") for r in job.results.values()})
    seconds: dict[str, float] = {}
    for name, result in job.results.items():
        stage = name.split("/")[0]
        seconds[stage] = seconds.get(stage, 0.0) + result["seconds"]
    if job.llg["frames"]:
        seconds["validation LLG"] = job.llg["seconds"]
    return {
        "skygas_version": __version__,
        "solver": "magnum.np field terms (finite differences, FFT stray field); "
        "Barzilai-Borwein minimisation with guiding centres held by Lagrange "
        "multipliers; RKF45 LLG",
        "magnumnp_version": _version("magnumnp"),
        "torch_version": _version("torch"),
        "device": ", ".join(devices) or "cpu",
        "workers": job.workers,
        # the running Dask cluster's scheduler that solved (None: a local cluster, or none)
        "scheduler": job.scheduler,
        "compiled_field_terms": job.config.compile,
        "cell_size_m": job.config.material.cell_size,
        "film": "one cell layer of the film's thickness, open boundaries; laws in compensated "
        "films with the reference field",
        "torque_tolerance_A_per_m": job.config.torque_tolerance,
        "llg_tolerance": job.config.validation.llg_tolerance,
        "solves": len(job.results),
        "solver_seconds_by_stage": seconds,
        # seconds of the run clock (CalibrationJob.run_seconds: wall time while running)
        "stage_spans_s": {k: list(v) for k, v in job.timeline.items()},
        "wall_seconds": job.run_seconds(),
        "llg_steps": job.llg["steps"],
        "written_at": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
    }


def record(cal: Calibration) -> dict[str, str]:
    """What every figure of the calibration records in its text chunks."""
    return {"skygas_version": __version__, "seed": "0", "config_json": cal.config.model_dump_json()}


# -- the quality checks ----------------------------------------------------------------------------
def _check(
    name: str, value: Any, tolerance: float, unit: str, what: str, passed: bool | None = None
) -> dict[str, Any]:
    """A quality check: ``passed`` (default: |value| ≤ tolerance) and what it measured."""
    ok = abs(value) <= tolerance if passed is None else passed
    return {
        "name": name,
        "value": value,
        "tolerance": tolerance,
        "unit": unit,
        "passed": bool(ok),
        "what": what,
    }


def _pct(x: float) -> str:
    return f"{x * 100:+.2f} %"


def mesh_distance_words(mesh: dict[str, Any], diameter: float) -> str:
    """How the mesh check compared the meshes' pair energies where they held the pair apart.

    A clause for the report; empty where both held it at the same distance (to the digits
    shown).
    """
    coarse, fine = (mesh[k]["distance_m"] / diameter for k in ("coarse", "fine"))
    if f"{fine:.2f}" == f"{coarse:.2f}":
        return ""
    if mesh.get("energy_at_same_distance"):
        return (
            f"the fine mesh held the pair at {fine:.2f} d_sk, its energy taken to "
            f"{coarse:.2f} d_sk along the calibrated curve; as held, "
            f"{_pct(mesh['energy_change_as_held'])}"
        )
    return (
        f"the fine mesh held the pair at {fine:.2f} d_sk, outside the calibrated curve: the "
        "energies are compared as held, at different distances"
    )


def edge_model(cal: Calibration, points: list[dict[str, Any]]) -> tuple[str, str]:
    """(key of the points' model energy, the model's name) for the written particle model.

    A breathing model is judged with its radius free at the edge (``breathing_model_J``,
    :func:`skygas.calibration.breathing.edge_check`), a rigid one with the isolated radius.
    """
    breathing = getattr(cal, "breathing", None) or {}
    if breathing.get("particle_model") == "breathing" and all(
        "breathing_model_J" in p for p in points
    ):
        return "breathing_model_J", "breathing"
    return "model_J", "rigid"


def quality_checks(cal: Calibration) -> list[dict[str, Any]]:
    """The calibration's checks against their stated tolerances, each passed or failed.

    Each is ``{"name", "value", "tolerance", "unit", "passed", "what"}`` (summary.json's
    ``quality_checks``, the report's first rows, a warning line on the terminal when failed):
    the mesh (pair energy and radius at half the cell size, :data:`MESH_TOLERANCE`), the film's
    size (:data:`FILM_SIZE_TOLERANCE`), the edge energy at a real straight edge
    (:data:`STRAY_TOLERANCE`) and the validation's RMS centre error (:data:`VALIDATION_GOAL`).
    A check whose solves were not made (``--no-mesh-check``, ``--no-validate``) is left out.
    """
    out = []
    checks = cal.checks
    d = cal.diameter
    cell = cal.config.material.cell_size
    mesh = checks.get("mesh")
    if mesh:
        halved = f"halving the cells ({cell * 1e9:g} → {cell * 5e8:g} nm)"
        coarse = mesh["coarse"]["distance_m"] / d
        how = mesh_distance_words(mesh, d)
        out.append(
            _check(
                "mesh: pair energy",
                mesh["energy_change"],
                MESH_TOLERANCE,
                "relative change",
                f"{halved} changes the pair energy at {coarse:.2f} d_sk by "
                f"{_pct(mesh['energy_change'])} (at most ±{MESH_TOLERANCE * 100:g} %"
                + (f"; {how})" if how else ")"),
            )
        )
        out.append(
            _check(
                "mesh: radius",
                mesh["radius_change"],
                MESH_TOLERANCE,
                "relative change",
                f"{halved} changes the isolated skyrmion's radius by "
                f"{_pct(mesh['radius_change'])} (at most ±{MESH_TOLERANCE * 100:g} %)",
            )
        )
    enlarged = checks.get("enlarged")
    if enlarged:
        out.append(
            _check(
                "film size",
                enlarged["radius_change"],
                FILM_SIZE_TOLERANCE,
                "relative change",
                f"in a film {enlarged['enlarged_side_m'] / enlarged['film_side_m']:.2f} times "
                f"larger the isolated skyrmion's radius changes by "
                f"{_pct(enlarged['radius_change'])} (at most ±{FILM_SIZE_TOLERANCE * 100:g} %; "
                f"its energy, which the model does not use, by "
                f"{_pct(enlarged['energy_change'])})",
            )
        )
    points = [p for p in checks.get("stray_field", {}).get("points", []) if p["micromagnetic_J"]]
    if points:
        key, whose = edge_model(cal, points)
        ratios = [p[key] / p["micromagnetic_J"] for p in points]
        worst = max(range(len(points)), key=lambda k: abs(ratios[k] - 1))
        out.append(
            _check(
                "edge energy at a real edge",
                ratios[worst] - 1,
                STRAY_TOLERANCE,
                "relative deviation",
                f"the {whose} model's edge energy (short-range law plus first-order "
                "stray-field energy) at a straight edge of a real film is "
                + ", ".join(
                    f"{r:.2f}× the micromagnetic one at {p['x_d_sk']:.2f} d_sk"
                    for r, p in zip(ratios, points, strict=True)
                )
                + f" (at most ±{STRAY_TOLERANCE * 100:g} % off)",
            )
        )
    if cal.config.validate_dynamics:
        v = cal.validation
        if v is None:
            out.append(
                _check(
                    "validation",
                    None,
                    VALIDATION_GOAL,
                    "d_sk",
                    f"nothing to compare: {cal.validation_note or 'no validation run'}",
                    passed=False,
                )
            )
        else:
            worst_error = float(v.error.max())
            what = (
                f"the particle model's RMS centre error against the micromagnetic run is at "
                f"most {worst_error:.3f} d_sk over {v.times[-1] * 1e9:.2f} ns (at most "
                f"{VALIDATION_GOAL:g} d_sk)"
            )
            travel = cal.config.validation.min_travel
            if float(np.min(v.path_length)) < travel:
                what += (
                    f"; the run stopped before every skyrmion had travelled {travel:g} "
                    "diameters, so "
                    "the comparison is short"
                )
            out.append(_check("validation", worst_error, VALIDATION_GOAL, "d_sk", what))
    return out


# -- numbers -------------------------------------------------------------------------------------
def summary(cal: Calibration, job) -> dict[str, Any]:
    """summary.json: every number of the calibration (SI units; d_sk and F₀ where said)."""
    iso = cal.isolated
    out = {
        "skygas_version": __version__,
        # first: what a reader of the file should know before any number (report.py's headline)
        "quality_checks": quality_checks(cal),
        "material": cal.config.material.as_record(),
        "config": json.loads(cal.config.model_dump_json()),
        "reference_field_T": MU_0 * cal.config.reference_field,
        "isolated": {
            **iso.as_record(),
            "diameter": cal.diameter,
            "force_scale_N": cal.force_scale,
            "profile_radius_m": list(iso.profile_radius),
            "profile_mz": list(iso.profile_mz),
        },
        "pair": _law_record(cal.pair, cal.pair_energy, cal),
        "wall_short_range": _law_record(cal.wall, cal.wall_energy, cal),
        "straight_edge": {
            "distance_m": cal.straight_edge_x.tolist(),
            "force_N": cal.straight_edge_force.tolist(),
        },
        "fits": cal.fits,
        "checks": cal.checks,
        "breathing": cal.breathing,
        "provenance": provenance(job),
    }
    if cal.validation is not None:
        v = cal.validation
        out["validation"] = {
            **v.summary(),
            "times_s": v.times.tolist(),
            "error_d_sk": v.error.tolist(),
            "micromagnetic_m": v.micromagnetic.tolist(),
            "particle_m": v.particle.tolist(),
        }
        out["validation"]["models"] = {
            name: None if c is None else c.summary() for name, c in cal.validation_models.items()
        }
        r = cal.validation_restarted
        if r is not None:
            out["validation"]["restarted"] = {
                "from_s": float(v.times[-1] - r.times[-1]),
                "rms_error_max_d_sk": float(r.error.max()),
                "rms_error_final_d_sk": float(r.error[-1]),
                "error_d_sk": r.error.tolist(),
            }
    elif cal.config.validate_dynamics:
        out["validation"] = {"note": cal.validation_note}
    return out


def _law_record(law, energy, cal: Calibration) -> dict[str, Any]:
    return {
        "energy_distance_m": energy.distance.tolist(),
        "energy_J": energy.energy.tolist(),
        "dropped": [{"distance_m": d, "why": why} for d, why in energy.dropped],
        "table_distance_m": law.distance.tolist(),
        "table_force_N": law.force.tolist(),
        "measured_range_m": list(law.measured),
        "tail_decay_length_m": law.decay,
        "measured_range_d_sk": [x / cal.diameter for x in law.measured],
    }


# -- the model file ------------------------------------------------------------------------------
def write_model_file(cal: Calibration, job, path: Path) -> Path:
    """Write the particle model ``model.toml`` to ``path``.

    The material with its tabulated laws, then the micromagnetics, Thiele coefficients, laws,
    fits and provenance of the calibration.
    """
    iso = cal.isolated
    m = cal.config.material
    fits = cal.fits
    header = [
        f"skygas {__version__} calibrated particle model of {m.name} (skygas calibrate).",
        f'Use it as `material = "{path.name}"` (a path) in any configuration, or '
        f"`--material {path.name}` where a command takes one.",
        "The [material] table is what the engine reads: its tabulated laws (pair_table,",
        'wall_table) are the default; forces.pair_law = "paper" / forces.wall_law = "paper"',
        "use the paper's forms fitted to them (pair_law, wall_law) instead.",
        f"Laws measured for skyrmions in the interior of a device of "
        f"{cal.config.reference_diameter * 1e9:g} nm (reference field "
        f"{MU_0 * cal.config.reference_field * 1e3:.3f} mT on top of B_z).",
    ]
    sections = {
        "micromagnetics": {k: v for k, v in m.model_dump().items() if v is not None},
        "thiele": {
            "charge": iso.charge,
            "k_kg_per_s": iso.k,
            "gyrocoupling_kg_per_s": iso.gyrocoupling,
            "dissipation": iso.dissipation,
            "dissipation_tensor": [list(row) for row in iso.dissipation_tensor],
            "thin_wall_dissipation": iso.thin_wall_dissipation,
            "radius_m": iso.radius,
            "wall_width_m": iso.wall_width,
            "diameter_m": cal.diameter,
            "force_scale_N": cal.force_scale,
            "energy_J": iso.energy,
            "moment_deficit_m2": iso.moment_deficit,
        },
        "laws": {
            "pair_measured_m": list(cal.pair.measured),
            "wall_measured_m": list(cal.wall.measured),
            "pair_tail_decay_m": cal.pair.decay,
            "wall_tail_decay_m": cal.wall.decay,
            "reference_diameter_m": cal.config.reference_diameter,
            "reference_field_T": MU_0 * cal.config.reference_field,
        },
        "fits": {
            law: {k: v for k, v in fit.items() if v not in (None, "")} for law, fit in fits.items()
        },
        "breathing": breathing_section(cal.breathing),
        "provenance": {k: v for k, v in provenance(job).items() if not isinstance(v, dict)},
    }
    comments = {
        "material.pair_table": "pair law |F|(d): d centre distance [m], force [N] (PCHIP; held "
        "below the first distance, 0 beyond the last)",
        "material.wall_table": "short-range wall law |F|(x): x distance to the nearest wall "
        "[m], force [N]; the long-range part is the stray field below",
        "material.stray_field": "the skyrmion's profile 1 - m_z(r) for its energy in the "
        "device's edge stray field (added with the table wall law)",
        "fits": "the paper's forms fitted to the tables over their measured ranges (d_sk units)",
        "material.breathing": "the breathing model's radius: E_self(R) [m, J] from a field scan, "
        "its friction 𝒟_RR and the shifts of the laws\nwith the radius (used when "
        'particle_model = "breathing"; measured either way)',
        "breathing": "how the particle model was chosen and how well the breathing "
        "measurement holds (summary.json: every point)",
    }
    return write_model(path, cal.material_table(), sections, header, comments)


def _finite(value: Any) -> bool:
    return not isinstance(value, float) or math.isfinite(value)


def breathing_section(b: dict[str, Any]) -> dict[str, Any]:
    """model.toml's ``[breathing]``: the choice, the scan's range, 𝒟_RR's estimates, the fits."""
    out: dict[str, Any] = {
        k: b[k]
        for k in (
            "particle_model",
            "why",
            "threshold_per_mT",
            "sensitivity_per_mT",
            "neighbour_field_T",
            "neighbour_radius_change",
            "radius_range_m",
            "field_range_T",
            "note",
        )
        if k in b
    }
    if "points" in b and b.get("spec"):
        out["field_T"] = [p["field_T"] for p in b["points"]]
        out["energy_integrated_J"] = [p["energy_integrated_J"] for p in b["points"]]
        out["energy_check_relative"] = b["energy_check"]["relative_to_span"]
    dissipation = b.get("radius_dissipation", {})
    for key in ("finite_difference", "shifted_profile", "ansatz", "thin_wall"):
        if key in dissipation:
            out[f"radius_dissipation_{key}"] = dissipation[key]
    for law in ("pair", "wall"):
        fit = b.get("shifts", {}).get(law, {})
        for key in ("shift", "rms_log_residual", "rms_log_residual_unshifted"):
            if fit.get(key) is not None:
                out[f"{law}_{key}"] = fit[key]
    if "radius_change_m" in b.get("shifts", {}):
        out["shifted_radius_change_m"] = b["shifts"]["radius_change_m"]
    return {k: v for k, v in out.items() if v is not None and _finite(v)}


# -- figures -------------------------------------------------------------------------------------
def _paper_laws(cal: Calibration):
    """The paper's pair and wall laws for the same material, in its own units.

    The preset's table diameter and F₀; None when the material is not a preset.
    """
    from skygas.physics.materials import derive_thiele, preset, preset_names

    name = cal.config.material.name
    if name not in preset_names():
        return None
    p = preset(name)
    thiele = derive_thiele(p, cal.config.material.film_thickness)
    return p, thiele.skyrmion_diameter, thiele.force_scale


def plot_profile(cal: Calibration, path: Path) -> Path:
    """Plot the isolated skyrmion's m_z(r) against the 360° wall ansatz, to ``path`` (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from skygas.calibration.profile import ansatz_mz

    iso = cal.isolated

    def draw(tmp):
        fig, ax = plt.subplots(figsize=(6, 4))
        r = np.asarray(iso.profile_radius) * 1e9
        ax.plot(r, iso.profile_mz, "k.", ms=3, label="relaxed (azimuthal mean)")
        ax.plot(
            r,
            ansatz_mz(np.asarray(iso.profile_radius), iso.radius, iso.wall_width),
            "r-",
            lw=1,
            label=f"360° wall ansatz, R = {iso.radius * 1e9:.2f} nm, "
            f"Δ = {iso.wall_width * 1e9:.2f} nm",
        )
        ax.axvline(iso.radius * 1e9, color="0.6", lw=0.8, ls="--")
        ax.set(
            xlabel="r [nm]",
            ylabel="m_z",
            title=f"{cal.config.material.name}: isolated "
            f"skyrmion, Q = {iso.charge:+.4f}, $\\mathcal{{D}}$ = {iso.dissipation:.2f}",
        )
        ax.legend(fontsize=8, loc="lower right")
        fig.tight_layout()
        fig.savefig(tmp, dpi=110)
        plt.close(fig)

    return write_figure(path, draw, record(cal))


def plot_law(cal: Calibration, which: str, path: Path) -> Path:
    """|F| [pN] against distance [nm] of law ``which`` ("pair" or "wall"), to ``path`` (PNG).

    The calibrated table (over the measured range, and its continuation), −dE/dd at the measured
    energies, the paper-form fit and the paper's law for the same material (if it is a preset).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from skygas.physics.forces import (
        law_coefficient_names,
        law_formula,
        paper_pair_force,
        paper_wall_force,
    )

    law = cal.pair if which == "pair" else cal.wall
    energy = cal.pair_energy if which == "pair" else cal.wall_energy
    fit = cal.fits[which]["coefficients"]
    paper = _paper_laws(cal)
    d_sk = cal.diameter

    def draw(tmp):
        fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 6))
        lo, hi = law.measured
        inside = law.distance <= hi
        ax.semilogy(
            law.distance[inside] * 1e9,
            law.force[inside] * 1e12,
            "k-",
            lw=1.5,
            label="calibrated (table)",
        )
        ax.semilogy(
            law.distance[~inside] * 1e9,
            law.force[~inside] * 1e12,
            "k:",
            lw=1.2,
            label="continuation (exponential)",
        )
        if which == "wall":
            ax.semilogy(
                cal.straight_edge_x * 1e9,
                cal.straight_edge_force * 1e12,
                "b-",
                lw=1,
                label="straight edge of a real film (+ stray field)",
            )
        x = np.linspace(max(lo, d_sk), max(hi, 4 * d_sk), 200)
        if fit:
            shape = (
                paper_pair_force(x / d_sk, *fit)
                if which == "pair"
                else paper_wall_force(x / d_sk, fit)
            )
            values = [
                f"{name} = {c:.4g}"
                for name, c in zip(law_coefficient_names(which, len(fit)), fit, strict=True)
            ]
            ax.semilogy(
                x * 1e9,
                cal.force_scale * shape * 1e12,
                "r--",
                lw=1,
                label="\n".join(
                    [
                        f"paper's form fitted: {law_formula(which, len(fit))},",
                        f"F₀ = {cal.force_scale * 1e12:.4g} pN, d in d_sk = {d_sk * 1e9:.3g} nm:",
                        *(", ".join(values[k : k + 3]) for k in range(0, len(values), 3)),
                    ]
                ),
            )
        if paper is not None:
            p, pd, pf = paper
            xp = np.linspace(0.5 * pd if which == "wall" else pd, 5 * pd, 200)
            shape = (
                paper_pair_force(xp / pd, *p.pair_law)
                if which == "pair"
                else paper_wall_force(xp / pd, p.wall_law)
            )
            ax.semilogy(
                xp * 1e9,
                pf * shape * 1e12,
                "g-.",
                lw=1,
                label=f"paper's {p.name} law (d_sk = {pd * 1e9:.1f} nm)",
            )
        ax.set(
            xlabel=("centre distance" if which == "pair" else "distance to the edge") + " [nm]",
            ylabel="|F| [pN]",
            title=f"{which} law",
        )
        # below the axes: inside, the fitted law's form and values would cover the curves
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14))
        bx.plot(energy.distance * 1e9, energy.energy / (cal.force_scale * d_sk), "ko", ms=4)
        bx.set(
            xlabel="distance [nm]",
            ylabel="E / (F₀ d_sk)",
            title=f"energies (F₀ d_sk = {cal.force_scale * d_sk:.3g} J)",
        )
        bx.set_yscale("log")
        fig.tight_layout()
        fig.savefig(tmp, dpi=110)
        plt.close(fig)

    return write_figure(path, draw, record(cal))


def plot_validation(cal: Calibration, path: Path) -> Path:
    """Plot the validation to ``path`` (PNG): both models' trajectories and the RMS error."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    v = cal.validation

    def draw(tmp):
        fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.8))
        cx, cy = v.centre
        if v.size is None:
            half_w = half_h = v.disk_radius
            ax.add_patch(plt.Circle((cx * 1e9, cy * 1e9), half_w * 1e9, fill=False, color="0.5"))
        else:
            half_w, half_h = 0.5 * v.size[0], 0.5 * v.size[1]
            ax.add_patch(
                plt.Rectangle(
                    ((cx - half_w) * 1e9, (cy - half_h) * 1e9),
                    v.size[0] * 1e9,
                    v.size[1] * 1e9,
                    fill=False,
                    color="0.5",
                )
            )
        for k in range(v.micromagnetic.shape[1]):
            mm, pm = v.micromagnetic[:, k] * 1e9, v.particle[:, k] * 1e9
            (line,) = ax.plot(
                mm[:, 0], mm[:, 1], "-", lw=1.5, label="micromagnetic (LLG)" if k == 0 else None
            )
            ax.plot(
                pm[:, 0],
                pm[:, 1],
                "--",
                lw=1.2,
                color=line.get_color(),
                label="particle model" if k == 0 else None,
            )
            ax.plot(*mm[0], "o", color=line.get_color(), ms=4)
        ax.set_aspect("equal")
        pad = 0.05 * max(half_w, half_h) * 1e9
        ax.set(
            xlim=((cx - half_w) * 1e9 - pad, (cx + half_w) * 1e9 + pad),
            ylim=((cy - half_h) * 1e9 - pad, (cy + half_h) * 1e9 + pad),
            xlabel="x [nm]",
            ylabel="y [nm]",
            title="trajectories (dots: start)",
        )
        ax.legend(fontsize=8)
        bx.plot(v.times * 1e9, v.error, "k-", label="from the release")
        r = cal.validation_restarted
        if r is not None:
            start = v.times[-1] - r.times[-1]
            bx.plot(
                (r.times + start) * 1e9,
                r.error,
                "b--",
                label=f"model restarted at {start * 1e9:.2f} ns",
            )
        bx.axhline(
            VALIDATION_GOAL, color="r", lw=0.8, ls="--", label=f"goal {VALIDATION_GOAL:g} d_sk"
        )
        bx.set(
            xlabel="t [ns]", ylabel="RMS centre error [d_sk]", title=f"max {v.error.max():.3f} d_sk"
        )
        bx.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(tmp, dpi=110)
        plt.close(fig)

    return write_figure(path, draw, record(cal))


def plot_breathing(cal: Calibration, path: Path) -> Path:
    """Plot E_self(R) of the breathing scan to ``path`` (PNG), and R against the field offset."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from scipy import interpolate

    b = cal.breathing
    points = b["points"]
    r = np.array([p["radius_m"] for p in points])
    e = np.array([p["energy_J"] for p in points])
    e_int = np.array([p["energy_integrated_J"] for p in points])
    field = np.array([p["field_T"] for p in points])
    r0 = cal.isolated.radius
    e0 = cal.isolated.energy

    def draw(tmp):
        fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.5))
        fine = np.linspace(r[0], r[-1], 200)
        curve = interpolate.PchipInterpolator(r, e)(fine)
        ax.plot(fine * 1e9, (curve - e0) * 1e21, "k-", lw=1, label="table (PCHIP)")
        ax.plot(r * 1e9, (e - e0) * 1e21, "ko", ms=5, label="relaxed at H_ref + b (subtracted)")
        ax.plot(r * 1e9, (e_int - e0) * 1e21, "rx", ms=7, label="−M_s t ∫ B dA_m (multiplier only)")
        ax.axvline(r0 * 1e9, color="0.5", ls="--", lw=0.8, label=f"R₀ = {r0 * 1e9:.2f} nm")
        ax.set(
            xlabel="radius R [nm]",
            ylabel="E_self(R) − E_self(R₀) [zJ]",
            title=f"self-energy; model: {b['particle_model']}",
        )
        ax.legend(fontsize=8)
        bx.plot(field * 1e3, r * 1e9, "ko-", ms=4)
        bx.axhline(r0 * 1e9, color="0.5", ls="--", lw=0.8)
        bx.set(xlabel="field offset B [mT]", ylabel="radius R [nm]", title="radius against field")
        fig.tight_layout()
        fig.savefig(tmp, dpi=110)
        plt.close(fig)

    return write_figure(path, draw, record(cal))


# -- everything ------------------------------------------------------------------------------------
def write_results(job, out: Path) -> dict[str, Any]:
    """Analyse ``job`` and write its files into ``out``; returns summary.json's data."""
    cal = analyse(job)
    data = summary(cal, job)
    plot_profile(cal, out / "profile.png")
    plot_law(cal, "pair", out / "pair.png")
    plot_law(cal, "wall", out / "wall.png")
    if cal.validation is not None:
        plot_validation(cal, out / "validation.png")
    if cal.breathing.get("spec"):
        plot_breathing(cal, out / "breathing.png")
    _save_textures(job, out / "textures.npz")
    write_json(out / "summary.json", data)
    write_model_file(cal, job, out / "model.toml")
    from skygas.calibration.report import write_report

    write_report(cal, data, out)
    return data


def _save_textures(job, path: Path) -> None:
    """The relaxed isolated skyrmion and the validation run's first and last textures."""
    from skygas.runs.run_driver import write_atomic

    arrays = {}
    prefix = job.isolated_prefix()
    if prefix is not None:
        arrays["isolated"] = job.textures[f"{prefix}/single"]
    if "validation/start" in job.textures:
        arrays["validation_start"] = job.textures["validation/start"]
    if job.llg_m is not None:
        arrays["validation_end"] = job.llg_m
    # Any values: typed as arrays, mypy would match the ``**`` below against savez_compressed's
    # bool ``allow_pickle`` (the keys are array names)
    meta: dict[str, Any] = {
        "skygas_version": np.array(__version__),
        "config_json": np.array(job.config.model_dump_json()),
        "layout": np.array(
            "m[i, j, component], cell (i, j) centred at ((i + 1/2) cell, (j + 1/2) cell)"
        ),
    }
    write_atomic(path, lambda tmp: np.savez_compressed(tmp, **arrays, **meta))
