"""``skygas reservoir``: bad configurations get one clear line before any work; a short run
writes its JSON, figures and report; a finished study's folder is refused in one line unless
``--overwrite`` is given."""

from __future__ import annotations

import json
import time

import pytest

from skygas.cli import main

FAST = """
hold_time = 2e-7
[sensors]
sample_interval = 2e-9
[study]
n_inputs = 24
temporal_inputs = 24
workers = 1
"""


def _run(tmp_path, capsys, text, *extra):
    config = tmp_path / "c.toml"
    config.write_text(text)
    started = time.perf_counter()
    code = main(["reservoir", str(config), "--out", str(tmp_path / "out"), *extra])
    out, err = capsys.readouterr()
    return code, out, err, time.perf_counter() - started


@pytest.mark.parametrize(
    "text, field",
    [
        (
            "[chamber]\ncontacts = [{name = 'A', start = [0.0, 0.0], end = [1e-8, 0.0]},"
            " {name = 'B', start = [-1.5e-7, -8.66e-8], end = [1.5e-7, -8.66e-8]}]",
            "chamber.contacts[0]",
        ),
        ("n_skyrmions = 0", "n_skyrmions"),
        ("hold_time = 1e-12", "hold_time"),
        ("[drive]\ninput_contacts = ['A', 'X']", "drive.input_contacts[1]"),
        ("[chamber]\ncontact_width = 2e-7", "chamber.contact_width"),
        ("[sensors]\nsample_interval = 1e-5", "sensors.sample_interval"),
    ],
)
def test_bad_configurations_get_one_line_before_any_work(tmp_path, capsys, text, field):
    code, out, err, seconds = _run(tmp_path, capsys, text)
    assert code == 2 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"skygas: error: {field} = "), err
    assert not (tmp_path / "out").exists()
    assert seconds < 20


def test_short_run_writes_json_figures_and_report(tmp_path, capsys):
    code, out, err, _ = _run(tmp_path, capsys, FAST, "--json")
    assert code == 0
    summary = json.loads(out)
    for key in (
        "task",
        "accuracy",
        "hold_time_s",
        "temperature_K",
        "n_skyrmions",
        "energy_per_operation_J",
    ):
        assert key in summary
    assert list(summary["accuracy"])[0] == "XOR" and len(summary["accuracy"]) == 16
    assert summary["energy_per_operation_J"] > 0
    assert summary["device"]["seed"] == 0 and summary["device"]["skygas_version"]
    for name in ("summary.json", "occupation.png", "accuracy.png", "report.html"):
        assert (tmp_path / "out" / name).is_file()
    assert not (tmp_path / "out" / "report.md").exists()  # the report is report.html
    # a finished study is never overwritten; resumed, it has nothing to do
    code, out, err, _ = _run(tmp_path, capsys, FAST, "--resume")
    assert code == 0 and "nothing to resume" in err, err
    code, out, err, _ = _run(tmp_path, capsys, FAST)
    assert code == 2 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("skygas: error: --out = "), err
    assert "--overwrite" in lines[0], err
    # the reservoir's own sweep of earlier versions says where it went, in one line
    code, out, err, _ = _run(tmp_path, capsys, FAST, "--sweep", "--overwrite")
    lines = err.strip().splitlines()
    assert code == 2 and out == "" and len(lines) == 1, err
    assert lines[0].startswith("skygas: error: --sweep") and "skygas sweep" in lines[0], err
    # --overwrite runs it again (the same numbers)
    code, out, err, _ = _run(tmp_path, capsys, FAST, "--overwrite", "--json", "--no-report")
    assert code == 0
    again = json.loads(out)
    for key in ("accuracy", "boolean", "temporal", "sensor_means", "steps", "device"):
        assert again[key] == summary[key], key
