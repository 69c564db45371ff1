"""How well the estimate a command announces matches the time its run takes.

For each case (the shipped examples, the reshuffler with every material preset, and a
calibrated model when one is given), the command is built as for a run and stopped at its
exact estimate (:func:`skygas.core.estimates.estimate_only`), its kernels are compiled by a
short run, then it runs for real. The script prints, per case, the estimate, the measured
wall time of the stepping (the summary's ``wall_time_s``) and their ratio, against the step
rate of the 45-skyrmion gas measured here first (:mod:`skygas.runs.machine_speed`).
``--record FILE`` writes them as JSON. Measure on a quiet machine: another process on the same
cores changes the gas's rate and the runs' differently.

Run: ``.venv/bin/python benchmarks/estimates.py --nominal --record FILE``
(the record that the tests read is benchmarks/estimates-recorded.json)
(each case over its whole nominal duration; ``--quick``/``--steps N`` cap the steps instead, which
misleads where the step is short: S6's 3e5 steps are 10 ns). tests/runs/test_estimates_recorded.py
reads the record.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import platform
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"
PRESETS = ["S1", "S2", "S3", "S4", "S5", "S6", "S7"]


def cases(model: str | None) -> dict[str, tuple[list[str], float]]:
    """Name → (the command line without --out and --duration, a nominal duration [s])."""
    c = {
        "simulate closed chamber": (["simulate", str(EX / "closed-chamber.toml")], 200e-6),
        "reshuffle default (demo)": (["reshuffle"], 100e-6),
        "neuron example": (["neuron", str(EX / "neuron.toml")], 3e-6),
    }
    for name in PRESETS:
        # long enough for the chambers' gas to settle (S6 and S7 take steps of 0.04–0.1 ps)
        nominal = 1e-6 if name in ("S6", "S7") else 20e-6
        c[f"reshuffle {name}"] = (["reshuffle", "--material", name], nominal)
    if model:
        c[f"reshuffle {Path(model).parent.name}"] = (["reshuffle", "--material", model], 20e-6)
    return c


def estimate(args: list[str], out: Path):
    """The command's exact estimate and the seconds it took to reach it."""
    from skygas import cli
    from skygas.core.estimates import EstimateOnly, estimate_only

    started = time.perf_counter()
    with estimate_only(), contextlib.redirect_stderr(io.StringIO()):
        try:
            cli.main([*args, "--out", str(out), "--quiet", "--overwrite", "--force"])
        except EstimateOnly as stop:
            return stop.estimate, time.perf_counter() - started
    raise RuntimeError(f"{args}: no estimate was checked")


def measure(args: list[str], out: Path) -> float:
    """Wall seconds of the command's run, run for real: its summary's ``wall_time_s`` (the
    stepping, without set-up and results) plus its transfer curve's (the neuron's other runs,
    which its estimate prices too), or the whole command's time where it has none."""
    from skygas import cli

    started = time.perf_counter()
    with contextlib.redirect_stdout(io.StringIO()):
        status = cli.main(
            [*args, "--out", str(out), "--quiet", "--overwrite", "--no-report", "--force"]
        )
    if status:
        raise RuntimeError(f"{args}: exit status {status}")
    total = time.perf_counter() - started
    summary = json.loads((out / "summary.json").read_text())
    return float(summary.get("wall_time_s", total)) + float(summary.get("transfer_wall_time_s", 0))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="runs of 5e4 steps, not 2e5")
    parser.add_argument("--steps", type=float, help="steps of each measured run (not --quick's)")
    parser.add_argument(
        "--nominal", action="store_true", help="run each case for its whole nominal duration"
    )
    parser.add_argument("--record", help="write the cases, estimates and times as JSON")
    parser.add_argument("--model", help="a calibrated model.toml to include")
    parser.add_argument("--only", help="run only the cases whose name holds this text")
    opts = parser.parse_args()

    from skygas.runs import machine_speed

    rate = machine_speed._calibrate()  # this machine, now; not the cached figure
    os.environ["SKYGAS_STEP_SECONDS"] = repr(rate)
    print(f"45-skyrmion gas: {rate * 1e6:.2f} µs per step on {platform.node()}")
    print(f"{'case':34s} {'steps':>9s} {'estimate':>9s} {'measured':>9s} {'ratio':>6s}")
    rows = []
    target = opts.steps or (5e4 if opts.quick else 2e5)  # steps of each measured run
    with tempfile.TemporaryDirectory() as tmp:
        for i, (name, (args, nominal)) in enumerate(cases(opts.model).items()):
            if opts.only and opts.only not in name:
                continue
            out = Path(tmp) / f"run{i}"
            est, _ = estimate([*args, "--duration", f"{nominal:g}"], out)
            dt = nominal / est.steps
            # the kernels this device uses, compiled (or loaded) before anything is timed; a
            # short case runs whole, since a short run may not reach every code path (the
            # neuron's gate opens only after its threshold is reached)
            warm = nominal if est.seconds < 30 else max(200 * dt, nominal / 100)
            measure([*args, "--duration", f"{warm:.6g}"], out)
            duration = f"{nominal if opts.nominal else min(nominal, target * dt):.6g}"
            est, setup = estimate([*args, "--duration", duration], out)
            run = measure([*args, "--duration", duration], out)
            rows.append(
                {"case": name, "args": [*args, "--duration", duration], "steps": est.steps,
                 "estimate_s": est.seconds, "run_s": run, "setup_s": setup}
            )  # fmt: skip
            print(
                f"{name:34s} {est.steps:9.3g} {est.seconds:8.3g}s {run:8.3g}s "
                f"{est.seconds / run:6.2f}",
                flush=True,
            )
    if opts.record:
        Path(opts.record).write_text(
            json.dumps({"step_seconds": rate, "machine": platform.node(), "cases": rows}, indent=1)
            + "\n"
        )


if __name__ == "__main__":
    main()
