"""From snapshots to a material preset: detect, track, measure G and 𝒟, extract forces, fit.

:func:`fit_trajectories` does the physics on trajectories (synthetic or detected);
:func:`fit_snapshots` reads a directory of OVF files, runs it, and writes the results.

Thiele coefficients (conventions of :func:`skygas.materials.derive_thiele`): k = M_s t_F/γ,
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

from skygas import units
from skygas._version import __version__
from skygas.errors import InputError
from skygas.materials import Material, load_material
from skygas.micromag import export, forces
from skygas.micromag.detection import detect_skyrmions
from skygas.micromag.ovf import read_ovf
from skygas.micromag.topology import unit_layer
from skygas.micromag.tracking import Trajectory, link


@dataclass
class FitResult:
    """Fitted laws (``pair``, ``wall``: :class:`~forces.LawFit` or None), the force samples
    per law (d, |F| [N]), the Thiele coefficients used, all parameters, and warnings."""

    pair: forces.LawFit | None
    wall: forces.LawFit | None
    samples: dict
    thiele: dict
    parameters: dict
    material: Material | None = None
    warnings: list[str] = field(default_factory=list)

    def as_record(self) -> dict:
        return {
            "skygas_version": __version__,
            "pair_law": None if self.pair is None else self.pair.as_record(),
            "wall_law": None if self.wall is None else self.wall.as_record(),
            "thiele": self.thiele, "parameters": self.parameters, "warnings": self.warnings,
        }

    def write(self, out_dir: str | Path) -> dict[str, Path]:
        """Write ``fit.json``, ``forces.csv``, ``fit.png`` and ``material.toml``."""
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        paths = {"json": out / "fit.json", "csv": out / "forces.csv", "plot": out / "fit.png"}
        rows = ["law,distance_diameters,force_N"]
        for law, (d, f) in self.samples.items():
            rows += [f"{law},{a!r},{b!r}" for a, b in zip(d.tolist(), f.tolist())]
        paths["csv"].write_text("\n".join(rows) + "\n")
        export.plot_fits(paths["plot"], self.samples, {"pair": self.pair, "wall": self.wall})
        if self.material is not None:
            notes = [f"{k} = {v}" for k, v in self.parameters.items()]
            notes.append(f"force scale F0 = {self.thiele['force_scale_N']!r} N "
                         "(= A_ex t_F / d_sk unless overridden at fit time)")
            notes += [f"{fit.law} law fitted to {fit.n_points} samples over d = "
                      f"{fit.distance_range[0]:.3f}–{fit.distance_range[1]:.3f} d_sk"
                      for fit in (self.pair, self.wall) if fit is not None]
            notes += self.warnings
            paths["material"] = export.write_material_toml(out / "material.toml",
                                                           self.material, notes)
        paths["json"].write_text(json.dumps(self.as_record(), indent=2) + "\n")
        return paths


def thiele_coefficients(charge: float, dissipation: float, material: Material,
                        film_thickness: float, damping: float | None = None) -> dict:
    """k, G = −4πQk and α𝒟k [kg/s] from a measured charge Q and dissipation 𝒟."""
    alpha = material.damping if damping is None else damping
    k = material.saturation_magnetization * film_thickness / units.GYROMAGNETIC_RATIO
    return {"k": k, "gyrocoupling": -4.0 * math.pi * charge * k,
            "friction": alpha * dissipation * k, "charge": charge, "dissipation": dissipation,
            "damping": alpha}


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
) -> FitResult:
    """Fit the pair law (two trajectories) and/or the wall law (trajectories near ``boundary``).

    ``law``: "pair", "wall", "both" or "auto" (pair if two skyrmions coexist, else wall).
    Measured charge, 𝒟 and diameter are used unless given. Units: SI.
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
        overlap = len(tracks) >= 2 and any(frames[i] & frames[j] for i in range(len(frames))
                                           for j in range(i + 1, len(frames)))
        law = "pair" if overlap else "wall"
    points = [p for t in tracks for p in t.points]
    measured_q = float(np.median([p.charge for p in points])) if points else math.nan
    measured_d = float(np.median([p.dissipation for p in points])) if points else math.nan
    measured_r = float(np.nanmedian([p.radius for p in points])) if points else math.nan
    q = measured_q if charge is None else charge
    dis = measured_d if dissipation is None else dissipation
    diameter = 2.0 * measured_r if skyrmion_diameter is None else skyrmion_diameter
    if not (diameter > 0 and math.isfinite(q) and dis > 0):
        raise InputError("trajectories", "no measured Q, 𝒟 or radius",
                         "detected skyrmions, or charge, dissipation and skyrmion_diameter")
    scale = material.exchange_stiffness * film_thickness / diameter \
        if force_scale is None else force_scale
    thiele = thiele_coefficients(q, dis, material, film_thickness, damping)
    thiele.update(force_scale_N=scale, skyrmion_diameter_m=diameter,
                  measured_charge=measured_q, measured_dissipation=measured_d,
                  measured_radius_m=measured_r)
    per_track = {}
    for t in tracks:
        v = forces.velocities(t.times, t.positions, window=window)
        per_track[t.id] = forces.thiele_forces(v, thiele["gyrocoupling"], thiele["friction"])
    samples, fits, warnings = {}, {}, []
    if law in ("pair", "both"):
        a, b = sorted(tracks, key=len, reverse=True)[:2] if len(tracks) >= 2 else (None, None)
        if a is None:
            raise InputError("law", "pair", "two skyrmion trajectories for a pair fit")
        common = sorted(set(a.frames) & set(b.frames))
        ia = [a.frames.index(f) for f in common]
        ib = [b.frames.index(f) for f in common]
        d, f = forces.pair_samples(a.positions[ia], per_track[a.id][ia], b.positions[ib],
                                   per_track[b.id][ib], diameter)
        samples["pair"] = (d, f)
        fits["pair"] = forces.fit_pair_law(d, f, scale)
        if len(tracks) > 2:
            warnings.append(f"{len(tracks)} trajectories: the pair fit used the two longest")
    if law in ("wall", "both"):
        if boundary is None:
            raise InputError("boundary", None, "a wall geometry (DiskBoundary or LineBoundary)")
        parts = [forces.wall_samples(t.positions, per_track[t.id], boundary, diameter)
                 for t in tracks]
        d, f = (np.concatenate(x) for x in zip(*parts))
        samples["wall"] = (d, f)
        fits["wall"] = forces.fit_wall_law(d, f, scale, degree=wall_degree)
    result = FitResult(fits.get("pair"), fits.get("wall"), samples, thiele, {
        "base_material": material.name, "film_thickness_m": film_thickness, "law": law,
        "window": window, "wall_degree": wall_degree, "skygas_version": __version__})
    for fit in (result.pair, result.wall):
        if fit is not None:
            warnings.extend(_coverage_notes(fit))
    result.warnings.extend(warnings)
    # A preset the material model refuses is an error here, before anything is written.
    result.material = export.material_preset(
        material, name=f"{material.name}-fitted",
        pair_law=None if result.pair is None else result.pair.coefficients,
        wall_law=None if result.wall is None else result.wall.coefficients,
        skyrmion_radius=diameter / 2.0, dissipation=dis,
        damping=thiele["damping"],
        topological_charge=-1 if q < 0 else 1)
    return result


def _coverage_notes(fit: forces.LawFit) -> list[str]:
    """What a user must know about a fitted law: a constrained refit, and the distances at which
    the engine will use it beyond those the data covered (an extrapolation)."""
    notes = [fit.note] if fit.note else []
    closest, cutoff = forces.engine_range(fit.law, fit.coefficients)
    lo, hi = fit.distance_range
    if lo > closest or hi < cutoff:
        notes.append(f"{fit.law} law: the engine uses it from {closest:.2f} to {cutoff:.2f} d_sk "
                     f"(its cutoff); the data covered {lo:.2f}–{hi:.2f} d_sk, beyond that the "
                     "law is an extrapolation")
    return notes


def snapshot_paths(directory: str | Path, pattern: str = "*.ovf") -> list[Path]:
    """The snapshot files of ``directory`` matching ``pattern``, sorted by name."""
    directory = Path(directory)
    if not directory.is_dir():
        raise InputError("snapshot_dir", str(directory), "an existing directory")
    paths = sorted(directory.glob(pattern))
    if len(paths) < 3:
        raise InputError("snapshot_dir", f"{len(paths)} files matching {pattern!r}",
                         "at least 3 snapshot files")
    return paths


def fit_snapshots(
    directory: str | Path,
    out_dir: str | Path | None = None,
    *,
    pattern: str = "*.ovf",
    interval: float | None = None,
    max_step: float | None = None,
    threshold: float = 0.0,
    **fit_options,
) -> FitResult:
    """Read OVF snapshots, detect and track skyrmions, fit the laws, and write to ``out_dir``.

    Times come from each file's "Total simulation time" unless ``interval`` [s] is given.
    ``max_step`` [m] gates the tracking (default: one measured skyrmion radius). For a wall
    fit the boundary is the disk of the first snapshot's magnetic cells unless
    ``boundary`` is given. Other options go to :func:`fit_trajectories`.
    """
    if interval is not None and not interval > 0:
        raise InputError("interval", interval, "a snapshot interval > 0 in seconds")
    paths = snapshot_paths(directory, pattern)
    snaps, first = [], None
    for path in paths:
        field_ = read_ovf(path)
        first = field_ if first is None else first
        snaps.append(detect_skyrmions(field_, threshold=threshold))
    if interval is not None:
        times = [i * interval for i in range(len(snaps))]
    else:
        times = [s.time for s in snaps]
        if not all(math.isfinite(t) for t in times):
            raise InputError("interval", None, "a snapshot interval in seconds: the files give "
                             "no 'Total simulation time'")
    radii = [s.radius for snap in snaps for s in snap.skyrmions if math.isfinite(s.radius)]
    if not radii:
        raise InputError("snapshot_dir", str(directory), "snapshots containing skyrmions")
    step = float(np.median(radii)) if max_step is None else max_step
    trajectories = link(snaps, max_step=step, times=times)
    if fit_options.get("law", "auto") in ("auto", "wall", "both") and \
            fit_options.get("boundary") is None:
        _, magnetic = unit_layer(first)
        if not magnetic.all():
            fit_options["boundary"] = forces.disk_from_mask(magnetic, first.x.values,
                                                            first.y.values)
    result = fit_trajectories(trajectories, **fit_options)
    result.parameters.update(snapshot_dir=str(directory), pattern=pattern, n_snapshots=len(paths),
                             interval_s=interval, max_step_m=step, threshold=threshold,
                             n_trajectories=len(trajectories))
    if out_dir is not None:
        result.write(out_dir)
    return result
