"""Configuration of a reshuffler run (TOML, validated with pydantic; SI units).

Defaults describe the paper's device (two 1024 nm chambers, 100 nm × 50 nm conduits, one
nucleation every 5 ns, material S2, 2 nm film, 300 K). Quantities the paper leaves open have
documented defaults (docs/physics.md §4) and are recorded with every result:

- ``spin_drift_coefficient`` ξ [m³/C] (v_s = ξ j): default the spin-transfer estimate
  ξ = P g μ_B/(2 e M_s) with spin polarisation P = ``spin_polarization`` (0.5) and g = 2. The
  ``paper`` preset calibrates it instead (see ``docs/paper-reproduction.md``).
- the input's correlation time (``signal.correlation_time``, default one injection interval);
- the occupied-site rule (:mod:`skygas.reshuffler.injection`);
- the conductor's thickness and resistivity for the power (:mod:`skygas.fields.current`).

``[hypothesis]`` holds knobs that are not physics (:mod:`skygas.physics.hypothesis`): a dynamics
time scale s (k → k/s: forces and thermal noise s times faster, drift from v_s unchanged) and a
noise scale n (noise temperature nT). Both default to 1; the ``paper-figures`` preset sets s.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Literal

from pydantic import Field, ValidationError

from skygas.core import units
from skygas.core.config_types import (
    CHAMBER_GAP,
    ChamberSize,
    Length,
    PositiveFloat,
    StrictModel,
    apply_overrides,
    read_toml,
    to_input_error,
)
from skygas.core.errors import require
from skygas.fields.current import (
    DEFAULT_CELL_SIZE,
    DEFAULT_CONDUCTOR_THICKNESS,
    DEFAULT_RESISTIVITY,
)
from skygas.physics.hypothesis import HypothesisSpec, noise_temperature, scale_dynamics
from skygas.physics.materials import ThieleParameters
from skygas.reshuffler.presets import preset_data
from skygas.runs.config import MaterialFields, OperationsField, resolve_paths

#: the device's name in messages about its configuration (a sweep's ``[base]`` table)
DEVICE_NAME = "reshuffler"


class DeviceSpec(ChamberSize):
    """The two chambers: the paper's chamber and conduits, ``chamber_gap`` [m] apart."""

    chamber_gap: Length = CHAMBER_GAP


class SignalConfig(StrictModel):
    """The input signal (see :mod:`skygas.sc.signals`)."""

    kind: Literal["telegraph", "bernoulli", "file"] = "telegraph"
    p: float = Field(0.5, ge=0, le=1)
    correlation_time: PositiveFloat = 5e-9
    path: str | None = None


class InjectionSpec(StrictModel):
    """Nucleation: one event every ``interval`` [s], and the rule for an occupied site.

    A site is occupied when another centre lies within ``site_clearance`` skyrmion diameters;
    ``occupied_rule`` ``"delay"`` retries every ``retry_interval`` [s] (default: ``interval``/10),
    dropping the oldest event of a queue longer than ``max_pending``; ``"skip"`` drops the event
    (:mod:`skygas.reshuffler.injection`).
    """

    interval: PositiveFloat = 5e-9
    occupied_rule: Literal["delay", "skip"] = "delay"
    site_clearance: PositiveFloat = 1.0  # skyrmion diameters
    retry_interval: PositiveFloat | None = None  # default: interval / 10
    max_pending: int = Field(1000, ge=1)


class CurrentSpec(StrictModel):
    """The current solve: its cell size, and the layer that carries the current.

    Finite-volume ``cell_size`` [m], and the ``conductor_thickness`` [m] and ``resistivity`` [Ω·m]
    of the layer. The defaults are those of :func:`~skygas.fields.current.solve_current` (the
    layer's are assumptions).
    """

    cell_size: PositiveFloat = DEFAULT_CELL_SIZE
    conductor_thickness: PositiveFloat = DEFAULT_CONDUCTOR_THICKNESS
    resistivity: PositiveFloat = DEFAULT_RESISTIVITY


class OutputSpec(StrictModel):
    """What a run records.

    Snapshots of all positions every ``snapshot_interval`` [s] (stored sparsely), dense frames over
    the first ``trajectory_window`` [s] for the device figure, ``running_points`` points of the
    running correlation, and the lag scan of ρ over −``max_lag`` … ``max_lag`` events.
    """

    snapshot_interval: PositiveFloat = 100e-9  # positions of all skyrmions, stored sparsely
    trajectory_window: float = Field(300e-9, ge=0)  # dense 1 ns frames for the figure
    running_points: int = Field(200, ge=2)
    max_lag: int = Field(50, ge=1)  # events; the lag scan of ρ covers −max_lag … max_lag


class ReshufflerConfig(MaterialFields, OperationsField):
    """Everything that defines a reshuffler run."""

    seed: int = Field(0, ge=0, lt=2**63)
    temperature: float = Field(300.0, ge=0)
    current_density: PositiveFloat = 1.7e11  # J in the conduits [A/m²]
    duration: PositiveFloat = 20e-6  # simulated time [s]
    time_step: PositiveFloat | None = None  # default: 0.1 τ_min
    spin_drift_coefficient: PositiveFloat | None = None  # ξ [m³/C]
    spin_polarization: float = Field(0.5, gt=0, le=1)
    device: DeviceSpec = DeviceSpec()
    signal: SignalConfig = SignalConfig()
    injection: InjectionSpec = InjectionSpec()
    current: CurrentSpec = CurrentSpec()
    output: OutputSpec = OutputSpec()
    hypothesis: HypothesisSpec = HypothesisSpec()

    def thiele_parameters(self) -> ThieleParameters:
        """The material's Thiele coefficients with the overrides, then the dynamics time scale.

        The time scale is ``hypothesis.dynamics_time_scale``
        (:func:`skygas.physics.hypothesis.scale_dynamics`).
        """
        return scale_dynamics(super().thiele_parameters(), self.hypothesis.dynamics_time_scale)

    def noise_temperature(self) -> float:
        """The temperature [K] given to the thermal noise.

        ``temperature`` × ``hypothesis.noise_scale``; the engine uses the temperature for nothing
        else.
        """
        return noise_temperature(self.temperature, self.hypothesis.noise_scale)

    def drift_coefficient(self) -> float:
        """ξ [m³/C]: the configured value or the spin-transfer estimate P g μ_B/(2 e M_s)."""
        if self.spin_drift_coefficient is not None:
            return self.spin_drift_coefficient
        m_s = self.resolved_material().saturation_magnetization
        return (
            self.spin_polarization
            * 2.0
            * units.BOHR_MAGNETON
            / (2.0 * units.ELEMENTARY_CHARGE * m_s)
        )


def parse_reshuffler_config(
    data: dict, source: str = "", overrides: dict[str, Any] | None = None
) -> ReshufflerConfig:
    """Validate a mapping (with optional dotted-key overrides) into a config."""
    data = apply_overrides(data, overrides or {})
    preset = data.pop("preset", None)
    if preset is not None:
        data = apply_overrides(preset_data(preset), _flatten(data))
    try:
        return ReshufflerConfig(**data)
    except ValidationError as err:
        raise to_input_error(err, source) from None


def _flatten(data: dict, prefix: str = "") -> dict:
    out = {}
    for key, value in data.items():
        if isinstance(value, dict) and key not in ("material",):
            out.update(_flatten(value, f"{prefix}{key}."))
        else:
            out[f"{prefix}{key}"] = value
    return out


def load_reshuffler_config(
    path: str | Path | None = None,
    *,
    preset: str | None = None,
    overrides: dict[str, Any] | None = None,
) -> ReshufflerConfig:
    """A config from a TOML file, or from a preset when no file is given, then overrides."""
    if path is None:
        data = {"preset": preset or "default"}
        source = f"preset {preset or 'default'}: "
    else:
        path = Path(path)
        data = resolve_paths(read_toml(path), path.parent)
        if preset is not None:
            data["preset"] = preset
        source = f"{path.name}: "
    return parse_reshuffler_config(data, source, overrides)


def check_time_step(config: ReshufflerConfig) -> None:
    """Refuse a ``time_step`` that does not divide the injection interval a whole number of times.

    Nucleations happen on steps; ``time_step = None`` (the suggested step, shortened to divide
    the interval) always passes.
    """
    interval, time_step = config.injection.interval, config.time_step
    if time_step is not None:
        per_interval = interval / time_step
        require(
            abs(per_interval - round(per_interval)) < 1e-6 * per_interval,
            "time_step",
            time_step,
            f"a step that divides the injection interval ({interval:g} s) a "
            f"whole number of times, e.g. {interval / math.ceil(per_interval):.6g} s",
        )
