"""From snapshots to a material preset: detect, track, measure G and 𝒟, extract forces, fit.

:func:`fit_trajectories` does the physics on trajectories (synthetic or detected);
:func:`fit_snapshots` reads a directory of OVF files, runs it, and writes the results.

Thiele coefficients (conventions of :func:`skygas.physics.materials.derive_thiele`): k = M_s t_F/γ,
G = −4π⟨Q⟩k with ⟨Q⟩ the median measured charge (the lattice charge rather than the integer, as
in the paper's measured G), and α𝒟k with ⟨𝒟⟩ the median measured dissipation. The laws' length
unit d_sk defaults to twice the median measured radius, and F₀ to A_ex t_F / d_sk, exactly what
the engine computes from the exported preset (which stores R_sk = d_sk/2).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from skygas._version import __version__
from skygas.core import units
from skygas.core.errors import InputError
from skygas.micromag import export, forces
from skygas.micromag.detection import detect_skyrmions
from skygas.micromag.ovf import read_mesh, read_ovf
from skygas.micromag.topology import unit_layer
from skygas.micromag.tracking import Trajectory, link
from skygas.physics.materials import Material, load_material
from skygas.runs.run_driver import write_atomic, write_figure, write_json

#: Why a fit writes no material.toml, when a requested law is not fixed by the data.
NO_PRESET = (
    "no material.toml: the data fix no law the engine accepts for {laws} (the "
    "tracks, the forces and the law tabulated over the measured range are written)"
)


@dataclass
class FitResult:
    """What the snapshots give.

    ``pair``, ``wall``: the fitted :class:`~forces.LawFit` or None; ``samples``: the force
    samples per law (d [d_sk], F [N]); ``tables``: each law tabulated over the measured range
    (:class:`~forces.LawTable`, always made); ``unfixed``: per law the
    :class:`~forces.UnfixedLawError` of a law the samples do not fix outside their range;
    ``tracks``: every trajectory; the Thiele coefficients used, all parameters, the preset
    (None when a requested law is unfixed) and the warnings.
    """

    pair: forces.LawFit | None
    wall: forces.LawFit | None
    samples: dict
    thiele: dict
    parameters: dict
    material: Material | None = None
    warnings: list[str] = field(default_factory=list)
    tables: dict = field(default_factory=dict)
    unfixed: dict = field(default_factory=dict)
    tracks: list[Trajectory] = field(default_factory=list)

    @property
    def no_material_reason(self) -> str | None:
        """Why there is no preset (None if there is one)."""
        if self.material is not None or not self.unfixed:
            return None
        return (
            NO_PRESET.format(laws=" and ".join(f"the {law} law" for law in self.unfixed))
            + ": "
            + "; ".join(
                f"{law} law: {err.why} (data: d = {err.fit.distance_range[0]:.2f}"
                f"–{err.fit.distance_range[1]:.2f} d_sk)"
                for law, err in self.unfixed.items()
            )
        )

    def as_record(self) -> dict:
        """The result as a JSON-able dict (``summary.json``)."""
        return {
            "skygas_version": __version__,
            "pair_law": None if self.pair is None else self.pair.as_record(),
            "wall_law": None if self.wall is None else self.wall.as_record(),
            "unfixed_laws": {
                law: {
                    "reason": err.why,
                    "unfixed": err.unfixed,
                    "remedy": err.remedy,
                    "unconstrained_fit": err.fit.as_record(),
                }
                for law, err in self.unfixed.items()
            },
            "tables": {law: table.as_record() for law, table in self.tables.items()},
            "material_toml": None if self.material is None else "material.toml",
            "no_material_toml": self.no_material_reason,
            "thiele": self.thiele,
            "parameters": self.parameters,
            "warnings": self.warnings,
            "tracks": [track_record(t) for t in self.tracks],
        }

    def write(self, out_dir: str | Path) -> dict[str, Path]:
        """Write the fit's files into ``out_dir``, each atomically.

        ``summary.json``, ``tracks.csv``, ``forces.csv``, ``<law>_table.csv``, ``fit.png`` and (when
        every requested law was fitted) ``material.toml``. A ``material.toml`` left in ``out_dir``
        by an earlier fit is removed when this fit has none, so that the folder never holds a preset
        the data no longer support.
        """
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        paths = {
            "json": out / "summary.json",
            "tracks": out / "tracks.csv",
            "csv": out / "forces.csv",
            "plot": out / "fit.png",
        }
        # The CSV files are plain tables (a header row, then numbers) that any CSV reader
        # takes; the skygas version and the parameters they were made with are in summary.json,
        # written with them, and in fit.png's text chunks (with the hash of the parameters as
        # config_hash, and the command line).
        rows = ["track,frame,time_s,x_m,y_m,radius_m,charge,dissipation"]
        for t in self.tracks:
            rows += [
                f"{t.id},{f},{time!r},{p.x!r},{p.y!r},{p.radius!r},{p.charge!r},{p.dissipation!r}"
                for f, time, p in zip(t.frames, t.times, t.points, strict=True)
            ]
        _write_text(paths["tracks"], rows)
        rows = ["law,distance_diameters,force_N"]
        for law, (d, f) in self.samples.items():
            rows += [f"{law},{a!r},{b!r}" for a, b in zip(d.tolist(), f.tolist(), strict=True)]
        _write_text(paths["csv"], rows)
        for law, table in self.tables.items():
            paths[f"{law}_table"] = out / f"{law}_table.csv"
            rows = [",".join(table.COLUMNS)]
            rows += [",".join(repr(v) for v in row.values()) for row in table.rows()]
            _write_text(paths[f"{law}_table"], rows)
        from skygas.runs.provenance import provenance

        parameters_json = json.dumps(self.parameters, default=str)
        # a fit draws no random numbers: its seed is "none"; its configuration is its parameters
        record = {
            **provenance(seed=None, config_json=parameters_json),
            "parameters_json": parameters_json,
        }
        del record["config_json"]  # the same text as parameters_json
        write_figure(
            paths["plot"],
            lambda tmp: export.plot_fits(
                tmp, self.samples, {"pair": self.pair, "wall": self.wall}, self.tables
            ),
            record,
        )
        material_path = out / "material.toml"
        material = self.material
        if material is not None:
            notes = [f"{k} = {v}" for k, v in self.parameters.items()]
            notes.append(
                f"force scale F0 = {self.thiele['force_scale_N']!r} N "
                "(= A_ex t_F / d_sk unless overridden at fit time)"
            )
            notes += [
                f"{fit.law} law fitted to {fit.n_points} samples over d = "
                f"{fit.distance_range[0]:.3f}–{fit.distance_range[1]:.3f} d_sk: {fit.describe()}"
                for fit in (self.pair, self.wall)
                if fit is not None
            ]
            notes += self.warnings
            paths["material"] = write_atomic(
                material_path, lambda tmp: export.write_material_toml(tmp, material, notes)
            )
        elif (
            material_path.is_file()
            and export.PRESET_MARK in material_path.read_text(errors="replace").partition("\n")[0]
        ):
            material_path.unlink()
        write_json(
            paths["json"],
            {
                **self.as_record(),
                "config_hash": record["config_hash"],
                "command_line": record["command_line"],
                "files": sorted(path.name for path in paths.values()),
            },
        )
        return paths


def _write_text(path: Path, lines: list[str]) -> Path:
    text = "\n".join(lines) + "\n"
    return write_atomic(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))


def track_record(track: Trajectory) -> dict:
    """One trajectory as JSON-able lists (SI units), the columns of ``tracks.csv``."""
    return {
        "id": track.id,
        "frames": list(track.frames),
        "time_s": list(track.times),
        "x_m": track.positions[:, 0].tolist(),
        "y_m": track.positions[:, 1].tolist(),
        "radius_m": track.radius.tolist(),
        "charge": track.charge.tolist(),
        "dissipation": track.dissipation.tolist(),
    }


def thiele_coefficients(
    charge: float,
    dissipation: float,
    material: Material,
    film_thickness: float,
    damping: float | None = None,
) -> dict:
    """k, G = −4πQk and α𝒟k [kg/s] from a measured charge Q and dissipation 𝒟."""
    alpha = material.damping if damping is None else damping
    k = material.saturation_magnetization * film_thickness / units.GYROMAGNETIC_RATIO
    return {
        "k": k,
        "gyrocoupling": -4.0 * math.pi * charge * k,
        "friction": alpha * dissipation * k,
        "charge": charge,
        "dissipation": dissipation,
        "damping": alpha,
    }


def fit_trajectories(
    trajectories: list[Trajectory],
    material: Material | str = "S2",
    *,
    film_thickness: float = 2e-9,
    law: str = "auto",
    boundary=None,
    skyrmion_diameter: float | None = None,
    force_scale: float | None = None,
    damping: float | None = None,
    charge: float | None = None,
    dissipation: float | None = None,
    window: int = 9,
    wall_degree: int = 5,
    table_bins: int | None = None,
    strict: bool = False,
) -> FitResult:
    """Fit the pair law (two trajectories) and/or the wall law (trajectories near ``boundary``).

    ``law``: "pair", "wall", "both" or "auto" (pair if two skyrmions coexist, else wall).
    Measured charge, 𝒟 and diameter are used unless given. Units: SI. Each law is also
    tabulated over the measured distances (``table_bins`` bins, see
    :func:`~forces.tabulate_law`).

    A law the samples do not fix outside their range (:class:`~forces.UnfixedLawError`: no
    decaying law, or a wall polynomial that fails the checks beyond the data) is left out:
    ``result.unfixed`` says why, one warning says what the data do not fix, and there is no
    preset (``result.material`` is None), since the engine would use that law where nothing
    measured it. With ``strict`` the error is raised instead. A law that rises inside its own
    data is always an error.
    """
    material = load_material(material)
    if law not in ("auto", "pair", "wall", "both"):
        raise InputError("law", law, "auto, pair, wall or both")
    if not film_thickness > 0:
        raise InputError("film_thickness", film_thickness, "a thickness > 0 in metres")
    tracks = [t for t in trajectories if len(t) >= 3]
    if not tracks:
        raise InputError("trajectories", len(trajectories), "at least one with >= 3 snapshots")
    if law == "auto":
        frames = [set(t.frames) for t in tracks]
        overlap = len(tracks) >= 2 and any(
            frames[i] & frames[j] for i in range(len(frames)) for j in range(i + 1, len(frames))
        )
        law = "pair" if overlap else "wall"
    points = [p for t in tracks for p in t.points]
    measured_q = float(np.median([p.charge for p in points])) if points else math.nan
    measured_d = float(np.median([p.dissipation for p in points])) if points else math.nan
    radii = np.array([p.radius for p in points], dtype=float)
    radii = radii[np.isfinite(radii)]  # no radius found: NaN, without numpy's warning
    measured_r = float(np.median(radii)) if radii.size else math.nan
    q = measured_q if charge is None else charge
    dis = measured_d if dissipation is None else dissipation
    diameter = 2.0 * measured_r if skyrmion_diameter is None else skyrmion_diameter
    if not (diameter > 0 and math.isfinite(q) and dis > 0):
        raise InputError(
            "trajectories",
            "no measured Q, 𝒟 or radius",
            "detected skyrmions, or charge, dissipation and skyrmion_diameter",
        )
    scale = (
        material.exchange_stiffness * film_thickness / diameter
        if force_scale is None
        else force_scale
    )
    thiele = thiele_coefficients(q, dis, material, film_thickness, damping)
    thiele.update(
        force_scale_N=scale,
        skyrmion_diameter_m=diameter,
        measured_charge=measured_q,
        measured_dissipation=measured_d,
        measured_radius_m=measured_r,
    )
    per_track = {}
    for t in tracks:
        v = forces.velocities(t.times, t.positions, window=window)
        per_track[t.id] = forces.thiele_forces(v, thiele["gyrocoupling"], thiele["friction"])
    unfixed: dict[str, forces.UnfixedLawError]
    samples, fits, warnings, unfixed = {}, {}, [], {}
    if law in ("pair", "both"):
        a, b = sorted(tracks, key=len, reverse=True)[:2] if len(tracks) >= 2 else (None, None)
        if a is None or b is None:  # both or neither
            raise InputError("law", "pair", "two skyrmion trajectories for a pair fit")
        common = sorted(set(a.frames) & set(b.frames))
        ia = [a.frames.index(f) for f in common]
        ib = [b.frames.index(f) for f in common]
        d, f = forces.pair_samples(
            a.positions[ia], per_track[a.id][ia], b.positions[ib], per_track[b.id][ib], diameter
        )
        samples["pair"] = (d, f)
        fits["pair"] = _fit_or_unfixed(forces.fit_pair_law, unfixed, strict, d, f, scale)
        if len(tracks) > 2:
            warnings.append(f"{len(tracks)} trajectories: the pair fit used the two longest")
    if law in ("wall", "both"):
        if boundary is None:
            raise InputError("boundary", None, "a wall geometry (DiskBoundary or LineBoundary)")
        parts = [
            forces.wall_samples(t.positions, per_track[t.id], boundary, diameter) for t in tracks
        ]
        d, f = (np.concatenate(x) for x in zip(*parts, strict=True))
        samples["wall"] = (d, f)
        fits["wall"] = _fit_or_unfixed(
            forces.fit_wall_law, unfixed, strict, d, f, scale, degree=wall_degree
        )
    tables = {
        name: forces.tabulate_law(name, *samples[name], diameter, scale, table_bins)
        for name in samples
    }
    result = FitResult(
        fits.get("pair"),
        fits.get("wall"),
        samples,
        thiele,
        {
            "base_material": material.name,
            "film_thickness_m": film_thickness,
            "law": law,
            "window": window,
            "wall_degree": wall_degree,
            "table_bins": table_bins,
            "strict": strict,
            "skygas_version": __version__,
        },
        tables=tables,
        unfixed=unfixed,
        tracks=list(trajectories),
    )
    for fit in (result.pair, result.wall):
        if fit is not None:
            warnings.extend(_coverage_notes(fit))
    for err in unfixed.values():
        warnings.append(_unfixed_warning(err))
    result.warnings.extend(warnings)
    if unfixed:
        # No preset: its unfixed law would have to be the base material's, a law that these
        # snapshots did not measure.
        return result
    # A preset the material model refuses is an error here, before anything is written.
    result.material = export.material_preset(
        material,
        name=f"{material.name}-fitted",
        pair_law=None if result.pair is None else result.pair.coefficients,
        wall_law=None if result.wall is None else result.wall.coefficients,
        skyrmion_radius=diameter / 2.0,
        dissipation=dis,
        damping=thiele["damping"],
        topological_charge=-1 if q < 0 else 1,
    )
    return result


def _fit_or_unfixed(fit_law, unfixed: dict, strict: bool, d, f, scale, **options):
    """``fit_law(d, f, scale)``, or None with the law's error put in ``unfixed``.

    The error is a :class:`~forces.UnfixedLawError`; with ``strict`` it is raised instead.
    """
    try:
        return fit_law(d, f, scale, **options)
    except forces.UnfixedLawError as err:
        if strict:
            raise
        unfixed[err.fit.law] = err
        return None


def _unfixed_warning(err: forces.UnfixedLawError) -> str:
    """One line: what the data do not fix, why, what was written instead and what to do."""
    lo, hi = err.fit.distance_range
    return (
        f"{err.fit.law} law: the samples (d = {lo:.2f}–{hi:.2f} d_sk) do not fix "
        f"{err.unfixed}: {err.why}; wrote the tracks, the forces and the law tabulated "
        f"over the measured range, no material.toml ({err.remedy}, or use `skygas "
        "calibrate`)"
    )


def _coverage_notes(fit: forces.LawFit) -> list[str]:
    """What a user must know about a fitted law.

    A constrained refit, and the distances at which the engine will use it beyond those the data
    covered (an extrapolation).
    """
    notes = [fit.note] if fit.note else []
    closest, cutoff = forces.engine_range(fit.law, fit.coefficients)
    lo, hi = fit.distance_range
    if lo > closest or hi < cutoff:
        notes.append(
            f"{fit.law} law: the engine uses it from {closest:.2f} to {cutoff:.2f} d_sk "
            f"(its cutoff); the data covered {lo:.2f}–{hi:.2f} d_sk, beyond that the "
            "law is an extrapolation"
        )
    return notes


def snapshot_paths(directory: str | Path, pattern: str = "*.ovf") -> list[Path]:
    """The snapshot files of ``directory`` matching ``pattern``, sorted by name."""
    directory = Path(directory)
    if not directory.is_dir():
        raise InputError("snapshot_dir", str(directory), "an existing directory")
    paths = sorted(directory.glob(pattern))
    if len(paths) < 3:
        raise InputError(
            "snapshot_dir", f"{len(paths)} files matching {pattern!r}", "at least 3 snapshot files"
        )
    return paths


def check_one_grid(directory: str | Path, paths: list[Path]) -> None:
    """Refuse a folder whose snapshots are not all on the first file's mesh.

    The mesh: node counts, cell sizes, corner. The error names the first file that differs and how;
    only the headers are read.

    Two runs in one folder (a restart on a finer mesh, another sample) would otherwise be
    tracked as one: skyrmions would jump between frames and the forces would be nonsense.
    """
    reference = read_mesh(paths[0])
    for path in paths[1:]:
        mesh = read_mesh(path)
        if not mesh.same_grid(reference):
            corner = mesh.nodes == reference.nodes and all(
                math.isclose(a, b, rel_tol=1e-6)
                for a, b in zip(mesh.cell, reference.cell, strict=True)
            )
            raise InputError(
                "snapshot_dir",
                str(directory),
                f"snapshots of one grid; {path.name} has {mesh.describe(corner)}, "
                f"{paths[0].name} {reference.describe(corner)}",
                "fit one run at a time (move the other files out, or choose them with --pattern)",
            )


def fit_snapshots(
    directory: str | Path,
    out_dir: str | Path | None = None,
    *,
    pattern: str = "*.ovf",
    interval: float | None = None,
    max_step: float | None = None,
    threshold: float = 0.0,
    edge_band: bool = True,
    **fit_options,
) -> FitResult:
    """Read OVF snapshots, detect and track skyrmions, fit the laws, and write to ``out_dir``.

    Every file must be on the same mesh (:func:`check_one_grid`, before any file is read).
    Times come from each file's "Total simulation time" unless ``interval`` [s] is given.
    ``max_step`` [m] gates the tracking (default: one measured skyrmion radius). For a wall
    fit the boundary is the disk of the first snapshot's magnetic cells unless
    ``boundary`` is given. ``threshold`` and ``edge_band`` go to
    :func:`~skygas.micromag.detection.detect_skyrmions`; other options to
    :func:`fit_trajectories`.
    """
    if interval is not None and not interval > 0:
        raise InputError("interval", interval, "a snapshot interval > 0 in seconds")
    paths = snapshot_paths(directory, pattern)
    check_one_grid(directory, paths)
    snaps, first = [], None
    for path in paths:
        field_ = read_ovf(path)
        first = field_ if first is None else first
        snaps.append(detect_skyrmions(field_, threshold=threshold, edge_band=edge_band))
    if interval is not None:
        times = [i * interval for i in range(len(snaps))]
    else:
        times = [s.time for s in snaps]
        if not all(math.isfinite(t) for t in times):
            raise InputError(
                "interval",
                None,
                "a snapshot interval in seconds: the files give no 'Total simulation time'",
            )
    radii = [s.radius for snap in snaps for s in snap.skyrmions if math.isfinite(s.radius)]
    if not radii:
        raise InputError("snapshot_dir", str(directory), "snapshots containing skyrmions")
    step = float(np.median(radii)) if max_step is None else max_step
    trajectories = link(snaps, max_step=step, times=times)
    if (
        fit_options.get("law", "auto") in ("auto", "wall", "both")
        and fit_options.get("boundary") is None
    ):
        assert first is not None  # snapshot_paths gave at least 3 files
        _, magnetic = unit_layer(first)
        if not magnetic.all():
            fit_options["boundary"] = forces.disk_from_mask(
                magnetic, first.x.values, first.y.values
            )
    result = fit_trajectories(trajectories, **fit_options)
    result.parameters.update(
        snapshot_dir=str(directory),
        pattern=pattern,
        n_snapshots=len(paths),
        interval_s=interval,
        max_step_m=step,
        threshold=threshold,
        edge_band="exclude" if edge_band else "keep",
        n_trajectories=len(trajectories),
    )
    if out_dir is not None:
        result.write(out_dir)
    return result
