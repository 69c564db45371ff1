"""Studies of the reservoir: the Boolean and the temporal study.

:func:`run_study` runs the input streams (:func:`~skygas.reservoir.streams.run_streams`), trains
and scores the 16 Boolean read-outs and the temporal tasks, and returns one JSON-able record
with every parameter, the seed and the version (:func:`study_summary`). Accuracy against a
parameter, with replicas, is a ``skygas sweep`` of ``device = "reservoir"``
(:mod:`skygas.reservoir.study_points`).

These run in memory; ``skygas reservoir`` runs the same streams piece by piece through the run
driver, with checkpoints and resume (:mod:`skygas.reservoir.files`), and gives the same numbers.
"""

from __future__ import annotations

import time
from typing import cast

import numpy as np

from skygas.reservoir.config import ReservoirConfig
from skygas.reservoir.device import ReservoirDevice, StreamResult
from skygas.reservoir.readout import split
from skygas.reservoir.streams import run_streams
from skygas.reservoir.tasks import boolean_study, temporal_study


def _readout(config: ReservoirConfig) -> dict:
    return {"model": config.readout.model, "regularization": config.readout.regularization}


def score_streams(
    config: ReservoirConfig, streams: list[StreamResult], temporal: list[StreamResult]
) -> dict:
    """Boolean scores of the states of ``streams``, temporal scores of ``temporal``.

    Parameters
    ----------
    config
        The configuration (read-out, test fraction, delays, seed of the split).
    streams
        The Boolean streams, concatenated in order.
    temporal
        The temporal streams (none: no temporal scores).

    Returns
    -------
    dict
        ``"boolean"``: the 16 functions' scores (XOR first); ``"temporal"``: recall and parity
        scores, or None.
    """
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


def study_summary(
    config: ReservoirConfig,
    device: ReservoirDevice,
    streams: list[StreamResult],
    temporal: list[StreamResult],
    scores: dict,
    wall_seconds: float,
) -> dict:
    """The JSON-able record of a study (what ``summary.json`` holds).

    Parameters
    ----------
    config, device
        The study's configuration and its device.
    streams, temporal
        The Boolean and temporal streams' results.
    scores
        Their scores (:func:`score_streams`).
    wall_seconds
        Wall time the study took [s] (streams and scoring).

    Returns
    -------
    dict
        Accuracies, parameters, sensor means, counts, times and the device's record; the
        ``[[operations]]``' summaries under ``"operations"``, by stream (``boolean0``, …,
        ``temporal0``, …), when there are any.
    """
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
        "wall_seconds": wall_seconds,
        # worker processes' CPU time (this process only waits on them)
        "cpu_seconds": float(sum(s.cpu_seconds for s in streams + temporal)),
        "temporal_hold_time_s": config.study.temporal_hold_time,
        "device": device.describe(),
    }
    # the summaries of the [[operations]], stream by stream (each stream is a simulation)
    operations = {
        f"{kind}{k}": s.operations
        for kind, group in (("boolean", streams), ("temporal", temporal))
        for k, s in enumerate(group)
        if s.operations
    }
    if operations:
        summary["operations"] = operations
    return summary


def run_study(
    config: ReservoirConfig,
    device: ReservoirDevice | None = None,
    n_inputs: int | None = None,
    temporal_tasks: bool = True,
) -> tuple[dict, list[StreamResult]]:
    """The study of ``config``, in memory.

    Parameters
    ----------
    config
        The validated configuration.
    device
        Its device, if already built.
    n_inputs
        Held inputs of the Boolean streams (default ``study.n_inputs``).
    temporal_tasks
        False: no temporal stream.

    Returns
    -------
    tuple
        The summary record (:func:`study_summary`) and the Boolean streams' results.
    """
    device = device or ReservoirDevice(config)
    started = time.perf_counter()
    streams, temporal = run_streams(
        config, n_inputs=n_inputs, n_temporal=None if temporal_tasks else 0
    )
    scores = score_streams(config, streams, temporal)
    summary = study_summary(
        config, device, streams, temporal, scores, time.perf_counter() - started
    )
    return summary, streams
