r"""What a study's best trial is worth: its value after re-evaluation, its rivals, its bounds.

The search's own best is the trial whose mean came out lowest (or highest) of many noisy
trials: it was picked *because* its runs were lucky, so its value is biased (the winner's
curse). Re-evaluation (``reevaluate`` candidates × ``reevaluate_replicas`` runs, new seeds)
measures the candidates again with runs that picked nothing, and:

- **the best** is the candidate with the best mean :math:`\bar y` over its re-evaluation runs
  alone, with the standard error :math:`s/\sqrt n` of their scatter (:math:`s` with
  :math:`n - 1` in its denominator); the trial's own runs are left out, since they are the ones
  that got it picked. Without re-evaluation the best is the search's, a single noisy value;
- **within noise of the best** (:func:`compare`): a candidate :math:`j` whose difference from
  the best, :math:`\Delta = \bar y_j - \bar y_b`, is inside what noise alone gives,

  .. math:: |\Delta| < t_{0.975,\,\nu}\,\sqrt{e_b^2 + e_j^2},

  Welch's two-sided t-test at the 5 % level (:data:`LEVEL`), :math:`e` the standard errors and
  :math:`\nu` the Welch–Satterthwaite degrees of freedom
  :math:`\nu = (e_b^2 + e_j^2)^2 / (e_b^4/(n_b - 1) + e_j^4/(n_j - 1))`. Two candidates of the
  same true value are told apart in 5 % of studies; with a single re-evaluation run a candidate
  has no error and is not compared;
- **at a bound** (:func:`at_bounds`): a parameter of the best within 1 % (:data:`BOUND_FRACTION`)
  of its range's width of an end (in :math:`\log_{10}` of the value for a log range), or at the
  last value of a whole-number or stepped range: the optimum may lie beyond it.

:func:`statement` writes what ``best.json`` holds as the rows the terminal prints and the
report's headline shows: both read the file, neither recomputes it.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from typing import Any

import numpy as np

#: Significance level of the two-sided test of a candidate against the best.
LEVEL = 0.05
#: Fraction of a range's width within which a parameter counts as at its end.
BOUND_FRACTION = 0.01
#: The rule of :func:`compare`, as the report and ``best.json`` state it.
RULE = (
    "A candidate is within noise of the best when Welch's two-sided t-test at the 5 % level does "
    "not tell their re-evaluated means apart: |difference| < t(0.975, ν) × √(s.e.(best)² + "
    "s.e.(candidate)²), ν the Welch–Satterthwaite degrees of freedom. Two designs of the same "
    "true value are told apart in 5 % of studies."
)


def run_statistics(values: Sequence[float]) -> dict[str, Any]:
    r"""The mean of ``values``, its standard error (None with fewer than 2) and their count.

    The error is :math:`s/\sqrt n` with :math:`s` the sample standard deviation
    (:math:`n - 1` in its denominator). A value that is not finite leaves no mean (None).
    """
    a = np.asarray(values, dtype=float)
    n = len(a)
    if n == 0 or not np.all(np.isfinite(a)):
        return {"mean": None, "error": None, "runs": n}
    error = float(a.std(ddof=1) / math.sqrt(n)) if n > 1 else None
    return {"mean": float(a.mean()), "error": error, "runs": n}


def compare(best: dict[str, Any], other: dict[str, Any]) -> dict[str, Any]:
    r"""Welch's test of ``other``'s mean against ``best``'s (see the module docstring).

    Parameters
    ----------
    best, other : dict
        Each ``{"mean", "error", "runs"}`` (:func:`run_statistics`).

    Returns
    -------
    dict
        ``difference`` (other − best), ``threshold`` (:math:`t_{0.975,\nu}` × the combined
        error; None when either has no error), ``dof`` (:math:`\nu`) and ``within_noise``:
        True, False, or None when it cannot be told (a mean or an error missing). Two means
        without any scatter (both errors 0) are within noise only when equal.
    """
    from scipy.stats import t

    out: dict[str, Any] = {"difference": None, "threshold": None, "dof": None}
    if best["mean"] is None or other["mean"] is None:
        return {**out, "within_noise": None}
    difference = other["mean"] - best["mean"]
    out["difference"] = difference
    if best["error"] is None or other["error"] is None:
        return {**out, "within_noise": None}
    vb, vo = best["error"] ** 2, other["error"] ** 2
    if vb + vo == 0:
        return {**out, "threshold": 0.0, "within_noise": difference == 0}
    dof = (vb + vo) ** 2 / (vb**2 / (best["runs"] - 1) + vo**2 / (other["runs"] - 1))
    threshold = float(t.ppf(1 - LEVEL / 2, dof)) * math.sqrt(vb + vo)
    return {**out, "threshold": threshold, "dof": dof, "within_noise": abs(difference) < threshold}


def _last_step(low: float, high: float, step: float) -> float:
    """The last value of the grid low, low + step, … that does not pass ``high`` (optuna's)."""
    return low + step * math.floor((high - low) / step + 1e-9)


def at_bounds(params: dict[str, Any], parameters: list[dict]) -> list[dict[str, Any]]:
    """The parameters of ``params`` that sit at an end of their search range.

    Parameters
    ----------
    params : dict
        A trial's parameter values by field.
    parameters : list of dict
        The study's parameters as ``study.json`` records them (field, kind, low, high, log,
        step).

    Returns
    -------
    list of dict
        ``{"field", "value", "bound": "low" | "high", "end"}`` for each: within
        :data:`BOUND_FRACTION` of the width of an end (in log₁₀ for a log range), or at the
        first or last value of a whole-number or stepped range. Choices have no bounds.
    """
    found = []
    for p in parameters:
        value = params.get(p["field"])
        if p["kind"] == "categorical" or value is None:
            continue
        low, high = float(p["low"]), float(p["high"])
        if p["kind"] == "int" or p.get("step"):
            step = float(p.get("step") or 1)
            ends = {"low": low, "high": _last_step(low, high, step)}
            near = {name: abs(float(value) - end) <= 1e-9 * step for name, end in ends.items()}
        else:
            scale = math.log10 if p.get("log") else float
            width = scale(high) - scale(low)
            where = scale(float(value))
            ends = {"low": low, "high": high}
            near = {
                "low": where - scale(low) <= BOUND_FRACTION * width,
                "high": scale(high) - where <= BOUND_FRACTION * width,
            }
        for name in ("low", "high"):
            if near[name]:
                flag = {"field": p["field"], "value": value, "bound": name, "end": ends[name]}
                found.append(flag)
    return found


# -- the statement: best.json's content as rows of text ------------------------------------------
def parameter_label(field: str) -> str:
    """A searched field as a reader names it: its quantity's label (:mod:`skygas.core.quantities`).

    A dotted field whose whole key has no label of its own takes its table's name before the
    label of its last part (``injection.interval`` → "injection interval"), but for the
    device's geometry (``device.chamber_diameter`` → "chamber diameter").
    """
    from skygas.core.quantities import QUANTITIES, label

    table, _, _ = field.rpartition(".")
    if not table or field in QUANTITIES or table == "device":
        return label(field)
    return f"{table.rsplit('.', 1)[-1].replace('_', ' ')} {label(field)}"


def _parameter(field: str, value: Any) -> str:
    from skygas.core.quantities import format_quantity

    return format_quantity(field, value) or "none"


def _parameters(params: dict[str, Any]) -> str:
    return ", ".join(f"{parameter_label(k)} = {_parameter(k, v)}" for k, v in params.items())


def value_text(stats: dict[str, Any] | None, unit: str | None) -> str:
    """A mean ± its standard error in ``unit`` (None: not derived), or ``none (why)``."""
    from skygas.core.quantities import format_value

    if not stats or stats.get("mean") is None:
        return "none (no finite value)"
    text = format_value(stats["mean"], stats.get("error"), unit or "") or "none"
    if stats.get("error") is None and stats.get("runs") == 1:
        text += " (one run: no error)"
    return text


def _runs(n: int) -> str:
    return f"{n} run" if n == 1 else f"{n} runs"


def _bound_text(flag: dict[str, Any]) -> str:
    side = "upper" if flag["bound"] == "high" else "lower"
    field = flag["field"]
    return (
        f"{parameter_label(field)} = {_parameter(field, flag['value'])} is at the {side} bound "
        f"of `space.{field}` ({_parameter(field, flag['end'])}): widen the range"
    )


def shown(name: str) -> str:
    """An objective's name as text: between backticks (code) when it is not plain words."""
    return f"`{name}`" if re.search(r"[^\w ]|_", name) else name


def _own(n: int) -> str:
    """What a trial's own value is, over ``n`` runs."""
    return "the trial's one run" if n == 1 else f"mean of the trial's {n} runs ± s.e."


def _objective_rows(result: dict, entry: dict) -> list[tuple[str, str]]:
    """The best's value: after re-evaluation where it ran, then the search's own."""
    rows = []
    for o in result["objectives"]:
        name, unit = shown(o["name"]), o.get("unit")
        if unit is None:  # an expression whose unit is not derived: its number as computed
            name += " (its unit not derived from the expression)"
        again = (entry.get("reevaluated") or {}).get(o["name"])
        # the label says how many runs the trial's own value is over
        own, runs = entry["objectives"][o["name"]], entry["replicas"]
        if again:
            rows.append(
                (
                    f"{name} ({o['direction']}), re-evaluated: mean of {_runs(again['runs'])} "
                    "± s.e.",
                    value_text(again, unit),
                )
            )
            rows.append((f"{name} in the search ({_own(runs)})", value_text(own, unit)))
        else:
            sense = "lowest" if o["direction"] == "minimize" else "highest"
            among = f"{result['trials_feasible']} trials" + (
                " meeting the constraints" if result["constraints"] else ""
            )
            rows.append(
                (
                    f"{name} ({o['direction']}; {_own(runs)})",
                    f"{value_text(own, unit)}, the {sense} of {among}",
                )
            )
    return rows


def _noise_row(result: dict) -> tuple[str, str]:
    noise = result.get("noise")
    if noise is None:
        why = (
            "no re-evaluation run of the best candidates finished; run the study again to "
            "re-evaluate them"
            if result.get("reevaluate")
            else "add `reevaluate = 3` to `[study]` to run the best candidates again with new "
            "seeds and choose on those runs"
        )
        return (
            "uncertainty of the best",
            "a single noisy value: the best of the trials on their own means, which favours the "
            f"luckiest (the winner's curse); {why}",
        )
    within, apart, untold = noise["within_noise"], noise["distinguishable"], noise["undecided"]
    others = len(within) + len(apart) + len(untold)
    if others == 0:
        return ("trials within noise of the best", "none compared (one candidate re-evaluated)")
    text = f"{len(within)} of the {others} other re-evaluated candidates"
    if within:
        text += ": " + "; ".join(f"trial {c['trial']} ({_parameters(c['params'])})" for c in within)
    if apart:
        text += f". Told apart from the best: {len(apart)} (" + ", ".join(
            f"trial {c['trial']}" for c in apart
        )
        text += ")"
    if untold:
        text += f". Not compared (a single re-evaluation run): {len(untold)}"
    return ("trials within noise of the best", text)


def statement(result: dict) -> list[tuple[str, str]]:
    """The rows (label, text) that say what a study found, from ``best.json``'s content.

    The terminal prints them (``label: text``) and the report's headline shows them; names of
    the study file's keys are written between backticks (the report shows them as code).
    """
    if "pareto_set" in result:
        rows = [("trials on the Pareto front", str(len(result["pareto_set"])))]
        for entry in result["pareto_set"]:
            values = []
            for o in result["objectives"]:
                again = (entry.get("reevaluated") or {}).get(o["name"])
                own = dict(entry["objectives"][o["name"]], runs=entry["replicas"])
                text = f"{shown(o['name'])} = {value_text(own, o.get('unit'))}"
                if again:
                    text += f" (re-evaluated: {value_text(again, o.get('unit'))})"
                values.append(text)
            text = f"{_parameters(entry['params'])}: {', '.join(values)}"
            bounds = [_bound_text(f) for f in entry.get("at_bounds", [])]
            rows.append((f"trial {entry['trial']}", "; ".join([text, *bounds])))
        return rows
    entry = result.get("best")
    if entry is None:
        return [("best trial", "none (no complete trial meets the constraints yet)")]
    chosen = (
        "the best mean over its re-evaluation runs"
        if result["chosen_on"] == "re-evaluation"
        else "the best of the search's trials on their own means"
    )
    rows = [("best trial", f"{entry['trial']} ({chosen})")]
    rows += [(parameter_label(k), _parameter(k, v)) for k, v in entry["params"].items()]
    rows += _objective_rows(result, entry)
    rows.append(_noise_row(result))
    again = entry.get("reevaluated_constraints") or {}
    for text, c in entry["constraints"].items():
        basis = again.get(text) or dict(c, runs=entry["replicas"])
        where = "re-evaluated" if text in again else "in the search"
        rows.append(
            (
                f"constraint `{text}` ({where})",
                f"{value_text(basis, None)} ({'met' if basis['met'] else 'not met'})",
            )
        )
    if entry.get("at_bounds"):
        rows.append(("at a search bound", "; ".join(_bound_text(f) for f in entry["at_bounds"])))
    return rows
