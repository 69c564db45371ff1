"""The reservoir study's Markdown report (``report.md``).

The parameters, the test accuracy of the 16 Boolean functions and of the temporal tasks, and
the sweep's table when there is one.
"""

from __future__ import annotations


def _margin(r: dict) -> str:
    m = r["margin_standard_errors"]
    return "n/a" if m is None else f"{m:.1f}"


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
    d = s["device"]
    c = d["config"]
    material = c["material"] if isinstance(c["material"], str) else "a custom material"
    lines = [
        "# Brownian reservoir",
        "",
        f"skygas {d['skygas_version']}, seed {d['seed']}: {s['n_skyrmions']} skyrmion(s) of "
        f"{material} at {s['temperature_K']:g} K in a {c['chamber']['shape']} chamber of size "
        f"{c['chamber']['size'] * 1e9:.0f} nm; each input held {s['hold_time_s'] * 1e6:.3g} µs; "
        f"time step {d['time_step_s']:.3g} s; free diffusion "
        f"{d['diffusion_constant_m2_per_s'] * 1e9:.3g} nm²/ns.",
        "",
        f"Drive: V₀ = {d['drive']['unit_voltage_V']:.3g} V; energy per operation "
        f"{s['energy_per_operation_J']:.3g} J. {s['n_inputs']} inputs in {s['streams']} "
        f"streams, {s['wall_seconds']:.1f} s ({s['cpu_seconds']:.1f} s CPU).",
        "",
        "## Boolean functions (test accuracy)",
        "",
        "| function | truth table | accuracy | chance | margin (standard errors) |",
        "|---|---|---|---|---|",
        *(
            f"| {n} | {r['truth_table']} | {100 * r['accuracy']:.1f} % | "
            f"{100 * r['chance']:.0f} % | {_margin(r)} |"
            for n, r in s["boolean"].items()
        ),
        "",
        "## Temporal tasks",
        "",
    ]
    t = s["temporal"]
    if t:
        lines.append(
            f"Inputs held {s['temporal_hold_time_s'] * 1e9:.3g} ns; the state at "
            "step n is read out.\n"
        )
        lines += [
            f"- recall of input a, {k} inputs back: {100 * r['accuracy']:.1f} % "
            f"(chance {100 * r['chance']:.0f} %, margin {_margin(r)})"
            for k, r in t["recall"].items()
        ]
        p = t["parity_last_two"]
        lines.append(
            f"- parity of the last two inputs: {100 * p['accuracy']:.1f} % "
            f"(chance {100 * p['chance']:.0f} %, margin {_margin(p)})"
        )
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
            "| value | XOR | std | mean of 16 |",
            "|---|---|---|---|",
            *(
                f"| {r['value']:g} | {100 * r['xor_mean']:.1f} % | "
                f"{100 * r['xor_std']:.1f} % | {100 * r['mean_accuracy_mean']:.1f} % |"
                for r in sweep["rows"]
            ),
            "",
            "Figure: `sweep.png`.",
        ]
    return "\n".join(lines) + "\n"
