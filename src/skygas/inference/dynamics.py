"""Forces, the Hall angle and D from the displacements: Stochastic Force Inference for skyrmions.

A skyrmion obeys the overdamped Thiele equation (docs/physics.md §1). Written with its free
diffusion constant D and its Hall angle θ_H (t = tan θ_H), the drift of a skyrmion at x is

    v(x) = D (I − t ε) f(x),       ε = [[0, 1], [−1, 0]],

with f the force in units of k_BT/m and a thermal noise of covariance 2D per coordinate, D being
the symmetric part of the mobility times k_BT (the fluctuation–dissipation theorem). The force is
expanded in basis fields, f = Σ θ_k g_k (:mod:`skygas.inference.force_basis`), and the
coefficients follow from projecting the displacements onto them, as Stochastic Force Inference
does (Frishman & Ronceray, Phys. Rev. X 10, 021009 (2020)):

- **the moments** ⟨v·g_k⟩ in their Stratonovich form, which is blind to the localisation error
  of the tracked positions (the error at the start and at the end of a step enter with opposite
  signs and cancel):

      M_k = Σ ½ Δ·(g_k(x_t) + g_k(x_{t+1}))/Δt − D Σ ∇·g_k(x_t),
      N_k = Σ ½ Δ·ε(g_k(x_t) + g_k(x_{t+1}))/Δt       (∇·εg_k = 0 for every basis field),

  and the Gram matrix G_kl = Σ g_k·g_l at the steps' starts;
- **the Hall angle with the forces**: minimising Σ |v − D(I − tε)Σθ_k g_k|² + penalty over θ
  for a given t gives θ = A⁻¹(M − tN)/(D(1 + t²)) with A = G + λR (R the landscape's roughness,
  scaled by the same D²(1 + t²) as G), and what is left to maximise over t,
  (M − tN)ᵀA⁻¹(M − tN)/(1 + t²), is a Rayleigh quotient in (1, −t): t follows from the top
  eigenvector of the 2×2 matrix [[MᵀA⁻¹M, MᵀA⁻¹N], [NᵀA⁻¹M, NᵀA⁻¹N]], in closed form. A
  uniform force rotated by ε is another uniform force, so a drive alone says nothing about t;
  a landscape (a gradient field) and a pair or wall force (central fields) fix it;
- **D** from the noise, by the covariance estimator of Vestergaard, Blainey & Flyvbjerg
  (Phys. Rev. E 89, 022726 (2014)), blind to the localisation error,
  D_raw = (⟨|Δ_t|²⟩ + 2⟨Δ_t·Δ_{t−1}⟩)/(4Δt), then freed of the drift it picks up to first order
  in Δt: D = D_raw − Δt(⟨|v_t|²⟩/4 + ⟨v_t·v_{t−1}⟩/2 + D⟨∇·v⟩). A gyrotropic skyrmion drifts
  fast across the forces, |v|² = D²(1 + t²)|f|² (t = 4.3 for the paper's S2), so this term
  matters; the estimate and the forces are iterated to agreement
  (:data:`D_ITERATIONS`).

All sums are kept per contiguous block of time (:data:`BLOCKS`), so that leaving blocks out
gives the held-out score of a model (cross-validation: the roughness weight λ, and which terms a
model has) and the jackknife errors of everything derived from θ, t and D.

The held-out score is the log-likelihood of the left-out displacements under the short-time
propagator Δ ~ N(vΔt, 2DΔt I) relative to a model with no force: ln L = −Δt J/(4D) with
J = Σ |v̂|² − 2v·v̂, whose expectation is computed from the held-out block's moments (the same
Stratonovich form, so the localisation error does not reward a model).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.sparse import linalg as splinalg

from skygas.analysis.frames import Frames
from skygas.inference.diffusion import block_of_frame
from skygas.inference.film import Film, unwrapped_steps
from skygas.inference.force_basis import ForceBasis, neighbour_pairs

#: Contiguous blocks of time: the folds of the cross-validation and of the jackknife.
BLOCKS = 16
#: Groups of tracks: a second jackknife, over which skyrmions are seen. Where skyrmions stay in
#: their wells for the whole movie, the blocks of time all see the same skyrmions in the same
#: places (and the same neighbours), and a jackknife over time alone misses that the landscape
#: there rests on one skyrmion's visit. Used where there are at least this many tracks.
TRACK_GROUPS = 16
#: Rounds of (forces → D → forces).
D_ITERATIONS = 3
#: The landscape coefficients' ridge, relative to the Gram matrix's mean diagonal.
LANDSCAPE_RIDGE = 1e-6


@dataclass(frozen=True)
class Steps:
    """The displacements used: entry ``a`` at frame t, ``b`` at t + 1, ``c`` at t − 1.

    ``dx``, ``dy`` [m] the step a → b, ``px``, ``py`` the step c → a (unwrapped);
    ``block`` the block of time of each step; ``group`` its group of tracks (0 … ``groups`` − 1;
    ``groups`` = 0 where there are too few tracks); ``dt`` [s].
    """

    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    dx: np.ndarray
    dy: np.ndarray
    px: np.ndarray
    py: np.ndarray
    block: np.ndarray
    blocks: int
    dt: float
    group: np.ndarray
    groups: int

    def __len__(self) -> int:
        return len(self.a)


def make_steps(frames: Frames, film: Film, keep=None, blocks: int = BLOCKS) -> Steps:
    """Every step a → b with a step c → a before it; ``keep(a)`` (E,) → bool selects starts."""
    a, b = frames.pairs_at_lag(1)
    c, a2 = frames.pairs_at_lag(1)
    # the step before a: the pair (c, a) whose end is a
    order = np.argsort(a2)
    where = np.searchsorted(a2[order], a)
    where = np.minimum(where, len(a2) - 1)
    has = a2[order][where] == a if len(a2) else np.zeros(len(a), bool)
    a, b, c = a[has], b[has], c[order][where][has]
    if keep is not None:
        ok = keep[a]
        a, b, c = a[ok], b[ok], c[ok]
    order = np.argsort(frames.frame_of_entry[a], kind="stable")
    a, b, c = a[order], b[order], c[order]
    dx, dy = unwrapped_steps(film, frames, a, b)
    px, py = unwrapped_steps(film, frames, c, a)
    block = block_of_frame(frames.n_frames, blocks)[frames.frame_of_entry[a]]
    group, groups = track_groups(frames.ids[a])
    return Steps(a, b, c, dx, dy, px, py, block, blocks, frames.frame_interval(), group, groups)


def track_groups(ids: np.ndarray, groups: int = TRACK_GROUPS) -> tuple[np.ndarray, int]:
    """(the group of each step's track, the number of groups).

    Tracks are dealt to ``groups`` groups in a fixed shuffled order (neighbouring ids are often
    neighbouring skyrmions); no groups (all −1, 0) with fewer tracks than groups.
    """
    uniq, inverse = np.unique(ids, return_inverse=True)
    if len(uniq) < groups:
        return np.full(len(ids), -1), 0
    order = np.random.default_rng(0).permutation(len(uniq))
    return (order * groups // len(uniq))[inverse], groups


@dataclass
class Moments:
    """Per-block sums over the steps (B blocks, K coefficients).

    ``count`` (B,); ``square`` Σ|Δ_t|², ``lagged`` Σ Δ_t·Δ_{t−1} (B,); ``strat`` Σ ½Δ·(g_a + g_b),
    ``rot`` Σ ½Δ·ε(g_a + g_b), ``div`` Σ ∇·g_a (B, K); ``gram`` Σ g_a g_aᵀ and ``lag``
    Σ ½(g_a g_cᵀ + g_c g_aᵀ) (B sparse K × K), every product summed over both coordinates.
    """

    count: np.ndarray
    square: np.ndarray
    lagged: np.ndarray
    strat: np.ndarray
    rot: np.ndarray
    div: np.ndarray
    gram: list
    lag: list
    dt: float
    #: the same sums per group of tracks (:data:`TRACK_GROUPS`), or None with too few tracks
    by_track: Moments | None = None

    def total(self, part: str, blocks: np.ndarray):
        """The sum of ``part`` over the chosen blocks (a boolean mask).

        Sums over most blocks are the whole's minus the few left out (the whole is kept).
        """
        values = getattr(self, part)
        blocks = np.asarray(blocks, bool)
        whole = self._whole.get(part)
        if whole is None:
            whole = sum(values[1:], values[0]) if isinstance(values, list) else values.sum(axis=0)
            self._whole[part] = whole
        if blocks.all():
            return whole
        if isinstance(values, list):
            if blocks.sum() > len(blocks) // 2:
                out = whole
                for m in (m for m, keep in zip(values, blocks, strict=True) if not keep):
                    out = out - m
                return out
            picked = [m for m, keep in zip(values, blocks, strict=True) if keep]
            return sum(picked[1:], picked[0])
        return values[blocks].sum(axis=0)

    def __post_init__(self) -> None:
        self._whole: dict = {}


def _empty_moments(k: int, nb: int, dt: float) -> Moments:
    return Moments(
        np.zeros(nb),
        np.zeros(nb),
        np.zeros(nb),
        np.zeros((nb, k)),
        np.zeros((nb, k)),
        np.zeros((nb, k)),
        [sparse.csr_matrix((k, k)) for _ in range(nb)],
        [sparse.csr_matrix((k, k)) for _ in range(nb)],
        dt,
    )


def _add_sums(out: Moments, i: int, rows, g, ia, ib, ic, steps: Steps, sel) -> None:
    """Add the sums over ``rows`` (of ``sel``) to slot ``i`` of ``out``."""
    dx, dy = steps.dx[sel][rows], steps.dy[sel][rows]
    ia, ib, ic = ia[rows], ib[rows], ic[rows]
    ax, ay = g.gx[ia], g.gy[ia]
    sx, sy = ax + g.gx[ib], ay + g.gy[ib]
    out.count[i] += len(dx)
    out.square[i] += float(np.sum(dx * dx + dy * dy))
    out.lagged[i] += float(np.sum(dx * steps.px[sel][rows] + dy * steps.py[sel][rows]))
    out.strat[i] += 0.5 * (sx.T @ dx + sy.T @ dy)
    out.rot[i] += 0.5 * (sy.T @ dx - sx.T @ dy)
    out.div[i] += np.asarray(g.div[ia].sum(axis=0)).ravel()
    out.gram[i] = (out.gram[i] + (ax.T @ ax + ay.T @ ay)).tocsr()
    cx, cy = g.gx[ic], g.gy[ic]
    cross = ax.T @ cx + ay.T @ cy
    out.lag[i] = (out.lag[i] + 0.5 * (cross + cross.T)).tocsr()


def accumulate(frames: Frames, steps: Steps, basis: ForceBasis, progress=None) -> Moments:
    """The per-block sums of :class:`Moments` for ``basis`` over ``steps``.

    Also per group of tracks (``by_track``), where there are enough tracks.
    """
    k, nb = basis.size, steps.blocks
    out = _empty_moments(k, nb, steps.dt)
    if steps.groups:
        out.by_track = _empty_moments(k, steps.groups, steps.dt)
    fof = frames.frame_of_entry
    for blk in range(nb):
        sel = np.flatnonzero(steps.block == blk)
        if len(sel) == 0:
            continue
        a, b, c = steps.a[sel], steps.b[sel], steps.c[sel]
        entries = np.unique(np.concatenate([a, b, c]))
        first = int(fof[entries].min())
        last = int(fof[entries].max())
        pairs = neighbour_pairs(frames, basis.film, first, last, basis.pair_range)
        g = basis.fields(frames, entries, pairs)
        ia, ib, ic = (np.searchsorted(entries, e) for e in (a, b, c))
        _add_sums(out, blk, slice(None), g, ia, ib, ic, steps, sel)
        if out.by_track is not None:
            group = steps.group[sel]
            for grp in np.unique(group):
                rows = np.flatnonzero(group == grp)
                _add_sums(out.by_track, int(grp), rows, g, ia, ib, ic, steps, sel)
        if progress is not None:
            progress(blk + 1, nb)
    return out


@dataclass(frozen=True)
class Fit:
    """θ (K,) [k_BT/m per basis unit, zero outside ``columns``], t = tan θ_H, D [m²/s]."""

    theta: np.ndarray
    tan_hall: float
    diffusion: float
    columns: np.ndarray
    roughness: float

    @property
    def hall_angle(self) -> float:
        """θ_H [rad]."""
        return float(np.arctan(self.tan_hall))


@dataclass(frozen=True)
class Penalty:
    """The landscape's roughness R and the ridges that fix what the data cannot (K × K).

    ``roughness`` is scaled by λ; ``ridge`` is fixed: a small one on the landscape's
    coefficients (:data:`LANDSCAPE_RIDGE`: the constant, which no force sees, and the uniform
    force, which a drive carries) and a whisper on every other coefficient, so that columns
    nothing sampled stay determined.
    """

    roughness: sparse.csr_matrix
    ridge: sparse.csr_matrix

    def matrix(self, lam: float, scale: float) -> sparse.csr_matrix:
        """λR + ridge, both times ``scale`` (the training set's share of the whole)."""
        return (scale * (lam * self.roughness + self.ridge)).tocsr()


def penalty(basis: ForceBasis, gram: sparse.csr_matrix) -> Penalty:
    """The :class:`Penalty` of ``basis``, scaled to its Gram matrix ``gram`` (all steps)."""
    k = basis.size
    diag = gram.diagonal()
    rough = sparse.csr_matrix((k, k))
    # each column's whisper relative to its own weight in the data (columns differ in scale by
    # many orders: a landscape field is ~1/h, a pair field ~1); unsampled columns get the mean's
    floor = float(np.mean(diag[diag > 0])) if np.any(diag > 0) else 1.0
    ridge = sparse.diags(1e-9 * np.where(diag > 0, diag, floor), format="csr")
    if basis.landscape is not None:
        cols = basis.indices(["landscape"])
        land = basis.landscape
        r = land.roughness()
        g_scale = float(np.mean(diag[cols])) if len(cols) else 1.0
        r_scale = float(np.mean(r.diagonal())) or 1.0
        embed = sparse.csr_matrix(
            (np.ones(len(cols)), (cols, np.arange(len(cols)))), shape=(k, len(cols))
        )
        rough = (embed @ (r * (g_scale / r_scale)) @ embed.T).tocsr()
        # the constant, which no force sees, and with a drive the uniform force, which the
        # drive carries unpenalised: a small ridge on the landscape's coefficients fixes both
        # (a ramp across the film has large coefficients) and leaves the sampled features as
        # they are (a shrinkage of 1e-6 where the data weigh in)
        ridge = ridge + (embed @ (LANDSCAPE_RIDGE * g_scale * embed.T)).tocsr()
    return Penalty(rough, ridge.tocsr())


def constraints(mom: Moments, basis: ForceBasis, terms) -> np.ndarray:
    """Rows C (c × K) with C θ = 0 that keep the landscape apart from a wall and a drive.

    A wall and a landscape can both push a skyrmion away from the edge, and a drive and a
    landscape can both push it one way across the film. The wall is what no landscape of
    statistically uniform pinning does: push on average along the edge's normal; the drive is
    the uniform force. So the landscape's force is held orthogonal, over the tracked positions,
    to the wall's fields and to the drive's: Σ g_land · g_wall θ_land = 0, i.e. the rows of the
    Gram matrix that couple them (in a periodic film a landscape has no mean force anyway, and
    the drive's rows are left out).

    The rows are those of every wall or drive *candidate* of ``basis``, whether or not
    ``terms`` has it: a model without the wall is then a film whose edge does not push, not one
    whose landscape pushes instead, and the held-out score that compares them asks the right
    question. Empty without a landscape in ``terms``.
    """
    others = [t for t in ("wall", "drive") if basis.has(t)]
    periodic = basis.landscape is not None and basis.landscape.ax.periodic
    if periodic and "drive" in others:
        others.remove("drive")
    if "landscape" not in set(terms) or not basis.has("landscape") or not others:
        return np.zeros((0, basis.size))
    gram = mom.total("gram", np.ones(len(mom.count), bool))
    land = basis.indices(["landscape"])
    rows = gram[basis.indices(others)][:, land].toarray()
    out = np.zeros((len(rows), basis.size))
    out[:, land] = rows
    return out / np.maximum(np.linalg.norm(out, axis=1, keepdims=True), 1e-300)


def _solve(a: sparse.csr_matrix, rhs: np.ndarray, constraints: np.ndarray | None = None):
    """X minimising xᵀAx − 2xᵀb for each column b of ``rhs``, subject to C x = 0.

    A symmetric positive definite (scaled to unit diagonal, sparse LU); with constraints C (c ×
    K) the augmented system [[A, Cᵀ], [C, 0]] [x; μ] = [b; 0].
    """
    d = a.diagonal()
    s = 1.0 / np.sqrt(np.where(d > 0, d, 1.0))
    scaled = sparse.diags(s) @ a @ sparse.diags(s)
    b = s[:, None] * rhs
    c = 0 if constraints is None else len(constraints)
    if constraints is not None and c:
        rows = constraints * s[None, :]
        rows = rows / np.maximum(np.linalg.norm(rows, axis=1, keepdims=True), 1e-300)
        cs = sparse.csr_matrix(rows)
        scaled = sparse.bmat([[scaled, cs.T], [cs, None]], format="csc")
        b = np.vstack([b, np.zeros((c, rhs.shape[1]))])
    lu = splinalg.splu(scaled.tocsc())
    x = lu.solve(b)
    return s[:, None] * x[: len(s)]


def _sub(matrix, columns: np.ndarray, k: int):
    """The rows and columns ``columns`` of a K × K matrix (itself when they are all)."""
    return matrix if len(columns) == k else matrix[columns][:, columns]


def fit(
    mom: Moments,
    columns: np.ndarray,
    blocks: np.ndarray,
    diffusion: float,
    pen: Penalty,
    lam: float,
    constraints: np.ndarray | None = None,
) -> Fit:
    """θ and t from the moments of ``blocks`` (mask) for the model of ``columns``.

    ``constraints`` (c × K): C θ = 0 (:meth:`~skygas.inference.force_basis.ForceBasis.constraints`).
    """
    k = mom.strat.shape[1]
    theta = np.zeros(k)
    scale = float(mom.count[blocks].sum() / mom.count.sum())
    if len(columns) == 0:
        return Fit(theta, 0.0, diffusion, columns, lam)
    g = mom.total("gram", blocks)
    m = (mom.total("strat", blocks) / mom.dt - diffusion * mom.total("div", blocks))[columns]
    n = (mom.total("rot", blocks) / mom.dt)[columns]
    a = _sub(g + pen.matrix(lam, scale), columns, k)
    cons = None if constraints is None or not len(constraints) else constraints[:, columns]
    u, w = _solve(a, np.column_stack([m, n]), cons).T
    s = np.array([[m @ u, m @ w], [n @ u, n @ w]])
    vals, vecs = np.linalg.eigh(0.5 * (s + s.T))
    e1, e2 = vecs[:, int(np.argmax(vals))]
    t = float(-e2 / e1) if e1 != 0 else 0.0
    theta[columns] = (u - t * w) / (diffusion * (1 + t * t))
    return Fit(theta, t, diffusion, columns, lam)


def held_out(mom: Moments, f: Fit, blocks: np.ndarray) -> float:
    """J = Σ |v̂|² − 2v·v̂ [m²/s²] of ``f`` over ``blocks`` (lower is better)."""
    d, t = f.diffusion, f.tan_hall
    cols = f.columns
    if len(cols) == 0:
        return 0.0
    th = f.theta
    g = mom.total("gram", blocks)
    m = mom.total("strat", blocks) / mom.dt - d * mom.total("div", blocks)
    n = mom.total("rot", blocks) / mom.dt
    return float(d * d * (1 + t * t) * th @ (g @ th) - 2 * d * th @ (m - t * n))


def log_likelihood(j: float, diffusion: float, dt: float) -> float:
    """Held-out ln L relative to no force, from J (:func:`held_out`)."""
    return -dt * j / (4 * diffusion)


@dataclass(frozen=True)
class Score:
    """A model's held-out log-likelihood gain over no force: total and per block (nats)."""

    total: float
    per_block: np.ndarray
    folds: list

    def minus(self, other: Score) -> tuple[float, float]:
        """(ln L − ln L_other, its standard error) from the per-block differences."""
        diff = self.per_block - other.per_block
        nb = len(diff)
        return float(diff.sum()), float(np.sqrt(nb) * np.std(diff, ddof=1))


def fold_masks(blocks: int, folds: int) -> list[np.ndarray]:
    """``folds`` test sets of contiguous blocks (masks over the ``blocks`` blocks)."""
    group = (np.arange(blocks) * folds) // blocks
    return [group == k for k in range(folds)]


def cross_validate(
    mom: Moments,
    columns: np.ndarray,
    diffusion: float,
    pen: Penalty,
    lam: float,
    folds: int = BLOCKS,
    constraints: np.ndarray | None = None,
) -> Score:
    """Leave each fold of blocks out in turn; score it by the fit of the others."""
    tests = fold_masks(len(mom.count), folds)
    per = np.zeros(len(tests))
    fits = []
    for k, test in enumerate(tests):
        f = fit(mom, columns, ~test, diffusion, pen, lam, constraints)
        per[k] = log_likelihood(held_out(mom, f, test), diffusion, mom.dt)
        fits.append(f)
    return Score(float(per.sum()), per, fits)


def diffusion_constant(mom: Moments, f: Fit | None, blocks: np.ndarray) -> tuple[float, float]:
    """(D [m²/s], σ² [m²]) over ``blocks``: the covariance estimator, freed of the drift of ``f``.

    Without a fit, the raw estimator. σ² is the localisation error's variance per coordinate.
    """
    dt = mom.dt
    n = mom.count[blocks].sum()
    sq = mom.square[blocks].sum() / n
    lagged = mom.lagged[blocks].sum() / n
    d = (sq + 2 * lagged) / (4 * dt)
    if f is None or len(f.columns) == 0:
        return float(d), float(-lagged / 2)
    cols, th = f.columns, f.theta[f.columns]
    scale = f.diffusion**2 * (1 + f.tan_hall**2)
    v2 = scale * th @ (mom.total("gram", blocks)[cols][:, cols] @ th) / n
    v_lag = scale * th @ (mom.total("lag", blocks)[cols][:, cols] @ th) / n
    div_v = f.diffusion * th @ mom.total("div", blocks)[cols] / n
    d_free = d - dt * (v2 / 4 + v_lag / 2 + f.diffusion * div_v)
    sigma2 = (v_lag * dt * dt + 2 * f.diffusion * dt * dt * div_v - lagged) / 2
    return float(d_free), float(sigma2)
