"""``skygas check-timestep`` on a reservoir configuration: its skyrmions, its fastest input.

See :class:`~skygas.devices.registry.TimeStepCheck`.
"""

from __future__ import annotations

from typing import Any

from skygas.devices.timestep import filled, with_step


def load(path: str | None, preset: str | None) -> Any:
    """The reservoir's configuration from ``path`` (its defaults without); it has no presets."""
    from skygas.reservoir.config import load_reservoir_config

    return load_reservoir_config(path)


def probe(config) -> tuple[Any, int]:
    """The builder of the reservoir's engine at a time step, and the skyrmions it places."""
    from skygas.reservoir.device import ReservoirDevice

    count = config.n_skyrmions

    def build_reservoir(dt, substeps):
        device = ReservoirDevice(with_step(config, dt))
        sim = device.simulation(config.seed, brownian_substeps=substeps)
        fields = device.drive.drift_fields(sim.wall_field.grid)
        # the input whose current drives fastest: the most demanding for the step
        vx, vy = max(fields.values(), key=lambda v: float((v[0] ** 2 + v[1] ** 2).max()))
        sim.set_drift_field(vx, vy)
        return filled(sim, count, config.seed)

    return build_reservoir, count
