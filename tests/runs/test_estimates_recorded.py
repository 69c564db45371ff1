"""Each command's estimate against the wall time its run took, as recorded by
``benchmarks/estimates.py --nominal --record``: within 2× for the shipped examples and every
material preset of the reshuffler.

Not a timed test: the run times are the recorded ones, and the estimate is recomputed now by the
current code with the recorded machine's speed (its 45-skyrmion gas's step, measured in the
same session as the runs). What can fail is the model of the cost: a device whose steps,
population or operations it misjudges (the neuron's estimate once left out its transfer curve
and its operations' turns: 2000× too short; the reshuffler's priced the demonstration 9× too
long).
"""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import pytest

from skygas import cli
from skygas.core.estimates import EstimateOnly, estimate_only

RECORD = Path(__file__).resolve().parents[2] / "benchmarks" / "estimates-recorded.json"
CASES = json.loads(RECORD.read_text())["cases"] if RECORD.exists() else []


def _estimate(args: list[str], out: Path):
    with estimate_only(), contextlib.redirect_stderr(io.StringIO()):
        try:
            cli.main([*args, "--out", str(out), "--quiet", "--overwrite", "--force"])
        except EstimateOnly as stop:
            return stop.estimate
    raise AssertionError(f"{args}: no estimate was checked")


def test_the_record_covers_the_examples_and_every_preset():
    names = {case["case"] for case in CASES}
    assert {"simulate closed chamber", "reshuffle default (demo)", "neuron example"} <= names
    assert {f"reshuffle S{k}" for k in range(1, 8)} <= names


@pytest.mark.parametrize("case", [pytest.param(c, id=c["case"]) for c in CASES])
def test_the_estimate_is_within_twice_the_recorded_run(case, tmp_path, monkeypatch):
    record = json.loads(RECORD.read_text())
    monkeypatch.setenv("SKYGAS_STEP_SECONDS", repr(record["step_seconds"]))
    estimate = _estimate(case["args"], tmp_path / "out")
    assert estimate.steps == pytest.approx(case["steps"], rel=1e-6)  # the same run
    ratio = estimate.seconds / case["run_s"]
    assert 0.5 <= ratio <= 2.0, f"estimate {estimate.seconds:.3g} s, run {case['run_s']:.3g} s"
