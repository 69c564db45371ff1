"""Configuration of a neuron run (TOML, validated with pydantic; SI units).

Defaults: the paper's chamber (1024 nm, 100 nm × 50 nm conduits), material S2 in a 2 nm film at
300 K, the reshuffler's calibrated ξ = 1.84e-10 m³/C (data/reshuffler-paper.toml), the
calibrated annihilation model (:mod:`skygas.neuron.calibration`), a 20 k_B T gate (a potential
band 30 nm wide with 10 nm edges: it holds the threshold's crowd of 12 at the holding current;
docs/neuron.md, "The gate: the crowd it holds back") and a whole-chamber counting sensor. The
paper gives no operating point for the neuron; the drive and the rule were chosen so that the
default run integrates, fires and resets (docs/neuron.md, "Choosing the defaults"):

- holding current J = 5e10 A/m² while the gate is closed: it carries injected skyrmions into
  the chamber without pressing them against the gate (at 1e11 A/m² and above the current packs
  the arrivals against the closed gate, where they annihilate as fast as they would leave
  through an open one, and the gate stops mattering);
- release current 3.8e11 A/m² (the paper's largest reshuffler current) while the gate is open,
  which usually empties the chamber to the reset level within 150 ns;
- a Poisson input of 5e7 Hz, threshold 12, reset level 3, release time at most 200 ns,
  refractory time 20 ns.

Every float must be finite: an infinite duration, interval or rate is refused here, before any
run.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Literal

from pydantic import ConfigDict, Field, ValidationError, model_validator

from skygas.core.config_types import (
    ChamberSize,
    StrictModel,
    apply_overrides,
    read_toml,
    to_input_error,
)
from skygas.core.errors import InputError
from skygas.neuron.annihilation import AnnihilationModel
from skygas.neuron.calibration import CALIBRATED
from skygas.neuron.inputs import InputSpec
from skygas.runs.config import MaterialFields, OperationsField, resolve_paths


class DeviceSpec(ChamberSize):
    """The neuron's chamber (the paper's by default)."""


class GateSpec(StrictModel):
    """The closed gate, a potential band across the output conduit (skygas.neuron.gate).

    The top of the barrier [k_BT], its width between the half-height points [m] and the width of its
    tanh edges [m].
    """

    barrier_height: float = Field(20.0, ge=0)  # k_B T
    band_width: float = Field(30e-9, gt=0)  # m, inside the conduit
    edge_width: float = Field(10e-9, gt=0)  # m
    initially_open: bool = False


class SensorSpec(StrictModel):
    """The read element: a disk inside the chamber, read every ``read_interval`` [s].

    ``center`` [m], ``radius`` [m] (default: the chamber's radius); ``signal`` ``"count"`` (centres
    inside) or ``"area"`` (the fraction of the disk covered by skyrmions); ``read_noise``: standard
    deviation of Gaussian read noise, in the signal's units.
    """

    center: tuple[float, float] = (0.0, 0.0)  # m
    radius: float | None = Field(None, gt=0)  # m; default the chamber's radius
    signal: Literal["count", "area"] = "count"
    read_noise: float = Field(0.0, ge=0)  # signal units
    read_interval: float = Field(1e-9, gt=0)  # s


class RuleSpec(StrictModel):
    """The firing rule.

    A closed gate opens when the reading is ≥ ``threshold`` and no refractory time is running; an
    open gate closes when the reading is ≤ ``reset_level`` or after ``release_time`` [s], whichever
    comes first; after it closes, ``refractory_time`` [s] must pass before it opens again.
    """

    # The release usually ends at the reset level (the release current empties the chamber in
    # ~150 ns); the release time only bounds an opening that cannot get there.
    threshold: float = Field(12.0, gt=0)
    reset_level: float = Field(3.0, ge=0)
    release_time: float | None = Field(2e-7, gt=0)  # s
    refractory_time: float = Field(2e-8, ge=0)  # s


class AnnihilationSpec(StrictModel):
    """The annihilation and nucleation rule, in SI units.

    As :class:`~skygas.neuron.annihilation.AnnihilationModel`. Defaults: the calibrated model
    (:data:`~skygas.neuron.calibration.CALIBRATED`), without nucleation.
    """

    base_rate: float = Field(CALIBRATED.base_rate, ge=0)
    compression_sensitivity: float = Field(CALIBRATED.compression_sensitivity, ge=0)
    crowding_distance: float | None = Field(CALIBRATED.crowding_distance, gt=0)
    collapse_distance: float | None = Field(CALIBRATED.collapse_distance, gt=0)
    check_interval: float = Field(CALIBRATED.check_interval, gt=0)
    nucleation_rate: float = Field(0.0, ge=0)
    enabled: bool = True


class InputConfig(StrictModel):
    """One input spike train (:class:`~skygas.neuron.inputs.InputSpec`; rates in Hz, times in s).

    ``kind`` ``"poisson"`` (``rate``), ``"regular"`` (``rate``), ``"telegraph"``/``"bernoulli"``
    (clock ``interval``, P(1) = ``p``, telegraph ``correlation_time``) or ``"bits"`` (``bits`` at
    ``interval``); every event injects with probability ``weight``.
    """

    kind: Literal["poisson", "telegraph", "bernoulli", "regular", "bits"] = "poisson"
    rate: float = Field(0.0, ge=0)
    p: float = Field(0.5, ge=0, le=1)
    interval: float = Field(5e-9, gt=0)
    correlation_time: float = Field(5e-9, gt=0)
    weight: float = Field(1.0, ge=0, le=1)
    bits: list[Literal[0, 1]] = []

    @model_validator(mode="after")
    def _kind_needs(self):
        if self.kind == "bits" and not self.bits:
            raise ValueError("a 'bits' input needs a non-empty bits list of 0 and 1")
        if self.kind == "telegraph" and not 0 < self.p < 1:
            raise ValueError(f"p = {self.p}: a telegraph input needs p strictly in (0, 1)")
        return self


class InjectionSpec(StrictModel):
    """The injectors' handling of an occupied site.

    An event finding another centre closer than ``site_clearance`` skyrmion diameters waits and is
    retried every ``retry_interval`` [s] (``occupied_rule = "delay"``), or is dropped (``"skip"``).
    """

    occupied_rule: Literal["delay", "skip"] = "delay"
    site_clearance: float = Field(1.0, gt=0)  # skyrmion diameters
    retry_interval: float = Field(0.5e-9, gt=0)


class TransferSpec(StrictModel):
    """The transfer curve's runs: input ``rates`` [Hz] and their ``duration`` [s].

    Empty ``rates``: a default sweep; ``duration`` by default the run's.
    """

    rates: list[Annotated[float, Field(ge=0)]] = []  # Hz; empty: a default sweep
    duration: float | None = Field(None, gt=0)  # s; default the run's duration


class NeuronConfig(MaterialFields, OperationsField):
    """A neuron run (SI units); defaults in the module docstring.

    Besides the material fields every run shares (material, film, Thiele overrides, force laws,
    potentials) and its ``[[operations]]``: ``seed``, ``temperature`` [K], ``duration`` [s],
    ``time_step`` [s] (``None``: the simulation's suggested step), ``current_density`` [A/m²]
    while the gate is closed, ``release_current_density`` [A/m²] while it is open (``None``: the
    same), ``spin_drift_coefficient`` ξ [m³/C], and the sections ``device``, ``gate``,
    ``sensor``, ``rule``, ``annihilation``, ``inputs``, ``injection`` and ``transfer``.
    """

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    seed: int = Field(0, ge=0, lt=2**63)
    temperature: float = Field(300.0, ge=0)
    duration: float = Field(3e-6, gt=0)
    time_step: float | None = Field(2.5e-10, gt=0)
    current_density: float = Field(5e10, ge=0)  # A/m², holding (gate closed)
    release_current_density: float | None = Field(3.8e11, ge=0)  # A/m², gate open; None: same
    spin_drift_coefficient: float = Field(1.84e-10, gt=0)
    device: DeviceSpec = DeviceSpec()
    gate: GateSpec = GateSpec()
    sensor: SensorSpec = SensorSpec()
    rule: RuleSpec = RuleSpec()
    annihilation: AnnihilationSpec = AnnihilationSpec()
    inputs: list[InputConfig] = [InputConfig(kind="poisson", rate=5e7)]
    injection: InjectionSpec = InjectionSpec()
    transfer: TransferSpec = TransferSpec()

    def release_current(self) -> float:
        """Conduit current density [A/m²] while the gate is open."""
        if self.release_current_density is None:
            return self.current_density
        return self.release_current_density

    def annihilation_model(self) -> AnnihilationModel:
        """The annihilation section as an :class:`~skygas.neuron.annihilation.AnnihilationModel`."""
        return AnnihilationModel(**self.annihilation.model_dump())

    def input_specs(self) -> list[InputSpec]:
        """The :class:`~skygas.neuron.inputs.InputSpec` of each ``inputs`` entry."""
        return [InputSpec(**{**i.model_dump(), "bits": tuple(i.bits)}) for i in self.inputs]


def _check_negative_rates(data: dict) -> None:
    """Negative rates get a message naming the field (before pydantic's generic one)."""
    for k, inp in enumerate(data.get("inputs", []) or []):
        if isinstance(inp, dict):
            for key in ("rate", "weight"):
                v = inp.get(key)
                if isinstance(v, (int, float)) and v < 0:
                    raise InputError(f"inputs[{k}].{key}", v, "a value >= 0 (rates in Hz)")
    ann = data.get("annihilation", {}) or {}
    for key in ("base_rate", "nucleation_rate"):
        v = ann.get(key)
        if isinstance(v, (int, float)) and v < 0:
            raise InputError(f"annihilation.{key}", v, "a rate >= 0")


def neuron_config(data: dict | None = None, **overrides) -> NeuronConfig:
    """A validated :class:`NeuronConfig` from a mapping plus overrides.

    Overrides take dotted keys (:func:`~skygas.core.config_types.apply_overrides`).
    """
    data = apply_overrides(data or {}, overrides)
    _check_negative_rates(data)
    try:
        return NeuronConfig.model_validate(data)
    except ValidationError as err:
        raise to_input_error(err, "neuron config: ") from None


def load_neuron_config(path: str | Path | None = None, **overrides) -> NeuronConfig:
    """A validated :class:`NeuronConfig` from a TOML file (or the defaults), plus overrides.

    Relative paths in the file are taken relative to its folder; overrides take dotted keys, as
    :func:`neuron_config`. Raises :class:`InputError` naming the field.
    """
    data = resolve_paths(read_toml(path), Path(path).parent) if path is not None else {}
    return neuron_config(data, **overrides)
