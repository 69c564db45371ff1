"""Validation: the calibrated particle model against micromagnetic many-skyrmion dynamics.

The micromagnetic run (:mod:`skygas.calibration.pipeline`): ``n`` skyrmions in a disk or a
rectangle,
relaxed with their guiding centres held, released at t = 0 and integrated with LLG at T = 0,
without current, with the material's α, in the same environment as the laws (compensated
film with the reference field, so the disk's edge acts at short range). Each snapshot is read by the
project's own detector (:func:`skygas.micromag.detect_skyrmions`, guiding centres) and the
skyrmions are followed from frame to frame by minimum total displacement.

The particle run: the same number of skyrmions at the tracked positions of the first frame, in
a disk of the micromagnetic disk's equal-area radius (or the film's own rectangle), T = 0, the
calibrated model (its tables, without the edge stray field, which the compensated film does not
have), recorded at the same
times. The error is the RMS over skyrmions of the distance between the two runs' positions, in
skyrmion diameters, at every snapshot; and each skyrmion's final displacement is compared in
length (the ratio particle/micromagnetic) and direction (the angle between them).

A calibration that measured the breathing model's table compares both particle models, rigid and
breathing, with the same micromagnetic run (:func:`compare_models`); a breathing run also
records its mean radius at each snapshot, beside the micromagnetic one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment


def match_frames(start: list[dict], frames: list[dict], diameter: float):
    """Positions (frames + 1, skyrmions, 2) [m] of the skyrmions of ``start``, through ``frames``.

    Each frame is a dict with ``skyrmions``; they are followed by minimum total displacement. None
    if a skyrmion is lost (annihilated or merged) or jumps by more than half a diameter.
    """
    current = np.array([[s["x"], s["y"]] for s in start])
    out = [current.copy()]
    for frame in frames:
        points = np.array([[s["x"], s["y"]] for s in frame["skyrmions"]]).reshape(-1, 2)
        if len(points) != len(current):
            return None
        cost = np.linalg.norm(current[:, None, :] - points[None, :, :], axis=-1)
        rows, cols = linear_sum_assignment(cost)
        if np.max(cost[rows, cols]) > 0.5 * diameter:
            return None
        current = points[cols[np.argsort(rows)]]
        out.append(current.copy())
    return np.array(out)


def path_lengths(start: list[dict], frames: list[dict], diameter: float):
    """Path length of each skyrmion [d_sk], or None if one was lost."""
    tracks = match_frames(start, frames, diameter)
    if tracks is None:
        return None
    steps = np.linalg.norm(np.diff(tracks, axis=0), axis=-1)
    return (steps.sum(axis=0) / diameter).tolist()


@dataclass(frozen=True)
class Comparison:
    """Both runs at the snapshot times.

    ``times`` [s], ``micromagnetic`` and ``particle`` positions (frames, skyrmions, 2) [m],
    ``error`` RMS centre error per frame [d_sk], ``path_length`` per skyrmion in the micromagnetic
    run [d_sk], ``radius`` the mean micromagnetic radius per frame [m], ``particle_radius`` the
    breathing model's (None for rigid skyrmions), ``particle_model`` which model ran;
    ``disk_radius`` [m] of a disk, or ``size`` (width, height) [m] of a rectangle (the other
    None), whose centre is ``centre``.
    """

    times: np.ndarray
    micromagnetic: np.ndarray
    particle: np.ndarray
    error: np.ndarray
    path_length: np.ndarray
    radius: np.ndarray
    diameter: float
    disk_radius: float | None
    centre: tuple[float, float]
    particle_radius: np.ndarray | None = None
    particle_model: str = "rigid"
    size: tuple[float, float] | None = None

    def displacements(self) -> tuple[np.ndarray, np.ndarray]:
        """Each skyrmion's final displacement: length ratio particle/micromagnetic, angle [°].

        The angle is the particle's direction minus the micromagnetic one, in (−180°, 180°].
        """
        mm = self.micromagnetic[-1] - self.micromagnetic[0]
        pm = self.particle[-1] - self.particle[0]
        length = np.linalg.norm(mm, axis=-1)
        ratio = np.linalg.norm(pm, axis=-1) / np.where(length > 0, length, np.nan)
        angle = np.degrees(
            np.arctan2(mm[:, 0] * pm[:, 1] - mm[:, 1] * pm[:, 0], np.sum(mm * pm, axis=-1))
        )
        return ratio, angle

    def summary(self) -> dict:
        """The comparison in numbers, JSON-able: errors, duration, paths, displacements, radii."""
        ratio, angle = self.displacements()
        extra = (
            {}
            if self.particle_radius is None
            else {
                "particle_radius_range_m": [
                    float(np.nanmin(self.particle_radius)),
                    float(np.nanmax(self.particle_radius)),
                ],
                "radius_rms_error_m": float(
                    np.sqrt(np.nanmean((self.particle_radius - self.radius) ** 2))
                ),
            }
        )
        return {
            "particle_model": self.particle_model,
            "displacement_length_ratio": [float(x) for x in ratio],
            "displacement_angle_deg": [float(x) for x in angle],
            **extra,
            "rms_error_max_d_sk": float(self.error.max()),
            "rms_error_final_d_sk": float(self.error[-1]),
            "rms_error_mean_d_sk": float(self.error.mean()),
            "duration_s": float(self.times[-1]),
            "path_length_d_sk": [float(x) for x in self.path_length],
            "radius_range_m": [float(self.radius.min()), float(self.radius.max())],
            **(
                {"disk_radius_m": self.disk_radius}
                if self.size is None
                else {"rectangle_m": [float(x) for x in self.size]}
            ),
            "skyrmions": int(self.micromagnetic.shape[1]),
        }


def outline(film):
    """The particle model's outline of a validation film, and the disk's radius [m] or None.

    A disk film: the disk of its magnetic cells' equal-area radius; a rectangular film: the
    rectangle of its cells.
    """
    from skygas.physics import geometry

    centre = (0.5 * film.size[0], 0.5 * film.size[1])
    if not film.disk:
        return geometry.rectangle(*film.size, center=centre), None
    radius = math.sqrt(film.magnetic().sum() / math.pi) * film.cell_size
    return geometry.disk(diameter=2 * radius, center=centre), radius


def particle_run(material, film, start: np.ndarray, times: np.ndarray, thickness: float):
    """Positions (frames, n, 2) [m] of the particle model from ``start`` (n, 2) [m].

    At ``times`` [s] (the first is 0), in the film's :func:`outline`. Also the mean radius [m]
    at each time of a breathing model (None for rigid skyrmions), the disk's radius (None for a
    rectangle) and the film's centre.
    """
    from skygas.engine import Simulation

    centre = (0.5 * film.size[0], 0.5 * film.size[1])
    shape, radius = outline(film)
    sim = Simulation(
        shape,
        material,
        temperature=0.0,
        film_thickness=thickness,
        seed=0,
    )
    interval = float(times[1] - times[0])
    steps = max(1, round(interval / sim.suggested_time_step()))
    sim = Simulation(
        shape,
        material,
        temperature=0.0,
        film_thickness=thickness,
        seed=0,
        time_step=interval / steps,
    )
    ids = sim.add_skyrmions(start)
    out = [np.asarray(start, float)]
    radii = [float(np.mean(sim.radii()[1]))]
    for _ in times[1:]:
        sim.run(interval)
        present, xy = sim.positions()
        if len(present) != len(ids):
            break
        out.append(xy[np.searchsorted(present, ids)])
        radii.append(float(np.mean(sim.radii()[1])))
    mean_radius = np.array(radii) if sim.particle_model == "breathing" else None
    return np.array(out), mean_radius, radius, centre


def compare(
    material,
    film,
    start: list[dict],
    frames: list[dict],
    diameter: float,
    thickness: float,
    settle: float = 0.0,
) -> Comparison | None:
    """The particle model against the micromagnetic frames (module docstring).

    From the first frame at or after ``settle`` [s]; None if the micromagnetic run lost a skyrmion.
    """
    tracks = match_frames(start, frames, diameter)
    if tracks is None:
        return None
    times = np.array([0.0] + [f["time"] for f in frames])
    first = int(np.searchsorted(times, settle - 1e-15))
    if first:
        start, frames = frames[first - 1]["skyrmions"], frames[first:]
    tracks, times = tracks[first:], times[first:] - times[first]
    particle, particle_radius, radius, centre = particle_run(
        material, film, tracks[0], times, thickness
    )
    n = min(len(particle), len(tracks))
    error = np.sqrt(np.mean(np.sum((particle[:n] - tracks[:n]) ** 2, axis=-1), axis=1))
    steps = np.linalg.norm(np.diff(tracks, axis=0), axis=-1)
    radii = np.array(
        [np.mean([s["radius"] for s in start])]
        + [np.mean([s["radius"] for s in f["skyrmions"]]) for f in frames]
    )
    return Comparison(
        times[:n],
        tracks[:n],
        particle[:n],
        error / diameter,
        steps.sum(axis=0) / diameter,
        radii[:n],
        diameter,
        radius,
        centre,
        None if particle_radius is None else particle_radius[:n],
        material.particle_model,
        None if film.disk else film.size,
    )


def compare_models(material, *args, **kwargs) -> dict[str, Comparison | None]:
    """:func:`compare` of ``material`` as rigid and, if it has a breathing table, as breathing."""
    models = ("rigid", "breathing") if material.breathing is not None else ("rigid",)
    return {
        model: compare(material.model_copy(update={"particle_model": model}), *args, **kwargs)
        for model in models
    }
