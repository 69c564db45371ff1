"""Materials: the paper's presets S1–S7, user materials from TOML, and their Thiele parameters.

The Thiele parameters are derived from a material and a film thickness.

Everything here is SI at the interface. The derived :class:`ThieleParameters` carry both SI values
(for records) and the internal nm/ns/pN values the engine uses (see :mod:`skygas.core.units`).

Derivations (docs/physics.md §1, with its sign convention):

- ``k = M_s t_F / γ`` [kg/s], γ = 1.7595e11 rad/(s·T).
- ``G = −4π Q k`` with Q = (1/4π)∫ n·(∂x n × ∂y n) dA (−1 for the paper's skyrmion, so G > 0);
  ``G = 0`` for an antiferromagnetic skyrmion.
- ``𝒟 ≈ 2π (R/Δ + Δ/R)`` (thin-wall estimate) with wall width Δ = √(A_ex/K_u), unless given.
- ``F₀ = A_ex t_F / d_sk`` (exchange force scale), unless given.
- free diffusion ``D = k_B T α𝒟 / (k (G̃² + (α𝒟)²))`` with G̃ = G/k.

A calibrated material (``skygas calibrate``'s ``model.toml``) may carry more: the film thickness
its laws were measured for (any other thickness is refused), its own γ, tabulated pair and wall
laws (:class:`ForceTableSpec`) and the profile of its skyrmion for the edge stray field
(:class:`StrayFieldSpec`; docs/physics.md §2, "Tabulated laws and the edge stray field").
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import asdict, dataclass
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import (
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

from skygas.core import units
from skygas.core.config_types import PositiveFloat, StrictModel, to_input_error
from skygas.core.errors import InputError

#: The film thickness [m] of a material that does not name its own (the paper's 2 nm).
DEFAULT_FILM_THICKNESS = 2e-9

FinitePositive = Annotated[float, Field(gt=0, allow_inf_nan=False)]

#: Relative difference of two film thicknesses above which they are different films.
FILM_THICKNESS_RTOL = 1e-9
#: Largest deficit 1 − m_z accepted at a profile's last radius: w is taken as 0 beyond it, so
#: the profile must have decayed there (1 % of the core's 2).
PROFILE_TAIL_MAX = 0.02


def _strictly_increasing(values: tuple[float, ...], name: str) -> None:
    if any(b <= a for a, b in zip(values, values[1:], strict=False)):
        raise ValueError(f"{name} must be strictly increasing")


class ForceTableSpec(StrictModel):
    """A tabulated repulsive force law in physical units (a calibrated model's pair or wall law).

    Attributes
    ----------
    distance : tuple of float
        Centre–centre distance (pair) or distance from the skyrmion's centre to the nearest
        wall (wall) [m]; at least 4 points, strictly increasing, ≥ 0.
    force : tuple of float
        |F| at those distances [N]; finite, ≥ 0.

    The engine interpolates it with PCHIP, holds it at ``force[0]`` below the first distance and
    sets it to 0 beyond the last (:func:`skygas.physics.forces.tabulated_law`). The table is in SI,
    not in units of d_sk and F₀: overriding either never changes a tabulated law.
    """

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    distance: tuple[float, ...]
    force: tuple[float, ...]

    @field_validator("distance")
    @classmethod
    def _distances(cls, value: tuple[float, ...]) -> tuple[float, ...]:
        if len(value) < 4:
            raise ValueError("at least 4 distances (m)")
        if value[0] < 0:
            raise ValueError("distances (m) must be >= 0")
        _strictly_increasing(value, "distance")
        return value

    @field_validator("force")
    @classmethod
    def _forces(cls, value: tuple[float, ...]) -> tuple[float, ...]:
        if any(f < 0 for f in value):
            raise ValueError("forces (N) must be >= 0 (a repulsion's magnitude)")
        return value

    @model_validator(mode="after")
    def _same_length(self):
        if len(self.force) != len(self.distance):
            raise ValueError(
                f"force needs one value per distance ({len(self.distance)}), not {len(self.force)}"
            )
        return self


class StrayFieldSpec(StrictModel):
    """The isolated skyrmion's radial profile, for its energy in the film's edge stray field.

    Attributes
    ----------
    profile_radius : tuple of float
        Radii ρ [m], strictly increasing from 0 (at least 2).
    profile_deficit : tuple of float
        w(ρ) = 1 − m_z at those radii (dimensionless): 2 at a fully reversed core, decaying to
        ~0 (at most PROFILE_TAIL_MAX) at the last radius; linearly interpolated and 0 beyond
        the last radius (:mod:`skygas.fields.landscape.stray_field`).
    """

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    profile_radius: tuple[float, ...]
    profile_deficit: tuple[float, ...]

    @field_validator("profile_radius")
    @classmethod
    def _radii(cls, value: tuple[float, ...]) -> tuple[float, ...]:
        if len(value) < 2:
            raise ValueError("at least 2 radii (m)")
        if value[0] != 0:
            raise ValueError("radii (m) must start at 0 (the skyrmion's centre)")
        _strictly_increasing(value, "profile_radius")
        return value

    @field_validator("profile_deficit")
    @classmethod
    def _deficits(cls, value: tuple[float, ...]) -> tuple[float, ...]:
        if any(not 0 <= w <= 2 for w in value):
            raise ValueError("deficits 1 - m_z between 0 and 2")
        if value and value[-1] > PROFILE_TAIL_MAX:
            raise ValueError(
                f"a deficit that has decayed to <= {PROFILE_TAIL_MAX} at the last "
                "radius (it is taken as 0 beyond)"
            )
        return value

    @model_validator(mode="after")
    def _same_length(self):
        if len(self.profile_deficit) != len(self.profile_radius):
            raise ValueError(
                f"profile_deficit needs one value per radius "
                f"({len(self.profile_radius)}), not {len(self.profile_deficit)}"
            )
        return self


class BreathingSpec(StrictModel):
    """What a breathing skyrmion needs beyond a rigid one: its radius as a degree of freedom.

    Each skyrmion carries its radius Rᵢ. The energy the engine integrates is

        E = Σᵢ E_self(Rᵢ) + Σ_{i<j} U_pair(dᵢⱼ − s_p (Rᵢ + Rⱼ − 2R₀))
              + Σᵢ U_wall(wᵢ − s_w (Rᵢ − R₀))

    with R₀ the material's ``skyrmion_radius`` (the isolated skyrmion's), U_pair and U_wall the
    material's pair and wall laws (their forces are the tabulated or paper laws; with
    ``pair_radius`` and ``wall_radius``, the tables read at the gap of the radii they were
    measured with), dᵢⱼ the centre distance and wᵢ the distance to the nearest wall.
    A larger skyrmion meets its neighbours and the walls earlier: the laws act on the gap
    between domain walls, not between centres, which s = 1 states exactly. The radius relaxes
    with its own friction Γ_R = α 𝒟_RR k (k = M_s t_F/γ, as for the centre's α𝒟k):

        Γ_R dRᵢ/dt = −∂E/∂Rᵢ + ξᵢ,   ⟨ξᵢ(t) ξᵢ(t')⟩ = 2 k_B T Γ_R δ(t − t')

    so that at equilibrium the radii follow exp(−E/k_BT). docs/physics.md §2 "Breathing
    skyrmions" derives it from Thiele's projection onto ∂m/∂R.

    Attributes
    ----------
    radius : tuple of float
        Radii R [m], strictly increasing, at least 3, spanning ``skyrmion_radius``.
    energy : tuple of float
        E_self(R) [J] of an isolated skyrmion of that radius in the material's film and
        applied field (any constant offset). Interpolated with PCHIP; the radius is kept within
        the table (a step that would leave it is reflected back and counted).
    radius_dissipation : float or None
        𝒟_RR = ∫ ∂_R m · ∂_R m dA (dimensionless); ``None`` takes the thin-wall estimate
        4πR₀/Δ.
    pair_shift, wall_shift : float
        s_p and s_w above (dimensionless, ≥ 0; 0 makes the laws blind to the radius).
    moment_deficit : tuple of float or None
        The reversed area A_m(R) = ∫(1 − m_z) dA [m²] at each radius (a calibration's scan
        measures it); ``None`` takes the thin wall's A_m ∝ R². The energy in the edges' stray
        field, U_s(r) at R₀ (:class:`StrayFieldSpec`), scales with it: a skyrmion of radius R
        has a(R) U_s(r), a(R) = A_m(R)/A_m(R₀), exact for a field that varies slowly across
        the skyrmion. So the radius feels the local stray field, −a'(R) U_s, and shrinks where
        it is strong (near edges, in narrow conduits).
    dissipation : tuple of float or None
        The centre's 𝒟(R) = ½∫(∂ₓm·∂ₓm + ∂ᵧm·∂ᵧm) dA (dimensionless) at each radius (a
        calibration measures it on the scan's textures); ``None`` keeps 𝒟 at every radius.
        The table sets the ratio c(R) = 𝒟(R)/𝒟(R₀) only; the material's ``dissipation``
        stays 𝒟 at R₀. A skyrmion of radius R moves with the friction α𝒟(R)k, is driven with
        η𝒟(R)k, and diffuses with D(R) = k_BT α𝒟(R)k/((α𝒟(R)k)² + G²): a squeezed skyrmion,
        whose wall is shorter, moves faster and at another Hall angle.
    pair_radius, wall_radius : tuple of float or None
        The radius [m] of the skyrmions the laws were measured with, at each distance of the
        material's ``pair_table`` (``wall_table``): a calibration relaxes its pairs and edge
        singles, and neighbours and edges squeeze them. The measured law is then the force
        along that family of relaxed skyrmions; at their radii ∂E/∂R = 0, so (the envelope
        theorem) it equals the force of U at the gap g(d) = d − 2 s_p (R(d) − R₀)
        (x − s_w (R(x) − R₀) for an edge). With them the breathing model's U is the table
        read at the gap (:meth:`Material.breathing_laws`); without them the table is taken
        as U itself, a law measured with the radii held at R₀. Reading a law of squeezed
        skyrmions as U places it too far out and weakens it: the model's skyrmions are
        squeezed too little and pushed too weakly.
    """

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    radius: tuple[float, ...]
    energy: tuple[float, ...]
    radius_dissipation: FinitePositive | None = None
    pair_shift: Annotated[float, Field(ge=0, allow_inf_nan=False)] = 1.0
    wall_shift: Annotated[float, Field(ge=0, allow_inf_nan=False)] = 1.0
    moment_deficit: tuple[FinitePositive, ...] | None = None
    dissipation: tuple[FinitePositive, ...] | None = None
    pair_radius: tuple[FinitePositive, ...] | None = None
    wall_radius: tuple[FinitePositive, ...] | None = None

    @field_validator("radius")
    @classmethod
    def _radii(cls, value: tuple[float, ...]) -> tuple[float, ...]:
        if len(value) < 3:
            raise ValueError("at least 3 radii (m)")
        if value[0] <= 0:
            raise ValueError("radii (m) must be > 0")
        _strictly_increasing(value, "radius")
        return value

    @model_validator(mode="after")
    def _same_length(self):
        if len(self.energy) != len(self.radius):
            raise ValueError(
                f"energy needs one value per radius ({len(self.radius)}), not {len(self.energy)}"
            )
        area = self.moment_deficit
        if area is not None:
            if len(area) != len(self.radius):
                raise ValueError(
                    f"moment_deficit needs one value per radius ({len(self.radius)}), "
                    f"not {len(area)}"
                )
            if any(b <= a for a, b in zip(area, area[1:], strict=False)):
                raise ValueError("moment_deficit (m²) must grow with the radius")
        if self.dissipation is not None and len(self.dissipation) != len(self.radius):
            raise ValueError(
                f"dissipation needs one value per radius ({len(self.radius)}), "
                f"not {len(self.dissipation)}"
            )
        return self

    def dissipation_ratio(self, reference_radius: float, unit: float = 1.0):
        """c(R) = 𝒟(R)/𝒟(R₀) as a function (radii as in :meth:`area_ratio`), or ``None``.

        ``None`` without a ``dissipation`` table (𝒟 is the same at every radius). The table
        is interpolated with PCHIP: it keeps 𝒟 positive and does not overshoot between
        radii.
        """
        if self.dissipation is None:
            return None
        import numpy as np
        from scipy.interpolate import PchipInterpolator

        radius = np.asarray(self.radius, float) * unit
        table = PchipInterpolator(radius, np.asarray(self.dissipation, float))
        at_r0 = float(table(reference_radius))
        return lambda r: table(r) / at_r0

    def area_ratio(self, reference_radius: float, unit: float = 1.0):
        """(a, a', a''): a(R) = A_m(R)/A_m(R₀) and its first two derivatives, as functions.

        The radii are the table's [m] times ``unit`` (``reference_radius`` R₀ in the same
        units): the not-a-knot cubic spline of ``moment_deficit``, or without it the thin
        wall's (R/R₀)². The one definition of the stray field's scale on a breathing radius,
        for the engine and the calibration's edge check alike.
        """
        import numpy as np

        r0 = reference_radius
        if self.moment_deficit is None:
            return (
                lambda r: (np.asarray(r, float) / r0) ** 2,
                lambda r: 2.0 * np.asarray(r, float) / r0**2,
                lambda r: np.full_like(np.asarray(r, float), 2.0 / r0**2),
            )
        from scipy.interpolate import CubicSpline

        radius = np.asarray(self.radius, float) * unit
        spline = CubicSpline(radius, np.asarray(self.moment_deficit, float))
        at_r0 = float(spline(r0))
        first, second = spline.derivative(), spline.derivative(2)
        return (
            lambda r: spline(r) / at_r0,
            lambda r: first(r) / at_r0,
            lambda r: second(r) / at_r0,
        )


def law_gap(law: str, distance, radius, reference_radius: float, shift: float):
    """The gap [m] at which a breathing model reads a law measured at ``distance`` [m].

    ``radius`` [m]: the measured skyrmions' radius at each distance; ``law``: ``"pair"``
    (g = d − 2s(R − R₀), both skyrmions squeezed) or ``"wall"`` (g = x − s(R − R₀)).
    """
    import numpy as np

    factor = 2.0 * shift if law == "pair" else shift
    return np.asarray(distance, float) - factor * (np.asarray(radius, float) - reference_radius)


class Material(StrictModel):
    """A magnetic film and its fitted particle-model laws (SI units).

    Attributes
    ----------
    name : str
        Preset or user name.
    saturation_magnetization : float
        M_s [A/m].
    exchange_stiffness : float
        A_ex [J/m].
    dmi : float
        Interfacial DMI constant D [J/m²] (recorded; the particle model does not use it).
    anisotropy : float
        Uniaxial anisotropy K_u [J/m³].
    applied_field : float
        Out-of-plane field B [T] (recorded only).
    skyrmion_radius : float
        R_sk [m]; the laws' length unit is the diameter 2 R_sk.
    damping : float
        Gilbert damping α.
    pair_law : tuple of float
        [a2, a1, a0] of the skyrmion–skyrmion law (docs/physics.md §2).
    wall_law : tuple of float
        Wall-law polynomial p(d), highest power first.
    topological_charge : {-1, 1}
        Q = ±1 (standard micromagnetic sign).
    antiferromagnetic : bool
        If true, the gyrocoupling vanishes (G = 0).
    dissipation : float or None
        Dimensionless 𝒟; ``None`` uses the thin-wall estimate.
    wall_width : float or None
        Δ [m]; ``None`` uses √(A_ex/K_u).
    film_thickness : float or None
        t_F [m] the laws were measured for (a calibrated model); ``None``: any film (default
        2 nm). When set, a run in another film is refused.
    gyromagnetic_ratio : float or None
        γ [rad/(s·T)] for k = M_s t_F/γ; ``None`` uses
        :data:`skygas.core.units.GYROMAGNETIC_RATIO`.
    pair_table, wall_table : ForceTableSpec or None
        Tabulated laws in SI, chosen by ``forces.pair_law`` / ``forces.wall_law = "table"``
        (the default when present).
    stray_field : StrayFieldSpec or None
        The skyrmion's profile for the edge stray-field energy, added with a tabulated wall
        law (docs/physics.md §2).
    particle_model : {"rigid", "breathing"}
        Rigid skyrmions keep the radius ``skyrmion_radius``; breathing ones carry their own
        (:class:`BreathingSpec`, which ``breathing`` must then give).
    breathing : BreathingSpec or None
        The radius's energy, friction and coupling to the laws (a calibrated soft film).
    wall_geometry : {"nearest", "film"}
        How the wall law meets the outline. ``"nearest"``: along the normal of the nearest
        wall only (the paper's way). ``"film"``: as the field of the missing film, every edge
        within reach (both sides of a corner, both walls of a conduit;
        :mod:`skygas.fields.landscape.wall_film`), which a calibration writes: it is how the
        law was measured, one straight edge at a time.
    """

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=True)

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
    film_thickness: FinitePositive | None = None
    gyromagnetic_ratio: FinitePositive | None = None
    pair_table: ForceTableSpec | None = None
    wall_table: ForceTableSpec | None = None
    stray_field: StrayFieldSpec | None = None
    particle_model: Literal["rigid", "breathing"] = "rigid"
    breathing: BreathingSpec | None = None
    wall_geometry: Literal["nearest", "film"] = "nearest"

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

    @model_validator(mode="after")
    def _breathing_has_its_spec(self):
        if self.particle_model == "breathing":
            spec = self.breathing
            if spec is None:
                raise ValueError(
                    "particle_model = 'breathing' needs a [breathing] table (radius, energy)"
                )
            if not spec.radius[0] <= self.skyrmion_radius <= spec.radius[-1]:
                raise ValueError(
                    f"breathing.radius must span skyrmion_radius = {self.skyrmion_radius:g} m "
                    f"(it runs from {spec.radius[0]:g} to {spec.radius[-1]:g} m)"
                )
        return self

    @model_validator(mode="after")
    def _law_radii_fit_the_tables(self):
        spec = self.breathing
        if spec is None:
            return self
        for name, radii, table in (
            ("pair", spec.pair_radius, self.pair_table),
            ("wall", spec.wall_radius, self.wall_table),
        ):
            if radii is None:
                continue
            if table is None:
                raise ValueError(f"breathing.{name}_radius needs the material's {name}_table")
            if len(radii) != len(table.distance):
                raise ValueError(
                    f"breathing.{name}_radius needs one radius per {name}_table distance "
                    f"({len(table.distance)}), not {len(radii)}"
                )
        gaps = self._law_gaps()
        for name, gap in gaps.items():
            if any(b <= a for a, b in zip(gap, gap[1:], strict=False)):
                raise ValueError(
                    f"breathing.{name}_radius makes the gaps of the {name} law decrease: "
                    "the radii may not grow faster than the distance over 2·shift"
                )
        return self

    def _law_gaps(self) -> dict[str, tuple[float, ...]]:
        """The gap [m] at each distance of the pair and wall tables that have law radii."""
        spec = self.breathing
        out: dict[str, tuple[float, ...]] = {}
        if spec is None:
            return out
        for name, radii, table, shift in (
            ("pair", spec.pair_radius, self.pair_table, spec.pair_shift),
            ("wall", spec.wall_radius, self.wall_table, spec.wall_shift),
        ):
            if radii is not None and table is not None:
                gap = law_gap(name, table.distance, radii, self.skyrmion_radius, shift)
                out[name] = tuple(float(g) for g in gap)
        return out

    def breathing_laws(self) -> Material:
        """The material whose pair and wall tables are the breathing model's U, at the gap.

        The tables with law radii (:class:`BreathingSpec` ``pair_radius``, ``wall_radius``)
        are moved to their gaps, the force at each unchanged; the material itself without.
        """
        gaps = self._law_gaps()
        if not gaps:
            return self
        update: dict[str, Any] = {}
        for name, gap in gaps.items():
            table = getattr(self, f"{name}_table")
            update[f"{name}_table"] = table.model_copy(update={"distance": gap})
        return self.model_copy(update=update)

    @property
    def is_breathing(self) -> bool:
        """True if its skyrmions carry their radius as a degree of freedom."""
        return self.particle_model == "breathing"

    @property
    def skyrmion_diameter(self) -> float:
        """d_sk = 2 R_sk [m]."""
        return 2.0 * self.skyrmion_radius

    def antiferromagnetic_variant(self) -> Material:
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
    """A built-in material preset by name (``"S1"`` … ``"S7"``).

    Raises
    ------
    InputError
        If there is no preset of that name (:func:`preset_names` lists them).
    """
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
        raise to_input_error(err, prefix=field) from None


def load_material(source: str | Path | dict | Material) -> Material:
    """A material from a preset name, a TOML file path, a mapping, or a Material.

    Parameters
    ----------
    source : str, Path, dict or Material
        A preset name (:func:`preset_names`); a ``.toml`` file, whose ``[material]`` table (or
        its top level) is read; a mapping of :class:`Material` fields, where ``base = "S2"``
        starts from that preset and overrides only the keys given; or a :class:`Material`,
        returned as it is.

    Returns
    -------
    Material

    Raises
    ------
    InputError
        If ``source`` is neither a preset nor an existing ``.toml`` file, or a field is invalid.
    """
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
    k : float
        M_s t_F / γ [kg/s].
    gyrocoupling : float
        G [kg/s] (= −4πQk, or 0 for antiferromagnets).
    dissipation : float
        𝒟 (dimensionless).
    damping : float
        α.
    eta : float
        η, the non-adiabatic drive parameter (paper: η = α).
    mu : float
        μ, the drive intensity (paper: μ = 1).
    force_scale : float
        F₀ [N].
    skyrmion_diameter : float
        d_sk [m], the length unit of the force laws.
    film_thickness : float
        t_F [m].
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
        """α𝒟k in pN·ns/nm."""
        return self.friction * units.KG_PER_S_TO_INTERNAL

    @property
    def gyrocoupling_internal(self) -> float:
        """G in pN·ns/nm."""
        return self.gyrocoupling * units.KG_PER_S_TO_INTERNAL

    @property
    def drive_friction_internal(self) -> float:
        """η𝒟k in pN·ns/nm."""
        return self.eta * self.dissipation * self.k * units.KG_PER_S_TO_INTERNAL

    @property
    def force_scale_internal(self) -> float:
        """F₀ in pN."""
        return self.force_scale * units.N_TO_PN

    @property
    def skyrmion_diameter_internal(self) -> float:
        """d_sk in nm."""
        return self.skyrmion_diameter * units.M_TO_NM


def resolve_film_thickness(
    material: Material, film_thickness: float | None = None, field: str = "film_thickness"
) -> float:
    """The film thickness t_F [m] of a run of ``material``.

    ``None`` takes the material's own ``film_thickness`` (a calibrated model), else
    :data:`DEFAULT_FILM_THICKNESS`. A material calibrated for one film refuses any other
    (relative difference above :data:`FILM_THICKNESS_RTOL`): its laws hold for that film only.
    """
    if film_thickness is None:
        own = material.film_thickness
        return DEFAULT_FILM_THICKNESS if own is None else own
    mismatch = film_mismatch(material, film_thickness)
    if mismatch is not None:
        raise InputError(field, film_thickness, mismatch)
    return film_thickness


def film_mismatch(material: Material, film_thickness: float) -> str | None:
    """What is allowed instead of ``film_thickness`` [m] for ``material``; ``None`` if it is.

    Any film is allowed for a material without ``film_thickness``.
    """
    own = material.film_thickness
    if own is None or abs(film_thickness - own) <= FILM_THICKNESS_RTOL * own:
        return None
    return (
        f"the {own:g} m film the model '{material.name}' was calibrated for "
        "(leave film_thickness out to take it)"
    )


def derive_thiele(
    material: Material,
    film_thickness: float | None = None,
    *,
    dissipation: float | None = None,
    force_scale: float | None = None,
    skyrmion_diameter: float | None = None,
    eta: float | None = None,
    mu: float = 1.0,
) -> ThieleParameters:
    """Thiele coefficients of ``material`` in a film of ``film_thickness`` [m].

    Arguments left ``None`` take the defaults of docs/physics.md §4: t_F from the material (a
    calibrated model; :func:`resolve_film_thickness`) or 2 nm, 𝒟 from the material (or the
    thin-wall estimate), F₀ = A_ex t_F / d_sk, d_sk = 2 R_sk, η = α; γ in k = M_s t_F/γ is the
    material's ``gyromagnetic_ratio`` or :data:`skygas.core.units.GYROMAGNETIC_RATIO`.

    Parameters
    ----------
    material : Material
        The film's material.
    film_thickness : float, optional
        t_F [m]; a material calibrated for one film refuses any other.
    dissipation : float, optional
        𝒟 (dimensionless), > 0.
    force_scale : float, optional
        F₀ [N], > 0.
    skyrmion_diameter : float, optional
        d_sk [m], the length unit of the force laws, > 0.
    eta : float, optional
        η, the non-adiabatic drive parameter.
    mu : float
        μ, the drive intensity.

    Returns
    -------
    ThieleParameters
        The coefficients in SI units.

    Raises
    ------
    InputError
        If a value given (or derived) is not > 0, or the film is not the calibrated one.
    """
    if film_thickness is not None and not film_thickness > 0:
        raise InputError("film_thickness", film_thickness, "a thickness > 0 in metres")
    film_thickness = resolve_film_thickness(material, film_thickness)
    gamma = material.gyromagnetic_ratio or units.GYROMAGNETIC_RATIO
    k = material.saturation_magnetization * film_thickness / gamma
    gyro = 0.0 if material.antiferromagnetic else -4.0 * math.pi * material.topological_charge * k
    if dissipation is None:
        dissipation = material.dissipation
    if dissipation is None:
        width = material.wall_width or math.sqrt(material.exchange_stiffness / material.anisotropy)
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
