"""The best of a study and what it is worth, on the analytic device whose truth is known.

f = |r − a|² + σξ with a = (0.3, −0.2, 0) (:mod:`skygas.optimize.analytic`): a range of x
around 0.3 narrower than 1e-4 makes f flat (its true values differ by < 1e-8) under a noise σ,
a noise of 1e-4 over the square [−1, 1]² makes every candidate distinguishable, and a range
that stops short of 0.3 puts the optimum outside it.
"""

from __future__ import annotations

import html
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from skygas.optimize.execute import run_study
from skygas.optimize.results import write_results
from skygas.optimize.spec import load_study
from skygas.optimize.verdict import at_bounds, compare, run_statistics, statement

CENTER = (0.3, -0.2, 0.0)


def _exact_f(params: dict) -> float:
    """The noise-free f of the analytic device at ``params`` (shape "a", z = 0 by default)."""
    r = [params.get(k, 0.0) for k in ("x", "y", "z")]
    return sum((a - c) ** 2 for a, c in zip(r, CENTER, strict=True))


def _study(tmp_path: Path, text: str, name: str = "study.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def _reevaluation(out: Path, trial: dict) -> np.ndarray:
    """f of each re-evaluation run of a candidate, read from its run files."""
    summary = json.loads((out / "trials" / str(trial["trial"]) / "summary.json").read_text())
    folder = out / "runs" / f"trial-{summary['seed_key']}"
    return np.array(
        [json.loads(p.read_text())["quantities"]["f"] for p in folder.glob("reeval-*.json")]
    )


def _welch_agrees(out: Path, result: dict) -> None:
    """Each verdict is scipy's Welch test at 5 % on the run files (an independent computation)."""
    best = _reevaluation(out, result["best"])
    verdicts = result["noise"]["within_noise"] + result["noise"]["distinguishable"]
    assert len(verdicts) == len(result["candidates"]) - 1
    for candidate in verdicts:
        other = _reevaluation(out, candidate)
        p = stats.ttest_ind(other, best, equal_var=False).pvalue
        assert (p >= 0.05) == (candidate in result["noise"]["within_noise"]), (candidate, p)


# -- the rule, on numbers drawn here -------------------------------------------------------------
@pytest.mark.parametrize(
    ("n_best", "sigma_best", "n_other", "sigma_other"), [(6, 1, 6, 1), (4, 1, 12, 3)]
)
def test_candidates_of_the_same_value_are_told_apart_in_5_percent_of_cases(
    n_best, sigma_best, n_other, sigma_other
):
    rng = np.random.default_rng(11)
    draws = 4000
    apart = sum(
        compare(
            run_statistics(rng.normal(0.0, sigma_best, n_best)),
            run_statistics(rng.normal(0.0, sigma_other, n_other)),
        )["within_noise"]
        is False
        for _ in range(draws)
    )
    # the test's level: 5 %; binomial standard deviation √(0.05·0.95/4000) = 0.0034, 3σ allowed
    assert abs(apart / draws - 0.05) < 3 * math.sqrt(0.05 * 0.95 / draws)


def test_a_difference_of_seven_standard_errors_is_told_apart():
    rng = np.random.default_rng(12)
    # two means of 6 runs of σ = 1: combined standard error √(2/6) = 0.58; a difference of 4 is
    # 6.9 of them, beyond the threshold of 2.2 of them in all but ~1e-4 of cases
    results = [
        compare(run_statistics(rng.normal(0.0, 1.0, 6)), run_statistics(rng.normal(4.0, 1.0, 6)))[
            "within_noise"
        ]
        for _ in range(1000)
    ]
    assert results.count(False) >= 990


def test_without_scatter_or_a_second_run_nothing_is_assumed():
    same = {"mean": 1.0, "error": 0.0, "runs": 3}
    assert compare(same, dict(same))["within_noise"] is True
    assert compare(same, {**same, "mean": 1.0 + 1e-12})["within_noise"] is False
    one_run = run_statistics([2.0])
    assert one_run == {"mean": 2.0, "error": None, "runs": 1}
    assert compare(same, one_run)["within_noise"] is None  # one run: no error, no verdict
    values = [1.0, 2.0, 4.0]
    assert run_statistics(values)["error"] == pytest.approx(np.std(values, ddof=1) / math.sqrt(3))


def test_a_parameter_at_the_end_of_its_range_is_flagged():
    space = [
        {"field": "x", "kind": "float", "low": -1.0, "high": 1.0, "log": False, "step": None},
        {"field": "j", "kind": "float", "low": 1e11, "high": 4e11, "log": True, "step": None},
        {"field": "n", "kind": "int", "low": 0, "high": 10, "log": False, "step": 3},
        {"field": "s", "kind": "categorical", "choices": ["a", "b"]},
    ]
    width_j = math.log10(4.0)

    def flags(**params):
        return {(f["field"], f["bound"]) for f in at_bounds(params, space)}

    # 1 % of the width from an end (0.02 here) is at it; 2 % is not
    assert flags(x=0.985, j=2e11, n=3, s="a") == {("x", "high")}
    assert flags(x=-0.96, j=2e11, n=3, s="b") == set()
    # a log range: 1 % of its width in log10
    assert flags(x=0.0, j=1e11 * 10 ** (0.005 * width_j), n=3) == {("j", "low")}
    assert flags(x=0.0, j=1e11 * 10 ** (0.02 * width_j), n=3) == set()
    # whole numbers in steps of 3 from 0 reach 9, not 10: 9 is the upper end, 6 is not
    assert flags(x=0.0, j=2e11, n=9) == {("n", "high")}
    assert flags(x=0.0, j=2e11, n=0) == {("n", "low")}
    assert flags(x=0.0, j=2e11, n=6) == set()


# -- whole studies --------------------------------------------------------------------------------
FLAT = """
[study]
device = "analytic"
seed = 4
sampler = "random"
reevaluate = 3
reevaluate_replicas = 10
[base]
noise = 1.0
[space]
x = { low = 0.3, high = 0.30005 }
[[objectives]]
expression = "f"
"""


def test_a_flat_noisy_function_has_every_candidate_within_noise_and_an_honest_best(tmp_path):
    out = tmp_path / "out"
    run_study(load_study(_study(tmp_path, FLAT)), out, 20, serial=True, progress=False)
    result = write_results(out)["best"]
    assert result["chosen_on"] == "re-evaluation"
    # the true f is 0.04 at every x searched (within 3e-9): no candidate is better than another.
    # Each comparison is a false alarm with probability 5 % (the test's level): none here.
    assert len(result["noise"]["within_noise"]) == 2
    assert result["noise"]["distinguishable"] == []
    _welch_agrees(out, result)
    # the search's best is the lowest of 20 single runs of σ = 1: below 0.04 − 0.5 unless all 20
    # runs landed above it (probability 0.69²⁰ = 6e-4)
    assert result["search_best"]["objectives"]["f"]["mean"] < 0.04 - 0.5
    # the best's value is the mean of its 10 re-evaluation runs alone: 0.04 within 4 of its
    # standard errors (σ/√10 = 0.32), not the lucky value that got it picked
    again = result["best"]["reevaluated"]["f"]
    assert again["runs"] == 10
    assert again["mean"] == pytest.approx(np.mean(_reevaluation(out, result["best"])))
    assert abs(again["mean"] - 0.04) < 4 * 1.0 / math.sqrt(10)
    assert (
        result["best"]["trial"]
        == min(result["candidates"], key=lambda c: c["reevaluated"]["f"]["mean"])["trial"]
    )
    rows = dict(statement(result))
    assert rows["trials within noise of the best"].startswith("2 of the 2 other re-evaluated")


STEEP = """
[study]
device = "analytic"
seed = 4
reevaluate = 3
reevaluate_replicas = 4
startup_trials = 6
[base]
noise = 1e-4
[space]
x = { low = -1.0, high = 1.0 }
y = { low = -1.0, high = 1.0 }
[[objectives]]
expression = "f"
"""


def test_a_steep_function_under_little_noise_has_a_distinguishable_best(tmp_path):
    out = tmp_path / "out"
    run_study(load_study(_study(tmp_path, STEEP)), out, 12, serial=True, progress=False)
    result = write_results(out)["best"]
    candidates = result["candidates"]
    assert len(candidates) == 3
    exact = {c["trial"]: _exact_f(c["params"]) for c in candidates}
    gaps = sorted(exact.values())
    # the candidates' true values differ by far more than the noise can hide (σ/√4 = 5e-5 each)
    assert np.diff(gaps).min() > 1e-3
    assert result["noise"]["within_noise"] == []
    assert len(result["noise"]["distinguishable"]) == 2
    _welch_agrees(out, result)
    # the best is the candidate of the lowest true f, its value that f within 4 standard errors
    assert result["best"]["trial"] == min(exact, key=exact.get)
    again = result["best"]["reevaluated"]["f"]
    assert abs(again["mean"] - exact[result["best"]["trial"]]) < 4 * 1e-4 / 2
    assert dict(statement(result))["trials within noise of the best"].startswith("0 of the 2")


OUTSIDE = """
[study]
device = "analytic"
seed = 4
sampler = "random"
[base]
noise = 0.01
[space]
x = { low = -2, high = 0 }
y = { low = -1.0, high = 0.0 }
[[objectives]]
name = "g"
expression = "-f"
direction = "maximize"
"""


def test_a_best_on_a_search_bound_is_flagged_and_a_single_value_said_so(tmp_path):
    # −f is largest at x = 0.3, beyond the whole numbers −2 … 0 searched: at x = 0, −f ≥ −0.73;
    # at x = −1 it is at most −1.69, so any trial at x = 0 beats every other
    out = tmp_path / "out"
    run_study(load_study(_study(tmp_path, OUTSIDE)), out, 20, serial=True, progress=False)
    result = write_results(out)["best"]
    best = result["best"]
    assert best["params"]["x"] == 0  # 20 random draws of 3 values miss 0 with probability 3e-4
    flags = {(f["field"], f["bound"]) for f in best["at_bounds"]}
    y = best["params"]["y"]
    expected = {("x", "high")} | ({("y", "high")} if y > -0.01 else set())
    expected |= {("y", "low")} if y < -0.99 else set()
    assert flags == expected
    rows = dict(statement(result))
    assert (
        "x = 0 is at the upper bound of `space.x` (0): widen the range" in rows["at a search bound"]
    )
    # no re-evaluation: the value is the trial's own, and the statement says what that is worth
    assert result["chosen_on"] == "search" and result["noise"] is None
    assert "a single noisy value" in rows["uncertainty of the best"]
    assert "`reevaluate = 3`" in rows["uncertainty of the best"]


class _Headline:
    """The rows of a report's headline block, code shown between backticks as in the terminal."""

    def __init__(self, page: str):
        start = page.index("<section class=headline id=headline>")
        block = page[start : page.index("</section>", start)]
        block = re.sub(r"</?code>", "`", block)
        self.rows = [
            (html.unescape(k), html.unescape(v))
            for k, v in re.findall(r"<tr><th>(.*?)</th><td class=n>(.*?)</td></tr>", block)
        ]


def test_terminal_best_json_and_report_say_the_same(tmp_path, capsys):
    from skygas import cli

    path = _study(tmp_path, FLAT)
    out = tmp_path / "out"
    code = cli.main(["optimize", str(path), "--out", str(out), "--serial", "--trials", "12"])
    assert code == 0
    printed = capsys.readouterr().out.splitlines()[1:]  # after the line of trials run
    result = json.loads((out / "best.json").read_text())
    rows = statement(result)
    assert printed == [f"{label}: {text}" for label, text in rows]
    report = (out / "report.html").read_text()
    assert _Headline(report).rows == rows
    # the numbers themselves: the trial and the re-evaluated value of best.json, once each
    best = result["best"]
    again = best["reevaluated"]["f"]
    line = next(p for p in printed if p.startswith("best trial: "))
    assert line.startswith(f"best trial: {best['trial']} ")
    assert sum(p.startswith("best trial") for p in printed) == 1
    shown = next(v for k, v in rows if k.startswith("f (minimize), re-evaluated"))
    mean, error = (float(t.replace("−", "-")) for t in shown.split(" ± "))
    assert abs(mean - again["mean"]) <= 0.5 * 10 ** math.floor(math.log10(error) - 1)
    assert error == pytest.approx(again["error"], rel=0.1)
    assert "Made by <code class=command>skygas optimize" in report
    # `skygas report` redraws the same statement from the folder
    assert cli.main(["report", str(out)]) == 0
    assert _Headline((out / "report.html").read_text()).rows == rows
