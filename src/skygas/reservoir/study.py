"""Studies of the reservoir: the default Boolean + temporal study, and accuracy against one
parameter with replicas.

:func:`run_study` runs the input streams (:func:`~skygas.reservoir.device.run_streams`), trains
and scores the 16 Boolean read-outs and the temporal tasks, and returns one JSON-able record
with every parameter, the seed and the version. :func:`accuracy_sweep` repeats a smaller study
for each value of a parameter (hold time, temperature, number of skyrmions, pinning depth,
current density) and each replica seed.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path
from typing import cast

import numpy as np

from skygas._version import __version__
from skygas.reservoir.config import ReservoirConfig
from skygas.reservoir.device import ReservoirDevice, StreamResult, run_streams
from skygas.reservoir.readout import split
from skygas.reservoir.tasks import boolean_study, temporal_study


def _readout(config: ReservoirConfig) -> dict:
    return {"model": config.readout.model, "regularization": config.readout.regularization}


def score_streams(
    config: ReservoirConfig, streams: list[StreamResult], temporal: list[StreamResult]
) -> dict:
    """Boolean scores of the states of ``streams``, temporal scores of ``temporal``."""
    features = np.concatenate([s.features for s in streams])
    bits = np.concatenate([s.bits for s in streams])
    train, test = split(len(features), config.readout.test_fraction, config.seed)
    return {
        "boolean": boolean_study(features, bits, train, test, **_readout(config)),
        "temporal": temporal_study(
            temporal,
            config.study.delays,
            config.readout.test_fraction,
            config.seed,
            **_readout(config),
        )
        if temporal
        else None,
    }


def run_study(
    config: ReservoirConfig,
    device: ReservoirDevice | None = None,
    n_inputs: int | None = None,
    temporal_tasks: bool = True,
) -> tuple[dict, list[StreamResult]]:
    """The study of ``config`` (``temporal_tasks=False`` skips the temporal stream): (summary
    record, the Boolean streams)."""
    device = device or ReservoirDevice(config)
    started = time.perf_counter()
    streams, temporal = run_streams(
        config, n_inputs=n_inputs, n_temporal=None if temporal_tasks else 0
    )
    scores = score_streams(config, streams, temporal)
    wall = time.perf_counter() - started
    boolean = scores["boolean"]
    summary = {
        "task": "boolean-2-input",
        "accuracy": {name: r["accuracy"] for name, r in boolean.items()},
        "xor": boolean["XOR"],
        "mean_accuracy": float(np.mean([r["accuracy"] for r in boolean.values()])),
        "hold_time_s": config.hold_time,
        "temperature_K": config.temperature,
        "n_skyrmions": config.n_skyrmions,
        "energy_per_operation_J": device.drive.record(config.hold_time)["energy_per_operation_J"],
        "boolean": boolean,
        # mean sensor signal (covered fraction) while each input is held
        "sensor_means": {
            "".join(map(str, sym)): dict(zip(device.sensor_names, map(float, m), strict=True))
            for sym, m in zip(
                device.drive.symbols,
                # a sum of arrays (typeshed allows sum's start value 0 for an empty iterable)
                cast(np.ndarray, sum(s.sensor_means for s in streams)) / len(streams),
                strict=True,
            )
        },
        "temporal": scores["temporal"],
        "n_inputs": int(sum(len(s.bits) for s in streams)),
        "streams": len(streams),
        "steps": int(sum(s.steps for s in streams + temporal)),
        "wall_seconds": wall,
        # worker processes' CPU time (this process only waits on them)
        "cpu_seconds": float(sum(s.cpu_seconds for s in streams + temporal)),
        "temporal_hold_time_s": config.study.temporal_hold_time,
        "device": device.describe(),
    }
    return summary, streams


def _with(config: ReservoirConfig, parameter: str, value: float, seed: int) -> ReservoirConfig:
    """``config`` with one swept parameter set (and the replica's seed)."""
    data = config.model_dump()
    data["seed"] = seed
    if parameter == "hold_time":
        data["hold_time"] = float(value)
    elif parameter == "temperature":
        data["temperature"] = float(value)
    elif parameter == "n_skyrmions":
        data["n_skyrmions"] = int(value)
    elif parameter == "current_density":
        data["drive"]["current_density"] = float(value)
    elif parameter == "pinning_depth_kT":
        # random pinning wells one skyrmion radius wide, one per (2 d_sk)² on average
        d = config.thiele_parameters().skyrmion_diameter
        if value > 0:
            data["potentials"] = [
                *data["potentials"],
                {
                    "kind": "random_pinning",
                    "density": 1.0 / (2 * d) ** 2,
                    "sigma": d / 2,
                    "depth_kT": float(value),
                },
            ]
    return ReservoirConfig.model_validate(data)


def accuracy_sweep(config: ReservoirConfig, checkpoint: Path | None = None, progress=None) -> dict:
    """XOR and mean Boolean accuracy against ``config.sweep.parameter`` (mean and standard
    deviation over ``replicas`` seeds).

    Every (value, replica) point is appended to ``checkpoint`` (JSON lines) when it finishes;
    a later call with the same file skips the points already there, so an interrupted sweep
    resumes where it stopped. Every point's configuration is validated before the first runs.
    """
    sw = config.sweep
    plan = [
        (value, r, _with(config, sw.parameter, value, config.seed + 1000 * (r + 1)))
        for value in sw.values
        for r in range(sw.replicas)
    ]
    for _, _, cfg in plan:
        ReservoirDevice(cfg)
    done = {}
    if checkpoint is not None and Path(checkpoint).exists():
        for line in Path(checkpoint).read_text().splitlines():
            try:
                point = json.loads(line)
            except json.JSONDecodeError:
                continue  # a line cut short by a kill while it was written: run that point again
            done[(point["value"], point["replica"])] = point
    for value, r, cfg in plan:
        if (value, r) not in done:
            summary, _ = run_study(cfg, n_inputs=sw.n_inputs, temporal_tasks=False)
            point = {
                "value": value,
                "replica": r,
                "seed": cfg.seed,
                "xor_accuracy": summary["xor"]["accuracy"],
                "mean_accuracy": summary["mean_accuracy"],
            }
            done[(value, r)] = point
            if checkpoint is not None:
                # a whole line per point, flushed to disk before the next point starts; after
                # a line cut short by a kill the next point starts on a line of its own
                with open(checkpoint, "a") as f:
                    f.write("\n" + json.dumps(point) + "\n")
                    f.flush()
                    os.fsync(f.fileno())
        if progress is not None:
            progress(value, r)
    rows = []
    for value in sw.values:
        xor = [done[(value, r)]["xor_accuracy"] for r in range(sw.replicas)]
        mean = [done[(value, r)]["mean_accuracy"] for r in range(sw.replicas)]
        rows.append(
            {
                "value": value,
                "xor_accuracy": xor,
                "mean_accuracy": mean,
                "xor_mean": float(np.mean(xor)),
                "xor_std": float(np.std(xor, ddof=1)) if len(xor) > 1 else 0.0,
                "mean_accuracy_mean": float(np.mean(mean)),
            }
        )
    return {
        "parameter": sw.parameter,
        "replicas": sw.replicas,
        "n_inputs": sw.n_inputs,
        "skygas_version": __version__,
        "seed": config.seed,
        "rows": rows,
    }
