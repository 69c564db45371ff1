"""A finished run read back from its directory or result file, whatever command made it.

:func:`load_run` accepts a run directory or one of the files the run commands write:

- ``trajectories.nc`` (``skygas simulate``, ``skygas demo``): dense positions;
- ``reshuffler.nc`` (``skygas reshuffle``): the sparse snapshots;
- ``frames.nc`` (``skygas neuron --animate``): dense positions of the neuron's chamber.

and returns a :class:`RunRecord`: the positions as :class:`~skygas.analysis.frames.Frames`,
the device outline rebuilt from the recorded configuration, the skyrmion diameter, how to
colour each skyrmion, the direction of the drive, and the provenance (version, seed, config).
The device registry (:mod:`skygas.devices.registry`) tells whose file it is and reads the
parts only its kind knows (:class:`~skygas.devices.records.RecordParts`).
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
from skygas.devices.registry import DeviceKind, kind_of_record, record_files

if TYPE_CHECKING:
    from skygas.physics.geometry import Outline

#: result files in the order a directory is searched (each kind's, from the device registry)
RESULT_FILES = record_files()


@dataclass
class RunRecord:
    """One run, read back from its result file.

    ``kind`` (its kind's name in :mod:`skygas.devices.registry`), its result ``path``, ``frames``
    [m, s], the ``outline`` (nm), ``skyrmion_diameter`` [m], ``group_names`` and
    ``group_of(ids, x, y)`` → index into them (the colour of each skyrmion), ``drive``: the
    direction of the spin drift (unit vector, or None without one), and the provenance.
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
            from skygas.figures.plotting import landscape_energy

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
    device = kind_of_record(ds)
    if device is None:
        raise InputError(
            "RUN",
            str(file),
            "a result file written by skygas simulate, reshuffle or neuron --animate "
            "(this netCDF file is not a skygas run)",
            _REDO,
        )
    try:
        record = _build(device, ds, file)
    except InputError:
        raise
    except (KeyError, ValueError, TypeError, IndexError) as err:
        # ValueError includes a configuration that no longer validates (pydantic's error)
        why = f"{type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''}"
        raise _not_readable(file, f"damaged or incomplete: {why}") from None
    record.summary = summary
    record.config_json = str(ds.attrs["config_json"]) if "config_json" in ds.attrs else None
    return record


def _build(device: DeviceKind, ds, file: Path) -> RunRecord:
    """The run of kind ``device`` whose result file ``file`` (opened: ``ds``) is."""
    assert device.record is not None  # kind_of_record tells only kinds with a result file
    parts = device.record.read(ds)
    frames = (
        Frames(*parts.snapshots) if parts.snapshots is not None else Frames.from_trajectories(ds)
    )
    return RunRecord(
        device.name,
        file,
        frames,
        parts.outline,
        parts.skyrmion_diameter,
        parts.group_names,
        parts.group_of,
        parts.drive,
        json.loads(ds.attrs["config_json"]),
        str(ds.attrs.get("skygas_version", "?")),
        int(ds.attrs.get("seed", -1)),
        background_fn=parts.background_fn,
        landscape_fn=parts.landscape_fn,
    )
