"""The files of ``skygas infer``.

- ``inference.json``: every number, with its error and how it was measured;
- ``landscape.nc``: the landscape from the forces with its jackknife error, the areas it is
  sampled and well sampled on, and the Boltzmann inversion's map where it was made;
- ``landscape-map.npy``: the model's map (U [k_BT] where the film was sampled, NaN elsewhere),
  which model.toml's ``[[potentials]]`` table names;
- ``model.toml``: the model, every number of which is in inference.json;
- ``report.html`` (:mod:`skygas.inference.report`).

Everything is made before the first file is written; then every file is written under a
temporary name (:func:`skygas.runs.run_driver.partial_path`) and, once all are complete, all
are renamed (:func:`write_all`): an inference stopped by a full disk, an error or Ctrl-C leaves
no file under its real name. Each carries the provenance record (version, command line, the
input's hash).
"""

from __future__ import annotations

import errno
import io
import os
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from skygas.core.errors import WriteFailed
from skygas.inference.pipeline import MAP_FILE, Inference
from skygas.runs.provenance import provenance


def record(result: Inference) -> dict:
    """The provenance record of the inference's files."""
    return provenance(
        seed=result.summary["input"]["seed"],
        config_hash=result.summary["input"]["sha256"][:16],
        source=result.tracks.source,
    )


def landscape_dataset(result: Inference):
    """The maps [k_BT] on x, y [m]: from the forces, its error, the masks, the cross-check."""
    import xarray as xr

    fmap = result.map
    g = fmap.grid
    variables: dict[str, tuple] = {
        "U": (("y", "x"), fmap.u, {"units": "k_BT", "long_name": "landscape from the forces"}),
        "U_error": (
            ("y", "x"),
            fmap.error,
            {
                "units": "k_BT",
                "long_name": "jackknife error of U relative to its mean over the well-sampled area",
            },
        ),
        "sampled": (("y", "x"), fmap.sampled.astype(np.int8)),
        "well_sampled": (("y", "x"), fmap.well_sampled.astype(np.int8)),
    }
    if result.boltzmann is not None:
        variables["U_boltzmann"] = (
            ("y", "x"),
            result.boltzmann,
            {"units": "k_BT", "long_name": "-ln rho, the neighbours' mean push taken out"},
        )
        variables["U_boltzmann_error"] = (
            ("y", "x"),
            result.boltzmann_error,
            {"units": "k_BT", "long_name": "bootstrap error of -ln rho (time and tracks)"},
        )
    return xr.Dataset(
        variables,
        coords={"x": ("x", g.x, {"units": "m"}), "y": ("y", g.y, {"units": "m"})},
        attrs={**record(result), "temperature_K": result.summary["input"]["temperature_K"]},
    )


def model_sections(result: Inference) -> tuple[dict, list[str], dict[str, str]]:
    """The model file's tables besides ``[material]``, its header and its comments."""
    s = result.summary
    fitted_pair = s["pair"]["fitted"] or {}
    fitted_wall = s["wall"]["fitted"] or {}
    sections: dict = {
        "potentials": [dict(p) for p in result.potentials],
        "inference": {
            "diffusion_constant": s["diffusion_constant"],
            "diffusion_constant_error": s["diffusion_constant_error"],
            "hall_angle": s["hall_angle_in_model"],
            "hall_angle_error": s["hall_angle_error"],
            "hall_angle_fixed_by_data": s["hall_angle"] is not None,
            "temperature": s["input"]["temperature_K"],
            "terms": s["model_selection"]["terms"],
            "pair_fixed_range": fitted_pair.get("fixed_range_m") or [],
            "wall_fixed_range": fitted_wall.get("fixed_range_m") or [],
            "drive_force": s["model"]["drive_force_N"],
            "film": s["film"]["kind"],
            "consistency_check_passed": None
            if s["consistency_check"] is None
            else s["consistency_check"]["passed"],
        },
        "provenance": {k: v for k, v in record(result).items() if k != "config_json"},
    }
    header = [
        "A particle model inferred from tracked skyrmions by `skygas infer` (docs/inference.md).",
        'Use it as --material FILE or material = "FILE" in any device; every number in it is',
        "in inference.json beside it.",
    ]
    comments = {
        "potentials": "The landscape where the movie sampled the film (landscape-map.npy, in the\n"
        "movie's coordinates) and random of its statistics elsewhere. Copy this table, with the\n"
        "file, into a configuration as [[potentials]] for a device on the same film.",
        "inference": "What the data measured (SI; angles in rad; drive_force in N, applied as\n"
        "external_force in the self-check).",
    }
    return sections, header, comments


#: Free space [bytes] beyond a file's own size under which a failed write is the disk's doing.
DISK_HEADROOM = 2**20
#: What the library says when it could not write a netCDF file, whatever the reason (a full
#: disk among them): HDF5 does not pass the operating system's error on.
HDF_WORDS = ("HDF error", "NetCDF")
#: Said after a failed write: what is left and what to do.
WRITE_HINT = "no file of the inference was kept: free some space, or choose another --out"


@dataclass(frozen=True)
class OutputFile:
    """One file of the inference: ``write(path)`` writes it; ``size`` [bytes] about its size."""

    write: Callable[[Path], Path]
    size: int


def output_files(result: Inference) -> dict[str, OutputFile]:
    """The files of the inference by name, made in memory (nothing written yet)."""
    from skygas.calibration.model_file import write_model
    from skygas.inference.report import report_html
    from skygas.runs.run_driver import write_atomic, write_json, write_netcdf

    summary = {**result.summary, "provenance": record(result)}
    dataset = landscape_dataset(result)
    text = report_html(result).encode("utf-8")
    sections, header, comments = model_sections(result)
    buffer = io.BytesIO()
    np.save(buffer, result.map_values)
    data = buffer.getvalue()
    return {
        MAP_FILE: OutputFile(
            lambda p: write_atomic(p, lambda tmp: tmp.write_bytes(data)), len(data)
        ),
        "model.toml": OutputFile(
            lambda p: write_model(p, result.material, sections, header, comments), 0
        ),
        "inference.json": OutputFile(lambda p: write_json(p, summary), 0),
        "landscape.nc": OutputFile(lambda p: write_netcdf(dataset, p), int(dataset.nbytes)),
        "report.html": OutputFile(
            lambda p: write_atomic(p, lambda tmp: tmp.write_bytes(text)), len(text)
        ),
    }


def write_outputs(result: Inference, out) -> list[Path]:
    """Write the files into ``out``, all or none (:func:`write_all`); returns their paths."""
    return write_all(out, output_files(result))


def write_all(out, files: dict[str, OutputFile]) -> list[Path]:
    """Write ``files`` into folder ``out``: each under a temporary name, then all renamed.

    Raises
    ------
    WriteFailed
        Naming the file that could not be written and why ("No space left on device" for a
        netCDF file HDF5 could not write on a full disk); no file of ``files`` is then left,
        under its real name or a temporary one.
    """
    from skygas.runs.run_driver import partial_path

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    staged: list[tuple[Path, Path]] = []
    renamed: list[Path] = []
    try:
        for name, file in files.items():
            path = out / name
            staged.append((partial_path(path), path))
            _write_as(path, partial_path(path), file)
        for tmp, path in staged:
            try:
                os.replace(tmp, path)
            except OSError as err:
                raise WriteFailed(path, err.strerror or str(err), WRITE_HINT) from None
            renamed.append(path)
    except BaseException:  # a failure or Ctrl-C: no result under its real name
        for path in [*(tmp for tmp, _ in staged), *renamed]:
            path.unlink(missing_ok=True)
        raise
    return [path for _, path in staged]


def _write_as(path: Path, tmp: Path, file: OutputFile) -> None:
    """Write ``file`` at ``tmp``; a failure is reported for ``path``, the file it stands for."""
    try:
        file.write(tmp)
    except WriteFailed as err:
        cause = err.cause
        if any(w in cause for w in HDF_WORDS) and _disk_full(path.parent, file.size):
            cause = os.strerror(errno.ENOSPC)
        raise WriteFailed(path, cause, WRITE_HINT) from None


def _disk_full(folder: Path, size: int) -> bool:
    """Whether ``folder``'s disk has no room for ``size`` bytes (and a little more)."""
    try:
        return shutil.disk_usage(folder).free < size + DISK_HEADROOM
    except OSError:
        return False
