"""The pair potential by iterative Boltzmann inversion (IBI) with skygas simulations.

g(r) of the tracks (:func:`skygas.analysis.pair_correlation`, normalised by an ideal gas in the
same outline) starts the potential at V₀(r) = −k_BT ln g(r). Each iteration simulates the model
(the measured D and Hall angle, the wall law, the inferred pinning landscape, the current pair
law, as many skyrmions as the movie shows on average) in the device's outline, measures its
g(r) the same way, and corrects

    V_{n+1}(r) = V_n(r) + k_BT ln(g_n(r) / g_measured(r))

over the distances the data fix (the pinning landscape of the runs is the crowding-corrected
Boltzmann inversion of :mod:`skygas.inference.crowding`, held fixed; each iteration also
reports the rms of ln(ρ_n/ρ_measured) over the well-sampled nodes, both densities seen alike:
the model's positions plus the movie's localisation error, the movie's kernel), for
:data:`ITERATIONS` iterations (every run also serves the retuning of D), each reporting
χ² = mean((g_n − g)²/(σ_n² + σ²)). The law handed to the engine is the smooth fit of V
(:mod:`skygas.inference.laws`), weighted by σ_V = σ_g/g (the movie's error, and from the second
iteration on the previous run's as well), so each simulation runs the force −dV/dr of a smooth
V; the fit's covariance gives the force's statistical error (:meth:`IBIResult.force`).

The **distances the data fix** are the bins with at least :data:`MIN_PAIRS` pairs where
g is below 1 by more than two standard errors: closer, no pair was seen; farther, the
potential is indistinguishable from zero.
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy import ndimage

from skygas.analysis import pair_correlation
from skygas.analysis.frames import Frames
from skygas.analysis.structure import PairCorrelation
from skygas.core import units
from skygas.core.units import M_TO_NM
from skygas.inference.landscape import LandscapeMap, smoothed_density
from skygas.inference.laws import (
    coefficient_covariance,
    first_run,
    fit_exp_quadratic,
    force,
    force_error,
    force_table,
)
from skygas.physics.geometry import Outline

#: Iterations.
ITERATIONS = 6
#: A bin enters the fixed range with at least this many pairs.
MIN_PAIRS = 20
#: Bins of g(r) per skyrmion diameter: the pair law falls e-fold over about half a diameter,
#: and a fit that can bend (:func:`~skygas.inference.laws.fit_exp_quadratic`, five points or
#: more) needs several bins across the few diameters where g < 1.
BINS_PER_DIAMETER = 7
#: g(r) of the movie is counted over at most this many frames, evenly chosen.
MOVIE_FRAMES = 20000
#: The iterations' law replaces the material's only where the movie's g(r) fixes the force at
#: the middle of the range to this relative standard error.
MAX_FORCE_ERROR = 0.1
#: Frames of each simulation.
SIM_FRAMES = 2000


@dataclass
class IBIResult:
    """The iterations: r [m], measured g ± error, per iteration g_sim, V [k_BT], χ²; the range."""

    r: np.ndarray
    g: np.ndarray
    g_error: np.ndarray
    fixed: np.ndarray
    potentials: list = field(default_factory=list)
    simulated: list = field(default_factory=list)
    chi2: list = field(default_factory=list)
    coefs: list = field(default_factory=list)
    coef_covs: list = field(default_factory=list)
    density_rms: list = field(default_factory=list)
    #: σ_F/F at the middle of the fixed range from the movie's g(r) alone (None: no fit)
    initial_force_error: float | None = None

    @property
    def fixed_range(self) -> tuple[float, float] | None:
        """(closest, farthest) distance [m] the data fix, or None."""
        if not self.fixed.any():
            return None
        return float(self.r[self.fixed].min()), float(self.r[self.fixed].max())

    @property
    def coef(self):
        """The fit (c₀, c₁, c₂) of ln V, r in nm, of the last iteration (None if none)."""
        return self.coefs[-1] if self.coefs else None

    def force(self, r) -> tuple[np.ndarray, np.ndarray]:
        """The final law's force −dV/dr and its standard error [k_BT/m] at ``r`` [m].

        The error carries the movie's g(r) errors and the last simulation's to the fit
        (:func:`~skygas.inference.laws.force_error`); it is statistical only. Only for a result
        with a law of its own (:attr:`coef` not None).
        """
        if self.coef is None:
            raise ValueError("the iterations kept the material's pair law: no force of their own")
        r_nm = np.asarray(r, float) * M_TO_NM
        return (
            force(self.coef, r_nm) * M_TO_NM,
            force_error(self.coef, self.coef_covs[-1], r_nm) * M_TO_NM,
        )


def fixed_bins(g: np.ndarray, err: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """The bins the data fix: enough pairs and g below 1 by more than 2σ, from the first such."""
    return first_run(
        (pairs >= MIN_PAIRS) & np.isfinite(g) & (g > 0) & (g < 1 - 2 * np.nan_to_num(err, nan=1))
    )


def simulate(
    outline: Outline,
    material: dict,
    landscape: list,
    temperature: float,
    frame_interval: float,
    skyrmions: int,
    frames: int,
    seed: int,
    min_separation: float,
) -> Frames:
    """The model's positions over ``frames`` frames after 200 frames of relaxation."""
    from skygas.engine import Simulation
    from skygas.physics.materials import material_from_mapping

    model = material_from_mapping(material, field="inferred material")

    # the suggested step of the whole model (laws and landscape), shortened to divide a frame
    probe = Simulation(outline, model, temperature=temperature, landscape=landscape)
    steps = int(np.ceil(frame_interval / probe.suggested_time_step() - 1e-9))
    sim = Simulation(
        outline,
        model,
        temperature=temperature,
        seed=seed,
        landscape=landscape,
        time_step=frame_interval / steps,
    )
    sim.add_random(skyrmions, min_separation=min_separation)
    sim.run(200 * frame_interval)
    start = sim.time
    sim.run(frames * frame_interval, record_interval=frame_interval)
    ds = sim.trajectories()
    keep = ds.time.values >= start - 0.5 * frame_interval
    return Frames.from_dense(
        ds.time.values[keep] - ds.time.values[keep][0],
        ds.skyrmion.values,
        ds.x.values[keep],
        ds.y.values[keep],
    )


def iterate(
    frames: Frames,
    outline: Outline,
    material: dict,
    temperature: float,
    landscape: LandscapeMap,
    pinning: np.ndarray,
    sigma: float,
    folder: Path,
    *,
    measured: PairCorrelation,
    iterations: int = ITERATIONS,
    sim_frames: int = 2000,
    seed: int = 0,
    progress=None,
    retune=None,
) -> tuple[IBIResult, dict]:
    """Run IBI on the pair potential over the fixed ``pinning`` [k_BT] on the landscape's grid.

    ``retune(run)``, if given, is called with each simulation's positions and returns material
    fields for the next one (the D correction of :mod:`skygas.inference.bias`).
    Returns the iterations and the material with the final ``pair_table``: none if the data fix
    fewer than three distances, or if the fit of −ln g(r) leaves the force at the middle of
    their range uncertain by more than :data:`MAX_FORCE_ERROR` (the simulations then run the
    material's own pair law).
    """
    kt = units.BOLTZMANN * temperature
    grid = landscape.grid
    fixed = fixed_bins(measured.g, measured.error, measured.pairs)
    result = IBIResult(measured.r, measured.g, measured.error, fixed)
    rho_meas = smoothed_density(grid.bins(frames.x, frames.y), grid, landscape.bandwidth)
    update = landscape.well_sampled & (rho_meas > 0)
    pinning = np.where(landscape.well_sampled, pinning, np.nan)
    potential = pinning_grid_file(folder, pinning, grid.x, grid.y, pad_nodes(grid), "pinning")
    r_nm = measured.r * M_TO_NM
    v = -np.log(np.where(measured.g > 0, measured.g, np.nan))
    # σ(V) = σ_g/g: the movie's g(r), and from the second iteration on the last simulation's
    with np.errstate(divide="ignore", invalid="ignore"):
        v_error = measured.error / measured.g
    skyrmions, separation = gas_layout(frames, material, result.fixed_range)
    r_max = float(measured.edges[-1])
    rng = np.random.default_rng([seed, 0x1B1])
    result.initial_force_error = initial_force_error(r_nm[fixed], v[fixed], v_error[fixed])
    usable = (
        result.initial_force_error is not None and result.initial_force_error <= MAX_FORCE_ERROR
    )
    for n in range(iterations):
        current = dict(material)
        coef, cov = None, None
        if usable:
            coef = fit_exp_quadratic(r_nm[fixed], v[fixed], v_error[fixed])
        if coef is not None:
            cov = coefficient_covariance(r_nm[fixed], v[fixed], v_error[fixed])
            current["pair_table"] = force_table(
                coef, r_nm[fixed][0], 5 * r_nm[fixed][-1], kt, 1 / M_TO_NM
            )
        sim = simulate(
            outline,
            current,
            [potential],
            temperature,
            frames.frame_interval(),
            skyrmions,
            sim_frames,
            seed + n,
            separation,
        )
        seen = seen_as_movie(sim, sigma, rng)
        rho_sim = smoothed_density(grid.bins(seen.x, seen.y), grid, landscape.bandwidth)
        g_sim = pair_correlation(seen, outline, r_max, len(measured.r), max_frames=sim_frames)
        with np.errstate(divide="ignore", invalid="ignore"):
            sigma2 = measured.error**2 + g_sim.error**2
            chi2 = (
                float(np.mean((g_sim.g[fixed] - measured.g[fixed]) ** 2 / sigma2[fixed]))
                if fixed.any()
                else float("nan")
            )
            ratio = np.log(rho_sim / rho_meas)
        ok = update & np.isfinite(ratio)
        shift = ratio[ok] - np.mean(ratio[ok]) if ok.any() else np.zeros(0)
        result.potentials.append(v.copy())
        result.simulated.append((g_sim.g, g_sim.error))
        result.chi2.append(chi2)
        result.coefs.append(coef)
        result.coef_covs.append(cov)
        result.density_rms.append(float(np.sqrt(np.mean(shift**2))) if len(shift) else None)
        if coef is not None:
            material = current
        if retune is not None:
            material = {**material, **retune(sim)}
        if progress is not None:
            progress(
                f"IBI iteration {n + 1}: g(r) chi2 = {chi2:.2f}, density mismatch rms "
                f"{result.density_rms[-1] or 0:.3f} k_BT"
            )
        if n + 1 < iterations:
            good = fixed & (g_sim.g > 0)
            v[good] = v[good] + np.log(g_sim.g[good] / measured.g[good])
            with np.errstate(divide="ignore", invalid="ignore"):
                v_error = np.hypot(measured.error, g_sim.error) / measured.g
    return result, material


def initial_force_error(r_nm: np.ndarray, v: np.ndarray, v_error: np.ndarray) -> float | None:
    """σ_F/F at the middle of the fixed range, of the fit of V = −ln g (None: fewer than 3 points).

    The first iteration's law; the iterations move V but not how well the movie's g(r) fixes it.
    """
    if len(r_nm) < 3:
        return None
    coef = fit_exp_quadratic(r_nm, v, v_error)
    if coef is None:
        return None
    mid = 0.5 * (r_nm[0] + r_nm[-1])
    f = float(force(coef, mid))
    if not f > 0:
        return float("inf")
    cov = coefficient_covariance(r_nm, v, v_error)
    return float(force_error(coef, cov, mid)) / f


def measured_pair_correlation(
    frames: Frames, outline: Outline, r_max: float, skyrmion_diameter: float
) -> PairCorrelation:
    """The movie's g(r) over [0, ``r_max``], :data:`BINS_PER_DIAMETER` bins per diameter."""
    bins = max(1, int(np.ceil(BINS_PER_DIAMETER * r_max / skyrmion_diameter)))
    return pair_correlation(frames, outline, r_max, bins, max_frames=MOVIE_FRAMES)


def gas_layout(frames: Frames, material: dict, fixed_range) -> tuple[int, float]:
    """How a model run places its gas: (skyrmions, least separation at the start).

    The movie's mean number of skyrmions, and 0.9 of the closest distance the data fix in
    skyrmion diameters (at least half a diameter).
    """
    skyrmions = max(1, int(round(float(np.mean(frames.count)))))
    d_sk = 2 * material["skyrmion_radius"]
    closest = fixed_range[0] if fixed_range else d_sk
    return skyrmions, max(0.5, 0.9 * closest / d_sk)


def seen_as_movie(run: Frames, sigma: float, rng: np.random.Generator) -> Frames:
    """A run's positions as a movie sees them: Gaussian localisation error σ [m] added."""
    return Frames(
        run.time,
        run.count,
        run.ids,
        run.x + rng.normal(0.0, sigma, len(run.x)),
        run.y + rng.normal(0.0, sigma, len(run.y)),
    )


def pad_nodes(grid) -> int:
    """Nodes of padding around the landscape's grid for a ``grid`` potential: half its size."""
    return int(np.ceil(0.5 * max(len(grid.x), len(grid.y))))


def pinning_grid_file(
    folder: Path, u_kt: np.ndarray, x: np.ndarray, y: np.ndarray, pad: int, name: str
) -> dict:
    """Save U [k_BT], padded by ``pad`` nodes of edge values, as a ``grid`` potential.

    Nodes without a value (NaN: not well sampled) take the value of the nearest node with one:
    the landscape continues flat where the data say nothing, instead of stepping to 0 (a step
    at the edge of the sampled area would be a force the film does not have).
    """
    known = np.isfinite(u_kt)
    if known.any():
        nearest = ndimage.distance_transform_edt(
            ~known, return_distances=False, return_indices=True
        )
        values = u_kt[tuple(nearest)]
    else:
        values = np.zeros_like(u_kt)
    values = np.pad(values, pad, mode="edge")
    h = float(x[1] - x[0])
    path = Path(folder) / f"{name}.npy"
    np.save(path, values)
    return {
        "kind": "grid",
        "path": str(path),
        "spacing": h,
        "origin": (float(x[0] - pad * h), float(y[0] - pad * h)),
        "unit": "kT",
    }


def scratch_folder():
    """A temporary folder for the simulations' landscape file (removed afterwards)."""
    return tempfile.TemporaryDirectory(prefix="skygas-infer-")
