"""Every standard observable of one run, as one JSON-able dict (``skygas analyze``).

Which observables apply depends on the record: the MSD and D need evenly spaced frames; the
Hall angle needs a drive direction. The free diffusion constant D₀ = k_B T α𝒟k/((α𝒟k)² + G²)
of the run's material is given beside the measured D for comparison (they agree for a dilute
gas far from walls; crowding and confinement lower the measured one).
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

import numpy as np

from skygas.analysis.diffusion import mean_squared_displacement
from skygas.analysis.maps import density_map, occupancy, velocity_map
from skygas.analysis.structure import pair_correlation
from skygas.analysis.transport import mean_velocity

if TYPE_CHECKING:
    from skygas.neuron.config import NeuronConfig
    from skygas.reshuffler.config import ReshufflerConfig
    from skygas.runs.config import SimulationConfig


def _free_diffusion_constant(record) -> float | None:
    temperature = record.config.get("temperature")
    if temperature is None:
        return None
    Config: type[SimulationConfig] | type[ReshufflerConfig] | type[NeuronConfig]
    if record.kind == "simulate":
        from skygas.runs.config import SimulationConfig as Config
    elif record.kind == "reshuffle":
        from skygas.reshuffler.config import ReshufflerConfig as Config
    else:
        from skygas.neuron.config import NeuronConfig as Config
    thiele = Config.model_validate_json(json.dumps(record.config)).thiele_parameters()
    return thiele.diffusion_constant(float(temperature))


def analyze(record, *, maps: bool = True, pair_bins: int = 40) -> dict:
    """The observables of a :class:`~skygas.outputs.records.RunRecord` (SI units).

    Parameters
    ----------
    record : RunRecord
        The run, read back from its result file.
    maps : bool
        Add the density map and, with evenly spaced frames, the velocity map.
    pair_bins : int
        Bins of the pair correlation function.

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
        msd = mean_squared_displacement(frames, subtract_drift=record.drive is not None)
        out["msd"] = msd.as_dict()
        out["free_diffusion_constant_m2_s"] = _free_diffusion_constant(record)
        out["velocity"] = mean_velocity(frames).as_dict(record.drive)
    x0, y0, x1, y1 = record.outline.bounds_nm
    r_max = min(10 * record.skyrmion_diameter, 0.5 * min(x1 - x0, y1 - y0) * 1e-9)
    if frames.n_frames and frames.count.max(initial=0) >= 2:
        out["pair_correlation"] = pair_correlation(
            frames, record.outline, r_max, bins=pair_bins
        ).as_dict()
    groups = None
    if record.kind == "reshuffle":
        groups = (lambda x, y: np.where(y >= 0.0, 0, 1), ("up", "down"))
    out["occupancy"] = occupancy(frames, *(groups or ()))
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


def _nan_to_none(values: np.ndarray) -> list:
    """Nested lists with None where NaN (JSON has no NaN)."""
    return [[None if not np.isfinite(v) else float(v) for v in row] for row in values]
