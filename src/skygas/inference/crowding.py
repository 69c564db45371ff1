"""The neighbours' share of the occupation, taken out by force balance.

In a gas the occupation ρ(r) of the tracks is not exp(−U(r)/k_BT): the neighbours push each
skyrmion about, and in a crowded film they even out the density (30 skyrmions in 1.44 µm² of S2
flatten a 1.5 k_BT landscape to half its amplitude in −ln ρ, 60 to a third). In equilibrium the
mean force on a skyrmion at r balances the gradient of the occupation (the first equation of the
Yvon–Born–Green hierarchy):

    k_BT ∇ln ρ(r) = −∇U(r) + f̄(r),     f̄(r) = ⟨Σ_j F_pair(r − r_j)⟩ at r,

the mean of the neighbours' pair forces on the skyrmions found at r. So

    U(r)/k_BT = −ln ρ(r) + Φ(r),        ∇Φ = f̄/k_BT,

and f̄ is measured on the movie's own frames: the pair force of every neighbour on every
tracked position, with the pair law the steps show (:mod:`skygas.inference.forces`), averaged with
the landscape's kernel. Φ is the least-squares potential of that field on the well-sampled
nodes (a sparse solve). No simulation enters, so no simulation noise does either. On a
round-trip gas of 30 skyrmions, −ln ρ has 0.49 of the true landscape's amplitude and a
correlation of 0.78 with it, U = −ln ρ + Φ 0.96 and 0.93 (docs/inference.md).

Near a wall the same balance, along the normal to the outline, gives the wall potential free of
the neighbours' layering (:func:`normal_component`, used by :mod:`skygas.inference.wall`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy import ndimage, sparse
from scipy.sparse.linalg import lsqr

from skygas.analysis.frames import Frames

#: A pair law: F(r) [k_BT/m] (positive: repulsive) of the distance r [m].
PairLaw = Callable[[np.ndarray], np.ndarray]


def pair_forces(frames: Frames, law: PairLaw, cutoff: float) -> tuple[np.ndarray, np.ndarray]:
    """Σ_j F(r_ij) r̂_ij [k_BT/m] on every entry from the others of its frame within ``cutoff``."""
    from scipy.spatial import cKDTree

    fx = np.zeros(len(frames.x))
    fy = np.zeros(len(frames.x))
    off = frames.offsets
    for f in range(frames.n_frames):
        lo, hi = off[f], off[f + 1]
        if hi - lo < 2:
            continue
        xy = np.column_stack([frames.x[lo:hi], frames.y[lo:hi]])
        pairs = cKDTree(xy).query_pairs(cutoff, output_type="ndarray")
        if len(pairs) == 0:
            continue
        i, j = pairs[:, 0], pairs[:, 1]
        d = xy[i] - xy[j]
        r = np.hypot(d[:, 0], d[:, 1])
        m = law(r) / np.maximum(r, 1e-30)
        np.add.at(fx, lo + i, m * d[:, 0])
        np.add.at(fy, lo + i, m * d[:, 1])
        np.add.at(fx, lo + j, -m * d[:, 0])
        np.add.at(fy, lo + j, -m * d[:, 1])
    return fx, fy


def mean_force_map(
    frames: Frames, grid, bandwidth: float, fx: np.ndarray, fy: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """f̄ (ny, nx) [k_BT/m]: the kernel-weighted mean of (fx, fy) over the positions near a node."""
    s = bandwidth / grid.h

    def smoothed(w):
        return ndimage.gaussian_filter(grid.bins(frames.x, frames.y, w), s, mode="constant")

    counts = smoothed(None)
    with np.errstate(invalid="ignore", divide="ignore"):
        return smoothed(fx) / counts, smoothed(fy) / counts


def potential_of(gx: np.ndarray, gy: np.ndarray, mask: np.ndarray, h: float) -> np.ndarray:
    """Φ (ny, nx), mean 0 on ``mask`` and NaN off it, with ∇Φ ≈ (gx, gy) by least squares.

    Each pair of neighbouring nodes both in ``mask`` gives one equation
    Φ_b − Φ_a = h·(g_a + g_b)/2 along their direction; solved by LSQR.
    """
    index = -np.ones(mask.shape, int)
    index[mask] = np.arange(int(mask.sum()))
    rows, cols, vals, rhs = [], [], [], []
    k = 0
    for axis, g in ((1, gx), (0, gy)):
        both = mask.copy()
        if axis == 1:
            both[:, :-1] &= mask[:, 1:]
            both[:, -1] = False
        else:
            both[:-1, :] &= mask[1:, :]
            both[-1, :] = False
        ja, ia = np.nonzero(both)
        jb, ib = (ja, ia + 1) if axis == 1 else (ja + 1, ia)
        target = 0.5 * (g[ja, ia] + g[jb, ib]) * h
        ok = np.isfinite(target)
        n = int(ok.sum())
        r = np.arange(k, k + n)
        rows += [r, r]
        cols += [index[jb[ok], ib[ok]], index[ja[ok], ia[ok]]]
        vals += [np.ones(n), -np.ones(n)]
        rhs.append(target[ok])
        k += n
    out = np.full(mask.shape, np.nan)
    if k == 0:
        out[mask] = 0.0
        return out
    a = sparse.csr_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
        shape=(k, int(mask.sum())),
    )
    phi = lsqr(a, np.concatenate(rhs), atol=1e-10, btol=1e-10, iter_lim=20 * int(mask.sum()))[0]
    out[mask] = phi - phi.mean()
    return out


def crowding_potential(
    frames: Frames, landscape, law: PairLaw, cutoff: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Φ [k_BT] on the landscape's grid (NaN off its well-sampled nodes), and (fx, fy) per entry.

    U = −ln ρ + Φ is the one-body potential with the neighbours' mean push taken out.
    """
    fx, fy = pair_forces(frames, law, cutoff)
    mx, my = mean_force_map(frames, landscape.grid, landscape.bandwidth, fx, fy)
    return potential_of(mx, my, landscape.well_sampled, landscape.grid.h), fx, fy


def normal_component(
    frames: Frames, grid, distance: np.ndarray, fx: np.ndarray, fy: np.ndarray
) -> np.ndarray:
    """The component [k_BT/m] of (fx, fy) along the outline's inward normal at each entry.

    ``distance`` (ny, nx) [m] the nodes' distance to the outline; the normal is its gradient.
    """
    gy, gx = np.gradient(distance, grid.h)
    norm = np.hypot(gx, gy)
    with np.errstate(invalid="ignore", divide="ignore"):
        nx, ny = gx / norm, gy / norm
    j, i = grid.node_of(frames.x, frames.y)
    return np.nan_to_num(fx * nx[j, i] + fy * ny[j, i])


#: The pair force is summed out to where it falls below this [k_BT/m] (0.001 k_BT/nm: over
#: 100 nm, a tenth of k_BT).
NEGLIGIBLE_FORCE = 1e6


def material_law(material: dict, base, temperature: float) -> PairLaw:
    """The pair law a model material runs with, in k_BT/m of r [m].

    Its ``pair_table`` (distance [m], force [N]; constant below the first distance, 0 beyond
    the last) if it has one, else the base material's paper law.
    """
    from skygas.core import units
    from skygas.physics.forces import paper_pair_force
    from skygas.physics.materials import derive_thiele

    kt = units.BOLTZMANN * temperature
    table = material.get("pair_table")
    if table is not None:
        r_t = np.asarray(table["distance"], float)
        f_t = np.asarray(table["force"], float) / kt
        return lambda r: np.interp(r, r_t, f_t, left=f_t[0], right=0.0)
    t = derive_thiele(base)
    a2, a1, a0 = base.pair_law
    return lambda r: t.force_scale * paper_pair_force(r / t.skyrmion_diameter, a2, a1, a0) / kt


def reach(law: PairLaw, r_min: float, r_max: float) -> float:
    """The distance [m] beyond which ``law`` stays below :data:`NEGLIGIBLE_FORCE` (≤ r_max)."""
    r = np.linspace(r_min, r_max, 400)
    strong = np.flatnonzero(np.abs(law(r)) >= NEGLIGIBLE_FORCE)
    return float(r[strong[-1]]) if len(strong) else r_min
