"""A finished run read back from its directory or result file, whatever command made it.

:func:`load_run` accepts a run directory or one of the files the run commands write:

- ``trajectories.nc`` (``skygas simulate``, ``skygas demo``): dense positions;
- ``reshuffler.nc`` (``skygas reshuffle``): the sparse snapshots;
- ``frames.nc`` (``skygas neuron --animate``): dense positions of the neuron's chamber.

and returns a :class:`RunRecord`: the positions as :class:`~skygas.analysis.frames.Frames`,
the device outline rebuilt from the recorded configuration, the skyrmion diameter, how to
colour each skyrmion, the direction of the drive, and the provenance (version, seed, config).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from skygas.analysis.frames import Frames
from skygas.core.errors import InputError

if TYPE_CHECKING:
    from skygas.physics.geometry import Outline

#: result files in the order a directory is searched
RESULT_FILES = ("trajectories.nc", "reshuffler.nc", "frames.nc")


@dataclass
class RunRecord:
    """One run, read back from its result file.

    ``kind`` ("simulate", "reshuffle" or "neuron"), its result ``path``, ``frames`` [m, s], the
    ``outline`` (nm), ``skyrmion_diameter`` [m], ``group_names`` and ``group_of(ids, x, y)`` → index
    into them (the colour of each skyrmion), ``drive``: the direction of the spin drift (unit
    vector, or None without one), and the provenance.
    """

    kind: str
    path: Path
    frames: Frames
    outline: Outline
    skyrmion_diameter: float
    group_names: tuple[str, ...]
    group_of: Callable
    drive: tuple[float, float] | None
    config: dict
    version: str
    seed: int | None
    summary: dict | None = None
    background_fn: Callable | None = field(default=None, repr=False)
    #: builds the run's energy landscape (a LandscapeField), for runs that have one
    landscape_fn: Callable | None = field(default=None, repr=False)
    #: the configuration exactly as the result file holds it (its hash is the manifest's)
    config_json: str | None = field(default=None, repr=False)

    def provenance(self) -> dict[str, str]:
        """The provenance record of a file made from this run.

        Returns
        -------
        dict of str to str
            The run's skygas version, seed and configuration (with its hash), and the command
            that makes the file (:func:`skygas.runs.provenance.provenance`).
        """
        from skygas.runs.provenance import provenance

        return provenance(
            seed=self.seed,
            config_json=self.config_json or json.dumps(self.config),
            skygas_version=self.version,
            source=str(self.path),
        )

    @property
    def directory(self) -> Path:
        """The folder that holds the result file."""
        return self.path.parent

    def background(self, nx: int = 320):
        """The picture behind the skyrmions, or None.

        (values (ny, nx), extent (x0, x1, y0, y1) [m], label, scale); NaN outside the device. The
        energy landscape (U/k_BT on the engine's grid, ``scale`` "linear") when the run has one,
        else the current density (``scale`` "log").
        """
        field_ = self.landscape_fn() if self.landscape_fn is not None else None
        if field_ is not None and field_.terms:
            from skygas.runs.plotting import landscape_energy

            energy = landscape_energy(field_, self.outline)
            assert energy is not None  # the field has terms
            values, label = energy
            g = field_.grid
            extent = (
                g.x0 - g.spacing / 2,
                g.x0 + g.spacing * (g.nx - 0.5),
                g.y0 - g.spacing / 2,
                g.y0 + g.spacing * (g.ny - 0.5),
            )
            return values, tuple(e * 1e-9 for e in extent), label, "linear"
        if self.background_fn is None:
            return None
        x0, y0, x1, y1 = self.outline._bounds_nm
        ny = max(2, int(round(nx * (y1 - y0) / (x1 - x0))))
        gx, gy = np.meshgrid(np.linspace(x0, x1, nx), np.linspace(y0, y1, ny))
        values, label = self.background_fn(gx * 1e-9, gy * 1e-9)
        values = np.where(self.outline._contains_nm(gx, gy), values, np.nan)
        return values, (x0 * 1e-9, x1 * 1e-9, y0 * 1e-9, y1 * 1e-9), label, "log"


def find_result_file(path: str | Path) -> Path:
    """The result file of a run directory (or ``path`` itself when it is one)."""
    p = Path(path)
    if p.is_dir():
        for name in RESULT_FILES:
            if (p / name).exists():
                return p / name
        raise InputError(
            "RUN",
            str(path),
            "a run directory holding one of "
            f"{', '.join(RESULT_FILES)} (written by simulate, reshuffle or "
            "neuron --animate)",
        )
    if not p.exists():
        raise InputError("RUN", str(path), "an existing run directory or result file")
    if p.suffix != ".nc":
        raise InputError("RUN", str(path), f"a run directory or one of {', '.join(RESULT_FILES)}")
    return p


#: what to do about a result file that cannot be read
_REDO = "give a run folder skygas wrote, or run the simulation again to write it anew"


def _not_readable(file: Path, why: str) -> InputError:
    return InputError("RUN", str(file), f"a skygas result file (this one is {why})", _REDO)


def _open_result(file: Path):
    """The dataset of a result file, loaded; an :class:`InputError` if it cannot be read."""
    import xarray as xr

    try:
        with open(file, "rb") as handle:
            head = handle.read(8)
    except OSError as err:
        raise _not_readable(file, f"unreadable: {err.strerror}") from None
    if not head:
        raise _not_readable(file, "empty")
    if not (head.startswith(b"CDF") or head.startswith(b"\x89HDF")):
        raise _not_readable(file, "not a netCDF file")
    try:
        with xr.open_dataset(file) as ds:
            return ds.load()
    except (OSError, ValueError, RuntimeError, KeyError, IndexError, TypeError) as err:
        why = getattr(err, "strerror", None) or str(err) or type(err).__name__
        raise _not_readable(file, f"truncated or damaged: {why}") from None


def load_run(path: str | Path) -> RunRecord:
    """Read the run at ``path`` (directory or result file); see the module docstring.

    A result file that is empty, truncated, damaged or not one that skygas wrote, and a
    ``summary.json`` beside it that is not JSON, are refused with one :class:`InputError`.
    """
    file = find_result_file(path)
    ds = _open_result(file)
    summary_file = file.parent / "summary.json"
    try:
        summary = json.loads(summary_file.read_text()) if summary_file.exists() else None
    except (OSError, ValueError) as err:
        raise InputError(
            "RUN",
            str(summary_file),
            f"the run's summary as JSON (this one is unreadable: {err})",
            _REDO,
        ) from None
    if "snapshot_count" in ds:
        build = _reshuffler_record
    elif ds.attrs.get("skygas_run_kind") == "neuron":
        build = _neuron_record
    elif "x" in ds and "config_json" in ds.attrs:
        build = _simulation_record
    else:
        raise InputError(
            "RUN",
            str(file),
            "a result file written by skygas simulate, reshuffle or neuron --animate "
            "(this netCDF file is not a skygas run)",
            _REDO,
        )
    try:
        record = build(ds, file)
    except InputError:
        raise
    except (KeyError, ValueError, TypeError, IndexError) as err:
        # ValueError includes a configuration that no longer validates (pydantic's error)
        why = f"{type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''}"
        raise _not_readable(file, f"damaged or incomplete: {why}") from None
    record.summary = summary
    record.config_json = str(ds.attrs["config_json"]) if "config_json" in ds.attrs else None
    return record


def _one_group(ids, x, y):
    return np.zeros(len(ids), dtype=np.int64)


def _simulation_record(ds, file: Path) -> RunRecord:
    from skygas.runs.config import SimulationConfig

    config = SimulationConfig.model_validate_json(ds.attrs["config_json"])
    v = np.asarray(config.drift.velocity, float)
    drive = tuple(v / np.hypot(*v)) if np.any(v) else None
    return RunRecord(
        "simulate",
        file,
        Frames.from_trajectories(ds),
        config.geometry.build(),
        config.thiele_parameters().skyrmion_diameter,
        ("skyrmions",),
        _one_group,
        drive,
        json.loads(ds.attrs["config_json"]),
        str(ds.attrs.get("skygas_version", "?")),
        int(ds.attrs.get("seed", -1)),
        landscape_fn=(lambda: config.build().landscape) if config.potentials else None,
    )


def _reshuffler_record(ds, file: Path) -> RunRecord:
    from skygas.reshuffler.config import ReshufflerConfig
    from skygas.reshuffler.device import CHAMBERS, ReshufflerGeometry

    config = ReshufflerConfig.model_validate_json(ds.attrs["config_json"])
    d = config.device
    geometry = ReshufflerGeometry(
        d.chamber_diameter, d.conduit_width, d.conduit_length, d.chamber_gap
    )
    frames = Frames(
        ds.snapshot_time.values,
        ds.snapshot_count.values.astype(np.int64),
        ds.snapshot_skyrmion.values.astype(np.int64),
        ds.snapshot_x.values,
        ds.snapshot_y.values,
    )
    # the input bit each skyrmion carries: 1 is steered to UP, 0 to DOWN
    carried = ds.event_skyrmion.values
    nucleated = carried >= 0
    bit_ids = carried[nucleated]
    bits = ds.input_bit.values[nucleated]
    order = np.argsort(bit_ids)
    bit_ids, bits = bit_ids[order], bits[order]

    def group_of(ids, x, y):
        out = np.full(len(ids), 2)  # "unknown": not in the event log
        if len(bit_ids):
            where = np.clip(np.searchsorted(bit_ids, ids), 0, len(bit_ids) - 1)
            known = bit_ids[where] == ids
            out[known] = 1 - bits[where[known]]
        return out

    def background(x, y):
        from skygas.fields.current import solve_current

        c = config.current
        solution = solve_current(
            geometry.chamber(),
            config.current_density,
            cell_size=c.cell_size,
            conductor_thickness=c.conductor_thickness,
            resistivity=c.resistivity,
        )
        values = np.zeros_like(x)
        which = geometry.chamber_of(y * 1e9)
        for index, name in enumerate(CHAMBERS):
            cx, cy = geometry.centres()[name]
            mask = which == index
            jx, jy = solution.current_density_at(x[mask] - cx, y[mask] - cy)
            values[mask] = np.hypot(jx, jy)
        return values, "current density |j| (A/m²)"

    return RunRecord(
        "reshuffle",
        file,
        frames,
        geometry.device_outline(),
        config.thiele_parameters().skyrmion_diameter,
        ("input bit 1 (to UP)", "input bit 0 (to DOWN)", "unknown"),
        group_of,
        (1.0, 0.0),
        json.loads(ds.attrs["config_json"]),
        str(ds.attrs.get("skygas_version", "?")),
        int(ds.attrs.get("seed", -1)),
        background_fn=background,
        landscape_fn=_reshuffler_landscape(config),
    )


def _reshuffler_landscape(config):
    """Builds the landscape of a reshuffler run (the engine's, same grid and seed), or None."""
    if not config.potentials:
        return None

    def build():
        from skygas.reshuffler.run import ReshufflerRun

        return ReshufflerRun.build(config).sim.landscape

    return build


def _neuron_record(ds, file: Path) -> RunRecord:
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

    return RunRecord(
        "neuron",
        file,
        Frames.from_trajectories(ds),
        full.without_ports("input"),
        config.thiele_parameters().skyrmion_diameter,
        ("skyrmions",),
        _one_group,
        (1.0, 0.0),
        json.loads(ds.attrs["config_json"]),
        str(ds.attrs.get("skygas_version", "?")),
        int(ds.attrs.get("seed", -1)),
        background_fn=background if config.current_density > 0 else None,
        landscape_fn=lambda: NeuronDevice(config).build().sim.landscape,
    )
