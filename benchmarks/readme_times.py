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

#: (name, what it runs, argv after ``skygas``): ``{out}`` is the command's own folder (removed
#: before each run), ``{work}`` the scratch folder of this whole measurement (later commands read
#: what earlier ones wrote there), ``{root}`` the repository.
COMMANDS: tuple[tuple[str, str, list[str]], ...] = (
    ("demo", "`make demo`: the reshuffler, 100 µs", ["demo", "--out", "{out}", "--quiet"]),
    (
        "reshuffle-paper",
        "the reshuffler, paper preset, 40 µs",
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
        "the reshuffler, 800 nm chambers",
        ["reshuffle", "--out", "{out}", "--json", "--p", "0.3", "--chamber-diameter", "800e-9"],
    ),
    (
        "sweep",
        "a sweep of 60 runs of 10 µs, 2 workers",
        [
            "sweep",
            "{root}/examples/sweeps/quick-current.toml",
            "--out",
            "{work}/sweep.zarr",
            "--workers",
            "2",
            "--quiet",
        ],
    ),
    (
        "plot",
        "the sweep's figures and fits",
        ["plot", "{work}/sweep.zarr", "--out", "{out}"],
    ),
    ("neuron", "the neuron", ["neuron", "--out", "{out}", "--json"]),
    (
        "saturation",
        "saturation of two chambers",
        ["saturation", "--diameters", "512e-9", "1024e-9", "--out", "{out}", "--quiet"],
    ),
    ("reservoir", "reservoir computing", ["reservoir", "--out", "{out}", "--json"]),
    (
        "simulate",
        "a closed chamber, 45 skyrmions, 200 ns",
        ["simulate", "{root}/examples/closed-chamber.toml", "--out", "{out}", "--quiet"],
    ),
    (
        "check-timestep",
        "the time-step check of that chamber",
        ["check-timestep", "{root}/examples/closed-chamber.toml"],
    ),
    ("sc-demo", "the stochastic-computing demo", ["sc", "demo", "--out", "{out}"]),
    (
        "sc-demo-reshuffler",
        "the same with the reshuffler as a decorrelator",
        ["sc", "demo", "--reshuffler", "--out", "{out}"],
    ),
    (
        "track",
        "tracking the shipped movie (400 frames)",
        ["track", "{root}/examples/tracking/chamber-movie.tif", "--out", "{work}/track", "--quiet"],
    ),
    (
        "infer",
        "inference from those tracks",
        [
            "infer",
            "{work}/track/tracks.csv",
            "--pixel-size",
            "14e-9",
            "--frame-interval",
            "2e-9",
            "--outline",
            "{root}/examples/tracking/chamber-movie-outline.csv",
            "--temperature",
            "300",
            "--out",
            "{out}",
        ],
    ),
    (
        "optimize",
        "a design search of 40 trials, 2 workers",
        [
            "optimize",
            "{root}/examples/optimize/reshuffler-rate.toml",
            "--out",
            "{out}",
            "--workers",
            "2",
            "--trials",
            "40",
        ],
    ),
    ("calibrate", "micromagnetics to a model, film S6", ["calibrate", "S6", "--out", "{out}"]),
)


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _run(name: str, argv: list[str], work: Path) -> tuple[float, float]:
    """Wall and CPU seconds of one run of ``skygas argv`` (its folder made afresh)."""
    out = work / name
    shutil.rmtree(out, ignore_errors=True)
    if "--out" in argv:  # a folder a later command reads is made afresh too
        shutil.rmtree(argv[argv.index("--out") + 1].format(out=out, work=work), ignore_errors=True)
    args = [a.format(out=out, work=work, root=ROOT) for a in argv]
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
    parser.add_argument(
        "--warmup", type=int, default=1, help="runs before the timed ones (default 1)"
    )
    parser.add_argument("--only", default="", help="comma-separated names of commands to time")
    parser.add_argument(
        "--skip",
        default="calibrate",
        help="comma-separated names to leave out (default: calibrate)",
    )
    args = parser.parse_args()
    only = {name for name in args.only.split(",") if name}
    skip = {name for name in args.skip.split(",") if name} - only
    print(f"load average before: {os.getloadavg()[0]:.2f}", file=sys.stderr)
    rows = []
    work = Path(tempfile.mkdtemp(prefix="skygas-times-"))
    for name, label, argv in COMMANDS:
        if (only and name not in only) or name in skip:
            continue
        for _ in range(args.warmup):
            _run(name, argv, work)
        timings = [_run(name, argv, work) for _ in range(args.rounds)]
        wall = statistics.median(t[0] for t in timings)
        cpu = statistics.median(t[1] for t in timings)
        rows.append((name, label, wall, cpu))
        print(f"{name}: {wall:.1f} s, CPU {cpu:.1f} s", file=sys.stderr)
    shutil.rmtree(work, ignore_errors=True)
    print(f"load average after: {os.getloadavg()[0]:.2f}", file=sys.stderr)
    print("| what | command | wall time (median) | CPU time |")
    print("|---|---|---|---|")
    for name, label, wall, cpu in rows:
        argv = next(a for n, _, a in COMMANDS if n == name)
        shown = " ".join(a.replace("{root}/", "").replace("{work}", "out") for a in argv)
        shown = shown.replace("{out}", f"out/{name}")
        print(f"| {label} | `skygas {shown}` | {wall:.1f} s | {cpu:.0f} s |")


if __name__ == "__main__":
    main()
