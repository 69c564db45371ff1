"""``infer``: tracks → the forces the data show, D and the Hall angle → a model, checked.

The steps, each in its own module of :mod:`skygas.inference`:

1. tracks in SI, unwrapped if they wrap around a periodic box, a drift of the view removed
   where it is one (:mod:`~skygas.inference.tracks`);
2. the film: walls, an open field of view (tracks leave and enter), or a periodic box
   (:mod:`~skygas.inference.film`);
3. the candidate forces, sized from the tracks: a landscape, a pair law, a wall law, a drive
   (:mod:`~skygas.inference.candidates`), and the displacements projected onto them
   (:mod:`~skygas.inference.dynamics`): D from the noise, the Hall angle and every force from
   the drift, jointly;
4. the terms the data show, by held-out likelihood, with jackknife errors
   (:mod:`~skygas.inference.forces`); the landscape on a grid with the area it is fixed on
   (:mod:`~skygas.inference.maps`);
5. cross-checks where the gas is in equilibrium: the landscape by Boltzmann inversion
   (:mod:`~skygas.inference.landscape`, the neighbours' mean push taken out by
   :mod:`~skygas.inference.crowding`) and the wall by the density against the distance to the
   edge (:mod:`~skygas.inference.wall`);
6. the model (:mod:`~skygas.inference.model`) and its self-check: runs of it must reproduce
   the movie's MSD(τ), g(r) and density map within their errors
   (:mod:`~skygas.inference.selfcheck`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from skygas._version import __version__
from skygas.analysis.frames import Frames
from skygas.core import units
from skygas.core.errors import require
from skygas.inference import (
    candidates,
    crowding,
    dynamics,
    forces,
    maps,
    model,
    sampling,
    selfcheck,
    wall,
)
from skygas.inference import diffusion as diff
from skygas.inference import landscape as land
from skygas.inference.film import EDGE_STEPS, Film, box_film, field_of_view, tracks_leave
from skygas.inference.outline import read_outline
from skygas.inference.tracks import Tracks, load_tracks, metres, pixel_size_for
from skygas.physics.materials import derive_thiele, load_material

#: Largest share of positions allowed outside the outline (by more than a pixel).
OUTSIDE_SHARE = 0.01
#: The pair and wall forces are "fixed" where their jackknife error is at most this share.
FIXED_SHARE = 0.05
#: Frames of the self-check's model run at most.
CHECK_FRAMES = 2000
#: Points of a written force table.
TABLE_POINTS = 24
#: The map's grid: about this many nodes along the film's longer side.
MAP_NODES = 120
#: The model's landscape map, beside model.toml (model.toml's ``[[potentials]]`` names it).
MAP_FILE = "landscape-map.npy"
#: The modes of ``pair`` and ``walls``.
PAIR_MODES = ("none", "infer", "material")
WALL_MODES = ("none", "infer", "outline")


@dataclass
class Inference:
    """What :func:`infer` found: ``summary`` (inference.json) and what the files are made of."""

    summary: dict
    forces: forces.ForceInference
    film: Film
    tracks: Tracks
    map: maps.ForceMap
    boltzmann: np.ndarray | None
    boltzmann_error: np.ndarray | None
    wall_profile: wall.WallProfile | None
    material: dict
    potentials: list
    map_values: np.ndarray
    check: dict | None


def _check_inside(frames: Frames, film: Film, pixel_size: float, source: str) -> None:
    x, y = film.wrap(frames.x, frames.y)
    d = wall.wall_distance(film.outline, x, y)
    outside = float(np.mean(d < -pixel_size))
    require(
        outside <= OUTSIDE_SHARE,
        "--outline",
        source,
        f"an outline around the tracks ({100 * outside:.1f} % of the positions lie outside it "
        f"by more than a pixel; at most {100 * OUTSIDE_SHARE:g} % allowed)",
        "check --pixel-size and that the outline is on the tracks' pixel grid (x = column, "
        "y = row) or in metres",
    )


def _film(data: Tracks, shape, walls: str, step: float) -> tuple[Film, str]:
    """The film of the tracks (``shape``: the outline given, or None), and how it was decided."""
    frames = data.frames
    if data.box is not None:
        return box_film(*data.box), "periodic: the tracks wrap around a box"
    if shape is None:
        fov = field_of_view(frames, 0.5 * data.pixel_size)
        return Film("open", fov), "open: no outline given, the field of view is the tracks' extent"
    if walls != "outline" and tracks_leave(frames, shape, step):
        return Film("open", shape), "open: tracks end and start at the outline"
    return Film("walls", shape), "walls: no track leaves through the outline"


def _skyrmion_radius(given, base, pair_range) -> tuple[float, str]:
    """The model's length unit: given, the base material's, or a quarter of the closest pairs."""
    if given is not None:
        return float(given), "given (--skyrmion-radius)"
    if pair_range is not None and pair_range[0] / 4 > 2 * base.skyrmion_radius:
        return float(pair_range[0] / 4), (
            "a quarter of the closest distance between tracked skyrmions (the base material's "
            f"{base.skyrmion_radius:.3g} m is far smaller than what the tracks show)"
        )
    return float(base.skyrmion_radius), f"the base material's ({base.name})"


def _radial_summary(
    result: forces.ForceInference,
    term: str,
    kt: float,
    numbers,
    correction,
    coarse: bool = False,
) -> dict | None:
    """The pair or wall force of ``numbers`` with its jackknife error over its range [N].

    ``coarse``: the frames are too coarse for the forces (the sampling correction did not
    converge), so no distance is fixed whatever the errors say: they see the noise, not the
    bias of frames that blur the motion.
    """
    basis = getattr(result.basis, term)
    if basis is None or term not in result.terms:
        return None
    cols = result.basis.columns[term]
    r = np.linspace(basis.lo, basis.hi, 25)[:-1]

    def force(fit):
        return basis.force(r, fit.theta[cols])

    def pot(fit):
        return _potential(basis, r, fit.theta[cols])

    f = basis.force(r, numbers.theta[cols])
    potential = _potential(basis, r, numbers.theta[cols])
    _, err = result.jackknife(force)
    _, potential_err = result.jackknife(pot)
    if correction is not None:
        err = correction.error(force, err)
        potential_err = correction.error(pot, potential_err)
    fixed = (f > 0) & (err <= FIXED_SHARE * np.abs(f)) & (not coarse)
    run = np.flatnonzero(fixed)
    return {
        "r_m": r.tolist(),
        "force_N": (f * kt).tolist(),
        "force_error_N": (err * kt).tolist(),
        "potential_kT": potential.tolist(),
        "potential_error_kT": potential_err.tolist(),
        "fixed_range_m": [float(r[run[0]]), float(r[run[-1]])] if len(run) else None,
        "fixed_definition": f"where the force is repulsive and its jackknife error at most "
        f"{100 * FIXED_SHARE:g} % of it",
        "basis": {"closest_m": basis.lo, "farthest_m": basis.hi, "splines": basis.count},
    }


def _potential(basis, r: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """V(r) = ∫_r^hi f [k_BT] of a radial force (0 at the end of its range)."""
    fine = np.linspace(basis.lo, basis.hi, 400)
    f = basis.force(fine, theta)
    tail = np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(fine))])
    return np.interp(r, fine, tail[-1] - tail)


def infer(
    source,
    *,
    pixel_size: float | None,
    frame_interval: float | None,
    temperature: float,
    outline=None,
    walls: str = "infer",
    pair: str = "infer",
    periodic="auto",
    base_material="S2",
    skyrmion_radius: float | None = None,
    subtract_drift: str = "auto",
    check_frames: int | None = CHECK_FRAMES,
    seed: int = 0,
    progress=None,
) -> Inference:
    """Infer the particle model of a tracked skyrmion gas (docs/inference.md).

    Parameters
    ----------
    source : DataFrame or path
        trackpy's table (``frame``, ``particle``, ``x``, ``y`` in pixels) or its file.
    pixel_size, frame_interval : float
        Metres per pixel, seconds per frame.
    temperature : float
        T [K] of the film.
    outline : path or Outline, optional
        The device or the field of view: a CSV of x,y vertices [m] or a binary mask on the
        tracks' pixel grid. Without one, the field of view is the tracks' extent.
    walls : {"infer", "none", "outline"}
        A wall force where the held-out likelihood asks for one (``infer``), never, or always
        where the outline is a wall (``outline``).
    pair : {"infer", "none", "material"}
        A pair law fitted to these tracks where the held-out likelihood asks for one, none, or
        the base material's law (its amplitude checked against the tracks).
    periodic : "auto", None or (L_x, L_y)
        Tracks that wrap around a periodic box: found (``auto``), ruled out, or declared [m].
    base_material : str or Material
        Supplies what tracks cannot measure (M_s, film thickness, α; the pair law of
        ``pair = "material"``); default S2.
    skyrmion_radius : float, optional
        R [m], the model's length unit (default: the base material's, or a quarter of the
        closest distance between tracked skyrmions where that is far larger).
    subtract_drift : {"auto", "yes", "no"}
        See :func:`skygas.inference.tracks.load_tracks`.
    check_frames : int or None
        Frames of the self-check's model run (at most the movie's); None: no self-check.
    seed : int
        Seeds the self-check's run and the cross-check's bootstrap.
    progress : callable, optional
        Called with a line of text as each step starts.
    """
    say = progress or (lambda text: None)
    require(
        np.isfinite(temperature) and temperature > 0,
        "--temperature",
        temperature,
        "the film's temperature in kelvin, > 0",
    )
    require(walls in WALL_MODES, "--walls", walls, " or ".join(WALL_MODES))
    require(pair in PAIR_MODES, "--pair", pair, " or ".join(PAIR_MODES))
    base = load_material(base_material)
    if skyrmion_radius is not None:
        metres("--skyrmion-radius", skyrmion_radius)
    kt = units.BOLTZMANN * temperature
    # a track folder's track.json holds the pixel size its tracks were made with
    pixel_size, note = pixel_size_for(source, pixel_size)
    if note is not None:
        say(note)
    # the outline's file is judged before the tracks are worked on (a mask needs the pixel size)
    shape = None
    if outline is not None and pixel_size is not None:
        shape = read_outline(outline, metres("--pixel-size", pixel_size))

    data = load_tracks(
        source, pixel_size, frame_interval, subtract_drift=subtract_drift, period=periodic
    )
    frames = data.frames
    require(
        frames.n_frames >= 2 * dynamics.BLOCKS,
        "tracks.frame",
        f"{frames.n_frames} frames",
        f"at least {2 * dynamics.BLOCKS} frames (errors are blocked over {dynamics.BLOCKS} "
        "blocks of time)",
    )
    if shape is not None:
        require(
            data.box is None,
            "--outline",
            str(outline),
            "no outline for tracks in a periodic box (they wrap: the box is the film)",
            "leave --outline out, or give --periodic none if the tracks do not wrap",
        )
        _check_inside(frames, Film("walls", shape), data.pixel_size, str(outline))
    loose = Film("open", field_of_view(frames, data.pixel_size))
    first_steps = dynamics.make_steps(frames, loose if data.box is None else box_film(*data.box))
    require(
        len(first_steps) >= 100,
        "tracks",
        data.source,
        f"tracks of at least three frames each, 100 steps in all ({len(first_steps)} here)",
        "link the features with a larger memory, or track a longer movie",
    )
    d_rough = (
        np.mean(first_steps.dx**2 + first_steps.dy**2)
        + 2 * np.mean(first_steps.dx * first_steps.px + first_steps.dy * first_steps.py)
    ) / (4 * first_steps.dt)
    require(
        d_rough > 0,
        "tracks",
        data.source,
        "skyrmions that move (the noise of their steps reads D ≤ 0)",
    )
    step = math.sqrt(2 * d_rough * frames.frame_interval())
    film, film_reason = _film(data, shape, walls, step)
    say(
        f"{len(frames.x)} positions in {frames.n_frames} frames, {len(np.unique(frames.ids))} "
        f"tracks; film: {film_reason}"
    )

    keep = None
    if film.kind == "open":
        keep = wall.wall_distance(film.outline, frames.x, frames.y) >= EDGE_STEPS * step
    steps = dynamics.make_steps(frames, film, keep)
    require(
        len(steps) >= 100,
        "tracks",
        data.source,
        f"at least 100 steps farther than {EDGE_STEPS:g} rms steps from the edge of the "
        f"field of view ({len(steps)} here)",
        "track a larger field of view or a longer movie",
    )
    material_law, material_range = None, 0.0
    if pair == "material":
        law = crowding.material_law({}, base, temperature)
        material_law = law
        material_range = crowding.reach(law, 0.25 * base.skyrmion_radius, 50 * base.skyrmion_radius)
    basis = candidates.build(
        frames,
        film,
        step,
        pair=pair,
        walls=walls,
        material_law=material_law,
        material_range=material_range,
    )
    say(
        f"projecting {len(steps)} steps onto {basis.size} force fields ("
        + ", ".join(
            t for t in ("landscape", "pair", "material_pair", "wall", "drive") if basis.has(t)
        )
        + ")"
    )
    moments = dynamics.accumulate(frames, steps, basis)
    fixed = tuple(
        t
        for t, asked in (("wall", walls == "outline"), ("material_pair", pair == "material"))
        if asked and basis.has(t)
    )
    say("choosing the terms the data show (held-out likelihood over blocks of time)")
    result = forces.infer_forces(moments, basis, fixed=fixed, progress=say)

    say("the landscape on a grid, its errors and the area it is fixed on")
    x0, y0, x1, y1 = film.outline.bounds
    fmap = maps.force_map(result, frames, max(x1 - x0, y1 - y0) / MAP_NODES)
    interior = None
    if "wall" in result.terms and result.basis.wall is not None:
        gx, gy = np.meshgrid(fmap.grid.x, fmap.grid.y)
        interior = wall.wall_distance(film.outline, gx, gy) >= result.basis.wall.hi
    stats = maps.statistics(fmap, interior)
    stats_area = "well sampled"
    if stats["rms_kT"] is None and fmap.sampled.sum() >= 4:
        rough = maps.ForceMap(
            fmap.grid, fmap.u, fmap.error, fmap.sampled, fmap.sampled, fmap.film, fmap.replicas
        )
        stats = maps.statistics(rough, interior)
        stats_area = "sampled (no node is well sampled: the statistics carry the map's noise)"

    hall_value, hall_spread = result.jackknife(lambda f: f.hall_angle)
    hall_fixed = result.hall_angle_fixed
    hall_note = None
    if hall_fixed:
        hall_model = float(hall_value)
    else:
        t_base = derive_thiele(base)
        hall_model = math.atan2(t_base.gyrocoupling, t_base.friction)
        hall_note = (
            "not fixed: the data show no force that turns (no landscape, pair or wall "
            f"force); the model keeps the base material's {math.degrees(hall_model):.1f}°"
        )

    pair_range = (basis.pair.lo, basis.pair.hi) if basis.pair is not None else None
    radius, radius_source = _skyrmion_radius(skyrmion_radius, base, pair_range)
    base_sized = base.model_copy(update={"skyrmion_radius": radius})

    # the model's landscape: the map where the film was sampled, its statistics elsewhere
    map_values = np.where(fmap.sampled, fmap.u, np.nan)
    landscape_table = None
    if "landscape" in result.terms and np.isfinite(map_values).any():
        landscape_table = {
            "kind": "measured",
            "path": MAP_FILE,
            "spacing": float(fmap.grid.h),
            "origin": [float(fmap.grid.x[0]), float(fmap.grid.y[0])],
            "rms_kT": float(stats["rms_kT"] or 0.0),
            "correlation_length": float(stats["correlation_length_m"] or 4 * fmap.grid.h),
        }

    def build(numbers: sampling.ModelNumbers) -> model.Model:
        return model.build(
            numbers,
            basis,
            result.terms,
            base_sized,
            temperature,
            hall_fixed=hall_fixed,
            hall_error=float(hall_spread),
            landscape=landscape_table,
            map_values=map_values,
        )

    def run(built: model.Model, n_frames: int, run_seed: int) -> selfcheck.ModelRun:
        return _run_model(film, built, data, result, n_frames, temperature, run_seed)

    check_length = min(check_frames or 0, frames.n_frames)
    numbers = sampling.numbers_of(result, hall_model)
    correction: sampling.Correction | None = None
    coarse = sampling.coarseness(result)
    if abs(coarse) >= sampling.COARSE_SHARE and check_length:
        say(
            f"the drift within a frame is {100 * coarse:.0f} % of the steps' spread: measuring "
            "the estimator's bias on runs of the model"
        )
        correction = sampling.correct(
            result,
            hall_model,
            film,
            lambda n: run(build(n), check_length, seed + 2000),
            step,
            progress=say,
        )
        numbers = correction.numbers
    coarse_note = None
    correction_used = correction
    if correction is not None and not correction.converged:
        # the runs of the model never read what the movie reads: no D, θ_H or force is fixed
        # by these frames. The model keeps the numbers as read (the data's own, not a guess
        # moved by a correction that runs away) and says so.
        coarse_note = (
            "the frames are too coarse for the forces: runs of the model do not read what the "
            "movie reads, however it is moved (sampling_correction); D, the Hall angle and the "
            "forces are not fixed by these data, and the model keeps them as read"
        )
        numbers = sampling.numbers_of(result, hall_model)
        correction = None
    built = build(numbers)

    equilibrium = "drive" not in result.terms
    boltzmann = boltzmann_err = None
    cross = None
    wprof = None
    bi = None
    if equilibrium:
        say("cross-check: the landscape by Boltzmann inversion (the gas is in equilibrium)")
        boltzmann, boltzmann_err, cross, bi = _boltzmann_check(result, film, frames, fmap)
        if film.kind == "walls":
            wprof = _wall_cross_check(result, film, frames, fmap)

    check = None
    if check_length:
        say("self-check: runs of the written model against the movie")
        check_run = run(built, check_length, seed + 1000)
        check = _compare(film, frames, check_run, result, fmap, bi, check_length, seed)

    hall_err = float(hall_spread)
    d_err = result.diffusion_error
    if coarse_note is not None:
        hall_fixed = False
        hall_note = coarse_note
    if correction is not None and correction.run is not None:
        _, run_hall = correction.run.jackknife(lambda f: f.hall_angle)
        hall_err = float(np.hypot(np.hypot(hall_err, run_hall), correction.hall_spread))
        d_err = float(
            np.hypot(np.hypot(d_err, correction.run.diffusion_error), correction.diffusion_spread)
        )
    hall = numbers.hall_angle if hall_fixed else None

    d_msd = diff.estimate_diffusion(frames)
    summary = {
        "skygas_version": __version__,
        "input": {
            "source": data.source,
            "sha256": data.sha256,
            "pixel_size_m": data.pixel_size,
            "frame_interval_s": data.frame_interval,
            "frames": int(frames.n_frames),
            "positions": int(len(frames.x)),
            "tracks": int(len(np.unique(frames.ids))),
            "steps_used": int(len(steps)),
            "mean_skyrmions_per_frame": float(np.mean(frames.count)),
            "temperature_K": float(temperature),
            "outline": None if outline is None else str(outline),
            "walls": walls,
            "pair": pair,
            "periodic": None if data.box is None else [list(data.box[0]), list(data.box[1])],
            "drift_subtracted": data.drift_subtracted,
            "drift_end_to_end_m": float(np.hypot(*(data.drift[-1] - data.drift[0]))),
            "base_material": base.name,
            "seed": seed,
        },
        "film": {
            "kind": film.kind,
            "reason": film_reason,
            "bounds_m": list(film.outline.bounds),
            "period_m": list(film.period) if film.period else None,
            "edge_margin_m": EDGE_STEPS * step if film.kind == "open" else None,
        },
        "diffusion_constant": numbers.diffusion,
        "diffusion_constant_error": d_err,
        "diffusion_constant_method": "the covariance estimator (Vestergaard, Blainey & "
        "Flyvbjerg 2014) of the steps, blind to the localisation error, freed of the drift of "
        "the inferred forces to first order in the frame interval (and, where the frames are "
        "coarse, of the rest by runs of the model: sampling_correction); jackknife error over "
        f"{dynamics.BLOCKS} blocks of time",
        "diffusion_constant_fixed_by_data": coarse_note is None,
        "diffusion_constant_note": coarse_note,
        "diffusion_constant_as_read": result.diffusion,
        "diffusion_constant_as_read_error": result.diffusion_error,
        "diffusion_constant_noise_only": result.diffusion_raw,
        "diffusion_constant_msd_fit": d_msd.diffusion_constant,
        "diffusion_constant_msd_fit_error": d_msd.error,
        "localisation_error_m": math.sqrt(max(result.sigma2, 0.0)),
        "localisation_error_error_m": result.sigma2_error / (2 * math.sqrt(result.sigma2))
        if result.sigma2 > 0
        else None,
        "hall_angle": hall,
        "hall_angle_error": hall_err if hall_fixed else None,
        # what the steps read, also where the frames are too coarse to fix it
        "hall_angle_as_read": float(hall_value) if result.hall_angle_fixed else None,
        "hall_angle_note": hall_note,
        "hall_angle_definition": "angle from a force to the velocity it causes, "
        "counter-clockwise positive (atan2(G, alpha*D*k) of the Thiele equation)",
        "hall_angle_in_model": numbers.hall_angle,
        "skyrmion_radius_m": radius,
        "skyrmion_radius_source": radius_source,
        "model_selection": {
            "terms": list(result.terms),
            "candidates": {
                t: {
                    "delta_log_likelihood": c.get("delta_log_likelihood"),
                    "error": c.get("error"),
                    "kept": c.get("kept"),
                    "fixed_by_user": c.get("fixed_by_user", False),
                }
                for t, c in result.comparisons.items()
            },
            "held_out_log_likelihood": result.score.total,
            "rule": "a term stays when leaving it out lowers the held-out log-likelihood of the "
            f"steps by more than {forces.KEEP_SIGMAS:g} standard errors ({forces.FOLDS} folds of "
            "contiguous blocks of time)",
        },
        "landscape": {
            "in_model": "landscape" in result.terms,
            "spline_spacing_m": result.basis.landscape.ax.spacing
            if result.basis.landscape is not None
            else None,
            "roughness_weight": result.roughness,
            "roughness_weights_tried": result.roughness_grid.tolist(),
            "roughness_scores": result.roughness_scores.tolist(),
            "grid_spacing_m": float(fmap.grid.h),
            "well_sampled_definition": f"jackknife error of U, relative to its mean over the "
            f"area, at most {maps.WELL_SAMPLED_ERROR} k_BT, and at least {maps.MIN_POSITIONS} "
            "positions within one spline spacing",
            "sampled_area_m2": float(np.sum(fmap.sampled) * fmap.grid.h**2),
            "well_sampled_area_m2": float(np.sum(fmap.well_sampled) * fmap.grid.h**2),
            "film_area_m2": float(np.sum(fmap.film) * fmap.grid.h**2),
            "pinning_rms_kT": stats["rms_kT"],
            "pinning_rms_error_kT": stats["rms_error_kT"],
            "pinning_correlation_length_m": stats["correlation_length_m"],
            "statistics_over": stats_area,
            "deepest_wells": stats["wells"],
        },
        "pair": {
            "mode": pair,
            "in_model": "fitted (pair_table)"
            if "pair" in result.terms
            else "the base material's law"
            if "material_pair" in result.terms
            else "none: no interaction (a zero pair_table)",
            "fitted": _radial_summary(
                result, "pair", kt, numbers, correction, coarse_note is not None
            ),
            "material_law_scale": float(numbers.theta[basis.columns["material_pair"]][0])
            if "material_pair" in result.terms
            else None,
        },
        "wall": {
            "mode": walls,
            "in_model": "fitted (wall_table)"
            if "wall" in result.terms
            else "none: a zero wall_table (the edge only stops skyrmions)",
            "fitted": _radial_summary(
                result, "wall", kt, numbers, correction, coarse_note is not None
            ),
            "density_profile": None
            if wprof is None
            else {
                "distance_m": wprof.d.tolist(),
                "potential_kT": [float(v) if np.isfinite(v) else None for v in wprof.w],
                "potential_error_kT": [float(v) if np.isfinite(v) else None for v in wprof.error],
                "note": "W(d) = −ln(ρ(d)/ρ_bulk) from the density against the distance to the "
                "edge: the cross-check (it carries the neighbours' layering)",
            },
        },
        "drive": _drive_summary(result, numbers, correction, kt),
        "equilibrium": equilibrium,
        "boltzmann_cross_check": cross,
        "sampling_correction": {
            "drift_share_of_raw_d": coarse,
            "threshold": sampling.COARSE_SHARE,
            "made": correction_used is not None,
            "converged": None if correction_used is None else correction_used.converged,
            "applied": correction is not None,
            "rounds": correction_used.history if correction_used is not None else [],
            "note": "the estimator's bias at this frame interval, read off runs of the model "
            "and taken out of D, the Hall angle and the pair, wall and drive forces"
            if correction is not None
            else coarse_note
            if coarse_note is not None
            else "the frames resolve the motion: no correction",
        },
        "consistency_check": check,
        "notes": list(built.notes) + ([coarse_note] if coarse_note is not None else []),
        "model": {
            "free_diffusion_m2_s": numbers.diffusion,
            "hall_angle_rad": numbers.hall_angle,
            "landscape": built.potentials[0] if built.potentials else None,
            "landscape_scale": numbers.landscape_scale,
            "drive_force_N": list(built.drive_force),
        },
    }
    # the inference's own checks lead its summary, as they lead its report
    summary = {"quality_checks": selfcheck.quality_checks(summary), **summary}
    return Inference(
        summary,
        result,
        film,
        data,
        fmap,
        boltzmann,
        boltzmann_err,
        wprof,
        built.material,
        built.potentials,
        built.map_values,
        check,
    )


def _drive_summary(result, numbers, correction, kt: float) -> dict | None:
    """The drive's force [N] with its error, and the drift velocity it gives [m/s]."""
    if "drive" not in result.terms:
        return None
    cols = result.basis.columns["drive"]
    fd = numbers.theta[cols]
    _, err = result.jackknife(lambda f: f.theta[cols])
    if correction is not None:
        err = correction.error(lambda f: f.theta[cols], err)
    t = math.tan(numbers.hall_angle)
    velocity = numbers.diffusion * np.array([fd[0] - t * fd[1], fd[1] + t * fd[0]])
    return {
        "force_N": (fd * kt).tolist(),
        "force_error_N": (np.asarray(err) * kt).tolist(),
        "velocity_m_s": velocity.tolist(),
        "note": "a uniform force (a current's push, or a tilt of the film), written as "
        "[inference] drive_force and applied as external_force in the self-check",
    }


def _pair_law(result: forces.ForceInference):
    """The kept pair law [k_BT/m] of r [m], or None."""
    if "pair" in result.terms and result.basis.pair is not None:
        basis, theta = result.basis.pair, result.coefficients("pair")
        return lambda r: np.where(r < basis.hi, basis.force(np.asarray(r), theta), 0.0), basis.hi
    if "material_pair" in result.terms and result.basis.material_pair is not None:
        scale = float(result.coefficients("material_pair")[0])
        law = result.basis.material_pair
        return lambda r: scale * law(r), result.basis.material_pair_range
    return None


def _boltzmann_check(result, film: Film, frames: Frames, fmap: maps.ForceMap):
    """−ln ρ (crowding taken out with the kept pair law) on the map's grid, and the comparison."""
    seen = Frames(frames.time, frames.count, frames.ids, *film.wrap(frames.x, frames.y))
    bi = land.boltzmann_inversion(seen, film.outline, fmap.grid.h)
    u = bi.u.copy()
    law = _pair_law(result)
    crowd_note = "no pair law: −ln ρ as it is"
    if law is not None:
        phi, _, _ = crowding.crowding_potential(seen, bi, law[0], law[1])
        u = u + np.nan_to_num(phi)
        crowd_note = "the neighbours' mean push taken out with the inferred pair law"
    err = (
        np.fmax(bi.error, bi.error_across_skyrmions)
        if bi.error_across_skyrmions is not None
        else bi.error
    )
    area = fmap.well_sampled if fmap.well_sampled.any() else fmap.sampled
    both = area & bi.well_sampled & np.isfinite(u) & np.isfinite(fmap.u)
    if both.sum() < 10:
        return (
            u,
            err,
            {
                "nodes_compared": int(both.sum()),
                "note": "too few nodes sampled by both to compare",
            },
            bi,
        )
    a = fmap.u[both] - fmap.u[both].mean()
    b = u[both] - u[both].mean()
    return (
        u,
        err,
        {
            "nodes_compared": int(both.sum()),
            "rms_difference_kT": float(np.sqrt(np.mean((a - b) ** 2))),
            "rms_dynamics_kT": float(np.std(a)),
            "rms_boltzmann_kT": float(np.std(b)),
            # no correlation to speak of where either map is flat (no landscape was kept)
            "correlation": float(np.corrcoef(a, b)[0, 1])
            if np.std(a) > 0 and np.std(b) > 0
            else None,
            "kernel_width_m": bi.bandwidth,
            "crowding": crowd_note,
            "note": "the landscape from the forces (the model's) against −ln ρ of the positions, "
            "over the nodes both fix; −ln ρ needs the movie to have visited the wells in "
            "proportion to their weight, which a short movie does not",
        },
        bi,
    )


def _wall_cross_check(result, film: Film, frames: Frames, fmap: maps.ForceMap):
    """W(d) from the density, the neighbours' mean push along the normal taken out."""
    law = _pair_law(result)
    normal = None
    if law is not None:
        fx, fy = crowding.pair_forces(frames, law[0], law[1])
        gx, gy = np.meshgrid(fmap.grid.x, fmap.grid.y)
        node_d = wall.wall_distance(film.outline, gx, gy)
        normal = crowding.normal_component(frames, fmap.grid, node_d, fx, fy)
    return wall.wall_profile(frames, film.outline, max(fmap.grid.h, 2e-9), normal_force=normal)


def _run_model(film, built, data, result, n_frames, temperature, seed):
    """A run of ``built`` in the movie's film (the map written to a scratch file)."""
    import tempfile
    from pathlib import Path

    frames = data.frames
    with tempfile.TemporaryDirectory(prefix="skygas-infer-") as scratch:
        pots = []
        for p in built.potentials:
            path = Path(scratch) / p["path"]
            np.save(path, built.map_values)
            pots.append({**p, "path": str(path)})
        pair_reach = result.basis.pair_range if _pair_law(result) is not None else 0.0
        margin = max(3 * pair_reach, 10 * math.sqrt(2 * result.diffusion * frames.frame_interval()))
        return selfcheck.run_model(
            film,
            built.material,
            pots,
            temperature=temperature,
            frame_interval=frames.frame_interval(),
            frames=n_frames,
            skyrmions_seen=float(np.mean(frames.count)),
            drive_force=built.drive_force,
            sigma=math.sqrt(max(result.sigma2, 0.0)),
            margin=margin,
            seed=seed,
            start=frames.frame(0)[1],
        )


def _compare(film, frames, run, result, fmap, bi, n_frames, seed):
    """The self-check's comparisons (:func:`.selfcheck.compare`) over the movie's first frames."""
    size = candidates.film_size(film)
    r_max = min(size, result.basis.pair_range * 1.5 if result.basis.pair_range else size)
    bandwidth = bi.bandwidth if bi is not None else 2 * fmap.grid.h
    movie = frames.select(np.arange(n_frames)) if n_frames < frames.n_frames else frames
    pair_error = None
    if "pair" in result.terms and result.basis.pair is not None:
        basis, cols = result.basis.pair, result.basis.columns["pair"]

        def pair_error(r: np.ndarray) -> np.ndarray:
            return result.jackknife(lambda f: _potential(basis, r, f.theta[cols]))[1]

    return selfcheck.compare(
        movie,
        run,
        film,
        bandwidth=bandwidth,
        spacing=fmap.grid.h,
        r_max=max(r_max, 4 * fmap.grid.h),
        bins=15,
        seed=seed,
        interacting=any(t in result.terms for t in ("pair", "material_pair")),
        pair_potential_error=pair_error,
    )
