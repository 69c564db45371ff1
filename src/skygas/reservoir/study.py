"""Studies of the reservoir: the Boolean and temporal study, and the accuracy sweep.

:func:`run_study` runs the input streams (:func:`~skygas.reservoir.streams.run_streams`), trains
and scores the 16 Boolean read-outs and the temporal tasks, and returns one JSON-able record
with every parameter, the seed and the version (:func:`study_summary`). :func:`accuracy_sweep`
repeats a smaller study for each value of a parameter (hold time, temperature, number of
skyrmions, pinning depth, current density) and each replica seed (:func:`sweep_configs`,
:func:`sweep_point`, :func:`sweep_record`).

These run in memory; ``skygas reservoir`` runs the same streams piece by piece through the run
driver, with checkpoints and resume (:mod:`skygas.reservoir.files`), and gives the same numbers.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from typing import cast

import numpy as np

from skygas._version import __version__
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
        Accuracies, parameters, sensor means, counts, times and the device's record.
    """
    boolean = scores["boolean"]
    return {
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


def sweep_configs(config: ReservoirConfig) -> list[tuple[float, int, ReservoirConfig]]:
    """The points of the sweep of ``config`` (``config.sweep``), in order.

    Each is (value, replica, the configuration with that value and the replica's seed
    ``seed + 1000·(replica + 1)``), every value with every replica. The configurations are
    validated, not their devices.
    """
    sw = config.sweep
    return [
        (value, r, _with(config, sw.parameter, value, config.seed + 1000 * (r + 1)))
        for value in sw.values
        for r in range(sw.replicas)
    ]


def sweep_point(
    value: float, replica: int, config: ReservoirConfig, streams: list[StreamResult]
) -> dict:
    """The record of one sweep point: XOR and mean Boolean accuracy of its streams.

    ``streams`` are the results of :func:`~skygas.reservoir.streams.stream_specs` of
    ``config`` with ``sweep.n_inputs`` inputs and no temporal stream.

    Parameters
    ----------
    value, replica
        The point's value of the swept parameter, and its replica.
    config
        The point's configuration (:func:`sweep_configs`).
    streams
        Its Boolean streams' results.

    Returns
    -------
    dict
        ``value``, ``replica``, ``seed``, ``xor_accuracy`` and ``mean_accuracy``.
    """
    boolean = score_streams(config, streams, [])["boolean"]
    return {
        "value": value,
        "replica": replica,
        "seed": config.seed,
        "xor_accuracy": boolean["XOR"]["accuracy"],
        "mean_accuracy": float(np.mean([r["accuracy"] for r in boolean.values()])),
    }


def sweep_record(config: ReservoirConfig, points: Mapping[tuple[float, int], dict]) -> dict:
    """XOR and mean Boolean accuracy against the swept parameter: what ``sweep.json`` holds.

    One row per value of ``config.sweep``: every replica's accuracies, their mean and standard
    deviation, from every point's record (:func:`sweep_point`) in ``points``, keyed by (value,
    replica).
    """
    sw = config.sweep
    rows = []
    for value in sw.values:
        xor = [points[(value, r)]["xor_accuracy"] for r in range(sw.replicas)]
        mean = [points[(value, r)]["mean_accuracy"] for r in range(sw.replicas)]
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


def accuracy_sweep(config: ReservoirConfig) -> dict:
    """The sweep of ``config`` (``config.sweep``), in memory; returns :func:`sweep_record`.

    Every point's configuration is validated, its device built, before the first runs.
    """
    plan = sweep_configs(config)
    for _, _, cfg in plan:
        ReservoirDevice(cfg)
    points = {}
    for value, r, cfg in plan:
        streams, _ = run_streams(cfg, n_inputs=config.sweep.n_inputs, n_temporal=0)
        points[(value, r)] = sweep_point(value, r, cfg, streams)
    return sweep_record(config, points)
