"""How fast this machine steps a gas: the rate behind the expected times of the estimates.

(:mod:`skygas.core.estimates`.)

The engine's cost per Heun step grows linearly with the number of skyrmions N: about
(:data:`~skygas.core.estimates.OVERHEAD_SKYRMIONS` + N) × a constant (docs/performance.md:
4.5 µs at 100 skyrmions, 42 µs at 1 000 on the measuring machine). One figure fixes the
constant: the wall time of a step of the demonstration's gas (45 skyrmions in the paper's
closed 1024 nm chamber), :func:`measured_step_seconds`, measured by running
:data:`CALIBRATION_STEPS` steps once per process (~0.3 s with the kernels compiled; their
first compilation on a new install is paid once) and kept on disk (``machine-speed.json`` in
the set-up cache, :mod:`skygas.core.disk_cache`) for the same code on the same machine, so
later processes pay nothing.

It is measured only when it matters: :func:`run_estimate` first prices a run at
:data:`REFERENCE_STEP_SECONDS` × :data:`SLOW_MARGIN` and measures only if that could reach
:data:`~skygas.core.estimates.ANNOUNCE_SECONDS`. ``SKYGAS_STEP_SECONDS`` (seconds per step of
the 45-skyrmion gas) replaces the measurement.
"""

from __future__ import annotations

import json
import os
import platform
import sys
import time

from skygas.core import disk_cache
from skygas.core.estimates import (
    ANNOUNCE_SECONDS,
    BUILD_SECONDS,
    OPERATION_TURN_SECONDS,
    REFERENCE_STEP_SECONDS,
    Estimate,
    step_seconds,
)

#: What a command says before the first run of an installation compiles the kernels.
COMPILING_LINE = "skygas: compiling the engine's kernels (once per installation, about a minute)..."
#: Steps timed (after a few untimed ones that load the kernels).
CALIBRATION_STEPS = 3000
#: How much slower than the reference a machine may be before a run is worth measuring.
SLOW_MARGIN = 10.0
#: How much faster than the reference a machine may be (the early checks price steps at that).
FAST_MARGIN = 2.0

_measured: float | None = None


def _cache_file():
    where = disk_cache.location()
    return None if where is None else where / "machine-speed.json"


def _key() -> str:
    return f"{platform.node()}:{disk_cache.code_fingerprint()}"


def _calibrate() -> float:
    """Wall time [s] of one step of the calibration gas, timed here and now."""
    import tomllib
    from importlib import resources

    from skygas.runs.config import parse_config

    text = resources.files("skygas").joinpath("data/demo-closed-chamber.toml").read_text()
    sim = parse_config(tomllib.loads(text), source="calibration gas: ").build()
    dt = sim.time_step
    sim.run(20 * dt)  # loads (or compiles) the kernel
    started = time.perf_counter()
    sim.run(CALIBRATION_STEPS * dt)
    return (time.perf_counter() - started) / CALIBRATION_STEPS


def _say_compiling() -> None:
    """Say so before the measurement compiles the engine's kernels (about a minute, once).

    The measurement runs before the run driver's progress bar, which would otherwise say it:
    without this line, the first long run of an installation sat silent for that time. Said
    only where estimates are announced (the command line, except under --json or --quiet).
    """
    from skygas.core.estimates import current_limits
    from skygas.core.kernel_cache import engine_compiled

    # a line for a person at a terminal: a refusal that follows stays the only line elsewhere
    if current_limits().announce and sys.stderr.isatty() and not engine_compiled():
        print(COMPILING_LINE, file=sys.stderr, flush=True)


def measured_step_seconds() -> float:
    """Seconds per step of the calibration gas on this machine.

    ``SKYGAS_STEP_SECONDS`` if set; else the figure measured earlier in this process or kept on
    disk for this code on this machine; else measured now (and kept).

    Returns
    -------
    float
        Wall time [s] of one Heun step of 45 skyrmions.
    """
    global _measured
    given = os.environ.get("SKYGAS_STEP_SECONDS")
    if given:
        return float(given)
    if _measured is not None:
        return _measured
    path = _cache_file()
    key = _key()
    try:
        if path is not None:
            _measured = float(json.loads(path.read_text())[key])
            return _measured
    except (OSError, ValueError, KeyError, TypeError):
        pass
    _say_compiling()
    _measured = _calibrate()
    if path is not None:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            tmp = path.with_suffix(f".{os.getpid()}.tmp")
            tmp.write_text(json.dumps({key: _measured}))
            os.replace(tmp, path)
        except OSError:
            pass  # not kept: measured again by the next process
    return _measured


def run_estimate(
    steps: float,
    skyrmions: float,
    memory: float,
    runs: int = 1,
    workers: int = 1,
    turns: float = 0.0,
    builds: float = 0.0,
) -> Estimate:
    """The :class:`~skygas.core.estimates.Estimate` of ``runs`` runs of ``steps`` steps each.

    Parameters
    ----------
    steps : float
        Time steps of one run.
    skyrmions : float
        Mean skyrmions in the device during a run.
    memory : float
        Bytes of the largest arrays.
    runs, workers : int
        Number of runs and of processes running them at once.
    turns : float
        Operations' turns in one run (an operation acting every k steps takes steps/k), each
        priced at :data:`~skygas.core.estimates.OPERATION_TURN_SECONDS`.
    builds : float
        Simulations built for one run (a device that builds one per point of a curve),
        each priced at :data:`~skygas.core.estimates.BUILD_SECONDS`.

    Returns
    -------
    Estimate
        With the expected wall time from :func:`measured_step_seconds`, measured only when
        the run could last :data:`~skygas.core.estimates.ANNOUNCE_SECONDS` or more: the
        reference machine's prices times this machine's step over the reference step.
    """
    share = runs / max(1, min(workers, runs))
    reference = share * (
        float(steps) * step_seconds(skyrmions, REFERENCE_STEP_SECONDS)
        + turns * OPERATION_TURN_SECONDS
        + builds * BUILD_SECONDS
    )
    if reference * SLOW_MARGIN < ANNOUNCE_SECONDS and not os.environ.get("SKYGAS_STEP_SECONDS"):
        seconds = reference
    else:
        seconds = reference * measured_step_seconds() / REFERENCE_STEP_SECONDS
    return Estimate(steps=float(steps), memory=float(memory), seconds=seconds, runs=runs)


def optimistic_estimate(steps: float, skyrmions: float, memory: float) -> Estimate:
    """An estimate that prices a run at the reference machine's speed, measuring nothing.

    For the first check of a device, made before any numerics with a lower bound of its steps:
    what it refuses would be refused by the exact check too (on a machine at most
    :data:`FAST_MARGIN` times faster than the reference).

    Parameters
    ----------
    steps : float
        A lower bound of the time steps.
    skyrmions : float
        Mean skyrmions in the device.
    memory : float
        Bytes of the largest arrays.

    Returns
    -------
    Estimate
        Priced at :data:`REFERENCE_STEP_SECONDS` / :data:`FAST_MARGIN`.
    """
    seconds = float(steps) * step_seconds(skyrmions, REFERENCE_STEP_SECONDS / FAST_MARGIN)
    return Estimate(steps=float(steps), memory=float(memory), seconds=seconds)
