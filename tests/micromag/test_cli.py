"""`skygas micromag inspect` and `skygas micromag fit` on synthetic OVF files."""

import json

import numpy as np
import pytest

from skygas.cli import main
from skygas.materials import load_material, preset
from skygas.micromag import pair_law_magnitude, synthetic, write_ovf
from skygas.micromag.forces import disk_from_mask
from skygas.micromag.workflow import thiele_coefficients


def test_inspect_json(tmp_path, two_skyrmions, profile, capsys):
    path = write_ovf(tmp_path / "m000000.ovf", two_skyrmions, fmt="bin8")
    assert main(["micromag", "inspect", str(path), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["total_charge"] == pytest.approx(-2.0, abs=1e-3)
    found = sorted(report["skyrmions"], key=lambda s: s["x_m"])
    for sk, (x, y) in zip(found, sorted(profile.centres)):
        assert set(sk) >= {"charge", "x_m", "y_m", "radius_m", "dissipation"}
        assert sk["charge"] == pytest.approx(-1.0, abs=1e-3)
        assert abs(sk["x_m"] - x) < 0.05 * profile.cell and abs(sk["y_m"] - y) < 0.05 * profile.cell
        assert sk["radius_m"] == pytest.approx(profile.radius, rel=0.01)
    assert main(["micromag", "inspect", str(path)]) == 0
    assert "Q = -1.0000" in capsys.readouterr().out


def test_inspect_bad_file_is_a_clear_error(tmp_path, capsys):
    path = tmp_path / "bad.ovf"
    path.write_text("# not an OVF file\n")
    assert main(["micromag", "inspect", str(path)]) == 2
    assert "bad.ovf:header" in capsys.readouterr().err


def test_fit_from_ovf_snapshots(tmp_path, capsys):
    """Snapshots drawn from a known pair-law trajectory are fitted back by the CLI."""
    material, film, cell, wall_width = preset("S2"), 2e-9, 2e-9, 3e-9
    radius = material.skyrmion_radius
    dis = synthetic.ansatz_dissipation(radius, wall_width)  # what the detector will measure
    coeffs = thiele_coefficients(-1.0, dis, material, film)
    system = synthetic.ThieleSystem(coeffs["gyrocoupling"], coeffs["friction"],
                                    material.exchange_stiffness * film / (2 * radius), 2 * radius)
    box = 256e-9
    times = np.linspace(0.0, 40e-9, 121)
    start = [(box / 2 - 0.6 * 2 * radius, box / 2), (box / 2 + 0.6 * 2 * radius, box / 2)]
    positions = synthetic.integrate_thiele(system, start, times,
                                           synthetic.pair_forces(system, material.pair_law))
    snaps = tmp_path / "snaps"
    snaps.mkdir()
    for i, (t, p) in enumerate(zip(times, positions)):
        field = synthetic.skyrmion_field((128, 128), cell, p, radius, wall_width, time=t)
        write_ovf(snaps / f"m{i:06d}.ovf", field, fmt="bin4")
    out = tmp_path / "fit"
    assert main(["micromag", "fit", str(snaps), "--out", str(out)]) == 0
    assert "pair law" in capsys.readouterr().out
    fitted = load_material(out / "material.toml")
    # The first frames (d ≈ 1.2 d_sk, walls 8 nm apart) bias the drawn centres by ~0.15 cell and
    # a₁, a₀ are strongly correlated, so the check is on the force the fitted law gives, over
    # the sampled range (and the coefficients only loosely).
    d = np.linspace(1.3, 2.9, 40)
    np.testing.assert_allclose(pair_law_magnitude(d, fitted.pair_law),
                               pair_law_magnitude(d, material.pair_law), rtol=0.02)
    np.testing.assert_allclose(fitted.pair_law, material.pair_law, rtol=0.1)
    assert fitted.skyrmion_radius == pytest.approx(radius, rel=0.01)
    record = json.loads((out / "fit.json").read_text())
    assert record["thiele"]["measured_charge"] == pytest.approx(-1.0, abs=1e-3)
    assert record["skygas_version"]
    assert (out / "fit.png").exists() and (out / "forces.csv").exists()


def test_fit_needs_times(tmp_path, capsys):
    field = synthetic.skyrmion_field((40, 40), 1e-9, [(20e-9, 20e-9)], 8e-9, 2e-9)
    for i in range(3):
        write_ovf(tmp_path / f"m{i:06d}.ovf", field, fmt="text")
    assert main(["micromag", "fit", str(tmp_path), "--out", str(tmp_path / "o")]) == 2
    assert "interval" in capsys.readouterr().err


def test_disk_from_mask():
    x = (np.arange(200) + 0.5) * 1e-9
    yy, xx = np.meshgrid(x, x, indexing="ij")
    mask = np.hypot(xx - 101e-9, yy - 99e-9) < 90e-9
    disk = disk_from_mask(mask, x, x)
    # equal-area radius and centroid of a rasterised disk: within a small fraction of a cell
    assert disk.radius == pytest.approx(90e-9, abs=0.05e-9)
    assert disk.centre == pytest.approx((101e-9, 99e-9), abs=0.05e-9)
