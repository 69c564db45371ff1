"""A study's figures, drawn from its trial summaries and ``best.json`` (matplotlib, no display).

- ``history.png`` (``history-NAME.png`` per objective with several): each complete trial's
  objective against its number, as the mean of its runs (± standard error with several runs);
  with one objective also the best so far and the re-evaluated candidates;
- ``slice.png`` (``slice-NAME.png``): the objective against each parameter, one point per trial;
- ``importances.png`` (``importances-NAME.png``): each parameter's share of the objective's
  variance, by fANOVA (optuna's evaluator, seeded with the study's seed);
- ``pareto.png`` (two or three objectives): the objectives of every trial against each other,
  the Pareto set marked.

Axes carry the quantities' labels and units (:mod:`skygas.core.quantities`), scaled by an SI
prefix (nm, µs) or a power of ten; each function returns its figure and a caption that says
what it draws (the names of the study file between backticks, shown as code in the report).
"""

from __future__ import annotations

import itertools
import math
import warnings
from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from skygas.core.quantities import quantity
from skygas.figures.plotting import axis_scale
from skygas.optimize.verdict import parameter_label, shown

#: the colours of the figures: trials, the best so far, re-evaluation, trials breaking a constraint
TRIAL, BEST, AGAIN, BROKEN = "tab:blue", "tab:red", "tab:orange", "0.6"


def _titled(name: str, unit: str) -> str:
    return f"{name} ({unit})" if unit else name


def _objective_values(summaries: list[dict], name: str) -> list[dict]:
    """Complete trials: number, parameters, mean, error and whether it meets the constraints."""
    rows = []
    for s in summaries:
        if s["state"] != "COMPLETE":
            continue
        value = s["objectives"][name]
        rows.append(
            {
                "trial": s["number"],
                "params": s["params"],
                "mean": value["mean"],
                "error": value.get("error"),
                "feasible": all(c["met"] for c in s.get("constraints", {}).values()),
            }
        )
    return rows


def _errors(rows: list[dict], scale: float) -> np.ndarray | None:
    errors = np.array([np.nan if r["error"] is None else r["error"] for r in rows], float)
    return None if not np.isfinite(errors).any() else np.nan_to_num(errors) / scale


def history(record: dict, summaries: list[dict], result: dict, index: int) -> tuple[Figure, str]:
    """Objective ``index`` of each complete trial against the trial's number (module docstring)."""
    o = result["objectives"][index]
    rows = _objective_values(summaries, o["name"])
    single = "pareto_set" not in result
    candidates = result.get("candidates", []) if single else []
    again = [c["reevaluated"][o["name"]] for c in candidates]
    scale, unit = axis_scale([r["mean"] for r in rows] + [a["mean"] for a in again], o["unit"])
    fig = Figure(figsize=(7.4, 3.8), layout="constrained")
    ax = fig.add_subplot()
    runs = f"mean of its {record['replicas']} runs ± s.e." if record["replicas"] > 1 else "one run"
    parts = [f"each complete trial's {shown(o['name'])} ({runs}) against the trial's number"]
    for feasible in (True, False):
        chosen = [r for r in rows if r["feasible"] == feasible]
        if not chosen:
            continue
        ax.errorbar(
            [r["trial"] for r in chosen],
            np.array([r["mean"] for r in chosen]) / scale,
            yerr=_errors(chosen, scale),
            fmt="o",
            ms=4,
            lw=0.8,
            label="trial" if feasible else "trial breaking a constraint",
            color=TRIAL if feasible else BROKEN,
            mfc=None if feasible else "none",
        )
        if not feasible:
            parts.append("trials that break a constraint hollow and grey")
    sign = 1.0 if o["direction"] == "minimize" else -1.0
    if single and any(r["feasible"] for r in rows):
        best, line = math.inf, []
        for r in rows:
            if r["feasible"]:
                best = min(best, sign * r["mean"])
            line.append(sign * best if math.isfinite(best) else np.nan)
        trials = [r["trial"] for r in rows]
        ax.step(trials, np.array(line) / scale, where="post", color=BEST, label="best so far")
        sense = "lowest" if sign > 0 else "highest"
        parts.append(f"the best so far (the {sense} mean of the trials meeting the constraints)")
    if again:
        ax.errorbar(
            [c["trial"] for c in candidates],
            np.array([a["mean"] for a in again]) / scale,
            yerr=_errors(again, scale),
            fmt="D",
            ms=5,
            lw=1.0,
            color=AGAIN,
            label="re-evaluated",
        )
        parts.append(
            f"the {len(again)} re-evaluated candidates' means over their re-evaluation runs "
            "± s.e. (orange diamonds)"
        )
    ax.set_xlabel("trial")
    ax.set_ylabel(_titled(o["name"], unit))
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    fig.legend(loc="outside right upper", fontsize=8)
    return fig, "Optimisation history: " + "; ".join(parts) + "."


def _parameter_axis(ax, p: dict, values: list[Any]) -> tuple[list[float], str]:
    """Set ``ax``'s x axis for parameter ``p``; the values' positions on it and its label."""
    from skygas.figures.plotting import log_ticks

    name = parameter_label(p["field"])
    if p["kind"] == "categorical":
        choices = [str(c) for c in p["choices"]]
        ax.set_xticks(range(len(choices)), labels=choices)
        ax.set_xlim(-0.5, len(choices) - 0.5)
        return [float(choices.index(str(v))) for v in values], name
    scale, unit = axis_scale([float(p["low"]), float(p["high"])], quantity(p["field"]).unit)
    x = [float(v) / scale for v in values]
    low, high = float(p["low"]) / scale, float(p["high"]) / scale
    margin = 0.03 * (high - low)
    if p.get("log"):
        ax.set_xscale("log")
        ax.set_xlim(low / (high / low) ** 0.03, high * (high / low) ** 0.03)
        log_ticks(ax.xaxis, low, high)
    else:
        ax.set_xlim(low - margin, high + margin)
        ax.xaxis.set_major_locator(MaxNLocator(nbins=4, integer=p["kind"] == "int"))
    return x, _titled(name, unit)


def slices(record: dict, summaries: list[dict], result: dict, index: int) -> tuple[Figure, str]:
    """Objective ``index`` of each complete trial against each parameter, one panel each."""
    o = result["objectives"][index]
    rows = _objective_values(summaries, o["name"])
    parameters = record["parameters"]
    columns = min(3, len(parameters))
    lines = math.ceil(len(parameters) / columns)
    fig = Figure(figsize=(2.9 * columns + 1.4, 2.7 * lines + 0.5), layout="constrained")
    axes = fig.subplots(lines, columns, sharey=True, squeeze=False)
    scale, unit = axis_scale([r["mean"] for r in rows], o["unit"])
    broken = any(not r["feasible"] for r in rows)
    for k, ax in enumerate(axes.flat):
        if k >= len(parameters):
            fig.delaxes(ax)
            continue
        p = parameters[k]
        x, text = _parameter_axis(ax, p, [r["params"][p["field"]] for r in rows])
        y = np.array([r["mean"] for r in rows]) / scale
        ok = np.array([r["feasible"] for r in rows], bool)
        ax.plot(np.array(x)[ok], y[ok], "o", ms=3.5, alpha=0.75, color=TRIAL, label="trial")
        if broken:
            label_ = "trial breaking a constraint"
            ax.plot(np.array(x)[~ok], y[~ok], "o", ms=3.5, mfc="none", color=BROKEN, label=label_)
        ax.set_xlabel(text)
        if k % columns == 0:
            ax.set_ylabel(_titled(o["name"], unit))
    if broken:
        handles, names = axes.flat[0].get_legend_handles_labels()
        fig.legend(handles, names, loc="outside lower center", ncols=2, fontsize=8)
    caption = (
        f"Slice plot: each complete trial's {shown(o['name'])} (the mean of its runs) against each "
        "searched parameter, one point per trial"
    )
    return fig, caption + ("; trials that break a constraint hollow and grey." if broken else ".")


def importances(out: Path, record: dict, result: dict, index: int) -> tuple[Figure, str]:
    """The importance of each parameter for objective ``index``, by fANOVA (module docstring).

    Raises
    ------
    ValueError
        With one parameter (its importance is 1 by definition) or trials too few for fANOVA.
    """
    import optuna

    if len(record["parameters"]) < 2:
        raise ValueError("one parameter searched: its importance is 1 by definition")
    study = load_optuna(out)
    evaluator = optuna.importance.FanovaImportanceEvaluator(seed=int(record["seed"]) % 2**32)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        found = optuna.importance.get_param_importances(
            study, evaluator=evaluator, target=lambda t: t.values[index]
        )
    o = result["objectives"][index]
    names = list(found)[::-1]  # the most important on top
    fig = Figure(figsize=(6.4, 0.45 * len(names) + 1.3), layout="constrained")
    ax = fig.add_subplot()
    ax.barh(range(len(names)), [found[n] for n in names], color=TRIAL)
    ax.set_yticks(range(len(names)), labels=[parameter_label(n) for n in names])
    ax.set_xlim(0, 1)
    ax.set_xlabel(f"share of the variance of {o['name']} (fANOVA)")
    caption = (
        f"Parameter importances: the share of the variance of {shown(o['name'])} over the complete "
        "trials that each parameter explains (fANOVA, a random forest fitted to the trials' "
        "means)."
    )
    return fig, caption


def pareto(record: dict, summaries: list[dict], result: dict) -> tuple[Figure, str]:
    """Each pair of objectives of every complete trial, the Pareto set marked."""
    objectives = result["objectives"]
    front = {e["trial"] for e in result["pareto_set"]}
    pairs = list(itertools.combinations(range(len(objectives)), 2))
    fig = Figure(figsize=(3.8 * len(pairs) + 2.4, 3.8), layout="constrained")
    axes = np.ravel(fig.subplots(1, len(pairs)))
    rows = {o["name"]: _objective_values(summaries, o["name"]) for o in objectives}
    trials = rows[objectives[0]["name"]]
    groups = (
        ("trial", lambda r: r["feasible"] and r["trial"] not in front, {"color": TRIAL}),
        ("trial breaking a constraint", lambda r: not r["feasible"], {"color": BROKEN}),
        ("Pareto set", lambda r: r["trial"] in front, {"color": BEST, "ms": 5}),
    )
    for ax, (i, j) in zip(axes, pairs, strict=True):
        oi, oj = objectives[i], objectives[j]
        si, ui = axis_scale([r["mean"] for r in rows[oi["name"]]], oi["unit"])
        sj, uj = axis_scale([r["mean"] for r in rows[oj["name"]]], oj["unit"])
        for name, keep, style in groups:
            chosen = [k for k, r in enumerate(trials) if keep(r)]
            if not chosen:
                continue
            x = [rows[oi["name"]][k]["mean"] / si for k in chosen]
            y = [rows[oj["name"]][k]["mean"] / sj for k in chosen]
            mfc = "none" if name.startswith("trial breaking") else None
            ax.plot(x, y, "o", ms=style.get("ms", 3.5), color=style["color"], mfc=mfc, label=name)
        ax.set_xlabel(_titled(f"{oi['name']} ({oi['direction']})", ui))
        ax.set_ylabel(_titled(f"{oj['name']} ({oj['direction']})", uj))
        ax.xaxis.set_major_locator(MaxNLocator(nbins=4))
    handles, names = axes[0].get_legend_handles_labels()
    fig.legend(handles, names, loc="outside right upper", fontsize=8)
    caption = (
        "Pareto front: the objectives of each complete trial (the means of its runs) against each "
        "other; the Pareto set (trials meeting the constraints that no other such trial beats in "
        "every objective) in red."
    )
    return fig, caption


def load_optuna(out: Path):
    """The optuna study of study folder ``out``, read from its journal."""
    import optuna
    from optuna.storages import JournalStorage
    from optuna.storages.journal import JournalFileBackend

    from skygas.optimize.execute import JOURNAL, STUDY_NAME

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    storage = JournalStorage(JournalFileBackend(str(out / JOURNAL)))
    return optuna.load_study(study_name=STUDY_NAME, storage=storage)


def draw_figures(
    out: Path, record: dict, summaries: list[dict], result: dict, provenance: dict[str, str]
) -> tuple[dict[str, str], dict[str, str]]:
    """Draw and write every figure of the study folder ``out``.

    Returns
    -------
    tuple of dict
        By file name: ``"written"`` or ``"not drawn: why"``; and each written figure's caption.
    """
    from skygas.runs.run_driver import write_figure

    notes: dict[str, str] = {}
    captions: dict[str, str] = {}

    def save(name: str, draw: Callable[[], tuple[Figure, str]]) -> None:
        try:
            fig, caption = draw()
        except (ValueError, RuntimeError, ZeroDivisionError) as err:
            notes[name] = f"not drawn: {err}"
            return
        write_figure(out / name, lambda tmp: fig.savefig(tmp, dpi=100, format="png"), provenance)
        notes[name], captions[name] = "written", caption

    objectives = result["objectives"]
    few = sum(s["state"] == "COMPLETE" for s in summaries) < 2
    for i, o in enumerate(objectives):
        suffix = "" if len(objectives) == 1 else f"-{o['name']}"
        for kind, draw in (
            ("history", partial(history, record, summaries, result, i)),
            ("importances", partial(importances, out, record, result, i)),
            ("slice", partial(slices, record, summaries, result, i)),
        ):
            if few:
                notes[f"{kind}{suffix}.png"] = "not drawn: fewer than 2 complete trials"
            else:
                save(f"{kind}{suffix}.png", draw)
    if 2 <= len(objectives) <= 3:
        if few:
            notes["pareto.png"] = "not drawn: fewer than 2 complete trials"
        else:
            save("pareto.png", partial(pareto, record, summaries, result))
    return notes, captions
