"""A study's results, made from its folder: tables, the best trial or the Pareto set, figures.

``skygas optimize`` writes them at its end, ``skygas report DIR`` again:

- ``trials.csv``: one row per finished trial (complete or failed): its number, state,
  parameters, each objective's mean and standard error over the trial's replicas, each
  constraint's mean and whether it was met, the error of a failed trial;
- ``best.json``: one objective: the best complete trial that meets every constraint, its
  parameters and objective (mean ± standard error over its replicas), then the re-evaluated
  candidates with the mean and standard error over all their runs (the trial's and the
  re-evaluation's); several objectives: the Pareto set of such trials, each with its
  re-evaluation where it had one;
- ``pareto.csv`` and ``pareto.png`` (several objectives): the Pareto set's objectives;
- ``history.png`` (``history-NAME.png`` per objective with several), ``importances.png`` and
  ``slice.png``: optuna's own figures (:mod:`optuna.visualization.matplotlib`); importances are
  fANOVA's, seeded with the study's seed.

Every file carries the provenance record (:mod:`skygas.runs.provenance`): the skygas version,
the study's seed and fingerprint, the command line.
"""

from __future__ import annotations

import csv
import io
import math
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from skygas.optimize.execute import (
    iter_trial_summaries,
    read_study_record,
    reevaluation_runs,
)

FIGURES = ("history.png", "importances.png", "slice.png", "pareto.png")


def _finite(value: Any) -> float:
    return math.nan if value is None else float(value)


def _feasible(summary: dict) -> bool:
    return all(c["met"] for c in summary.get("constraints", {}).values())


def _dominates(a: list[float], b: list[float]) -> bool:
    return all(x <= y for x, y in zip(a, b, strict=True)) and any(
        x < y for x, y in zip(a, b, strict=True)
    )


def pareto_set(record: dict, summaries: list[dict]) -> list[dict]:
    """The complete, feasible trials that no other such trial dominates (in trial order)."""
    signs = [1.0 if o["direction"] == "minimize" else -1.0 for o in record["objectives"]]
    good = [s for s in summaries if s["state"] == "COMPLETE" and _feasible(s)]
    points = [
        [
            sg * s["objectives"][o["name"]]["mean"]
            for sg, o in zip(signs, record["objectives"], strict=True)
        ]
        for s in good
    ]
    return [
        s
        for s, p in zip(good, points, strict=True)
        if not any(_dominates(q, p) for q in points if q is not p)
    ]


def _combined(record: dict, summary: dict, out: Path) -> dict | None:
    """A trial's objectives over its runs and its re-evaluation runs together."""
    from skygas.optimize.expressions import parse_expression

    extra = reevaluation_runs(out, summary["seed_key"])
    if not extra:
        return None
    runs = [{k: _finite(v) for k, v in r.items()} for r in summary["runs"]] + extra
    names = list(runs[0])
    combined = {}
    for o in record["objectives"]:
        expression = parse_expression(o["expression"], o["name"], names)
        values = np.array([expression(r) for r in runs])
        n = len(values)
        combined[o["name"]] = {
            "mean": float(values.mean()),
            "error": float(values.std(ddof=1) / math.sqrt(n)) if n > 1 else None,
            "runs": n,
        }
    return combined


def _entry(record: dict, summary: dict, out: Path) -> dict:
    return {
        "trial": summary["number"],
        "params": summary["params"],
        "objectives": summary["objectives"],
        "constraints": summary.get("constraints", {}),
        "replicas": len(summary["runs"]),
        "reevaluated": _combined(record, summary, out),
    }


def best(out: Path, record: dict, summaries: list[dict]) -> dict:
    """What ``best.json`` holds (see the module docstring)."""
    complete = [s for s in summaries if s["state"] == "COMPLETE"]
    feasible = [s for s in complete if _feasible(s)]
    result: dict[str, Any] = {
        "objectives": record["objectives"],
        "constraints": record["constraints"],
        "trials_finished": len(summaries),
        "trials_complete": len(complete),
        "trials_feasible": len(feasible),
    }
    if len(record["objectives"]) > 1:
        result["pareto_set"] = [_entry(record, s, out) for s in pareto_set(record, summaries)]
        return result
    o = record["objectives"][0]
    sign = 1.0 if o["direction"] == "minimize" else -1.0
    ranked = sorted(feasible, key=lambda s: sign * s["objectives"][o["name"]]["mean"])
    result["best"] = _entry(record, ranked[0], out) if ranked else None
    reevaluated = [e for e in (_entry(record, s, out) for s in ranked) if e["reevaluated"]]
    # after re-evaluation, the candidate whose mean over all its runs is best
    result["candidates"] = sorted(
        reevaluated, key=lambda e: sign * e["reevaluated"][o["name"]]["mean"]
    )
    result["best_after_reevaluation"] = result["candidates"][0] if reevaluated else None
    return result


def _provenance(out: Path, record: dict) -> dict[str, str]:
    from skygas.runs.provenance import provenance

    return provenance(
        seed=record["seed"],
        config_hash=record["fingerprint"],
        skygas_version=record["skygas_version"],
        source=str(out),
    )


def trials_table(record: dict, summaries: list[dict]) -> tuple[list[str], list[list[Any]]]:
    """The header and rows of ``trials.csv``."""
    fields = [p["field"] for p in record["parameters"]]
    names = [o["name"] for o in record["objectives"]]
    header = ["number", "state", *fields]
    for n in names:
        header += [n, f"{n}_error"]
    header += [c for c in record["constraints"]] + ["feasible", "replicas", "error"]
    rows = []
    for s in summaries:
        row: list[Any] = [s["number"], s["state"], *(s["params"].get(f) for f in fields)]
        for n in names:
            o = s.get("objectives", {}).get(n, {})
            row += [o.get("mean"), o.get("error")]
        cons = s.get("constraints", {})
        row += [cons.get(c, {}).get("mean") for c in record["constraints"]]
        row += [_feasible(s) if s["state"] == "COMPLETE" else None, len(s["runs"]), s.get("error")]
        rows.append(row)
    return header, rows


def _write_csv(path: Path, header: list[str], rows: list[list[Any]], record: dict) -> None:
    from skygas.runs.provenance import csv_header
    from skygas.runs.run_driver import write_atomic

    buffer = io.StringIO()
    buffer.write(csv_header(record))
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    for row in rows:
        writer.writerow(["" if v is None else v for v in row])
    text = buffer.getvalue()
    write_atomic(path, lambda tmp: tmp.write_text(text))


def _load_optuna(out: Path, record: dict):
    import optuna
    from optuna.storages import JournalStorage
    from optuna.storages.journal import JournalFileBackend

    from skygas.optimize.execute import JOURNAL, STUDY_NAME

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    storage = JournalStorage(JournalFileBackend(str(out / JOURNAL)))
    return optuna.load_study(study_name=STUDY_NAME, storage=storage)


def _figures(out: Path, record: dict, provenance: dict[str, str]) -> dict[str, str]:
    """Draw optuna's figures; returns the names written, and why others were not."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import optuna
    import optuna.visualization.matplotlib as ov
    from optuna.trial import TrialState

    from skygas.optimize.execute import constraint_values
    from skygas.runs.run_driver import write_figure

    study = _load_optuna(out, record)
    complete = study.get_trials(deepcopy=False, states=(TrialState.COMPLETE,))
    objectives = record["objectives"]
    notes: dict[str, str] = {}

    def save(name: str, draw) -> None:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                drawn = draw()
        except (ValueError, RuntimeError, ZeroDivisionError) as err:
            notes[name] = f"not drawn: {err}"
            plt.close("all")
            return
        axes = np.ravel(drawn)
        figure = axes[0].figure
        figure.set_size_inches(max(6.4, 3.6 * len(axes) + 1.0), 4.4)
        write_figure(
            out / name,
            lambda tmp: figure.savefig(tmp, dpi=100, bbox_inches="tight"),
            provenance,
        )
        plt.close(figure)
        notes[name] = "written"

    def target(i: int):
        return lambda t: t.values[i]

    if len(complete) < 2:
        return {f: "not drawn: fewer than 2 complete trials" for f in FIGURES}
    evaluator = optuna.importance.FanovaImportanceEvaluator(seed=int(record["seed"]) % 2**32)
    for i, o in enumerate(objectives):
        suffix = "" if len(objectives) == 1 else f"-{o['name']}"
        save(
            f"history{suffix}.png",
            lambda i=i, o=o: ov.plot_optimization_history(
                study, target=target(i), target_name=o["name"]
            ),
        )
        save(
            f"importances{suffix}.png",
            lambda i=i, o=o: ov.plot_param_importances(
                study, evaluator=evaluator, target=target(i), target_name=o["name"]
            ),
        )
        save(
            f"slice{suffix}.png",
            lambda i=i, o=o: ov.plot_slice(study, target=target(i), target_name=o["name"]),
        )
    if 2 <= len(objectives) <= 3:
        save(
            "pareto.png",
            lambda: ov.plot_pareto_front(
                study,
                target_names=[o["name"] for o in objectives],
                constraints_func=constraint_values if record["constraints"] else None,
            ),
        )
    return notes


def _best_rows(record: dict, entry: dict) -> list[tuple[str, str]]:
    from skygas.outputs.report import format_number

    rows = [("trial", str(entry["trial"]))]
    rows += [(f"parameter {k}", format_number(v)) for k, v in entry["params"].items()]
    for o in record["objectives"]:
        value = entry["objectives"][o["name"]]
        rows.append(
            (
                f"{o['name']} ({o['direction']}; mean of {entry['replicas']} runs ± s.e.)",
                format_number(value["mean"], value["error"]),
            )
        )
        again = (entry.get("reevaluated") or {}).get(o["name"])
        if again:
            rows.append(
                (
                    f"{o['name']} re-evaluated (mean of {again['runs']} runs ± s.e.)",
                    format_number(again["mean"], again["error"]),
                )
            )
    for text, c in entry["constraints"].items():
        rows.append(
            (
                f"constraint {text}",
                f"{format_number(c['mean'], c['error'])} ({'met' if c['met'] else 'not met'})",
            )
        )
    return rows


def _report(out: Path, record: dict, result: dict, table, notes: dict[str, str]) -> str:
    import html

    from skygas._version import __version__
    from skygas.outputs import headlines as H
    from skygas.outputs.report import Page

    page = Page(f"skygas optimize — {record.get('name') or out.name}")
    page.paragraph(f"Report written by skygas {__version__} from the study folder {out}.")
    # the answer first: the best trial (after re-evaluation where there was one), or the front
    headline = H.Results()
    if "pareto_set" in result:
        headline.rows.append(("trials on the Pareto front", str(len(result["pareto_set"]))))
        headline.notes.append("Each trial of the front is listed under “Pareto set” below.")
    elif result["best"] is None:
        headline.rows.append(("best trial", H.none("no complete trial meets the constraints yet")))
    else:
        chosen = result.get("best_after_reevaluation") or result["best"]
        headline.rows += _best_rows(record, chosen)
        if result.get("best_after_reevaluation"):
            headline.notes.append(
                "The best trial after the best candidates were run again (re-evaluation)."
            )
    page.headline(headline)
    page.heading("Study")
    page.table(
        [
            ("device", record["device"]),
            ("sampler", record["sampler"]),
            ("seed", record["seed"]),
            ("replicas per trial", record["replicas"]),
            ("fingerprint", record["fingerprint"]),
            ("skygas version of the study", record["skygas_version"]),
            (
                "trials finished (complete)",
                f"{result['trials_finished']} ({result['trials_complete']})",
            ),
            ("complete trials meeting the constraints", result["trials_feasible"]),
            ("constraints", html.escape("; ".join(record["constraints"]) or "none")),
        ]
    )
    if "pareto_set" in result:
        page.heading(f"Pareto set ({len(result['pareto_set'])} trials)")
        for entry in result["pareto_set"]:
            page.table(_best_rows(record, entry))
    elif result.get("best_after_reevaluation"):  # the headline holds the re-evaluated best
        page.heading("Best trial of the search, before re-evaluation")
        page.table(_best_rows(record, result["best"]))
    page.heading("Figures")
    for name in sorted(notes):
        if notes[name] == "written" and (out / name).exists():
            page.image((out / name).read_bytes(), _caption(name))
        else:
            page.paragraph(f"{_caption(name)}: {notes[name]}")
    header, rows = table
    page.heading(f"Trials ({len(rows)})")
    cells = "".join(f"<th>{html.escape(str(h))}</th>" for h in header)
    body = "".join(
        "<tr>" + "".join(f"<td class=n>{html.escape(_cell(v))}</td>" for v in row) + "</tr>"
        for row in rows
    )
    page.parts.append(f"<table><tr>{cells}</tr>{body}</table>")
    page.heading("Study file")
    page.pre(record.get("study_file", ""))
    page.heading("Data")
    page.json_block("best", result)
    return page.html()


#: what each of optuna's figures shows (a caption, not the file name)
_CAPTIONS = {
    "history": "Optimisation history: each trial's objective and the best so far",
    "importances": "Parameter importances (fANOVA) for the objective",
    "slice": "Slice plot: the objective against each parameter, one point per trial",
    "pareto": "The Pareto front of the objectives (trials not dominated by any other)",
}


def _caption(name: str) -> str:
    """The caption of figure file ``name`` (``history-rho.png`` → its objective named too)."""
    stem = name.removesuffix(".png")
    kind, _, objective = stem.partition("-")
    text = _CAPTIONS.get(kind, stem)
    return f"{text} ({objective})" if objective else text


def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return f"{value:.5g}"
    return str(value)


def write_results(out: str | Path) -> dict:
    """Write every result file of the study folder ``out`` (see the module docstring).

    Returns
    -------
    dict
        ``best``: what best.json holds; ``files``: the paths written.
    """
    from skygas.outputs.report import check_report_path
    from skygas.runs.run_driver import write_atomic, write_json

    out = Path(out)
    record = read_study_record(out)
    provenance = _provenance(out, record)
    summaries = list(iter_trial_summaries(out))
    files = []
    table = trials_table(record, summaries)
    _write_csv(out / "trials.csv", *table, provenance)
    files.append(out / "trials.csv")
    result = best(out, record, summaries)
    write_json(out / "best.json", {**result, "provenance": provenance})
    files.append(out / "best.json")
    if "pareto_set" in result:
        names = [o["name"] for o in record["objectives"]]
        fields = [p["field"] for p in record["parameters"]]
        header = ["number", *fields]
        for n in names:
            header += [n, f"{n}_error"]
        rows = []
        for e in result["pareto_set"]:
            row = [e["trial"], *(e["params"].get(f) for f in fields)]
            for n in names:
                row += [e["objectives"][n]["mean"], e["objectives"][n]["error"]]
            rows.append(row)
        _write_csv(out / "pareto.csv", header, rows, provenance)
        files.append(out / "pareto.csv")
    notes = _figures(out, record, provenance)
    files += [out / n for n, v in notes.items() if v == "written"]
    text = _report(out, record, result, table, notes)
    report = check_report_path(out / "report.html")
    write_atomic(report, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    files.append(report)
    return {"best": result, "files": [str(f) for f in files], "figures": notes}
