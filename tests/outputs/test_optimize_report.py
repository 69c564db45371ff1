"""A study's figures and report can be read: no layout fault (:func:`.figure_layout.layout_faults`),
axes labelled with the quantities' units, captions that say what is drawn, and a report with no
key names or raw numbers in its text, made by a named command on a date.

The studies run on the analytic device (:mod:`skygas.optimize.analytic`, microseconds a run);
the figures of a reshuffler study are drawn from made-up trials over its real fields and units.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from matplotlib.figure import Figure

from skygas._version import __version__
from skygas.optimize.execute import run_study
from skygas.optimize.figures import axis_scale, history, slices
from skygas.optimize.results import write_results
from skygas.optimize.spec import load_study

from .figure_layout import layout_faults
from .test_report import _check_reads_as_a_summary, _Text

ONE_OBJECTIVE = """
[study]
device = "analytic"
seed = 2
constraints = ["z < 2"]
reevaluate = 2
reevaluate_replicas = 3
[base]
noise = 0.1
[space]
x = { low = 1e11, high = 4e11, log = true }
y = { low = 6e-8, high = 1.6e-7 }
z = { low = -3, high = 3 }
shape = { choices = ["a", "b"] }
[[objectives]]
expression = "f"
"""
TWO_OBJECTIVES = """
[study]
device = "analytic"
seed = 3
[space]
x = { low = -1.0, high = 1.0 }
y = { low = -1.0, high = 1.0 }
[[objectives]]
expression = "f"
[[objectives]]
expression = "h"
"""


@pytest.fixture
def drawn(monkeypatch):
    """Every figure saved while the test runs, by file name: its layout faults and legend."""
    found: dict[str, dict] = {}
    save = Figure.savefig

    def savefig(self, fname, *args, **kwargs):
        # write_figure saves to ".NAME.partial.png" first: the name is NAME.png
        name = Path(str(fname)).name.lstrip(".").replace(".partial", "")
        legend = [t.get_text() for lg in self.legends for t in lg.get_texts()]
        found[name] = {"faults": layout_faults(self), "legend": legend}
        return save(self, fname, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", savefig)
    return found


@pytest.fixture
def one_objective(tmp_path, drawn):
    path = tmp_path / "study.toml"
    path.write_text(ONE_OBJECTIVE)
    out = tmp_path / "out"
    run_study(load_study(path), out, 16, serial=True, progress=False)
    return out, write_results(out)


def test_the_figures_of_a_study_have_no_layout_fault(one_objective, drawn, tmp_path):
    _, result = one_objective
    names = {"history.png", "slice.png", "importances.png"}
    assert {n for n, v in result["figures"].items() if v == "written"} == names
    path = tmp_path / "two.toml"
    path.write_text(TWO_OBJECTIVES)
    run_study(load_study(path), tmp_path / "two", 12, serial=True, progress=False)
    two = write_results(tmp_path / "two")
    names_two = {f"{k}-{o}.png" for k in ("history", "slice", "importances") for o in "fh"}
    assert {n for n, v in two["figures"].items() if v == "written"} == names_two | {"pareto.png"}
    assert set(drawn) == names | names_two | {"pareto.png"}
    assert {n: d["faults"] for n, d in drawn.items() if d["faults"]} == {}


def test_the_history_caption_says_what_the_figure_draws(one_objective, drawn):
    out, result = one_objective
    page = (out / "report.html").read_text()
    caption = re.search(r"<figcaption>(Optimisation history[^<]*)</figcaption>", page).group(1)
    legend = drawn["history.png"]["legend"]
    assert "best so far" in legend and "best so far" in caption
    assert "re-evaluated" in legend and "2 re-evaluated candidates" in caption
    # trials at z = 2 or 3 break the constraint: drawn hollow, and said
    assert "trial breaking a constraint" in legend and "break a constraint" in caption


def test_the_report_reads_as_a_summary_and_says_who_made_it_when(one_objective):
    out, _ = one_objective
    text = (out / "report.html").read_text()
    page = _Text()
    page.feed(text)
    # joined with spaces, as a browser shows table cells apart
    _check_reads_as_a_summary(" ".join(page.text))
    # run from Python: no command line to name, but the version and the date are said
    assert "<p class=made>Made from Python (no command line recorded), with skygas " in text
    assert re.search(
        rf"Report written by skygas {__version__} on \d{{4}}-\d\d-\d\d \d\d:\d\d UTC", text
    )
    labels = re.findall(r"<tr><th>([^<]*)</th><td class=n>", text)
    assert len(labels) == len(set(labels)), labels
    assert not re.search(r"<figcaption>[^<]*\.png", text)


# -- a reshuffler study's fields and units, on made-up trials ------------------------------------
FIELDS = [
    {"field": "current_density", "kind": "float", "low": 1e11, "high": 4e11, "log": True},
    {"field": "device.chamber_diameter", "kind": "float", "low": 5e-7, "high": 1.6e-6},
    {"field": "device.conduit_width", "kind": "float", "low": 6e-8, "high": 1.6e-7, "step": 1e-8},
    {"field": "injection.interval", "kind": "float", "low": 2e-9, "high": 2e-8, "log": True},
    {"field": "signal.kind", "kind": "categorical", "choices": ["telegraph", "bernoulli"]},
]


def _made_up_trials(n: int = 30) -> list[dict]:
    rng = np.random.default_rng(5)
    trials = []
    for k in range(n):
        params = {
            "current_density": float(10 ** rng.uniform(11, np.log10(4e11))),
            "device.chamber_diameter": float(rng.uniform(5e-7, 1.6e-6)),
            "device.conduit_width": float(rng.integers(6, 17) * 1e-8),
            "injection.interval": float(10 ** rng.uniform(np.log10(2e-9), np.log10(2e-8))),
            "signal.kind": str(rng.choice(["telegraph", "bernoulli"])),
        }
        mean = float(rng.uniform(1.5e8, 2.1e8))
        trials.append(
            {
                "number": k,
                "state": "COMPLETE",
                "params": params,
                "objectives": {"throughput": {"mean": mean, "error": 0.02 * mean}},
                "constraints": {"correlation < 0.05": {"met": bool(k % 4)}},
            }
        )
    return trials


def test_axes_carry_the_quantities_labels_and_units_without_overlap():
    assert axis_scale([6e-8, 1.6e-7], "m") == (1e-9, "nm")
    assert axis_scale([1e11, 4e11], "A/m²") == (1e11, "10¹¹ A/m²")
    assert axis_scale([0.02, 0.5], "") == (1.0, "")
    record = {"parameters": FIELDS, "replicas": 2}
    result = {
        "objectives": [{"name": "throughput", "unit": "Hz", "direction": "maximize"}],
        "candidates": [],
    }
    trials = _made_up_trials()
    fig, _ = slices(record, trials, result, 0)
    labels = [ax.get_xlabel() for ax in fig.axes]
    assert labels == [
        "current density (10¹¹ A/m²)",
        "chamber diameter (µm)",
        "conduit width (nm)",
        "injection interval (ns)",
        "signal kind",
    ]
    assert fig.axes[0].get_ylabel() == "throughput (MHz)"
    assert layout_faults(fig) == []
    fig, caption = history(record, trials, result, 0)
    assert fig.axes[0].get_ylabel() == "throughput (MHz)"
    assert "highest mean" in caption  # a maximised objective's best so far
    assert layout_faults(fig) == []
