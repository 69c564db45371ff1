"""Basis functions for the forces of a tracked gas: a landscape, a pair law, a wall law.

The force on a skyrmion is written as a sum of known vector fields with unknown coefficients,
f(x) = Σ_k θ_k g_k(x) [k_BT/m], so that projecting the measured displacements onto the g_k
gives the θ_k (:mod:`skygas.inference.dynamics`). Three families, each a set of cubic B-splines
(smooth, local: a point touches four functions per axis):

- :class:`LandscapeBasis`: U(x, y) = Σ θ_k φ_k(x, y) [k_BT] on a tensor grid of cardinal cubic
  B-splines of spacing h over the film (periodic in a periodic film), g_k = −∇φ_k;
- :class:`RadialBasis` on a distance r: a pair force f(r) r̂ᵢⱼ summed over the neighbours, or a
  wall force f(d) n̂ along the inward normal of the outline.

Each evaluation returns the field g_k at the points and its divergence ∇·g_k, which the
Stratonovich form of the estimator needs (:mod:`skygas.inference.dynamics`).

The cardinal cubic B-spline centred on node j, with u = (x − x₀)/h − j + 2 ∈ [0, 4), is the
piecewise cubic whose pieces, for s the fractional part of u and the point between nodes i and
i + 1, weight nodes i − 1 … i + 2 by (1 − s)³/6, (3s³ − 6s² + 4)/6, (−3s³ + 3s² + 3s + 1)/6 and
s³/6 (de Boor, *A Practical Guide to Splines*, ch. IX).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse


def cubic_weights(s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Weights (n, 4) of nodes i − 1 … i + 2 at fraction ``s`` ∈ [0, 1), and their derivatives.

    Derivatives are with respect to the node index u (divide by h, h² for metres).
    """
    s = np.asarray(s, float)[:, None]
    t = 1.0 - s
    value = np.hstack([t**3, 3 * s**3 - 6 * s**2 + 4, -3 * s**3 + 3 * s**2 + 3 * s + 1, s**3]) / 6
    first = np.hstack([-(t**2), 3 * s**2 - 4 * s, -3 * s**2 + 2 * s + 1, s**2]) / 2
    second = np.hstack([t, 3 * s - 2, 1 - 3 * s, s])
    return value, first, second


@dataclass(frozen=True)
class Axis:
    """Nodes x₀ + j·h, j = 0 … n − 1 [m] of a cardinal cubic B-spline basis along one axis.

    ``periodic``: the basis wraps with period n·h (node n is node 0).
    """

    origin: float
    spacing: float
    count: int
    periodic: bool = False

    @classmethod
    def covering(cls, lo: float, hi: float, spacing: float) -> Axis:
        """Nodes whose functions sum to one everywhere on [lo, hi] (one node beyond each end)."""
        n = int(np.ceil((hi - lo) / spacing - 1e-9)) + 3
        return cls(lo - spacing, spacing, n)

    @classmethod
    def around(cls, origin: float, period: float, spacing: float) -> Axis:
        """A periodic axis of period ``period`` with nodes about ``spacing`` apart."""
        n = max(4, int(round(period / spacing)))
        return cls(origin, period / n, n, periodic=True)

    @property
    def nodes(self) -> np.ndarray:
        """Node positions [m]."""
        return self.origin + self.spacing * np.arange(self.count)

    def evaluate(self, x: np.ndarray) -> tuple[np.ndarray, tuple[np.ndarray, ...]]:
        """Node indices (n, 4) touched by each point and weights (value, d/dx, d²/dx²) (n, 4)."""
        u = (np.asarray(x, float) - self.origin) / self.spacing
        i = np.floor(u).astype(np.int64)
        value, first, second = cubic_weights(u - i)
        idx = i[:, None] + np.arange(-1, 3)[None, :]
        if self.periodic:
            idx = np.mod(idx, self.count)
        else:
            # points beyond the covered range lean on the end nodes' functions (weights clipped
            # to the grid): the basis is only used inside the film, where this never happens
            bad = (idx < 0) | (idx >= self.count)
            if bad.any():
                idx = np.clip(idx, 0, self.count - 1)
                value, first, second = (np.where(bad, 0.0, w) for w in (value, first, second))
        return idx, (value, first / self.spacing, second / self.spacing**2)

    def second_difference(self) -> sparse.csr_matrix:
        """The second-difference operator on the node coefficients (wrapping if periodic)."""
        n = self.count
        if self.periodic:
            rows = np.repeat(np.arange(n), 3)
            cols = np.mod(rows + np.tile([-1, 0, 1], n), n)
            vals = np.tile([1.0, -2.0, 1.0], n)
            return sparse.csr_matrix((vals, (rows, cols)), shape=(n, n))
        return sparse.diags([1.0, -2.0, 1.0], [0, 1, 2], shape=(max(n - 2, 0), n), format="csr")


@dataclass(frozen=True)
class Fields:
    """Vector fields g_k at N points: x and y components (N, K) and divergences (N, K), sparse."""

    gx: sparse.csr_matrix
    gy: sparse.csr_matrix
    div: sparse.csr_matrix

    @staticmethod
    def stack(parts: list[Fields]) -> Fields:
        """The fields of several bases side by side (columns in order)."""
        return Fields(
            sparse.hstack([p.gx for p in parts], format="csr"),
            sparse.hstack([p.gy for p in parts], format="csr"),
            sparse.hstack([p.div for p in parts], format="csr"),
        )


@dataclass(frozen=True)
class LandscapeBasis:
    """U(x, y) = Σ θ_k φ_k(x, y) [k_BT]: tensor cubic B-splines on ``ax`` × ``ay``.

    Coefficient k = j_y · n_x + j_x. The force fields are g_k = −∇φ_k, with ∇·g_k = −∇²φ_k.
    """

    ax: Axis
    ay: Axis

    @property
    def size(self) -> int:
        """Number of functions."""
        return self.ax.count * self.ay.count

    @property
    def shape(self) -> tuple[int, int]:
        """(n_y, n_x) of the coefficient grid."""
        return self.ay.count, self.ax.count

    def _products(self, x, y):
        ix, (vx, dx, ddx) = self.ax.evaluate(x)
        iy, (vy, dy, ddy) = self.ay.evaluate(y)
        cols = (iy[:, :, None] * self.ax.count + ix[:, None, :]).reshape(len(ix), 16)

        def outer(a, b):
            return (a[:, :, None] * b[:, None, :]).reshape(len(ix), 16)

        return cols, outer(vy, vx), outer(vy, dx), outer(dy, vx), outer(vy, ddx) + outer(ddy, vx)

    def _matrix(self, cols: np.ndarray, vals: np.ndarray) -> sparse.csr_matrix:
        n = len(cols)
        indptr = np.arange(0, 16 * n + 1, 16)
        m = sparse.csr_matrix((vals.ravel(), cols.ravel(), indptr), shape=(n, self.size))
        m.sum_duplicates()  # a small periodic axis can touch one node twice
        return m

    def values(self, x, y) -> sparse.csr_matrix:
        """φ_k at the points (N, K)."""
        cols, v, *_ = self._products(np.ravel(x), np.ravel(y))
        return self._matrix(cols, v)

    def fields(self, x, y) -> Fields:
        """g_k = −∇φ_k and ∇·g_k = −∇²φ_k at the points."""
        cols, _, gx, gy, lap = self._products(np.ravel(x), np.ravel(y))
        return Fields(self._matrix(cols, -gx), self._matrix(cols, -gy), self._matrix(cols, -lap))

    def roughness(self) -> sparse.csr_matrix:
        """The P-spline penalty matrix: squared second differences along x and y, and mixed.

        θᵀPθ approximates ∫ (U_xx² + 2U_xy² + U_yy²) dA up to a scale (Eilers & Marx, *Statist.
        Sci.* 11, 89 (1996)); its null space is the constant and the linear functions.
        """
        ix, iy = sparse.identity(self.ax.count), sparse.identity(self.ay.count)
        dxx = sparse.kron(iy, self.ax.second_difference())
        dyy = sparse.kron(self.ay.second_difference(), ix)
        d1x = _first_difference(self.ax)
        d1y = _first_difference(self.ay)
        dxy = sparse.kron(d1y, d1x)
        return (dxx.T @ dxx + dyy.T @ dyy + 2 * dxy.T @ dxy).tocsr()

    def grid(self, x: np.ndarray, y: np.ndarray, theta: np.ndarray) -> np.ndarray:
        """U [k_BT] on the grid x (nx,) × y (ny,) → (ny, nx)."""
        gx, gy = np.meshgrid(x, y)
        return (self.values(gx, gy) @ theta).reshape(gx.shape)


def _first_difference(axis: Axis) -> sparse.csr_matrix:
    n = axis.count
    if axis.periodic:
        return (sparse.eye(n, k=1, format="csr") + sparse.eye(n, k=1 - n) - sparse.eye(n)).tocsr()
    return sparse.diags([-1.0, 1.0], [0, 1], shape=(n - 1, n), format="csr")


@dataclass(frozen=True)
class RadialBasis:
    """f(r) = Σ θ_k ψ_k(r) on [``lo``, ``hi``] [m]: cubic B-splines that vanish at ``hi``.

    ``count`` cardinal splines on knots h = (s(hi) − s(lo))/count apart in s(r), centred from
    s(lo) − h to s(hi) − 2h: none reaches past ``hi``, so f and f′ are 0 at hi and beyond (a
    force that ends smoothly). s(r) = r, or ln r with ``logarithmic`` (knots closer together
    near ``lo``, where a repulsion changes fastest). Below ``lo`` each function continues with
    its value and slope at lo: the data there are few, and the basis must not fall to zero
    inside the closest distance seen.
    """

    lo: float
    hi: float
    count: int
    logarithmic: bool = False

    def _s(self, r):
        return np.log(r) if self.logarithmic else np.asarray(r, float)

    @property
    def spacing(self) -> float:
        """Knot spacing h in s(r)."""
        return float(self._s(self.hi) - self._s(self.lo)) / self.count

    @property
    def size(self) -> int:
        """Number of functions."""
        return self.count

    def evaluate(self, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """ψ_k(r) and dψ_k/dr (N, K) dense."""
        r = np.asarray(r, float)
        h = self.spacing
        below = r < self.lo
        at = np.where(below, self.lo, np.maximum(r, 1e-300))
        # node k sits at u = k: function k is centred on s(lo) + (k − 1) h, so the last one,
        # centred 2h before s(hi), ends at hi
        u = (self._s(at) - float(self._s(self.lo))) / h + 1.0
        i = np.floor(u).astype(np.int64)
        w, dw, _ = cubic_weights(u - i)
        k = i[:, None] + np.arange(-1, 3)[None, :]
        ok = (k >= 0) & (k < self.count)
        rows = np.broadcast_to(np.arange(len(r))[:, None], k.shape)
        value = np.zeros((len(r), self.count))
        slope = np.zeros((len(r), self.count))
        value[rows[ok], k[ok]] = w[ok]
        # d/dr = d/du · du/ds · ds/dr
        ds_dr = 1.0 / at if self.logarithmic else np.ones_like(at)
        slope[rows[ok], k[ok]] = (dw * (ds_dr / h)[:, None])[ok]
        if below.any():
            # below lo, each function continues linearly from its value and slope at lo
            value[below] += slope[below] * (r[below] - self.lo)[:, None]
        return value, slope

    def force(self, r, theta) -> np.ndarray:
        """f(r) = Σ θ_k ψ_k(r)."""
        return self.evaluate(np.atleast_1d(r))[0] @ theta

    def second_difference(self) -> sparse.csr_matrix:
        """Second differences of the coefficients (a roughness penalty)."""
        n = self.count
        return sparse.diags([1.0, -2.0, 1.0], [0, 1, 2], shape=(max(n - 2, 0), n), format="csr")
