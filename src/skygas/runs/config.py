"""TOML configuration of a simulation, validated with pydantic before anything runs.

A configuration file looks like ``examples/closed-chamber.toml``. All values are SI (metres,
seconds, kelvin, m/s). Every field is checked when the file is loaded; an invalid value raises
:class:`~skygas.core.errors.InputError` naming the field, the value and what is allowed.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field, ValidationError, ValidationInfo, field_validator, model_validator

from skygas.core.config_types import (
    ChamberSize,
    Length,
    PositiveFloat,
    StrictModel,
    apply_overrides,
    read_toml,
    to_input_error,
)
from skygas.core.errors import InputError
from skygas.core.units import M_TO_NM
from skygas.fields.landscape.kinds import Potential
from skygas.physics import geometry as geo
from skygas.physics.forces import DEFAULT_CUTOFF_FRACTION
from skygas.physics.materials import (
    DEFAULT_FILM_THICKNESS,
    Material,
    ThieleParameters,
    derive_thiele,
    film_mismatch,
    load_material,
    preset_names,
)
from skygas.runs.operations import OperationSpec

Point2 = tuple[float, float]


class PortSpec(StrictModel):
    """An open boundary segment, from ``start`` to ``end`` [m]."""

    name: str
    start: Point2
    end: Point2


class DiskSpec(StrictModel):
    """A disk of ``diameter`` [m] around ``center`` [m] (sizes are diameters, as everywhere)."""

    kind: Literal["disk"]
    diameter: Length
    center: Point2 = (0.0, 0.0)

    @model_validator(mode="before")
    @classmethod
    def _no_radius(cls, data: Any) -> Any:
        if isinstance(data, dict) and "radius" in data:
            raise ValueError(
                "a disk given by its diameter: write diameter = 2 × radius instead of radius"
            )
        return data


class RectangleSpec(StrictModel):
    """A rectangle ``width`` × ``height`` [m] around ``center`` [m]."""

    kind: Literal["rectangle"]
    width: Length
    height: Length
    center: Point2 = (0.0, 0.0)


class PolygonSpec(StrictModel):
    """A polygon through ``vertices`` [m] (at least three)."""

    kind: Literal["polygon"]
    vertices: list[Point2] = Field(min_length=3)


ShapeSpec = Annotated[DiskSpec | RectangleSpec | PolygonSpec, Field(discriminator="kind")]


class ChamberGeometry(ChamberSize):
    """The paper's chamber with input and output conduits (ports ``input``, ``output``)."""

    kind: Literal["chamber"] = "chamber"
    closed: bool = Field(False, description="close both conduit ends (no ports)")

    def build(self) -> geo.Outline:
        """The chamber's outline, with its ports unless ``closed``."""
        outline = geo.chamber_with_conduits(
            self.chamber_diameter, self.conduit_width, self.conduit_length
        )
        return geo.Outline(outline.region) if self.closed else outline


class ShapesGeometry(StrictModel):
    """A union of shapes with optional ports."""

    kind: Literal["shapes"]
    shapes: list[ShapeSpec] = Field(min_length=1)
    ports: list[PortSpec] = []

    def build(self) -> geo.Outline:
        """The union of the shapes, with the ports."""
        parts = []
        for s in self.shapes:
            if s.kind == "disk":
                parts.append(geo.disk(diameter=s.diameter, center=s.center))
            elif s.kind == "rectangle":
                parts.append(geo.rectangle(s.width, s.height, s.center))
            else:
                parts.append(geo.polygon(s.vertices))
        outline = geo.union(*parts) if len(parts) > 1 else parts[0]
        for p in self.ports:
            outline = outline.with_port(p.name, p.start, p.end)
        return outline


GeometrySpec = Annotated[ChamberGeometry | ShapesGeometry, Field(discriminator="kind")]


class ThieleOverrides(StrictModel):
    """Optional overrides of the derived Thiele parameters (docs/physics.md §4)."""

    dissipation: PositiveFloat | None = None
    force_scale: PositiveFloat | None = None  # F0 [N]
    skyrmion_diameter: Length | None = None  # d_sk [m]
    eta: float | None = None
    mu: float = 1.0


class ForcesSpec(StrictModel):
    """The force laws (docs/physics.md §2).

    ``pair_law`` / ``wall_law`` left out take the material's own: ``"table"`` when it has a
    ``pair_table`` / ``wall_table`` (a calibrated model), else ``"paper"``; results record the
    law used.
    """

    pair_law: Literal["paper", "lin-reichhardt", "table"] | None = None
    wall_law: Literal["paper", "table"] | None = None
    pair_law_params: dict[str, float] = {}
    cutoff_fraction: float = Field(DEFAULT_CUTOFF_FRACTION, gt=0, lt=1)
    #: a uniform force (F_x, F_y) [N] on every skyrmion (a field gradient, a tilted film;
    #: :class:`~skygas.engine.term_rules.ConstantForce`)
    external_force: Point2 = (0.0, 0.0)
    #: ``"rigid"`` or ``"breathing"`` (each skyrmion's radius its own degree of freedom, for a
    #: material with a ``[material.breathing]`` table); left out: the material's own
    particle_model: Literal["rigid", "breathing"] | None = None
    #: ``"nearest"`` (the wall law along the nearest wall's normal) or ``"film"`` (every edge
    #: within reach, :mod:`skygas.fields.landscape.wall_film`); left out: the material's own
    wall_geometry: Literal["nearest", "film"] | None = None

    def simulation_arguments(self) -> dict:
        """The keyword arguments of :class:`~skygas.engine.Simulation` these choices give."""
        return {
            "pair_law": self.pair_law,
            "wall_law": self.wall_law,
            "pair_law_params": self.pair_law_params,
            "cutoff_fraction": self.cutoff_fraction,
            "external_force": self.external_force,
            "particle_model": self.particle_model,
            "wall_geometry": self.wall_geometry,
        }


class DriftSpec(StrictModel):
    """A uniform spin-drift velocity v_s [m/s]."""

    velocity: Point2 = (0.0, 0.0)  # uniform v_s [m/s]


class SkyrmionsSpec(StrictModel):
    """Initial skyrmions.

    Explicit ``positions`` [m] and/or ``random_count`` placed at random at least
    ``min_separation`` diameters apart and from walls.
    """

    positions: list[Point2] = []
    random_count: int = Field(0, ge=0)
    min_separation: PositiveFloat = 1.0


def _material(material: str | dict[str, Any]) -> Material:
    """The material a configuration names: a preset name, a TOML file, or an inline table."""
    if (
        isinstance(material, str)
        and not material.endswith(".toml")
        and material not in preset_names()
    ):
        raise InputError(
            "material", material, f"a preset ({', '.join(preset_names())}), a .toml file or a table"
        )
    return load_material(material)


def _material_or_none(material) -> Material | None:
    """The material, or ``None`` if it does not load.

    Its error is reported where the material is used, as for any configuration.
    """
    try:
        return None if material is None else _material(material)
    except InputError:
        return None


class MaterialFields(StrictModel):
    """Fields every run configuration shares.

    The material, its film, Thiele overrides, the force laws and the landscape.

    ``film_thickness`` left out takes the material's own when it has one (a calibrated model,
    measured for one film); a different explicit value is then refused.
    """

    material: str | dict[str, Any] = "S2"
    film_thickness: Length = DEFAULT_FILM_THICKNESS
    thiele: ThieleOverrides = ThieleOverrides()
    forces: ForcesSpec = ForcesSpec()
    #: the energy landscape: external potentials (``[[potentials]]``, skygas.fields.landscape)
    potentials: list[Potential] = []

    @field_validator("film_thickness")
    @classmethod
    def _film_of_the_model(cls, value: float, info: ValidationInfo) -> float:
        material = _material_or_none(info.data.get("material"))
        mismatch = None if material is None else film_mismatch(material, value)
        if mismatch is not None:
            raise ValueError(mismatch)
        return value

    @model_validator(mode="after")
    def _adopt_film_thickness(self):
        if "film_thickness" not in self.model_fields_set:
            material = _material_or_none(self.material)
            if material is not None and material.film_thickness is not None:
                self.film_thickness = material.film_thickness
        return self

    def resolved_material(self) -> Material:
        """The material: a preset name, a TOML file, or an inline table."""
        return _material(self.material)

    def simulation(
        self,
        outline: geo.Outline,
        *,
        seed: int,
        temperature: float,
        time_step: float | None,
        brownian_substeps: int = 1,
        extra_potentials: Sequence[Any] = (),
        **device_arguments: Any,
    ):
        """The :class:`~skygas.engine.Simulation` of this configuration in ``outline``.

        The one place a configuration becomes an engine run, for every device: its material,
        film, Thiele coefficients (with the overrides), force laws (``[forces]``) and energy
        landscape (``[[potentials]]``, then the device's ``extra_potentials``). The device
        gives the rest: ``seed``, ``temperature`` [K], ``time_step`` [s] (None: the engine's
        suggested step), ``brownian_substeps`` and its own arguments (``step_interval``,
        ``drift_velocity``, ``capacity``, …; :class:`~skygas.engine.Simulation`).
        """
        from skygas.engine import Simulation

        return Simulation(
            outline,
            self.resolved_material(),
            temperature=temperature,
            time_step=time_step,
            seed=seed,
            film_thickness=self.film_thickness,
            thiele=self.thiele_parameters(),
            brownian_substeps=brownian_substeps,
            landscape=[*self.potentials, *extra_potentials],
            **self.forces.simulation_arguments(),
            **device_arguments,
        )

    def thiele_parameters(self) -> ThieleParameters:
        """Thiele coefficients of the material in the film, with the overrides applied."""
        o = self.thiele
        return derive_thiele(
            self.resolved_material(),
            self.film_thickness,
            dissipation=o.dissipation,
            force_scale=o.force_scale,
            skyrmion_diameter=o.skyrmion_diameter,
            eta=o.eta,
            mu=o.mu,
        )


class OperationsField(StrictModel):
    """The ``[[operations]]`` tables of a run (:mod:`skygas.runs.operations`).

    Sensors and the user's own operations, attached to the run's simulation by
    :meth:`~skygas.runs.device_run.DeviceRun.attach_operations`. Every device takes them
    (``simulate``, ``reshuffle``, ``neuron``; the reservoir in each stream of its study).
    """

    operations: list[OperationSpec] = []

    @field_validator("operations")
    @classmethod
    def _unique_names(cls, operations: list) -> list:
        names = [op.name for op in operations]
        for name in names:
            if names.count(name) > 1:
                raise ValueError(f"operations with different names ('{name}' is used twice)")
        return operations


class SimulationConfig(MaterialFields, OperationsField):
    """Everything that defines a simulation run (SI units)."""

    seed: int = Field(0, ge=0, lt=2**63)
    temperature: float = Field(300.0, ge=0)
    # default: the engine's suggested step, shortened to divide record_interval exactly
    time_step: PositiveFloat | None = None
    duration: PositiveFloat  # [s]; 0 is refused, as by every command
    record_interval: PositiveFloat = 1e-9
    integrator: Literal["heun", "euler-maruyama"] = "heun"
    drift: DriftSpec = DriftSpec()
    geometry: GeometrySpec = ChamberGeometry(closed=True)
    skyrmions: SkyrmionsSpec

    @field_validator("record_interval")
    @classmethod
    def _a_frame_within_the_run(cls, value: float, info: ValidationInfo) -> float:
        duration = info.data.get("duration")
        if duration is not None and value > duration:
            raise ValueError(
                f"a record interval at most the duration ({duration:g} s): no frame would be "
                "recorded; shorten record_interval or lengthen duration"
            )
        return value

    def build(self, *, time_step: float | None = None, brownian_substeps: int = 1):
        """A ready :class:`~skygas.engine.Simulation` with the initial skyrmions placed.

        ``time_step`` and ``brownian_substeps`` override the configuration (time-step checks).
        """
        outline = self.geometry.build()
        if time_step is None:
            time_step = self.time_step
        # time_step None: the suggested step, shortened to divide record_interval exactly
        sim = self.simulation(
            outline,
            seed=self.seed,
            temperature=self.temperature,
            time_step=time_step,
            brownian_substeps=brownian_substeps,
            step_interval=self.record_interval,
            drift_velocity=self.drift.velocity,
            integrator=self.integrator,
        )
        s = self.skyrmions
        if s.positions:
            sim.add_skyrmions(np.asarray(s.positions), validate=True)
        if s.random_count:
            d_sk = sim.thiele.skyrmion_diameter_internal
            rng = np.random.default_rng(np.random.SeedSequence([self.seed, 0x5EED]))
            pts = geo._random_positions_nm(
                sim.outline, s.random_count, s.min_separation * d_sk, s.min_separation * d_sk, rng
            )
            sim.validate_positions(pts / M_TO_NM, "skyrmions.random_count")
            sim.state.insert_nm(pts)
        return sim


def resolve_paths(data: dict, folder: Path) -> dict:
    """``data`` (a parsed TOML configuration) with its relative file names, a material's ``.toml``.

    The ``path`` of ``grid`` potentials and the files of ``[[operations]]`` targets, taken
    relative to ``folder`` (the configuration's folder), as a user who writes them next to the
    file means them.
    """
    data = dict(data)
    material = data.get("material")
    if (
        isinstance(material, str)
        and material.endswith(".toml")
        and not Path(material).is_absolute()
    ):
        data["material"] = str(folder / material)
    potentials = data.get("potentials")
    if isinstance(potentials, list):
        data["potentials"] = [
            {**p, "path": str(folder / p["path"])}
            if isinstance(p, dict)
            and isinstance(p.get("path"), str)
            and not Path(p["path"]).is_absolute()
            else p
            for p in potentials
        ]
    operations = data.get("operations")
    if isinstance(operations, list):
        data["operations"] = [_resolve_target(op, folder) for op in operations]
    return data


def _resolve_target(table: Any, folder: Path) -> Any:
    """An ``[[operations]]`` table whose ``target`` file (``"file.py:name"``) is relative.

    Taken relative to ``folder``.
    """
    if not isinstance(table, dict) or not isinstance(table.get("target"), str):
        return table
    module, sep, name = table["target"].rpartition(":")
    if sep and module.endswith(".py") and not Path(module).is_absolute():
        return {**table, "target": f"{folder / module}:{name}"}
    return table


def parse_config(data: dict, source: str = "") -> SimulationConfig:
    """Validate a mapping (e.g. parsed TOML) into a :class:`SimulationConfig`."""
    try:
        return SimulationConfig(**data)
    except ValidationError as err:
        raise to_input_error(err, source) from None


def load_config(path: str | Path, **overrides: Any) -> SimulationConfig:
    """Read and validate a TOML configuration file, with overrides.

    ``overrides`` take dotted keys (:func:`~skygas.core.config_types.apply_overrides`;
    ``None`` leaves the file's value), e.g. ``seed=3`` or ``duration=1e-7``.
    """
    path = Path(path)
    data = apply_overrides(resolve_paths(read_toml(path), path.parent), overrides)
    return parse_config(data, source=f"{path.name}: ")
