"""The Verlet neighbour list of the pair term (compiled; internal units nm, ns).

At each build, skyrmion i gets a margin s_i (:func:`margins`) and the list holds every pair
closer than cutoff + s_i + s_j, found with a cell list (cells no smaller than
cutoff + 2·max s_i, so the build is linear in the number of skyrmions). The list stays valid
while every skyrmion is within s_i of where it was at the build: then no pair outside the list
can have come closer than the cutoff. The kernel checks the displacements before every force
evaluation (including Heun's predictor), so no interacting pair is ever missed. A skyrmion
that a current carries fast along a conduit gets a wider margin, so that it does not force a
rebuild at every step.

The list is a half list grouped by owner: the partners of ``owner[e]`` are
``pair_j[start[e]:start[e + 1]]``. Insertions and removals edit it in place
(:func:`list_append`, :func:`list_remove`) instead of rebuilding it.
"""

from __future__ import annotations

import math

import numba

from skygas.engine._jit import JIT


@numba.njit(inline="always")
def margins(vx, vy, alive, cells, dt, margin):
    """Margin s_i [nm] of each skyrmion for a build, from its latest velocity [nm/ns].

        s_i = min(skin/2 + K·dt·|v_i|, s_max),   K = cells.margin_steps.
    A slow skyrmion keeps the base half-skin; one drifting fast along a conduit gets room for
    about K steps of its motion, so the list is not rebuilt at every step.
    """
    base = 0.5 * cells.skin
    ahead = cells.margin_steps * dt
    top = cells.margin_max
    for i in range(vx.shape[0]):
        speed = math.sqrt(vx[i] * vx[i] + vy[i] * vy[i]) if alive[i] else 0.0
        margin[i] = min(base + ahead * speed, top)


@numba.njit(**JIT)
def build_neighbor_list(
    x, y, alive, margin, cells, cutoff, cell_head, cell_next, owner, start, pair_j
):
    """Half neighbour list of all alive pairs closer than ``cutoff`` + s_i + s_j (``margin``).

    Returns the number of owners, or −1 if ``pair_j`` is too small (the caller grows it and calls
    again).
    """
    ncx = cells.ncx
    ncy = cells.ncy
    cell_head[:] = -1
    for i in range(x.shape[0]):
        if alive[i]:
            cx = min(max(int((x[i] - cells.x0) / cells.size), 0), ncx - 1)
            cy = min(max(int((y[i] - cells.y0) / cells.size), 0), ncy - 1)
            c = cy * ncx + cx
            cell_next[i] = cell_head[c]
            cell_head[c] = i
    count = 0
    owners = 0
    capacity = pair_j.shape[0]
    for cy in range(ncy):
        for cx in range(ncx):
            i = cell_head[cy * ncx + cx]
            while i >= 0:
                xi = x[i]
                yi = y[i]
                reach_i = cutoff + margin[i]
                owner[owners] = i
                start[owners] = count
                # half shell: own cell (later entries only) and 4 forward neighbours
                for k in range(5):
                    ox = (0, 1, -1, 0, 1)[k]
                    oy = (0, 0, 1, 1, 1)[k]
                    nbx = cx + ox
                    nby = cy + oy
                    if nbx < 0 or nbx >= ncx or nby >= ncy:
                        continue
                    j = cell_next[i] if k == 0 else cell_head[nby * ncx + nbx]
                    while j >= 0:
                        if count >= capacity:
                            return -1
                        dx = xi - x[j]
                        dy = yi - y[j]
                        reach = reach_i + margin[j]
                        # every candidate is written and kept only if close enough: no branch
                        # on the distance, which would be mispredicted about half the time
                        pair_j[count] = j
                        count += dx * dx + dy * dy < reach * reach
                        j = cell_next[j]
                owners += 1
                i = cell_next[i]
    start[owners] = count
    return owners


@numba.njit(inline="always")
def list_remove(k, owner, start, pair_j, n_owners):
    """Remove skyrmion ``k`` from the list, as owner and as partner, compacting the arrays in place.

    A few hundred entries: cheaper than a rebuild. Returns the number of owners left.
    """
    kept_owners = 0
    kept_pairs = 0
    for e in range(n_owners):
        first = start[e]  # not yet overwritten: writes go to indices ≤ e
        last = start[e + 1]
        if owner[e] == k:
            continue
        owner[kept_owners] = owner[e]
        start[kept_owners] = kept_pairs
        for p in range(first, last):
            if pair_j[p] != k:
                pair_j[kept_pairs] = pair_j[p]
                kept_pairs += 1
        kept_owners += 1
    start[kept_owners] = kept_pairs
    return kept_owners


@numba.njit(inline="always")
def list_append(
    k, x, y, alive, ref_x, ref_y, margin, cells, cutoff, owner, start, pair_j, n_owners
):
    """Add skyrmion ``k``, just inserted at rest, to a valid list.

    It gets the base margin and its position as reference, and becomes an owner whose partners are
    all other skyrmions j with |x_k − ref_j| < cutoff + s_k + s_j, which is the build's criterion,
    so the list's guarantee extends to it. Returns the new number of owners, or −1 if ``pair_j`` is
    full (the caller then rebuilds).
    """
    margin[k] = 0.5 * cells.skin
    ref_x[k] = x[k]
    ref_y[k] = y[k]
    reach_k = cutoff + margin[k]
    count = start[n_owners]
    for j in range(x.shape[0]):
        if alive[j] and j != k:
            dx = x[k] - ref_x[j]
            dy = y[k] - ref_y[j]
            reach = reach_k + margin[j]
            if dx * dx + dy * dy < reach * reach:
                if count >= pair_j.shape[0]:
                    return -1
                pair_j[count] = j
                count += 1
    owner[n_owners] = k
    start[n_owners + 1] = count
    return n_owners + 1


@numba.njit(inline="always")
def list_is_stale(x, y, alive, ref_x, ref_y, margin):
    """True if some skyrmion has moved farther than its margin since the list was built."""
    stale = False
    for i in range(x.shape[0]):  # no early exit: the loop then compiles to SIMD
        dx = x[i] - ref_x[i]
        dy = y[i] - ref_y[i]
        stale |= alive[i] and dx * dx + dy * dy > margin[i] * margin[i]
    return stale
