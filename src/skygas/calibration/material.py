"""A film's micromagnetic parameters: what ``skygas calibrate`` starts from.

:class:`MicromagneticMaterial` holds the parameters of a thin film (SI units) and the cell
size the calibration meshes it with. It comes from a preset (``"S2"``: the paper's Appendix C
row, in a 2 nm film with α = 0.1) or from a TOML file. Every field is checked here, before any
solver starts, and a value that cannot describe a thin perpendicular film with isolated
skyrmions, or a mesh too coarse for its length scales, is refused with one line naming the
field.

Length scales (thin-film limit, the film one cell thick, demagnetisation as a shape anisotropy
for the estimates only; the solver computes the full stray field):

- exchange length l_ex = √(2A/(μ₀M_s²));
- effective anisotropy K_eff = K_u − μ₀M_s²/2, and the perpendicular stiffness
  K_⊥ = K_eff + M_s B_z/2 (> 0: the film is magnetised out of plane, by its anisotropy or by
  the field);
- wall width Δ_eff = √(A/K_⊥), and the DMI length A/|D|;
- the critical DMI D_c = 4√(A K_eff)/π, above which a film without field prefers spirals.

The cell must resolve all of them: ``cell_size`` ≤ min(l_ex, Δ_eff, A/|D|).
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path
from typing import Any

from pydantic import Field, ValidationError, model_validator

from skygas.core import units
from skygas.core.config_types import Length, PositiveFloat, StrictModel, to_input_error
from skygas.core.errors import InputError

#: Defaults of the paper's simulations (Methods): 2 nm film, 2 nm cells, α = 0.1.
DEFAULT_FILM_THICKNESS = 2e-9
DEFAULT_CELL_SIZE = 2e-9
DEFAULT_DAMPING = 0.1


class MicromagneticMaterial(StrictModel):
    """A thin film's micromagnetic parameters (SI units) and the calibration's mesh.

    Attributes
    ----------
    name : str
        A name for the material (recorded in the model file).
    saturation_magnetization : float
        M_s [A/m].
    exchange_stiffness : float
        A_ex [J/m].
    dmi : float
        Interfacial DMI constant D [J/m²] (Néel skyrmions).
    bulk_dmi : float
        Bulk DMI constant [J/m²] (Bloch skyrmions; default 0).
    anisotropy : float
        Uniaxial out-of-plane anisotropy K_u [J/m³] (magnetocrystalline; the solver adds the
        stray field itself).
    applied_field : float
        Out-of-plane field B_z [T]; the film is magnetised along +z and the skyrmion's core
        points along −z.
    film_thickness : float
        t_F [m]; the film is one cell thick.
    damping : float
        Gilbert damping α.
    gyromagnetic_ratio : float
        γ [rad/(s·T)].
    cell_size : float
        In-plane cell size [m] of the calibration's mesh.
    temperature : float or None
        The temperature [K] of the runs the model is meant for (recorded; the calibration
        itself is at T = 0). None: not stated.
    """

    name: str = "custom"
    saturation_magnetization: PositiveFloat
    exchange_stiffness: PositiveFloat
    dmi: float = Field(0.0, ge=0)
    bulk_dmi: float = Field(0.0, ge=0)
    anisotropy: float = Field(ge=0)
    applied_field: float = 0.0
    film_thickness: Length = DEFAULT_FILM_THICKNESS
    damping: float = Field(DEFAULT_DAMPING, gt=0, le=1)
    gyromagnetic_ratio: PositiveFloat = units.GYROMAGNETIC_RATIO
    cell_size: Length = DEFAULT_CELL_SIZE
    temperature: float | None = Field(None, ge=0)

    # -- length scales ------------------------------------------------------------------------
    @property
    def shape_anisotropy(self) -> float:
        """μ₀M_s²/2 [J/m³], the thin film's demagnetising energy density."""
        return 0.5 * units.MU_0 * self.saturation_magnetization**2

    @property
    def effective_anisotropy(self) -> float:
        """K_eff = K_u − μ₀M_s²/2 [J/m³] (thin-film limit)."""
        return self.anisotropy - self.shape_anisotropy

    @property
    def perpendicular_stiffness(self) -> float:
        """K_⊥ = K_eff + M_s B_z/2 [J/m³]: > 0 when the uniform film along +z is stable."""
        return self.effective_anisotropy + 0.5 * self.saturation_magnetization * self.applied_field

    @property
    def exchange_length(self) -> float:
        """l_ex = √(2A/(μ₀M_s²)) [m]."""
        return math.sqrt(
            2 * self.exchange_stiffness / (units.MU_0 * self.saturation_magnetization**2)
        )

    @property
    def total_dmi(self) -> float:
        """|D| of the DMI that is switched on (interfacial or bulk) [J/m²]."""
        return self.dmi + self.bulk_dmi

    @property
    def dmi_length(self) -> float:
        """A/|D| [m]."""
        return self.exchange_stiffness / self.total_dmi

    @property
    def wall_width(self) -> float:
        """Δ_eff = √(A/K_⊥) [m] (thin-film limit)."""
        return math.sqrt(self.exchange_stiffness / self.perpendicular_stiffness)

    @property
    def bare_wall_width(self) -> float:
        """Δ = √(A/K_u) [m], the wall width without the stray field.

        What the presets' thin-wall estimate of 𝒟 uses.
        """
        return (
            math.sqrt(self.exchange_stiffness / self.anisotropy)
            if self.anisotropy > 0
            else math.inf
        )

    @property
    def critical_dmi(self) -> float:
        """D_c = 4√(A K_eff)/π [J/m²]: above it a film without field prefers spirals.

        0 for a film that is in-plane without field.
        """
        return (
            4 * math.sqrt(self.exchange_stiffness * max(self.effective_anisotropy, 0.0)) / math.pi
        )

    @property
    def largest_cell(self) -> float:
        """The largest cell size the calibration accepts, min(l_ex, Δ_eff, A/|D|) [m]."""
        return min(self.exchange_length, self.wall_width, self.dmi_length)

    @model_validator(mode="after")
    def _thin_perpendicular_film(self) -> MicromagneticMaterial:
        if self.dmi > 0 and self.bulk_dmi > 0:
            raise ValueError(
                "dmi|interfacial and bulk DMI at once|one of `dmi` (interfacial, "
                "Néel skyrmions) or `bulk_dmi` (Bloch skyrmions), the other 0"
            )
        if self.total_dmi == 0:
            raise ValueError(
                "dmi|0|a DMI constant > 0 (`dmi` for interfacial, `bulk_dmi` for "
                "bulk): without DMI there are no stable skyrmions"
            )
        if self.perpendicular_stiffness <= 0:
            raise ValueError(
                f"anisotropy|{self.anisotropy:g}|K_u + M_s B_z/2 > μ₀M_s²/2 = "
                f"{self.shape_anisotropy:.4g} J/m³ (the stray field's shape anisotropy), "
                "so that the film is magnetised out of plane (along +z; a larger B_z helps)"
            )
        if self.film_thickness > self.exchange_length:
            raise ValueError(
                f"film_thickness|{self.film_thickness:g}|at most the exchange length "
                f"l_ex = {self.exchange_length:.3g} m: the film is modelled as one cell layer"
            )
        if self.cell_size > self.largest_cell:
            lengths = {
                "the exchange length": self.exchange_length,
                "the wall width √(A/K_⊥)": self.wall_width,
                "the DMI length A/D": self.dmi_length,
            }
            name, value = min(lengths.items(), key=lambda item: item[1])
            raise ValueError(
                f"cell_size|{self.cell_size:g}|at most {name}, {value:.3g} m, so "
                "that the mesh resolves the skyrmion"
            )
        return self

    def as_record(self) -> dict[str, Any]:
        """The parameters with the derived length scales (SI), for result files."""
        return {
            **self.model_dump(),
            "effective_anisotropy": self.effective_anisotropy,
            "exchange_length": self.exchange_length,
            "wall_width_effective": self.wall_width,
            "dmi_length": self.dmi_length,
            "critical_dmi": self.critical_dmi,
        }


def split_error(err: ValidationError, source: str = "") -> InputError:
    """A validation error as an :class:`InputError`.

    A validator's own message is ``field|value|allowed`` (several fields at once, so it cannot be
    attached to one by pydantic); anything else is pydantic's, in skygas's words.
    """
    first = err.errors()[0]
    message = first["msg"].removeprefix("Value error, ")
    if first["type"] == "value_error" and message.count("|") == 2:
        field, value, allowed = message.split("|")
        return InputError(f"{source}{field}", _number_or_text(value), allowed)
    return to_input_error(err, source)


def _number_or_text(text: str) -> float | str:
    """The number a validator's message wrote (``"1e-08"``), or the text if it is none."""
    try:
        return float(text)
    except ValueError:
        return text


def _preset_parameters(name: str) -> dict[str, Any]:
    from skygas.physics.materials import preset

    m = preset(name)
    return {
        "name": name,
        "saturation_magnetization": m.saturation_magnetization,
        "exchange_stiffness": m.exchange_stiffness,
        "dmi": m.dmi,
        "anisotropy": m.anisotropy,
        "applied_field": m.applied_field,
        "damping": m.damping,
    }


def micromagnetic_material(data: dict[str, Any], source: str = "") -> MicromagneticMaterial:
    """Validate a mapping into a :class:`MicromagneticMaterial`.

    A key ``base = "S2"`` starts from that preset's micromagnetic parameters and overrides only the
    keys given.
    """
    data = dict(data)
    base = data.pop("base", None)
    if base is not None:
        from skygas.physics.materials import preset_names

        if base not in preset_names():
            raise InputError(f"{source}base", base, f"one of {', '.join(preset_names())}")
        data = {**_preset_parameters(base), "name": f"{base}-custom", **data}
    try:
        return MicromagneticMaterial(**data)
    except ValidationError as err:
        raise split_error(err, source) from None


def load_micromagnetic_material(
    source: str | Path | dict | MicromagneticMaterial, **overrides: Any
) -> MicromagneticMaterial:
    """The film to calibrate, from a preset name, a TOML file, a mapping or a material.

    Parameters
    ----------
    source : str, Path, dict or MicromagneticMaterial
        A preset name (``"S1"`` … ``"S7"``), a TOML file (its ``[micromagnetics]`` table, or its top
        level), a mapping or a material.
    **overrides
        Single fields to replace (``cell_size=1e-9``), validated like the rest.

    Returns
    -------
    MicromagneticMaterial

    Raises
    ------
    InputError
        If the source cannot be read or a field is invalid.
    """
    from skygas.physics.materials import preset_names

    if isinstance(source, MicromagneticMaterial):
        data, where = source.model_dump(), ""
    elif isinstance(source, dict):
        data, where = dict(source), ""
    elif str(source) in preset_names():
        data, where = _preset_parameters(str(source)), ""
    else:
        path = Path(str(source))
        if path.suffix != ".toml" or not path.is_file():
            raise InputError(
                "MATERIAL",
                str(source),
                f"a preset ({', '.join(preset_names())}) or an existing .toml file "
                "of micromagnetic parameters",
            )
        try:
            table = tomllib.loads(path.read_text(encoding="utf-8"))
        except (UnicodeDecodeError, tomllib.TOMLDecodeError) as err:
            raise InputError("MATERIAL", str(path), f"a valid UTF-8 TOML file ({err})") from None
        data = table.get("micromagnetics", table)
        if not isinstance(data, dict):
            raise InputError(f"{path.name}: micromagnetics", data, "a table of parameters")
        where = f"{path.name}: "
    data = {**data, **{k: v for k, v in overrides.items() if v is not None}}
    return micromagnetic_material(data, where)
