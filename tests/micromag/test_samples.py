"""The sample OVF files shipped with the package: present, what their generator makes, and
usable at once by ``skygas micromag inspect`` and ``fit``."""

import json
import math

import numpy as np
import pytest

from skygas.cli import main
from skygas.micromag import pair_law_magnitude, read_ovf, samples
from skygas.physics.materials import load_material, preset


def test_shipped_samples_are_what_the_generator_makes(tmp_path):
    made = samples.write_samples(tmp_path)
    shipped = samples.folder()
    assert len(made) == samples.PAIR_FRAMES + 1
    for path in made:
        twin = shipped / path.relative_to(tmp_path)
        ours, theirs = read_ovf(path), read_ovf(twin)
        # float32 data: equal up to one rounding of the last bit
        np.testing.assert_allclose(theirs.values, ours.values, rtol=0, atol=2.0**-23)
        assert theirs.attrs["time"] == ours.attrs["time"] or math.isnan(ours.attrs["time"])
        assert b"synthetic sample made by skygas.micromag.samples" in twin.read_bytes()[:2000]
    assert sum(p.stat().st_size for p in made) < 300_000  # the package stays small


def test_samples_command_prints_the_folder(capsys):
    assert main(["micromag", "samples"]) == 0
    printed = capsys.readouterr().out
    assert str(samples.folder()) in printed and "skygas micromag fit" in printed


def test_inspect_the_tilted_disk_sample(capsys):
    path = samples.folder() / "disk-tilted-edges.ovf"
    assert main(["micromag", "inspect", str(path), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["edge_band_width_m"] > 0
    found = sorted(report["skyrmions"], key=lambda s: s["x_m"])
    assert len(found) == 2
    for sk, (x, y) in zip(found, samples.DISK_CENTRES, strict=True):
        assert sk["charge"] == pytest.approx(-1.0, abs=2e-3)
        assert math.hypot(sk["x_m"] - x, sk["y_m"] - y) < 0.1e-9


def test_fit_the_pair_sample(tmp_path, capsys):
    """The pair relaxes by S2's law: the fit gives that force back over the covered range."""
    out = tmp_path / "fit"
    assert main(["micromag", "fit", str(samples.folder() / "pair"), "--out", str(out)]) == 0
    assert "pair law (16 samples, d = 1.2" in capsys.readouterr().out
    fitted = load_material(out / "material.toml")
    d = np.linspace(1.25, 2.2, 20)
    np.testing.assert_allclose(
        pair_law_magnitude(d, fitted.pair_law),
        pair_law_magnitude(d, preset("S2").pair_law),
        rtol=0.03,
    )
