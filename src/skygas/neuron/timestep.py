"""``skygas check-timestep`` on a neuron configuration: its chamber at its threshold's crowd.

See :class:`~skygas.devices.registry.TimeStepCheck`.
"""

from __future__ import annotations

import math
from typing import Any

from skygas.devices.timestep import filled, with_step


def load(path: str | None, preset: str | None) -> Any:
    """The neuron's configuration from ``path`` (its defaults without); it has no presets."""
    from skygas.neuron.config import load_neuron_config

    return load_neuron_config(path)


def population(config) -> int:
    """Skyrmions in the neuron's chamber at its threshold (the crowd before it fires)."""
    rule = config.rule
    if config.sensor.signal == "count":
        return max(1, math.ceil(rule.threshold))
    d_sk = config.thiele_parameters().skyrmion_diameter
    return max(1, math.ceil(rule.threshold * (config.device.chamber_diameter / d_sk) ** 2))


def probe(config) -> tuple[Any, int]:
    """The builder of the neuron's engine at a time step, and the skyrmions it places."""
    from skygas.neuron.device import NeuronDevice

    count = population(config)

    def build_neuron(dt, substeps):
        run = NeuronDevice(with_step(config, dt)).build(brownian_substeps=substeps)
        return filled(run.sim, count, config.seed)  # the gate closed, as a run starts

    return build_neuron, count
