"""The pair potential by iterative Boltzmann inversion (IBI) with skygas simulations.

g(r) of the tracks (:func:`skygas.analysis.pair_correlation`, normalised by an ideal gas in the
same outline) starts the potential at V₀(r) = −k_BT ln g(r). Each iteration simulates the model
(the measured D and Hall angle, the wall law, the inferred pinning landscape, the current pair
law, as many skyrmions as the movie shows on average) in the device's outline, measures its
g(r) the same way, and corrects

    V_{n+1}(r) = V_n(r) + k_BT ln(g_n(r) / g_measured(r))

and, at the same time, the pinning landscape (the one-body Boltzmann inversion is exact only for
independent skyrmions: in a crowded gas the neighbours flatten the density, and the kernel and
the localisation error smooth it):

    U_{n+1}(x, y) = U_n(x, y) + ½ k_BT ln(ρ_n(x, y) / ρ_measured(x, y))

on the well-sampled nodes, with ρ_n estimated from the simulation's positions plus the movie's
localisation error with the movie's kernel, so that both densities are seen alike (damped by
:data:`LANDSCAPE_DAMPING`, and only where the mismatch exceeds :data:`SIGNIFICANCE` times the
combined standard error of the two maps: the bootstrap error of the movie's, scaled by the
ratio of the samples for the model's).

over the distances the data fix, until χ² = mean((g_n − g)²/(σ_n² + σ²)) is at most
:data:`CHI2_GOAL` or :data:`ITERATIONS` are done. The law handed to the engine is the smooth fit
of V (:mod:`skygas.inference.laws`), so each simulation runs the force −dV/dr of a smooth V.

The **distances the data fix** are the bins with at least :data:`MIN_PAIRS` pairs where
g is below 1 by more than two standard errors: closer, no pair was seen; farther, the
potential is indistinguishable from zero.
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from skygas.analysis import pair_correlation
from skygas.analysis.frames import Frames
from skygas.core import units
from skygas.core.units import M_TO_NM
from skygas.inference.landscape import LandscapeMap, smoothed_density
from skygas.inference.laws import fit_exp_quadratic, force_table
from skygas.physics.geometry import Outline

#: Iterations at most, and the χ² that ends them earlier.
ITERATIONS = 6
CHI2_GOAL = 1.5
#: A bin enters the fixed range with at least this many pairs.
MIN_PAIRS = 20
#: Bins of g(r).
BINS = 40
#: Frames of each simulation.
SIM_FRAMES = 2000
#: The landscape's correction is damped by this factor (each simulation's density is noisy:
#: a full step would pile its noise into the map).
LANDSCAPE_DAMPING = 0.5
#: ... and applied only where the mismatch exceeds this many combined standard errors.
SIGNIFICANCE = 2.0


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
    density_rms: list = field(default_factory=list)
    last_frames: Frames | None = None

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


def fixed_bins(g: np.ndarray, err: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """The bins the data fix: enough pairs and g below 1 by more than 2σ, from the first such."""
    ok = (pairs >= MIN_PAIRS) & np.isfinite(g) & (g > 0) & (g < 1 - 2 * np.nan_to_num(err, nan=1))
    out = np.zeros(len(g), bool)
    idx = np.flatnonzero(ok)
    if len(idx):
        k = idx[0]
        while k < len(g) and ok[k]:
            out[k] = True
            k += 1
    return out


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
    r_max: float,
    iterations: int = ITERATIONS,
    sim_frames: int = 2000,
    seed: int = 0,
    progress=None,
) -> tuple[IBIResult, dict, np.ndarray]:
    """Run IBI on the pair potential and the pinning landscape together.

    Returns the iterations, the material with the final ``pair_table`` (none if the data fix
    fewer than three distances) and the final pinning [k_BT] on the landscape's grid.
    """
    kt = units.BOLTZMANN * temperature
    grid = landscape.grid
    measured = pair_correlation(frames, outline, r_max, BINS, max_frames=2000)
    fixed = fixed_bins(measured.g, measured.error, measured.pairs)
    result = IBIResult(measured.r, measured.g, measured.error, fixed)
    rho_meas = smoothed_density(grid.bins(frames.x, frames.y), grid, landscape.bandwidth)
    update = landscape.well_sampled & (rho_meas > 0)
    pinning = np.where(landscape.well_sampled, np.nan_to_num(pinning), 0.0)
    r_nm = measured.r * M_TO_NM
    v = -np.log(np.where(measured.g > 0, measured.g, np.nan))
    skyrmions = max(1, int(round(float(np.mean(frames.count)))))
    d_sk = 2 * material["skyrmion_radius"]
    closest = float(measured.r[fixed].min()) if fixed.any() else d_sk
    separation = max(0.5, 0.9 * closest / d_sk)
    pad = int(np.ceil(0.5 * max(len(grid.x), len(grid.y))))
    rng = np.random.default_rng([seed, 0x1B1])
    for n in range(iterations):
        current = dict(material)
        coef = None
        if fixed.sum() >= 3:
            coef = fit_exp_quadratic(r_nm[fixed], v[fixed], np.full(fixed.sum(), 0.1))
        if coef is not None:
            current["pair_table"] = force_table(
                coef, r_nm[fixed][0], 5 * r_nm[fixed][-1], kt, 1 / M_TO_NM
            )
        potential = pinning_grid_file(folder, pinning, grid.x, grid.y, pad, f"pinning_{n}")
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
        # the model's positions seen as the movie sees them: the same localisation error
        seen = Frames(
            sim.time,
            sim.count,
            sim.ids,
            sim.x + rng.normal(0, sigma, len(sim.x)),
            sim.y + rng.normal(0, sigma, len(sim.y)),
        )
        rho_sim = smoothed_density(grid.bins(seen.x, seen.y), grid, landscape.bandwidth)
        g_sim = pair_correlation(seen, outline, r_max, BINS, max_frames=2000)
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
        # the model's density is as noisy as its sample is small: correct only where the
        # mismatch exceeds twice the combined standard error of both maps
        noise = landscape.error[ok] * np.sqrt(1 + len(frames.x) / max(len(sim.x), 1))
        significant = np.abs(shift) > SIGNIFICANCE * noise
        result.potentials.append(v.copy())
        result.simulated.append((g_sim.g, g_sim.error))
        result.chi2.append(chi2)
        result.coefs.append(coef)
        result.density_rms.append(float(np.sqrt(np.mean(shift**2))) if len(shift) else None)
        result.last_frames = sim
        if coef is not None:
            material = current
        if progress is not None:
            progress(
                f"IBI iteration {n + 1}: g(r) chi2 = {chi2:.2f}, density mismatch rms "
                f"{result.density_rms[-1] or 0:.3f} k_BT"
            )
        if n + 1 < iterations:
            pinning[ok] += LANDSCAPE_DAMPING * np.where(significant, shift, 0.0)
            good = fixed & (g_sim.g > 0)
            v[good] = v[good] + np.log(g_sim.g[good] / measured.g[good])
    return result, material, pinning


def pinning_grid_file(
    folder: Path, u_kt: np.ndarray, x: np.ndarray, y: np.ndarray, pad: int, name: str
) -> dict:
    """Save U [k_BT] (NaN → 0), padded by ``pad`` nodes of edge values, as a ``grid`` potential."""
    values = np.nan_to_num(u_kt, nan=0.0)
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
