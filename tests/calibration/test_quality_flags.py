"""``skygas calibrate``'s quality checks: each verdict against its stated tolerance.

No solver runs here: the checks are built from a calibration's numbers, so they are given by
hand (the S6 validation's 0.124 d_sk, a mesh check on an exponential pair energy whose two
meshes held the pair at different distances), and the command's warnings and ``--strict`` are
checked with the calibration itself replaced by those numbers.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from skygas.calibration import analysis, laws, results
from skygas.cli import build_parser, main

DECAY = 8e-9  # m: the pair energy E(d) = E₀ exp(−d/λ) of these tests
E0 = 1e-18  # J


def energy(d: float) -> float:
    return E0 * math.exp(-d / DECAY)


def mesh_job(d_coarse: float, d_fine: float, fine_scale: float = 1.0):
    """The mesh solves of a film whose pair energy is :func:`energy` (times ``fine_scale``
    on the fine mesh), the two meshes holding the pair at ``d_coarse`` and ``d_fine``."""
    results_ = {}
    for label, d, scale in (("coarse", d_coarse, 1.0), ("fine", d_fine, fine_scale)):
        sk = {"x": 0.0, "y": 0.0, "charge": -1.0, "radius": 10e-9}
        results_[f"mesh/{label}/uniform"] = {"energy": 0.0, "skyrmions": []}
        results_[f"mesh/{label}/single"] = {"energy": 0.0, "skyrmions": [sk]}
        results_[f"mesh/{label}/pair"] = {
            "energy": scale * energy(d),
            "skyrmions": [sk, {**sk, "x": d}],
        }
    material = SimpleNamespace(cell_size=2e-9)
    return SimpleNamespace(results=results_, config=SimpleNamespace(material=material))


def curve() -> laws.EnergyCurve:
    d = np.linspace(20e-9, 120e-9, 11)
    return laws.EnergyCurve(d, np.array([energy(x) for x in d]))


def test_the_mesh_check_compares_both_meshes_at_the_same_distance():
    """Held 2 nm apart on a law that falls by e over 8 nm: 28 % apart as held, 0 % at one d."""
    mesh = analysis._check_mesh(mesh_job(36e-9, 34e-9), None, curve(), 23e-9)
    assert mesh["energy_change_as_held"] == pytest.approx(math.exp(2 / 8) - 1)
    assert mesh["energy_change"] == pytest.approx(0.0, abs=1e-9)
    # a fine mesh that reads the energy 3 % higher at every distance: +3 %, wherever it held
    mesh = analysis._check_mesh(mesh_job(36e-9, 34e-9, 1.03), None, curve(), 23e-9)
    assert mesh["energy_change"] == pytest.approx(0.03, rel=1e-6)
    assert mesh["energy_at_same_distance"]


def calibration(validation_error=0.124, ratios=(1.69, 1.40), mesh=0.029, radius=0.003):
    """A calibration's numbers as :func:`~skygas.calibration.results.quality_checks` reads them."""
    d = 23e-9
    v = SimpleNamespace(
        error=np.array([0.0, 0.05, validation_error, 0.1]),
        times=np.array([0.0, 0.4e-9, 0.8e-9, 1.25e-9]),
        path_length=np.array([1.1, 1.07, 1.08]),
    )
    return SimpleNamespace(
        diameter=d,
        config=SimpleNamespace(
            material=SimpleNamespace(cell_size=2e-9),
            validate_dynamics=True,
            validation=SimpleNamespace(min_travel=0.5),
        ),
        checks={
            "mesh": {
                "coarse": {"distance_m": 1.5 * d},
                "fine": {"distance_m": 1.5 * d},
                "energy_change": mesh,
                "energy_change_as_held": mesh,
                "energy_at_same_distance": True,
                "radius_change": -0.007,
            },
            "enlarged": {
                "film_side_m": 1.0,
                "enlarged_side_m": 1.28,
                "radius_change": radius,
                "energy_change": -0.002,
            },
            "stray_field": {
                "points": [
                    {"x_d_sk": x, "micromagnetic_J": 1e-20, "model_J": r * 1e-20}
                    for x, r in zip((1.2, 2.0), ratios, strict=True)
                ]
            },
        },
        validation=v,
        validation_note="",
    )


def test_the_s6_validation_error_is_flagged():
    checks = {c["name"]: c for c in results.quality_checks(calibration())}
    v = checks["validation"]
    assert not v["passed"] and v["value"] == 0.124 and v["tolerance"] == 0.1
    assert "at most 0.124 d_sk over 1.25 ns (at most 0.1 d_sk)" in v["what"]
    assert checks["mesh: pair energy"]["passed"] and checks["mesh: radius"]["passed"]
    assert checks["film size"]["passed"]
    # the S2 straight edge, 1.69× and 1.40× the micromagnetic energy: far beyond ±25 %
    edge = checks["edge energy at a real edge"]
    assert not edge["passed"] and edge["value"] == pytest.approx(0.69)
    passed = {c["name"]: c for c in results.quality_checks(calibration(0.09, (1.1, 0.9)))}
    assert passed["validation"]["passed"] and passed["edge energy at a real edge"]["passed"]


@pytest.mark.parametrize(("change", "passed"), [(0.049, True), (-0.049, True), (0.051, False)])
def test_the_mesh_tolerance_is_five_percent_either_way(change, passed):
    checks = {c["name"]: c for c in results.quality_checks(calibration(mesh=change))}
    assert checks["mesh: pair energy"]["passed"] is passed


def test_a_lost_skyrmion_fails_the_validation():
    cal = calibration()
    cal.validation, cal.validation_note = None, "a skyrmion was lost"
    checks = {c["name"]: c for c in results.quality_checks(cal)}
    assert not checks["validation"]["passed"] and checks["validation"]["value"] is None
    assert "a skyrmion was lost" in checks["validation"]["what"]


def test_calibrates_strict_says_what_it_does_for_calibrate():
    import argparse

    commands = next(
        a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction)
    ).choices

    def strict_help(command: str) -> str:
        (found,) = [a for a in commands[command]._actions if "--strict" in a.option_strings]
        return str(found.help)

    assert "quality check" in strict_help("calibrate")
    assert "quality check" not in strict_help("simulate")


def summary_data(checks: list[dict]) -> dict:
    """The parts of summary.json that ``skygas calibrate`` prints."""
    return {
        "quality_checks": checks,
        "isolated": {
            "radius": 1.16e-8,
            "wall_width": 3.1e-9,
            "charge": -1.0,
            "gyrocoupling": 1.4e-13,
            "dissipation": 25.9,
            "thin_wall_dissipation": 32.2,
        },
        "pair": {"measured_range_d_sk": [1.0, 6.0]},
        "wall_short_range": {"measured_range_d_sk": [0.9, 3.8]},
        "validation": {"skyrmions": 3, "duration_s": 1.25e-9, "rms_error_max_d_sk": 0.124},
    }


@pytest.mark.parametrize("strict", [False, True])
def test_a_failed_check_is_a_warning_and_under_strict_an_exit_status(
    strict, tmp_path, monkeypatch, capsys
):
    import skygas.calibration as calibration_module

    checks = results.quality_checks(calibration())
    monkeypatch.setattr(calibration_module, "calibrate", lambda *a, **k: summary_data(checks))
    argv = ["calibrate", "S6", "--out", str(tmp_path / "out"), "--quiet"]
    assert main(argv + (["--strict"] if strict else [])) == (1 if strict else 0)
    out, err = capsys.readouterr()
    failed = [c for c in checks if not c["passed"]]
    assert {c["name"] for c in failed} == {"validation", "edge energy at a real edge"}
    for c in failed:
        assert f"skygas: warning: the model fails a quality check ({c['name']}): " in err
    # the terminal's summary leads with the checks, one line each
    lines = out.splitlines()
    for line, c in zip(lines, checks, strict=False):
        assert line.startswith(f"{c['name']}: {'passed' if c['passed'] else 'FAILED'}: ")
    assert any("RMS centre error max 0.124 d_sk (goal 0.1)" in line for line in lines)
