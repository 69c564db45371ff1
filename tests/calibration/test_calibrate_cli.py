"""`skygas calibrate` end to end on a small, cheap film (S6: 23 nm skyrmions on 2 nm cells):
the model file, the laws' physics, the validation, the model running in the engine, and the
report, every headline number of which is recomputed from the files beside it.

Every test that reads the calibration (the session fixture ``calibrated`` of
tests/calibration/conftest.py, minutes of micromagnetics) is in this one module: the suite runs
with ``--dist loadscope``, which keeps a module on one worker, so the calibration is made once
(two modules on two workers made it twice). Resume after an interruption, which makes its own
calibrations, is in test_calibrate_resume.py, free to run on the other worker.

The report's checks: the headline block of report.html (its quality-check rows and the
summary's sentences) is read and each number is recomputed here, with code of its own, from what
the calibration wrote: model.toml's tables and Thiele numbers, the material and the raw
energies, radii and trajectories of summary.json; and each verdict from the tolerance the report
states. A stated number agrees when it lies within half a unit of its last printed digit of the
recomputed one.
"""

from __future__ import annotations

import json
import math
import re
import tomllib

import numpy as np
import pytest
from scipy import integrate, interpolate
from tests.outputs.test_headlines_recomputed import _numbers, agrees, captions, headline

pytest.importorskip("magnumnp")

from skygas import cli  # noqa: E402
from skygas.physics.materials import load_material  # noqa: E402

pytestmark = pytest.mark.slow


def test_writes_the_model_report_and_numbers(calibrated):
    for name in (
        "model.toml",
        "summary.json",
        "report.html",
        "profile.png",
        "pair.png",
        "wall.png",
        "validation.png",
        "textures.npz",
        "manifest.json",
    ):
        assert (calibrated / name).is_file(), name
    material = load_material(calibrated / "model.toml")
    data = json.loads((calibrated / "summary.json").read_text())
    iso = data["isolated"]
    assert material.skyrmion_radius == iso["radius"] and material.film_thickness == 2e-9
    assert material.pair_table is not None and material.wall_table is not None
    assert material.stray_field is not None
    assert abs(iso["charge"] + 1) < 1e-3 and iso["gyrocoupling"] > 0
    report = (calibrated / "report.html").read_text()
    assert f"{iso['radius'] * 1e9:.2f} nm" in report
    assert "<section class=headline id=headline>" in report  # the summary sentences first
    # the calibration's own report is never replaced by `skygas report`'s
    assert cli.main(["report", str(calibrated)]) == 2
    assert (calibrated / "report.html").read_text() == report
    assert data["skygas_version"] and data["provenance"]["magnumnp_version"]


def test_pair_energy_decreases_to_zero_and_the_edge_repels(calibrated):
    data = json.loads((calibrated / "summary.json").read_text())
    pair, wall = data["pair"], data["wall_short_range"]
    e = np.array(pair["energy_J"])
    assert np.all(np.diff(e) < 0) and e[-1] < 0.02 * e[0]
    assert pair["measured_range_d_sk"][0] < 1.2 and pair["measured_range_d_sk"][1] > 4
    f = np.array(pair["table_force_N"])
    assert np.all(f >= 0) and f[-1] < 1e-3 * f[0]
    w = np.array(wall["energy_J"])
    assert np.all(np.diff(w) < 0)  # farther from the edge, lower energy: repulsive
    wf = np.array(wall["table_force_N"])
    assert np.all(wf > 0) and np.all(np.diff(wf) <= 0)


def test_validation_compares_a_run_that_moved_half_a_diameter(calibrated):
    data = json.loads((calibrated / "summary.json").read_text())
    v = data["validation"]
    assert data["config"]["validation"]["min_travel"] == 0.5
    assert v["skyrmions"] == 3 and min(v["path_length_d_sk"]) >= 0.5
    error = np.array(v["error_d_sk"])
    assert error[0] == 0.0 and np.all(np.isfinite(error))
    # the model follows the micromagnetic skyrmions: far closer than they moved
    assert v["rms_error_max_d_sk"] < 0.5 * min(v["path_length_d_sk"])


def test_the_model_runs_in_simulate_and_reshuffle(calibrated, tmp_path):
    config = tmp_path / "chamber.toml"
    config.write_text(
        f'material = "{calibrated / "model.toml"}"\nduration = 2e-9\n'
        "temperature = 300\nrecord_interval = 1e-10\n"
        '[geometry]\nkind = "shapes"\n[[geometry.shapes]]\nkind = "disk"\n'
        "diameter = 300e-9\n[skyrmions]\nrandom_count = 6\n"
    )
    assert (
        cli.main(
            ["simulate", str(config), "--out", str(tmp_path / "sim"), "--quiet", "--no-report"]
        )
        == 0
    )
    import xarray as xr

    with xr.open_dataset(tmp_path / "sim" / "trajectories.nc") as ds:
        parameters = json.loads(ds.attrs["parameters_json"])
    assert parameters["pair_law"] == "table" and parameters["wall_law"] == "table"
    assert parameters["edge_stray_field"]
    assert (
        cli.main(
            [
                "reshuffle",
                "--material",
                str(calibrated / "model.toml"),
                "--duration",
                "2e-8",
                "--out",
                str(tmp_path / "rs"),
                "--quiet",
                "--no-report",
            ]
        )
        == 0
    )


# -- the report ---------------------------------------------------------------------------------
#: the tolerances the report states
MESH, FILM_SIZE, EDGE, GOAL = 0.05, 0.02, 0.25, 0.1


def _after(text: str, words: str) -> str:
    assert words in text, (words, text)
    return text.split(words, 1)[1]


def _note(notes: list[str], start: str) -> str:
    (found,) = [n for n in notes if n.startswith(start)]
    return found


def _verdict(row: str, passed: bool) -> None:
    assert row.startswith("passed: " if passed else "FAILED: "), row


def _files(folder):
    data = json.loads((folder / "summary.json").read_text())
    model = tomllib.loads((folder / "model.toml").read_text())
    return data, model


def rms_error(a: np.ndarray, b: np.ndarray, diameter: float) -> np.ndarray:
    """RMS over skyrmions of the distance between two runs' positions, per frame [d_sk]."""
    return np.sqrt(np.mean(np.sum((a - b) ** 2, axis=-1), axis=1)) / diameter


def test_the_checks_lead_and_are_recomputed_from_the_raw_numbers(calibrated):
    data, model = _files(calibrated)
    rows, _ = headline(calibrated / "report.html")
    names = [c["name"] for c in data["quality_checks"]]
    assert list(rows)[: len(names)] == names  # the checks are the headline's first rows
    d_sk = 2 * model["material"]["skyrmion_radius"]
    assert data["isolated"]["diameter"] == pytest.approx(d_sk, rel=1e-12)

    # the mesh: the fine pair energy taken to the coarse pair's distance along ln E of the
    # calibrated pair energies (a cubic spline through them, written here)
    mesh = data["checks"]["mesh"]
    d_c, d_f = mesh["coarse"]["distance_m"], mesh["fine"]["distance_m"]
    e = np.array(data["pair"]["energy_J"])
    d = np.array(data["pair"]["energy_distance_m"])
    positive = e > 0
    spline = interpolate.CubicSpline(d[positive], np.log(e[positive]))
    as_held = mesh["fine"]["energy_J"] / mesh["coarse"]["energy_J"]
    change = as_held * math.exp(float(spline(d_c) - spline(d_f))) - 1
    row = rows["mesh: pair energy"]
    _verdict(row, abs(change) <= MESH)
    agrees(_after(row, " at "), d_c / d_sk)
    agrees(_after(row, " by "), change)
    agrees(_after(row, "at most ±"), MESH)
    if "held the pair at" in row:
        agrees(_after(row, "held the pair at "), d_f / d_sk)
        agrees(_after(row, "as held, "), as_held - 1)
    radius = mesh["fine"]["radius_m"] / mesh["coarse"]["radius_m"] - 1
    row = rows["mesh: radius"]
    _verdict(row, abs(radius) <= MESH)
    agrees(_after(row, " by "), radius)

    enlarged = data["checks"]["enlarged"]
    radius = enlarged["radius_m"][1] / enlarged["radius_m"][0] - 1
    energy = enlarged["energy_J"][1] / enlarged["energy_J"][0] - 1
    row = rows["film size"]
    _verdict(row, abs(radius) <= FILM_SIZE)
    agrees(_after(row, "in a film "), enlarged["enlarged_side_m"] / enlarged["film_side_m"])
    agrees(_after(row, "radius changes by "), radius)
    agrees(_after(row, "does not use, by "), energy)

    points = data["checks"]["stray_field"]["points"]
    # the model written is judged: a breathing one with its radius free at the edge
    key = "breathing_model_J" if data["breathing"]["particle_model"] == "breathing" else "model_J"
    ratios = [p[key] / p["micromagnetic_J"] for p in points]
    row = rows["edge energy at a real edge"]
    _verdict(row, all(abs(r - 1) <= EDGE for r in ratios))
    stated = _numbers(_after(row, "real film is "))
    for k, (r, p) in enumerate(zip(ratios, points, strict=True)):
        agrees(stated[2 * k].text, r)
        agrees(stated[2 * k + 1].text, p["x_m"] / d_sk)

    # the validation: the RMS centre error recomputed from both runs' trajectories
    v = data["validation"]
    error = rms_error(np.array(v["particle_m"]), np.array(v["micromagnetic_m"]), d_sk)
    row = rows["validation"]
    _verdict(row, error.max() <= GOAL)
    agrees(_after(row, "at most "), error.max())
    agrees(_after(row, " over "), v["times_s"][-1], unit="s")
    agrees(_after(row, "(at most "), GOAL)


def test_the_summary_sentences_are_recomputed_from_the_model_and_material(calibrated):
    data, model = _files(calibrated)
    _, notes = headline(calibrated / "report.html")
    m, iso = data["material"], data["isolated"]
    table = model["material"]
    radius, width = table["skyrmion_radius"], table["wall_width"]
    d_sk = 2 * radius

    text = _note(notes, "The isolated skyrmion")
    agrees(_after(text, "radius of "), radius, unit="m")
    agrees(_after(text, "wall width of "), width, unit="m")
    # G = −4πQk, k = M_s t/γ; F₀ = A t/d_sk; the thin-wall 𝒟 = 2π(R/Δ₀ + Δ₀/R), Δ₀ = √(A/K_u)
    k = m["saturation_magnetization"] * m["film_thickness"] / m["gyromagnetic_ratio"]
    agrees(_after(text, "(k = "), k)
    agrees(_after(text, "G = −4πQk = "), -4 * math.pi * iso["charge"] * k)
    agrees(_after(text, "Q = "), iso["charge"])
    agrees(_after(text, "𝒟 = "), table["dissipation"])
    delta0 = math.sqrt(m["exchange_stiffness"] / m["anisotropy"])
    agrees(_after(text, "√(A/K_u) = "), delta0, unit="m")
    agrees(_after(text, "gives "), 2 * math.pi * (radius / delta0 + delta0 / radius))
    agrees(_after(text, "d_sk = "), d_sk, unit="m")
    f0 = m["exchange_stiffness"] * m["film_thickness"] / d_sk
    agrees(_after(text, "F₀ = A t/d_sk = ").rstrip("."), f0, unit="N")  # the parser keeps a "."

    # the forces at whole distances: model.toml's tables, interpolated as the engine does (PCHIP)
    for start, name, distances in (
        ("Pair repulsion", "pair_table", (1.0, 1.5, 2.0, 3.0)),
        ("Edge repulsion", "wall_table", (1.0, 1.5, 2.0)),
    ):
        text = _note(notes, start)
        law = interpolate.PchipInterpolator(table[name]["distance"], table[name]["force"])
        key = "pair" if name == "pair_table" else "wall_short_range"
        lo, hi = (x / d_sk for x in data[key]["measured_range_m"])
        agrees(_after(text, "measured from "), lo)
        agrees(_after(text, f"{lo:.2f} to "), hi)
        if name == "wall_table":  # continued along its tangent below the measured range
            agrees(_after(text, "tangent down to "), table[name]["distance"][0] / d_sk)
        for x in distances:
            if lo <= x <= hi:
                stated = re.search(rf"([\d.]+ [fpn]?N) at {x:g} d_sk", text)
                assert stated, (x, text)
                agrees(stated.group(1), float(law(x * d_sk)), unit="N")

    text = _note(notes, "The skyrmion's size follows the field")
    s = data["checks"]["sensitivity"]
    per_mt = (s["radius_plus_m"] - s["radius_minus_m"]) / (2 * s["field_step_T"]) * 1e-3 / radius
    agrees(_after(text, "field: "), per_mt)

    text = _note(notes, "Validation:")
    v = data["validation"]
    mm, pm = np.array(v["micromagnetic_m"]), np.array(v["particle_m"])
    error = rms_error(pm, mm, d_sk)
    paths = np.linalg.norm(np.diff(mm, axis=0), axis=-1).sum(axis=0) / d_sk
    assert text.startswith(f"Validation: {mm.shape[1]} skyrmions")
    width, height = v["rectangle_m"]  # the default validation film
    agrees(_after(text, "a rectangle of "), width, unit="m")
    agrees(_after(text, " × "), height, unit="m")
    agrees(_after(text, "T = 0 for "), v["times_s"][-1], unit="s")
    agrees(_after(text, "each moved "), paths.min())
    agrees(_after(text, f"{paths.min():.2f}–"), paths.max())
    agrees(_after(text, "error is at most "), error.max())
    agrees(_after(text, "(final "), error[-1])
    agrees(_after(text, "mean "), error.mean())
    if "Over the run" in text:
        travelled = np.linalg.norm(np.diff(pm, axis=0), axis=-1).sum() / (paths.sum() * d_sk)
        agrees(_after(text, "travel "), travelled)


def test_every_figure_has_a_caption_that_says_what_it_draws(calibrated):
    data, model = _files(calibrated)
    found = captions(calibrated / "report.html")
    assert len(found) == 5 and not any(".png" in c for c in found)
    profile, pair, wall, validation, breathing = found
    radius = model["material"]["skyrmion_radius"]
    assert profile.startswith("The isolated skyrmion's m_z against the distance r")
    agrees(_after(profile, "R = "), radius, unit="m")
    assert pair.startswith("Left: the pair law |F| against the centre distance")
    assert wall.startswith("Left: the short-range edge law |F|")
    assert "blue, the force at a straight edge of a real film" in wall
    v = data["validation"]
    error = rms_error(np.array(v["particle_m"]), np.array(v["micromagnetic_m"]), 2 * radius)
    agrees(_after(validation, "Its maximum, "), error.max())
    assert ("validation check failed" in validation) == (error.max() > GOAL)
    assert breathing.startswith("Left: the isolated skyrmion's self-energy E_self against")
    agrees(_after(breathing, "R₀ = "), radius, unit="m")
    page = (calibrated / "report.html").read_text()
    assert "<p class=made>Made by <code class=command>skygas calibrate S6" in page
    assert re.search(r"on \d{4}-\d\d-\d\d \d\d:\d\d UTC", page)


# -- the breathing measurement ------------------------------------------------------------------
# The field scan's E_self(R) (model.toml's [material.breathing]) against the Lagrange relation
# of a uniform field b: relaxed at H_ref + b, the skyrmion sits where dE_self/dA_m = −M_s t B
# (A_m = ∫(1 − m_z) dA, B = μ₀b), so −dE_self/dR ≈ 4πR M_s t B for its thin-wall area 2πR²;
# 𝒟_RR against the 360° wall ansatz's ∫(∂_R θ)² dA and the thin-wall 4πR/Δ (written here).


def _breathing(folder):
    data, model = _files(folder)
    table = model["material"]["breathing"]
    points = {p["radius_m"]: p for p in data["breathing"]["points"]}
    radius = np.array(table["radius"])
    energy = np.array(table["energy"])
    field = np.array([points[r]["field_T"] for r in radius])
    return data, model, radius, energy, field


def test_the_self_energy_is_lowest_at_the_isolated_radius(calibrated):
    data, model, radius, energy, field = _breathing(calibrated)
    r0 = model["material"]["skyrmion_radius"]
    assert len(radius) >= 5 and radius[0] < 0.85 * r0 and radius[-1] > 1.1 * r0
    # the minimum of a spline through the other points, not the point measured at R₀ itself
    others = radius != r0
    spline = interpolate.CubicSpline(radius[others], energy[others])
    fine = np.linspace(radius[0], radius[-1], 20_001)
    lowest = fine[np.argmin(spline(fine))]
    cell = data["material"]["cell_size"]
    assert abs(lowest - r0) < 0.05 * cell  # 0.1 nm on 2 nm cells
    assert energy[radius == r0][0] == pytest.approx(data["isolated"]["energy"], rel=1e-12)


def test_the_self_energys_slope_is_the_fields_lagrange_force(calibrated):
    data, model, radius, energy, field = _breathing(calibrated)
    m = data["material"]
    ms_t = m["saturation_magnetization"] * m["film_thickness"]
    force = -interpolate.CubicSpline(radius, energy)(radius, 1)  # −dE_self/dR
    thin_wall = 4 * math.pi * radius * ms_t * field
    # within 5 % of the largest force (the spline through 7 points, and A_m ≠ 2πR² exactly)
    assert np.abs(force - thin_wall).max() < 0.05 * np.abs(thin_wall).max()
    # each step of E_self against the multiplier's work −M_s t ∫ B dA_m (trapezoids)
    points = sorted(data["breathing"]["points"], key=lambda p: p["moment_deficit_m2"])
    area = np.array([p["moment_deficit_m2"] for p in points])
    b = np.array([p["field_T"] for p in points])
    e = np.array([p["energy_J"] for p in points])
    work = -ms_t * 0.5 * (b[1:] + b[:-1]) * np.diff(area)
    assert np.abs(np.diff(e) - work).max() < 0.05 * np.ptp(e)


def test_radius_dissipation_against_the_ansatz_and_the_thin_wall(calibrated):
    data, model, *_ = _breathing(calibrated)
    table = model["material"]
    r, width = table["skyrmion_radius"], table["wall_width"]
    measured = table["breathing"]["radius_dissipation"]
    s, c = math.sinh(r / width), math.cosh(r / width)

    def integrand(x):  # (∂_R θ)² r of θ = 2 atan[sinh(R/Δ)/sinh(r/Δ)]
        sh = math.sinh(x / width)
        return (2 * c * sh / (width * (sh * sh + s * s))) ** 2 * x

    ansatz = 2 * math.pi * integrate.quad(integrand, 0, r + 40 * width, points=[r])[0]
    assert measured == pytest.approx(ansatz, rel=0.10)
    assert measured == pytest.approx(4 * math.pi * r / width, rel=0.25)


def test_the_centres_dissipation_follows_the_radius_as_the_360_degree_wall_says(calibrated):
    """𝒟(R) of the scan's textures, as model.toml writes it: measured at every scan point,
    growing with R, and its ratio to 𝒟(R₀) within 8 % of the 360° wall ansatz's
    π∫(θ'² + sin²θ/r²) r dr at the isolated Δ (computed here by quadrature), whose wall keeps
    its width; the measured 𝒟 changes less, as the wall of a squeezed skyrmion widens."""
    data = json.loads((calibrated / "summary.json").read_text())
    spec = load_material(calibrated / "model.toml").breathing
    points = data["breathing"]["points"]
    assert spec is not None and spec.dissipation == tuple(p["dissipation"] for p in points)
    radius = np.array([p["radius_m"] for p in points])
    measured = np.array(spec.dissipation)
    assert np.all(np.diff(measured) > 0)
    r0, width = data["isolated"]["radius"], data["isolated"]["wall_width"]

    def ansatz(r):  # θ = 2 atan[sinh(R/Δ)/sinh(ρ/Δ)]
        s = math.sinh(r / width)

        def theta(rho):
            return 2 * math.atan2(s, math.sinh(rho / width))

        def integrand(rho):
            sh, ch = math.sinh(rho / width), math.cosh(rho / width)
            slope = -2 * s * ch / (width * (sh * sh + s * s))
            return (slope**2 + math.sin(theta(rho)) ** 2 / max(rho, 1e-30) ** 2) * rho

        return math.pi * integrate.quad(integrand, 0, r + 40 * width, points=[r], limit=200)[0]

    expected = np.array([ansatz(r) for r in radius]) / ansatz(r0)
    ratio = measured / measured[radius == r0][0]
    assert radius[0] < 0.75 * r0  # the scan reaches squeezed skyrmions
    assert np.allclose(ratio, expected, rtol=0.08)


def test_the_laws_radii_are_the_squeezed_solves_radii(calibrated):
    """model.toml's pair_radius and wall_radius, at the tables' distances, pass through the
    radii of the squeezed pairs and edge singles (summary.json) within 0.2 % of R₀, and the
    breathing model reads each law at the gap d − 2s_p(R(d) − R₀) (x − s_w(R(x) − R₀))."""
    data = json.loads((calibrated / "summary.json").read_text())
    material = load_material(calibrated / "model.toml")
    spec = material.breathing
    assert spec is not None and spec.pair_radius is not None and spec.wall_radius is not None
    r0 = material.skyrmion_radius
    squeezed = data["breathing"]["shifts_squeezed"]
    laws = material.breathing_laws()
    for name, radii, factor in (
        ("pair", spec.pair_radius, 2 * spec.pair_shift),
        ("wall", spec.wall_radius, spec.wall_shift),
    ):
        table = getattr(material, f"{name}_table")
        rows = squeezed[name]
        at = np.interp(rows["distance_m"], table.distance, radii)
        assert np.allclose(at, rows["radius_m"], rtol=0, atol=2e-3 * r0), name
        gap = np.asarray(table.distance) - factor * (np.asarray(radii) - r0)
        assert np.array_equal(getattr(laws, f"{name}_table").distance, tuple(gap))
        assert getattr(laws, f"{name}_table").force == table.force
    # the report's sentence: the closest pair, its radii and its gap, from model.toml
    _, notes = headline(calibrated / "report.html")
    text = _note(notes, "Particle model:")
    d_sk = 2 * r0
    d0, r = material.pair_table.distance[0], spec.pair_radius[0]
    agrees(_after(text, "the closest pair, "), d0 / d_sk)
    agrees(_after(text, "d_sk apart with radii of "), r, unit="m")
    agrees(_after(text, "nm, acts at "), (d0 - 2 * spec.pair_shift * (r - r0)) / d_sk)


def test_the_laws_move_with_the_radius_as_the_field_shifts_say(calibrated):
    """At a radius ΔR smaller by a field: E_pair(d) = U_pair(d − 2 s_p ΔR), E_wall(x) =
    U_wall(x − s_w ΔR), with the shifts fitted to them.

    U: ln E of the laws at R₀ (summary.json's energies), interpolated here (PCHIP).
    """
    data, model, *_ = _breathing(calibrated)
    shifts = data["breathing"]["shifts"]
    delta = shifts["radius_change_m"]
    assert -0.2 < shifts["relative_radius_change"] < -0.1  # aimed at −15 %
    for law, key, per_unit in (("pair", "pair", 2 * delta), ("wall", "wall_short_range", delta)):
        ref = data[key]
        d, e = np.array(ref["energy_distance_m"]), np.array(ref["energy_J"])
        positive = e > 0
        u = interpolate.PchipInterpolator(d[positive], np.log(e[positive]))
        x = np.array(shifts[law]["distance_m"])
        measured = np.log(shifts[law]["energy_J"])
        s = shifts[law]["shift"]
        assert len(x) == 3 and 0.5 < s < 3
        assert np.abs(measured - u(x - s * per_unit)).max() < 0.15
        assert np.abs(measured - u(x)).min() > 0.25  # unshifted, the laws miss them


def test_the_model_s_shifts_balance_the_squeezed_radii(calibrated):
    """The model's s_p and s_w, recomputed from the squeezed solves' radii and distances in
    summary.json with model.toml's own tables: the push on the radius −E_self'(R) (the
    E_self(R) table, a cubic spline) against the law's force at the held distance (the force
    table, PCHIP, as the engine reads it), a least-squares slope through the origin."""
    data, model, *_ = _breathing(calibrated)
    squeezed = data["breathing"]["shifts_squeezed"]
    table = model["material"]["breathing"]
    e_self = interpolate.CubicSpline(table["radius"], table["energy"])
    for law, key in (("pair", "pair_table"), ("wall", "wall_table")):
        fit = squeezed[law]
        laws = model["material"][key]
        at = np.clip(fit["distance_m"], laws["distance"][0], laws["distance"][-1])
        force = interpolate.PchipInterpolator(laws["distance"], laws["force"])(at)
        push = -e_self(fit["radius_m"], 1)
        assert len(push) >= 3 and np.all(push > 0)  # squeezed: smaller than R₀
        shift = float(np.sum(push * force) / np.sum(force * force))
        assert table[f"{law}_shift"] == pytest.approx(shift, rel=1e-6), law
        assert data["breathing"]["shift_measure"][law] == "squeezed"


def test_the_model_file_carries_breathing_and_the_choice_is_stated(calibrated):
    data, model, radius, *_ = _breathing(calibrated)
    material = load_material(calibrated / "model.toml")
    b = data["breathing"]
    per_mt = abs(data["checks"]["sensitivity"]["relative_change_per_mT"])
    threshold = b["threshold_per_mT"]
    # the validation ran both models: the one with the smaller error is the model's
    errors = {k: m["rms_error_max_d_sk"] for k, m in data["validation"]["models"].items()}
    chosen = min(errors, key=errors.__getitem__)
    other = "rigid" if chosen == "breathing" else "breathing"
    assert material.particle_model == b["particle_model"] == chosen
    by_sensitivity = b["by_sensitivity"]["particle_model"]
    assert by_sensitivity == ("breathing" if per_mt > threshold else "rigid")
    assert by_sensitivity == "rigid"  # S6: 0.7 % per mT, below 2 % per mT
    spec = material.breathing
    assert spec is not None and spec.radius == tuple(radius)
    assert spec.radius[0] < material.skyrmion_radius < spec.radius[-1]
    assert spec.pair_shift == b["shifts_squeezed"]["pair"]["shift"]
    # the same table makes a valid breathing model
    from skygas.physics.materials import material_from_mapping

    table = {**model["material"], "particle_model": "breathing"}
    assert material_from_mapping(table).is_breathing
    _, notes = headline(calibrated / "report.html")
    text = _note(notes, f"Particle model: {chosen}")
    agrees(_after(text, "RMS centre error is at most "), errors[chosen])
    agrees(_after(text, f"d_sk with {chosen} skyrmions, "), errors[other])
    if chosen != by_sensitivity:
        agrees(_after(text, "changes by "), per_mt)
        agrees(_after(text, "% per mT, at most "), threshold)
    else:
        assert "by the field sensitivity alone" not in text
    # a neighbour's pair force at 1.5 d_sk on the radius (s = 1), as the field it equals
    pair = model["material"]["pair_table"]
    law = interpolate.PchipInterpolator(pair["distance"], pair["force"])
    r0 = material.skyrmion_radius
    m = data["material"]
    neighbour = float(law(3 * r0)) / (
        4 * math.pi * r0 * m["saturation_magnetization"] * m["film_thickness"]
    )
    agrees(_after(text, "presses on the radius like "), neighbour * 1e3, unit="mT")
    agrees(_after(text, "which changes it by "), -per_mt * neighbour * 1e3)
    agrees(_after(text, "𝒟_RR = "), spec.radius_dissipation)
    # the centre's 𝒟 at the table's ends over its value at R₀, and the thin wall's
    assert spec.dissipation is not None
    at_r0 = spec.dissipation[spec.radius.index(r0)]
    width = data["isolated"]["wall_width"]
    stated = _numbers(_after(text, "The centre's 𝒟 is "))
    for k, end in enumerate((0, -1)):
        r = spec.radius[end]
        agrees(stated[2 * k].text, spec.dissipation[end] / at_r0)
        agrees(stated[2 * k + 1].text, r, unit="m")
        thin = (r / width + width / r) / (r0 / width + width / r0)
        agrees(_numbers(_after(text, "isolated Δ: "))[k].text, thin)
    agrees(_after(text, "s_p = "), spec.pair_shift)
    agrees(_after(text, "s_w = "), spec.wall_shift)


def test_both_particle_models_are_validated_against_the_same_run(calibrated):
    """The rigid and the breathing model each against the micromagnetic run, recomputed here.

    Each model's displacements (length ratio, angle) are recomputed from the trajectories the
    summary holds for the chosen model, and the chosen model's entry is the validation's own.
    """
    data = json.loads((calibrated / "summary.json").read_text())
    v = data["validation"]
    models = v["models"]
    assert set(models) == {"rigid", "breathing"}  # the calibration measured the table
    chosen = models[data["breathing"]["particle_model"]]
    assert chosen["rms_error_max_d_sk"] == v["rms_error_max_d_sk"]
    mm = np.asarray(v["micromagnetic_m"])
    pm = np.asarray(v["particle_m"])
    a, b = mm[-1] - mm[0], pm[-1] - pm[0]
    ratio = np.hypot(*b.T) / np.hypot(*a.T)
    angle = np.degrees(np.arctan2(b[:, 1], b[:, 0]) - np.arctan2(a[:, 1], a[:, 0]))
    angle = (angle + 180.0) % 360.0 - 180.0
    np.testing.assert_allclose(chosen["displacement_length_ratio"], ratio, rtol=1e-9)
    np.testing.assert_allclose(chosen["displacement_angle_deg"], angle, atol=1e-7)
    # the breathing model's radii stay inside its table, and are compared with the run's
    lo, hi = models["breathing"]["particle_radius_range_m"]
    radius = data["breathing"]["spec"]["radius"]
    assert radius[0] <= lo <= hi <= radius[-1]
    assert models["breathing"]["radius_rms_error_m"] > 0
    assert "rigid:" in (calibrated / "report.html").read_text()


def test_the_breathing_radius_at_a_real_edge_is_the_micromagnetic_one(calibrated):
    """By a real film's straight edge the stray field squeezes the skyrmion; the breathing
    model's radius, free in E_self(R) + a(R) U_s(x) + U_wall(x − s_w(R − R₀)), is the
    micromagnetic skyrmion's within 2 % at every single of the check and at its film's centre,
    where the isolated radius R₀ (the rigid model's) is 3-14 % off. Its edge energy is within
    the check's ±25 %. And a(R) in model.toml is the scan's measured A_m(R)/A_m(R₀).
    """
    data = json.loads((calibrated / "summary.json").read_text())
    check = data["checks"]["stray_field"]
    r0 = data["isolated"]["radius"]
    pairs = [(p["breathing_radius_m"], p["radius_m"]) for p in check["points"]]
    pairs.append((check["breathing_centre_radius_m"], check["centre_radius_m"]))
    for model, micromagnetic in pairs:
        assert model == pytest.approx(micromagnetic, rel=0.02)
        assert abs(r0 / micromagnetic - 1) > 0.02  # the stray field's squeeze is real
    for p in check["points"]:
        assert p["breathing_model_J"] == pytest.approx(p["micromagnetic_J"], rel=0.25)
    spec = load_material(calibrated / "model.toml").breathing
    points = data["breathing"]["points"]
    assert spec is not None and spec.moment_deficit == tuple(p["moment_deficit_m2"] for p in points)
    # the report's sentence: the written model's edge energies, and the radii at its worst
    if data["breathing"]["particle_model"] == "breathing":
        _, notes = headline(calibrated / "report.html")
        text = _note(notes, "In a real film (no compensation) the breathing model's")
        ratios = [p["breathing_model_J"] / p["micromagnetic_J"] for p in check["points"]]
        stated = _numbers(_after(text, "energy, is "))
        for k, (r, p) in enumerate(zip(ratios, check["points"], strict=True)):
            agrees(stated[2 * k].text, r)
            agrees(stated[2 * k + 1].text, p["x_d_sk"])
        worst = check["points"][int(np.argmax([abs(r - 1) for r in ratios]))]
        agrees(_after(text, "the skyrmion's radius is "), worst["radius_m"], unit="m")
        agrees(_after(text, "nm, the breathing model's "), worst["breathing_radius_m"], unit="m")
        agrees(_after(text, "(the isolated one "), r0, unit="m")


def test_the_terminal_states_where_the_wall_table_goes_on_along_its_tangent(calibrated):
    """The summary line of the edge law: the measured range and, below it, the tangent's end
    (half the first measured distance), recomputed from summary.json's table."""
    from skygas.commands.calibrate import lines

    data = json.loads((calibrated / "summary.json").read_text())
    wall = data["wall_short_range"]
    lo, hi = wall["measured_range_d_sk"]
    first = wall["table_distance_m"][0] / data["isolated"]["diameter"]
    assert first == pytest.approx(0.5 * lo)
    assert f"edge law (short range): measured from {lo:.2f} to {hi:.2f} d_sk (tabulated from " + (
        f"{first:.2f}, along its tangent)"
    ) in lines(data)
