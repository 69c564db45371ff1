"""The reservoir study's tables, and its Markdown report (``report.md``).

The parameters, the test accuracy of the 16 Boolean functions and of the temporal tasks, and
the sweep's table when there is one. The tables (:func:`boolean_table`, :func:`temporal_table`,
:func:`sweep_table`) are rows of text cells, shared by ``report.md`` and ``report.html``
(:mod:`skygas.outputs.report`).
"""

from __future__ import annotations

from skygas.core.quantities import format_value, quantity

Table = tuple[list[str], list[list[str]]]


def _percent(value, error=None) -> str:
    return format_value(value, error, kind="percent", digits=3) or "n/a"


def accuracy_text(r: dict) -> str:
    """A test accuracy with its 68 % Wilson interval over the test inputs.

    E.g. "98.3 % (97.6–98.8 %)". The interval is the accuracy's own uncertainty
    (:func:`~skygas.reservoir.readout.accuracy_interval`), which stays inside [0, 100 %];
    the standard error at chance is a property of the chance level, not of the accuracy.
    """
    from skygas.reservoir.readout import accuracy_interval

    lo, hi = (float(v) for v in accuracy_interval(r["accuracy"], r["n_test"]))
    return (
        f"{format_value(r['accuracy'], kind='percent', digits=3)} ({100 * lo:.1f}–{100 * hi:.1f} %)"
    )


def _margin(r: dict) -> str:
    m = r["margin_standard_errors"]
    return "n/a (chance is 100 %)" if m is None else f"{m:.1f}"


def describe(summary: dict) -> list[str]:
    """Two sentences on the device and the run: material, chamber, hold time, drive, costs."""
    s = summary
    d = s["device"]
    c = d["config"]
    material = c["material"] if isinstance(c["material"], str) else "a custom material"
    return [
        f"skygas {d['skygas_version']}, seed {d['seed']}: {s['n_skyrmions']} skyrmion(s) of "
        f"{material} at {s['temperature_K']:g} K in a {c['chamber']['shape']} chamber of size "
        f"{c['chamber']['size'] * 1e9:.0f} nm; each input held "
        f"{format_value(s['hold_time_s'], unit='s', digits=3)}; time step "
        f"{format_value(d['time_step_s'], unit='s', digits=3)}; free diffusion "
        f"{d['diffusion_constant_m2_per_s'] * 1e9:.3g} nm²/ns.",
        f"Drive: V₀ = {format_value(d['drive']['unit_voltage_V'], unit='V', digits=3)}; "
        f"energy per operation {format_value(s['energy_per_operation_J'], unit='J', digits=3)}. "
        f"{s['n_inputs']} inputs in {s['streams']} stream(s), {s['wall_seconds']:.1f} s "
        f"({s['cpu_seconds']:.1f} s CPU).",
    ]


def boolean_table(summary: dict) -> Table:
    """The 16 functions: name, truth table, accuracy (68 % interval), chance, margin."""
    header = [
        "function",
        "truth table",
        "test accuracy (68 % interval)",
        "chance",
        "margin (standard errors at chance)",
    ]
    rows = [
        [
            name,
            str(r["truth_table"]),
            accuracy_text(r),
            _percent(r["chance"]),
            _margin(r),
        ]
        for name, r in summary["boolean"].items()
    ]
    return header, rows


def temporal_table(summary: dict) -> Table:
    """The temporal tasks (recall k inputs back, parity): accuracy, chance, margin."""
    header = [
        "task",
        "test accuracy (68 % interval)",
        "chance",
        "margin (standard errors at chance)",
    ]
    t = summary["temporal"]
    rows = []
    if t:
        tasks = [(f"recall of input a, {k} input(s) back", r) for k, r in t["recall"].items()]
        tasks.append(("parity of the last two inputs", t["parity_last_two"]))
        rows = [
            [
                name,
                accuracy_text(r),
                _percent(r["chance"]),
                _margin(r),
            ]
            for name, r in tasks
        ]
    return header, rows


def sweep_table(sweep: dict) -> Table:
    """Accuracy against the swept parameter: XOR (mean and spread of the replicas), mean of 16."""
    swept = quantity(sweep["parameter"])
    header = [
        swept.label,
        "XOR accuracy (mean)",
        "XOR spread (std of replicas)",
        "mean of the 16 functions",
    ]
    rows = [
        [
            format_value(r["value"], unit=swept.unit, kind=swept.kind) or "n/a",
            _percent(r["xor_mean"]),
            _percent(r["xor_std"]),
            _percent(r["mean_accuracy_mean"]),
        ]
        for r in sweep["rows"]
    ]
    return header, rows


def _markdown(table: Table) -> list[str]:
    header, rows = table
    return [
        "| " + " | ".join(header) + " |",
        "|" + "---|" * len(header),
        *("| " + " | ".join(row) + " |" for row in rows),
    ]


def markdown_report(summary: dict, sweep: dict | None = None) -> str:
    """The study as a Markdown report (``report.md``).

    Parameters
    ----------
    summary
        The study's summary (:func:`~skygas.reservoir.study.study_summary`).
    sweep
        The sweep's record (:func:`~skygas.reservoir.study.sweep_record`), if one was run.

    Returns
    -------
    str
        The report's text: parameters, the 16 functions, the temporal tasks, the sweep.
    """
    s = summary
    first, second = describe(s)
    lines = [
        "# Brownian reservoir",
        "",
        first,
        "",
        second,
        "",
        "## Boolean functions (test accuracy)",
        "",
        *_markdown(boolean_table(s)),
        "",
        "## Temporal tasks",
        "",
    ]
    if s["temporal"]:
        lines += [
            f"Inputs held {s['temporal_hold_time_s'] * 1e9:.3g} ns; the state at step n is read "
            "out.",
            "",
            *_markdown(temporal_table(s)),
        ]
    else:
        lines.append("No temporal stream (study.temporal_inputs = 0).")
    lines += [
        "",
        "Figures: `occupation.png` (where the skyrmion is while each input is "
        "held), `accuracy.png` (the 16 functions and the temporal tasks).",
    ]
    if sweep:
        lines += [
            "",
            f"## Accuracy against {sweep['parameter']}",
            "",
            f"{sweep['replicas']} replicas of {sweep['n_inputs']} inputs.",
            "",
            *_markdown(sweep_table(sweep)),
            "",
            "Figure: `sweep.png`.",
        ]
    return "\n".join(lines) + "\n"
