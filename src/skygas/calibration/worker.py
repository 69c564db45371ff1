"""The solves, as functions a Dask worker runs: a constrained relaxation, a piece of LLG.

Each task is a pure function of its arguments (the material, the film, the starting texture):
run again, it gives the same bits, so a calibration that is interrupted and resumed recomputes
only what it had not finished, and gets the same results. A worker process keeps one
:class:`~skygas.calibration.solver.FilmSolver` per film (the stray-field kernel is built once)
and per thread that solves (a solver holds its texture while it solves: two threads of one
worker must not share it).

The calibration hands them out through :func:`solve` (:mod:`skygas.calibration.cluster`), which
sets torch's threads and compilation before the first solve of the process.
"""

from __future__ import annotations

import math
import threading
from typing import Any

import numpy as np

from skygas.calibration import solver
from skygas.calibration.material import MicromagneticMaterial
from skygas.calibration.plan import Relaxation
from skygas.calibration.solver import Film

#: The solvers a worker process keeps, by (material, film, thread that solves with it).
_solvers: dict[tuple[str, Film, int], solver.FilmSolver] = {}
#: Solvers a worker keeps per solving thread: it sees few films, and each keeps its
#: stray-field kernel (memory).
SOLVERS_KEPT = 4

#: A held skyrmion's guiding centre is taken over the cells within this many radii of its
#: target (and nearer to it than to another target): all of its charge but e⁻⁶ or so.
HOLD_REACH = 2.5


def _film_solver(material_json: str, film: Film) -> solver.FilmSolver:
    thread = threading.get_ident()
    key = (material_json, film, thread)
    if key not in _solvers:
        # list() copies the keys at once: another thread of the worker may add its own
        mine = [k for k in list(_solvers) if k[2] == thread]
        if len(mine) >= SOLVERS_KEPT:
            _solvers.pop(mine[0], None)
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


def solve(kind: str, threads: int, compile: bool, *args: Any) -> dict[str, Any]:
    """Run the solve ``kind`` (``"relax"`` or ``"evolve"``) on ``args``, as a Dask task.

    ``threads`` torch threads (for this solve: :func:`~skygas.calibration.solver.use_threads`)
    and ``compile`` (torch.compile of the field terms) are set first.
    Each task carries them, rather than a Dask worker plugin that sets them once per worker:
    they are the calibration's own choice, so they travel with its tasks to whatever workers
    run them (a shared cluster's too, without a plugin installed on every worker), and setting
    them is free after the first solve of a process (:func:`~skygas.calibration.solver.configure`
    returns at once once torch is set up: the first calibration that a worker process serves
    decides them for that process).
    """
    solver.configure(threads=threads, compile=compile)
    solver.use_threads(threads)
    if kind == "relax":
        return relax(*args)
    if kind == "evolve":
        return evolve(*args)
    raise ValueError(f"no solve of the kind {kind!r}")
