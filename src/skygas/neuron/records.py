"""A neuron run read back from its ``frames.nc`` (``skygas neuron --animate``).

:func:`record` is the neuron's reader of :class:`~skygas.devices.registry.RecordFile`: the
dense positions in the neuron's chamber, its outline without the input port, and the holding
current behind them.
"""

from __future__ import annotations

import numpy as np

from skygas.devices.records import RecordParts, one_group


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
