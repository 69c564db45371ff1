"""A neuron run's ``frames.nc`` (``skygas neuron --animate``): written, and read back.

:func:`write_frames` writes the positions the run recorded. :func:`record` is the neuron's
reader of :class:`~skygas.devices.registry.RecordFile`: the dense positions in the neuron's
chamber, its outline without the input port, and the holding current behind them.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from skygas.devices.records import RecordParts, one_group

#: The attribute that tells a ``frames.nc`` to be a neuron's (read by the device registry).
RUN_KIND_ATTRIBUTE = "skygas_run_kind"


def write_frames(simulation, config, path: Path) -> Path:
    """The positions a :class:`~skygas.engine.Simulation` recorded, as ``frames.nc``.

    The trajectories dataset, with the run's configuration and kind; written under a temporary
    name and renamed into place.
    """
    ds = simulation.trajectories()
    ds.attrs["config_json"] = config.model_dump_json()
    ds.attrs[RUN_KIND_ATTRIBUTE] = "neuron"
    tmp = path.with_name(f".{path.name}.tmp")
    ds.to_netcdf(tmp)
    os.replace(tmp, path)
    return path


def record(ds) -> RecordParts:
    """The neuron's parts of the run whose result file is ``ds``."""
    from skygas.fields.current import solve_current
    from skygas.neuron.config import NeuronConfig
    from skygas.neuron.device import NeuronDevice
    from skygas.physics.geometry import chamber_with_conduits

    config = NeuronConfig.model_validate_json(ds.attrs["config_json"])
    d = config.device
    full = chamber_with_conduits(d.chamber_diameter, d.conduit_width, d.conduit_length)

    def background(x, y):
        solution = solve_current(full, config.current_density)
        jx, jy = solution.current_density_at(x, y)
        return np.hypot(jx, jy), "holding current density |j| (A/m²)"

    return RecordParts(
        full.without_ports("input"),
        config.thiele_parameters().skyrmion_diameter,
        ("skyrmions",),
        one_group,
        (1.0, 0.0),
        background_fn=background if config.current_density > 0 else None,
        landscape_fn=lambda: NeuronDevice(config).build().sim.landscape,
    )
