"""A study's results, made from its folder: tables, the best trial or the Pareto set, figures.

``skygas optimize`` writes them at its end, ``skygas report DIR`` again:

- ``trials.csv``: one row per finished trial (complete or failed): its number, state,
  parameters, each objective's mean and standard error over the trial's replicas, each
  constraint's mean and whether it was met, the error of a failed trial;
- ``best.json``: one objective: the best trial (:func:`best`; chosen on the re-evaluated means
  where re-evaluation ran, :mod:`skygas.optimize.verdict`), the search's own best, the
  re-evaluated candidates (mean ± standard error over their re-evaluation runs), which of them
  are within noise of the best, and the parameters of the best that sit on a search bound;
  several objectives: the Pareto set, each member with its re-evaluation where it had one;
- ``pareto.csv`` and ``pareto.png`` (several objectives): the Pareto set's objectives;
- ``history.png``, ``slice.png``, ``importances.png`` (one of each per objective with several):
  :mod:`skygas.optimize.figures`;
- ``report.html``: :mod:`skygas.optimize.report`.

``best.json`` is the one answer: the report and the terminal show what the file says
(:func:`skygas.optimize.verdict.statement`). Every file carries the provenance record
(:mod:`skygas.runs.provenance`): the skygas version, the study's seed and fingerprint, the
command line.
"""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path
from typing import Any

from skygas.optimize.execute import (
    RUNS,
    iter_trial_summaries,
    read_study_record,
    reevaluation_runs,
)
from skygas.optimize.verdict import LEVEL, RULE, at_bounds, compare, run_statistics

FIGURES = ("history.png", "importances.png", "slice.png", "pareto.png")


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


def objectives_with_units(record: dict) -> list[dict]:
    """The study's objectives, each with the ``unit`` of its value (None: not derived)."""
    from skygas.core.quantities import quantity
    from skygas.optimize.devices import device
    from skygas.optimize.expressions import parse_expression, unit_of

    names = device(record["device"]).quantities
    return [
        {
            **o,
            "unit": unit_of(
                parse_expression(o["expression"], o["name"], names), lambda n: quantity(n).unit
            ),
        }
        for o in record["objectives"]
    ]


def _reevaluated(record: dict, summary: dict, out: Path) -> tuple[dict, dict] | None:
    """A candidate's objectives and constraints over its re-evaluation runs alone.

    Each a mean with its standard error (:func:`~skygas.optimize.verdict.run_statistics`); a
    constraint also its mean violation and whether that is ≤ 0. None without such runs.
    """
    from skygas.optimize.expressions import parse_constraint, parse_expression

    runs = reevaluation_runs(out, summary["seed_key"])
    if not runs:
        return None
    names = list(runs[0])
    objectives = {}
    for o in record["objectives"]:
        expression = parse_expression(o["expression"], o["name"], names)
        objectives[o["name"]] = run_statistics([expression(r) for r in runs])
    constraints = {}
    for text in record["constraints"]:
        c = parse_constraint(text, text, names)
        stats = run_statistics([c.expression(r) for r in runs])
        violation = run_statistics([c.violation(r) for r in runs])["mean"]
        met = violation is not None and violation <= 0
        constraints[text] = {**stats, "violation": violation, "met": met}
    return objectives, constraints


def _entry(record: dict, summary: dict, out: Path) -> dict:
    again = _reevaluated(record, summary, out)
    return {
        "trial": summary["number"],
        "params": summary["params"],
        "objectives": summary["objectives"],
        "constraints": summary.get("constraints", {}),
        "replicas": len(summary["runs"]),
        "reevaluated": again[0] if again else None,
        "reevaluated_constraints": again[1] if again else None,
        "at_bounds": at_bounds(summary["params"], record["parameters"]),
    }


def _noise(best: dict, others: list[dict], name: str) -> dict:
    """Each other candidate against the best (:func:`~skygas.optimize.verdict.compare`)."""
    verdicts: dict[str, list[dict]] = {"within_noise": [], "distinguishable": [], "undecided": []}
    for other in others:
        test = compare(best["reevaluated"][name], other["reevaluated"][name])
        kind = {True: "within_noise", False: "distinguishable", None: "undecided"}
        verdicts[kind[test["within_noise"]]].append(
            {
                "trial": other["trial"],
                "params": other["params"],
                **other["reevaluated"][name],
                **test,
            }
        )
    return {"rule": RULE, "level": LEVEL, **verdicts}


def best(out: Path, record: dict, summaries: list[dict]) -> dict:
    """What ``best.json`` holds (see the module docstring and :mod:`skygas.optimize.verdict`).

    One objective: ``best`` is the re-evaluated candidate of the best mean over its
    re-evaluation runs (``chosen_on = "re-evaluation"``; those that meet the constraints on
    those runs first) or, without re-evaluation, the feasible trial of the best mean of its own
    runs (``"search"``); ``search_best`` the latter in either case; ``candidates`` the
    re-evaluated ones, best first; ``noise`` each of them against the best (None without
    re-evaluation). Several objectives: ``pareto_set``.
    """
    complete = [s for s in summaries if s["state"] == "COMPLETE"]
    feasible = [s for s in complete if _feasible(s)]
    result: dict[str, Any] = {
        "objectives": objectives_with_units(record),
        "constraints": record["constraints"],
        "reevaluate": record.get("reevaluate", 0),
        "reevaluate_replicas": record.get("reevaluate_replicas"),
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
    result["search_best"] = _entry(record, ranked[0], out) if ranked else None
    # every trial re-evaluated (a resumed study may have re-evaluated others before)
    entries = [
        _entry(record, s, out)
        for s in ranked
        if any((out / RUNS / f"trial-{s['seed_key']}").glob("reeval-*.json"))
    ]

    def again(e: dict) -> float:
        mean = e["reevaluated"][o["name"]]["mean"]
        return math.inf if mean is None else sign * mean

    candidates = [e for e in entries if e["reevaluated"]]
    # those meeting the constraints on their re-evaluation runs first, then by their mean there
    candidates.sort(
        key=lambda e: (not all(c["met"] for c in e["reevaluated_constraints"].values()), again(e))
    )
    result["candidates"] = candidates
    if candidates:
        result["best"], result["chosen_on"] = candidates[0], "re-evaluation"
        result["noise"] = _noise(candidates[0], candidates[1:], o["name"])
    else:
        result["best"], result["chosen_on"] = result["search_best"], "search"
        result["noise"] = None
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


def write_results(out: str | Path) -> dict:
    """Write every result file of the study folder ``out`` (see the module docstring).

    ``best.json`` is written first and read back: the figures, the report and the terminal
    (``skygas optimize``) all show what the file says.

    Returns
    -------
    dict
        ``best``: what best.json holds; ``files``: the paths written; ``figures``: by figure
        file, ``"written"`` or why it was not drawn.
    """
    import json

    from skygas.optimize.figures import draw_figures
    from skygas.optimize.report import study_report
    from skygas.outputs.report import check_report_path
    from skygas.runs.run_driver import write_atomic, write_json

    out = Path(out)
    record = read_study_record(out)
    provenance = _provenance(out, record)
    summaries = list(iter_trial_summaries(out))
    files = []
    _write_csv(out / "trials.csv", *trials_table(record, summaries), provenance)
    files.append(out / "trials.csv")
    write_json(out / "best.json", {**best(out, record, summaries), "provenance": provenance})
    files.append(out / "best.json")
    result = json.loads((out / "best.json").read_text())
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
    notes, captions = draw_figures(out, record, summaries, result, provenance)
    files += [out / n for n, v in notes.items() if v == "written"]
    text = study_report(out, record, result, summaries, notes, captions)
    report = check_report_path(out / "report.html")
    write_atomic(report, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    files.append(report)
    return {"best": result, "files": [str(f) for f in files], "figures": notes}
