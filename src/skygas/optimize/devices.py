"""The devices a study can optimise: how a trial's configuration is built and what it measures.

Each device names its configuration model, the summary quantities a run of it returns (what
objectives and constraints may use, checked before anything runs) and how the base
configuration and a trial's parameters make one run's validated configuration:

- ``reshuffler``: a :class:`~skygas.reshuffler.config.ReshufflerConfig`, built and checked as a
  sweep's point (:func:`skygas.sweep.spec.point_config`); its quantities are the sweep's
  (:data:`skygas.sweep.worker.QUANTITIES`) and ``throughput_Hz``, the read-outs per second
  (``n_detected / simulated_time_s``);
- ``neuron``: a :class:`~skygas.neuron.config.NeuronConfig`; :data:`NEURON_QUANTITIES`;
- ``reservoir``: a :class:`~skygas.reservoir.config.ReservoirConfig` whose Boolean study (no
  temporal tasks) runs as one stream in the trial's process (``study.workers = 1``: the study's
  workers are the trials); :data:`RESERVOIR_QUANTITIES`;
- ``analytic``: :mod:`skygas.optimize.analytic`, a known function for checking a study.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from pydantic import BaseModel

from skygas.core.errors import InputError, require
from skygas.core.estimates import Estimate
from skygas.optimize.analytic import QUANTITIES as ANALYTIC_QUANTITIES
from skygas.sweep.worker import QUANTITIES as SWEEP_QUANTITIES

#: The reshuffler's summary quantities in a study: a sweep's and the read-out rate.
RESHUFFLER_QUANTITIES = (*SWEEP_QUANTITIES, "throughput_Hz")
#: The neuron's summary quantities (``isi_*``: inter-spike intervals; NaN with fewer than 2).
NEURON_QUANTITIES = (
    "firing_rate_Hz",
    "n_output_spikes",
    "input_rate_Hz",
    "injection_rate_Hz",
    "leak_time_s",
    "max_count",
    "final_count",
    "n_injected",
    "n_annihilated",
    "n_emitted",
    "isi_mean_s",
    "isi_std_s",
    "isi_cv",
    "simulated_time_s",
    "wall_time_s",
)
#: The reservoir's summary quantities: the XOR read-out's and the mean of the 16 Boolean
#: functions' test accuracies, and the drive's energy per held input [J].
RESERVOIR_QUANTITIES = ("xor_accuracy", "mean_accuracy", "energy_per_operation_J", "wall_time_s")


@dataclass(frozen=True)
class Device:
    """One device a study can optimise (see the module docstring)."""

    name: str
    quantities: tuple[str, ...]
    model: Callable[[], type[BaseModel]]
    build: Callable[[dict, dict[str, Any], str], BaseModel]
    default_base: dict
    #: the estimate of one run of a built configuration, priced as the device prices it
    estimate: Callable[[Any], Estimate]
    #: seeds are taken modulo this (the reservoir derives its streams' seeds as 1000·seed + k)
    seed_limit: int = 2**63

    def field_exists(self, dotted: str) -> bool:
        """Whether ``dotted`` is a field of the device's configuration."""
        from skygas.sweep.spec import field_exists

        return field_exists(self.model(), dotted)


def _named(what: str, overrides: dict[str, Any], build: Callable[[], BaseModel]) -> BaseModel:
    try:
        return build()
    except InputError as err:
        label = ", ".join(f"{f} = {v!r}" for f, v in overrides.items())
        raise InputError(f"{what} ({label}): {err.field}", err.value, err.allowed) from None


def _reshuffler_model() -> type[BaseModel]:
    from skygas.reshuffler.config import ReshufflerConfig

    return ReshufflerConfig


def _reshuffler(base: dict, overrides: dict[str, Any], what: str) -> BaseModel:
    from skygas.sweep.spec import point_config

    return point_config(base, overrides, what)


def _neuron_model() -> type[BaseModel]:
    from skygas.neuron.config import NeuronConfig

    return NeuronConfig


def _neuron(base: dict, overrides: dict[str, Any], what: str) -> BaseModel:
    from skygas.neuron.config import neuron_config

    return _named(what, overrides, lambda: neuron_config(dict(base), **overrides))


def _reservoir_model() -> type[BaseModel]:
    from skygas.reservoir.config import ReservoirConfig

    return ReservoirConfig


def _reservoir(base: dict, overrides: dict[str, Any], what: str) -> BaseModel:
    from skygas.reservoir.config import reservoir_config

    one_stream = {**overrides, "study.workers": 1}
    return _named(what, overrides, lambda: reservoir_config(dict(base), **one_stream))


def _analytic_model() -> type[BaseModel]:
    from skygas.optimize.analytic import AnalyticConfig

    return AnalyticConfig


def _analytic(base: dict, overrides: dict[str, Any], what: str) -> BaseModel:
    from pydantic import ValidationError

    from skygas.core.config_types import apply_overrides, to_input_error
    from skygas.optimize.analytic import AnalyticConfig

    def build() -> BaseModel:
        try:
            return AnalyticConfig(**apply_overrides(base, overrides))
        except ValidationError as err:
            raise to_input_error(err, "") from None

    return _named(what, overrides, build)


# -- one run's estimate, before anything is built (skygas.core.estimates) ---------------------
def _reshuffler_estimate(config) -> Estimate:
    """As a sweep prices its runs: its steps at least its injection events."""
    from skygas.reshuffler.run import STEP_COST_FACTOR, expected_population, reshuffler_memory
    from skygas.runs.machine_speed import run_estimate

    events = config.duration / config.injection.interval
    population = expected_population(config)
    memory = sum(reshuffler_memory(config, events, population).values())
    return run_estimate(events, STEP_COST_FACTOR * population, memory)


#: The step [s] a neuron run is priced at when its configuration leaves the step to the engine
#: (``time_step = None``; the configuration's default).
NEURON_TIME_STEP = 2.5e-10


def _neuron_estimate(config) -> Estimate:
    """As the neuron prices its run.

    Its steps with at most ``rule.threshold`` skyrmions, the turns of its controller (every
    sensor read) and annihilator (every check), and its build.
    """
    from skygas.runs.machine_speed import run_estimate

    skyrmions = max(1.0, float(config.rule.threshold))
    dt = config.time_step or NEURON_TIME_STEP
    steps = config.duration / dt
    model = config.annihilation_model()
    turns = steps / max(1.0, round(config.sensor.read_interval / dt))
    if model.enabled:
        turns += steps / max(1.0, round(model.check_interval / dt))
    # a study records no frames
    return run_estimate(steps, skyrmions, 24.0 * skyrmions, turns=turns, builds=1)


def _reservoir_estimate(config) -> Estimate:
    """As the reservoir prices its study's Boolean streams (one step per held input at least)."""
    from skygas.runs.machine_speed import optimistic_estimate, run_estimate

    st = config.study
    inputs = st.n_inputs + st.warmup_inputs
    frames = config.hold_time / config.sensors.sample_interval
    skyrmions = max(1, config.n_skyrmions)
    memory = 8.0 * len(config.drive.input_contacts) * inputs + 24.0 * (frames + 1) * skyrmions
    if config.time_step is None:  # the engine's step is known once the device is built
        return optimistic_estimate(inputs, skyrmions, memory)
    return run_estimate(inputs * config.hold_time / config.time_step, skyrmions, memory)


def _analytic_estimate(config) -> Estimate:
    """A known function: its ``delay`` [s] and nothing else."""
    return Estimate(steps=1.0, memory=0.0, seconds=float(config.delay))


#: The devices by name.
DEVICES: dict[str, Device] = {
    "reshuffler": Device(
        "reshuffler",
        RESHUFFLER_QUANTITIES,
        _reshuffler_model,
        _reshuffler,
        {"preset": "default"},
        _reshuffler_estimate,
    ),
    "neuron": Device("neuron", NEURON_QUANTITIES, _neuron_model, _neuron, {}, _neuron_estimate),
    "reservoir": Device(
        "reservoir",
        RESERVOIR_QUANTITIES,
        _reservoir_model,
        _reservoir,
        {},
        _reservoir_estimate,
        seed_limit=(2**63 - 1) // 1000 - 1000,
    ),
    "analytic": Device(
        "analytic", ANALYTIC_QUANTITIES, _analytic_model, _analytic, {}, _analytic_estimate
    ),
}


def device(name: object) -> Device:
    """The device called ``name`` (one of :data:`DEVICES`), refused in one line otherwise."""
    require(name in DEVICES, "study.device", name, f"one of {', '.join(DEVICES)}")
    assert isinstance(name, str)  # one of the names
    return DEVICES[name]
