"""A finished calibration's numbers: the isolated skyrmion, the laws, the checks, the model.

:func:`analyse` turns the solves of a :class:`~skygas.calibration.pipeline.CalibrationJob`
into a :class:`Calibration`: what :mod:`skygas.calibration.results` writes (model.toml,
summary.json, the figures and the report). Energies are in J, lengths in m, forces in N;
"d_sk" is the isolated skyrmion's measured diameter and F₀ = A_ex t_F/d_sk.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from skygas.calibration import laws, plan
from skygas.calibration.profile import IsolatedSkyrmion, measure_isolated
from skygas.core.errors import InputError
from skygas.core.units import MU_0

#: Skyrmions whose measured |Q| is below this are not (or no longer) skyrmions.
MIN_CHARGE = 0.9
#: The validation is also compared from the micromagnetic positions this long [s] after the
#: release (or a quarter of the run, if shorter).
RESTART_TIME = 0.5e-9
#: The profile for the stray field ends where 1 − m_z has fallen below this.
PROFILE_TAIL = 0.01


@dataclass
class Calibration:
    """Everything a calibration found (see the module docstring)."""

    config: plan.CalibrationConfig
    isolated: IsolatedSkyrmion
    diameter: float
    force_scale: float
    pair_energy: laws.EnergyCurve
    wall_energy: laws.EnergyCurve
    pair: laws.ForceLaw
    wall: laws.ForceLaw
    profile_radius: np.ndarray
    profile_deficit: np.ndarray
    straight_edge_x: np.ndarray
    straight_edge_force: np.ndarray
    fits: dict[str, Any]
    checks: dict[str, Any] = field(default_factory=dict)
    validation: Any = None
    validation_restarted: Any = None
    validation_note: str = ""
    #: the validation of each particle model the calibration measured ("rigid", "breathing")
    validation_models: dict[str, Any] = field(default_factory=dict)
    provenance: dict[str, Any] = field(default_factory=dict)
    #: the breathing measurement and the model's choice
    #: (:func:`skygas.calibration.breathing.measure`)
    breathing: dict[str, Any] = field(default_factory=dict)

    def material_table(self) -> dict[str, Any]:
        """The ``[material]`` table of model.toml (a :class:`skygas.physics.materials.Material`)."""
        m = self.config.material
        iso = self.isolated
        pair_fit = self.fits["pair"]["coefficients"]
        wall_fit = self.fits["wall"]["coefficients"]
        from skygas.physics.materials import preset

        paper = preset("S2")  # the paper's forms, when a fit of this material's laws failed
        return {
            "name": f"{m.name}-calibrated",
            "saturation_magnetization": m.saturation_magnetization,
            "exchange_stiffness": m.exchange_stiffness,
            "dmi": m.total_dmi,
            "anisotropy": m.anisotropy,
            "applied_field": m.applied_field,
            "skyrmion_radius": iso.radius,
            "damping": m.damping,
            "pair_law": list(pair_fit) if pair_fit else list(paper.pair_law),
            "wall_law": list(wall_fit) if wall_fit else list(paper.wall_law),
            "topological_charge": -1 if iso.charge < 0 else 1,
            "dissipation": iso.dissipation,
            "wall_width": iso.wall_width,
            "film_thickness": m.film_thickness,
            "gyromagnetic_ratio": m.gyromagnetic_ratio,
            "pair_table": {
                "distance": self.pair.distance.tolist(),
                "force": self.pair.force.tolist(),
            },
            "wall_table": {
                "distance": self.wall.distance.tolist(),
                "force": self.wall.force.tolist(),
            },
            "stray_field": {
                "profile_radius": self.profile_radius.tolist(),
                "profile_deficit": self.profile_deficit.tolist(),
            },
            "particle_model": self.breathing.get("particle_model", "rigid"),
            "breathing": self.breathing.get("spec"),
            # the wall law was measured one straight edge at a time: every edge in reach acts
            "wall_geometry": "film",
        }

    def particle_material(self, stray_field: bool = True):
        """The calibrated :class:`~skygas.physics.materials.Material`.

        Without its stray-field profile when ``stray_field`` is False: a compensated film has no
        edge stray field.
        """
        from skygas.physics.materials import material_from_mapping

        table = self.material_table()
        if not stray_field:
            table.pop("stray_field")
        return material_from_mapping(table, field="calibrated material")


def valid_solve(result: dict, count: int) -> bool:
    """Whether a relaxation kept its ``count`` skyrmions, each whole and where it was held.

    Whole: |Q| ≥ :data:`MIN_CHARGE` and a m_z = 0 contour. Where held: within half its radius
    of a held centre. An S2 single held 0.6 d_sk from the edge leaves through it, and what the
    detector then finds (a charge of 0.99 spread over the film, no contour, 4.2 d_sk away) is
    not a point of the law.
    """
    found = result["skyrmions"]
    if len(found) != count or any(abs(s["charge"]) < MIN_CHARGE for s in found):
        return False
    held = result.get("centres", [])
    for s in found:
        if not math.isfinite(s["radius"]):
            return False
        if held and min(math.hypot(s["x"] - x, s["y"] - y) for x, y in held) > 0.5 * s["radius"]:
            return False
    return True


def _distance(result: dict) -> float:
    a, b = result["skyrmions"]
    return math.hypot(a["x"] - b["x"], a["y"] - b["y"])


def energy_curves(results: dict[str, dict], prefix: str = "laws"):
    """(pair curve, short-range wall curve) of a calibration film.

    See :mod:`skygas.calibration.laws`. A skyrmion that escaped through the edge or merged with its
    neighbour drops its point, with the reason.
    """
    singles = {
        int(k.rsplit("/", 1)[1]): v for k, v in results.items() if k.startswith(f"{prefix}/single/")
    }
    pairs = {
        int(k.rsplit("/", 1)[1]): v for k, v in results.items() if k.startswith(f"{prefix}/pair/")
    }
    uniform = results[f"{prefix}/uniform"]["energy"]
    centre = singles[max(singles)]
    if not valid_solve(centre, 1):
        raise InputError(
            "material",
            "the calibration film",
            "a skyrmion that stays one in the middle of the calibration film",
        )
    wall_points, dropped = [], []
    for _, single in sorted(singles.items()):
        if valid_solve(single, 1):
            wall_points.append((single["skyrmions"][0]["x"], single["energy"] - centre["energy"]))
        else:
            dropped.append((single["centres"][0][0], "the skyrmion left through the edge"))
    pair_points, pair_dropped = [], []
    for i, pair in sorted(pairs.items()):
        nominal = math.dist(pair["centres"][0], pair["centres"][1])
        if not valid_solve(pair, 2):
            pair_dropped.append((nominal, "the two skyrmions did not stay two"))
        elif i not in singles or not valid_solve(singles[i], 1):
            pair_dropped.append((nominal, "its reference single is not a skyrmion"))
        else:
            pair_points.append(
                (_distance(pair), pair["energy"] - 2 * singles[i]["energy"] + uniform)
            )
    return laws.curve(pair_points, pair_dropped), laws.curve(wall_points, dropped)


def stray_profile(isolated: IsolatedSkyrmion) -> tuple[np.ndarray, np.ndarray]:
    """(ρ [m], w = 1 − m_z): the isolated profile, up to where w has decayed.

    Up to where w has decayed below PROFILE_TAIL beyond the wall (0 from there: the stray field's
    profile must end low).
    """
    r = np.asarray(isolated.profile_radius)
    w = 1.0 - np.asarray(isolated.profile_mz)
    outside = np.nonzero((r > isolated.radius) & (w < PROFILE_TAIL))[0]
    end = int(outside[0]) + 1 if len(outside) else len(r)
    w = np.clip(w[:end], 0.0, 2.0)
    w[-1] = min(w[-1], PROFILE_TAIL)
    return r[:end], w


def _isolated(job) -> tuple[IsolatedSkyrmion, Any]:
    prefix = job.isolated_prefix()
    single, uniform = job.results[f"{prefix}/single"], job.results[f"{prefix}/uniform"]
    film = job.isolated_film()
    iso = measure_isolated(
        job.textures[f"{prefix}/single"],
        film,
        job.config.material,
        single["energy"] - uniform["energy"],
    )
    return iso, film


def _check_enlarged(job, iso: IsolatedSkyrmion) -> dict:
    r = job.results
    if "enlarged/single" not in r or not valid_solve(r["enlarged/single"], 1):
        return {}
    radius = r["enlarged/single"]["skyrmions"][0]["radius"]
    energy = r["enlarged/single"]["energy"] - r["enlarged/uniform"]["energy"]
    return {
        "film_side_m": job.isolated_film().size[0],
        "enlarged_side_m": [s.film for s in job.planned() if s.name == "enlarged/single"][0].size[
            0
        ],
        "radius_m": [iso.radius, radius],
        "energy_J": [iso.energy, energy],
        "radius_change": radius / iso.radius - 1.0,
        "energy_change": energy / iso.energy - 1.0,
    }


def _check_sensitivity(job, iso: IsolatedSkyrmion) -> dict:
    r = job.results
    if not all(k in r and valid_solve(r[k], 1) for k in ("sensitivity/plus", "sensitivity/minus")):
        return {}
    plus = r["sensitivity/plus"]["skyrmions"][0]["radius"]
    minus = r["sensitivity/minus"]["skyrmions"][0]["radius"]
    slope = (plus - minus) / (2 * plan.SENSITIVITY_STEP)  # m/T
    return {
        "field_step_T": plan.SENSITIVITY_STEP,
        "radius_plus_m": plus,
        "radius_minus_m": minus,
        "radius_per_tesla_m": slope,
        "relative_change_per_mT": slope * 1e-3 / iso.radius,
    }


def _check_mesh(job, pair: laws.ForceLaw, pair_energy: laws.EnergyCurve, diameter: float) -> dict:
    r = job.results
    out: dict[str, Any] = {}
    for label in ("coarse", "fine"):
        keys = [f"mesh/{label}/{k}" for k in ("uniform", "single", "pair")]
        if not all(k in r for k in keys) or not (
            valid_solve(r[keys[1]], 1) and valid_solve(r[keys[2]], 2)
        ):
            return {}
        out[label] = {
            "distance_m": _distance(r[keys[2]]),
            "energy_J": r[keys[2]]["energy"] - 2 * r[keys[1]]["energy"] + r[keys[0]]["energy"],
            "radius_m": r[keys[1]]["skyrmions"][0]["radius"],
        }
    cell = job.config.material.cell_size
    out["cells_m"] = [cell, cell / 2]
    # Each mesh holds the pair at its cells nearest to 1.5 d_sk: the two distances differ by up
    # to a coarse cell, and there the pair energy changes by tens of percent per cell (S6, 2 nm
    # cells: 36.2 and 34.1 nm, 28 % apart on the curve). The fine energy is therefore taken to
    # the coarse distance along the calibrated curve (the spline through ln E that the force
    # law differentiates) before the two are compared; the mesh's own effect on the curve's
    # slope over that step is of second order.
    d_coarse, d_fine = out["coarse"]["distance_m"], out["fine"]["distance_m"]
    ratio = out["fine"]["energy_J"] / out["coarse"]["energy_J"]
    along = _log_energy_step(pair_energy, d_fine, d_coarse)
    out["energy_change_as_held"] = ratio - 1.0
    out["energy_change"] = (ratio * math.exp(along) if along is not None else ratio) - 1.0
    out["energy_at_same_distance"] = along is not None
    out["radius_change"] = out["fine"]["radius_m"] / out["coarse"]["radius_m"] - 1.0
    return out


def _log_energy_step(curve: laws.EnergyCurve, start: float, end: float) -> float | None:
    """The step of ln E from ``start`` to ``end`` [m] along ``curve``'s spline through ln E.

    None where either distance lies outside the curve's positive energies.
    """
    d, e = curve.distance, curve.energy
    positive = e > 0
    if not positive.all():  # as the force law: the tail that vanished into rounding left out
        last = int(np.argmin(positive))
        d, e = d[:last], e[:last]
    if len(d) < 4 or not (d[0] <= min(start, end) and max(start, end) <= d[-1]):
        return None
    from scipy import interpolate

    spline = interpolate.CubicSpline(d, np.log(e), bc_type="not-a-knot")
    return float(spline(end) - spline(start))


def _check_stray(job, wall_energy: laws.EnergyCurve, profile, diameter: float) -> dict:
    """The singles at the real straight edge against the model.

    The model: the short-range energy (interpolated from the compensated film's curve) plus the
    first-order energy in the edge's stray field
    (:func:`~skygas.calibration.laws.halfplane_stray_energy`), both relative to the film's centre.
    """
    r = job.results
    singles = {int(k.rsplit("/", 1)[1]): v for k, v in r.items() if k.startswith("stray/single/")}
    if not singles or not all(valid_solve(s, 1) for s in singles.values()):
        return {}
    m = job.config.material

    def model(x):
        u = laws.halfplane_stray_energy(x, m.saturation_magnetization, m.film_thickness, *profile)[
            0
        ]
        return float(u + np.interp(x, wall_energy.distance, wall_energy.energy, right=0.0))

    centre = singles[max(singles)]
    c = centre["skyrmions"][0]
    rows = []
    for i, single in sorted(singles.items()):
        if i == max(singles):
            continue
        s = single["skyrmions"][0]
        rows.append(
            {
                "x_m": s["x"],
                "x_d_sk": s["x"] / diameter,
                "micromagnetic_J": single["energy"] - centre["energy"],
                "model_J": model(s["x"]) - model(c["x"]),
                "radius_m": s["radius"],
            }
        )
    return {"points": rows, "centre_radius_m": c["radius"], "centre_x_m": c["x"]}


def analyse(job) -> Calibration:
    """The numbers of a finished calibration job (see the module docstring)."""
    config = job.config
    material = config.material
    iso, _ = _isolated(job)
    diameter = iso.diameter
    force_scale = material.exchange_stiffness * material.film_thickness / diameter
    pair_energy, wall_energy = energy_curves(job.results)
    try:
        pair = laws.force_law(pair_energy, force_scale)
        wall = laws.force_law(wall_energy, force_scale, continued=True)
    except ValueError as err:
        raise InputError(
            "material",
            material.name,
            f"a film whose skyrmions repel each other and the edges ({err})",
        ) from None
    radius, deficit = stray_profile(iso)
    x = np.linspace(max(wall.distance[0], 0.5 * diameter), 5.0 * diameter, 60)
    edge_force = laws.straight_edge_force(
        wall, x, material.saturation_magnetization, material.film_thickness, radius, deficit
    )
    fits = laws.paper_form_fits(pair, x, edge_force, diameter, force_scale)
    calibration = Calibration(
        config,
        iso,
        diameter,
        force_scale,
        pair_energy,
        wall_energy,
        pair,
        wall,
        radius,
        deficit,
        x,
        edge_force,
        fits,
    )
    calibration.checks = {
        "enlarged": _check_enlarged(job, iso),
        "sensitivity": _check_sensitivity(job, iso),
        "mesh": _check_mesh(job, pair, pair_energy, diameter) if config.mesh_check else {},
        "stray_field": _check_stray(job, wall_energy, (radius, deficit), diameter),
        "reference_field_T": MU_0 * config.reference_field,
    }
    from skygas.calibration.breathing import measure

    calibration.breathing = measure(job, calibration)
    if config.validate_dynamics and "validation/start" in job.results:
        from skygas.calibration.validation import compare, compare_models

        particle = calibration.particle_material(stray_field=False)
        arguments = (
            job.validation_film(),
            job.results["validation/start"]["skyrmions"],
            job.llg["frames"],
            diameter,
            material.film_thickness,
        )

        def run_compare(settle: float = 0.0):
            return compare(particle, *arguments, settle=settle)

        # both particle models against the same micromagnetic run, where both exist; the
        # better one is the model's
        from skygas.calibration.breathing import choose_by_validation

        calibration.validation_models = compare_models(particle, *arguments)
        if choose_by_validation(calibration.breathing, calibration.validation_models) != (
            particle.particle_model
        ):
            particle = calibration.particle_material(stray_field=False)
        result = calibration.validation_models[particle.particle_model]
        calibration.validation = result
        if result is not None and len(result.times) > 8:
            # the same comparison restarted after the release (the hold let go at t = 0,
            # the skyrmions take up the shape of moving ones): what remains is the model's
            calibration.validation_restarted = run_compare(
                settle=min(RESTART_TIME, 0.25 * float(result.times[-1]))
            )
        if result is None:
            calibration.validation_note = (
                "a skyrmion of the micromagnetic run was lost "
                "(annihilated or merged): nothing to compare"
            )
    return calibration
