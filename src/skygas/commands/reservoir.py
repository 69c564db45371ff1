"""``skygas reservoir [CONFIG.toml] --out DIR [--json] [--sweep]``: the Brownian reservoir
(docs/reservoir.md): all 16 Boolean functions of two inputs and the temporal tasks from one
confined chamber, with occupation maps and a report; ``--sweep`` adds the accuracy against the
configuration's swept parameter, with replicas (resumable: finished points are kept)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

from skygas.core.errors import InputError

# command-line option → top-level or nested configuration field it overrides
#: command-line option -> the configuration's field (a dotted key)
OVERRIDES = {
    "seed": "seed",
    "hold_time": "hold_time",
    "temperature": "temperature",
    "n_skyrmions": "n_skyrmions",
    "current_density": "drive.current_density",
    "n_inputs": "study.n_inputs",
    "workers": "study.workers",
}
SUMMARY = "reservoir.json"


def _format(s: dict, out: Path) -> str:
    xor = s["xor"]
    t = s["temporal"]
    lines = [
        f"Brownian reservoir: {s['n_skyrmions']} skyrmion(s), T = {s['temperature_K']:g} K, "
        f"hold {s['hold_time_s'] * 1e6:.3g} µs, {s['n_inputs']} inputs "
        f"({s['wall_seconds']:.1f} s, {s['cpu_seconds']:.1f} s CPU in {s['streams']} streams)",
        f"  XOR: {100 * xor['accuracy']:.1f} % on {xor['n_test']} test inputs "
        f"(chance {100 * xor['chance']:.0f} %, {xor['margin_standard_errors']:.1f} standard "
        f"errors above)",
        "  " + ", ".join(f"{n} {100 * a:.0f} %" for n, a in s["accuracy"].items()),
        f"  mean of the 16 functions {100 * s['mean_accuracy']:.1f} %; energy per operation "
        f"{s['energy_per_operation_J']:.3g} J",
    ]
    if t:
        lines.append(
            "  recall of input a, k back: "
            + ", ".join(f"k={k} {100 * r['accuracy']:.0f} %" for k, r in t["recall"].items())
            + f"; parity of the last two {100 * t['parity_last_two']['accuracy']:.0f} %"
        )
    lines.append(f"results in {out.resolve()}")
    return "\n".join(lines)


def _margin(r: dict) -> str:
    m = r["margin_standard_errors"]
    return "n/a" if m is None else f"{m:.1f}"


def _report(s: dict, sweep: dict | None) -> str:
    """The study as a Markdown report (report.md)."""
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


def _reservoir(args) -> int:
    # imported here: building the command line (every skygas call) imports no numerics
    from skygas.reservoir.config import reservoir_config
    from skygas.reservoir.device import ReservoirDevice
    from skygas.reservoir.figures import plot_accuracies, plot_occupation, plot_sweep
    from skygas.reservoir.study import accuracy_sweep, run_study
    from skygas.runs.run_driver import write_atomic, write_json

    data = {}
    if args.config is not None:
        from skygas.core.config_types import read_toml

        data = read_toml(args.config)
    config = reservoir_config(data, **{key: getattr(args, opt) for opt, key in OVERRIDES.items()})
    out = Path(args.out)
    if (out / SUMMARY).exists() and not args.sweep:
        raise InputError(
            "out",
            str(out),
            f"a folder without a finished study ({SUMMARY} "
            "exists there; choose another folder or delete it)",
        )
    device = ReservoirDevice(config)  # validates everything before any run
    out.mkdir(parents=True, exist_ok=True)
    talk = not args.json
    if (out / SUMMARY).exists():
        summary = json.loads((out / SUMMARY).read_text())
    else:
        if talk:
            print(
                f"running {config.study.n_inputs} inputs of {config.hold_time * 1e6:g} µs in "
                f"{config.study.workers} stream(s)...",
                file=sys.stderr,
            )
        summary, streams = run_study(config, device)
        plot_occupation(device, streams, out / "occupation.png")
        plot_accuracies(summary, out / "accuracy.png")
        write_json(out / SUMMARY, summary, indent=1)
    sweep = None
    if args.sweep:
        sweep = accuracy_sweep(
            config,
            checkpoint=out / "sweep-points.jsonl",
            progress=(
                lambda v, r: print(
                    f"  {config.sweep.parameter} = {v:g}, replica {r + 1} done", file=sys.stderr
                )
            )
            if talk
            else None,
        )
        write_json(out / "sweep.json", sweep, indent=1)
        plot_sweep(sweep, out / "sweep.png")
        summary["sweep"] = sweep
    report = _report(summary, sweep)
    write_atomic(out / "report.md", lambda tmp: tmp.write_text(report))
    if not args.no_report:
        from skygas.outputs.report import write_report

        write_report(out, out / "report.html")
    print(json.dumps(summary) if args.json else _format(summary, out))
    return 0


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "reservoir",
        help="Brownian reservoir computing: Boolean functions and temporal tasks from one chamber",
    )
    p.add_argument("config", nargs="?", default=None, help="TOML configuration")
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument(
        "--no-report",
        action="store_true",
        help="do not write report.html (a self-contained page of the results)",
    )
    p.add_argument(
        "--sweep", action="store_true", help="also run the configuration's [sweep] (resumable)"
    )
    p.add_argument("--seed", type=int, help="random seed")
    p.add_argument("--hold-time", type=float, help="time each input is held [s]")
    p.add_argument("--temperature", type=float, help="temperature [K]")
    p.add_argument("--n-skyrmions", type=int, help="number of skyrmions")
    p.add_argument(
        "--current-density", type=float, help="chamber-mean |j| of the unit input pattern [A/m²]"
    )
    p.add_argument("--n-inputs", type=int, help="held inputs in the study")
    p.add_argument("--workers", type=int, help="parallel streams")
    p.set_defaults(func=_reservoir)
