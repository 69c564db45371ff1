"""The calibration's report: every headline number recomputed from the files beside it.

The calibration is the suite's (the session fixture ``calibrated`` of
tests/calibration/conftest.py, S6 on 2 nm cells). The headline block of report.html (its
quality-check rows and the summary's sentences) is read and each number is recomputed here, with
code of its own, from what the calibration wrote: model.toml's tables and Thiele numbers, the
material and the raw energies, radii and trajectories of summary.json; and each verdict from the
tolerance the report states. A stated number agrees when it lies within half a unit of its last
printed digit of the recomputed one.
"""

from __future__ import annotations

import json
import math
import re
import tomllib

import numpy as np
import pytest
from scipy import interpolate
from tests.outputs.test_headlines_recomputed import _numbers, agrees, captions, headline

pytest.importorskip("magnumnp")

pytestmark = pytest.mark.slow

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
    ratios = [p["model_J"] / p["micromagnetic_J"] for p in points]
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
    agrees(_after(text, "disk of radius "), v["disk_radius_m"], unit="m")
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
    assert len(found) == 4 and not any(".png" in c for c in found)
    profile, pair, wall, validation = found
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
    page = (calibrated / "report.html").read_text()
    assert "<p class=made>Made by <code class=command>skygas calibrate S6" in page
    assert re.search(r"on \d{4}-\d\d-\d\d \d\d:\d\d UTC", page)
