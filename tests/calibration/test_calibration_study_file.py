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


def _point(k: int, field: float, radius: float) -> dict:
    return {
        "values": {"applied_field": field},
        "folder": f"point-{k}",
        "computed_now": True,
        "radius_m": radius,
        "wall_width_m": 4.1e-9 + 1e-10 * k,
        "dissipation": 2.5 + 0.25 * k,
        "gyrocoupling_kg_per_s": 2.07e-13,
        "pair_measured_range_d_sk": [1.0, 4.5],
        "wall_measured_range_d_sk": [0.6, 3.0],
        "rms_error_max_d_sk": None if k else 0.0873,
    }


def test_the_study_report_shows_every_point_s_numbers_as_study_json_holds_them(tmp_path):
    """report.html of a study: one row per point whose cells are study.json's numbers (read
    back from the page and compared), a figure for a numeric swept field, and none for
    films named by file."""
    import html
    import re

    from skygas.calibration.study_report import write_study_report

    radii = [11.6e-9, 10.9e-9, 10.31e-9]
    record = {
        "fields": ["applied_field"],
        "points": [
            _point(k, f, r) for k, (f, r) in enumerate(zip([0.0, 0.01, 0.02], radii, strict=True))
        ],
        "study_file": "[study]\nmaterial = 'S6'\n",
        "skygas_version": "test",
    }
    page = write_study_report(record, tmp_path).read_text()
    rows = re.findall(r"<tr>(.*?)</tr>", page)
    header = [html.unescape(h) for h in re.findall(r"<th>(.*?)</th>", rows[0])]
    cells = [[html.unescape(c) for c in re.findall(r"<td class=n>(.*?)</td>", r)] for r in rows[1:]]
    assert header[:3] == ["point", "applied_field", "radius R (nm)"]
    assert [c[0] for c in cells] == ["point-0", "point-1", "point-2"]
    for row, point in zip(cells, record["points"], strict=True):
        values = dict(zip(header, row, strict=True))
        assert float(values["applied_field"]) == point["values"]["applied_field"]
        assert abs(float(values["radius R (nm)"]) - point["radius_m"] * 1e9) <= 0.005
        assert abs(float(values["𝒟"]) - point["dissipation"]) <= 0.0005
        lo, hi = (float(v) for v in values["pair law measured to (d_sk)"].split("–"))
        assert [lo, hi] == point["pair_measured_range_d_sk"]
    rms = [
        dict(zip(header, r, strict=True))["validation: largest RMS centre error (d_sk)"]
        for r in cells
    ]
    assert rms == ["0.087", "–", "–"]  # a point without a validation says so
    assert page.count("<img") == 1 and "against applied_field" in page

    films = {**record, "fields": ["material"]}
    films["points"] = [
        {**p, "values": {"material": name}}
        for p, name in zip(record["points"], ["S6", "a.toml", "b.toml"], strict=True)
    ]
    assert "<img" not in write_study_report(films, tmp_path).read_text()


def test_a_point_folder_of_another_film_is_refused_not_reused(tmp_path):
    """A study folder whose point holds a finished calibration of another film (the study
    file was edited, or --out holds another study) is refused in one line before any solve,
    instead of reporting that calibration as the point's."""
    from skygas.calibration.study import run_study

    path = tmp_path / "study.toml"
    path.write_text(STUDY.replace("FIRST", "7.5e5"))
    study = load_study(path)
    folder = tmp_path / "out" / "point-0"
    folder.mkdir(parents=True)
    (folder / "summary.json").write_text('{"isolated": {}}')
    (folder / "manifest.json").write_text(
        '{"command": "calibrate", "config_hash": "0123456789abcdef", '
        '"finished_at": "2026-01-01T00:00:00Z"}'
    )
    with pytest.raises(InputError) as err:
        run_study(study, tmp_path / "out", progress=False)
    line = str(err.value)
    assert "point-0" in line and "another film" in line and "\n" not in line
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["point-0"]  # nothing written
