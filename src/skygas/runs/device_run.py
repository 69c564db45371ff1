"""The one skeleton of a device run: a :class:`~skygas.engine.Simulation` driven piece by piece.

Every device run (``simulate``'s, the reshuffler's, the neuron's, each stream of a reservoir
study) is a :class:`DeviceRun`.
A device declares three things and inherits the rest:

- how it builds its :class:`~skygas.engine.Simulation` (its outline, fields, landscape and
  its own operations), in its constructor or a ``build`` class method;
- how long it runs, :attr:`DeviceRun.total_steps`, and, if a piece must do more than
  ``sim.run``, :meth:`DeviceRun.run_steps` (the reshuffler keeps sparse snapshots there);
- what it reports, :meth:`DeviceRun.summary` (on top of :meth:`DeviceRun.base_summary`) and
  its result file.

The skeleton owns the rest:

- pieces: :meth:`DeviceRun.advance_piece` runs to the next multiple of
  :attr:`DeviceRun.piece_steps`, whatever run (first or resumed) gets there, so a resumed run
  re-enters the compiled kernel at the same steps as one never stopped
  (:func:`~skygas.runs.run_driver.steps_to_piece_end`);
- checkpoints: :meth:`DeviceRun.state_dict` is the simulation's state, which holds every
  *named* operation's own state (the device's and the user's), plus what the run keeps
  outside the simulation (:meth:`DeviceRun.extra_state`) and its wall time;
- the configuration's ``[[operations]]`` (:mod:`skygas.runs.operations`), attached by
  :meth:`DeviceRun.attach_operations`, and every named operation's ``summary()`` in the
  summary and ``data()`` in the result file.

:class:`~skygas.runs.run_driver.PiecewiseRunJob` turns a :class:`DeviceRun` into a job of the
run driver (progress, periodic checkpoints, Ctrl-C, ``--resume``).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from skygas._version import __version__
from skygas.core.state_keys import nest, unnest
from skygas.runs.run_driver import steps_to_piece_end

if TYPE_CHECKING:
    import xarray as xr

    from skygas.engine import Simulation


class DeviceRun:
    """A device's simulation in progress, cut into pieces of equal length.

    Parameters
    ----------
    config
        The validated configuration of the run (a pydantic model with a ``seed``).
    sim
        The built :class:`~skygas.engine.Simulation`, with the device's own operations added.

    Attributes
    ----------
    pieces : int
        How many pieces a whole run is cut into (each returns to Python once: progress,
        checkpoints, interruption).
    min_piece_steps : int
        The shortest piece [steps]: each return to Python costs about 0.5 ms.
    record_interval : float or None
        Time [s] between the frames :meth:`run_steps` records (``None``: none).
    wall_time : float
        Wall time [s] spent stepping, carried through checkpoints.
    """

    pieces: int = 100
    min_piece_steps: int = 1
    record_interval: float | None = None

    def __init__(self, config: Any, sim: Simulation):
        self.config = config
        self.sim = sim
        self.wall_time = 0.0

    # -- what a device declares -------------------------------------------------------------
    @property
    def total_steps(self) -> int:
        """Steps of the whole run (a device defines it)."""
        raise NotImplementedError

    def run_steps(self, n: int) -> None:
        """Advance the simulation by ``n`` steps (one piece).

        Recording frames every :attr:`record_interval`; a device that does more per piece
        overrides it.
        """
        dt = self.sim.time_step
        interval = self.record_interval
        if interval is not None:  # the whole number of steps nearest to it (a movie's frames)
            interval = max(1, round(interval / dt)) * dt
        self.sim.run(n * dt, record_interval=interval)

    def extra_state(self) -> dict[str, np.ndarray]:
        """What the run keeps outside the simulation and its named operations, as arrays."""
        return {}

    def load_extra_state(self, state: dict[str, np.ndarray]) -> None:
        """Restore what :meth:`extra_state` saved."""

    # -- pieces -------------------------------------------------------------------------------
    @property
    def piece_steps(self) -> int:
        """Length [steps] of a piece.

        The run cut into :attr:`pieces`, at least :attr:`min_piece_steps`.
        """
        return max(self.min_piece_steps, self.total_steps // self.pieces)

    def advance_piece(self, end: int | None = None) -> None:
        """Run to the next multiple of :attr:`piece_steps`.

        Or to ``end`` [steps] (default :attr:`total_steps`) if that comes first.
        """
        end = self.total_steps if end is None else min(end, self.total_steps)
        if self.sim.step >= end:
            return
        started = time.perf_counter()
        self.run_steps(steps_to_piece_end(self.sim.step, self.piece_steps, end))
        self.wall_time += time.perf_counter() - started

    def advance(self, pieces: int | None = None, stop_after_step: int | None = None) -> None:
        """Run to the end (or to ``stop_after_step``), piece by piece.

        Parameters
        ----------
        pieces
            Cut the run into this many pieces (sets :attr:`pieces`; a run resumed from a
            checkpoint must use the same number to continue bit-identically).
        stop_after_step
            Stop at this step [steps] instead of :attr:`total_steps`.
        """
        if pieces is not None:
            self.pieces = int(pieces)
        end = (
            self.total_steps if stop_after_step is None else min(stop_after_step, self.total_steps)
        )
        while self.sim.step < end:
            self.advance_piece(end)

    # -- checkpoints --------------------------------------------------------------------------
    def state_dict(self) -> dict[str, np.ndarray]:
        """The whole mutable state.

        The simulation's (its named operations' included), the run's own
        (:meth:`extra_state`) and the wall time spent so far.
        """
        state = nest("sim_", self.sim.state_dict())
        state.update(self.extra_state())
        state["wall_time"] = np.array(self.wall_time)
        return state

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        """Restore a state saved by :meth:`state_dict`; the run then continues bit-identically."""
        self.sim.load_state_dict(unnest("sim_", state))
        self.load_extra_state(state)
        self.wall_time = float(state["wall_time"])

    # -- operations ---------------------------------------------------------------------------
    def attach_operations(self, specs: Sequence[Any]) -> None:
        """Add the operations of a configuration's ``[[operations]]`` tables to the simulation.

        They are built by :func:`skygas.runs.operations.build_operations`; a name that another
        operation of the run already has is refused.
        """
        from skygas.engine.scheduler import named_operations
        from skygas.runs.operations import build_operations

        self.sim.operations.extend(build_operations(specs, self.sim))
        named_operations(self.sim.operations)  # a name the device's own operations use: refused

    # -- results ------------------------------------------------------------------------------
    def base_summary(self) -> dict:
        """What every device's summary starts with.

        The version, the seed, the simulated and wall times, the step, and the named
        operations' summaries (when there are any).
        """
        sim = self.sim
        summary = {
            "skygas_version": __version__,
            "seed": self.config.seed,
            "simulated_time_s": sim.time,
            "time_step_s": sim.time_step,
            "steps": sim.step,
            "wall_time_s": self.wall_time,
        }
        if operations := sim.operation_summaries():
            summary["operations"] = operations
        return summary

    def add_operation_data(self, ds: xr.Dataset) -> xr.Dataset:
        """``ds`` with every named operation's ``data()`` added as variables.

        See :meth:`Simulation.operation_data <skygas.engine.Simulation.operation_data>`.
        """
        for name, (dims, array) in self.sim.operation_data().items():
            ds[name] = (dims, array)
        return ds
