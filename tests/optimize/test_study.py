"""Studies on the analytic device: the optimum is found, proposals repeat, a killed study resumes.

The analytic device's optimum is known exactly (:mod:`skygas.optimize.analytic`): f = |r − a|²
with a = (0.3, −0.2, 0), smallest (0) at a.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from skygas.core.errors import InputError
from skygas.optimize.execute import open_optuna, run_study
from skygas.optimize.results import write_results
from skygas.optimize.spec import load_study

CENTER = np.array([0.3, -0.2])


def _params(out: Path, study) -> list[tuple]:
    trials = open_optuna(out, study, sampler=False).get_trials(deepcopy=False)
    return [(t.number, t.state.name, tuple(sorted(t.params.items())), t.values) for t in trials]


def test_tpe_finds_the_known_optimum_within_a_fixed_number_of_trials(write_study, tmp_path):
    study = load_study(write_study())
    run_study(study, tmp_path / "out", 40, serial=True, progress=False)
    best = write_results(tmp_path / "out")["best"]["best"]
    found = np.array([best["params"]["x"], best["params"]["y"]])
    # 40 trials of TPE over the 2 x 2 square, seed 4: within 0.1 of the optimum (f < 0.01)
    assert np.linalg.norm(found - CENTER) < 0.1, found
    assert best["objectives"]["f"]["mean"] < 0.01
    for name in ("trials.csv", "best.json", "report.html", "history.png", "slice.png"):
        assert (tmp_path / "out" / name).exists(), name


def test_the_same_seed_gives_the_same_proposals_on_the_serial_path(write_study, tmp_path):
    path = write_study()
    runs = []
    for name, seed in (("a", None), ("b", None), ("c", 5)):
        study = load_study(path, seed=seed)
        run_study(study, tmp_path / name, 15, serial=True, progress=False)
        runs.append(_params(tmp_path / name, study))
    assert runs[0] == runs[1]
    assert len(runs[0]) == 15
    assert [r[2] for r in runs[0]] != [r[2] for r in runs[2]]  # another seed: other proposals


def test_constraints_move_the_optimum_to_the_boundary(write_study, tmp_path):
    # the unconstrained optimum has x = 0.3; with x > 0.6 the best is on x = 0.6, y = -0.2
    study = load_study(write_study(study='constraints = ["x > 0.6"]'))
    run_study(study, tmp_path / "out", 40, serial=True, progress=False)
    result = write_results(tmp_path / "out")["best"]
    best = result["best"]
    assert best["constraints"]["x > 0.6"]["met"]
    assert 0.6 < best["params"]["x"] < 0.75
    assert abs(best["params"]["y"] + 0.2) < 0.15
    assert result["trials_feasible"] < result["trials_complete"]  # some proposals broke it


def test_replicas_give_the_mean_and_its_standard_error_and_the_best_is_reevaluated(
    write_study, tmp_path
):
    study = load_study(
        write_study(study="replicas = 3\nreevaluate = 2\nreevaluate_replicas = 5", noise=0.1)
    )
    report = run_study(study, tmp_path / "out", 12, serial=True, progress=False)
    assert report.reevaluated == 10
    out = tmp_path / "out"
    summary = json.loads((out / "trials" / "0" / "summary.json").read_text())
    f = np.array([r["f"] for r in summary["runs"]])
    assert len(f) == 3
    assert summary["objectives"]["f"]["mean"] == pytest.approx(f.mean())
    assert summary["objectives"]["f"]["error"] == pytest.approx(f.std(ddof=1) / np.sqrt(3))
    # the noise-free part of f is known: the runs scatter around it with σ = 0.1
    x, y = summary["params"]["x"], summary["params"]["y"]
    exact = (x - 0.3) ** 2 + (y + 0.2) ** 2
    assert abs(f.mean() - exact) < 5 * 0.1 / np.sqrt(3)
    best = write_results(out)["best"]
    assert len(best["candidates"]) == 2
    again = best["candidates"][0]["reevaluated"]["f"]
    # the re-evaluation's own runs only: the trial's 3 got it picked, and are left out
    assert again["runs"] == 5
    # resuming with nothing to do reruns nothing
    assert run_study(study, out, 12, serial=True, progress=False).finished_now == 0


def test_several_objectives_give_a_pareto_set_and_front(write_study, tmp_path):
    study = load_study(
        write_study(objectives='[[objectives]]\nexpression = "h"\ndirection = "minimize"')
    )
    assert study.sampler == "nsga2"
    run_study(study, tmp_path / "out", 30, serial=True, progress=False)
    result = write_results(tmp_path / "out")
    pareto = result["best"]["pareto_set"]
    assert pareto
    points = [(e["objectives"]["f"]["mean"], e["objectives"]["h"]["mean"]) for e in pareto]
    for p in points:  # no member dominates another
        assert not any(q[0] <= p[0] and q[1] <= p[1] and q != p for q in points)
    assert (tmp_path / "out" / "pareto.csv").exists()
    assert result["figures"]["pareto.png"] == "written"


def test_a_folder_of_another_study_is_refused(write_study, tmp_path):
    run_study(load_study(write_study()), tmp_path / "out", 3, serial=True, progress=False)
    other = load_study(write_study("other.toml", study="replicas = 2"))
    with pytest.raises(InputError, match="a study folder made from this study file"):
        run_study(other, tmp_path / "out", 3, serial=True, progress=False)
    with pytest.raises(InputError, match="--out"):  # a seed of its own is another study too
        run_study(load_study(write_study(), seed=9), tmp_path / "out", 3, serial=True)


def test_a_killed_study_resumes_with_the_same_finished_trials(write_study, tmp_path):
    path = write_study(delay=0.15)
    out = tmp_path / "out"
    env = {**os.environ, "PYTHONWARNINGS": "ignore"}
    command = [sys.executable, "-m", "skygas.cli", "optimize", str(path), "--out", str(out)]
    proc = subprocess.Popen(
        [*command, "--trials", "12", "--serial", "--quiet"],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        deadline = time.time() + 120
        while time.time() < deadline:
            if (out / "trials").is_dir() and len(list((out / "trials").iterdir())) >= 4:
                break
            time.sleep(0.05)
        proc.send_signal(signal.SIGKILL)
    finally:
        proc.wait(timeout=60)
    study = load_study(path)
    before = [t for t in _params(out, study) if t[1] == "COMPLETE"]
    assert 4 <= len(before) < 12
    done = subprocess.run(
        [*command, "--trials", "12", "--serial", "--quiet"], env=env, capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    after = _params(out, study)
    complete = [t for t in after if t[1] == "COMPLETE"]
    assert complete[: len(before)] == before  # the finished trials, unchanged
    assert len(complete) == 12  # and the study went on to 12
    # a trial that was running when the client died is failed and asked again, same parameters
    # (unless it died while being asked, before its parameters were all drawn)
    failed = [t for t in after if t[1] == "FAIL" and len(t[2]) == len(study.parameters)]
    reruns = {t[2] for t in complete[len(before) :]}
    assert all(t[2] in reruns for t in failed)
    assert "already done" in done.stdout


def test_trials_run_several_at_once_on_dask(write_study, tmp_path):
    study = load_study(write_study(delay=0.3))
    report = run_study(study, tmp_path / "out", 6, workers=2, progress=False)
    assert report.finished_now == 6
    trials = open_optuna(tmp_path / "out", study, sampler=False).get_trials(deepcopy=False)
    assert [t.state.name for t in trials] == ["COMPLETE"] * 6
    # two trials were asked before either was told: their runs overlapped in time
    spans = [(t.datetime_start, t.datetime_complete) for t in trials]
    assert any(a[0] < b[1] and b[0] < a[1] for i, a in enumerate(spans) for b in spans[i + 1 :])


def test_skygas_report_redraws_a_study_folder(write_study, tmp_path, capsys):
    from skygas import cli

    out = tmp_path / "out"
    run_study(load_study(write_study()), out, 6, serial=True, progress=False)
    assert not (out / "report.html").exists()  # run_study only runs; results are written after
    assert cli.main(["report", str(out)]) == 0
    assert "study's tables and figures" in capsys.readouterr().out
    for name in ("trials.csv", "best.json", "report.html", "history.png"):
        assert (out / name).exists(), name
    rows = [r for r in (out / "trials.csv").read_text().splitlines() if not r.startswith("#")]
    assert len(rows) == 1 + 6
    assert rows[0].startswith("number,state,x,y,f,f_error")
    assert cli.main(["report", str(out), "--out", str(tmp_path / "copy.html")]) == 0
    assert (tmp_path / "copy.html").read_text() == (out / "report.html").read_text()


def test_a_half_written_last_journal_line_is_dropped_and_the_study_goes_on(write_study, tmp_path):
    study = load_study(write_study())
    out = tmp_path / "out"
    run_study(study, out, 5, serial=True, progress=False)
    before = _params(out, study)
    journal = out / "journal.log"
    journal.write_bytes(journal.read_bytes() + b'{"op_code": 5, "worker_id": "x", "tri')
    run_study(study, out, 8, serial=True, progress=False)
    after = _params(out, study)
    assert after[:5] == before
    assert [t[1] for t in after] == ["COMPLETE"] * 8


def test_a_study_longer_than_a_day_is_refused_before_its_folder_is_made(write_study, tmp_path):
    from skygas.core.estimates import run_limits
    from skygas.optimize.execute import check_study

    text = "replicas = 10\nreevaluate = 1000\nreevaluate_replicas = 1000"
    study = load_study(write_study(study=text, delay=60.0))
    with pytest.raises(InputError, match="1000000 re-evaluation runs.*give --force"):
        run_study(study, tmp_path / "out", 1000, serial=True, progress=False)
    assert not (tmp_path / "out").exists()
    with run_limits(force=True):  # forced, the same study is accepted
        estimate = check_study(study, 1000, 4)
    assert estimate.runs == 1000 * 10 + 1000 * 1000
    assert estimate.seconds == pytest.approx(estimate.runs * (60.0 + 0.02) / 4)


def test_the_estimate_of_a_resumed_study_counts_only_the_trials_left(write_study, tmp_path):
    from skygas.optimize.execute import _finished_before

    study = load_study(write_study(study="reevaluate = 2"))
    out = tmp_path / "out"
    assert _finished_before(out, study) == 0
    run_study(study, out, 4, serial=True, progress=False)
    assert _finished_before(out, study) == 4
    other = load_study(write_study("other.toml", study="reevaluate = 2", noise=0.5))
    assert _finished_before(out, other) == 0  # another study's folder: refused later


def test_a_trial_killed_while_being_asked_is_failed_and_not_repeated():
    """A running trial with every parameter is asked again with them; one killed before its
    parameters were all stored is only failed (enqueueing its few would repeat nothing)."""
    import optuna
    from optuna.distributions import FloatDistribution
    from optuna.trial import TrialState

    from skygas.optimize.execute import _recover

    names = {"x": FloatDistribution(0, 1), "y": FloatDistribution(0, 1)}
    ostudy = optuna.create_study()
    whole = ostudy.ask(names)
    ostudy.ask({"x": names["x"]})  # died between its two parameters
    assert _recover(ostudy, names) == 2
    states = [t.state for t in ostudy.get_trials(deepcopy=False)]
    assert states[:2] == [TrialState.FAIL, TrialState.FAIL]
    waiting = ostudy.get_trials(deepcopy=False, states=(TrialState.WAITING,))
    assert [t.system_attrs["fixed_params"] for t in waiting] == [whole.params]
    assert waiting[0].user_attrs["rerun_of"] == whole.number
