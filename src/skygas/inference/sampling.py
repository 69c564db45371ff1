"""Frames too far apart for the motion: the estimator's bias, measured on runs of the model.

The projection of :mod:`skygas.inference.dynamics` is exact as the frame interval Δt → 0.
When a skyrmion's drift within one frame is not small against the distances over which the
forces change (a crowded gyrotropic gas, a steep pinning well, a movie with few frames per
unit of motion), the estimates are biased: D read from the steps' noise carries the drift
(the first-order term is removed, the rest is not), the Hall angle and the pair force come
out weak.

The bias is a property of the estimator at this frame interval and in this film, so it is
measured the way a parametric bootstrap does (indirect inference): the model inferred so far
is run with skygas's engine at fine time steps, in the movie's film, seen as the movie was
seen, and the same estimator (the same terms, roughness weight and basis) is applied to the
run. What it reads off the run, against what the run was made with, is the bias; the model is
moved by the difference between what the movie read and what the run read,

    q_{k+1} = q_k + (q̂ − q*(q_k)),

for D, the Hall angle, the pair, wall and drive forces, and the landscape's amplitude,
:data:`ROUNDS` times. (The landscape's shape is left as the movie read it: correcting each of
its coefficients with a run of the same length would add as much noise again; a blurred
landscape is first of all a weaker one.) The errors of the corrected numbers add the run's
jackknife error and the spread of the bias from round to round to the movie's, in quadrature.
Where the last run still does not read what the movie read within those errors, the
correction has not converged: the frames are too coarse for it, and ``infer`` says that the
data do not fix D, the Hall angle or the forces.

The correction is made when the first-order drift term of D is at least :data:`COARSE_SHARE`
of D: below that the frames resolve the motion.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from skygas.inference import dynamics, forces, selfcheck
from skygas.inference.film import EDGE_STEPS, Film
from skygas.inference.wall import wall_distance

#: The correction runs when the drift within a frame adds at least this share to the raw D.
COARSE_SHARE = 0.05
#: Rounds of (run the model → read it → move the model).
ROUNDS = 2
#: The last run must read the movie's D and θ_H within this many combined errors.
CONVERGED_SIGMAS = 3.0
#: The correction keeps D within these multiples of the movie's reading, |θ_H| below 89°, and
#: the landscape's amplitude within these multiples of the movie's map.
D_RANGE = (0.1, 10.0)
SCALE_RANGE = (0.2, 5.0)
#: The terms whose coefficients are corrected.
CORRECTED = ("pair", "material_pair", "wall", "drive")


@dataclass(frozen=True)
class ModelNumbers:
    """The numbers a model is written from.

    D [m²/s], θ_H [rad], θ (the force coefficients), and the landscape's amplitude relative to
    the map the movie read (``landscape_scale``).
    """

    diffusion: float
    hall_angle: float
    theta: np.ndarray
    landscape_scale: float = 1.0

    def moved(self, read: ModelNumbers, target: ModelNumbers, columns: np.ndarray):
        """These numbers moved by ``target`` − ``read``.

        On D, θ_H, the landscape's amplitude and ``columns`` of θ.
        """
        theta = self.theta.copy()
        theta[columns] += target.theta[columns] - read.theta[columns]
        return ModelNumbers(
            self.diffusion + target.diffusion - read.diffusion,
            self.hall_angle + target.hall_angle - read.hall_angle,
            theta,
            self.landscape_scale + target.landscape_scale - read.landscape_scale,
        )


@dataclass
class Correction:
    """The corrected numbers, the last run's inference (for its errors) and the history.

    ``converged``: the last run read what the movie read, D and θ_H within
    :data:`CONVERGED_SIGMAS` of their combined errors (otherwise the frames are too coarse for
    this correction, and the numbers are not fixed by the data). The combined error holds the
    movie's and the run's jackknife errors and the spread of the bias between the rounds'
    runs (``diffusion_spread``, ``hall_spread``): in a pinned film which wells a run's
    skyrmions happen to hold moves its reading by more than its own blocks see.
    """

    numbers: ModelNumbers
    run: forces.ForceInference | None
    history: list = field(default_factory=list)
    converged: bool = True
    #: the spread of the bias of D [m²/s] and of θ_H [rad] from one run to the next
    diffusion_spread: float = 0.0
    hall_spread: float = 0.0

    def error(self, quantity: Callable, data_error: np.ndarray) -> np.ndarray:
        """The error of a corrected quantity: the movie's and the last run's in quadrature."""
        if self.run is None:
            return data_error
        _, run_error = self.run.jackknife(quantity)
        return np.hypot(data_error, run_error)


def _amplitude(read: forces.ForceInference, made: np.ndarray, scale: float) -> float:
    """The landscape's amplitude the run read, relative to the movie's map.

    The run was made with ``scale`` × the movie's landscape coefficients ``made``; what it read
    is projected on them in the metric of the forces (the Gram matrix): a landscape read too
    weak (the frames blur the wells) reads an amplitude below ``scale``.
    """
    if "landscape" not in read.terms or read.basis.landscape is None:
        return scale
    cols = read.basis.indices(["landscape"])
    gram = read.moments.total("gram", np.ones(len(read.moments.count), bool))[cols][:, cols]
    base = made[cols]
    norm = float(base @ (gram @ base))
    if norm <= 0:
        return scale
    return float(read.fit.theta[cols] @ (gram @ base)) / norm


def coarseness(result: forces.ForceInference) -> float:
    """The share of the raw D that is drift within a frame, the drive's left out.

    The first-order term that :func:`~skygas.inference.dynamics.diffusion_constant` removes,
    of the forces that change across the film: a uniform drive changes nowhere, and its drift,
    however fast, biases nothing.
    """
    fit = result.fit
    if result.basis.has("drive"):
        theta = fit.theta.copy()
        theta[result.basis.columns["drive"]] = 0.0
        fit = dynamics.Fit(theta, fit.tan_hall, fit.diffusion, fit.columns, fit.roughness)
    everything = np.ones(len(result.moments.count), bool)
    raw, _ = dynamics.diffusion_constant(result.moments, None, everything)
    free, _ = dynamics.diffusion_constant(result.moments, fit, everything)
    return (raw - free) / free


def numbers_of(result: forces.ForceInference, hall_angle: float) -> ModelNumbers:
    """The model's numbers as ``result`` read them (θ_H as the model takes it)."""
    return ModelNumbers(result.diffusion, hall_angle, result.fit.theta.copy())


def _run_steps(film: Film, run: selfcheck.ModelRun, step: float):
    """The run's frames, the film to read them in, and which steps to use, as for the movie."""
    if film.periodic:
        # every skyrmion of the 3 × 3 copies, neighbours where they are; steps that start in
        # the middle copy
        assert film.period is not None
        tiled = Film("tiled", run.outline, film.period, film.origin)
        frames = run.everything
        x0, y0 = film.origin
        lx, ly = film.period
        middle = (frames.x >= x0) & (frames.x < x0 + lx) & (frames.y >= y0) & (frames.y < y0 + ly)
        return frames, tiled, middle
    frames = run.frames
    keep: np.ndarray | None = None
    if film.kind == "open":
        keep = wall_distance(film.outline, frames.x, frames.y) >= EDGE_STEPS * step
    return frames, film, keep


def read_run(
    result: forces.ForceInference, run: selfcheck.ModelRun, film: Film, step: float
) -> forces.ForceInference:
    """The movie's estimator (its terms, roughness weight and basis) applied to a run."""
    frames, run_film, keep = _run_steps(film, run, step)
    basis = replace(result.basis, film=run_film)
    steps = dynamics.make_steps(frames, run_film, keep)
    moments = dynamics.accumulate(frames, steps, basis)
    return forces.fit_terms(moments, basis, result.terms, result.roughness)


def correct(
    result: forces.ForceInference,
    hall_angle: float,
    film: Film,
    run_model: Callable[[ModelNumbers], selfcheck.ModelRun],
    step: float,
    progress=None,
) -> Correction:
    """Move the model until runs of it read what the movie read (see the module's text).

    ``hall_angle``: the model's θ_H (moved only where the data fix it);
    ``run_model(numbers)`` runs the model written from ``numbers``; ``step`` [m] the rms step
    per frame (the margin of an open film's steps).
    """
    target = numbers_of(result, hall_angle)
    columns = result.basis.indices([t for t in CORRECTED if t in result.terms])
    current = target
    last = None
    history = []
    for k in range(ROUNDS):
        run = run_model(current)
        last = read_run(result, run, film, step)
        read_hall = float(np.arctan(last.fit.tan_hall)) if result.hall_angle_fixed else hall_angle
        read = replace(
            numbers_of(last, read_hall),
            landscape_scale=_amplitude(last, target.theta, current.landscape_scale),
        )
        history.append(
            {
                "model_diffusion_constant": current.diffusion,
                "model_hall_angle": current.hall_angle,
                "read_diffusion_constant": read.diffusion,
                "read_hall_angle": read.hall_angle,
            }
        )
        moved = current.moved(read, target, columns)
        current = replace(
            moved,
            diffusion=float(
                np.clip(
                    moved.diffusion, D_RANGE[0] * target.diffusion, D_RANGE[1] * target.diffusion
                )
            ),
            hall_angle=float(np.clip(moved.hall_angle, -math.radians(89), math.radians(89))),
            landscape_scale=float(np.clip(moved.landscape_scale, *SCALE_RANGE)),
        )
        if progress is not None:
            made = history[-1]
            progress(
                f"sampling correction {k + 1}: a run made with D = "
                f"{made['model_diffusion_constant']:.4g} m²/s, θ_H = "
                f"{math.degrees(made['model_hall_angle']):.2f}° reads "
                f"{read.diffusion:.4g} m²/s, {math.degrees(read.hall_angle):.2f}°"
            )
    converged = True
    d_spread, hall_spread = _bias_spread(history, current.diffusion)
    if last is not None:
        d_err = math.hypot(math.hypot(result.diffusion_error, last.diffusion_error), d_spread)
        converged = abs(read.diffusion - target.diffusion) <= CONVERGED_SIGMAS * d_err
        if result.hall_angle_fixed:
            _, movie_hall = result.jackknife(lambda f: f.hall_angle)
            _, run_hall = last.jackknife(lambda f: f.hall_angle)
            hall_err = float(np.hypot(np.hypot(movie_hall, run_hall), hall_spread))
            converged &= abs(read.hall_angle - target.hall_angle) <= CONVERGED_SIGMAS * hall_err
    return Correction(current, last, history, bool(converged), d_spread, hall_spread)


def _bias_spread(history: list[dict], diffusion: float) -> tuple[float, float]:
    """The standard deviation of the bias from round to round, of D and of θ_H.

    D's as a share of what each run was made with, times ``diffusion`` [m²/s]; θ_H's [rad].
    Zero with a single round.
    """
    if len(history) < 2:
        return 0.0, 0.0
    ratio = [h["read_diffusion_constant"] / h["model_diffusion_constant"] for h in history]
    turn = [h["read_hall_angle"] - h["model_hall_angle"] for h in history]
    return float(np.std(ratio, ddof=1) * diffusion), float(np.std(turn, ddof=1))
