"""The reservoir study's tables in its report (``report.html``, :mod:`skygas.outputs.report`).

The parameters (:func:`describe`), the test accuracy of the 16 Boolean functions
(:func:`boolean_table`) and of the temporal tasks (:func:`temporal_table`), as rows of text
cells.
"""

from __future__ import annotations

from skygas.core.quantities import format_value

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
