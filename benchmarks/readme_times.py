"""The times the README states, measured: each command of the README's tour, run as a user runs it.

Every command runs in a scratch folder, once to warm up (the compiled kernels and the set-up cache
are built then, if they were not) and then ``--rounds`` times; the table gives the median wall
time of the warm runs and the CPU time (user + system of the command's processes, all cores). Run
it on a quiet machine: other work on the cores slows every figure.

    python benchmarks/readme_times.py [--rounds 3] [--only neuron,saturation]

It prints a Markdown table, ready for the README, and the load average before and after.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: (name, what the README calls it, argv after ``skygas``); ``{out}`` is a fresh folder,
#: ``{root}`` the repository.
COMMANDS: tuple[tuple[str, str, list[str]], ...] = (
    ("demo", "`make demo` (the reshuffler, 100 µs)", ["demo", "--out", "{out}", "--quiet"]),
    (
        "reshuffle",
        "reshuffler, paper preset, 40 µs",
        [
            "reshuffle",
            "--out",
            "{out}",
            "--preset",
            "paper",
            "--current-density",
            "3.8e11",
            "--duration",
            "4e-5",
            "--quiet",
        ],
    ),
    (
        "reshuffle-800nm",
        "reshuffler, 800 nm chambers",
        ["reshuffle", "--out", "{out}", "--p", "0.3", "--chamber-diameter", "800e-9", "--quiet"],
    ),
    ("neuron", "the neuron", ["neuron", "--out", "{out}", "--quiet"]),
    (
        "saturation",
        "saturation of two chambers",
        ["saturation", "--diameters", "512e-9", "1024e-9", "--out", "{out}", "--quiet"],
    ),
    ("reservoir", "reservoir computing", ["reservoir", "--out", "{out}", "--quiet"]),
    (
        "simulate",
        "closed chamber, 45 skyrmions, 200 ns",
        ["simulate", "{root}/examples/closed-chamber.toml", "--out", "{out}", "--quiet"],
    ),
    (
        "check-timestep",
        "time-step check",
        ["check-timestep", "{root}/examples/closed-chamber.toml"],
    ),
    ("sc-demo", "stochastic computing demo", ["sc", "demo", "--out", "{out}"]),
    (
        "sweep",
        "sweep of 60 runs of 10 µs, 2 workers",
        [
            "sweep",
            "{root}/examples/sweeps/quick-current.toml",
            "--out",
            "{out}.zarr",
            "--workers",
            "2",
            "--quiet",
        ],
    ),
)


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _run(argv: list[str], scratch: Path) -> tuple[float, float]:
    """Wall and CPU seconds of one run of ``skygas argv`` in a fresh folder under ``scratch``."""
    out = scratch / "out"
    shutil.rmtree(out, ignore_errors=True)
    shutil.rmtree(scratch / "out.zarr", ignore_errors=True)
    args = [a.format(out=out, root=ROOT) for a in argv]
    cpu = _children_cpu()
    start = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-m", "skygas.cli", *args], capture_output=True, text=True, check=False
    )
    wall = time.perf_counter() - start
    if done.returncode != 0:
        raise SystemExit(f"skygas {' '.join(args)} failed ({done.returncode}): {done.stderr}")
    return wall, _children_cpu() - cpu


def main() -> None:
    """Measure and print the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3, help="warm runs per command")
    parser.add_argument("--only", default="", help="comma-separated names of commands to time")
    args = parser.parse_args()
    only = {name for name in args.only.split(",") if name}
    print(f"load average before: {os.getloadavg()[0]:.2f}", file=sys.stderr)
    rows = []
    for name, label, argv in COMMANDS:
        if only and name not in only:
            continue
        with tempfile.TemporaryDirectory() as scratch:
            _run(argv, Path(scratch))
            timings = [_run(argv, Path(scratch)) for _ in range(args.rounds)]
        wall = statistics.median(t[0] for t in timings)
        cpu = statistics.median(t[1] for t in timings)
        rows.append((name, label, wall, cpu))
        print(f"{name}: {wall:.1f} s, CPU {cpu:.1f} s", file=sys.stderr)
    print(f"load average after: {os.getloadavg()[0]:.2f}", file=sys.stderr)
    print("| command | what | wall time (median) | CPU time |")
    print("|---|---|---|---|")
    for name, label, wall, cpu in rows:
        print(f"| {name} | {label} | {wall:.1f} s | {cpu:.0f} s |")


if __name__ == "__main__":
    main()
