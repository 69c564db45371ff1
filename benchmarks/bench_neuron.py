"""Per-step cost of a neuron run: the default configuration and the earlier, busier one.

Times ``NeuronRun.run()`` (the time loop: engine steps, the annihilation check every 0.25 ns,
the sensor and rule every 1 ns, injections), not the device build (current solve) or the
analyses. Each workload runs ``--repeats`` times with seeds 1, 2, ... after one warm-up run that
compiles; the figure is the median over the repeats of wall time / time steps.

Workloads:
- ``default``: ``skygas neuron`` without a config (3 µs, 12 000 steps of 0.25 ns).
- ``busy``: the defaults before the operating point was chosen (constant J = 1e11 A/m², Poisson
  input 1e8 Hz, threshold 20, release time 50 ns): ~20-30 skyrmions in the chamber.

Run: ``.venv/bin/python benchmarks/bench_neuron.py [--repeats 5] [--workload default busy]``.
"""

from __future__ import annotations

import argparse
import statistics
import time

from skygas.neuron import NeuronDevice, neuron_config
from skygas.neuron.config import NeuronConfig

BUSY = {
    "current_density": 1e11,
    "inputs": [{"kind": "poisson", "rate": 1e8}],
    "rule": {"threshold": 20, "reset_level": 3, "release_time": 5e-8},
}


def workload(name: str) -> dict:
    if name == "default":
        return {}
    data = dict(BUSY)
    if "release_current_density" in NeuronConfig.model_fields:  # a constant current
        data["release_current_density"] = None
    return data


def one_run(data: dict, seed: int) -> dict:
    run = NeuronDevice(neuron_config(data, seed=seed)).build()
    start = time.perf_counter()
    run.run()
    wall = time.perf_counter() - start
    return {
        "per_step_us": wall / run.sim.step * 1e6,
        "steps": run.sim.step,
        "mean_count": float(run.trace()["count"].mean()),
        "spikes": len(run.spike_times()),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument(
        "--workload", nargs="+", default=["default", "busy"], choices=["default", "busy"]
    )
    args = parser.parse_args()
    for name in args.workload:
        data = workload(name)
        one_run({**data, "duration": 2e-8}, seed=0)  # compile outside the timing
        runs = [one_run(data, seed) for seed in range(1, args.repeats + 1)]
        per_step = [r["per_step_us"] for r in runs]
        print(
            f"{name}: {statistics.median(per_step):.1f} µs per step (median of {len(runs)}: "
            f"{', '.join(f'{v:.1f}' for v in per_step)}); {runs[0]['steps']} steps, "
            f"mean count {statistics.mean(r['mean_count'] for r in runs):.1f}, "
            f"spikes {[r['spikes'] for r in runs]}"
        )


if __name__ == "__main__":
    main()
