"""``skygas check-timestep`` on a reshuffler configuration: its chambers filled as in use.

See :class:`~skygas.devices.registry.TimeStepCheck`.
"""

from __future__ import annotations

from typing import Any

from skygas.devices.timestep import filled, with_step


def load(path: str | None, preset: str | None) -> Any:
    """The reshuffler's configuration from ``path`` over ``preset`` (its defaults without)."""
    from skygas.reshuffler.config import load_reshuffler_config

    return load_reshuffler_config(path, preset=preset)


def population(config) -> int:
    """Skyrmions in the reshuffler while in use.

    :func:`~skygas.reshuffler.run.expected_population`, capped at a third of the chambers'
    close packing, which random placement reaches.
    """
    from skygas.reshuffler.run import expected_population

    d_sk = config.thiele_parameters().skyrmion_diameter
    packing = 2 * (config.device.chamber_diameter / d_sk) ** 2
    return max(1, round(min(expected_population(config), packing / 3)))


def probe(config) -> tuple[Any, int]:
    """The builder of the reshuffler's engine at a time step, and the skyrmions it places."""
    from skygas.reshuffler.run import ReshufflerRun

    count = population(config)

    def build_reshuffler(dt, substeps):
        run = ReshufflerRun.build(with_step(config, dt), brownian_substeps=substeps)
        return filled(run.sim, count, config.seed)

    return build_reshuffler, count
