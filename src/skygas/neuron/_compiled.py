r"""Compiled parts of the neuron's per-step work (private; internal units nm, ns or s as named).

The model is documented in :mod:`skygas.neuron.annihilation` and :mod:`skygas.neuron.gate`;
these functions only do its arithmetic. They run every ``check_interval`` (by default every
time step), so they avoid per-call allocations beyond a few arrays of length N and find the
pairs within reach with a cell list (cells no smaller than the reach, so the search is linear
in N).

Random draws come from the caller's :class:`numpy.random.Generator`, passed in: numba advances
the same bit generator with the same algorithms as NumPy, so a draw made here is the draw NumPy
would have made, and the run stays reproducible from its seed.
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(inline="always")
def _bilinear(field, x0, y0, spacing, x, y):
    """Bilinear interpolation of ``field`` (ny, nx) at (x, y) nm, clamped to the grid.

    The arithmetic of :func:`skygas.fields.wall_field.bilinear_at_indices`.
    """
    ny, nx = field.shape
    fx = min(max((x - x0) / spacing, 0.0), nx - 1 - 1e-9)
    fy = min(max((y - y0) / spacing, 0.0), ny - 1 - 1e-9)
    i = int(fx)
    j = int(fy)
    tx = fx - i
    ty = fy - j
    return (
        (1 - tx) * (1 - ty) * field[j, i]
        + tx * (1 - ty) * field[j, i + 1]
        + (1 - tx) * ty * field[j + 1, i]
        + tx * ty * field[j + 1, i + 1]
    )


@numba.njit(cache=True)
def _pairs_within(px, py, reach):
    """All pairs (a < b) of points closer than ``reach`` [nm], with their distances.

    Sorted by (a, b) so that the result does not depend on the cell layout.
    """
    n = px.shape[0]
    empty_i = np.empty(0, np.int64)
    if n < 2:
        return empty_i, empty_i, np.empty(0)
    xmin, xmax, ymin, ymax = px.min(), px.max(), py.min(), py.max()
    cell = reach
    # Cells at least as large as the reach; a few more cells than points at most, so that a
    # sparse gas spread over a large device does not allocate a big empty grid.
    while (int((xmax - xmin) / cell) + 1) * (int((ymax - ymin) / cell) + 1) > 4 * n + 16:
        cell *= 2.0
    ncx = int((xmax - xmin) / cell) + 1
    ncy = int((ymax - ymin) / cell) + 1
    head = np.full(ncx * ncy, -1, np.int64)
    nxt = np.empty(n, np.int64)
    cx = np.empty(n, np.int64)
    cy = np.empty(n, np.int64)
    for k in range(n - 1, -1, -1):  # reverse, so each cell's chain runs in ascending order
        cx[k] = min(int((px[k] - xmin) / cell), ncx - 1)
        cy[k] = min(int((py[k] - ymin) / cell), ncy - 1)
        c = cy[k] * ncx + cx[k]
        nxt[k] = head[c]
        head[c] = k
    reach2 = reach * reach
    # two passes: count, then fill (no growing buffers)
    total = 0
    for sweep in range(2):
        if sweep == 1:
            pa = np.empty(total, np.int64)
            pb = np.empty(total, np.int64)
            pr = np.empty(total)
        m = 0
        for a in range(n):
            for dy in range(-1, 2):
                jy = cy[a] + dy
                if jy < 0 or jy >= ncy:
                    continue
                for dx in range(-1, 2):
                    jx = cx[a] + dx
                    if jx < 0 or jx >= ncx:
                        continue
                    b = head[jy * ncx + jx]
                    while b >= 0:
                        if b > a:
                            ddx = px[b] - px[a]
                            ddy = py[b] - py[a]
                            r2 = ddx * ddx + ddy * ddy
                            if r2 < reach2:
                                if sweep == 1:
                                    pa[m] = a
                                    pb[m] = b
                                    pr[m] = math.sqrt(r2)
                                m += 1
                        b = nxt[b]
        total = m
    order = np.argsort(pa * n + pb)
    return pa[order], pb[order], pr[order]


@numba.njit(cache=True)
def _frozen_state(
    x, y, alive, wall_distance, grid_x0, grid_y0, grid_spacing, crowding, collapse, sensitivity
):
    """What the rule needs at the check time: occupied slots, wall distances and pairs in reach.

    The occupied slots, their wall distances [nm] and the pairs (indices into the slots, distance
    [nm]) within reach of either length.
    """
    slots = np.flatnonzero(alive)
    n = slots.shape[0]
    px = x[slots]
    py = y[slots]
    wall = np.empty(n)
    for k in range(n):
        wall[k] = _bilinear(wall_distance, grid_x0, grid_y0, grid_spacing, px[k], py[k])
    reach = max(crowding, collapse) if sensitivity > 0 else collapse
    pa, pb, pr = _pairs_within(px, py, reach)
    return slots, wall, pa, pb, pr


@numba.njit(cache=True)
def _rates(wall, pa, pb, pr, dead, crowding, base_rate, sensitivity):
    """Γ_i = Γ0 exp(c χ_i) [1/s] of every slot, with the ``dead`` ones left out of χ.

    Plus the χ values and the adjacency (CSR: start, partner, weight) of the living pairs within
    r_c, so that a removal can relieve its neighbours.
    """
    n = wall.shape[0]
    rate = np.full(n, base_rate)
    chi = np.zeros(n)
    start = np.zeros(n + 1, np.int64)
    if sensitivity <= 0:
        return rate, chi, start, np.empty(0, np.int64), np.empty(0)
    for k in range(n):
        chi[k] = max(1.0 - 2.0 * wall[k] / crowding, 0.0)
    degree = np.zeros(n + 1, np.int64)
    for m in range(pa.shape[0]):
        if pr[m] < crowding and not dead[pa[m]] and not dead[pb[m]]:
            w = 1.0 - pr[m] / crowding
            chi[pa[m]] += w
            chi[pb[m]] += w
            degree[pa[m] + 1] += 1
            degree[pb[m] + 1] += 1
    start = np.cumsum(degree)
    fill = start[:n].copy()
    partner = np.empty(start[n], np.int64)
    weight = np.empty(start[n])
    for m in range(pa.shape[0]):
        if pr[m] < crowding and not dead[pa[m]] and not dead[pb[m]]:
            w = 1.0 - pr[m] / crowding
            a, b = pa[m], pb[m]
            partner[fill[a]] = b
            weight[fill[a]] = w
            fill[a] += 1
            partner[fill[b]] = a
            weight[fill[b]] = w
            fill[b] += 1
    for k in range(n):
        rate[k] = base_rate * math.exp(sensitivity * chi[k])
    return rate, chi, start, partner, weight


@numba.njit(cache=True)
def total_rate(
    x,
    y,
    alive,
    wall_distance,
    grid_x0,
    grid_y0,
    grid_spacing,
    crowding,
    collapse,
    base_rate,
    sensitivity,
):
    """(R = Σ_i Γ_i [1/s] over every skyrmion, number of immediate-collapse candidates).

    No randomness: the caller draws the first wait ~ Exp(R) itself and calls
    :func:`annihilation_check` only when there are candidates or the wait falls inside the
    interval. Nearly every check ends there, and passing a Generator into compiled code costs
    more than the rest of the check. Arguments as in :func:`annihilation_check`.
    """
    slots, wall, pa, pb, pr = _frozen_state(
        x, y, alive, wall_distance, grid_x0, grid_y0, grid_spacing, crowding, collapse, sensitivity
    )
    n = slots.shape[0]
    candidates = 0
    for k in range(n):
        if wall[k] < 0.5 * collapse:
            candidates += 1
    for m in range(pr.shape[0]):
        if pr[m] < collapse:
            candidates += 1
    dead = np.zeros(n, np.bool_)
    rate = _rates(wall, pa, pb, pr, dead, crowding, base_rate, sensitivity)[0]
    total = 0.0
    for k in range(n):
        total += rate[k]
    return total, candidates


@numba.njit(cache=True)
def annihilation_check(
    x,
    y,
    alive,
    wall_distance,
    grid_x0,
    grid_y0,
    grid_spacing,
    crowding,
    collapse,
    base_rate,
    sensitivity,
    interval,
    rng,
    first_wait,
    victims,
):
    r"""One application of the annihilation rule; returns how many skyrmions die.

    x, y: positions [nm] of every slot; alive: which slots hold a skyrmion; wall_distance:
    the wall-distance grid [nm] (origin, spacing [nm]); crowding r_c and collapse d_min [nm];
    base_rate Γ0 [1/s]; sensitivity c; interval Δt [s]; rng: a NumPy Generator; first_wait
    [s]: the first Gillespie wait if the caller has drawn it already (only when there is no
    immediate collapse), else negative. Writes the dead slots, ascending, into ``victims``
    (length ≥ number of slots).

    1. Immediate collapse: every skyrmion closer than d_min/2 to a wall, then, over the pairs
       closer than d_min in random order, one member (each with probability ½) of every pair
       whose members both still live.
    2. Kinetic Monte Carlo over Δt with positions frozen (Gillespie): total rate
       R = Σ_i Γ0 exp(c χ_i), χ_i = (1 − 2 d_w,i / r_c)_+ + Σ_j (1 − r_ij/r_c)_+ over the
       living; wait ~ Exp(R); if it fits in the time left, remove skyrmion i with probability
       Γ_i / R, lower its neighbours' χ and repeat.
    """
    slots, wall, pa, pb, pr = _frozen_state(
        x, y, alive, wall_distance, grid_x0, grid_y0, grid_spacing, crowding, collapse, sensitivity
    )
    n = slots.shape[0]
    if n == 0:
        return 0
    dead = wall < 0.5 * collapse
    close = np.flatnonzero(pr < collapse)
    if close.shape[0] > 0:
        for k in rng.permutation(close.shape[0]):
            a = pa[close[k]]
            b = pb[close[k]]
            if dead[a] or dead[b]:
                continue
            if rng.random() < 0.5:
                dead[a] = True
            else:
                dead[b] = True
    rate, chi, start, partner, weight = _rates(
        wall, pa, pb, pr, dead, crowding, base_rate, sensitivity
    )
    living = ~dead
    time_left = interval
    while True:
        total = 0.0
        for k in range(n):
            if living[k]:
                total += rate[k]
        if total <= 0.0:
            break
        if first_wait >= 0.0:
            wait = first_wait
            first_wait = -1.0
        else:
            wait = rng.exponential(1.0 / total)
        if wait > time_left:
            break
        time_left -= wait
        target = rng.random() * total
        pick = -1
        acc = 0.0
        for k in range(n):
            if living[k]:
                pick = k
                acc += rate[k]
                if acc >= target:
                    break
        living[pick] = False
        dead[pick] = True
        for e in range(start[pick], start[pick + 1]):
            j = partner[e]
            if living[j]:
                chi[j] -= weight[e]
                rate[j] = base_rate * math.exp(sensitivity * chi[j])

    count = 0
    for k in range(n):
        if dead[k]:
            victims[count] = slots[k]
            count += 1
    return count


@numba.njit(inline="always")
def _slots_in_disk(x, y, alive, center_x, center_y, radius, out):
    """Store in ``out`` the slots of living centres (x, y) [nm] strictly inside the disk.

    The disk is (centre, radius) [nm]; returns how many.
    """
    r2 = radius * radius
    count = 0
    for k in range(x.shape[0]):
        if alive[k]:
            dx = x[k] - center_x
            dy = y[k] - center_y
            if dx * dx + dy * dy < r2:
                out[count] = k
                count += 1
    return count


@numba.njit(cache=True)
def count_in_disk(x, y, alive, center_x, center_y, radius):
    """Number of living centres (x, y) [nm] strictly inside the disk (centre, radius) [nm]."""
    return _slots_in_disk(x, y, alive, center_x, center_y, radius, np.empty(x.shape[0], np.int64))


@numba.njit(cache=True)
def covered_fraction(x, y, alive, center_x, center_y, radius, skyrmion_radius, samples):
    """Fraction of the sample points (shape (m, 2), nm) inside at least one skyrmion disk.

    The disks have radius ``skyrmion_radius`` [nm] and are centred on a living (x, y) [nm]; only
    skyrmions whose disk can reach the sensor disk (centre, radius) are considered.
    """
    near = np.empty(x.shape[0], np.int64)
    m = _slots_in_disk(x, y, alive, center_x, center_y, radius + skyrmion_radius, near)
    if m == 0:
        return 0.0
    rs2 = skyrmion_radius * skyrmion_radius
    covered = 0
    for s in range(samples.shape[0]):
        sx = samples[s, 0]
        sy = samples[s, 1]
        for q in range(m):
            dx = sx - x[near[q]]
            dy = sy - y[near[q]]
            if dx * dx + dy * dy < rs2:
                covered += 1
                break
    return covered / samples.shape[0]
