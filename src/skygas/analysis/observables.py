"""Every standard observable of one run, as one JSON-able dict (``skygas analyze``).

Which observables apply depends on the record, and an observable the record cannot support is
absent, with the reason:

- the MSD needs evenly spaced frames; the short- and long-time diffusion constants are given
  only where MSD(τ)/4τ is flat over their lags (:func:`~skygas.analysis.diffusion_estimate`);
  the free diffusion constant D₀ = k_B T α𝒟k/((α𝒟k)² + G²) of the run's material is given
  beside them for comparison (they agree for a dilute gas far from walls);
- the skyrmion Hall angle needs a uniform drive (``skygas simulate`` with ``[drift]``), and is
  measured on the skyrmions at least :data:`HALL_WALL_CLEARANCE` diameters from every wall:
  near a wall, or in a device whose current follows its conduits, the angle of the mean
  velocity is set by the walls, not by the skyrmion.
"""

from __future__ import annotations

import json

import numpy as np

from skygas.analysis.diffusion import diffusion_estimate
from skygas.analysis.maps import density_map, occupancy, velocity_map
from skygas.analysis.structure import pair_correlation
from skygas.analysis.transport import mean_velocity
from skygas.devices.registry import KINDS, DeviceKind

#: Skyrmion diameters from every wall beyond which displacements count for the Hall angle.
HALL_WALL_CLEARANCE = 2.0


def _device(record) -> DeviceKind | None:
    """The kind of run ``record`` is (:mod:`skygas.devices.registry`); None for another."""
    return KINDS.get(record.kind)


def _free_diffusion_constant(record) -> float | None:
    temperature = record.config.get("temperature")
    if temperature is None:
        return None
    device = _device(record)
    model = device.config_model if device is not None else None
    if model is None:  # a kind without a configuration model records no positions
        return None
    # the configuration's own material and skyrmion (each device's model reads its own tables)
    thiele = model().model_validate_json(json.dumps(record.config)).thiele_parameters()
    return thiele.diffusion_constant(float(temperature))


def analyze(record, *, maps: bool = True, pair_bins: int = 40, burn_in: float = 0.0) -> dict:
    """The observables of a :class:`~skygas.outputs.records.RunRecord` (SI units).

    Parameters
    ----------
    record : RunRecord
        The run, read back from its result file.
    maps : bool
        Add the density map and, with evenly spaced frames, the velocity map.
    pair_bins : int
        Bins of the pair correlation function.
    burn_in : float
        Time [s] dropped at the start of the record before the MSD (a run that starts from
        random placement relaxes first).

    Returns
    -------
    dict
        JSON-able: the run's identity, then what applies to it: the MSD and D (beside the free
        D₀), the mean velocity and Hall angle, g(r), the occupancy and the maps.
    """
    frames = record.frames
    out: dict = {
        "kind": record.kind,
        "file": str(record.path),
        "skygas_version": record.version,
        "seed": record.seed,
        "frames": frames.n_frames,
        "entries": int(len(frames.ids)),
        "skyrmion_diameter_m": record.skyrmion_diameter,
    }
    even = frames.n_frames >= 3
    if even:
        try:
            frames.frame_interval()
        except ValueError:
            even = False
    if even and len(frames.ids):
        try:
            est = diffusion_estimate(
                frames, burn_in=burn_in, subtract_drift=record.drive is not None
            )
        except ValueError as err:  # nothing left after the burn-in
            out["diffusion"] = {"reason": str(err)}
        else:
            out["msd"] = est.msd.as_dict()
            out["diffusion"] = est.as_dict()
        out["free_diffusion_constant_m2_s"] = _free_diffusion_constant(record)
        out["velocity"] = _velocity(record, frames)
    x0, y0, x1, y1 = record.outline._bounds_nm
    r_max = min(10 * record.skyrmion_diameter, 0.5 * min(x1 - x0, y1 - y0) * 1e-9)
    if frames.n_frames and frames.count.max(initial=0) >= 2:
        out["pair_correlation"] = pair_correlation(
            frames, record.outline, r_max, bins=pair_bins
        ).as_dict()
    # per part of the device where it has parts (the reshuffler's chambers)
    device = _device(record)
    groups = device.occupancy_groups if device is not None else None
    out["occupancy"] = occupancy(frames, *(groups() if groups is not None else ()))
    if maps and len(frames.ids):
        extent = (x0 * 1e-9, x1 * 1e-9, y0 * 1e-9, y1 * 1e-9)
        dm = density_map(frames, 40, extent)
        out["density_map"] = {
            "x_edges_m": dm.x_edges.tolist(),
            "y_edges_m": dm.y_edges.tolist(),
            "density_per_m2": dm.values.tolist(),
        }
        if even:
            vm = velocity_map(frames, 20, extent)
            assert vm.u is not None and vm.v is not None  # a velocity map has both
            out["velocity_map"] = {
                "x_edges_m": vm.x_edges.tolist(),
                "y_edges_m": vm.y_edges.tolist(),
                "vx_m_s": _nan_to_none(vm.u),
                "vy_m_s": _nan_to_none(vm.v),
                "samples": vm.samples.astype(int).tolist(),
            }
    return out


def _velocity(record, frames) -> dict:
    """The mean velocity, and the Hall angle where it is the skyrmion's (module docstring)."""
    velocity = mean_velocity(frames).as_dict()
    if record.drive is None:
        return velocity
    device = _device(record)
    if device is None or not device.uniform_drive:
        velocity["hall_angle_reason"] = (
            "the drift follows the device's current and walls: the angle of the mean velocity "
            "to one direction is not the skyrmion Hall angle"
        )
        return velocity
    clearance_nm = HALL_WALL_CLEARANCE * record.skyrmion_diameter * 1e9
    far = record.outline._wall_distance_nm(frames.x * 1e9, frames.y * 1e9) >= clearance_nm
    free = frames.entries_where(far)
    try:
        away = mean_velocity(free)
    except ValueError:
        away = None
    if away is None or away.n < 10:
        velocity["hall_angle_reason"] = (
            f"fewer than 10 displacements of skyrmions {HALL_WALL_CLEARANCE:g} diameters or more "
            "from every wall"
        )
        return velocity
    far_from_walls = away.as_dict(record.drive)
    velocity.update(
        {
            "hall_angle_rad": far_from_walls["hall_angle_rad"],
            "hall_angle_error_rad": far_from_walls["hall_angle_error_rad"],
            "drive_direction": far_from_walls["drive_direction"],
            "hall_angle_displacements": away.n,
            "hall_angle_wall_clearance_diameters": HALL_WALL_CLEARANCE,
        }
    )
    return velocity


def _nan_to_none(values: np.ndarray) -> list:
    """Nested lists with None where NaN (JSON has no NaN)."""
    return [[None if not np.isfinite(v) else float(v) for v in row] for row in values]
