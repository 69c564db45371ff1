"""Materials: the paper's presets S1–S7, user materials from TOML, and the Thiele parameters
derived from a material and a film thickness.

Everything here is SI at the interface. The derived :class:`ThieleParameters` carry both SI values
(for records) and the internal nm/ns/pN values the engine uses (see :mod:`skygas.units`).

Derivations (docs/physics.md §1, with its sign convention):

- ``k = M_s t_F / γ`` [kg/s], γ = 1.7595e11 rad/(s·T).
- ``G = −4π Q k`` with Q = (1/4π)∫ n·(∂x n × ∂y n) dA (−1 for the paper's skyrmion, so G > 0);
  ``G = 0`` for an antiferromagnetic skyrmion.
- ``𝒟 ≈ 2π (R/Δ + Δ/R)`` (thin-wall estimate) with wall width Δ = √(A_ex/K_u), unless given.
- ``F₀ = A_ex t_F / d_sk`` (exchange force scale), unless given.
- free diffusion ``D = k_B T α𝒟 / (k (G̃² + (α𝒟)²))`` with G̃ = G/k.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import asdict, dataclass
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Literal

from pydantic import BaseModel, ConfigDict, ValidationError, field_validator

from skygas import units
from skygas.config_types import PositiveFloat
from skygas.errors import InputError



class Material(BaseModel):
    """A magnetic film and its fitted particle-model laws (SI units).

    Attributes
    ----------
    name: preset or user name.
    saturation_magnetization: M_s [A/m].
    exchange_stiffness: A_ex [J/m].
    dmi: interfacial DMI constant D [J/m²] (recorded; the particle model does not use it).
    anisotropy: uniaxial anisotropy K_u [J/m³].
    applied_field: out-of-plane field B [T] (recorded only).
    skyrmion_radius: R_sk [m]; the laws' length unit is the diameter 2 R_sk.
    damping: Gilbert damping α.
    pair_law: [a2, a1, a0] of the skyrmion–skyrmion law (docs/physics.md §2).
    wall_law: wall-law polynomial p(d), highest power first.
    topological_charge: Q = ±1 (standard micromagnetic sign).
    antiferromagnetic: if true, the gyrocoupling vanishes (G = 0).
    dissipation: dimensionless 𝒟; ``None`` uses the thin-wall estimate.
    wall_width: Δ [m]; ``None`` uses √(A_ex/K_u).
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    name: str = "custom"
    saturation_magnetization: PositiveFloat
    exchange_stiffness: PositiveFloat
    dmi: float = 0.0
    anisotropy: PositiveFloat
    applied_field: float = 0.0
    skyrmion_radius: PositiveFloat
    damping: PositiveFloat = 0.1
    pair_law: tuple[float, float, float]
    wall_law: tuple[float, ...]
    topological_charge: Literal[-1, 1] = -1
    antiferromagnetic: bool = False
    dissipation: PositiveFloat | None = None
    wall_width: PositiveFloat | None = None

    @field_validator("wall_law")
    @classmethod
    def _wall_law_grows(cls, value: tuple[float, ...]) -> tuple[float, ...]:
        if len(value) < 2:
            raise ValueError("needs at least two coefficients (highest power first)")
        if value[0] <= 0:
            raise ValueError(
                "leading (highest-power) coefficient must be > 0 so that the wall force "
                "decays away from the wall; coefficients are highest power first"
            )
        return value

    @property
    def skyrmion_diameter(self) -> float:
        """d_sk = 2 R_sk [m]."""
        return 2.0 * self.skyrmion_radius

    def antiferromagnetic_variant(self) -> "Material":
        """The same material with G = 0 (an antiferromagnetic skyrmion, paper §Reshuffler)."""
        return self.model_copy(update={"antiferromagnetic": True, "name": f"{self.name}-AFM"})


@cache
def _preset_table() -> dict[str, dict]:
    text = resources.files("skygas").joinpath("data/materials.toml").read_text()
    table = tomllib.loads(text)
    defaults = table.pop("defaults")
    return {name: {**defaults, **row, "name": name} for name, row in table.items()}


def preset_names() -> list[str]:
    """Names of the built-in material presets (S1–S7)."""
    return sorted(_preset_table())


def preset(name: str) -> Material:
    """A built-in material preset by name (``"S1"`` … ``"S7"``)."""
    table = _preset_table()
    if name not in table:
        raise InputError("material", name, f"one of {', '.join(sorted(table))} or a TOML file")
    return Material(**table[name])


def material_from_mapping(data: dict, field: str = "material") -> Material:
    """Build a :class:`Material` from a mapping, optionally starting from a preset.

    A key ``base = "S2"`` starts from that preset and overrides only the keys given.
    """
    data = dict(data)
    base = data.pop("base", None)
    if base is not None:
        data = {**_preset_table()[preset(base).name], **data}
    try:
        return Material(**data)
    except ValidationError as err:
        first = err.errors()[0]
        loc = ".".join(str(p) for p in first["loc"])
        raise InputError(
            f"{field}.{loc}" if loc else field, first.get("input"), first["msg"]
        ) from None


def load_material(source: str | Path | dict | Material) -> Material:
    """A material from a preset name, a TOML file path, a mapping, or a Material."""
    if isinstance(source, Material):
        return source
    if isinstance(source, dict):
        return material_from_mapping(source)
    text = str(source)
    if text in _preset_table():
        return preset(text)
    path = Path(text)
    if path.suffix == ".toml" and path.is_file():
        data = tomllib.loads(path.read_text())
        return material_from_mapping(data.get("material", data), field=f"{path.name}:material")
    raise InputError(
        "material", text, f"a preset ({', '.join(preset_names())}) or an existing .toml file"
    )


def thin_wall_dissipation(radius: float, wall_width: float) -> float:
    """Thin-wall estimate of the dissipation integral, 𝒟 ≈ 2π (R/Δ + Δ/R) (dimensionless)."""
    return 2.0 * math.pi * (radius / wall_width + wall_width / radius)


@dataclass(frozen=True)
class ThieleParameters:
    """Coefficients of the Thiele equation for one material and film (SI units).

    (G ε + α𝒟k I)·ẋ = μ (G ε + η𝒟k I)·v_s + F_th + F_ss + F_wall

    Attributes
    ----------
    k: M_s t_F / γ [kg/s].
    gyrocoupling: G [kg/s] (= −4πQk, or 0 for antiferromagnets).
    dissipation: 𝒟 (dimensionless).
    damping: α.
    eta: η, the non-adiabatic drive parameter (paper: η = α).
    mu: μ, the drive intensity (paper: μ = 1).
    force_scale: F₀ [N].
    skyrmion_diameter: d_sk [m], the length unit of the force laws.
    film_thickness: t_F [m].
    """

    k: float
    gyrocoupling: float
    dissipation: float
    damping: float
    eta: float
    mu: float
    force_scale: float
    skyrmion_diameter: float
    film_thickness: float

    @property
    def friction(self) -> float:
        """α𝒟k [kg/s], the dissipative coefficient."""
        return self.damping * self.dissipation * self.k

    def diffusion_constant(self, temperature: float) -> float:
        """Free diffusion constant D [m²/s]; ⟨|Δx|²⟩ = 4 D t in 2D (docs/physics.md §1)."""
        a, g = self.friction, self.gyrocoupling
        return units.BOLTZMANN * temperature * a / (a * a + g * g)

    def hall_angle(self) -> float:
        """Skyrmion Hall angle [rad] of the drift under a uniform v_s (see engine docs)."""
        a, g = self.friction, self.gyrocoupling
        b = self.eta * self.dissipation * self.k
        # velocity = μ (aI − gε)(gε + bI) v_s / (a² + g²) = μ [(ab + g²) I + g(a − b) ε] v_s
        # / (a² + g²); for v_s = x̂ (ε x̂ = −ŷ) the components are:
        vx = (a * b + g * g) / (a * a + g * g)
        vy = g * (b - a) / (a * a + g * g)
        return math.atan2(vy, vx)

    def as_record(self) -> dict[str, float]:
        """Flat dict for result attributes (SI, names with units)."""
        return {f"thiele_{key}": value for key, value in asdict(self).items()}

    # Internal-unit views used by the engine -----------------------------------------------
    @property
    def friction_internal(self) -> float:
        return self.friction * units.KG_PER_S_TO_INTERNAL

    @property
    def gyrocoupling_internal(self) -> float:
        return self.gyrocoupling * units.KG_PER_S_TO_INTERNAL

    @property
    def drive_friction_internal(self) -> float:
        """η𝒟k in pN·ns/nm."""
        return self.eta * self.dissipation * self.k * units.KG_PER_S_TO_INTERNAL

    @property
    def force_scale_internal(self) -> float:
        return self.force_scale * units.N_TO_PN

    @property
    def skyrmion_diameter_internal(self) -> float:
        return self.skyrmion_diameter * units.M_TO_NM


def derive_thiele(
    material: Material,
    film_thickness: float = 2e-9,
    *,
    dissipation: float | None = None,
    force_scale: float | None = None,
    skyrmion_diameter: float | None = None,
    eta: float | None = None,
    mu: float = 1.0,
) -> ThieleParameters:
    """Thiele coefficients of ``material`` in a film of ``film_thickness`` [m].

    Arguments left ``None`` take the defaults of docs/physics.md §4: 𝒟 from the material (or the
    thin-wall estimate), F₀ = A_ex t_F / d_sk, d_sk = 2 R_sk, η = α.
    """
    if not film_thickness > 0:
        raise InputError("film_thickness", film_thickness, "a thickness > 0 in metres")
    k = material.saturation_magnetization * film_thickness / units.GYROMAGNETIC_RATIO
    gyro = 0.0 if material.antiferromagnetic else -4.0 * math.pi * material.topological_charge * k
    if dissipation is None:
        dissipation = material.dissipation
    if dissipation is None:
        width = material.wall_width or math.sqrt(
            material.exchange_stiffness / material.anisotropy
        )
        dissipation = thin_wall_dissipation(material.skyrmion_radius, width)
    if not dissipation > 0:
        raise InputError("dissipation", dissipation, "a dimensionless 𝒟 > 0")
    diameter = skyrmion_diameter if skyrmion_diameter is not None else material.skyrmion_diameter
    if not diameter > 0:
        raise InputError("skyrmion_diameter", diameter, "a diameter > 0 in metres")
    if force_scale is None:
        force_scale = material.exchange_stiffness * film_thickness / diameter
    if not force_scale > 0:
        raise InputError("force_scale", force_scale, "a force > 0 in newtons")
    return ThieleParameters(
        k=k,
        gyrocoupling=gyro,
        dissipation=float(dissipation),
        damping=material.damping,
        eta=material.damping if eta is None else float(eta),
        mu=float(mu),
        force_scale=float(force_scale),
        skyrmion_diameter=float(diameter),
        film_thickness=float(film_thickness),
    )
