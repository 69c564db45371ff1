"""``infer``: tracks → diffusion, Hall angle, pinning landscape, wall and pair laws → a model.

The steps, each in its own module of :mod:`skygas.inference`:

1. tracks in SI, drift removed where significant (:mod:`~skygas.inference.tracks`);
2. U = −k_BT ln ρ with a cross-validated kernel and a bootstrap uncertainty
   (:mod:`~skygas.inference.landscape`);
3. the neighbours' mean push Φ by force balance (:mod:`~skygas.inference.crowding`) and the wall
   potential W(d) from the density against the distance to the outline
   (:mod:`~skygas.inference.wall`); the pinning is U + Φ − W(d);
4. D and the localisation error from the short-lag MSD, blocked errors, per skyrmion
   (:mod:`~skygas.inference.diffusion`);
5. the Hall angle from the displacements in the landscape's held-out force
   (:mod:`~skygas.inference.mobility`), and with D the Thiele parameters
   (:mod:`~skygas.inference.model`);
6. the pair potential by iterative Boltzmann inversion with skygas simulations of the whole model
   (:mod:`~skygas.inference.pair`), in which D is retuned until the model's runs, read by the
   same MSD fit, read what the movie reads (:mod:`~skygas.inference.bias`);
7. the consistency check: a run of the final model, its MSD(τ)/4τ against the measured one at
   the longer lags, where pinning, walls and neighbours have slowed the skyrmions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from skygas._version import __version__
from skygas.analysis import mean_squared_displacement
from skygas.analysis.frames import Frames
from skygas.core import units
from skygas.core.errors import require
from skygas.inference import bias, crowding, mobility, model, pair, tracks, wall
from skygas.inference import diffusion as diff
from skygas.inference import landscape as land
from skygas.inference.laws import force_table
from skygas.inference.outline import read_outline
from skygas.physics.materials import load_material

#: Largest share of positions allowed outside the outline (by more than a pixel).
OUTSIDE_SHARE = 0.01
#: Lags [frames] of the consistency check.
CHECK_LAGS = (1, 3, 10, 30, 100)


@dataclass
class Inference:
    """What :func:`infer` found: ``summary`` (inference.json), the maps, the model table."""

    summary: dict
    landscape: land.LandscapeMap
    crowding: np.ndarray
    pinning: np.ndarray
    wall: wall.WallProfile
    ibi: pair.IBIResult
    material: dict
    msd_lag_time: np.ndarray
    msd_over_4tau: np.ndarray
    msd_over_4tau_error: np.ndarray
    model_msd_over_4tau: np.ndarray | None
    tracks: tracks.Tracks
    outline: object


def _check_inside(frames: Frames, outline, pixel_size: float, source: str) -> None:
    d = wall.wall_distance(outline, frames.x, frames.y)
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


def _wall_table(profile: wall.WallProfile, kt: float) -> dict | None:
    """The engine's wall table of the fitted W(d) over its sampled range (None: no fit)."""
    if profile.coef is None or profile.sampled_range is None:
        return None
    lo = profile.sampled_range[0] * 1e9
    # up to where the fit has fallen to nothing (at least 10 nm past the first sampled distance)
    return force_table(profile.coef, lo, max(profile.reach * 1e9, lo + 10.0), kt, 1e-9)


def _pair_force_table(ibi: pair.IBIResult, kt: float) -> dict | None:
    """The final pair force and its statistical error [N] over the range the data fix."""
    if ibi.coef is None or not ibi.fixed_range:
        return None
    r = np.linspace(*ibi.fixed_range, 12)
    f, err = ibi.force(r)
    tight = r[err <= 0.1 * f]
    return {
        "r_m": r.tolist(),
        "force_N": (f * kt).tolist(),
        "force_error_N": (err * kt).tolist(),
        "range_within_10_percent_m": [float(tight[0]), float(tight[-1])] if len(tight) else None,
        "note": "statistical error only: the movie's g(r) and the last IBI run's, carried "
        "through the fit of ln V",
    }


def infer(
    source,
    *,
    pixel_size: float | None,
    frame_interval: float | None,
    outline,
    temperature: float,
    base_material="S2",
    skyrmion_radius: float | None = None,
    subtract_drift: str = "auto",
    ibi_iterations: int = pair.ITERATIONS,
    ibi_frames: int | None = None,
    seed: int = 0,
    progress=None,
) -> Inference:
    """Infer the particle model of a tracked skyrmion gas.

    Parameters
    ----------
    source : DataFrame or path
        trackpy's table (``frame``, ``particle``, ``x``, ``y`` in pixels) or its file.
    pixel_size, frame_interval : float
        Metres per pixel, seconds per frame.
    outline : path or Outline
        The device: a CSV of x,y vertices [m] or a binary mask on the tracks' pixel grid.
    temperature : float
        T [K] of the film.
    base_material : str or Material
        Supplies what tracks cannot measure (M_s, film thickness, A_ex, K_u, α, the paper-form
        laws for ``pair_law = "paper"``); default S2.
    skyrmion_radius : float, optional
        R [m] (default the base material's): the length unit of the engine's laws.
    subtract_drift : {"auto", "yes", "no"}
        See :func:`skygas.inference.tracks.load_tracks`.
    ibi_iterations, ibi_frames : int
        IBI iterations at most, and frames per simulation (default :data:`pair.SIM_FRAMES`).
    seed : int
        Seeds the bootstrap and the simulations.
    progress : callable, optional
        Called with a line of text as each step starts.

    Returns
    -------
    Inference
    """
    say = progress or (lambda text: None)
    require(
        np.isfinite(temperature) and temperature > 0,
        "--temperature",
        temperature,
        "the film's temperature in kelvin, > 0",
    )
    base = load_material(base_material)
    if skyrmion_radius is not None:
        require(skyrmion_radius > 0, "--skyrmion-radius", skyrmion_radius, "a radius > 0 [m]")
        base = base.model_copy(update={"skyrmion_radius": float(skyrmion_radius)})
    data = tracks.load_tracks(source, pixel_size, frame_interval, subtract_drift=subtract_drift)
    frames = data.frames
    shape = read_outline(outline, data.pixel_size)
    _check_inside(frames, shape, data.pixel_size, str(outline))
    require(
        frames.n_frames >= 2 * diff.BLOCKS,
        "tracks.frame",
        f"{frames.n_frames} frames",
        f"at least {2 * diff.BLOCKS} frames (errors are blocked over {diff.BLOCKS} blocks of time)",
    )
    kt = units.BOLTZMANN * temperature

    say("landscape: Boltzmann inversion, kernel width by cross-validation, bootstrap")
    spacing = max(data.pixel_size / 2, 1e-9)
    lmap = land.boltzmann_inversion(frames, shape, spacing, seed=seed)
    grid = lmap.grid

    say("pair correlation")
    r_max = min(
        0.5 * min(grid.x[-1] - grid.x[0], grid.y[-1] - grid.y[0]), 12 * base.skyrmion_radius * 2
    )
    measured_g = pair.measured_pair_correlation(frames, shape, r_max, 2 * base.skyrmion_radius)
    gx, gy = np.meshgrid(grid.x, grid.y)
    node_d = wall.wall_distance(shape, gx, gy)

    def one_body(material_now: dict) -> tuple[wall.WallProfile, np.ndarray, np.ndarray]:
        """The wall profile, the pinning map and Φ [k_BT] with the neighbours' push taken out."""
        law = crowding.material_law(material_now, base, temperature)
        cutoff = crowding.reach(law, 0.25 * base.skyrmion_radius, r_max)
        phi, fx, fy = crowding.crowding_potential(frames, lmap, law, cutoff)
        normal = crowding.normal_component(frames, grid, node_d, fx, fy)
        profile = wall.wall_profile(frames, shape, max(grid.h, 2e-9), normal_force=normal)
        return profile, lmap.u + phi - profile.at(node_d), phi

    say("neighbours' mean push (force balance) and the wall potential")
    wprof, pinning, crowd = one_body(model.model_material("inferred", base, {}, None, None))

    say("diffusion: MSD with the localisation error, blocked errors")
    d = diff.estimate_diffusion(frames)
    require(d.diffusion_constant > 0, "tracks", data.source, "skyrmions that move (D ≤ 0 measured)")

    say("Hall angle: displacements against the held-out landscape force")
    hall = mobility.fit_mobility(frames, mobility.landscape_force(frames, lmap), d.sigma)
    thiele = model.thiele_fields(d.diffusion_constant, hall.angle, hall.error, base, temperature)
    material = model.model_material("inferred", base, thiele, None, _wall_table(wprof, kt))

    d_tuner = bias.DiffusionTuner(
        d.diffusion_constant,
        d.error,
        d.sigma,
        lambda value: model.thiele_fields(value, hall.angle, hall.error, base, temperature),
        seed,
    )
    say("pair potential: iterative Boltzmann inversion with skygas simulations, D retuned")
    n_sim = ibi_frames or pair.SIM_FRAMES
    with pair.scratch_folder() as scratch:
        folder = Path(scratch)
        ibi, material = pair.iterate(
            frames,
            shape,
            material,
            temperature,
            lmap,
            pinning,
            d.sigma,
            folder,
            measured=measured_g,
            iterations=max(ibi_iterations, 1),
            sim_frames=n_sim,
            seed=seed,
            progress=say,
            retune=d_tuner.retune,
        )
        if "pair_table" in material:
            say("neighbours' mean push and the wall potential again, with the iterations' law")
            wprof, pinning, crowd = one_body(material)
            material = {k: v for k, v in material.items() if k != "wall_table"}
            if (table := _wall_table(wprof, kt)) is not None:
                material["wall_table"] = table
        grid_potential = pair.pinning_grid_file(
            folder,
            np.where(lmap.well_sampled, pinning, np.nan),
            grid.x,
            grid.y,
            pair.pad_nodes(grid),
            "final",
        )
        n_skyrmions, separation = pair.gas_layout(frames, material, ibi.fixed_range)
        d_value, d_error = d_tuner.result()
        material = {
            **material,
            **model.thiele_fields(d_value, hall.angle, hall.error, base, temperature),
        }
        say("consistency check: a skygas run of the final model")
        model_frames = pair.simulate(
            shape,
            material,
            [grid_potential],
            temperature,
            frames.frame_interval(),
            n_skyrmions,
            n_sim,
            seed + 1000,
            separation,
        )

    say("landscape statistics and dwell times")
    # the interior: well sampled and beyond the wall's reach (where the fitted W is negligible)
    reach = wprof.reach if wprof.coef is not None else wprof.bulk_from
    interior = lmap.well_sampled & (node_d >= reach)
    if interior.any():
        pinning = np.where(lmap.well_sampled, pinning - np.nanmean(pinning[interior]), np.nan)
    rms, xi = land.correlation_length(np.nan_to_num(pinning), interior, grid.h)
    radius = max(lmap.bandwidth, 0.5 * xi) if math.isfinite(xi) else lmap.bandwidth
    wells = []
    for x0, y0, depth in land.deepest_wells(pinning, interior, grid, radius):
        t, visits = land.dwell_time(frames, (x0, y0), radius)
        wells.append(
            {
                "x_m": x0,
                "y_m": y0,
                "depth_kT": depth,
                "radius_m": radius,
                "mean_dwell_time_s": t,
                "visits": visits,
            }
        )

    lags = np.array([lag for lag in CHECK_LAGS if lag < frames.n_frames // 4])
    measured = mean_squared_displacement(frames, lags, fit_lags=lags[:1])
    ratio = measured.msd / (4 * measured.lag_time)
    ratio_err = measured.msd_error / (4 * measured.lag_time)
    model_ratio = None
    check = None
    if model_frames.n_frames > 8:
        sim_lags = lags[lags < model_frames.n_frames // 4]
        sm = mean_squared_displacement(model_frames, sim_lags, fit_lags=sim_lags[:1])
        model_ratio = np.full(len(lags), np.nan)
        model_ratio[: len(sim_lags)] = sm.msd / (4 * sm.lag_time)
        # the measured MSD carries 4σ² of localisation error; the model's does not
        corrected = (measured.msd - 4 * d.sigma**2) / (4 * measured.lag_time)
        check = {
            "lag_time_s": measured.lag_time.tolist(),
            "measured_msd_over_4tau_m2_s": corrected.tolist(),
            "measured_error_m2_s": ratio_err.tolist(),
            "model_msd_over_4tau_m2_s": model_ratio.tolist(),
            "model_msd_over_4tau_error_m2_s": np.concatenate(
                [sm.msd_error / (4 * sm.lag_time), np.full(len(lags) - len(sim_lags), np.nan)]
            ).tolist(),
            "note": "a skygas run of the inferred model (landscape, walls, pair law, D and Hall "
            "angle) over the device's outline: its MSD(τ)/4τ against the measured one "
            "(localisation error 4σ² removed); agreement at the longer lags checks the "
            "landscape's effect on transport",
        }
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
            "mean_skyrmions_per_frame": float(np.mean(frames.count)),
            "temperature_K": float(temperature),
            "outline": str(outline),
            "drift_subtracted": data.drift_subtracted,
            "drift_end_to_end_m": float(np.hypot(*(data.drift[-1] - data.drift[0]))),
            "base_material": base.name,
            "seed": seed,
        },
        **d.as_dict(),
        **hall.as_dict(),
        "diffusion_constant": d_value,
        "diffusion_constant_error": d_error,
        "hall_angle": hall.angle,
        "hall_angle_error": hall.error,
        "diffusion_constant_systematic_error": bias.SYSTEMATIC_SHARE
        * abs(d.diffusion_constant - d_value),
        "diffusion_constant_as_read": d.diffusion_constant,
        "diffusion_constant_as_read_error": d.error,
        "diffusion_constant_method": "MSD = 4σ² + 4Dτ + cτ² fitted over frame lags 1-3, errors "
        "by blocking over 16 blocks of time; then D retuned until runs of the inferred model "
        "read what the movie reads (the systematic error: a share of that correction, the "
        "residual measured on the round-trip gases)",
        "diffusion_constant_retuning": d_tuner.as_dict(),
        "landscape": {
            "kernel_width_m": lmap.bandwidth,
            "kernel_candidates_m": lmap.candidates.tolist(),
            "kernel_cv_log_likelihood": lmap.scores.tolist(),
            "well_sampled_definition": f"bootstrap standard error of U at most "
            f"{land.WELL_SAMPLED_ERROR} k_BT ({land.BOOT_REPLICAS} resamples of "
            f"{land.BOOT_BLOCKS} blocks of time)",
            "well_sampled_area_m2": float(np.sum(lmap.well_sampled) * grid.h**2),
            "area_fixed_across_skyrmions_m2": float(
                np.sum(lmap.fixed_across_skyrmions) * grid.h**2
            ),
            "fixed_across_skyrmions_definition": "well sampled, and the standard error of U "
            f"from {land.BOOT_REPLICAS} resamples of the tracks at most "
            f"{land.WELL_SAMPLED_ERROR} k_BT",
            "film_area_m2": float(np.sum(grid.inside) * grid.h**2),
            "pinning_rms_kT": rms,
            "pinning_correlation_length_m": xi,
            "interior_from_wall_m": reach,
            "deepest_wells": wells,
        },
        "wall": {
            "distance_m": wprof.d.tolist(),
            "potential_kT": [float(v) if np.isfinite(v) else None for v in wprof.w],
            "potential_error_kT": [float(v) if np.isfinite(v) else None for v in wprof.error],
            "sampled_range_m": wprof.sampled_range,
            "bulk_from_m": wprof.bulk_from,
            "fit_ln_potential_coefficients_nm": None
            if wprof.coef is None
            else list(map(float, wprof.coef)),
        },
        "pair": {
            "r_m": ibi.r.tolist(),
            "g_measured": [float(v) for v in ibi.g],
            "g_measured_error": [float(v) if np.isfinite(v) else None for v in ibi.g_error],
            "range_fixed_by_data_m": ibi.fixed_range,
            "law_in_model": "pair_table from IBI"
            if "pair_table" in material
            else f"the base material's ({base.name}) law: "
            + (
                "the data fix fewer than 3 distances"
                if ibi.initial_force_error is None
                else "the fit of −ln g(r) gives no repulsion in the middle of the range"
                if not math.isfinite(ibi.initial_force_error)
                else f"the movie's g(r) fixes the force to {100 * ibi.initial_force_error:.0f} % "
                f"only (at most {100 * pair.MAX_FORCE_ERROR:.0f} % for a law of its own)"
            ),
            "force_relative_error_from_g": ibi.initial_force_error,
            "iterations": [
                {
                    "chi2": c,
                    "g_model": [float(v) for v in gs[0]],
                    "potential_kT": [float(v) if np.isfinite(v) else None for v in pot],
                }
                for c, gs, pot in zip(ibi.chi2, ibi.simulated, ibi.potentials, strict=True)
            ],
            "fit_ln_potential_coefficients_nm": None
            if ibi.coef is None
            else list(map(float, ibi.coef)),
            "force_over_fixed_range": _pair_force_table(ibi, kt),
        },
        "consistency_check": check,
        "model": {
            "free_diffusion_m2_s": d_value,
            "hall_angle_rad": hall.angle,
            "pinning_as_disorder": {
                "kind": "disorder",
                "rms_kT": rms,
                "correlation_length": xi,
            },
        },
    }
    return Inference(
        summary,
        lmap,
        crowd,
        pinning,
        wprof,
        ibi,
        material,
        measured.lag_time,
        ratio,
        ratio_err,
        model_ratio,
        data,
        shape,
    )
