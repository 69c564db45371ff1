"""Operations: what acts on a simulation, and when (HOOMD's trigger + action, with look-ahead).

An :class:`Operation` says at which step it next wants to act (``next_step``) and what it
does then (``act``, through ``sim.state``). The run loop (:meth:`Simulation.run`) asks every
operation for its next step, lets the compiled kernel run up to the earliest one, and calls the
operations that are due. An operation that only inserts skyrmions on a known schedule can also
hand those insertions to the kernel (:class:`PlannedInsertions`), which then runs through them
without returning to Python.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import TYPE_CHECKING, Protocol

import numpy as np

from skygas.core.errors import require
from skygas.engine.terms import PlannedInsertions as InsertionPlan

if TYPE_CHECKING:
    from skygas.engine.simulation import Simulation

#: what an operation's name may hold (it becomes part of checkpoint keys)
OPERATION_NAME = re.compile(r"[A-Za-z0-9_-]+")


class Operation(Protocol):
    """Something that acts on a simulation on a schedule (injectors, gates, writers).

    ``next_step(step)`` returns the step count at which the operation next wants to act: the
    engine stops there and calls ``act(sim)`` (a value ≤ ``step`` means "now", before any
    further stepping). An operation can change its schedule from one call to the next (an
    injector retrying an occupied site, a gate opening). It reads and changes skyrmions
    through ``sim.state`` (:class:`~skygas.engine.state.StateView`).
    """

    def next_step(self, step: int) -> int:
        """The step at which the operation next wants to act (≤ ``step``: now)."""
        ...

    def act(self, sim: Simulation) -> None:
        """Act on ``sim``, through ``sim.state``."""
        ...


class NamedOperation(Operation, Protocol):
    """An :class:`Operation` with a ``name``, checkpointed, summarised and saved by name.

    The name holds letters, digits, ``-`` and ``_``, and is unique among a simulation's
    operations. Three optional methods make it a full part of a run:

    - ``state_dict()`` / ``load_state_dict(state)``: :meth:`Simulation.state_dict
      <skygas.engine.Simulation.state_dict>` saves and restores its state under its name
      (arrays, or JSON-able values);
    - ``summary()``: JSON-able numbers, which the devices put in their summaries under
      ``"operations"``;
    - ``data()``: ``{variable: (dims, array)}``, written into the run's result file
      (:meth:`Simulation.operation_data <skygas.engine.Simulation.operation_data>`).

    An operation without them is neither saved, summarised nor written.
    """

    name: str


def named_operations(operations) -> dict[str, Operation]:
    """The operations that have a ``name``, by name (refusing a repeated or malformed name)."""
    named: dict[str, Operation] = {}
    for op in operations:
        name = getattr(op, "name", None)
        if name is None:
            continue
        require(
            isinstance(name, str) and bool(OPERATION_NAME.fullmatch(name)),
            "operation name",
            name,
            "letters, digits, '-' and '_'",
        )
        require(name not in named, "operation name", name, "a name no other operation has")
        named[name] = op
    return named


class PlannedInsertions(Protocol):
    """An :class:`Operation` that can also hand its insertions to the compiled kernel.

    ``plan_insertions(step, limit)`` returns the insertions it would make at steps in
    (``step``, ``limit``), as ``(steps, positions_nm (k, 2), clearance_nm)``, each to be made at
    the start of its step if no skyrmion lies closer than the clearance to its position, or
    ``None`` when it needs Python for its next decisions (then it acts through ``act`` as
    usual). The kernel makes them in order and stops before the first one it cannot make (site
    occupied, or no free slot); ``planned_insertions_made(sim, ids)`` then reports the ids of
    those made, and the operation's ``next_step`` takes over from there. This saves a return to
    Python for every insertion (the reshuffler nucleates every 20 steps).
    """

    def plan_insertions(self, step: int, limit: int):
        """The insertions at steps in (``step``, ``limit``), or ``None``."""
        ...

    def planned_insertions_made(self, sim: Simulation, ids: np.ndarray) -> None:
        """Take note of the ids of the planned insertions the kernel made."""
        ...


class Periodic:
    """Call ``action(sim)`` every ``period_steps`` steps (a convenience :class:`Operation`)."""

    def __init__(self, period_steps: int, action: Callable[[Simulation], None]):
        require(period_steps >= 1, "period_steps", period_steps, "an integer >= 1")
        self.period_steps = int(period_steps)
        self.action = action

    def next_step(self, step: int) -> int:
        """The next multiple of ``period_steps`` after ``step``."""
        return (step // self.period_steps + 1) * self.period_steps

    def act(self, sim: Simulation) -> None:
        """Call the action."""
        self.action(sim)


#: An empty plan, for kernel calls without planned insertions.
NO_PLAN = InsertionPlan(np.empty(0, np.int64), np.empty(0), np.empty(0), np.empty(0, np.int64), 0.0)


def first_plan(operations, due: list[int], step: int, horizon: int):
    """The first operation able to plan its insertions up to the next stop.

    And its plan (:class:`~skygas.engine.terms.PlannedInsertions`); ``due`` is updated so that
    the planner's own schedule does not stop the kernel. (None, None) if there is none.
    """
    for k, op in enumerate(operations):
        if due[k] <= step or not hasattr(op, "plan_insertions"):
            continue
        limit = min([horizon, *(d for j, d in enumerate(due) if j != k)])
        if limit <= step:
            return None, None
        planned = op.plan_insertions(step, limit)
        if planned is None:
            continue
        steps, pos, clearance = planned
        due[k] = limit
        plan = InsertionPlan(
            np.asarray(steps, np.int64),
            np.ascontiguousarray(pos[:, 0], float),
            np.ascontiguousarray(pos[:, 1], float),
            np.empty(len(steps), np.int64),
            float(clearance) ** 2,
        )
        return k, plan
    return None, None
