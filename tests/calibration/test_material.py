"""The micromagnetic input of `skygas calibrate`: presets, TOML files, and one line for every
bad value, before any solver starts."""

from __future__ import annotations

import math

import pytest

from skygas import cli
from skygas.calibration.material import load_micromagnetic_material
from skygas.core.errors import InputError
from skygas.core.units import MU_0


@pytest.mark.parametrize("name", ["S1", "S2", "S3", "S4", "S5", "S6", "S7"])
def test_every_preset_is_a_valid_film(name):
    m = load_micromagnetic_material(name)
    assert m.film_thickness == 2e-9 and m.cell_size == 2e-9 and m.damping == 0.1
    # S7 is in-plane without field (K_u < μ₀M_s²/2) and held out of plane by its 150 mT
    assert m.perpendicular_stiffness > 0


def test_derived_lengths_are_the_thin_film_formulas():
    m = load_micromagnetic_material("S2")
    k_eff = 1.45e6 - 0.5 * MU_0 * 1.45e6**2
    assert m.effective_anisotropy == pytest.approx(k_eff, rel=1e-12)
    assert m.exchange_length == pytest.approx(math.sqrt(2 * 27.5e-12 / (MU_0 * 1.45e6**2)))
    assert m.wall_width == pytest.approx(math.sqrt(27.5e-12 / (k_eff + 0.5 * 1.45e6 * 0.02)))
    assert m.critical_dmi == pytest.approx(4 * math.sqrt(27.5e-12 * k_eff) / math.pi)


def test_a_toml_file_may_start_from_a_preset(tmp_path):
    path = tmp_path / "film.toml"
    path.write_text('[micromagnetics]\nbase = "S2"\napplied_field = 0.03\ncell_size = 1e-9\n')
    m = load_micromagnetic_material(path)
    assert m.applied_field == 0.03 and m.cell_size == 1e-9
    assert m.exchange_stiffness == 27.5e-12 and m.name == "S2-custom"


BAD = [
    ("saturation_magnetization = -1.4e6", "saturation_magnetization"),
    ("saturation_magnetization = 'a lot'", "saturation_magnetization"),
    ("cell_size = 5e-9", "cell_size"),
    ("cell_size = 2", "cell_size"),
    ("bulk_dmi = 1e-3", "dmi"),
    ("dmi = 0", "dmi"),
    ("anisotropy = 0.5e6", "anisotropy"),
    ("film_thickness = 20e-9", "film_thickness"),
    ("damping = 0", "damping"),
    ("exchange_stifness = 1e-11", "exchange_stifness"),
]


@pytest.mark.parametrize("line, field", BAD)
def test_a_bad_value_is_one_line_naming_the_field_and_nothing_is_written(
    tmp_path, capsys, line, field
):
    path = tmp_path / "film.toml"
    path.write_text(f'base = "S2"\n{line}\n')
    out = tmp_path / "cal"
    assert cli.main(["calibrate", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("skygas: error: ") and field in err[0]
    assert not out.exists()


def test_unknown_presets_missing_fields_and_broken_files_are_refused(tmp_path, capsys):
    missing = tmp_path / "missing.toml"
    missing.write_text("saturation_magnetization = 1e6\n")
    binary = tmp_path / "binary.toml"
    binary.write_bytes(b"\xff\xfe\x00junk")
    for source, field in (
        ("S9", "MATERIAL"),
        (str(missing), "exchange_stiffness"),
        (str(binary), "MATERIAL"),
        (str(tmp_path / "none.toml"), "MATERIAL"),
    ):
        assert cli.main(["calibrate", source, "--out", str(tmp_path / "cal")]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and field in err[0], err


def test_options_are_named_in_their_error(tmp_path, capsys):
    for argv, flag in (
        (["--cell-size", "9e-9"], "--cell-size"),
        (["--skyrmions", "0"], "--skyrmions"),
        (["--reference-diameter", "-1"], "--reference-diameter"),
        (["--workers", "-2"], "--workers"),
    ):
        assert cli.main(["calibrate", "S2", "--out", str(tmp_path / "cal"), *argv]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and flag in err[0], err


def test_a_material_outside_the_model_is_refused_before_any_solve():
    with pytest.raises(InputError, match="out of plane"):
        load_micromagnetic_material("S2", anisotropy=1e5)
