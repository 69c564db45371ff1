"""Nucleation on a clock, steered by an input signal, with a rule for an occupied site.

Every ``injection_interval`` (event k at t_k = k·Δ) the input bit b_k chooses the chamber: UP
for 1, DOWN for 0 (paper, "Skyrmion Reshuffler"). A skyrmion is nucleated at that chamber's site
unless the site is **occupied**: another skyrmion's centre lies closer than
``site_clearance`` skyrmion diameters (a new skyrmion cannot be written on top of another).

Occupied-site rules (``occupied_rule``):

- ``"delay"`` (default): the nucleation waits in a first-in-first-out queue of its chamber and
  is retried every ``retry_interval`` until the site is clear. No bit is lost, so the p-value
  carried by the skyrmions is the input's exactly; only the timing shifts. Each delayed event
  and the total delay are counted. A queue longer than ``max_pending`` drops its oldest event
  (counted as skipped): a chamber that cannot take skyrmions as fast as they come is saturated,
  and the summary says so.
- ``"skip"``: the nucleation is dropped and counted. The p-value can then be biased (a busier
  chamber loses more bits); the summary reports p of the input and of the injected bits, so
  the bias is visible, never silent.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from skygas.reshuffler.device import CHAMBERS


@dataclass
class InjectionLog:
    """What happened to each input event (arrays indexed by event number k)."""

    bit: np.ndarray  # input bit b_k
    skyrmion: np.ndarray  # id of the nucleated skyrmion, −1 if none (yet)
    injection_step: np.ndarray  # step of the nucleation, −1 if none
    delayed: np.ndarray  # True if the site was occupied at t_k
    skipped: np.ndarray  # True if the event was dropped

    @classmethod
    def for_bits(cls, bits: np.ndarray) -> InjectionLog:
        """A log of the events ``bits``, none of them injected, delayed or skipped yet."""
        n = len(bits)
        return cls(
            np.asarray(bits, dtype=bool),
            np.full(n, -1, np.int64),
            np.full(n, -1, np.int64),
            np.zeros(n, bool),
            np.zeros(n, bool),
        )


@dataclass
class Injector:
    """An :class:`~skygas.engine.Operation` that nucleates skyrmions from an input signal.

    Steps are the engine's; ``sites`` are nucleation points in nm per chamber name.
    """

    #: its name among a run's operations: the simulation checkpoints it under this name
    name: ClassVar[str] = "injector"

    bits: np.ndarray
    interval_steps: int
    retry_steps: int
    sites: dict[str, np.ndarray]
    clearance_nm: float
    rule: str = "delay"
    max_pending: int = 1000
    log: InjectionLog = field(init=False)
    next_event: int = 0
    pending: dict[str, deque] = field(init=False)

    def __post_init__(self):
        self.log = InjectionLog.for_bits(self.bits)
        self.pending = {name: deque() for name in CHAMBERS}

    # -- schedule -----------------------------------------------------------------------------
    def next_step(self, step: int) -> int:
        """The next clock tick (possibly now), or sooner the next retry of a waiting event."""
        tick = self.next_event * self.interval_steps
        if self.next_event >= len(self.bits):
            tick = np.iinfo(np.int64).max
        if any(self.pending.values()):
            return min(tick, (step // self.retry_steps + 1) * self.retry_steps)
        return tick

    def act(self, sim) -> None:
        """Nucleate the events now due, or queue or drop them by the rule; retry the queued ones."""
        while (
            self.next_event < len(self.bits) and self.next_event * self.interval_steps <= sim.step
        ):
            k = self.next_event
            chamber = CHAMBERS[0] if self.bits[k] else CHAMBERS[1]
            queue = self.pending[chamber]
            if queue or not self._site_clear(sim, chamber):
                if self.rule == "skip":
                    self.log.skipped[k] = True
                else:
                    self.log.delayed[k] = True
                    queue.append(k)
                    if len(queue) > self.max_pending:
                        self.log.skipped[queue.popleft()] = True
            else:
                self._nucleate(sim, chamber, k)
            self.next_event += 1
        for chamber, queue in self.pending.items():
            while queue and self._site_clear(sim, chamber):
                self._nucleate(sim, chamber, queue.popleft())

    # -- the same, made by the compiled kernel (see skygas.engine.PlannedInsertions) ---------
    def plan_insertions(self, step: int, limit: int):
        """The nucleations due at steps in (step, limit), for the kernel to make on clear sites.

        None while a queue is waiting (retries need the rules above).
        """
        if any(self.pending.values()):
            return None
        first = self.next_event
        last = min(len(self.bits), -(-limit // self.interval_steps))  # ticks < limit
        ticks = np.arange(first, max(first, last), dtype=np.int64) * self.interval_steps
        keep = ticks > step
        events = np.arange(first, max(first, last))[keep]
        up, down = self.sites[CHAMBERS[0]], self.sites[CHAMBERS[1]]
        positions = np.where(self.bits[events, None], up, down)
        self._planned = events
        return ticks[keep], positions, self.clearance_nm

    def planned_insertions_made(self, sim, ids: np.ndarray) -> None:
        """Log the planned nucleations the kernel made (in order, from the first)."""
        events = self._planned[: len(ids)]
        self.log.skyrmion[events] = ids
        self.log.injection_step[events] = events * self.interval_steps
        if len(events):
            self.next_event = int(events[-1]) + 1

    # -- helpers ------------------------------------------------------------------------------
    def _site_clear(self, sim, chamber: str) -> bool:
        # the test the kernel applies to the nucleations planned into it
        site = self.sites[chamber]
        return sim.state.is_site_clear_nm(site[0], site[1], self.clearance_nm)

    def _nucleate(self, sim, chamber: str, k: int) -> None:
        ident = sim.state.insert_nm(self.sites[chamber][None, :])[0]
        self.log.skyrmion[k] = ident
        self.log.injection_step[k] = sim.step

    # -- accounting -----------------------------------------------------------------------------
    @property
    def n_injected(self) -> int:
        """Events nucleated so far."""
        return int(np.count_nonzero(self.log.skyrmion >= 0))

    @property
    def n_skipped(self) -> int:
        """Events dropped so far (by ``"skip"``, or from a full queue)."""
        return int(np.count_nonzero(self.log.skipped))

    @property
    def n_delayed(self) -> int:
        """Events that found their site occupied."""
        return int(np.count_nonzero(self.log.delayed))

    @property
    def n_pending(self) -> int:
        """Events waiting in the chambers' queues."""
        return sum(len(q) for q in self.pending.values())

    def state_dict(self) -> dict:
        """Everything needed to resume (arrays and the queues)."""
        return {
            "log_skyrmion": self.log.skyrmion.copy(),
            "log_injection_step": self.log.injection_step.copy(),
            "log_delayed": self.log.delayed.copy(),
            "log_skipped": self.log.skipped.copy(),
            "next_event": np.array(self.next_event),
            **{f"pending_{c}": np.array(list(q), dtype=np.int64) for c, q in self.pending.items()},
        }

    def load_state_dict(self, state: dict) -> None:
        """Restore the log, the schedule and the queues that :meth:`state_dict` saved."""
        self.log.skyrmion = state["log_skyrmion"].copy()
        self.log.injection_step = state["log_injection_step"].copy()
        self.log.delayed = state["log_delayed"].copy()
        self.log.skipped = state["log_skipped"].copy()
        self.next_event = int(state["next_event"])
        self.pending = {c: deque(int(k) for k in state[f"pending_{c}"]) for c in CHAMBERS}
