"""The mobility tensor and the Hall angle from thermal motion in the inferred landscape's force.

The Thiele equation (docs/physics.md §1) gives a skyrmion pushed by a force F the velocity
v = M F with M = (α𝒟k I − G ε)/((α𝒟k)² + G²): along F at the rate p = α𝒟k/(…) and across it
at q = G/(…). The Hall angle is the angle from the force to the velocity,
θ_H = atan2(q, p) = atan2(G, α𝒟k) (counter-clockwise positive), the deflection of a skyrmion
driven by a force (a field gradient, a pinning site, a wall, a neighbour).

Thermal motion measures it: the mean displacement over a short time τ from r is τ·M·F(r). The
force is F = −∇U with U = −k_BT ln ρ of the Boltzmann inversion: in equilibrium the mean force
on a skyrmion at r, pinning, walls and the neighbours' pushes averaged over where the
neighbours are, is exactly k_BT ∇ln ρ(r) (the first equation of the Yvon–Born–Green hierarchy),
so no pair law is needed. Four things keep the estimate unbiased to within a degree or two
(measured on simulated gases with a known Hall angle of 77°, docs/inference.md):

- **held-out force**: the force at a displacement's start is read from the map of the *other*
  blocks of time (:func:`skygas.inference.landscape.held_out_maps`); from the map of all
  positions it leans toward where the skyrmion went next, which makes p too large (−4° to −8°);
- **selection at the start only**: a displacement is used when its start is well sampled;
  asking its end to be well sampled too selects by the displacement's own noise (−1° to −2°);
- **localisation error** ε of the tracked positions: across the force, Δ = r(t+τ) − r(t) is
  regressed on the mean of the forces at both ends, F̄ = ½(F(r(t)) + F(r(t+τ))), with which ε's
  correlations cancel; along it, Δ on F(r(t)) plus σ²∇·F, which takes out the correlation of
  −ε(t) with F(r(t) + ε(t)):

      p(τ) = (Σ Δ·F + σ² Σ ∇·F)/(τ Σ |F|²),   q(τ) = Σ (F̄ × Δ)/(τ Σ |F̄|²);

- **finite frames**: the force changes within a frame (the skyrmion circles the wells), so p(τ)
  and q(τ) drift with τ; both are computed at lags 1 … :data:`LAGS` and extrapolated linearly to
  τ = 0 (at 5 ns frames the first lag alone reads 2–3° low).

Both p and q are divided by Σ|F|², so a force map shrunk by the kernel's smoothing scales them by
the same factor and θ_H is unbiased by it. The standard error is a jackknife over
:data:`BLOCKS` contiguous blocks of time.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from skygas.analysis.frames import Frames
from skygas.inference.diffusion import block_of_frame

#: Blocks of time for the jackknife error.
BLOCKS = 16
#: Frame lags of p(τ), q(τ), extrapolated to τ = 0.
LAGS = (1, 2, 3)

#: A force on entries: (entries) → (F_x, F_y, ∇·F, usable) in k_BT/m, k_BT/m², bool.
ForceField = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]


@dataclass(frozen=True)
class Mobility:
    """θ_H [rad] ± ``error``; p, q [m/s per k_BT/m] at τ → 0 from ``lags`` [frames].

    ``p_at_lag`` and ``q_at_lag`` the estimates at each lag of :data:`LAGS` (one lag in
    ``lags``: the extrapolation was not possible and the first lag was used);
    ``samples`` the displacements used at lag 1.
    """

    angle: float
    error: float
    p: float
    q: float
    lags: tuple[int, ...]
    p_at_lag: np.ndarray
    q_at_lag: np.ndarray
    samples: int

    def as_dict(self) -> dict:
        """JSON-able, SI units in the keys."""
        return {
            "hall_angle": self.angle,
            "hall_angle_error": self.error,
            "mobility_along_force_m2_per_kT_s": self.p,
            "mobility_across_force_m2_per_kT_s": self.q,
            "mobility_lags_frames": list(self.lags),
            "hall_angle_extrapolated_to_zero_lag": len(self.lags) > 1,
            "mobility_along_force_at_lag": self.p_at_lag.tolist(),
            "mobility_across_force_at_lag": self.q_at_lag.tolist(),
            "displacements": self.samples,
            "hall_angle_definition": "angle from the force to the velocity, counter-clockwise "
            "positive (atan2(G, alpha*D*k) of the Thiele equation)",
            "hall_angle_method": "displacements from well-sampled starts "
            "regressed on the held-out force k_BT∇ln ρ at lags 1-3, p and q extrapolated "
            "linearly to τ = 0; jackknife error over 16 blocks of time",
        }


def _lag_sums(frames: Frames, fields: tuple, sigma: float, lag: int) -> np.ndarray:
    """Σ Δ·F + σ²∇·F, Σ|F|², Σ F̄×Δ, Σ|F̄|² per block of time (4, BLOCKS) at ``lag``.

    ``fields`` (F_x, F_y, ∇·F, usable) at every entry (a :data:`ForceField` of all of them).
    """
    fx, fy, div, ok = fields
    a, b = frames.pairs_at_lag(lag)
    use = ok[a] & np.isfinite(fx[b]) & np.isfinite(fy[b])
    a, b = a[use], b[use]
    dx, dy = frames.x[b] - frames.x[a], frames.y[b] - frames.y[a]
    mx, my = 0.5 * (fx[a] + fx[b]), 0.5 * (fy[a] + fy[b])
    columns = (
        dx * fx[a] + dy * fy[a] + sigma**2 * div[a],
        fx[a] ** 2 + fy[a] ** 2,
        -dx * my + dy * mx,
        mx * mx + my * my,
    )
    blk = block_of_frame(frames.n_frames, BLOCKS)[frames.frame_of_entry[a]]
    return np.array([np.bincount(blk, weights=c, minlength=BLOCKS) for c in columns])


def _extrapolate(sums: np.ndarray, tau: np.ndarray) -> tuple[float, float, np.ndarray, np.ndarray]:
    """(p₀, q₀, p(τ), q(τ)) of the per-lag sums (lags, 4): lines in τ through p(τ), q(τ)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        p = sums[:, 0] / sums[:, 1] / tau
        q = sums[:, 2] / sums[:, 3] / tau
    if len(tau) < 2 or not (np.all(np.isfinite(p)) and np.all(np.isfinite(q))):
        return float(p[0]), float(q[0]), p, q
    return float(np.polyfit(tau, p, 1)[1]), float(np.polyfit(tau, q, 1)[1]), p, q


def fit_mobility(
    frames: Frames,
    force: ForceField,
    sigma: float,
    lags: tuple[int, ...] = LAGS,
) -> Mobility:
    """p, q and θ_H of ``frames`` in ``force`` (localisation error σ [m]) at ``lags`` → 0.

    Where the extrapolation gives p ≤ 0 (a negative dissipation: the data are too few for it),
    the first lag alone is used, and ``lags`` says so.
    """
    lags = tuple(lag for lag in lags if lag < frames.n_frames)
    fields = force(np.arange(len(frames.x)))
    per = np.array([_lag_sums(frames, fields, sigma, lag) for lag in lags])
    p, q, p_lag, q_lag = _extrapolate(per.sum(axis=2), frames.frame_interval() * np.array(lags))
    if not p > 0:
        lags, per = lags[:1], per[:1]
        p, q, _, _ = _extrapolate(per.sum(axis=2), frames.frame_interval() * np.array(lags))
    tau = frames.frame_interval() * np.array(lags, float)
    total = per.sum(axis=2)
    angle = float(np.arctan2(q, p))
    # jackknife: leave one block of time out
    kept = [k for k in range(BLOCKS) if per[0, 1, k] > 0]
    angles = []
    for k in kept:
        pk, qk, _, _ = _extrapolate(total - per[:, :, k], tau)
        angles.append(np.arctan2(qk, pk))
    n = len(angles)
    # the jackknife variance of an angle near ±π would wrap; the Hall angle is far from it
    error = (
        float(np.sqrt((n - 1) / n * np.sum((np.array(angles) - np.mean(angles)) ** 2)))
        if n > 1
        else float("nan")
    )
    a, _ = frames.pairs_at_lag(lags[0])
    samples = int(np.sum(fields[3][a]))
    return Mobility(angle, error, p, q, lags, p_lag, q_lag, samples)


def landscape_force(frames: Frames, landscape) -> ForceField:
    """The force −∇U [k_BT/m] and its divergence at every entry, each from a held-out map.

    ``landscape`` a :class:`~skygas.inference.landscape.LandscapeMap`: each block of time reads
    the map of the others (:func:`~skygas.inference.landscape.held_out_maps`); an entry is usable
    where ``landscape`` is well sampled and the held-out map is finite.
    """
    from skygas.inference.landscape import held_out_maps

    h = landscape.grid.h
    n = len(frames.x)
    fx, fy, div = np.full(n, np.nan), np.full(n, np.nan), np.full(n, np.nan)
    ok = np.zeros(n, bool)
    j, i = landscape.grid.node_of(frames.x, frames.y)
    for entries, u in held_out_maps(frames, landscape):
        gy, gx = np.gradient(u, h)
        d = -(np.gradient(gx, h, axis=1) + np.gradient(gy, h, axis=0))
        je, ie = j[entries], i[entries]
        fx[entries], fy[entries], div[entries] = -gx[je, ie], -gy[je, ie], d[je, ie]
        ok[entries] = (
            landscape.well_sampled[je, ie]
            & np.isfinite(gx[je, ie])
            & np.isfinite(gy[je, ie])
            & np.isfinite(d[je, ie])
        )

    def field(entries):
        return fx[entries], fy[entries], div[entries], ok[entries]

    return field
