"""Inputs of the neuron: spike trains that drive injectors at the input conduit.

Each input is a train of events (times); every event asks for one nucleation with probability
``weight`` (the synaptic weight as an injection probability; several inputs = several
injectors sharing the input conduit's nucleation site). Kinds:

- ``"poisson"``: Poisson spike train of ``rate`` [Hz].
- ``"telegraph"`` / ``"bernoulli"``: a clock of period ``interval`` [s]; an event at every tick
  where the bit (:func:`skygas.sc.signals.generate_bits`, P(1) = ``p``) is 1. Rate p/interval.
- ``"regular"``: a clock of period 1/``rate`` (one event per tick).
- ``"bits"``: an explicit bitstream ``bits`` sampled at ``interval`` (a stochastic-computing
  stream from :mod:`skygas.sc.bitstreams`, for example).

An event finding the site occupied (another centre closer than ``site_clearance`` diameters)
waits in a queue and is retried every ``retry_interval``, as the reshuffler's ``"delay"`` rule
(:mod:`skygas.reshuffler.injection`), or is dropped (``"skip"``).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field
from typing import ClassVar, cast

import numpy as np

from skygas.core.errors import InputError, require
from skygas.sc.signals import SignalKind, SignalSpec, generate_bits

KINDS = ("poisson", "telegraph", "bernoulli", "regular", "bits")


@dataclass(frozen=True)
class InputSpec:
    """One input; see the module docstring. Rates in Hz, times in s."""

    kind: str = "poisson"
    rate: float = 0.0
    p: float = 0.5
    interval: float = 5e-9
    correlation_time: float = 5e-9
    weight: float = 1.0
    bits: tuple = ()

    def __post_init__(self):
        require(self.kind in KINDS, "inputs.kind", self.kind, f"one of {list(KINDS)}")
        require(
            math.isfinite(self.rate) and self.rate >= 0,
            "inputs.rate",
            self.rate,
            "a rate >= 0 in Hz",
        )
        require(
            0 <= self.weight <= 1,
            "inputs.weight",
            self.weight,
            "an injection probability in [0, 1]",
        )
        require(
            math.isfinite(self.interval) and self.interval > 0,
            "inputs.interval",
            self.interval,
            "an interval > 0 in seconds",
        )
        require(0 <= self.p <= 1, "inputs.p", self.p, "a probability in [0, 1]")

    def mean_rate(self) -> float:
        """Expected events per second before the weight."""
        if self.kind in ("poisson", "regular"):
            return self.rate
        if self.kind == "bits":
            return float(np.mean(self.bits)) / self.interval if len(self.bits) else 0.0
        return self.p / self.interval

    def event_times(self, duration: float, rng: np.random.Generator) -> np.ndarray:
        """Event times [s] in [0, duration) (weight not applied)."""
        from skygas.core.resources import require_memory

        # the times, their sort and the draws: about three float64 arrays of the expected count
        expected = (
            self.mean_rate() * duration
            if self.kind in ("poisson", "regular")
            else duration / self.interval
        )
        require_memory(
            "inputs.rate" if self.kind in ("poisson", "regular") else "inputs.interval",
            self.rate if self.kind in ("poisson", "regular") else self.interval,
            24.0 * expected,
            f"{expected:.3g} input events",
            "use a lower rate or a shorter duration",
        )
        if self.kind == "poisson":
            n = rng.poisson(self.rate * duration)
            return np.sort(rng.uniform(0, duration, n))
        if self.kind == "regular":
            return np.arange(0, duration, 1 / self.rate) if self.rate > 0 else np.empty(0)
        n = int(duration / self.interval)
        if self.kind == "bits":
            bits = np.asarray(self.bits, bool)[:n]
        else:
            if self.kind == "telegraph" and not 0 < self.p < 1:
                raise InputError("inputs.p", self.p, "p strictly in (0, 1) for a telegraph input")
            # here kind is "telegraph" or "bernoulli", both signal kinds
            spec = SignalSpec(cast(SignalKind, self.kind), self.p, self.correlation_time)
            bits = generate_bits(spec, max(n, 1), self.interval, seed=int(rng.integers(2**63)))[:n]
        return np.flatnonzero(bits) * self.interval


def injection_schedule(inputs, duration: float, time_step: float, seed: int) -> np.ndarray:
    """Steps of all injection attempts (after the weights), sorted; from a seeded stream."""
    rngs = [
        np.random.default_rng(s)
        for s in np.random.SeedSequence((seed, 0x696E70)).spawn(len(inputs))
    ]
    from skygas.core.resources import require_memory

    # all inputs together (each is checked alone too): times, draws and steps of every event
    expected = sum(
        s.mean_rate() * duration if s.kind in ("poisson", "regular") else duration / s.interval
        for s in inputs
    )
    require_memory(  # one input alone is checked (naming its field) in event_times
        "duration",
        duration,
        24.0 * expected if len(inputs) > 1 else 0.0,
        f"the injection schedule of {expected:.3g} input events",
        "use lower input rates or a shorter duration",
    )
    steps = []
    for spec, rng in zip(inputs, rngs, strict=True):
        t = spec.event_times(duration, rng)
        keep = rng.random(len(t)) < spec.weight
        steps.append(np.round(t[keep] / time_step).astype(np.int64))
    return np.sort(np.concatenate(steps)) if steps else np.empty(0, np.int64)


@dataclass
class SiteInjector:
    """An :class:`~skygas.engine.Operation`: nucleates at ``site`` [nm] at the given steps."""

    #: its name among a run's operations: the simulation checkpoints it under this name
    name: ClassVar[str] = "injector"

    steps: np.ndarray
    site: np.ndarray
    clearance_nm: float
    retry_steps: int
    rule: str = "delay"
    injected: list = field(default_factory=list)  # (step, id)
    skipped: int = 0
    delayed: int = 0
    pending: deque = field(default_factory=deque)
    _k: int = 0

    def next_step(self, step: int) -> int:
        """The next scheduled event's step, or the next retry's if sooner while events wait."""
        tick = int(self.steps[self._k]) if self._k < len(self.steps) else np.iinfo(np.int64).max
        if self.pending:
            return min(tick, (step // self.retry_steps + 1) * self.retry_steps)
        return tick

    def act(self, sim) -> None:
        """Inject the events now due on a clear site, else delay or skip them; retry the waiting."""
        while self._k < len(self.steps) and self.steps[self._k] <= sim.step:
            if self.pending or not self._clear(sim):
                if self.rule == "skip":
                    self.skipped += 1
                else:
                    self.delayed += 1
                    self.pending.append(self._k)
            else:
                self._inject(sim)
            self._k += 1
        while self.pending and self._clear(sim):
            self.pending.popleft()
            self._inject(sim)

    def _clear(self, sim) -> bool:
        return sim.state.is_site_clear_nm(self.site[0], self.site[1], self.clearance_nm)

    def _inject(self, sim) -> None:
        ident = int(sim.state.insert_nm(self.site[None, :])[0])
        self.injected.append((sim.step, ident))

    @property
    def n_injected(self) -> int:
        """Skyrmions injected so far."""
        return len(self.injected)

    def state_dict(self) -> dict:
        """Its position in the schedule and its logs, as JSON-able values.

        The schedule itself is rebuilt from the seed.
        """
        return {
            "injected": [[int(s), int(i)] for s, i in self.injected],
            "skipped": int(self.skipped),
            "delayed": int(self.delayed),
            "pending": [int(k) for k in self.pending],
            "k": int(self._k),
        }

    def load_state_dict(self, state: dict) -> None:
        """Restore the state :meth:`state_dict` saved."""
        self.injected = [tuple(e) for e in state["injected"]]
        self.skipped, self.delayed = state["skipped"], state["delayed"]
        self.pending = deque(state["pending"])
        self._k = state["k"]
