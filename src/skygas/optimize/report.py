"""``report.html`` of a study folder: what the study found first, then how it was found.

From the top: which command made the study, when, with which skygas version; the headline
(:func:`skygas.optimize.verdict.statement` of ``best.json``, the rows the terminal prints); the
re-evaluated candidates against the best, or the Pareto set; the study and its search space;
the figures with captions that say what they draw; every trial; the study file; ``best.json``
itself. Values carry their quantities' units (:mod:`skygas.core.quantities`); the study file's
keys are shown as code.
"""

from __future__ import annotations

import html
import re
import time
from pathlib import Path
from typing import Any

from skygas.core.quantities import format_quantity, format_value
from skygas.optimize.verdict import RULE, parameter_label, shown, statement, value_text

#: `key` in a statement: a name from the study file, shown as code
_CODE = re.compile(r"`([^`]+)`")


def markup(text: str) -> str:
    """``text`` as HTML: escaped, with the names between backticks as code."""
    return _CODE.sub(r"<code>\1</code>", html.escape(text))


def _cells(header: list[str], rows: list[list[str]]) -> str:
    """A table of HTML cells under a header of text (names between backticks as code)."""
    head = "".join(f"<th>{markup(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td class=n>{c}</td>" for c in r) + "</tr>" for r in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


def _headline(result: dict) -> str:
    """The headline block, as every skygas report opens (:meth:`skygas.outputs.report.Page`)."""
    rows = "".join(
        f"<tr><th>{markup(k)}</th><td class=n>{markup(v)}</td></tr>" for k, v in statement(result)
    )
    notes = []
    if result.get("noise") is not None:
        notes.append(
            "The best is the re-evaluated candidate with the best mean over its re-evaluation "
            "runs (new seeds; the runs that got it picked are left out), its error the standard "
            "error of those runs. " + RULE
        )
    body = "".join(f"<p>{markup(n)}</p>" for n in notes)
    return (
        f"<section class=headline id=headline><h2>Results</h2><table>{rows}</table>{body}</section>"
    )


def _parameter_cells(params: dict[str, Any], fields: list[str]) -> list[str]:
    return [html.escape(format_quantity(f, params.get(f)) or "") for f in fields]


def _candidates(result: dict, fields: list[str]) -> str:
    """The re-evaluated candidates against the best: their means, differences and verdicts."""
    o = result["objectives"][0]
    name, unit = o["name"], o["unit"]
    verdicts = {c["trial"]: (c, "within noise") for c in result["noise"]["within_noise"]}
    verdicts |= {c["trial"]: (c, "told apart") for c in result["noise"]["distinguishable"]}
    verdicts |= {c["trial"]: (c, "not compared") for c in result["noise"]["undecided"]}
    rows = []
    for e in result["candidates"]:
        again = e["reevaluated"][name]
        own = e["objectives"][name]
        test, verdict = verdicts.get(e["trial"], ({}, "the best"))

        def number(value: Any) -> str:
            return format_value(value, unit=unit or "", digits=2) or ""

        rows.append(
            [
                str(e["trial"]),
                *_parameter_cells(e["params"], fields),
                html.escape(f"{value_text(again, unit)} ({again['runs']} runs)"),
                html.escape(value_text(own, unit)),
                html.escape(number(test.get("difference"))),
                html.escape(number(test.get("threshold"))),
                verdict,
            ]
        )
    header = [
        "trial",
        *(parameter_label(f) for f in fields),
        "re-evaluated (mean ± s.e.)",
        "in the search (the trial's runs)",
        "difference from the best",
        "noise threshold",
        "verdict",
    ]
    return _cells(header, rows)


def _pareto(result: dict, fields: list[str]) -> str:
    objectives = result["objectives"]
    header = ["trial", *(parameter_label(f) for f in fields)]
    header += [f"{shown(o['name'])} (mean ± s.e.)" for o in objectives] + ["re-evaluated"]
    rows = []
    for e in result["pareto_set"]:
        own = [value_text(e["objectives"][o["name"]], o["unit"]) for o in objectives]
        again = e.get("reevaluated") or {}
        redone = ", ".join(
            f"{shown(o['name'])} = {value_text(again[o['name']], o['unit'])}"
            for o in objectives
            if o["name"] in again
        )
        rows.append(
            [str(e["trial"]), *_parameter_cells(e["params"], fields)]
            + [html.escape(t) for t in own]
            + [markup(redone or "no")]
        )
    return _cells(header, rows)


def _space(record: dict) -> str:
    """The searched parameters: label, key in the study file, range with unit, and scale."""
    rows = []
    for p in record["parameters"]:
        if p["kind"] == "categorical":
            values, scale = ", ".join(map(str, p["choices"])), "choices"
        else:
            low, high = (format_quantity(p["field"], p[k]) for k in ("low", "high"))
            values = f"{low} to {high}"
            scale = "log-uniform" if p["log"] else "uniform"
            if p["kind"] == "int":
                scale += ", whole numbers"
            if p.get("step"):
                scale += f", steps of {format_quantity(p['field'], p['step'])}"
        rows.append(
            [
                html.escape(parameter_label(p["field"])),
                f"<code>{html.escape(p['field'])}</code>",
                html.escape(values),
                scale,
            ]
        )
    return _cells(["parameter", "study-file key", "range", "scale"], rows)


def _trials(record: dict, result: dict, summaries: list[dict]) -> str:
    """Every finished trial: state, parameters, objectives, constraints, runs, error."""
    fields = [p["field"] for p in record["parameters"]]
    objectives = result["objectives"]
    header = ["trial", "state", *(parameter_label(f) for f in fields)]
    header += [f"{shown(o['name'])} (mean ± s.e.)" for o in objectives]
    header += [f"constraint `{c}` (mean)" for c in record["constraints"]]
    header += ["meets the constraints", "runs", "error"]
    rows = []
    for s in summaries:
        values = s.get("objectives", {})
        row = [str(s["number"]), "complete" if s["state"] == "COMPLETE" else "failed"]
        row += _parameter_cells(s["params"], fields)
        row += [
            html.escape(value_text(values[o["name"]], o["unit"])) if o["name"] in values else ""
            for o in objectives
        ]
        constraints = s.get("constraints", {})
        row += [
            html.escape(format_value(constraints[c]["mean"]) or "") if c in constraints else ""
            for c in record["constraints"]
        ]
        met = all(c["met"] for c in constraints.values())
        row += ["yes" if met else "no"] if s["state"] == "COMPLETE" else [""]
        error = f"<code>{html.escape(s['error'])}</code>" if s.get("error") else ""
        row += [str(len(s["runs"])), error]
        rows.append(row)
    return _cells(header, rows)


def _study_rows(record: dict, result: dict) -> list[tuple[str, str]]:
    again = record.get("reevaluate", 0)
    reevaluation = (
        f"the {again} best candidates, {record.get('reevaluate_replicas')} more runs each"
        if again
        else "none (add <code>reevaluate = 3</code> to <code>[study]</code>)"
    )
    constraints = "; ".join(f"<code>{html.escape(c)}</code>" for c in record["constraints"])
    return [
        ("device", html.escape(record["device"])),
        ("sampler", html.escape(record["sampler"])),
        ("seed", html.escape(str(record["seed"]))),
        ("runs per trial", html.escape(str(record["replicas"]))),
        ("re-evaluation", reevaluation),
        ("fingerprint", f"<code>{html.escape(record['fingerprint'])}</code>"),
        ("skygas version of the study", html.escape(record["skygas_version"])),
        (
            "trials finished (complete)",
            f"{result['trials_finished']} ({result['trials_complete']})",
        ),
        ("complete trials meeting the constraints", str(result["trials_feasible"])),
        ("constraints", constraints or "none"),
    ]


def study_report(
    out: Path,
    record: dict,
    result: dict,
    summaries: list[dict],
    notes: dict[str, str],
    captions: dict[str, str],
) -> str:
    """The HTML of ``report.html`` (see the module docstring).

    ``result`` is ``best.json`` as read back from the file; ``notes`` and ``captions`` say,
    by figure file, whether it was drawn (or why not) and what it draws.
    """
    from skygas.outputs.report import Page, _made_by
    from skygas.runs import manifest

    page = Page(f"skygas optimize — {record.get('name') or out.name}")
    found = manifest.read(out) or {}
    _made_by(page, out, found.get("skygas_version") or record["skygas_version"], record["seed"])
    from skygas._version import __version__

    page.raw(
        f"<p>Report written by skygas {html.escape(__version__)} on "
        f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} from the study folder "
        f"<code>{html.escape(str(out))}</code>.</p>"
    )
    page.raw(_headline(result))
    fields = [p["field"] for p in record["parameters"]]
    if "pareto_set" in result:
        page.heading(f"Pareto set ({len(result['pareto_set'])} trials)")
        page.raw(_pareto(result, fields))
    elif result.get("candidates"):
        page.heading(f"Re-evaluated candidates ({len(result['candidates'])})")
        page.raw(_candidates(result, fields))
    page.heading("Study")
    page.table(_study_rows(record, result))
    page.heading("Search space")
    page.raw(_space(record))
    page.heading("Figures")
    for name in sorted(notes):
        if notes[name] == "written" and (out / name).exists():
            page.raw(_figure((out / name).read_bytes(), captions[name]))
        else:
            page.raw(f"<p>{markup(f'{_kind(name)}: {notes[name]}')}</p>")
    page.heading(f"Trials ({len(summaries)})")
    page.raw(_trials(record, result, summaries))
    page.heading("Study file")
    page.pre(record.get("study_file", ""))
    page.heading("Data")
    page.json_block("best", result)
    return page.html()


def _figure(png: bytes, caption: str) -> str:
    """A figure with its caption, as :meth:`skygas.outputs.report.Page.image` writes one."""
    import base64

    uri = "data:image/png;base64," + base64.b64encode(png).decode("ascii")
    alt = html.escape(caption.replace("`", ""))
    image = f'<img src="{uri}" alt="{alt}">'
    return f"<figure>{image}<figcaption>{markup(caption)}</figcaption></figure>"


def _kind(name: str) -> str:
    """What figure ``name`` would have shown (``history-f.png`` → "Optimisation history (f)")."""
    kinds = {
        "history": "Optimisation history",
        "importances": "Parameter importances",
        "slice": "Slice plot",
        "pareto": "Pareto front",
    }
    kind, _, objective = name.removesuffix(".png").partition("-")
    text = kinds.get(kind, kind)
    return f"{text} ({shown(objective)})" if objective else text
