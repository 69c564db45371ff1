"""The time-step check's shared parts, and a plain simulation's (``skygas check-timestep``).

Each kind's reader and builder (``load(path, preset)``, ``probe(config)``; see
:class:`~skygas.devices.registry.TimeStepCheck`) live in its package's ``timestep`` module; a
``skygas simulate`` configuration, which has no device package, has them here. A device is
checked without its operations and filled with skyrmions as it is in use (:func:`filled`).
"""

from __future__ import annotations

from typing import Any

from skygas.core.errors import InputError

#: least distance of the skyrmions placed in a device, from each other and from the walls
#: [skyrmion diameters] (the reservoir's own placement)
PLACEMENT_SEPARATION = 1.2


def with_step(config, time_step: float | None):
    """``config`` with its time step replaced (``None``: the configuration's own)."""
    return config if time_step is None else config.model_copy(update={"time_step": time_step})


def filled(sim, count: int, seed: int):
    """``sim`` without its device's operations, filled with ``count`` skyrmions at random."""
    sim.operations.clear()  # only the engine's forces are compared: no injection, no gate logic
    sim.add_random(count, min_separation=PLACEMENT_SEPARATION, seed=seed)
    return sim


def load(path: str | None, preset: str | None) -> Any:
    """A ``skygas simulate`` configuration from ``path``; it has no defaults to check."""
    if path is None:
        raise InputError(
            "config",
            None,
            "a simulation's TOML file (a simulation has no defaults to check)",
            "give the file, e.g. examples/closed-chamber.toml",
        )
    from skygas.runs.config import load_config

    return load_config(path)


def probe(config) -> tuple[Any, None]:
    """The builder of a simulation at a time step; it places its own skyrmions (count None)."""

    def build_simulation(dt, substeps):
        return config.build(
            time_step=dt if dt is not None else config.time_step, brownian_substeps=substeps
        )

    return build_simulation, None
