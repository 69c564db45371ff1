"""The reservoir's accuracy sweep resumes from its JSON-lines checkpoint, also after a kill that
cut the last line short: finished points are not run again, the cut one is."""

from __future__ import annotations

import json

from skygas.reservoir import study
from skygas.reservoir.config import reservoir_config


def test_a_sweep_resumes_past_a_line_cut_short(tmp_path, monkeypatch):
    runs = []

    def fake_study(cfg, n_inputs=None, temporal_tasks=True):
        runs.append(cfg.seed)
        return {"xor": {"accuracy": 0.5 + cfg.seed * 1e-6}, "mean_accuracy": 0.75}, None

    monkeypatch.setattr(study, "run_study", fake_study)
    monkeypatch.setattr(study, "ReservoirDevice", lambda cfg: None)  # validation: not the point
    config = reservoir_config(**{"sweep.values": [1e-6, 2e-6], "sweep.replicas": 2})
    checkpoint = tmp_path / "sweep-points.jsonl"

    whole = study.accuracy_sweep(config, checkpoint=tmp_path / "whole.jsonl")
    assert len(runs) == 4

    lines = [x for x in (tmp_path / "whole.jsonl").read_text().splitlines() if x]
    checkpoint.write_text("\n".join(lines[:2]) + "\n" + lines[2][:17])  # killed mid-line
    runs.clear()
    resumed = study.accuracy_sweep(config, checkpoint=checkpoint)
    assert len(runs) == 2  # the cut point and the one never started
    assert resumed == whole
    cut, *rest = checkpoint.read_text().splitlines()[2:]
    assert cut == lines[2][:17]  # left as it was; every point after it on a line of its own
    assert [json.loads(x) for x in rest if x] == [json.loads(x) for x in lines[2:]]
