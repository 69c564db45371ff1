"""The solves, as functions a worker process runs: a constrained relaxation, a piece of LLG.

Each task is a pure function of its arguments (the material, the film, the starting texture):
run again, it gives the same bits, so a calibration that is interrupted and resumed recomputes
only what it had not finished, and gets the same results. A worker process keeps one
:class:`~skygas.calibration.solver.FilmSolver` per film (the stray-field kernel is built once).

Worker processes (:func:`start_pool`) use one torch thread each, ignore Ctrl-C (the parent
decides when to stop and saves its checkpoint first) and, on Linux, are killed when their
parent dies, even by SIGKILL, so no orphan keeps computing.
"""

from __future__ import annotations

import math
import signal
import sys
from typing import TYPE_CHECKING, Any

import numpy as np

from skygas.calibration import solver
from skygas.calibration.material import MicromagneticMaterial
from skygas.calibration.plan import Relaxation
from skygas.calibration.solver import Film

if TYPE_CHECKING:
    from concurrent.futures import ProcessPoolExecutor

_solvers: dict[tuple[str, Film], solver.FilmSolver] = {}
#: Solvers a worker keeps: it sees few films, and each keeps its stray-field kernel (memory).
SOLVERS_KEPT = 4

#: A held skyrmion's guiding centre is taken over the cells within this many radii of its
#: target (and nearer to it than to another target): all of its charge but e⁻⁶ or so.
HOLD_REACH = 2.5


def _film_solver(material_json: str, film: Film) -> solver.FilmSolver:
    key = (material_json, film)
    if key not in _solvers:
        if len(_solvers) >= SOLVERS_KEPT:
            _solvers.pop(next(iter(_solvers)))
        _solvers[key] = solver.FilmSolver(
            MicromagneticMaterial.model_validate_json(material_json), film
        )
    return _solvers[key]


def _skyrmions(m: np.ndarray, film: Film, thickness: float) -> list[dict[str, float]]:
    from skygas.calibration.profile import detect

    return [
        {
            "x": s.x,
            "y": s.y,
            "radius": s.radius,
            "charge": s.charge,
            "dissipation": s.dissipation,
            "circularity": s.circularity,
        }
        for s in detect(m, film, thickness)
    ]


def initial_texture(fs: solver.FilmSolver, centres, radius: float, width: float) -> np.ndarray:
    """The ansatz at ``centres`` [m] with the helicity of lower energy.

    Néel: 0 or π; Bloch: ±π/2. The DMI's sign decides it, and a wrong one would collapse.
    """
    candidates = (math.pi / 2, -math.pi / 2) if fs.material.bulk_dmi > 0 else (0.0, math.pi)
    textures = [solver.skyrmion_texture(fs.film, centres, radius, width, h) for h in candidates]
    if not centres:
        return textures[0]
    energies = [sum(fs.energy(t).values()) for t in textures]
    return textures[int(np.argmin(energies))]


def relax(material_json: str, task: Relaxation, torque_tolerance: float) -> dict[str, Any]:
    """Run one :class:`~skygas.calibration.plan.Relaxation`.

    Returns its energies [J], the solver's statistics, the skyrmions found in the result,
    ``moment_z`` = ∫ m_z dA over the film [m²] (a uniform extra field b [A/m] adds
    −μ₀ M_s t b · moment_z to the energy) and (``task.keep``) the texture.
    """
    fs = _film_solver(material_json, task.film)
    x, y = task.film.centres()
    centres = [(float(x[c]), float(y[c])) for c in task.cores]
    if task.template is not None:
        t = task.template
        m0 = solver.template_texture(task.film, centres, t.radius, t.mz, t.helicity, task.scale)
    else:
        m0 = initial_texture(fs, centres, task.radius, task.width)
    result = fs.relax(
        m0,
        centres,
        reach=HOLD_REACH * max(task.radius, task.film.cell_size),
        torque_tolerance=torque_tolerance,
    )
    out = {
        "name": task.name,
        "energy": result.energy,
        "energies": result.energies,
        "iterations": result.iterations,
        "converged": result.converged,
        "torque": result.torque,
        "seconds": result.seconds,
        "device": solver.device_name(),
        "cells": [list(c) for c in task.cores],
        "centres": centres,
        "skyrmions": _skyrmions(result.m, task.film, fs.material.film_thickness),
        "moment_z": float(np.sum(result.m[..., 2]) * task.film.cell_size**2),
    }
    if task.keep:
        out["m"] = result.m
    return out


def evolve(
    material_json: str,
    film: Film,
    m: np.ndarray,
    time: float,
    next_step: float,
    duration: float,
    snapshot_interval: float,
    tolerance: float,
) -> dict[str, Any]:
    """Integrate LLG for ``duration`` [s] from (m, time, next_step), detecting skyrmions on the way.

    The skyrmions are detected at every multiple of ``snapshot_interval`` [s]; returns the end state
    and the frames.
    """
    fs = _film_solver(material_json, film)
    frames, seconds, steps = [], 0.0, 0
    n = int(round(duration / snapshot_interval))
    for _ in range(n):
        piece = fs.evolve(m, time, snapshot_interval, next_step, tolerance)
        m, time, next_step = piece.m, piece.time, piece.next_step
        seconds += piece.seconds
        steps += piece.steps
        frames.append({"time": time, "skyrmions": _skyrmions(m, film, fs.material.film_thickness)})
    return {
        "m": m,
        "time": time,
        "next_step": next_step,
        "frames": frames,
        "seconds": seconds,
        "steps": steps,
    }


def _die_with_parent() -> None:
    """Ask Linux to kill this process when its parent dies (prctl PR_SET_PDEATHSIG)."""
    if not sys.platform.startswith("linux"):
        return
    try:
        import ctypes

        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)
    except OSError:  # no libc by that name: the parent terminates the pool itself
        pass


def init_worker(threads: int, compile: bool) -> None:
    """Worker start-up: Ctrl-C is the parent's business; one or more torch threads."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _die_with_parent()
    solver.configure(threads=threads, compile=compile)


def start_pool(workers: int, threads: int, compile: bool) -> ProcessPoolExecutor:
    """A pool of ``workers`` fresh processes (spawned: torch and fork do not mix).

    A worker that dies (the kernel kills the largest process when memory runs out) breaks the
    pool: every solve in flight then fails with ``BrokenProcessPool`` instead of waiting for
    ever, as it would in a :class:`multiprocessing.pool.Pool`.
    """
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    return ProcessPoolExecutor(
        workers,
        mp_context=multiprocessing.get_context("spawn"),
        initializer=init_worker,
        initargs=(threads, compile),
    )
