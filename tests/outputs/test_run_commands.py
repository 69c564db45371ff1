"""Run commands write report.html by default and movie.mp4 with --animate; `skygas analyze`."""

from __future__ import annotations

import json

import pytest

from skygas.cli import main

CONFIG = """
seed = 2
temperature = 300.0
duration = 12e-9
record_interval = 1e-9
material = "S2"
[geometry]
kind = "chamber"
chamber_diameter = 1024e-9
conduit_width = 100e-9
conduit_length = 50e-9
closed = true
[skyrmions]
random_count = 10
min_separation = 1.5
"""


def test_simulate_writes_report_and_movie_when_asked(tmp_path, capsys):
    config = tmp_path / "run.toml"
    config.write_text(CONFIG)
    assert (
        main(["simulate", str(config), "--out", str(tmp_path / "a"), "--quiet", "--animate"]) == 0
    )
    assert (tmp_path / "a" / "report.html").stat().st_size > 10_000
    assert (tmp_path / "a" / "movie.mp4").stat().st_size > 1_000
    outputs = json.loads((tmp_path / "a" / "outputs.json").read_text())
    assert outputs["movie"]["frames"] == 13 and outputs["movie"]["stride"] == 1
    assert (
        main(["simulate", str(config), "--out", str(tmp_path / "b"), "--quiet", "--no-report"]) == 0
    )
    assert not (tmp_path / "b" / "report.html").exists()
    assert not (tmp_path / "b" / "movie.mp4").exists()
    capsys.readouterr()
    assert main(["analyze", str(tmp_path / "a"), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["kind"] == "simulate" and result["frames"] == 13
    assert len(result["msd"]["msd_m2"]) == len(result["diffusion"]["msd_over_4tau_m2_s"])
    assert result["occupancy"]["max_total"] == 10  # a closed chamber keeps all ten
    assert main(["analyze", str(tmp_path / "a")]) == 0
    assert "short-time D₀" in capsys.readouterr().out


@pytest.mark.slow
def test_neuron_records_frames_for_its_movie(tmp_path):
    out = tmp_path / "n"
    assert (
        main(
            [
                "neuron",
                "--duration",
                "1e-7",
                "--no-transfer",
                "--json",
                "--animate",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    from skygas.outputs.records import load_run

    record = load_run(out)
    assert record.kind == "neuron" and record.path.name == "frames.nc"
    assert record.frames.n_frames == 26  # t = 0 and every 4 ns to 100 ns
    assert (out / "movie.mp4").exists() and (out / "report.html").exists()
