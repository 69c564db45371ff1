"""The mobility tensor, Hall angle and a drift-free D from thermal motion in the inferred forces.

The Thiele equation (docs/physics.md §1) gives a skyrmion pushed by a force F the velocity
v = M F with M = (α𝒟k I − G ε)/((α𝒟k)² + G²): along F at the rate p = α𝒟k/(…) and across it
at q = G/(…). The Hall angle is the angle from the force to the velocity,
θ_H = atan2(q, p) = atan2(G, α𝒟k) (counter-clockwise positive), the deflection of a skyrmion
driven by a force (a field gradient, a pinning site, a wall, a neighbour).

Thermal motion measures it: the mean displacement over a frame from r is dt·M·F(r), with the
force F = −∇U (U = −k_BT ln ρ of the Boltzmann inversion, walls included) plus the inferred pair
forces of the neighbours. Two estimators remove the localisation error ε of the tracked
positions:

- **across the force** (q): the displacement Δ = r(t+1) − r(t) against the mean of the forces
  at both ends, F̄ = ½(F(r(t)) + F(r(t+1))); ε enters Δ with opposite signs at the two ends, so
  its correlations with F̄ cancel (and the along-force part of this product vanishes in
  equilibrium, a check);
- **along the force** (p): Δ against F(r(t)), corrected for the correlation of −ε(t) with
  F(r(t) + ε(t)), which adds −σ² ∇·F: p = (Σ Δ·F + σ² Σ ∇·F)/(dt Σ |F|²).

Both are divided by Σ|F|², so a force map shrunk by the kernel's smoothing scales p and q by
the same factor and θ_H = atan2(q, p) is unbiased by it. The displacement minus the drift
dt·M·F then moves by thermal noise alone: its MSD, MSD(τ) = 4σ² + 4Dτ, gives D free of the
deterministic (gyrotropic) motion that inflates the plain MSD (:mod:`skygas.inference.diffusion`).
Standard errors by blocking over contiguous blocks of time.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from skygas.analysis.frames import Frames
from skygas.inference.diffusion import block_of_frame, blocked, time_blocks

#: Blocks of time for the errors.
BLOCKS = 16
#: Lags [frames] of the drift-free MSD.
RESIDUAL_LAGS = 4

#: A force on entries: (entries) → (F_x, F_y, ∇·F, usable) in k_BT/m, k_BT/m², bool.
ForceField = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]


@dataclass(frozen=True)
class Mobility:
    """θ_H [rad] ± ``error``; p, q [m² per k_BT·s... per frame: m/(k_BT/m)/s]; D [m²/s] ± error.

    ``p`` and ``q`` are per second: the velocity [m/s] per force [k_BT/m]; ``diffusion`` the
    drift-free D with its blocked ``diffusion_error``; ``samples`` the displacements used.
    """

    angle: float
    error: float
    p: float
    q: float
    diffusion: float
    diffusion_error: float
    samples: int

    def as_dict(self) -> dict:
        """JSON-able, SI units in the keys."""
        return {
            "hall_angle": self.angle,
            "hall_angle_error": self.error,
            "mobility_along_force_m2_per_kT_s": self.p,
            "mobility_across_force_m2_per_kT_s": self.q,
            "displacements": self.samples,
            "hall_angle_definition": "angle from the force to the velocity, counter-clockwise "
            "positive (atan2(G, alpha*D*k) of the Thiele equation)",
        }


def successor(frames: Frames) -> np.ndarray:
    """The entry of the same skyrmion in the next frame, or −1 (E,)."""
    nxt = np.full(len(frames.ids), -1, np.int64)
    a, b = frames.pairs_at_lag(1)
    nxt[a] = b
    return nxt


def fit_mobility(frames: Frames, force: ForceField, sigma: float) -> Mobility:
    """p, q, θ_H and the drift-free D of ``frames`` in ``force`` (localisation error σ [m])."""
    dt = frames.frame_interval()
    nxt = successor(frames)
    a = np.flatnonzero(nxt >= 0)
    b = nxt[a]
    fx, fy, div, ok = force(np.arange(len(frames.ids)))
    use = ok[a] & ok[b]
    a, b = a[use], b[use]
    dx, dy = frames.x[b] - frames.x[a], frames.y[b] - frames.y[a]
    mx, my = 0.5 * (fx[a] + fx[b]), 0.5 * (fy[a] + fy[b])
    along = dx * fx[a] + dy * fy[a] + sigma**2 * div[a]
    norm = fx[a] ** 2 + fy[a] ** 2
    across = -dx * my + dy * mx
    norm_mid = mx * mx + my * my
    frame = frames.frame_of_entry[a]

    def pq(sel):
        return (
            float(np.sum(along[sel]) / max(np.sum(norm[sel]), 1e-300) / dt),
            float(np.sum(across[sel]) / max(np.sum(norm_mid[sel]), 1e-300) / dt),
        )

    p, q = pq(np.ones(len(a), bool))
    blocks = time_blocks(frames.n_frames, BLOCKS)
    angles = [np.arctan2(*pq((frame >= k[0]) & (frame <= k[-1]))[::-1]) for k in blocks]
    # drift-free increments: Δ − dt·M·F(r(t)), chained into lags 1 … RESIDUAL_LAGS
    ex = np.full(len(frames.ids), np.nan)
    ey = np.full(len(frames.ids), np.nan)
    ex[a] = dx - dt * (p * fx[a] - q * fy[a])
    ey[a] = dy - dt * (q * fx[a] + p * fy[a])
    d, d_err = residual_diffusion(frames, nxt, ex, ey)
    return Mobility(float(np.arctan2(q, p)), blocked(np.array(angles)), p, q, d, d_err, int(len(a)))


def residual_diffusion(
    frames: Frames, nxt: np.ndarray, ex: np.ndarray, ey: np.ndarray
) -> tuple[float, float]:
    """D [m²/s] ± blocked error of the increments (ex, ey) [m] summed over 1 … RESIDUAL_LAGS."""
    dt = frames.frame_interval()
    frame = frames.frame_of_entry
    sx, sy = ex.copy(), ey.copy()
    cur = np.arange(len(ex))
    blocks = time_blocks(frames.n_frames, BLOCKS)
    block_of = block_of_frame(frames.n_frames, BLOCKS)
    sums = np.zeros((len(blocks), RESIDUAL_LAGS))
    counts = np.zeros((len(blocks), RESIDUAL_LAGS))
    for lag in range(1, RESIDUAL_LAGS + 1):
        if lag > 1:
            cur = np.where(cur >= 0, nxt[np.maximum(cur, 0)], -1)
            ok = cur >= 0
            sx = np.where(ok, sx + np.where(ok, ex[np.maximum(cur, 0)], np.nan), np.nan)
            sy = np.where(ok, sy + np.where(ok, ey[np.maximum(cur, 0)], np.nan), np.nan)
        good = np.isfinite(sx) & np.isfinite(sy)
        r2 = sx[good] ** 2 + sy[good] ** 2
        blk = block_of[frame[good]]
        sums[:, lag - 1] = np.bincount(blk, weights=r2, minlength=len(blocks))
        counts[:, lag - 1] = np.bincount(blk, minlength=len(blocks))
    tau = dt * np.arange(1, RESIDUAL_LAGS + 1)

    def d_of(s, c):
        return 4 * fit_linear(tau, s / np.maximum(c, 1))

    total = d_of(sums.sum(axis=0), counts.sum(axis=0))
    per = [d_of(sums[k], counts[k]) for k in range(len(blocks)) if counts[k, -1] > 0]
    return float(total / 4), blocked(np.array(per) / 4)


def fit_linear(tau: np.ndarray, msd: np.ndarray) -> float:
    """D [m²/s] of the line MSD = 4σ² + 4Dτ through ``msd`` [m²] at ``tau`` [s]."""
    slope, _ = np.polyfit(tau, msd, 1)
    return float(slope / 4.0)


def total_force(frames: Frames, landscape, pair_coef=None, cutoff: float = 0.0) -> ForceField:
    """The force on every entry: −∇U of the landscape map plus the neighbours' pair forces.

    ``landscape`` a :class:`~skygas.inference.landscape.LandscapeMap` (usable on its
    well-sampled nodes); ``pair_coef`` the fit (c₀, c₁, c₂) of ln V(r) [k_BT], r in nm
    (:mod:`skygas.inference.laws`), applied up to ``cutoff`` [m]; None: no pair forces.
    """
    gx, gy = landscape.gradient()
    h = landscape.grid.h
    div_map = -(np.gradient(gx, h, axis=1) + np.gradient(gy, h, axis=0))
    j, i = landscape.grid.node_of(frames.x, frames.y)
    ok = landscape.well_sampled[j, i] & np.isfinite(gx[j, i]) & np.isfinite(div_map[j, i])
    fx, fy, div = -gx[j, i], -gy[j, i], div_map[j, i]
    if pair_coef is not None and cutoff > 0:
        from skygas.inference.laws import force, potential

        c1, c2 = pair_coef[1], pair_coef[2]

        def law(r):
            return force(pair_coef, r * 1e9) * 1e9

        def dlaw(r):
            rn = r * 1e9
            return (-2 * c2 + (c1 + 2 * c2 * rn) ** 2) * potential(pair_coef, rn) * 1e18

        px, py, pd = pair_force(frames, law, dlaw, cutoff)
        fx, fy, div = fx + px, fy + py, div + pd

    def field(entries):
        return fx[entries], fy[entries], div[entries], ok[entries]

    return field


def pair_force(frames: Frames, law: Callable, dlaw: Callable, cutoff: float):
    """Σ_j f(r_ij) r̂_ij [k_BT/m] on each entry and its divergence Σ_j (f′ + f/r) (2D, radial).

    ``law(r)`` f [k_BT/m] and ``dlaw(r)`` f′ [k_BT/m²] at r [m], zero beyond ``cutoff`` [m].
    """
    from scipy.spatial import cKDTree

    fx = np.zeros(len(frames.x))
    fy = np.zeros(len(frames.x))
    div = np.zeros(len(frames.x))
    off = frames.offsets
    for f in range(frames.n_frames):
        lo, hi = off[f], off[f + 1]
        if hi - lo < 2:
            continue
        xy = np.column_stack([frames.x[lo:hi], frames.y[lo:hi]])
        pairs = cKDTree(xy).query_pairs(cutoff, output_type="ndarray")
        if len(pairs) == 0:
            continue
        i, j = pairs[:, 0], pairs[:, 1]
        d = xy[i] - xy[j]
        r = np.hypot(d[:, 0], d[:, 1])
        mag = law(r) / np.maximum(r, 1e-30)
        dv = dlaw(r) + law(r) / np.maximum(r, 1e-30)
        for k, sign in ((i, 1.0), (j, -1.0)):
            np.add.at(fx, lo + k, sign * mag * d[:, 0])
            np.add.at(fy, lo + k, sign * mag * d[:, 1])
            np.add.at(div, lo + k, dv)
    return fx, fy, div
