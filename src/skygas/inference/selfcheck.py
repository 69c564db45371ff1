"""The self-check: runs of the written model must look like the movie.

The model (its material, its landscape, its drive) is run with skygas's engine in the movie's
film, seen as the movie saw it (the localisation error added; in a field of view, only what is
in view, a skyrmion that comes back being a new track), and three things are compared with
the movie's, each within the two records' standard errors:

- **MSD(τ)/4τ** at lags of 1 … 100 frames, errors blocked over :data:`BLOCKS` blocks of time
  each at least :data:`BLOCK_LAGS` lags long (shorter blocks are correlated and their errors
  too small): the transport, which the landscape, the walls and the neighbours shape at the
  longer lags;
- **g(r)**, the pair correlation (jackknife errors): the interaction, judged only where the
  model has one (see :func:`compare`);
- **the density map**, −ln ρ on the same grid and kernel, with the error of a bootstrap over
  the tracks (which sees which wells the skyrmions happened to visit): the landscape.

Each comparison is a χ² per degree of freedom of the differences in units of their combined
error; a comparison fails above :data:`MAX_CHI2` (neighbouring bins and nodes are correlated,
so the bound is looser than for independent ones; for MSD, whose lags are strongly
correlated, when any lag is off by more than :data:`MAX_Z` errors). MSD(τ)/4τ must also lie
within :data:`MSD_TOLERANCE` of the movie's at every lag: errors as large as a short movie's
would let a model through whose transport is a third off, and "within the errors" then says
only that the movie cannot tell. A failed check is a warning on the terminal, a headline in
the report, and exit status 1 under ``--strict``; :func:`quality_checks` lists every check of
an inference with its value, tolerance and verdict (the report's first rows).

The runs start from the movie's first frame (a gas is not always at rest when a movie starts,
and a run from elsewhere would differ by that alone). Where the film is periodic the model runs
in 3 × 3 copies of the box (the landscape and the first frame tiled) and only the middle copy
is seen; in a field of view, in the view widened by a margin of a few pair ranges and rms
steps, the landscape continued by its statistics and the margin filled at random.
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from skygas.analysis import pair_correlation
from skygas.analysis.frames import Frames
from skygas.inference.diffusion import block_of_frame, blocked
from skygas.inference.film import Film
from skygas.physics.geometry import Outline, rectangle

#: Lags [frames] of the MSD comparison.
LAGS = (1, 3, 10, 30, 100)
#: Largest χ² per degree of freedom of a consistent comparison (g(r), density).
MAX_CHI2 = 3.0
#: Largest deviation of one MSD lag, in combined standard errors.
MAX_Z = 3.0
#: Largest relative deviation |model/movie − 1| of MSD(τ)/4τ at any lag: the accuracy the
#: model's transport is held to, whatever the errors. A short movie's own noise can come near it
#: (8 free walkers over 640 frames: 13 % at a lag of 10 frames, 2.2 combined errors); the check
#: in units of the errors then says whether a difference is more than noise.
MSD_TOLERANCE = 0.2
#: Frames of relaxation before the record of a run that does not start from the movie.
RELAX_FRAMES = 200
#: Blocks of time for the MSD errors (each at least :data:`BLOCK_LAGS` of the longest lag).
BLOCKS = 8
BLOCK_LAGS = 4
#: g(r) bins with fewer pairs than this in the movie are not compared.
MIN_PAIRS = 20
#: The longer blocks of time of g(r)'s second error estimate.
LONG_BLOCKS = 5
#: The model's runs use a grid of at most this many nodes a side (coarser than the
#: skyrmion's sixteenth where the film is large: the model's landscape is no finer).
GRID_NODES = 600


@dataclass(frozen=True)
class ModelRun:
    """A run of the model, its positions as the movie would have seen them and all of them.

    ``frames`` as the movie would have seen them; ``everything`` in the outline it ran in
    (``outline``: the film, the field of view with a margin, or 3 × 3 copies of a periodic
    box); localisation error added to both.
    """

    frames: Frames
    everything: Frames
    outline: Outline
    skyrmions: int
    time_step: float


def _time_step(sim, frame_interval: float) -> float:
    """A step that divides the frame: a tenth of the fastest force relaxation of the model."""
    from skygas.engine.force_model import SUGGESTED_STEP_FRACTION, relaxation_time

    stiffness = max(t.stiffness() for t in sim.term_rules)
    tau = relaxation_time(sim.thiele, stiffness)
    step = SUGGESTED_STEP_FRACTION * tau if math.isfinite(tau) else frame_interval / 10
    return frame_interval / max(1, math.ceil(frame_interval / step - 1e-9))


def _tiled(potentials: list[dict], folder: Path) -> list[dict]:
    """A measured map tiled 3 × 3 (a periodic film's copies), as a new file in ``folder``."""
    out = []
    for p in potentials:
        if p.get("kind") != "measured":
            out.append(p)
            continue
        values = np.load(p["path"])
        tiled = np.tile(values, (3, 3))
        path = folder / "tiled.npy"
        np.save(path, tiled)
        n_y, n_x = values.shape
        h = p["spacing"]
        out.append(
            {
                **p,
                "path": str(path),
                "origin": (p["origin"][0] - n_x * h, p["origin"][1] - n_y * h),
            }
        )
    return out


def run_model(
    film: Film,
    material: dict,
    potentials: list[dict],
    *,
    temperature: float,
    frame_interval: float,
    frames: int,
    skyrmions_seen: float,
    drive_force: tuple[float, float],
    sigma: float,
    margin: float,
    seed: int,
    start: np.ndarray | None = None,
) -> ModelRun:
    """Run the model in the movie's film and see it as the movie did (see the module's text).

    ``skyrmions_seen``: the movie's mean count; ``drive_force`` [N]; ``sigma`` [m] the
    localisation error; ``margin`` [m] around a field of view; ``start`` (n, 2) [m]: the
    movie's first frame, where the run starts (:func:`_starting_positions`); without it, at
    random positions relaxed for :data:`RELAX_FRAMES` frames.
    """
    from skygas.engine import Simulation
    from skygas.physics.materials import material_from_mapping

    model = material_from_mapping(material, field="inferred material")
    step = math.sqrt(2 * _free_diffusion(model, temperature) * frame_interval)
    with tempfile.TemporaryDirectory(prefix="skygas-check-") as scratch:
        region = film.outline
        if film.periodic:
            assert film.period is not None
            lx, ly = film.period
            x0, y0 = film.origin
            outline = rectangle(3 * lx, 3 * ly, center=(x0 + lx / 2, y0 + ly / 2))
            potentials = _tiled(potentials, Path(scratch))
            count = 9 * skyrmions_seen
        elif film.kind == "open":
            from skygas.core.units import M_TO_NM

            bx0, by0, bx1, by1 = (v / M_TO_NM for v in region.region.bounds)
            outline = rectangle(
                bx1 - bx0 + 2 * margin,
                by1 - by0 + 2 * margin,
                center=((bx0 + bx1) / 2, (by0 + by1) / 2),
            )
            count = skyrmions_seen * outline.area() / region.area()
        else:
            outline = region
            count = skyrmions_seen
        n = max(1, int(round(count)))
        spacing = _grid_spacing(outline, model)
        # the engine's grid is at most a diameter: a model whose skyrmions are small against
        # the film (or move far in a frame) runs with a diameter of at least a grid spacing and
        # an rms step; its laws are tables in metres, which the diameter leaves as they are
        if 2 * model.skyrmion_radius < max(spacing, step):
            model = model.model_copy(update={"skyrmion_radius": 0.5 * max(spacing, step)})

        def simulation(time_step: float, run_seed: int = 0):
            return Simulation(
                outline,
                model,
                temperature=temperature,
                time_step=time_step,
                seed=run_seed,
                landscape=potentials,
                external_force=drive_force,
                grid_spacing=spacing,
            )

        dt = _time_step(simulation(1e-15), frame_interval)  # the probe is read, not run
        sim = simulation(dt, seed)
        if start is None:
            sim.add_random(n, min_separation=0.5)
            sim.run(RELAX_FRAMES * frame_interval)
        else:
            sim.add_skyrmions(_starting_positions(film, outline, start, n, seed), validate=False)
        start_time = sim.time
        sim.run(frames * frame_interval, record_interval=frame_interval)
        ds = sim.trajectories()
    keep = ds.time.values >= start_time - 0.5 * frame_interval
    x, y = ds.x.values[keep][:frames], ds.y.values[keep][:frames]
    rng = np.random.default_rng([seed, 0x5EE])
    x = x + rng.normal(0.0, sigma, x.shape)
    y = y + rng.normal(0.0, sigma, y.shape)
    ids = ds.skyrmion.values
    seen = _as_seen(film, region, x, y, ids, frame_interval)
    everything = Frames.from_dense(frame_interval * np.arange(len(x)), ids, x, y)
    return ModelRun(seen, everything, outline, n, dt)


def _starting_positions(
    film: Film, outline: Outline, first: np.ndarray, count: int, seed: int
) -> np.ndarray:
    """Where a run starts: the movie's first frame, as far as the run's outline goes.

    A gas is not always at rest when a movie starts (the skyrmions were just written, or
    pushed), and a run that starts elsewhere would differ from the movie by that alone. The
    first frame's positions inside the outline; in a periodic film, in each of the 3 × 3
    copies; around a field of view, the margin filled at random to the count asked for.
    """
    first = np.asarray(first, float).reshape(-1, 2)
    if film.periodic:
        assert film.period is not None
        lx, ly = film.period
        x, y = film.wrap(first[:, 0], first[:, 1])
        shifts = [(i * lx, j * ly) for i in (-1, 0, 1) for j in (-1, 0, 1)]
        return np.vstack([np.column_stack([x + sx, y + sy]) for sx, sy in shifts])
    inside = np.asarray(outline.contains(first[:, 0], first[:, 1]), bool)
    points = first[inside]
    if film.kind == "open" and count > len(points):
        rng = np.random.default_rng([seed, 0x57A7])
        x0, y0, x1, y1 = outline.bounds
        extra: list[np.ndarray] = []
        while len(extra) < count - len(points):
            p = rng.uniform((x0, y0), (x1, y1), size=(4 * count, 2))
            ok = np.asarray(outline.contains(p[:, 0], p[:, 1]), bool) & ~np.asarray(
                film.outline.contains(p[:, 0], p[:, 1]), bool
            )
            extra.extend(p[ok][: count - len(points) - len(extra)])
        points = np.vstack([points, np.array(extra)])
    return points


def _free_diffusion(model, temperature: float) -> float:
    """D [m²/s] of a free skyrmion of the model."""
    from skygas.physics.materials import derive_thiele

    return derive_thiele(model).diffusion_constant(temperature)


def _grid_spacing(outline: Outline, model) -> float:
    """The engine's grid: its default (d_sk/16) or :data:`GRID_NODES` a side, the coarser."""
    from skygas.core.units import M_TO_NM
    from skygas.physics.materials import derive_thiele

    x0, y0, x1, y1 = (v / M_TO_NM for v in outline.region.bounds)
    d_sk = derive_thiele(model).skyrmion_diameter
    return max(d_sk / 16, max(x1 - x0, y1 - y0) / GRID_NODES)


def _as_seen(film: Film, region: Outline, x, y, ids, dt: float) -> Frames:
    """Dense positions (frames, skyrmions) as the movie sees them."""
    t = dt * np.arange(len(x))
    if film.periodic:
        # the middle copy only; a skyrmion that leaves it and comes back is a new track
        assert film.period is not None
        lx, ly = film.period
        x0, y0 = film.origin
        inside = (x >= x0) & (x < x0 + lx) & (y >= y0) & (y < y0 + ly)
    elif film.kind == "open":
        inside = np.isfinite(x) & region.contains(np.nan_to_num(x), np.nan_to_num(y)).reshape(
            x.shape
        )
    else:
        return Frames.from_dense(t, ids, x, y)
    entered = inside & ~np.vstack([np.zeros((1, x.shape[1]), bool), inside[:-1]])
    track = np.cumsum(entered, axis=0)
    # one column per (skyrmion, visit): new ids for each re-entry
    frame, col = np.nonzero(inside)
    new_id = ids[col].astype(np.int64) * (int(track.max()) + 1) + track[frame, col]
    order = np.lexsort((new_id, frame))
    frame, col, new_id = frame[order], col[order], new_id[order]
    count = np.bincount(frame, minlength=len(t)).astype(np.int64)
    return Frames(t, count, new_id, x[frame, col], y[frame, col])


def msd_ratio(frames: Frames, lags, starts=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(τ [s], MSD/4τ [m²/s], its blocked standard error) at ``lags`` [frames].

    ``starts`` (E,) bool: the entries a displacement may start from (default: all).
    """
    dt = frames.frame_interval()
    block_of = block_of_frame(frames.n_frames, BLOCKS)
    values, errors = [], []
    for lag in lags:
        a, b = frames.pairs_at_lag(int(lag))
        if starts is not None:
            keep = starts[a]
            a, b = a[keep], b[keep]
        r2 = (frames.x[b] - frames.x[a]) ** 2 + (frames.y[b] - frames.y[a]) ** 2
        blk = block_of[frames.frame_of_entry[a]]
        sums = np.bincount(blk, r2, BLOCKS)
        counts = np.bincount(blk, minlength=BLOCKS)
        ok = counts > 0
        values.append(r2.mean() / (4 * lag * dt) if len(r2) else np.nan)
        errors.append(blocked(sums[ok] / counts[ok]) / (4 * lag * dt) if ok.sum() > 1 else np.nan)
    return np.asarray(lags) * dt, np.array(values), np.array(errors)


def _chi2(z: np.ndarray) -> float | None:
    z = z[np.isfinite(z)]
    return float(np.mean(z * z)) if len(z) else None


def compare(
    movie: Frames,
    run: ModelRun,
    film: Film,
    *,
    bandwidth: float,
    spacing: float,
    r_max: float,
    bins: int,
    seed: int,
    interacting: bool = True,
    pair_potential_error=None,
) -> dict:
    """The three comparisons of the module's text, with a verdict each and overall.

    ``pair_potential_error(r)``: the jackknife error of a fitted pair potential [k_BT] at
    distances r [m], added to the model's g(r) error to first order (δg = g δV).

    ``interacting``: whether the model has a pair law. Without one, g(r) is shown but not
    judged: it then carries only the landscape's density correlations, which the density map
    tests directly, and in two dimensions pairs of free skyrmions meet again and again (a
    random walk returns), so that g(r) at short range stays correlated over most of a movie
    and its block errors are too small (a free gas seen through a field of view reads
    g = 1.8 ± 0.26 at short range where the truth is 1).
    """
    from skygas.inference.landscape import boltzmann_inversion

    n_frames = min(movie.n_frames, run.frames.n_frames)
    # lags short enough for blocks of several of them: shorter blocks would be correlated,
    # and their errors too small
    lags = [lag for lag in LAGS if BLOCKS * BLOCK_LAGS * lag <= n_frames] or [1]
    tau, m_movie, e_movie = msd_ratio(movie, lags)
    if film.periodic:
        # every skyrmion that starts in the middle copy, followed wherever it goes (as the
        # movie's unwrapped tracks are): the seen copy alone would keep only those that stay
        assert film.period is not None
        x0, y0 = film.origin
        lx, ly = film.period
        e = run.everything
        middle = (e.x >= x0) & (e.x < x0 + lx) & (e.y >= y0) & (e.y < y0 + ly)
        _, m_model, e_model = msd_ratio(e, lags, middle)
    else:
        _, m_model, e_model = msd_ratio(run.frames, lags)
    z_msd = (m_model - m_movie) / np.hypot(e_movie, e_model)
    with np.errstate(invalid="ignore", divide="ignore"):
        relative = m_model / m_movie - 1.0
    within_errors = bool(np.all(np.abs(z_msd[np.isfinite(z_msd)]) <= MAX_Z))
    within_tolerance = bool(np.all(np.abs(relative[np.isfinite(relative)]) <= MSD_TOLERANCE))

    region = film.outline
    seen_movie = _folded(film, movie)
    seen_model = _folded(film, run.frames)
    g_movie, g_movie_err = _pair_correlation(seen_movie, region, r_max, bins)
    g_model, g_model_err = _pair_correlation(seen_model, region, r_max, bins)
    if pair_potential_error is not None:
        # the model's g(r) is as uncertain as its pair law: to first order g ∝ exp(−V(r)),
        # δg = g δV. With strong pairs a percent of the force moves g(r) at its first peak by
        # more than the movie's errors there, which alone are no evidence of a wrong law.
        g_model_err = np.hypot(g_model_err, g_model.g * pair_potential_error(g_model.r))
    use = g_movie.pairs >= MIN_PAIRS
    with np.errstate(invalid="ignore", divide="ignore"):
        z_g = (g_model.g - g_movie.g) / np.hypot(g_movie_err, g_model_err)
    chi2_g = _chi2(z_g[use]) if use.sum() >= 3 and interacting else None

    lm = boltzmann_inversion(seen_movie, region, spacing, candidates=[bandwidth], seed=seed)
    lr = boltzmann_inversion(seen_model, region, spacing, candidates=[bandwidth], seed=seed + 1)
    err_m = _density_error(lm)
    err_r = _density_error(lr)
    both = lm.well_sampled & lr.well_sampled & np.isfinite(err_m) & np.isfinite(err_r)
    chi2_d = None
    if both.sum() >= 10:
        diff = lr.u[both] - lm.u[both]
        diff = diff - diff.mean()
        chi2_d = _chi2(diff / np.hypot(err_m[both], err_r[both]))
    checks = {
        "msd": {
            "lag_time_s": tau.tolist(),
            "movie_msd_over_4tau_m2_s": m_movie.tolist(),
            "movie_error_m2_s": e_movie.tolist(),
            "model_msd_over_4tau_m2_s": m_model.tolist(),
            "model_error_m2_s": e_model.tolist(),
            "z": [float(v) if np.isfinite(v) else None for v in z_msd],
            "relative_deviation": [float(v) if np.isfinite(v) else None for v in relative],
            "within_errors": within_errors,
            "within_tolerance": within_tolerance,
            "max_z": MAX_Z,
            "tolerance": MSD_TOLERANCE,
            "passed": within_errors and within_tolerance,
            "rule": f"every lag within {MAX_Z:g} combined standard errors and within "
            f"{100 * MSD_TOLERANCE:g} % of the movie's",
        },
        "pair_correlation": {
            "r_m": g_movie.r.tolist(),
            "movie_g": g_movie.g.tolist(),
            "movie_error": g_movie_err.tolist(),
            "model_g": g_model.g.tolist(),
            "model_error": g_model_err.tolist(),
            "bins_compared": int(use.sum()),
            "chi2_per_bin": chi2_g,
            "passed": chi2_g is None or chi2_g <= MAX_CHI2,
            "judged": interacting,
            "rule": f"χ² per bin at most {MAX_CHI2:g} over the bins with at least {MIN_PAIRS} "
            "pairs in the movie"
            if interacting
            else "shown, not judged: the model has no pair law (g(r) then carries only the "
            "landscape, which the density map tests, and its errors over blocks of time are "
            "too small for skyrmions that meet again and again)",
        },
        "density": {
            "nodes_compared": int(both.sum()),
            "chi2_per_node": chi2_d,
            "passed": chi2_d is None or chi2_d <= MAX_CHI2,
            "rule": f"χ² per node of −ln ρ at most {MAX_CHI2:g} over the nodes both sample well, "
            "errors from a bootstrap over the tracks",
        },
    }
    failed = [name for name, c in checks.items() if not c["passed"]]
    return {
        **checks,
        "passed": not failed,
        "failed": failed,
        "checks": comparison_checks(checks),
        "model_skyrmions": run.skyrmions,
        "model_frames": int(run.frames.n_frames),
        "model_time_step_s": run.time_step,
    }


def _pair_correlation(frames: Frames, region, r_max: float, bins: int):
    """g(r) and its error, the larger of the jackknife errors over 20 and 5 blocks of time.

    Pairs that last longer than a short block make its errors too small; :data:`LONG_BLOCKS`
    longer blocks see them.
    """
    short = pair_correlation(frames, region, r_max, bins, max_frames=2000)
    long = pair_correlation(frames, region, r_max, bins, max_frames=2000, error_blocks=LONG_BLOCKS)
    return short, np.fmax(short.error, long.error)


def _density_error(lmap) -> np.ndarray:
    """The larger of the bootstrap errors over time and over tracks."""
    across = lmap.error_across_skyrmions
    return lmap.error if across is None else np.fmax(lmap.error, across)


def _folded(film: Film, frames: Frames) -> Frames:
    """Positions folded into a periodic box (unchanged otherwise)."""
    if not film.periodic:
        return frames
    x, y = film.wrap(frames.x, frames.y)
    return Frames(frames.time, frames.count, frames.ids, x, y)


def _number(value: float, unit: str = "", error: float | None = None, digits: int = 3) -> str:
    """``value`` (± ``error``) in ``unit`` as the reports write numbers (3 digits)."""
    from skygas.core.quantities import format_value

    return format_value(value, error, unit, digits=digits) or "?"


def _signed(value: float, digits: int) -> str:
    """``value`` with its sign, + or −, to ``digits`` significant digits."""
    return ("−" if value < 0 else "+") + _number(abs(value), digits=digits)


def _worst(values: list) -> int | None:
    """The index of the largest |value| of ``values`` (None entries skipped), or None."""
    finite = [(abs(v), k) for k, v in enumerate(values) if v is not None and math.isfinite(v)]
    return max(finite)[1] if finite else None


def comparison_checks(check: dict) -> list[dict]:
    """The self-check's comparisons as quality checks (see :func:`quality_checks`).

    From ``check``, the dict :func:`compare` returns (inference.json's ``consistency_check``):
    MSD(τ)/4τ within :data:`MAX_Z` combined errors, MSD(τ)/4τ within :data:`MSD_TOLERANCE`,
    and g(r) and the density map where they were judged (χ² at most :data:`MAX_CHI2`).
    """
    out = []
    msd = check["msd"]
    tau = msd["lag_time_s"]
    lags = (
        f"{len(tau)} lags, {_number(tau[0], 's')} to {_number(tau[-1], 's')}"
        if len(tau) > 1
        else "1 lag"
    )
    k = _worst(msd["z"])
    if k is not None:
        z = msd["z"][k]
        out.append(
            {
                "name": "self-check: MSD(τ)/4τ within its errors",
                "value": z,
                "tolerance": msd.get("max_z", MAX_Z),
                "unit": "combined standard errors",
                "passed": abs(z) <= msd.get("max_z", MAX_Z),
                "what": f"the model's MSD(τ)/4τ is {_signed(z, 2)} combined standard errors "
                f"from the movie's at τ = {_number(tau[k], 's')}, the farthest of {lags} (at "
                f"most {_number(msd.get('max_z', MAX_Z))} at every lag)",
            }
        )
    k = _worst(msd.get("relative_deviation", []))
    if k is not None:
        rel = msd["relative_deviation"][k]
        tolerance = msd.get("tolerance", MSD_TOLERANCE)
        movie, error = msd["movie_msd_over_4tau_m2_s"][k], msd["movie_error_m2_s"][k]
        model = _number(msd["model_msd_over_4tau_m2_s"][k], "m²/s")
        out.append(
            {
                "name": f"self-check: MSD(τ)/4τ within {100 * tolerance:g} %",
                "value": rel,
                "tolerance": tolerance,
                "unit": "relative deviation from the movie's",
                "passed": abs(rel) <= tolerance,
                "what": f"the model's MSD(τ)/4τ is {_signed(100 * rel, 3)} % off the movie's "
                f"at τ = {_number(tau[k], 's')} ({model} against "
                f"{_number(movie, error=error, unit='m²/s')}), the farthest of {lags} "
                f"(at most ±{_number(100 * tolerance)} % at every lag)",
            }
        )
    g = check["pair_correlation"]
    if g.get("judged", True) and g["chi2_per_bin"] is not None:
        out.append(
            {
                "name": "self-check: g(r)",
                "value": g["chi2_per_bin"],
                "tolerance": MAX_CHI2,
                "unit": "χ² per bin",
                "passed": g["chi2_per_bin"] <= MAX_CHI2,
                "what": f"g(r) of the model against the movie's: χ² per bin "
                f"{_number(g['chi2_per_bin'])} over {g['bins_compared']} bins (at most "
                f"{_number(MAX_CHI2)})",
            }
        )
    d = check["density"]
    if d["chi2_per_node"] is not None:
        out.append(
            {
                "name": "self-check: density map",
                "value": d["chi2_per_node"],
                "tolerance": MAX_CHI2,
                "unit": "χ² per node",
                "passed": d["chi2_per_node"] <= MAX_CHI2,
                "what": f"the model's density map (−ln ρ) against the movie's: χ² per node "
                f"{_number(d['chi2_per_node'])} over {d['nodes_compared']} nodes (at most "
                f"{_number(MAX_CHI2)})",
            }
        )
    return out


def frames_check(summary: dict) -> dict:
    """Whether the frames resolve the motion, as a quality check.

    The value is the share of the raw D that is drift within a frame
    (:func:`skygas.inference.sampling.coarseness`), the tolerance the share below which the
    frames resolve the motion (:data:`skygas.inference.sampling.COARSE_SHARE`). Above it the
    check passes only where the estimator's bias was measured on runs of the model and the
    correction converged: without a correction (no self-check's runs, ``--check-frames 0``) D,
    the Hall angle and the forces carry that bias.
    """
    sc = summary["sampling_correction"]
    share, threshold = sc["drift_share_of_raw_d"], sc["threshold"]
    said = (
        f"the drift within a frame adds {_number(100 * share)} % to the D the steps' spread "
        f"reads ({'below' if abs(share) < threshold else 'at least'} "
        f"{_number(100 * threshold)} %)"
    )
    if abs(share) < threshold:
        passed, what = True, f"{said}: the frames resolve the motion"
    elif sc["applied"]:
        passed = True
        what = (
            f"{said}: the estimator's bias at this frame interval was measured on runs of the "
            f"model and taken out ({len(sc['rounds'])} rounds; the last run read what the "
            "movie read, within their errors)"
        )
    elif sc["made"]:
        passed, what = False, f"{said}: {summary['diffusion_constant_note']}"
    else:
        passed = False
        what = (
            f"{said}: D, the Hall angle and the forces carry the estimator's bias at this frame "
            "interval, and no correction was made (it runs the model: --check-frames > 0)"
        )
    return {
        "name": "frames resolve the motion (D, Hall angle, forces)",
        "value": share,
        "tolerance": threshold,
        "unit": "share of D",
        "passed": passed and bool(summary["diffusion_constant_fixed_by_data"]),
        "what": what,
    }


def quality_checks(summary: dict) -> list[dict]:
    """Every check of an inference against its stated tolerance, from its summary.

    Each is ``{"name", "value", "tolerance", "unit", "passed", "what"}``: the frames against
    the motion (:func:`frames_check`), then the self-check's comparisons
    (:func:`comparison_checks`; none when it did not run). The report's headline starts with
    them; a failed one is also a warning line on the terminal.
    """
    out = [frames_check(summary)]
    check = summary["consistency_check"]
    if check is not None:
        out += comparison_checks(check)
    return out


def summary_lines(check: dict) -> list[str]:
    """One warning line per failed comparison (none when the check passed)."""
    return [c["what"] for c in comparison_checks(check) if not c["passed"]]
