"""Estimates before a run: steps, runs, memory and expected time, checked before any work.

Every device builds an :class:`Estimate` of what it is about to do before it allocates or steps
anything, and hands it to :func:`check`:

- memory above :func:`~skygas.core.resources.memory_limit` is refused (never forced: the machine
  cannot hold it);
- an expected time above :data:`MAX_SECONDS` is refused unless the run is *forced*
  (``--force`` on the command line, :func:`run_limits` ``force=True`` from Python): long but
  feasible runs start when asked for explicitly;
- an expected time of at least :data:`ANNOUNCE_SECONDS` is announced in one line on stderr
  (``skygas: estimate: 4.1e8 steps, about 25 min on this machine, 1.2 GiB``) when
  announcements are on (the command line turns them on, except under ``--json`` or
  ``--quiet``; library callers get none unless they ask). The line is held back until the run
  is about to start (:func:`announce_pending`, called by the run driver once the sanity checks
  and the output folder have accepted it, and at the end of the :func:`run_limits` block), so
  a run refused before it starts prints its one error line and nothing else.

The force and announce switches are a context (:func:`run_limits`, a ``ContextVar``), so the
builders' signatures do not change and every caller, command line or library, goes through the
same checks. The expected time comes from a rate of steps measured on this machine
(:mod:`skygas.runs.machine_speed`); this module only does the arithmetic.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass

from skygas.core.errors import InputError
from skygas.core.resources import format_bytes, require_memory

#: Longest expected time [s] a run or sweep starts without being forced: 24 h.
MAX_SECONDS = 24 * 3600.0
#: Shortest expected time [s] that is announced on stderr.
ANNOUNCE_SECONDS = 60.0
#: Skyrmions in the gas whose step sets the price of all (the demonstration's).
CALIBRATION_SKYRMIONS = 45
#: The per-step cost that does not grow with N, in skyrmions' worth (docs/performance.md).
OVERHEAD_SKYRMIONS = 8.0
#: Seconds per step of the 45-skyrmion gas on the measuring machine (docs/performance.md);
#: :mod:`skygas.runs.machine_speed` measures this machine's own figure.
REFERENCE_STEP_SECONDS = 2.2e-6
#: Seconds, on the measuring machine, of one operation's turn: the engine stops its kernel,
#: the operation acts in Python (a sensor read, a gate rule, an annihilation check) and the
#: kernel starts again. The neuron's controller and annihilator act every 4 and every step:
#: its example's command (3 µs: 8.4e4 steps and 1.05e5 turns with its transfer curve's six
#: runs, seven builds) stepped for 12.6 s in all (2.1 s the main run, 10.5 s the transfer
#: curve) with the 45-skyrmion gas at 7.6 µs per step, 3.45 times the measuring machine's:
#: 3.65 s there, of which the steps take 0.07 s and the builds (:data:`BUILD_SECONDS`) 0.7 s,
#: leaving 27 µs per turn (against 1 µs for a step of the 45-skyrmion gas).
OPERATION_TURN_SECONDS = 2.7e-5
#: Seconds, on the measuring machine, of building a device's simulation with its landscape
#: (the neuron's gate: 0.26–0.38 s on two busy cores, 0.08–0.15 s at the measuring one's speed).
BUILD_SECONDS = 0.1


@dataclass(frozen=True)
class RunLimits:
    """What :func:`check` does beyond refusing memory: force long runs, announce estimates."""

    force: bool = False
    announce: bool = False


_limits: ContextVar[RunLimits] = ContextVar("skygas_run_limits", default=RunLimits())  # noqa: B039 - frozen
#: whether a :func:`run_limits` block is open: its builder checked the job before it started
_inside: ContextVar[bool] = ContextVar("skygas_inside_run_limits", default=False)
#: whether :func:`check` stops at the first exact estimate (:func:`estimate_only`)
_estimate_only: ContextVar[bool] = ContextVar("skygas_estimate_only", default=False)
#: the last exact estimate checked in this context: the run that is about to start
_checked: ContextVar[Estimate | None] = ContextVar("skygas_checked_estimate", default=None)
_announced: set[str] = set()  # lines already printed (a study builds several equal runs)
_pending: list[str] = []  # lines waiting for the run to be accepted (announce_pending)


@contextmanager
def run_limits(*, force: bool = False, announce: bool = False) -> Iterator[RunLimits]:
    """Set how :func:`check` treats the runs built inside the ``with`` block.

    Parameters
    ----------
    force : bool
        Start runs expected to take longer than :data:`MAX_SECONDS` (memory is still refused).
    announce : bool
        Print the estimate of a run expected to take :data:`ANNOUNCE_SECONDS` or more on stderr.

    Yields
    ------
    RunLimits
        The limits in force inside the block.
    """
    limits = RunLimits(force=force, announce=announce)
    token = _limits.set(limits)
    inside = _inside.set(True)
    try:
        yield limits
    except BaseException:
        _pending.clear()  # a refused run announces nothing
        raise
    else:
        announce_pending()
    finally:
        _inside.reset(inside)
        _limits.reset(token)


class EstimateOnly(BaseException):
    """Raised by :func:`check` inside :func:`estimate_only`: the job's estimate, before its run.

    A ``BaseException``, so that no command's error handling turns it into an error line.
    """

    def __init__(self, estimate: Estimate):
        super().__init__(estimate.line())
        self.estimate = estimate


@contextmanager
def estimate_only() -> Iterator[None]:
    """Stop every job built inside the block at its exact estimate (raising :class:`EstimateOnly`).

    For the estimator's own checks (``benchmarks/estimates.py``): a device or command is built
    as for a run, checked, and stopped before its first step, whatever :func:`run_limits` its
    command line sets inside.
    """
    token = _estimate_only.set(True)
    try:
        yield
    finally:
        _estimate_only.reset(token)


def inside_limits() -> bool:
    """Whether a :func:`run_limits` block is open (its device or command checked the job).

    A :class:`~skygas.engine.Simulation` run from plain Python, outside any, checks itself.
    """
    return _inside.get()


def step_seconds(skyrmions: float, per_calibration_step: float = REFERENCE_STEP_SECONDS) -> float:
    """Wall time [s] of one step of ``skyrmions`` skyrmions.

    The engine's cost per Heun step grows as (8 + N) (docs/performance.md: 4.5 µs at 100
    skyrmions, 42 µs at 1 000 on the measuring machine), so one figure fixes it.

    Parameters
    ----------
    skyrmions : float
        Skyrmions in the device (a mean where it varies).
    per_calibration_step : float
        Seconds per step of the 45-skyrmion gas (default: the measuring machine's).

    Returns
    -------
    float
        ``per_calibration_step`` × (8 + N) / (8 + 45).
    """
    return (
        per_calibration_step
        * (OVERHEAD_SKYRMIONS + max(0.0, skyrmions))
        / (OVERHEAD_SKYRMIONS + CALIBRATION_SKYRMIONS)
    )


def checked_estimate() -> Estimate | None:
    """The last exact estimate :func:`check` accepted in this context (None: none yet)."""
    return _checked.get()


def announce_pending() -> None:
    """Print the estimates :func:`check` held back: the run they describe is about to start."""
    while _pending:
        print(_pending.pop(0), file=sys.stderr, flush=True)


def current_limits() -> RunLimits:
    """The :class:`RunLimits` in force (default: not forced, no announcement)."""
    return _limits.get()


def format_duration(seconds: float) -> str:
    """A wall time in the largest fitting unit (``"25 min"``, ``"3.2 h"``, ``"41 days"``)."""
    if not math.isfinite(seconds):
        return "forever"
    for unit, size, least in (
        ("years", 365.25 * 86400, 2.0),
        ("days", 86400.0, 2.0),
        ("h", 3600.0, 1.0),
    ):
        if seconds >= least * size:
            return f"{seconds / size:.2g} {unit}"
    if seconds >= 60:
        return f"{seconds / 60:.2g} min"
    return f"{seconds:.2g} s"


@dataclass(frozen=True)
class Estimate:
    """What a run or sweep is about to do, before it does any of it.

    Attributes
    ----------
    steps : float
        Time steps of one run (a lower bound before the time step is known).
    memory : float
        Bytes of the largest arrays the job allocates (all runs of a sweep held at once).
    seconds : float
        Expected wall time on this machine [s] (all runs, spread over the workers).
    runs : int
        Number of runs (1 for a single run).
    """

    steps: float
    memory: float
    seconds: float
    runs: int = 1

    def line(self) -> str:
        """The one-line announcement: ``skygas: estimate: 4.1e8 steps, about 25 min …``."""
        runs = f"{self.runs} runs of " if self.runs != 1 else ""
        return (
            f"skygas: estimate: {runs}{self.steps:.2g} steps, about "
            f"{format_duration(self.seconds)} on this machine, {format_bytes(self.memory)}"
        )


def check(
    estimate: Estimate,
    field: str,
    value,
    what: str,
    hint: str,
    *,
    announce: bool = True,
) -> None:
    """Refuse ``estimate`` if it exceeds the machine; announce it if it is long.

    Parameters
    ----------
    estimate : Estimate
        What the job is about to do.
    field, value
        The configuration field to change (named in the refusal) and its value.
    what : str
        What the memory is for (``"the input bits of 2e10 injection events"``).
    hint : str
        What to change (``"use a longer injection interval"``).
    announce : bool
        Whether this call may print the estimate (False for an early check with a lower bound
        of the steps, that a second, exact check follows).

    Raises
    ------
    InputError
        Memory above :func:`~skygas.core.resources.memory_limit` (always), or an expected time
        above :data:`MAX_SECONDS` when not forced (:func:`run_limits`).
    """
    require_memory(field, value, estimate.memory, what, hint)
    limits = current_limits()
    if not (estimate.seconds <= MAX_SECONDS) and not limits.force:
        raise InputError(
            field,
            value,
            f"a job of at most {format_duration(MAX_SECONDS)} on this machine "
            f"(this one: {estimate.steps:.3g} steps"
            + (f" × {estimate.runs} runs" if estimate.runs != 1 else "")
            + f", about {format_duration(estimate.seconds)})",
            f"{hint}, or give --force to run it anyway",
        )
    if announce:
        _checked.set(estimate)
    if announce and _estimate_only.get():
        raise EstimateOnly(estimate)
    if announce and limits.announce and estimate.seconds >= ANNOUNCE_SECONDS:
        line = estimate.line()
        if line not in _announced:
            _announced.add(line)
            _pending.append(line)
