"""Calibrations over a study file: several films, or one film at several values of its fields.

A study file is TOML::

    [study]
    material = "S2"            # the base film: a preset, a TOML file (relative to this file)
                               # or a table; each point changes it
    [settings]                 # calibrate's settings, the same for every point
    cell_size = 2.4e-9         # a field of the film (the in-plane cell)
    pair_distances = 4         # CalibrationConfig fields: reference_diameter, pair_distances,
    validate_dynamics = false  # validate_dynamics, mesh_check, validation = {...}
    mesh_check = false

    [grid]                     # fields of the film, each with its values (a Cartesian product)
    applied_field = [0.0, 0.02]

or, instead of ``[grid]``, one ``[[points]]`` table per point, each setting the same fields, a
point's ``material`` naming a whole film (``material = "S6"``).

Each point is an ordinary calibration (:func:`skygas.calibration.calibrate`) in the folder
``OUT/point-K`` (K from 0, in the grid's C order). Their solves are tasks of one Dask cluster: a
local cluster per point (``workers``), or the running scheduler at ``scheduler``, whose workers
then solve every point's relaxations. A point whose folder holds a finished calibration is not
computed again; one that was interrupted resumes from its checkpoint; so running the study again
after a kill only computes what is missing, to the same bits. ``OUT/study.json`` gathers each
point's values and its isolated skyrmion (radius, wall width, 𝒟, G), its laws' ranges and its
validation, with the file's text and the package version; ``OUT/report.html`` shows them
(:mod:`skygas.calibration.study_report`).
"""

from __future__ import annotations

import itertools
import json
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from skygas.core.errors import InputError, require

_TOP = {"study", "settings", "grid", "points"}
#: Settings of a point that are the film's (the rest are CalibrationConfig's).
_FILM_SETTINGS = {"cell_size"}


@dataclass(frozen=True)
class CalibrationPoint:
    """One calibration of a study: its swept ``values``, its film and its settings."""

    index: int
    values: dict[str, Any]
    material: Any  # a MicromagneticMaterial
    settings: dict[str, Any]

    @property
    def folder(self) -> str:
        """Its folder's name in the study's ``--out``."""
        return f"point-{self.index}"


@dataclass(frozen=True)
class CalibrationStudy:
    """A validated calibration study (see the module docstring)."""

    points: tuple[CalibrationPoint, ...]
    fields: tuple[str, ...]
    source_text: str


def is_study_file(source: object) -> bool:
    """Whether ``source`` (calibrate's MATERIAL) names a study file rather than a film."""
    if not isinstance(source, (str, Path)) or not str(source).endswith(".toml"):
        return False
    try:
        data = tomllib.loads(Path(source).read_text())
    except (OSError, tomllib.TOMLDecodeError, UnicodeDecodeError):
        return False  # the film's reader says what is wrong with it
    return "study" in data and ("grid" in data or "points" in data)


def _material(value: Any, folder: Path, where: str) -> Any:
    """A film of a study file: a preset name, a TOML file (relative to ``folder``) or a table."""
    require(
        isinstance(value, (str, dict)),
        where,
        value,
        "a preset name (S1 … S7), a TOML file of micromagnetic parameters or a table",
    )
    if isinstance(value, str) and value.endswith(".toml") and not Path(value).is_absolute():
        return str(folder / value)
    return value


def _points(data: dict) -> tuple[list[str], list[dict[str, Any]]]:
    """The swept fields and each point's values, from ``[grid]`` or ``[[points]]``.

    Read as a sweep file's (:func:`skygas.sweep.spec.parse_grid`, :func:`~skygas.sweep.spec.
    parse_points`: lists or ``{start, stop, num}`` ranges), over the film's fields.
    """
    from skygas.calibration.material import MicromagneticMaterial
    from skygas.sweep.spec import parse_grid, parse_points

    def check_field(key: str, where: str) -> None:
        require(
            key == "material" or key in MicromagneticMaterial.model_fields,
            f"{where}.{key}",
            key,
            "a field of the film (applied_field, anisotropy, dmi, exchange_stiffness, "
            "saturation_magnetization, …) or material (a whole film)",
        )

    has_grid, has_points = "grid" in data, "points" in data
    require(has_grid != has_points, "grid", "both or neither", "exactly one of [grid], [[points]]")
    if has_grid:
        fields, values = parse_grid(data["grid"], check_field)
        combos = list(itertools.product(*values))
    else:
        fields, values = parse_points(data["points"], check_field)
        combos = list(zip(*values, strict=True))
    return fields, [dict(zip(fields, c, strict=True)) for c in combos]


def parse_study(data: dict, source_text: str = "", folder: Path | None = None) -> CalibrationStudy:
    """Validate a parsed study file; every point's film and settings are checked now."""
    from pydantic import ValidationError

    from skygas.calibration.material import load_micromagnetic_material, split_error
    from skygas.calibration.plan import CalibrationConfig

    folder = folder or Path(".")
    unknown = set(data) - _TOP
    require(
        not unknown, ", ".join(sorted(unknown)), sorted(data), f"only {', '.join(sorted(_TOP))}"
    )
    head = data.get("study", {})
    require(isinstance(head, dict), "study", head, "a table")
    extra = set(head) - {"material", "name", "description"}
    require(not extra, f"study.{min(extra)}" if extra else "study", head, "only material, name")
    settings = dict(data.get("settings", {}))
    require(isinstance(settings, dict), "settings", settings, "a table of calibrate's settings")
    film_settings = {k: settings.pop(k) for k in list(settings) if k in _FILM_SETTINGS}
    fields, values = _points(data)
    base = head.get("material")
    points = []
    for index, point in enumerate(values):
        label = ", ".join(f"{k} = {v!r}" for k, v in point.items())
        what = f"point {index} ({label})"
        changes = {k: v for k, v in point.items() if k != "material"}
        source = point.get("material", base)
        require(source is not None, "study.material", None, "the film (here or in each point)")
        try:
            material = load_micromagnetic_material(
                _material(source, folder, f"{what}: material"), **film_settings, **changes
            )
            CalibrationConfig(material=material, **settings)
        except ValidationError as err:
            found = split_error(err)
            raise InputError(f"{what}: {found.field}", found.value, found.allowed) from None
        except InputError as err:
            raise InputError(f"{what}: {err.field}", err.value, err.allowed) from None
        points.append(CalibrationPoint(index, point, material, settings))
    return CalibrationStudy(tuple(points), tuple(fields), source_text)


def load_study(path: str | Path, cell_size: float | None = None) -> CalibrationStudy:
    """Read and validate the study file ``path`` (see the module docstring).

    ``cell_size`` [m] (``--cell-size``) is the cell where ``[settings]`` gives none.
    """
    from skygas.core.config_types import read_toml

    path = Path(path)
    data = read_toml(path, "study file")
    if cell_size is not None:
        data.setdefault("settings", {}).setdefault("cell_size", cell_size)
    return parse_study(data, path.read_text(), path.parent)


def _finished(folder: Path, point: CalibrationPoint, settings: dict[str, Any]) -> dict | None:
    """The summary of the point's finished calibration in ``folder``; None if there is none.

    A folder whose calibration is of another film or other settings (the study file was
    changed, or ``--out`` holds another study) is refused in one line: its results are not
    the point's, and replacing them is the user's choice.
    """
    from skygas.calibration.plan import CalibrationConfig
    from skygas.runs import manifest
    from skygas.runs.run_driver import fingerprint

    try:
        data = json.loads((folder / "summary.json").read_text())
    except (OSError, ValueError):
        return None
    config = CalibrationConfig(material=point.material, **settings)
    found = (manifest.read(folder) or {}).get("config_hash")
    if found is not None and found != fingerprint(config.model_dump_json()):
        values = ", ".join(f"{k} = {v!r}" for k, v in point.values.items())
        raise InputError(
            "--out",
            str(folder.parent),
            f"a study folder whose {point.folder} is this study's point {point.index} "
            f"({values}); it holds the calibration of another film or other settings",
            "choose another --out (or remove that point's folder to calibrate it again)",
        )
    return data


def run_study(
    study: CalibrationStudy,
    out: str | Path,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = True,
    checkpoint_seconds: float | None = None,
    settings: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Calibrate every point of ``study`` not yet done into ``out/point-K``; write study.json.

    And the study's report.html (:func:`~skygas.calibration.study_report.write_study_report`).

    ``settings`` (the command line's) apply where the file's ``[settings]`` give none.

    Returns
    -------
    dict
        The contents of ``out/study.json``: ``points`` (each point's values, folder, whether
        it was computed now, and its numbers), ``fields``, ``study_file``, ``skygas_version``.
    """
    from skygas._version import __version__
    from skygas.calibration import calibrate
    from skygas.calibration.study_report import write_study_report
    from skygas.runs.run_driver import CHECKPOINT, write_json

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    options: dict[str, Any] = {"progress": progress}
    if checkpoint_seconds is not None:
        options["checkpoint_seconds"] = checkpoint_seconds
    rows = []
    for point in study.points:
        folder = out / point.folder
        merged = {**(settings or {}), **point.settings}
        data = _finished(folder, point, merged)
        computed = data is None
        if data is None:
            resume = (folder / CHECKPOINT).exists()
            data = calibrate(
                point.material,
                folder,
                workers=workers,
                scheduler=scheduler,
                resume=resume,
                **options,
                **merged,
            )
        rows.append(
            {
                **numbers(data),
                "values": point.values,
                "folder": point.folder,
                "computed_now": computed,
            }
        )
    record = {
        "fields": list(study.fields),
        "points": rows,
        "study_file": study.source_text,
        "skygas_version": __version__,
    }
    write_json(out / "study.json", record)
    write_study_report(record, out)
    return record


def numbers(data: dict) -> dict[str, Any]:
    """A calibration's headline numbers (from its ``summary.json``).

    The isolated skyrmion's radius [m], wall width [m], 𝒟 and G [kg/s], the laws' measured
    ranges [d_sk] and the validation's largest RMS centre error [d_sk] (None without one).
    """
    iso = data["isolated"]
    validation = data.get("validation", {})
    return {
        "radius_m": iso["radius"],
        "wall_width_m": iso["wall_width"],
        "dissipation": iso["dissipation"],
        "gyrocoupling_kg_per_s": iso["gyrocoupling"],
        "pair_measured_range_d_sk": data["pair"]["measured_range_d_sk"],
        "wall_measured_range_d_sk": data["wall_short_range"]["measured_range_d_sk"],
        "rms_error_max_d_sk": validation.get("rms_error_max_d_sk"),
    }
