"""Compiled kernels of the engine (private; internal units nm, ns, pN).

The layers above (:mod:`skygas.engine`) prepare every array and scalar; these functions only do
arithmetic. The equation of motion and the integrator are documented in :mod:`skygas.engine`.

Velocity of a skyrmion under a total force F (pN), with a = α𝒟k, g = G (pN·ns/nm):
    (g ε + a I)·v = F   ⇒   v = (a F − g εF)/(a² + g²),   εF = (F_y, −F_x)

Pairs come from a Verlet neighbour list with a skin per skyrmion: at each build, skyrmion i gets
a margin s_i (see :func:`_margins`) and the list holds every pair closer than
cutoff + s_i + s_j, found with a cell list (cells no smaller than cutoff + 2·max s_i, so the
build is linear in the number of skyrmions). The list stays valid while every skyrmion is
within s_i of where it was at the build: then no pair outside the list can have come closer
than the cutoff. The displacements are checked before every force evaluation (including Heun's
predictor), so no interacting pair is ever missed. A skyrmion that a current carries fast along
a conduit gets a wider margin, so that it does not force a rebuild at every step.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from skygas._field_lookup import field_at, prefetch_at
from skygas._rng import STREAM_THERMAL, fill_gaussian_pairs, gaussian_pair

# Let LLVM fuse multiply-adds, reassociate and use reciprocals, but keep NaN/Inf semantics
# (NaN marks absent skyrmions in recorded frames). Results stay bit-reproducible for a given
# build of the package on a given machine.
_FASTMATH = {"contract", "arcp", "nsz", "reassoc", "afn"}
# NumPy's error model: a division by zero gives inf/NaN instead of raising, so a loop holds no
# hidden exception branch and the compiler can turn it into SIMD instructions.
_JIT = {"cache": True, "fastmath": _FASTMATH, "error_model": "numpy"}

# Indices into the float parameter vector ``fp``.
FP_DT = 0            # time step [ns]
FP_MOB_A = 1         # a / (a² + g²)   [nm/(pN·ns)]
FP_MOB_G = 2         # g / (a² + g²)
FP_NOISE = 3         # √(2 D dt) per axis [nm]
FP_DRIVE_G = 4       # μ g  (drive matrix μ(g ε + b I))
FP_DRIVE_B = 5       # μ b
FP_VS_X = 6          # uniform v_s [nm/ns]
FP_VS_Y = 7
FP_PAIR_H2 = 8       # pair table spacing in r² [nm²]
FP_PAIR_CUT = 9      # pair cutoff [nm]
FP_WALL_H = 10       # wall table spacing [nm]
FP_WALL_CUT = 11     # wall cutoff [nm]
FP_GRID_X0 = 12      # field grid origin and spacing [nm]
FP_GRID_Y0 = 13
FP_GRID_H = 14
FP_SKIN = 15         # neighbour-list skin [nm]: the smallest margin s_i is half of it
FP_CELL_X0 = 16      # cell-list origin and cell size [nm]
FP_CELL_Y0 = 17
FP_CELL_SIZE = 18
FP_MARGIN_MAX = 19   # largest margin s_i [nm] (cell size ≥ cutoff + 2·FP_MARGIN_MAX)
FP_MARGIN_STEPS = 20  # steps of motion at the current velocity a margin should cover
FP_SIZE = 21

# Indices into the integer parameter vector ``ip``.
IP_SEED = 0          # RNG key
IP_SUBSTEPS = 1      # Brownian sub-steps per step (1 = plain)
IP_SCHEME = 2        # 0 = Heun, 1 = Euler–Maruyama
IP_DRIFT_GRID = 3    # 0 = uniform v_s, 1 = v_s from the grid
IP_RECORD_EVERY = 4  # steps between recorded frames (0 = never)
IP_THERMAL = 5       # 1 if T > 0
IP_NCX = 6           # cell-list shape
IP_NCY = 7
IP_SIZE = 8

# Counters returned in ``stats``.
ST_PAIRS = 0         # pair-force evaluations inside the cutoff
ST_WALL_ESCAPES = 1  # steps that crossed a wall (undone)
ST_EXITS = 2         # skyrmions that left through a port
ST_FRAMES = 3        # frames recorded
ST_REBUILDS = 4      # neighbour-list builds
ST_STEPS = 5         # steps taken (fewer than asked when a planned insertion cannot be made)
ST_INSERTED = 6      # planned insertions made
ST_NEXT_ID = 7       # in: id for the next inserted skyrmion; out: the one after the last
ST_SIZE = 8

# Channels of the packed grid array ``fields[j, i, c]`` (float32, nm and nm/ns; N_CHANNELS = 8,
# see skygas._field_lookup). All per-node fields sit side by side, so one lookup interpolates
# them all with four vector loads.
CH_WALL_DIST = 0     # signed distance to the nearest wall
CH_NORMAL_X = 1      # inward wall normal
CH_NORMAL_Y = 2
CH_DOMAIN = 3        # signed distance to the boundary (walls and ports), > 0 inside
CH_DRIFT_X = 4       # spin-drift velocity v_s
CH_DRIFT_Y = 5       # (channels 6 and 7 are padding)


# Neighbour lists longer than this are run through without a branch on the cutoff: every
# entry gets the full force arithmetic, with the force set to zero beyond the cutoff. About a
# third of the entries lie beyond it, at random. A short list is run through the same way at
# every step until it is rebuilt, and the branch predictor learns its pattern; a long one it
# cannot learn, and the mispredictions cost more than the extra arithmetic. Measured in whole
# runs of the benchmark gas (benchmarks/bench_engine.py; ~4 entries per skyrmion), branch-free
# against branching: 1.09 at 100 skyrmions, 1.03 at 400, 0.83 at 1 000, 0.73 at 2 000, 0.80
# at 10 000 (time ratios).
BRANCH_FREE_ENTRIES = 2048

# Array indices in the hot loops are unsigned: NumPy-style negative-index wrap-around then
# needs no extra instructions, which matters in loops of a few dozen instructions.
_U = numba.uint64


@numba.njit(inline="always")
def _lerp(values, coordinate):
    """Linear interpolation of ``values`` at fractional index ``coordinate`` ≥ 0."""
    i = _U(coordinate)
    t = coordinate - i
    return (1.0 - t) * values[i] + t * values[i + _U(1)]


@numba.njit(inline="always")
def _margins(vx, vy, alive, fp, margin):
    """Margin s_i [nm] of each skyrmion for a neighbour-list build, from its latest velocity:
        s_i = min(skin/2 + K·dt·|v_i|, s_max),   K = FP_MARGIN_STEPS.
    A slow skyrmion keeps the base half-skin; one drifting fast along a conduit gets room for
    about K steps of its motion, so the list is not rebuilt at every step."""
    base = 0.5 * fp[FP_SKIN]
    ahead = fp[FP_MARGIN_STEPS] * fp[FP_DT]
    top = fp[FP_MARGIN_MAX]
    for i in range(vx.shape[0]):
        speed = math.sqrt(vx[i] * vx[i] + vy[i] * vy[i]) if alive[i] else 0.0
        margin[i] = min(base + ahead * speed, top)


@numba.njit(**_JIT)
def build_neighbor_list(x, y, alive, margin, fp, ip, cell_head, cell_next, owner, start,
                        pair_j):
    """Half neighbour list of all alive pairs closer than cutoff + s_i + s_j (``margin``),
    grouped by owner: the partners of ``owner[e]`` are ``pair_j[start[e]:start[e + 1]]``.
    Returns the number of owners, or −1 if ``pair_j`` is too small (the caller grows it and
    calls again)."""
    n = x.shape[0]
    ncx = ip[IP_NCX]
    ncy = ip[IP_NCY]
    x0 = fp[FP_CELL_X0]
    y0 = fp[FP_CELL_Y0]
    size = fp[FP_CELL_SIZE]
    cutoff = fp[FP_PAIR_CUT]
    cell_head[:] = -1
    for i in range(n):
        if alive[i]:
            cx = min(max(int((x[i] - x0) / size), 0), ncx - 1)
            cy = min(max(int((y[i] - y0) / size), 0), ncy - 1)
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
def _list_remove(k, owner, start, pair_j, n_owners):
    """Remove skyrmion ``k`` from the neighbour list, as owner and as partner, compacting the
    arrays in place (a few hundred entries: cheaper than a rebuild). Returns the number of
    owners left."""
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
def _list_append(k, x, y, alive, ref_x, ref_y, margin, fp, owner, start, pair_j, n_owners):
    """Add skyrmion ``k``, just inserted at rest, to a valid neighbour list: it gets the base
    margin and its position as reference, and becomes an owner whose partners are all other
    skyrmions j with |x_k − ref_j| < cutoff + s_k + s_j, which is the build's criterion, so
    the list's guarantee extends to it. Returns the new number of owners, or −1 if
    ``pair_j`` is full (the caller then rebuilds)."""
    margin[k] = 0.5 * fp[FP_SKIN]
    ref_x[k] = x[k]
    ref_y[k] = y[k]
    reach_k = fp[FP_PAIR_CUT] + margin[k]
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
def _list_is_stale(x, y, alive, ref_x, ref_y, margin):
    """True if some skyrmion has moved farther than its margin since the list was built."""
    stale = False
    for i in range(x.shape[0]):  # no early exit: the loop then compiles to SIMD
        dx = x[i] - ref_x[i]
        dy = y[i] - ref_y[i]
        stale |= alive[i] and dx * dx + dy * dy > margin[i] * margin[i]
    return stale


@numba.njit(inline="always")
def _interior_floors(x, y, alive, fp, ip, fields, margin, floor):
    """For each skyrmion, a lower bound on its distance to the device boundary [nm] that holds
    while it stays within its margin s_i of (x, y), if it is also certain to stay beyond the
    wall-force cutoff there; −1 otherwise (and always when the drift comes from the grid).

    The interpolated fields change by at most √2 per nm (bilinear interpolation of values
    that differ by at most one spacing h between neighbouring nodes), with one spacing more
    for safety where exact values meet the distance transform. A skyrmion with
        d_wall − √2 s_i − h ≥ wall cutoff   and   d_boundary − √2 s_i − h > 0
    feels no wall force and cannot leave while the neighbour list stays valid, and with a
    uniform drift nothing else in the grid concerns it: the force passes skip its lookup."""
    for i in range(x.shape[0]):
        floor[i] = _interior_floor(x[i], y[i], margin[i], fp, ip, fields) if alive[i] else -1.0


@numba.njit(inline="always")
def _interior_floor(xi, yi, margin_i, fp, ip, fields):
    """One skyrmion's value of :func:`_interior_floors`."""
    if ip[IP_DRIFT_GRID] != 0:
        return -1.0
    gh = fp[FP_GRID_H]
    field = field_at(fields, (xi - fp[FP_GRID_X0]) / gh, (yi - fp[FP_GRID_Y0]) / gh)
    slack = math.sqrt(2.0) * margin_i + gh
    if field[CH_WALL_DIST] - slack >= fp[FP_WALL_CUT] and field[CH_DOMAIN] - slack > 0.0:
        return field[CH_DOMAIN] - slack
    return -1.0


@numba.njit(inline="always")
def _velocities(x, y, alive, fp, ip, pair_table, wall_table, fields, owner, start, pair_j,
                n_owners, vx, vy, stats, domain, floor):
    """Deterministic velocity (nm/ns) of every alive skyrmion: pair + wall + drive forces.
    Forces are accumulated in ``vx, vy`` and converted to velocities in place. The signed
    distance to the device boundary at each position is stored in ``domain`` (it shares the
    cache lines of the wall lookup, and lets the step's acceptance skip a lookup); for a
    skyrmion with ``floor[i] > 0`` (see :func:`_interior_floors`) the lookup is skipped and
    ``domain`` gets that lower bound."""
    _pair_forces(x, y, fp, pair_table, owner, start, pair_j, n_owners, vx, vy, stats)
    _one_body_forces_and_velocities(x, y, alive, fp, ip, wall_table, fields, vx, vy, domain,
                                    floor)


@numba.njit(inline="always")
def _pair_forces(x, y, fp, pair_table, owner, start, pair_j, n_owners, fx, fy, stats):
    """Pair forces (pN) of the neighbour list into ``fx, fy`` (overwritten). The table holds
    |F|/r in r², so F = (|F|/r)(dx, dy) needs no square root or division."""
    for i in range(x.shape[0]):
        fx[i] = 0.0
        fy[i] = 0.0
    cut2 = fp[FP_PAIR_CUT] * fp[FP_PAIR_CUT]
    inv_h2 = 1.0 / fp[FP_PAIR_H2]
    evaluated = 0
    branch_free = start[n_owners] > BRANCH_FREE_ENTRIES
    for e in range(n_owners):
        i = _U(owner[e])
        xi = x[i]
        yi = y[i]
        fxi = 0.0  # accumulate in registers: one store per owner, not one per pair
        fyi = 0.0
        for p in range(start[e], start[e + 1]):
            j = _U(pair_j[_U(p)])
            dx = xi - x[j]
            dy = yi - y[j]
            r2 = dx * dx + dy * dy
            inside = r2 < cut2
            if branch_free or inside:  # the compiler makes two loops, one without the branch
                f = _lerp(pair_table, min(r2, cut2) * inv_h2)
                f = f if inside else 0.0
                fxi += f * dx
                fyi += f * dy
                fx[j] -= f * dx
                fy[j] -= f * dy
                evaluated += inside
        fx[i] += fxi
        fy[i] += fyi
    stats[ST_PAIRS] += evaluated


@numba.njit(inline="always")
def _one_body_forces_and_velocities(x, y, alive, fp, ip, wall_table, fields, vx, vy, domain,
                                    floor):
    """Add the wall and drive forces to the pair forces in ``vx, vy`` and convert the totals
    to velocities in place (see :func:`_velocities`)."""
    gx0 = fp[FP_GRID_X0]
    gy0 = fp[FP_GRID_Y0]
    inv_gh = 1.0 / fp[FP_GRID_H]
    inv_wall_h = 1.0 / fp[FP_WALL_H]
    wall_cut = fp[FP_WALL_CUT]
    mob_a = fp[FP_MOB_A]
    mob_g = fp[FP_MOB_G]
    drive_g = fp[FP_DRIVE_G]
    drive_b = fp[FP_DRIVE_B]
    drift_grid = ip[IP_DRIFT_GRID] == 1
    vsx = fp[FP_VS_X]
    vsy = fp[FP_VS_Y]
    for i in range(x.shape[0]):
        if not alive[i]:
            continue
        fx = vx[i]
        fy = vy[i]
        if floor[i] > 0.0:
            domain[i] = floor[i]
        else:
            field = field_at(fields, (x[i] - gx0) * inv_gh, (y[i] - gy0) * inv_gh)
            d = field[CH_WALL_DIST]
            domain[i] = field[CH_DOMAIN]
            if d < wall_cut:
                fw = _lerp(wall_table, max(d, 0.0) * inv_wall_h)
                fx += fw * field[CH_NORMAL_X]
                fy += fw * field[CH_NORMAL_Y]
            if drift_grid:
                vsx = field[CH_DRIFT_X]
                vsy = field[CH_DRIFT_Y]
        # drive force μ(g ε + b I)·v_s
        fx += drive_g * vsy + drive_b * vsx
        fy += -drive_g * vsx + drive_b * vsy
        # v = (a F − g εF)/(a² + g²)
        vx[i] = mob_a * fx - mob_g * fy
        vy[i] = mob_a * fy + mob_g * fx


@numba.njit(inline="always")
def _segments_cross(px, py, qx, qy, ax, ay, bx, by):
    """True if segment p→q crosses segment a→b (proper or touching)."""
    d1 = (bx - ax) * (py - ay) - (by - ay) * (px - ax)
    d2 = (bx - ax) * (qy - ay) - (by - ay) * (qx - ax)
    d3 = (qx - px) * (ay - py) - (qy - py) * (ax - px)
    d4 = (qx - px) * (by - py) - (qy - py) * (bx - px)
    return d1 * d2 <= 0.0 and d3 * d4 <= 0.0


@numba.njit(inline="always")
def _free_slot_if_clear(x, y, alive, sx, sy, clearance2):
    """The lowest free slot if no alive skyrmion lies closer than √clearance2 to (sx, sy);
    −1 if one does (the site is occupied), −2 if the site is clear but no slot is free."""
    free = -2
    for i in range(x.shape[0]):
        if alive[i]:
            dx = x[i] - sx
            dy = y[i] - sy
            if dx * dx + dy * dy < clearance2:
                return -1
        elif free == -2:
            free = i
    return free


@numba.njit(**_JIT)
def advance(x, y, alive, ids, step0, n_steps, fp, ip, pair_table, wall_table, fields, ports,
            frames_x, frames_y, frames_id, exit_id, exit_step, exit_port, exit_x, exit_y,
            plan_step, plan_x, plan_y, plan_ids, plan_clearance2, stats):
    """Advance the state by ``n_steps`` steps of the stochastic Heun (or Euler–Maruyama) scheme.

    Additive noise ξ = √(2D dt)·z is drawn once per skyrmion and step (keyed on its id and the
    global step number) and used in both Heun stages:
        x̃ = x + v(x) dt + ξ,   x' = x + ½[v(x) + v(x̃)] dt + ξ.
    After each step a skyrmion outside the device either crossed a port (it is removed and the
    exit recorded) or crossed a wall (the step is undone for it and counted).
    A frame is recorded into ``frames_x/y`` (NaN = absent) and ``frames_id`` (the id in each
    slot, −1 = absent) whenever the global step count reaches a multiple of
    ``ip[IP_RECORD_EVERY]``; ``stats[ST_FRAMES]`` counts them. Returns the number of exits.

    Planned insertions (an injector's nucleations, without a round trip to Python for each):
    at the start of global step ``plan_step[k]`` (increasing), a skyrmion is inserted at
    (``plan_x[k]``, ``plan_y[k]``) into the lowest free slot, with id ``stats[ST_NEXT_ID]``
    (stored in ``plan_ids[k]``), if no skyrmion lies closer than √plan_clearance2. If the site
    is occupied or no slot is free, the call stops before that step and leaves the event to the
    caller. ``stats[ST_STEPS]`` and ``stats[ST_INSERTED]`` say how far it got.
    """
    n = x.shape[0]
    dt = fp[FP_DT]
    noise = fp[FP_NOISE]
    seed = ip[IP_SEED]
    substeps = ip[IP_SUBSTEPS]
    heun = ip[IP_SCHEME] == 0
    thermal = ip[IP_THERMAL] == 1
    record_every = ip[IP_RECORD_EVERY]
    gx0 = fp[FP_GRID_X0]
    gy0 = fp[FP_GRID_Y0]
    inv_gh = 1.0 / fp[FP_GRID_H]
    inv_sqrt_sub = 1.0 / math.sqrt(substeps)
    vx0 = np.zeros(n)
    vy0 = np.zeros(n)
    vx1 = np.zeros(n)  # Heun's corrector velocities; before the first step, "at rest"
    vy1 = np.zeros(n)
    margin = np.empty(n)
    xp = np.empty(n)
    yp = np.empty(n)
    nx_ = np.zeros(n)
    ny_ = np.zeros(n)
    cand = np.empty((4, n))
    ref_x = np.empty(n)
    ref_y = np.empty(n)
    domain = np.empty(n)
    floor = np.full(n, -1.0)  # set at each neighbour-list build
    cell_head = np.empty(ip[IP_NCX] * ip[IP_NCY], dtype=np.int64)
    cell_next = np.empty(n, dtype=np.int64)
    owner = np.empty(n, dtype=np.int64)
    start = np.empty(n + 1, dtype=np.int64)
    capacity = 16 * n + 16
    pair_j = np.empty(capacity, dtype=np.int64)
    n_owners = -1  # no list yet
    n_exits = 0
    n_planned = plan_step.shape[0]
    cursor = 0
    steps_done = n_steps
    for s in range(n_steps):
        step = step0 + s
        if cursor < n_planned and plan_step[cursor] == step:
            slot = _free_slot_if_clear(x, y, alive, plan_x[cursor], plan_y[cursor],
                                       plan_clearance2)
            if slot < 0:
                steps_done = s
                break
            x[slot] = plan_x[cursor]
            y[slot] = plan_y[cursor]
            alive[slot] = True
            ids[slot] = stats[ST_NEXT_ID]
            plan_ids[cursor] = stats[ST_NEXT_ID]
            stats[ST_NEXT_ID] += 1
            cursor += 1
            vx0[slot] = 0.0  # its margin starts from rest
            vy0[slot] = 0.0
            vx1[slot] = 0.0
            vy1[slot] = 0.0
            if n_owners >= 0:  # add it to the list (−1 if there is no room: rebuild)
                n_owners = _list_append(slot, x, y, alive, ref_x, ref_y, margin, fp, owner,
                                        start, pair_j, n_owners)
                floor[slot] = _interior_floor(x[slot], y[slot], margin[slot], fp, ip, fields)
        if thermal and substeps == 1:
            fill_gaussian_pairs(seed, ids, alive, step, STREAM_THERMAL, cand, nx_, ny_)
            for i in range(n):
                nx_[i] *= noise
                ny_[i] *= noise
        elif thermal:
            for i in range(n):
                if alive[i]:
                    sx = 0.0
                    sy = 0.0
                    for b in range(substeps):
                        zx, zy = gaussian_pair(seed, ids[i], step * substeps + b, STREAM_THERMAL)
                        sx += zx
                        sy += zy
                    nx_[i] = noise * sx * inv_sqrt_sub
                    ny_[i] = noise * sy * inv_sqrt_sub
        if heun:
            # Heun's predictor will land near x + v dt + ξ (v: the last corrector velocity),
            # often on grid rows not read for a while: start loading them now, so that the
            # wait overlaps with the first force pass. Skyrmions far from every wall (see
            # _interior_floors) will not look their fields up.
            for i in range(n):
                if alive[i] and floor[i] <= 0.0:
                    prefetch_at(fields, (x[i] + vx1[i] * dt + nx_[i] - gx0) * inv_gh,
                                (y[i] + vy1[i] * dt + ny_[i] - gy0) * inv_gh)
        for stage in range(2 if heun else 1):
            px = x if stage == 0 else xp
            py = y if stage == 0 else yp
            if n_owners < 0 or _list_is_stale(px, py, alive, ref_x, ref_y, margin):
                # margins from the latest velocities: the last corrector's, or the predictor's
                if stage == 1 or not heun:
                    _margins(vx0, vy0, alive, fp, margin)
                else:
                    _margins(vx1, vy1, alive, fp, margin)
                while True:
                    n_owners = build_neighbor_list(px, py, alive, margin, fp, ip, cell_head,
                                                   cell_next, owner, start, pair_j)
                    if n_owners >= 0:
                        break
                    capacity *= 2
                    pair_j = np.empty(capacity, dtype=np.int64)
                ref_x[:] = px
                ref_y[:] = py
                _interior_floors(px, py, alive, fp, ip, fields, margin, floor)
                stats[ST_REBUILDS] += 1
            if stage == 0:
                _velocities(x, y, alive, fp, ip, pair_table, wall_table, fields, owner, start,
                            pair_j, n_owners, vx0, vy0, stats, domain, floor)
                for i in range(n):
                    xp[i] = x[i] + vx0[i] * dt + nx_[i]
                    yp[i] = y[i] + vy0[i] * dt + ny_[i]
            else:
                _velocities(xp, yp, alive, fp, ip, pair_table, wall_table, fields, owner, start,
                            pair_j, n_owners, vx1, vy1, stats, domain, floor)
                for i in range(n):
                    xp[i] = x[i] + 0.5 * (vx0[i] + vx1[i]) * dt + nx_[i]
                    yp[i] = y[i] + 0.5 * (vy0[i] + vy1[i]) * dt + ny_[i]
        # -- accept the step; handle skyrmions that left the device -------------------------
        for i in range(n):
            if not alive[i]:
                continue
            # ``domain`` holds the boundary distance at the last evaluated position (Heun's
            # predictor, or x for Euler); the interpolated field changes by at most √2 per nm,
            # so a skyrmion that moved less than distance/√2 from there is certainly inside.
            if heun:  # final − predictor = ½(v₁ − v₀) dt
                mx = 0.5 * (vx1[i] - vx0[i]) * dt
                my = 0.5 * (vy1[i] - vy0[i]) * dt
            else:
                mx = xp[i] - x[i]
                my = yp[i] - y[i]
            if domain[i] > 0.0 and domain[i] * domain[i] > 2.0 * (mx * mx + my * my):
                x[i] = xp[i]
                y[i] = yp[i]
                continue
            if field_at(fields, (xp[i] - gx0) * inv_gh, (yp[i] - gy0) * inv_gh)[CH_DOMAIN] >= 0.0:
                x[i] = xp[i]
                y[i] = yp[i]
                continue
            crossed = -1
            for p in range(ports.shape[0]):
                if _segments_cross(x[i], y[i], xp[i], yp[i], ports[p, 0], ports[p, 1],
                                   ports[p, 2], ports[p, 3]):
                    crossed = p
                    break
            if crossed >= 0:
                alive[i] = False
                if n_owners >= 0:
                    n_owners = _list_remove(i, owner, start, pair_j, n_owners)
                exit_id[n_exits] = ids[i]  # the slot may be reused later in this call
                exit_step[n_exits] = step + 1
                exit_port[n_exits] = crossed
                exit_x[n_exits] = xp[i]
                exit_y[n_exits] = yp[i]
                n_exits += 1
            else:
                stats[ST_WALL_ESCAPES] += 1  # position kept: the step is undone
        if record_every > 0 and (step + 1) % record_every == 0:
            f = stats[ST_FRAMES]
            for i in range(n):
                if alive[i]:
                    frames_x[f, i] = x[i]
                    frames_y[f, i] = y[i]
                    frames_id[f, i] = ids[i]
                else:
                    frames_x[f, i] = np.nan
                    frames_y[f, i] = np.nan
                    frames_id[f, i] = -1
            stats[ST_FRAMES] = f + 1
    stats[ST_EXITS] += n_exits
    stats[ST_STEPS] = steps_done
    stats[ST_INSERTED] = cursor
    return n_exits


@numba.njit(**_JIT)
def repeated_pair_pass(x, y, alive, fp, ip, pair_table, repeats, fx, fy, stats):
    """Build the neighbour list once and evaluate the pair forces ``repeats`` times
    (benchmarks: the pair-force loop a run repeats twice per step, without Python call
    overhead or the one-body forces)."""
    n = x.shape[0]
    cell_head = np.empty(ip[IP_NCX] * ip[IP_NCY], dtype=np.int64)
    cell_next = np.empty(n, dtype=np.int64)
    owner = np.empty(n, dtype=np.int64)
    start = np.empty(n + 1, dtype=np.int64)
    capacity = 16 * n + 16
    margin = np.full(n, 0.5 * fp[FP_SKIN])
    while True:
        pair_j = np.empty(capacity, dtype=np.int64)
        n_owners = build_neighbor_list(x, y, alive, margin, fp, ip, cell_head, cell_next, owner,
                                       start, pair_j)
        if n_owners >= 0:
            break
        capacity *= 2
    for _ in range(repeats):
        _pair_forces(x, y, fp, pair_table, owner, start, pair_j, n_owners, fx, fy, stats)
