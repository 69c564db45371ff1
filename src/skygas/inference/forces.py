"""Which forces the data show, and how well: model selection and errors for :mod:`.dynamics`.

:func:`infer_forces` takes the per-block moments of every candidate term and

1. chooses the landscape's roughness weight λ by the held-out score of the full model;
2. removes terms the data do not ask for, one at a time (backward elimination): a term stays
   only if the model without it scores worse on the held-out blocks by more than
   :data:`KEEP_SIGMAS` standard errors of the difference (a term that only fits noise scores
   about the same, or worse, out of sample). Terms the user fixed are never removed;
3. fits the final model on all blocks, iterating D and the forces (:data:`~.dynamics.D_ITERATIONS`);
4. gives every fitted number its jackknife error: the fits that leave one block of time out.

Each term's verdict (``comparisons``) records the held-out log-likelihood it adds, with its
error: what inference.json and the report say about which model won and by how much.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from skygas.inference import dynamics as dyn
from skygas.inference.force_basis import ForceBasis

#: A candidate term stays when dropping it costs more than this many standard errors of the
#: held-out log-likelihood.
KEEP_SIGMAS = 2.0
#: Roughness weights tried first (relative to the data's weight); the best is then refined.
ROUGHNESS_GRID = np.geomspace(1e-4, 1e4, 5)
#: Folds of the roughness weight's held-out score.
ROUGHNESS_FOLDS = 8
#: D freed of the drift stays within these multiples of the steps' raw D.
D_BOUNDS = (0.25, 1.5)
#: Folds of contiguous blocks for the held-out scores (the jackknife uses every block).
FOLDS = 8


def jackknife_error(replicas: np.ndarray) -> np.ndarray:
    """The jackknife standard error from leave-one-out replicas (along axis 0)."""
    nb = len(replicas)
    return np.sqrt((nb - 1) / nb * np.sum((replicas - replicas.mean(axis=0)) ** 2, axis=0))


@dataclass
class ForceInference:
    """The force model the data support, with D, the Hall angle and their jackknife errors.

    ``fit`` on all data; ``folds`` the leave-one-block-out fits (the jackknife replicates);
    ``track_folds`` the leave-one-group-of-tracks-out fits (empty with too few tracks): every
    error is the larger of the two jackknifes, over time and over which skyrmions are seen;
    ``terms`` the terms kept; ``comparisons`` per candidate term: the held-out log-likelihood
    it adds (nats), its standard error, and whether it was kept; ``roughness`` λ with the
    ``roughness_scores`` of ``roughness_grid``.
    """

    basis: ForceBasis
    moments: dyn.Moments
    fit: dyn.Fit
    folds: list
    terms: tuple[str, ...]
    comparisons: dict
    diffusion_raw: float
    diffusion: float
    diffusion_error: float
    sigma2: float
    sigma2_error: float
    roughness: float
    roughness_grid: np.ndarray
    roughness_scores: np.ndarray
    score: dyn.Score
    fixed: tuple[str, ...] = field(default=())
    track_folds: list = field(default_factory=list)

    @property
    def replica_sets(self) -> list[list]:
        """The jackknife's replicate fits: over blocks of time, and over groups of tracks."""
        return [reps for reps in (self.folds, self.track_folds) if reps]

    def jackknife(self, quantity) -> tuple[np.ndarray, np.ndarray]:
        """``quantity(fit)`` on all data and its jackknife standard error.

        The error is the larger of the jackknifes over blocks of time and over groups of tracks
        (elementwise).
        """
        value = np.asarray(quantity(self.fit), float)
        errors = [
            jackknife_error(np.array([np.asarray(quantity(f), float) for f in reps]))
            for reps in self.replica_sets
        ]
        return value, np.max(errors, axis=0)

    @property
    def hall_angle_fixed(self) -> bool:
        """Whether the kept terms fix the Hall angle (a drive alone does not)."""
        return any(t in self.terms for t in ("landscape", "pair", "material_pair", "wall"))

    def coefficients(self, term: str, fit: dyn.Fit | None = None) -> np.ndarray:
        """θ of ``term`` in ``fit`` (default: the final fit)."""
        return (fit or self.fit).theta[self.basis.columns[term]]


def _score(mom, basis, terms, d, pen, lam) -> dyn.Score:
    return dyn.cross_validate(
        mom, basis.indices(terms), d, pen, lam, FOLDS, dyn.constraints(mom, basis, terms)
    )


def choose_roughness(mom, basis, terms, d, pen, progress) -> tuple[float, np.ndarray, np.ndarray]:
    """λ: the least smoothing whose held-out score is within one standard error of the best.

    A coarse grid, then twice between the best's neighbours, scored over
    :data:`ROUGHNESS_FOLDS` folds; then smaller weights while they score as well within the
    error. Smoothing is a bias the jackknife errors do not see (an over-smoothed landscape
    leaves the attraction of wells that two skyrmions share to the pair force), noise is a
    variance they do: of two weights the data cannot tell apart, the smaller keeps the
    errors honest.
    """
    cols, cons = basis.indices(terms), dyn.constraints(mom, basis, terms)
    tried: dict[float, dyn.Score] = {}

    def score(lam: float) -> float:
        if lam not in tried:
            tried[lam] = dyn.cross_validate(mom, cols, d, pen, lam, ROUGHNESS_FOLDS, cons)
        return tried[lam].total

    best = max(ROUGHNESS_GRID, key=score)
    for factor in (10.0, np.sqrt(10.0)):
        best = max((best / factor, best, best * factor), key=score)
    chosen = best
    # down to the grid's least weight: where the scores cannot tell weights apart (a landscape
    # the data hardly sample) the walk would otherwise never end
    while chosen / np.sqrt(10.0) >= ROUGHNESS_GRID[0] * (1 - 1e-9):
        smaller = chosen / np.sqrt(10.0)
        score(smaller)
        gain, err = tried[best].minus(tried[smaller])
        if not gain <= err:  # a NaN score stops the walk too
            break
        chosen = smaller
    if progress is not None:
        progress(f"roughness weight {chosen:.3g}, by held-out likelihood over {len(tried)} values")
    grid = np.array(sorted(tried))
    return float(chosen), grid, np.array([tried[g].total for g in grid])


def infer_forces(
    mom: dyn.Moments,
    basis: ForceBasis,
    *,
    fixed: tuple[str, ...] = (),
    progress=None,
) -> ForceInference:
    """Select the terms of ``basis`` the data support and fit them (see the module's text).

    ``fixed``: terms kept whatever their score (the user asked for them).
    """
    nb = len(mom.count)
    everything = np.ones(nb, bool)
    candidates = [
        t for t in ("landscape", "pair", "material_pair", "wall", "drive") if basis.has(t)
    ]
    pen = dyn.penalty(basis, mom.total("gram", everything))
    d_raw, _ = dyn.diffusion_constant(mom, None, everything)
    d = d_raw
    lam, grid, scores = 1.0, np.zeros(0), np.zeros(0)
    if "landscape" in candidates:
        lam, grid, scores = choose_roughness(mom, basis, candidates, d, pen, progress)
    terms = list(candidates)
    best = _score(mom, basis, terms, d, pen, lam)
    comparisons: dict[str, dict] = {}
    while True:
        trial = {}
        for t in terms:
            if t in fixed:
                continue
            without = _score(mom, basis, [u for u in terms if u != t], d, pen, lam)
            gain, err = best.minus(without)
            trial[t] = (gain, err, without)
        if progress is not None:
            progress(
                "held-out log-likelihood each term adds: "
                + ", ".join(f"{t} {g:+.1f} ± {e:.1f}" for t, (g, e, _) in trial.items())
            )
        weakest = min(trial, key=lambda t: trial[t][0] - KEEP_SIGMAS * trial[t][1], default=None)
        if weakest is None:
            break
        gain, err, without = trial[weakest]
        for t, (g, e, _) in trial.items():
            comparisons[t] = {"delta_log_likelihood": g, "error": e, "kept": True}
        if gain > KEEP_SIGMAS * err and gain > 0:
            break
        comparisons[weakest]["kept"] = False
        terms.remove(weakest)
        best = without
    for t in fixed:
        comparisons.setdefault(t, {"delta_log_likelihood": None, "error": None, "kept": True})
        comparisons[t]["fixed_by_user"] = True
    return fit_terms(
        mom,
        basis,
        terms,
        lam,
        comparisons=comparisons,
        roughness=(grid, scores),
        fixed=tuple(fixed),
        pen=pen,
    )


def bounded(d: float, raw: float) -> float:
    """D freed of the drift, held within :data:`D_BOUNDS` of the steps' raw D.

    Where the drift within a frame is as large as the noise, the first-order correction is no
    longer small and iterating it can run away; the bounds keep it finite (and
    :mod:`skygas.inference.sampling` says the frames are too coarse).
    """
    lo, hi = D_BOUNDS
    return float(np.clip(d, lo * raw, hi * raw))


def fit_terms(
    mom: dyn.Moments,
    basis: ForceBasis,
    terms,
    lam: float,
    *,
    comparisons: dict | None = None,
    roughness: tuple[np.ndarray, np.ndarray] | None = None,
    fixed: tuple[str, ...] = (),
    pen: dyn.Penalty | None = None,
) -> ForceInference:
    """The model of ``terms`` fitted on all blocks, with its jackknife replicates.

    D and the forces are iterated to agreement (:data:`~.dynamics.D_ITERATIONS`); the
    leave-one-block-out fits give the jackknife errors. ``roughness``: the weights tried and
    their scores, to record.
    """
    grid, scores = roughness if roughness is not None else (np.zeros(0), np.zeros(0))
    nb = len(mom.count)
    everything = np.ones(nb, bool)
    terms = list(terms)
    pen = pen or dyn.penalty(basis, mom.total("gram", everything))
    d_raw, _ = dyn.diffusion_constant(mom, None, everything)
    cols, cons = basis.indices(terms), dyn.constraints(mom, basis, terms)

    def converged(blocks):
        raw, _ = dyn.diffusion_constant(mom, None, blocks)
        d = raw
        f = dyn.fit(mom, cols, blocks, d, pen, lam, cons)
        for _ in range(dyn.D_ITERATIONS):
            d = bounded(dyn.diffusion_constant(mom, f, blocks)[0], raw)
            f = dyn.fit(mom, cols, blocks, d, pen, lam, cons)
        d, s2 = dyn.diffusion_constant(mom, f, blocks)
        return f, bounded(d, raw), s2

    f, d, s2 = converged(everything)

    def leave_one_out(m: dyn.Moments):
        fits, ds, s2s = [], [], []
        for left in range(len(m.count)):
            train = np.ones(len(m.count), bool)
            train[left] = False
            # one round from the whole's D: the replicas differ from the whole by little
            fk = dyn.fit(m, cols, train, d, pen, lam, cons)
            dk, s2k = dyn.diffusion_constant(m, fk, train)
            dk = bounded(dk, dyn.diffusion_constant(m, None, train)[0])
            fits.append(dyn.fit(m, cols, train, dk, pen, lam, cons))
            ds.append(dk)
            s2s.append(s2k)
        return fits, np.array(ds), np.array(s2s)

    folds, d_folds, s2_folds = leave_one_out(mom)
    track_folds: list = []
    d_err, s2_err = jackknife_error(d_folds), jackknife_error(s2_folds)
    if mom.by_track is not None:
        track_folds, d_tracks, s2_tracks = leave_one_out(mom.by_track)
        d_err = max(d_err, jackknife_error(d_tracks))
        s2_err = max(s2_err, jackknife_error(s2_tracks))
    score = _score(mom, basis, terms, d, pen, lam)
    return ForceInference(
        basis,
        mom,
        f,
        folds,
        tuple(terms),
        comparisons or {},
        d_raw,
        d,
        float(d_err),
        s2,
        float(s2_err),
        lam,
        grid,
        scores,
        score,
        tuple(fixed),
        track_folds,
    )
