"""Two versions of skygas side by side: the time of the same workloads, alternating.

Each round runs every workload once with each version's source tree (in fresh processes, the
order alternating from round to round), so that the machine's changing clock affects both
alike; the script prints each round's time ratio new/old and the median ratio per workload.

Workloads (same as ``bench_engine.py`` and ``bench_reshuffler.py``): Heun steps of a relaxed gas
of 100 and 1 000 skyrmions (S2, 300 K, suggested step), and a 100 µs run of the ``paper``
reshuffler at J = 1.7×10¹¹ A/m².

Run: ``.venv/bin/python benchmarks/bench_versions.py OLD_SRC NEW_SRC [--rounds 5] [--clock cpu]``,
e.g. with OLD_SRC a ``git worktree`` of the older commit's ``src`` folder. ``--clock cpu`` times
the process's CPU time instead of the wall clock (the workloads run on one thread): on a machine
shared with other jobs it scatters far less from round to round.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys

# Runs in a fresh interpreter with one version's source first on the path: prints seconds.
# The API of both versions is used (skyrmions placed with add_skyrmions).
ENGINE = """
import time, numpy as np
from skygas.engine import Simulation
from skygas import disk
try:  # the nanometre form became private when random_positions took metres
    from skygas.physics.geometry import _random_positions_nm as random_positions
except ImportError:
    try:  # the module moved with the layers-as-folders layout
        from skygas.physics.geometry import random_positions
    except ImportError:
        from skygas.geometry import random_positions
n = {n}
radius_nm = np.sqrt(n / (np.pi * 45 / (np.pi * 512.0**2)))
try:  # sizes became diameters
    outline = disk(diameter=2 * radius_nm * 1e-9)
except TypeError:
    outline = disk(radius_nm * 1e-9)
sim = Simulation(outline, "S2", temperature=300.0, seed=1, grid_spacing=4e-9, capacity=n)
d_sk = sim.thiele.skyrmion_diameter_internal
pts = random_positions(sim.outline, n, 1.2 * d_sk, 0.6 * d_sk, np.random.default_rng(1))
sim.add_skyrmions(pts * 1e-9, validate=False)
sim.run(2000 * sim.time_step)
best = []
for _ in range(5):
    t0 = time.CLOCK(); sim.run({steps} * sim.time_step, chunk_steps={steps})
    best.append((time.CLOCK() - t0) / {steps})
print(sorted(best)[2])
"""

RESHUFFLER = """
import time
from skygas.reshuffler import ReshufflerRun, load_reshuffler_config
def run(duration):
    config = load_reshuffler_config(preset="paper", overrides={
        "duration": duration, "seed": 1, "current_density": 1.7e11,
        "output.trajectory_window": 0.0})
    r = ReshufflerRun.build(config)
    t0 = time.CLOCK(); r.advance(); return time.CLOCK() - t0
run(2e-7)
print(run(1e-4))
"""

WORKLOADS = {
    "engine, 100 skyrmions (s/step)": ENGINE.format(n=100, steps=4000),
    "engine, 1000 skyrmions (s/step)": ENGINE.format(n=1000, steps=600),
    "reshuffler, 100 µs (s)": RESHUFFLER,
}


def timed(src: str, code: str, clock: str = "perf_counter") -> float:
    code = code.replace("time.CLOCK", f"time.{clock}")
    # the version's source first, then whatever the caller's path holds (its dependencies)
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join(p for p in (src, os.environ.get("PYTHONPATH")) if p),
    }
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    if out.returncode:
        sys.exit(f"workload failed with {src}:\n{out.stderr}")
    return float(out.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("old_src")
    parser.add_argument("new_src")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--clock", choices=["wall", "cpu"], default="wall")
    args = parser.parse_args()
    clock = "process_time" if args.clock == "cpu" else "perf_counter"
    for code in WORKLOADS.values():  # compile both versions' kernels into their caches
        timed(args.old_src, code)
        timed(args.new_src, code)
    for name, code in WORKLOADS.items():
        ratios = []
        for r in range(args.rounds):
            order = (args.old_src, args.new_src) if r % 2 == 0 else (args.new_src, args.old_src)
            times = {src: timed(src, code, clock) for src in order}
            ratios.append(times[args.new_src] / times[args.old_src])
            print(
                f"  {name}: old {times[args.old_src]:.4g}, new {times[args.new_src]:.4g}, "
                f"new/old {ratios[-1]:.3f}",
                flush=True,
            )
        print(
            f"{name}: median new/old {statistics.median(ratios):.3f} over {args.rounds} rounds",
            flush=True,
        )


if __name__ == "__main__":
    main()
