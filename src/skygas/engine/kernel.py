"""The compiled time-step loop (private; internal units nm, ns, pN).

:func:`advance` runs ``n_steps`` steps of the stochastic Heun (or Euler–Maruyama) scheme on the
skyrmion store's arrays, staying compiled through planned insertions, exits and recordings.
The layers above (:mod:`skygas.engine.simulation`) prepare every record; the stages it calls
(:mod:`skygas.engine.stages`) hold the arithmetic, and the force terms they sum are declared in
:mod:`skygas.engine.terms`. The equation of motion and the integrator's orders are documented
in :mod:`skygas.engine`.
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np

from skygas.engine._jit import JIT
from skygas.engine.neighbors import (
    build_neighbor_list,
    list_append,
    list_is_stale,
    list_remove,
    margins,
)
from skygas.engine.stages import (
    crossed_port,
    draw_noise,
    draw_radius_normals,
    force_pass,
    insert_planned,
    interior_floor,
    interior_floors,
    is_inside,
    radius_corrector,
    radius_predictor,
    record_frame,
    record_radii,
    reflect_radius,
    scale_radius_noise,
)
from skygas.fields._field_lookup import prefetch_at
from skygas.fields.landscape.hermite import prefetch_cell


class Frames(NamedTuple):
    """Where one call records its frames: positions [nm] (NaN = empty slot) and ids (−1).

    ``r``: a breathing model's radii [nm] (a placeholder for rigid skyrmions).
    """

    x: np.ndarray  # (frames, slots)
    y: np.ndarray
    ids: np.ndarray
    r: np.ndarray


class Exits(NamedTuple):
    """Where one call records its exits (one row per skyrmion that left through a port)."""

    ids: np.ndarray
    step: np.ndarray  # global step at which it had left
    port: np.ndarray  # index into the outline's ports
    x: np.ndarray  # position past the port [nm]
    y: np.ndarray


@numba.njit(**JIT)
def advance(
    x,
    y,
    r,
    alive,
    ids,
    step0,
    n_steps,
    stepper,
    noise,
    mobility,
    terms,
    cells,
    ports,
    frames,
    exits,
    plan,
    counters_array,
):
    """Advance the store (``x, y`` [nm], ``alive``, ``ids``) by ``n_steps`` steps from ``step0``.

    ``step0`` is the global step number. Returns the number of exits written to ``exits``.
    ``r`` holds the radii [nm] of a breathing model (``terms.breathing.active``), which step
    with the centres in the same scheme (their own noise ξ_R, reflected back into the table's
    range); rigid skyrmions leave it as it is, but for insertions, which get R₀.

    Additive noise ξ = √(2D dt)·z is drawn once per skyrmion and step (keyed on its id and the
    global step number) and used in both Heun stages:
        x̃ = x + v(x) dt + ξ,   x' = x + ½[v(x) + v(x̃)] dt + ξ.
    After each step a skyrmion outside the device either crossed a port (it is removed and the
    exit recorded) or crossed a wall (the step is undone for it and counted).
    A frame is recorded whenever the global step count reaches a multiple of
    ``stepper.record_every``; ``counters.frames`` counts them.

    Planned insertions (``plan``, :class:`~skygas.engine.terms.PlannedInsertions`): at the
    start of global step ``plan.steps[k]``, a skyrmion is inserted at (``plan.x[k]``,
    ``plan.y[k]``) into the lowest free slot with id ``counters.next_id`` if its site is
    clear. If it is occupied or no slot is free, the call stops before that step and leaves
    the event to the caller; ``counters.steps`` and ``counters.inserted`` say how far it got.
    """
    counters = counters_array[0]
    n = x.shape[0]
    dt = stepper.dt
    heun = stepper.heun
    grid = terms.grid
    inv_gh = 1.0 / grid.spacing
    breathing = terms.breathing
    cutoff = terms.pair.cutoff + breathing.pair_reach  # the neighbour list's reach
    wall_reach = terms.wall.cutoff + breathing.wall_reach
    vx0 = np.zeros(n)
    vy0 = np.zeros(n)
    vx1 = np.zeros(n)  # Heun's corrector velocities; before the first step, "at rest"
    vy1 = np.zeros(n)
    margin = np.empty(n)
    xp = np.empty(n)
    yp = np.empty(n)
    nx_ = np.zeros(n)
    ny_ = np.zeros(n)
    vr0 = np.zeros(n)  # the radii's rates [nm/ns], predictor and corrector
    vr1 = np.zeros(n)
    rp = r.copy()
    zr_ = np.zeros(n)  # the radii's normals
    spare = np.zeros(n)
    kr0 = np.zeros(n)  # the stiffness the laws add to each radius [pN/nm], per stage
    kr1 = np.zeros(n)
    lam = np.zeros(n)  # their frozen relaxation rates [1/ns], and the corrector's weights
    e2 = np.zeros(n)
    cand = np.empty((4, n))
    ref_x = np.empty(n)
    ref_y = np.empty(n)
    domain = np.empty(n)
    floor = np.full(n, -1.0)  # set at each neighbour-list build
    cell_head = np.empty(cells.ncx * cells.ncy, dtype=np.int64)
    cell_next = np.empty(n, dtype=np.int64)
    owner = np.empty(n, dtype=np.int64)
    start = np.empty(n + 1, dtype=np.int64)
    capacity = 16 * n + 16
    pair_j = np.empty(capacity, dtype=np.int64)
    n_owners = -1  # no list yet
    n_exits = 0
    moved = 0  # skyrmion-steps taken (the rate of wall escapes is counted against them)
    n_planned = plan.steps.shape[0]
    cursor = 0
    steps_done = n_steps
    for s in range(n_steps):
        step = step0 + s
        # -- planned insertions ---------------------------------------------------------------
        if cursor < n_planned and plan.steps[cursor] == step:
            slot = insert_planned(x, y, alive, ids, plan, cursor, counters)
            if slot < 0:
                steps_done = s
                break
            cursor += 1
            r[slot] = breathing.r0
            rp[slot] = breathing.r0
            vx0[slot] = 0.0  # its margin starts from rest
            vy0[slot] = 0.0
            vx1[slot] = 0.0
            vy1[slot] = 0.0
            if n_owners >= 0:  # add it to the list (−1 if there is no room: rebuild)
                n_owners = list_append(
                    slot,
                    x,
                    y,
                    alive,
                    ref_x,
                    ref_y,
                    margin,
                    cells,
                    cutoff,
                    owner,
                    start,
                    pair_j,
                    n_owners,
                )
                floor[slot] = interior_floor(x[slot], y[slot], margin[slot], terms, wall_reach)
        # -- noise ----------------------------------------------------------------------------
        if noise.thermal:
            draw_noise(noise, ids, alive, step, cand, nx_, ny_)
            if breathing.active:
                draw_radius_normals(noise, ids, alive, step, cand, zr_, spare)
                if breathing.mobility_varies:
                    scale_radius_noise(r, alive, breathing, nx_, ny_)
        if heun:
            # Heun's predictor will land near x + v dt + ξ (v: the last corrector velocity),
            # often on grid rows not read for a while: start loading them now, so that the
            # wait overlaps with the first force pass. Skyrmions far from every wall (see
            # stages.interior_floor) will not look their fields up.
            land = terms.landscape
            inv_lh = 1.0 / land.spacing
            for i in range(n):
                if not alive[i]:
                    continue
                ax = x[i] + vx1[i] * dt + nx_[i]
                ay = y[i] + vy1[i] * dt + ny_[i]
                if floor[i] <= 0.0:
                    prefetch_at(grid.fields, (ax - grid.x0) * inv_gh, (ay - grid.y0) * inv_gh)
                if land.active:  # and the landscape's cells there (measured: the landscape
                    # term's cost falls by a fifth)
                    prefetch_cell(
                        land.coefficients, (ax - land.x0) * inv_lh, (ay - land.y0) * inv_lh
                    )
        # -- force passes: Heun's predictor and corrector (Euler: the first only) -------------
        for stage in range(2 if heun else 1):
            px = x if stage == 0 else xp
            py = y if stage == 0 else yp
            if n_owners < 0 or list_is_stale(px, py, alive, ref_x, ref_y, margin):
                # margins from the latest velocities: the last corrector's, or the predictor's
                if stage == 1 or not heun:
                    margins(vx0, vy0, alive, cells, dt, margin)
                else:
                    margins(vx1, vy1, alive, cells, dt, margin)
                while True:
                    n_owners = build_neighbor_list(
                        px,
                        py,
                        alive,
                        margin,
                        cells,
                        cutoff,
                        cell_head,
                        cell_next,
                        owner,
                        start,
                        pair_j,
                    )
                    if n_owners >= 0:
                        break
                    capacity *= 2
                    pair_j = np.empty(capacity, dtype=np.int64)
                ref_x[:] = px
                ref_y[:] = py
                interior_floors(px, py, alive, terms, margin, floor)
                counters.neighbor_rebuilds += 1
            if stage == 0:
                force_pass(
                    x,
                    y,
                    r,
                    alive,
                    terms,
                    mobility,
                    owner,
                    start,
                    pair_j,
                    n_owners,
                    vx0,
                    vy0,
                    vr0,
                    kr0,
                    counters,
                    domain,
                    floor,
                    True,
                )
                for i in range(n):
                    xp[i] = x[i] + vx0[i] * dt + nx_[i]
                    yp[i] = y[i] + vy0[i] * dt + ny_[i]
                if breathing.active:  # (the corrector's lookups clamp to the table)
                    radius_predictor(
                        r, vr0, kr0, zr_, alive, breathing, dt, noise.thermal, lam, e2, rp
                    )
            else:
                force_pass(
                    xp,
                    yp,
                    rp,
                    alive,
                    terms,
                    mobility,
                    owner,
                    start,
                    pair_j,
                    n_owners,
                    vx1,
                    vy1,
                    vr1,
                    kr1,
                    counters,
                    domain,
                    floor,
                    False,
                )
                for i in range(n):
                    xp[i] = x[i] + 0.5 * (vx0[i] + vx1[i]) * dt + nx_[i]
                    yp[i] = y[i] + 0.5 * (vy0[i] + vy1[i]) * dt + ny_[i]
                if breathing.active:
                    radius_corrector(r, rp, vr0, vr1, lam, e2, alive)
        if breathing.active:  # the final radii, reflected into the table's range
            for i in range(n):
                if alive[i]:
                    rp[i], reflected = reflect_radius(rp[i], breathing)
                    counters.radius_reflections += reflected
        # -- accept the step; handle skyrmions that left the device ---------------------------
        for i in range(n):
            if not alive[i]:
                continue
            moved += 1
            # ``domain`` holds the boundary distance at the last evaluated position (Heun's
            # predictor, or x for Euler); the interpolated field changes by at most √2 per nm,
            # so a skyrmion that moved less than distance/√2 from there is certainly inside.
            if heun:  # final − predictor = ½(v₁ − v₀) dt
                mx = 0.5 * (vx1[i] - vx0[i]) * dt
                my = 0.5 * (vy1[i] - vy0[i]) * dt
            else:
                mx = xp[i] - x[i]
                my = yp[i] - y[i]
            if (domain[i] > 0.0 and domain[i] * domain[i] > 2.0 * (mx * mx + my * my)) or is_inside(
                grid, xp[i], yp[i]
            ):
                x[i] = xp[i]
                y[i] = yp[i]
                r[i] = rp[i]  # (rigid: rp is r)
                continue
            crossed = crossed_port(x[i], y[i], xp[i], yp[i], ports)
            if crossed >= 0:
                alive[i] = False
                if n_owners >= 0:
                    n_owners = list_remove(i, owner, start, pair_j, n_owners)
                exits.ids[n_exits] = ids[i]  # the slot may be reused later in this call
                exits.step[n_exits] = step + 1
                exits.port[n_exits] = crossed
                exits.x[n_exits] = xp[i]
                exits.y[n_exits] = yp[i]
                n_exits += 1
            else:
                counters.wall_escapes += 1  # position kept: the step is undone
        # -- recording ------------------------------------------------------------------------
        if stepper.record_every > 0 and (step + 1) % stepper.record_every == 0:
            record_frame(x, y, alive, ids, counters.frames, frames.x, frames.y, frames.ids)
            if breathing.active:
                record_radii(r, alive, counters.frames, frames.r)
            counters.frames += 1
    counters.exits += n_exits
    counters.skyrmion_steps = moved
    counters.steps = steps_done
    counters.inserted = cursor
    return n_exits


class DirectCall:
    """Calls a compiled function's overload directly while its arguments' types stay the same.

    A numba dispatcher types every argument of every call to choose its overload. For
    :func:`advance`, whose records hold some sixty arrays, that costs 15 µs a call: more than
    15 steps of a small device, and part of the price of each operation's turn (the neuron's
    controller and annihilator stop the kernel every step or four). Once a call has gone
    through the dispatcher, the overload it chose is called directly for as long as the ``key``
    objects are the same objects. The key must hold every argument whose type could change; the
    others must be of fixed types (the engine's own buffers). ``key=None`` always dispatches.
    """

    def __init__(self, dispatcher):
        self.dispatcher = dispatcher
        self._key: tuple = ()
        self._entry = None

    def __call__(self, key: tuple | None, *args):
        """The function's result for ``args``; ``key``: the objects that fix their types."""
        if key is None:
            return self.dispatcher(*args)
        if len(key) == len(self._key) and all(a is b for a, b in zip(key, self._key, strict=True)):
            if self._entry is not None:
                return self._entry(*args)
            return self.dispatcher(*args)
        result = self.dispatcher(*args)  # compiles or loads the overload if needed
        types = tuple(numba.typeof(a) for a in args)
        compiled = self.dispatcher.overloads.get(types)
        # holding the key objects keeps their identities from being reused
        self._key, self._entry = key, None if compiled is None else compiled.entry_point
        return result
