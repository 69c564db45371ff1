"""Tracks of a simulated gas whose laws are known: the input of the round-trip validation.

:func:`simulated_tracks` runs a skygas :class:`~skygas.engine.Simulation` of skyrmions in a
rectangular chamber with walls, a random pinning landscape (``disorder``) and the material's
pair law, records their positions every ``frame_interval`` and writes them as trackpy does: a
table with ``frame``, ``particle``, ``x``, ``y`` in pixels, plus Gaussian localisation noise of
standard deviation ``localisation_error`` per coordinate. What went in (the landscape on a grid,
the Thiele parameters, the laws) is returned with it, so that an inference can be checked
against it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skygas.core import units


@dataclass(frozen=True)
class SyntheticGas:
    """A simulated gas's tracks and the truth they were made from.

    ``tracks`` is trackpy's table (pixels, frames); ``pixel_size`` [m], ``frame_interval`` [s],
    ``temperature`` [K]; ``width`` × ``height`` [m] the chamber centred on
    (``width``/2, ``height``/2); ``landscape_x``, ``landscape_y`` [m] and ``landscape_kt``
    (ny, nx) the pinning energy in k_BT that the engine used; ``material`` and ``thiele`` the
    particle model; ``disorder`` the landscape's table.
    """

    tracks: object
    pixel_size: float
    frame_interval: float
    temperature: float
    width: float
    height: float
    landscape_x: np.ndarray
    landscape_y: np.ndarray
    landscape_kt: np.ndarray
    material: object
    thiele: object
    disorder: dict
    localisation_error: float

    @property
    def outline(self):
        """The chamber as an :class:`~skygas.physics.geometry.Outline`."""
        from skygas.physics.geometry import rectangle

        return rectangle(self.width, self.height, center=(self.width / 2, self.height / 2))

    def infer(self, **options):
        """:func:`skygas.inference.infer` of these tracks, with their scales and outline."""
        from skygas.inference.pipeline import infer

        return infer(
            self.tracks,
            pixel_size=self.pixel_size,
            frame_interval=self.frame_interval,
            outline=self.outline,
            temperature=self.temperature,
            **options,
        )


def simulated_tracks(
    *,
    skyrmions: int = 30,
    frames: int = 2000,
    frame_interval: float = 5e-9,
    width: float = 1.2e-6,
    height: float = 1.2e-6,
    material="S2",
    temperature: float = 300.0,
    rms_kt: float = 1.5,
    correlation_length: float = 60e-9,
    pixel_size: float = 10e-9,
    localisation_error: float = 3e-9,
    seed: int = 1,
    progress=None,
) -> SyntheticGas:
    """Simulate a pinned, interacting gas in a walled rectangle; return its tracks and truth.

    Parameters
    ----------
    skyrmions : int
        Skyrmions placed at random (at least 1.5 diameters apart) at the start.
    frames : int
        Frames recorded, one every ``frame_interval`` [s], after a relaxation of 100 frames.
    width, height : float
        The chamber [m], its lower-left corner at the origin.
    material : str or Material
        The particle model (its pair and wall laws are the truth).
    temperature : float
        T [K].
    rms_kt, correlation_length : float
        The random landscape: a Gaussian random field of this rms [k_BT] and correlation
        length [m] (:class:`~skygas.fields.landscape.Disorder`).
    pixel_size : float
        Metres per pixel of the written tracks.
    localisation_error : float
        Standard deviation [m] of the Gaussian noise added to each coordinate.
    seed : int
        Seeds the run, the landscape and the noise.
    progress : callable, optional
        Called with the simulated time [s] as the run proceeds.

    Returns
    -------
    SyntheticGas
    """
    import pandas as pd

    from skygas.engine import Simulation
    from skygas.physics.geometry import rectangle

    outline = rectangle(width, height, center=(width / 2, height / 2))
    disorder = {"kind": "disorder", "rms_kT": rms_kt, "correlation_length": correlation_length}
    sim = Simulation(
        outline,
        material,
        temperature=temperature,
        seed=seed,
        landscape=[disorder],
        step_interval=frame_interval,
    )
    sim.add_random(skyrmions, min_separation=1.5)
    sim.run(100 * frame_interval)
    start = sim.time
    sim.run(frames * frame_interval, record_interval=frame_interval, progress=progress)
    ds = sim.trajectories()
    keep = ds.time.values >= start - 0.5 * frame_interval
    x, y = ds.x.values[keep][:frames], ds.y.values[keep][:frames]
    rng = np.random.default_rng([seed, 0x7AC])
    f, p = np.nonzero(np.isfinite(x))
    xs = x[f, p] + rng.normal(0.0, localisation_error, len(f)) if localisation_error else x[f, p]
    ys = y[f, p] + rng.normal(0.0, localisation_error, len(f)) if localisation_error else y[f, p]
    tracks = pd.DataFrame(
        {
            "frame": f.astype(np.int64),
            "particle": ds.skyrmion.values[p].astype(np.int64),
            "x": xs / pixel_size,
            "y": ys / pixel_size,
        }
    )
    grid = sim.wall_field.grid
    lx = (grid.x0 + grid.spacing * np.arange(grid.nx)) / units.M_TO_NM
    ly = (grid.y0 + grid.spacing * np.arange(grid.ny)) / units.M_TO_NM
    kt = units.thermal_energy_internal(temperature)
    return SyntheticGas(
        tracks,
        pixel_size,
        frame_interval,
        temperature,
        width,
        height,
        lx,
        ly,
        np.array(sim.landscape.nodes[..., 0]) / kt,
        sim.material,
        sim.thiele,
        disorder,
        localisation_error,
    )
