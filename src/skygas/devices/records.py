"""What a kind's result file holds, read back for :func:`skygas.outputs.records.load_run`.

Each kind that records positions (see :class:`~skygas.devices.registry.RecordFile`) has a
reader ``read(ds)`` → :class:`RecordParts`: the parts of a run that only the kind knows (its
outline rebuilt from the recorded configuration, its skyrmion diameter, how to colour each
skyrmion, the direction of its drive, its background). The reader lives in the kind's package
(``records`` module); a plain simulation's, which has no device package, is here.
:func:`~skygas.outputs.records.load_run` adds what every result file has (the positions as
:class:`~skygas.analysis.frames.Frames`, the configuration and the provenance).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np


@dataclass
class RecordParts:
    """The parts of a run read back from its result file that depend on its kind.

    ``outline`` (nm), ``skyrmion_diameter`` [m], ``group_names`` and ``group_of(ids, x, y)`` →
    index into them (the colour of each skyrmion), ``drive``: the direction of the spin drift
    (unit vector, or None without one). ``snapshots``: ``(time, count, skyrmion, x, y)`` of a
    file that holds sparse snapshots (None: the file's dense trajectories).
    """

    outline: Any
    skyrmion_diameter: float
    group_names: tuple[str, ...]
    group_of: Callable
    drive: tuple[float, float] | None
    snapshots: tuple[np.ndarray, ...] | None = None
    background_fn: Callable | None = field(default=None, repr=False)
    landscape_fn: Callable | None = field(default=None, repr=False)


def one_group(ids, x, y):
    """Every skyrmion in one group (``group_of`` of a kind that colours them all alike)."""
    return np.zeros(len(ids), dtype=np.int64)


def simulation(ds) -> RecordParts:
    """The parts of a plain simulation's ``trajectories.nc`` (``skygas simulate``, ``demo``)."""
    from skygas.runs.config import SimulationConfig

    config = SimulationConfig.model_validate_json(ds.attrs["config_json"])
    v = np.asarray(config.drift.velocity, float)
    drive = tuple(v / np.hypot(*v)) if np.any(v) else None
    return RecordParts(
        config.geometry.build(),
        config.thiele_parameters().skyrmion_diameter,
        ("skyrmions",),
        one_group,
        drive,
        landscape_fn=(lambda: config.build().landscape) if config.potentials else None,
    )
