"""Calibration study files: read and checked before anything runs (calibration.study)."""

from __future__ import annotations

import pytest

from skygas import cli
from skygas.calibration.study import is_study_file, load_study
from skygas.core.errors import InputError

STUDY = """
[study]
material = "S6"
[settings]
cell_size = 2.4e-9
validate_dynamics = false
[grid]
applied_field = [0.0, 0.01]
anisotropy = [FIRST, 8.0e5]
"""


def test_a_grid_makes_one_calibration_per_combination(tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(STUDY.replace("FIRST", "7.5e5"))
    assert is_study_file(path)
    study = load_study(path)
    assert [p.folder for p in study.points] == [f"point-{k}" for k in range(4)]
    assert [(p.material.applied_field, p.material.anisotropy) for p in study.points] == [
        (0.0, 7.5e5),
        (0.0, 8.0e5),
        (0.01, 7.5e5),
        (0.01, 8.0e5),
    ]
    assert all(p.material.cell_size == 2.4e-9 for p in study.points)
    assert study.points[0].settings == {"validate_dynamics": False}


def test_a_film_file_is_not_a_study():
    assert not is_study_file("S6")
    assert not is_study_file("examples/my-film.toml")


def test_a_bad_point_is_one_line_naming_it_before_any_work(tmp_path, capsys):
    path = tmp_path / "study.toml"
    path.write_text(STUDY.replace("FIRST", '"stiff"'))
    with pytest.raises(InputError) as err:
        load_study(path)
    assert "point 0 (applied_field = 0.0, anisotropy = 'stiff'): anisotropy" in str(err.value)
    out = tmp_path / "out"
    assert cli.main(["calibrate", str(path), "--out", str(out)]) == 2
    error = capsys.readouterr().err.strip()
    assert len(error.splitlines()) == 1 and "anisotropy" in error
    assert not (out / "point-0").exists()
