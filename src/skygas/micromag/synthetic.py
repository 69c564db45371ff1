"""Synthetic data with known answers: analytic skyrmion profiles and Thiele trajectories.

Profile: the 360° domain-wall ansatz of a skyrmion of radius R and wall width Δ,

    θ(r) = 2 atan[ sinh(R/Δ) / sinh(r/Δ) ],   n = (sin θ cos(φ+ψ), sin θ sin(φ+ψ), p cos θ),

with φ the polar angle around the centre, ψ the helicity (0: Néel, π/2: Bloch) and p the
background polarity (+1: up film, core down, Q = −1; −1: down film, core up, Q = +1). θ = π/2
exactly at r = R, so R is the radius of the m_z = 0 contour. Several skyrmions are drawn by giving
every cell the profile of its nearest centre (faithful while the tails, ∝ e^{−r/Δ}, are small at
the midlines).

Edge tilt: at a film's edges the DMI boundary condition tilts the magnetisation towards (or away
from) the edge normal; :func:`edge_tilt` rotates a field by θ(d) = θ_edge e^{−d/ξ} about ẑ × ν,
d the distance to the edge and ν the outward normal, so the up background becomes
(sin θ ν, cos θ). A disk's tilted rim then carries a charge of magnitude (1 − cos θ_edge)/2.

Trajectories: the deterministic (T = 0) Thiele equation (G ε + α𝒟k I)·ẋᵢ = Fᵢ with the paper's
pair and wall laws (:mod:`skygas.micromag.forces`), integrated by an adaptive Runge–Kutta method
(scipy's DOP853, tight tolerances), independent of the main engine.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import xarray as xr
from scipy import integrate, ndimage

from skygas.core.errors import InputError
from skygas.micromag.forces import LineBoundary, pair_law_magnitude, wall_law_magnitude
from skygas.micromag.ovf import field_from_array


def wall_profile_theta(r, radius: float, wall_width: float):
    """θ(r) [rad] of the 360° wall ansatz; r, R, Δ in the same length unit."""
    r = np.asarray(r, dtype=np.float64)
    ratio = math.sinh(radius / wall_width) / np.sinh(np.maximum(r, 1e-300) / wall_width)
    return 2.0 * np.arctan(ratio)


def ansatz_dissipation(radius: float, wall_width: float) -> float:
    """𝒟 = π ∫ (θ'² + sin²θ / r²) r dr of the ansatz, by adaptive quadrature (dimensionless)."""
    s = math.sinh(radius / wall_width)

    def integrand(r: float) -> float:
        # θ' = −2S cosh(r/Δ) / (Δ (sinh²(r/Δ) + S²)), sin θ = 2S sinh(r/Δ) / (sinh²(r/Δ) + S²)
        sh, ch = math.sinh(r / wall_width), math.cosh(r / wall_width)
        denominator = sh * sh + s * s
        dtheta = 2.0 * s * ch / (wall_width * denominator)
        sin_over_r = 2.0 * s * sh / (denominator * r)
        return (dtheta**2 + sin_over_r**2) * r

    edge = radius + 40.0 * wall_width
    parts = [(1e-12 * wall_width, radius), (radius, edge)]
    return math.pi * sum(
        integrate.quad(integrand, a, b, limit=400, epsabs=1e-12)[0] for a, b in parts
    )


def skyrmion_field(
    shape: tuple[int, int],
    cell_size: float,
    centres,
    radius: float,
    wall_width: float,
    *,
    helicity: float = 0.0,
    polarity: int = 1,
    time: float = math.nan,
    mask: np.ndarray | None = None,
) -> xr.DataArray:
    """A (1, ny, nx, 3) field of ansatz skyrmions at ``centres`` [(x, y) in m].

    ``shape`` = (ny, nx) cells of ``cell_size`` [m], mesh corner at the origin. ``mask`` (ny, nx)
    marks the magnetic cells; others get m = 0, as mumax3 writes outside a geometry.
    """
    if polarity not in (1, -1):
        raise InputError("polarity", polarity, "+1 (up film) or -1 (down film)")
    ny, nx = shape
    x = (np.arange(nx) + 0.5) * cell_size
    y = (np.arange(ny) + 0.5) * cell_size
    xx, yy = np.meshgrid(x, y)
    centres = np.atleast_2d(np.asarray(centres, dtype=np.float64))
    dist = np.hypot(xx[..., None] - centres[:, 0], yy[..., None] - centres[:, 1])
    nearest = np.argmin(dist, axis=-1)
    cx = centres[nearest, 0]
    cy = centres[nearest, 1]
    r = np.take_along_axis(dist, nearest[..., None], axis=-1)[..., 0]
    theta = wall_profile_theta(r, radius, wall_width)
    phi = np.arctan2(yy - cy, xx - cx) + helicity
    m = np.stack(
        [np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), polarity * np.cos(theta)],
        axis=-1,
    )
    if mask is not None:
        m = np.where(np.asarray(mask, bool)[..., None], m, 0.0)
    return field_from_array(m[np.newaxis], cell_size, time=time)


def edge_tilt(field: xr.DataArray, angle: float, decay_length: float) -> xr.DataArray:
    """``field`` with its film edges tilted by θ(d) = ``angle`` e^{−d/ξ} (see the module).

    ``angle`` [rad] > 0 tilts outward, < 0 inward; ``decay_length`` ξ [m]. The edge is the
    boundary of the magnetic cells (|m| > ½) and the mesh border; d is measured from a cell
    centre to the nearest empty cell centre less half a cell, and ν is the (normalised)
    gradient of −d. Square cells only.
    """
    if not decay_length > 0:
        raise InputError("decay_length", decay_length, "a length > 0 in metres")
    cell = float(field.attrs["dx"])
    if not math.isclose(cell, float(field.attrs["dy"]), rel_tol=1e-9):
        raise InputError("field.dy", field.attrs["dy"], f"square cells (dx = {cell:g} m)")
    m = np.asarray(field.transpose("z", "y", "x", "component").values, dtype=np.float64)
    magnetic = np.linalg.norm(m, axis=-1).max(axis=0) > 0.5
    depth = ndimage.distance_transform_edt(np.pad(magnetic, 1))[1:-1, 1:-1] - 0.5  # cells
    gy, gx = np.gradient(depth)
    size = np.hypot(gx, gy)
    size[size == 0] = 1.0
    axis = np.stack([gx / size, gy / size, np.zeros_like(gx)], axis=-1)  # ẑ × ν, ν = −∇d/|∇d|
    theta = (angle * np.exp(-depth * cell / decay_length))[..., None]
    # Rodrigues' rotation of every z layer about ``axis`` by θ
    along = np.sum(axis * m, axis=-1, keepdims=True)
    tilted = (
        m * np.cos(theta) + np.cross(axis, m) * np.sin(theta) + axis * along * (1.0 - np.cos(theta))
    )
    tilted = np.where(magnetic[..., None], tilted, 0.0)
    return field.copy(data=tilted)


@dataclass(frozen=True)
class ThieleSystem:
    """Coefficients of (G ε + α𝒟k I)·ẋ = F in SI.

    ``gyrocoupling`` G and ``friction`` α𝒟k [kg/s], ``force_scale`` F₀ [N], ``skyrmion_diameter``
    d_sk [m] (the laws' length unit).
    """

    gyrocoupling: float
    friction: float
    force_scale: float
    skyrmion_diameter: float

    def velocity(self, force: np.ndarray) -> np.ndarray:
        """ẋ = (G ε + a I)⁻¹ F = (a I − G ε) F / (a² + G²), for forces of shape (..., 2)."""
        g, a = self.gyrocoupling, self.friction
        fx, fy = force[..., 0], force[..., 1]
        # ε F = (F_y, −F_x), so (aI − Gε)F = (a F_x − G F_y, a F_y + G F_x).
        return np.stack([a * fx - g * fy, a * fy + g * fx], axis=-1) / (a * a + g * g)


def integrate_thiele(system: ThieleSystem, start, times, force) -> np.ndarray:
    """Positions (len(times), n, 2) [m] of the T = 0 Thiele dynamics from ``start`` (n, 2) [m].

    ``force(positions (n, 2)) -> forces (n, 2)`` [N].
    """
    start = np.atleast_2d(np.asarray(start, dtype=np.float64))
    times = np.asarray(times, dtype=np.float64)

    def rhs(_t, flat):
        return system.velocity(force(flat.reshape(-1, 2))).ravel()

    sol = integrate.solve_ivp(
        rhs,
        (times[0], times[-1]),
        start.ravel(),
        method="DOP853",
        t_eval=times,
        rtol=1e-11,
        atol=1e-9 * system.skyrmion_diameter,
    )
    if not sol.success:  # pragma: no cover - tolerances are loose enough for smooth laws
        raise RuntimeError(sol.message)
    return sol.y.T.reshape(len(times), -1, 2)


def pair_forces(system: ThieleSystem, pair_law) -> Callable[[np.ndarray], np.ndarray]:
    """Force function of skyrmions repelling pairwise by the pair law [a2, a1, a0]."""

    def force(positions: np.ndarray) -> np.ndarray:
        sep = positions[:, None, :] - positions[None, :, :]
        dist = np.linalg.norm(sep, axis=-1)
        # self-pairs (sep = 0) add nothing: evaluated at one diameter, then zeroed, so that a
        # law that grows with distance does not overflow there
        self_pair = np.eye(len(positions), dtype=bool)
        dist = np.where(self_pair, system.skyrmion_diameter, dist)
        size = system.force_scale * pair_law_magnitude(dist / system.skyrmion_diameter, pair_law)
        size = np.where(self_pair, 0.0, size)
        return np.sum(size[..., None] * sep / dist[..., None], axis=1)

    return force


def wall_forces(system: ThieleSystem, wall_law, boundary) -> Callable[[np.ndarray], np.ndarray]:
    """Force function of skyrmions pushed along the inward normal of ``boundary`` by the law b."""

    def force(positions: np.ndarray) -> np.ndarray:
        dist, normal = boundary.distance_and_normal(positions)
        size = system.force_scale * wall_law_magnitude(dist / system.skyrmion_diameter, wall_law)
        return size[:, None] * normal

    return force


def straight_wall(x_wall: float = 0.0) -> LineBoundary:
    """A straight wall along y at x = ``x_wall`` [m], the film on the side x > x_wall."""
    return LineBoundary(point=(x_wall, 0.0), inward_normal=(1.0, 0.0))
