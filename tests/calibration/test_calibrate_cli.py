"""`skygas calibrate` end to end on a small, cheap film (S6: 23 nm skyrmions on 2 nm cells,
about half a minute on two cores): the model file, the laws' physics, the validation, the
model running in the engine, and resume after an interruption."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

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


def test_validation_compares_a_run_that_moved_a_diameter(calibrated):
    v = json.loads((calibrated / "summary.json").read_text())["validation"]
    assert v["skyrmions"] == 3 and min(v["path_length_d_sk"]) >= 1.0
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


def test_interrupted_and_resumed_gives_the_same_bits(tmp_path):
    # cells of 2.4 nm (the coarsest S6 allows): a quarter faster, and bits are bits
    args = ["S6", "--no-validate", "--no-mesh-check", "--quiet", "--checkpoint-seconds", "0"]
    args += ["--cell-size", "2.4e-9"]
    straight = tmp_path / "straight"
    assert cli.main(["calibrate", *args, "--out", str(straight)]) == 0
    broken = tmp_path / "broken"
    process = subprocess.Popen(
        [sys.executable, "-m", "skygas.cli", "calibrate", *args, "--out", str(broken)],
        stderr=subprocess.PIPE,
        text=True,
    )
    checkpoint = broken / "checkpoint.npz"
    deadline = time.time() + 120
    while time.time() < deadline and process.poll() is None:
        if checkpoint.exists():
            with np.load(checkpoint) as data:
                if len(json.loads(str(data["results"]))) >= 6:
                    break
        time.sleep(0.2)
    process.send_signal(signal.SIGINT)
    assert process.wait(timeout=120) == 130, process.stderr.read()
    assert checkpoint.exists() and not (broken / "model.toml").exists()
    assert cli.main(["calibrate", *args, "--out", str(broken), "--resume"]) == 0
    a = json.loads((straight / "summary.json").read_text())
    b = json.loads((broken / "summary.json").read_text())
    for key in ("pair", "wall_short_range"):
        assert a[key]["energy_J"] == b[key]["energy_J"]
        assert a[key]["table_force_N"] == b[key]["table_force_N"]
    assert a["isolated"] == b["isolated"]
