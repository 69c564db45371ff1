"""Configuration of the Brownian reservoir (TOML, validated with pydantic; SI units).

Defaults (docs/reservoir.md, "Choosing the defaults"): an equilateral triangle of side 300 nm
(about 8 skyrmion diameters) whose corners are cut into 60 nm contacts A, B (bottom) and C (top);
one skyrmion of S2 in a 2 nm film at 300 K; inputs on A and B (bit 0 → −V₀, bit 1 → +V₀), C at
0 V; V₀ chosen so that the chamber-mean |j| of the unit pattern "A at V₀, others at 0 V" is
4e9 A/m² (drift speed ξJ ≈ 0.7 m/s); every input held 20 µs; one disk sensor of radius 90 nm
at each contact, read every 10 ns. A skyrmion of S2 diffuses 4.4 nm²/ns at 300 K and crosses
the region the walls leave it (~150 nm) in a few µs, so a 20 µs hold averages over several
explorations: the regime in which thermal motion, not the drive alone, sets where the skyrmion
tends to be.

Every configuration error is reported before any work, in one line naming the field.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Literal

from pydantic import Field, ValidationError

from skygas.core.config_types import StrictModel as _Strict
from skygas.core.config_types import apply_overrides, read_toml, to_input_error  # noqa: N814 (the name every config uses)
from skygas.core.errors import InputError
from skygas.fields.current import (
    DEFAULT_CELL_SIZE,
    DEFAULT_CONDUCTOR_THICKNESS,
    DEFAULT_RESISTIVITY,
)
from skygas.runs.config import MaterialFields, OperationsField, PortSpec


class ChamberSpec(_Strict):
    """The chamber: a regular shape or a polygon, contacts at its corners (or given)."""

    shape: Literal["triangle", "square", "disk", "polygon"] = "triangle"
    size: float = Field(300e-9, gt=0)  # m: side (triangle, square) or diameter (disk)
    contact_width: float = Field(60e-9, gt=0)  # m: width of each corner contact
    vertices: list[tuple[float, float]] = []  # m: corners of a "polygon" chamber
    contacts: list[PortSpec] = []  # explicit contacts (replace the corner cuts)


class DriveSpec(_Strict):
    """How input bits become contact voltages, and the film that carries the current."""

    input_contacts: list[str] = ["A", "B"]  # one contact per input bit
    levels: tuple[float, float] = (-1.0, 1.0)  # V/V₀ for bit 0 and bit 1; other contacts 0 V
    current_density: float = Field(4e9, ge=0)  # A/m²: chamber-mean |j| for unit V₀ on input 0
    spin_drift_coefficient: float = Field(1.84e-10, gt=0)  # ξ [m³/C]
    conductor_thickness: float = Field(DEFAULT_CONDUCTOR_THICKNESS, gt=0)
    resistivity: float = Field(DEFAULT_RESISTIVITY, gt=0)
    cell_size: float = Field(DEFAULT_CELL_SIZE, gt=0)


class SensorSpec(_Strict):
    """Magnetoresistive sensors.

    Disks; the signal is the fraction of the sensor's area the skyrmions cover, plus Gaussian
    read noise.
    """

    radius: float = Field(90e-9, gt=0)  # m
    centers: list[tuple[float, float]] = []  # m; empty: one at each contact's middle
    read_noise: float = Field(0.005, ge=0)  # covered fraction (std per read)
    sample_interval: float = Field(10e-9, gt=0)  # s
    bins: int = Field(4, ge=1, le=20)  # feature windows per hold


class ReadoutSpec(_Strict):
    """The trained linear read-out."""

    model: Literal["ridge", "logistic"] = "ridge"
    regularization: float = Field(1e-3, gt=0)  # ridge α or 1/C of the logistic fit
    test_fraction: float = Field(0.4, gt=0, lt=1)


class StudySpec(_Strict):
    """The input stream and the temporal tasks."""

    n_inputs: int = Field(600, ge=8)  # held inputs of the Boolean study (train + test)
    warmup_inputs: int = Field(2, ge=0)  # inputs run before each stream, not scored
    # The temporal tasks run their own stream with short holds: the skyrmion forgets its
    # previous position within ~100 ns at the default drive, so memory shows only when inputs
    # change faster than that (docs/reservoir.md, "Fading memory").
    temporal_inputs: int = Field(1200, ge=0)
    temporal_hold_time: float = Field(5e-8, gt=0)  # s
    temporal_sample_interval: float = Field(2e-9, gt=0)  # s
    delays: list[Annotated[int, Field(ge=1)]] = [1, 2, 3]  # recall of the input k steps back
    workers: int = Field(2, ge=1)  # independent streams run in parallel


class ReservoirConfig(MaterialFields, OperationsField):
    """Everything that defines a reservoir study (SI units)."""

    seed: int = Field(0, ge=0, lt=2**63)
    temperature: float = Field(300.0, ge=0)
    time_step: float | None = Field(None, gt=0)  # s; None: the engine's suggested step
    n_skyrmions: int = 1
    hold_time: float = Field(20e-6, gt=0)  # s each input is held
    chamber: ChamberSpec = ChamberSpec()
    drive: DriveSpec = DriveSpec()
    sensors: SensorSpec = SensorSpec()
    readout: ReadoutSpec = ReadoutSpec()
    study: StudySpec = StudySpec()


#: Where the reservoir's own sweep of earlier versions (``[sweep]``, ``--sweep``) went.
SWEEP_INSTEAD = (
    'sweep the reservoir with `skygas sweep FILE.toml` and [sweep] device = "reservoir" '
    "(docs/sweeps.md; examples/reservoir/sweep-*.toml)"
)


def _check_counts(data: dict) -> None:
    """Counts with their own clear message (before pydantic's generic one).

    A ``[sweep]`` table (the reservoir's own sweep of earlier versions) is refused with the
    way to run it now: a ``skygas sweep`` file of ``device = "reservoir"``.
    """
    if "sweep" in data:
        raise InputError(
            "sweep",
            data["sweep"],
            "no [sweep] table in a reservoir configuration (the reservoir's own sweep is gone)",
            SWEEP_INSTEAD,
        )
    n = data.get("n_skyrmions", 1)
    if not isinstance(n, int) or isinstance(n, bool) or n < 1:
        raise InputError("n_skyrmions", n, "an integer >= 1 (the reservoir needs a skyrmion)")
    hold = data.get("hold_time")
    if isinstance(hold, (int, float)) and not isinstance(hold, bool) and hold <= 0:
        raise InputError("hold_time", hold, "a duration > 0 in seconds")


def reservoir_config(data: dict | None = None, **overrides) -> ReservoirConfig:
    """A validated :class:`ReservoirConfig` from a mapping plus overrides.

    Overrides are dotted keys (:func:`~skygas.core.config_types.apply_overrides`).
    """
    data = apply_overrides(data or {}, overrides)
    _check_counts(data)
    try:
        config = ReservoirConfig.model_validate(data)
    except ValidationError as err:
        raise to_input_error(err, "reservoir config: ") from None
    config.resolved_material()
    return config


def load_reservoir_config(path: str | Path | None = None, **overrides) -> ReservoirConfig:
    """The configuration of TOML file ``path`` (defaults without one), plus overrides."""
    data = read_toml(path) if path is not None else {}
    return reservoir_config(data, **overrides)
