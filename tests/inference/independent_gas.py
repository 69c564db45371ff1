"""An overdamped gas simulated without skygas: the truth that ``skygas infer`` is checked against.

Nothing here imports skygas's engine or its force laws. The integrator is its own (Euler–Maruyama
with sub-steps), and so are the laws:

    dx = D (I − tan θ_H ε) f(x) dt + v_drive dt + √(2D dt) ξ,      ε = [[0, 1], [−1, 0]],

with f the force in units of k_BT per metre. This is the Thiele equation of a skyrmion written
with its free diffusion constant D and its Hall angle θ_H: the velocity M·F with
M = p I − q ε, p = D/k_BT, q/p = tan θ_H, and a thermal noise of covariance 2D per component
(docs/physics.md §1). The forces:

- **wells**: U(x) = −Σ_k A_k exp(−|x − c_k|²/2s_k²) [k_BT] (Gaussian pins);
- **pairs**: a central repulsion f(r) = A K₁(r/λ) [k_BT/m] (the modified Bessel function of
  the thin-film skyrmion interaction), or the paper's S2 law, cut at ``pair_cutoff``;
- **walls**: W(d) = A_w exp(−d/ℓ) [k_BT] of the distance d to the nearest edge of a
  rectangular film, pushing along that edge's inward normal (the convention of the paper's law);
- **drive**: a uniform force (a current), which puts the gas out of equilibrium.

Boundaries: ``walls`` (a closed rectangle), ``periodic`` (positions written wrapped into the
box, as a periodic code writes them), or a film that is periodic while the movie sees only a
field of view inside it (``field_of_view``): a skyrmion that leaves it ends its track, and one
that enters starts a new one.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd
from scipy import special

#: Boltzmann's constant [J/K] (CODATA), written here so that nothing comes from skygas.
BOLTZMANN = 1.380649e-23


@dataclass(frozen=True)
class GasSpec:
    """What to simulate; lengths in metres, times in seconds, energies in k_BT.

    ``wells`` (k, 4): x, y, depth A [k_BT], width s [m]. ``pair``: None, ``("k1", A, λ)`` with A
    in k_BT/m, or ``("s2", F₀ / k_BT [1/m], d_sk [m])``. ``wall``: None or (A_w [k_BT], ℓ [m]).
    ``drive``: a uniform force (f_x, f_y) [k_BT/m]. ``field_of_view``: (x0, y0, x1, y1) [m] of a
    periodic film, or None.
    """

    skyrmions: int = 30
    frames: int = 2000
    frame_interval: float = 10e-3
    substeps: int = 4
    width: float = 30e-6
    height: float = 30e-6
    boundary: str = "walls"
    diffusion: float = 0.31e-12
    hall_angle: float = 0.0
    wells: np.ndarray = field(default_factory=lambda: np.zeros((0, 4)))
    pair: tuple | None = None
    pair_cutoff: float = np.inf
    wall: tuple | None = None
    drive: tuple[float, float] = (0.0, 0.0)
    localisation_error: float = 0.0
    field_of_view: tuple[float, float, float, float] | None = None
    pixel_size: float = 100e-9
    temperature: float = 300.0
    seed: int = 1

    def with_(self, **changes) -> GasSpec:
        """A copy with ``changes``."""
        return replace(self, **changes)


def random_wells(
    count: int, width: float, height: float, depth: float, size: float, seed: int, margin=0.0
) -> np.ndarray:
    """``count`` wells of depth ``depth`` ± 30 % [k_BT] and width ``size`` [m] at random places."""
    rng = np.random.default_rng([seed, 0x3E11])
    return np.column_stack(
        [
            rng.uniform(margin, width - margin, count),
            rng.uniform(margin, height - margin, count),
            depth * rng.uniform(0.7, 1.3, count),
            np.full(count, size),
        ]
    )


def _periodic(spec: GasSpec) -> bool:
    return spec.boundary == "periodic" or spec.field_of_view is not None


def _separation(spec: GasSpec, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a − b, by the minimum image in a periodic film."""
    d = a - b
    if _periodic(spec):
        box = np.array([spec.width, spec.height])
        d = d - box * np.round(d / box)
    return d


def landscape(spec: GasSpec, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """U [k_BT] of the wells at points x, y [m] (any shape)."""
    p = np.stack([np.asarray(x, float), np.asarray(y, float)], axis=-1)
    u = np.zeros(p.shape[:-1])
    for cx, cy, depth, s in spec.wells:
        d = _separation(spec, p, np.array([cx, cy]))
        u -= depth * np.exp(-np.sum(d * d, axis=-1) / (2 * s * s))
    return u


def _well_forces(spec: GasSpec, pos: np.ndarray) -> np.ndarray:
    """−∇U [k_BT/m] of the wells on each skyrmion at ``pos`` (n, 2), all wells at once."""
    centres, depth, s = spec.wells[:, :2], spec.wells[:, 2], spec.wells[:, 3]
    d = _separation(spec, pos[:, None, :], centres[None, :, :])
    weight = (depth / (s * s)) * np.exp(-np.sum(d * d, axis=-1) / (2 * s * s))
    return -np.sum(weight[..., None] * d, axis=1)


def pair_force(spec: GasSpec, r) -> np.ndarray:
    """The pair repulsion f(r) [k_BT/m] (0 without pairs and beyond the cut-off)."""
    r = np.asarray(r, float)
    if spec.pair is None:
        return np.zeros_like(r)
    kind, amplitude, length = spec.pair
    if kind == "k1":
        f = amplitude * special.k1(r / length)
    elif kind == "s2":
        # the paper's fitted S2 law, d in skyrmion diameters: F₀ exp(−(a₂d² + a₁d + a₀)/(d + 1))
        d = np.minimum(r / length, 1e6)  # the diagonal's r = inf would give inf/inf
        a2, a1, a0 = 2.709, -5.643, 0.964
        f = amplitude * np.exp(-(a2 * d * d + a1 * d + a0) / (d + 1))
    else:
        raise ValueError(f"unknown pair law {kind!r}")
    return np.where(r < spec.pair_cutoff, f, 0.0)


def wall_potential(spec: GasSpec, d) -> np.ndarray:
    """W(d) [k_BT] of one edge at distance d [m]."""
    if spec.wall is None:
        return np.zeros_like(np.asarray(d, float))
    amplitude, decay = spec.wall
    return amplitude * np.exp(-np.asarray(d, float) / decay)


def _forces(spec: GasSpec, pos: np.ndarray) -> np.ndarray:
    """f [k_BT/m] on each skyrmion at ``pos`` (n, 2)."""
    f = np.zeros_like(pos)
    f += np.asarray(spec.drive, float)
    if len(spec.wells):
        f += _well_forces(spec, pos)
    if spec.pair is not None and len(pos) > 1:
        d = _separation(spec, pos[:, None, :], pos[None, :, :])
        r = np.sqrt(np.sum(d * d, axis=-1))
        np.fill_diagonal(r, np.inf)
        magnitude = pair_force(spec, r)
        f += np.sum((magnitude / r)[..., None] * d, axis=1)
    if spec.wall is not None and spec.boundary == "walls":
        # the nearest edge pushes, along its inward normal (the convention of the paper's law)
        amplitude, decay = spec.wall
        d = np.column_stack([pos[:, 0], spec.width - pos[:, 0], pos[:, 1], spec.height - pos[:, 1]])
        nearest = np.argmin(d, axis=1)
        push = (amplitude / decay) * np.exp(-d[np.arange(len(pos)), nearest] / decay)
        normal = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])[nearest]
        f += push[:, None] * normal
    return f


def _start(spec: GasSpec, rng) -> np.ndarray:
    """Random starting positions, kept apart by the pair law's length (none without one)."""
    margin = 3 * spec.wall[1] if spec.wall is not None and spec.boundary == "walls" else 0.0
    apart = 1.5 * spec.pair[2] if spec.pair is not None else 0.0
    pos = np.zeros((0, 2))
    while len(pos) < spec.skyrmions:
        p = rng.uniform([margin, margin], [spec.width - margin, spec.height - margin])
        if len(pos) == 0 or np.min(np.hypot(*_separation(spec, pos, p).T)) > apart:
            pos = np.vstack([pos, p])
    return pos


def relaxation_frames(spec: GasSpec) -> int:
    """Frames of relaxation: the time a skyrmion takes to diffuse one mean spacing (200–3000)."""
    spacing2 = spec.width * spec.height / spec.skyrmions
    frames = spacing2 / (4 * spec.diffusion * spec.frame_interval)
    return int(np.clip(frames, 200, 3000))


@dataclass(frozen=True)
class Gas:
    """The tracks in trackpy's format (pixels) and the spec that made them."""

    spec: GasSpec
    tracks: pd.DataFrame
    true_positions: np.ndarray  # (frames, n, 2) [m], unwrapped

    @property
    def kt(self) -> float:
        """k_BT [J]."""
        return BOLTZMANN * self.spec.temperature

    def infer(self, **options):
        """``skygas.inference.infer`` of these tracks, with their scales."""
        from skygas.inference import infer

        spec = self.spec
        options.setdefault("temperature", spec.temperature)
        return infer(
            self.tracks,
            pixel_size=spec.pixel_size,
            frame_interval=spec.frame_interval,
            **options,
        )


def simulate(spec: GasSpec, progress=None) -> Gas:
    """Run the gas: a relaxation (:func:`relaxation_frames`), then ``spec.frames`` frames."""
    rng = np.random.default_rng(spec.seed)
    pos = _start(spec, rng)
    dt = spec.frame_interval / spec.substeps
    t = np.tan(spec.hall_angle)
    kick = np.sqrt(2 * spec.diffusion * dt)
    box = np.array([spec.width, spec.height])
    out = np.empty((spec.frames, spec.skyrmions, 2))
    for frame in range(-relaxation_frames(spec), spec.frames):
        for _ in range(spec.substeps):
            f = _forces(spec, pos if not _periodic(spec) else np.mod(pos, box))
            v = spec.diffusion * np.column_stack([f[:, 0] - t * f[:, 1], f[:, 1] + t * f[:, 0]])
            pos = pos + v * dt + kick * rng.standard_normal(pos.shape)
            if spec.boundary == "walls":
                # a step through the wall (rare with the wall law) is reflected
                pos = np.abs(pos)
                pos = box - np.abs(box - pos)
        if frame >= 0:
            out[frame] = pos
        if progress is not None and frame % 1000 == 0:
            progress(frame)
    return Gas(spec, _tracks(spec, out, rng), out)


def _tracks(spec: GasSpec, positions: np.ndarray, rng) -> pd.DataFrame:
    """trackpy's table of ``positions`` (frames, n, 2), seen as the movie sees them."""
    frames, n, _ = positions.shape
    seen = positions + rng.normal(0.0, spec.localisation_error, positions.shape)
    box = np.array([spec.width, spec.height])
    if _periodic(spec):
        seen = np.mod(seen, box)
    f, p = np.meshgrid(np.arange(frames), np.arange(n), indexing="ij")
    particle = p.copy()
    keep = np.ones((frames, n), bool)
    if spec.field_of_view is not None:
        x0, y0, x1, y1 = spec.field_of_view
        keep = (
            (seen[..., 0] >= x0) & (seen[..., 0] < x1) & (seen[..., 1] >= y0) & (seen[..., 1] < y1)
        )
        # a skyrmion that leaves the field of view and comes back is a new track
        entered = keep & ~np.vstack([np.zeros((1, n), bool), keep[:-1]])
        particle = n * np.cumsum(entered, axis=0) + p
        seen = seen - np.array([x0, y0])
    return pd.DataFrame(
        {
            "frame": f[keep],
            "particle": particle[keep],
            "x": seen[..., 0][keep] / spec.pixel_size,
            "y": seen[..., 1][keep] / spec.pixel_size,
        }
    ).sort_values(["frame", "particle"], ignore_index=True)
