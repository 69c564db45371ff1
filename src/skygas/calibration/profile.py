"""An isolated skyrmion measured from its relaxed texture: size, charge, G and 𝒟.

Conventions (docs/physics.md §1):

- Q = (1/4π)∫ m·(∂ₓm × ∂ᵧm) dA (Berg–Lüscher lattice charge over the skyrmion's neighbourhood,
  :func:`skygas.micromag.detect_skyrmions`): −1 for a core pointing down in a film magnetised
  up;
- G = −4πQk with k = M_s t_F/γ [kg/s], from the *measured* Q;
- the dissipation tensor 𝒟_ij = ∫ ∂ᵢm·∂ⱼm dA, and the scalar of the Thiele equation
  𝒟 = ½(𝒟_xx + 𝒟_yy) = ½∫(∂ₓm·∂ₓm + ∂ᵧm·∂ᵧm) dA. The diagonal is summed over cell links as
  (β/h)² dA, β the angle between neighbouring moments (exact for a uniform rotation); the
  off-diagonal from central differences. For the 360° wall ansatz θ(r) = 2 atan[sinh(R/Δ)/
  sinh(r/Δ)], 𝒟 = π∫(θ'² + sin²θ/r²) r dr, which the thin-wall estimate 2π(R/Δ + Δ/R) of the
  presets approximates;
- radius R: the equal-area radius of the m_z = 0 contour; wall width Δ: the ansatz fitted to
  the azimuthally averaged profile m_z(r) with R fixed;
- the moment deficit A_m = ∫(1 − m_z) dA [m²]: the skyrmion's reversed moment is
  M_s t_F A_m, the quantity that couples it to a slowly varying stray field.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
from scipy import ndimage, optimize

from skygas.calibration.material import MicromagneticMaterial
from skygas.calibration.solver import Film
from skygas.core.errors import InputError
from skygas.micromag.synthetic import ansatz_dissipation


def as_field(m: np.ndarray, film: Film, thickness: float):
    """The texture ``m`` (nx, ny, 3) as the field DataArray of :mod:`skygas.micromag`.

    Dims z, y, x, component; origin at the mesh's lower-left corner.
    """
    from skygas.micromag.ovf import field_from_array

    return field_from_array(np.transpose(m, (1, 0, 2)), (film.cell_size, film.cell_size, thickness))


def detect(m: np.ndarray, film: Film, thickness: float):
    """The skyrmions of texture ``m`` (:func:`skygas.micromag.detect_skyrmions`).

    Each centre is the guiding centre of all the charge near its skyrmion, the film edge's
    tilted band included (``edge_band=False``): the coordinate that
    :meth:`~skygas.calibration.solver.FilmSolver.relax` holds, so that a law measured at held
    distances and a validation run read by this detector are in one coordinate. Without the band
    a skyrmion held 0.8 d_sk from an edge is read 0.1 d_sk farther away, and a law through such
    points is steepest where the tracks are not.
    """
    from skygas.micromag.detection import detect_skyrmions

    return detect_skyrmions(as_field(m, film, thickness), edge_band=False).skyrmions


def dissipation_tensor(m: np.ndarray, cell: float, region: np.ndarray | None = None) -> np.ndarray:
    """𝒟_ij = ∫ ∂ᵢm·∂ⱼm dA over the cells of ``region``, a 2×2 dimensionless matrix.

    ``region`` (nx, ny): all cells if None. See the module docstring for the discretisation.
    """
    m = np.asarray(m, dtype=float)
    region = np.ones(m.shape[:2], bool) if region is None else np.asarray(region, bool)
    tensor = np.zeros((2, 2))
    for axis in (0, 1):
        lo = [slice(None), slice(None)]
        hi = [slice(None), slice(None)]
        lo[axis], hi[axis] = slice(None, -1), slice(1, None)
        chord = np.linalg.norm(m[tuple(hi)] - m[tuple(lo)], axis=-1)
        angle = 2.0 * np.arcsin(np.clip(chord / 2.0, 0.0, 1.0))
        # a link counts half for each of its two cells' regions
        weight = 0.5 * (region[tuple(lo)].astype(float) + region[tuple(hi)])
        tensor[axis, axis] = float(np.sum(weight * angle**2))
    gx = np.gradient(m, cell, axis=0)
    gy = np.gradient(m, cell, axis=1)
    tensor[0, 1] = tensor[1, 0] = float(np.sum(np.sum(gx * gy, axis=-1)[region]) * cell * cell)
    return tensor


def radial_profile(
    m: np.ndarray,
    film: Film,
    centre: tuple[float, float],
    r_max: float,
    n_radii: int = 200,
    n_angles: int = 64,
) -> tuple[np.ndarray, np.ndarray]:
    """(r [m], ⟨m_z⟩(r)): m_z averaged over ``n_angles`` rays from ``centre`` [m].

    Sampled by cubic interpolation between cell centres.
    """
    radii = np.linspace(0.0, r_max, n_radii)
    angles = np.linspace(0.0, 2 * math.pi, n_angles, endpoint=False)
    px = centre[0] + radii[:, None] * np.cos(angles)[None, :]
    py = centre[1] + radii[:, None] * np.sin(angles)[None, :]
    coords = np.array([px / film.cell_size - 0.5, py / film.cell_size - 0.5])
    mz = ndimage.map_coordinates(m[..., 2], coords.reshape(2, -1), order=3, mode="nearest")
    return radii, mz.reshape(px.shape).mean(axis=1)


def helicity(m: np.ndarray, film: Film, centre: tuple[float, float]) -> float:
    """The angle [rad] from the radial direction to the in-plane magnetisation.

    Averaged over the wall (0 or π: Néel; ±π/2: Bloch).
    """
    x, y = film.centres()
    dx, dy = x - centre[0], y - centre[1]
    r = np.maximum(np.hypot(dx, dy), 1e-30)
    wall = np.hypot(m[..., 0], m[..., 1]) > 0.5
    radial = (m[..., 0] * dx + m[..., 1] * dy) / r
    azimuthal = (m[..., 1] * dx - m[..., 0] * dy) / r
    return float(math.atan2(azimuthal[wall].mean(), radial[wall].mean()))


def ansatz_mz(r, radius: float, wall_width: float):
    """m_z(r) = cos θ of the 360° wall ansatz (core −1, background +1)."""
    s = math.sinh(radius / wall_width)
    sh = np.sinh(np.asarray(r, float) / wall_width)
    # cos(2 atan(s/sh)) = (sh² − s²)/(sh² + s²)
    return (sh * sh - s * s) / (sh * sh + s * s)


def fit_wall_width(r: np.ndarray, mz: np.ndarray, radius: float) -> float:
    """Δ of the ansatz m_z(r) with the measured R, fitted by least squares [m]."""

    def residual(log_width):
        return ansatz_mz(r, radius, math.exp(log_width[0])) - mz

    guess = math.log(max(radius / 4.0, 1e-12))
    fit = optimize.least_squares(residual, [guess])
    return math.exp(float(fit.x[0]))


def thin_wall_dissipation(radius: float, wall_width: float) -> float:
    """The presets' estimate 𝒟 ≈ 2π(R/Δ + Δ/R)."""
    return 2.0 * math.pi * (radius / wall_width + wall_width / radius)


@dataclass(frozen=True)
class IsolatedSkyrmion:
    """The relaxed isolated skyrmion (SI units); see the module docstring.

    ``energy``: its energy over the uniform film's [J]; ``dissipation_tensor``: 𝒟_ij;
    ``dissipation``: 𝒟; ``thin_wall_dissipation``: 2π(R/Δ₀ + Δ₀/R) with the presets'
    Δ₀ = √(A/K_u); ``ansatz_dissipation``: π∫(θ'² + sin²θ/r²) r dr of the ansatz with the
    measured R and the fitted Δ;
    ``moment_deficit``: A_m = ∫(1 − m_z) dA [m²]; ``k`` [kg/s]; ``gyrocoupling`` G [kg/s];
    ``profile_radius`` [m] and ``profile_mz``: the azimuthally averaged profile;
    ``circularity``: shortest / longest contour ray.
    """

    charge: float
    x: float
    y: float
    radius: float
    wall_width: float
    circularity: float
    energy: float
    dissipation_tensor: tuple[tuple[float, float], tuple[float, float]]
    dissipation: float
    thin_wall_dissipation: float
    ansatz_dissipation: float
    moment_deficit: float
    k: float
    gyrocoupling: float
    profile_radius: tuple[float, ...]
    profile_mz: tuple[float, ...]

    @property
    def diameter(self) -> float:
        """d_sk = 2R [m]."""
        return 2.0 * self.radius

    def as_record(self) -> dict:
        """The measurement as a dict, without the profile arrays."""
        record = asdict(self)
        record.pop("profile_radius")
        record.pop("profile_mz")
        return record


def measure_isolated(
    m: np.ndarray,
    film: Film,
    material: MicromagneticMaterial,
    energy: float,
    what: str = "isolated skyrmion",
) -> IsolatedSkyrmion:
    """Measure the one skyrmion of the relaxed texture ``m``.

    ``energy`` is its energy above the uniform film [J]. Refuses (one line) a texture without
    exactly one skyrmion of |Q| ≈ 1: the material does not hold an isolated skyrmion on this mesh.
    """
    found = detect(m, film, material.film_thickness)
    if len(found) != 1 or abs(abs(found[0].charge) - 1.0) > 0.05:
        charges = ", ".join(f"{s.charge:+.2f}" for s in found) or "none"
        raise InputError(
            "material",
            material.name,
            f"a film that holds an isolated skyrmion (the relaxed {what} has skyrmion charges: "
            f"{charges}, radius {found[0].radius * 1e9:.1f} nm)"
            if found
            else f"a film that holds an isolated skyrmion (the {what} vanished while relaxing)",
            "check M_s, A_ex, D, K_u and B_z: the skyrmion collapses when D is too small or the "
            "field too large, and grows into a stripe domain when D is too large",
        )
    s = found[0]
    cell = film.cell_size
    if s.radius < 2 * cell:
        raise InputError(
            "material",
            material.name,
            f"a skyrmion larger than two cells (radius {s.radius * 1e9:.2f} nm on "
            f"{cell * 1e9:g} nm cells)",
            "use a smaller cell_size",
        )
    r_max = min(0.5 * min(film.size) - cell, 6.0 * s.radius)
    radii, mz = radial_profile(m, film, (s.x, s.y), r_max)
    width = fit_wall_width(radii, mz, s.radius)
    x, y = film.centres()
    region = np.hypot(x - s.x, y - s.y) <= r_max
    tensor = dissipation_tensor(m, cell, region)
    k = material.saturation_magnetization * material.film_thickness / material.gyromagnetic_ratio
    # within r_max only: the film's tilted edges have a deficit of their own
    deficit = float(np.sum((1.0 - m[..., 2])[region & film.magnetic()]) * cell * cell)
    return IsolatedSkyrmion(
        charge=s.charge,
        x=s.x,
        y=s.y,
        radius=s.radius,
        wall_width=width,
        circularity=s.circularity,
        energy=float(energy),
        dissipation_tensor=(
            (float(tensor[0, 0]), float(tensor[0, 1])),
            (float(tensor[1, 0]), float(tensor[1, 1])),
        ),
        dissipation=0.5 * float(tensor[0, 0] + tensor[1, 1]),
        thin_wall_dissipation=thin_wall_dissipation(s.radius, material.bare_wall_width),
        ansatz_dissipation=ansatz_dissipation(s.radius, width),
        moment_deficit=deficit,
        k=k,
        gyrocoupling=-4.0 * math.pi * s.charge * k,
        profile_radius=tuple(map(float, radii)),
        profile_mz=tuple(map(float, mz)),
    )
