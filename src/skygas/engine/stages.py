"""The stages of one time step, as the compiled kernel (:mod:`skygas.engine.kernel`) runs them.

Internal units nm, ns, pN; private.

One step: :func:`insert_planned` → :func:`draw_noise` → force passes (:func:`force_pass`:
:func:`pair_forces`, then :func:`add_one_body_forces`, which also turns forces into
velocities) in the integrator's stages → :func:`accept_or_exit` → :func:`record_frame`.

Velocity of a skyrmion under a total force F (pN), with a = α𝒟k, g = G (pN·ns/nm):
    (g ε + a I)·v = F   ⇒   v = (a F − g εF)/(a² + g²),   εF = (F_y, −F_x)
"""

from __future__ import annotations

import math

import numba
import numpy as np

from skygas.engine._jit import JIT, U
from skygas.engine._rng import STREAM_RADIUS, STREAM_THERMAL, fill_gaussian_pairs, gaussian_pair
from skygas.engine.terms import (
    CH_DOMAIN,
    CH_DRIFT_X,
    CH_DRIFT_Y,
    CH_NORMAL_X,
    CH_NORMAL_Y,
    CH_WALL_DIST,
)
from skygas.fields._field_lookup import field_at
from skygas.fields.landscape.hermite import hermite_gradient, hermite_value
from skygas.fields.landscape.wall_film import catmull_rom

# Neighbour lists longer than this are run through without a branch on the cutoff: every
# entry gets the full force arithmetic, with the force set to zero beyond the cutoff. About a
# third of the entries lie beyond it, at random. A short list is run through the same way at
# every step until it is rebuilt, and the branch predictor learns its pattern; a long one it
# cannot learn, and the mispredictions cost more than the extra arithmetic. Measured in whole
# runs of the benchmark gas (benchmarks/bench_engine.py; ~4 entries per skyrmion), branch-free
# against branching: 1.09 at 100 skyrmions, 1.03 at 400, 0.83 at 1 000, 0.73 at 2 000, 0.80
# at 10 000 (time ratios).
BRANCH_FREE_ENTRIES = 2048


@numba.njit(inline="always")
def _lerp(values, coordinate):
    """Linear interpolation of ``values`` at fractional index ``coordinate`` ≥ 0."""
    i = U(coordinate)
    t = coordinate - i
    return (1.0 - t) * values[i] + t * values[i + U(1)]


@numba.njit(inline="always")
def _lerp_slope(values, coordinate):
    """:func:`_lerp` of ``values`` at ``coordinate``, and its slope per unit of coordinate."""
    i = U(coordinate)
    t = coordinate - i
    low = values[i]
    high = values[i + U(1)]
    return (1.0 - t) * low + t * high, high - low


# -- insertions ----------------------------------------------------------------------------------
@numba.njit(inline="always")
def free_slot_if_clear(x, y, alive, sx, sy, clearance2):
    """The lowest free slot if no alive skyrmion lies closer than √clearance2 to (sx, sy).

    −1 if one does (the site is occupied), −2 if the site is clear but no slot is free.
    """
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


@numba.njit(inline="always")
def insert_planned(x, y, alive, ids, plan, cursor, counters):
    """Make planned insertion ``cursor`` if its site is clear.

    Returns the slot it went into, or a negative number if it cannot be made now (see
    :func:`free_slot_if_clear`).
    """
    slot = free_slot_if_clear(x, y, alive, plan.x[cursor], plan.y[cursor], plan.clearance2)
    if slot >= 0:
        x[slot] = plan.x[cursor]
        y[slot] = plan.y[cursor]
        alive[slot] = True
        ids[slot] = counters.next_id
        plan.ids[cursor] = counters.next_id
        counters.next_id += 1
    return slot


# -- noise ---------------------------------------------------------------------------------------
@numba.njit(inline="always")
def draw_noise(noise, ids, alive, step, cand, nx_, ny_):
    """The step's noise increments ξ = √(2D dt)·z [nm] into ``nx_, ny_``.

    z is standard normal keyed on (seed, id, step): with sub-steps, z is the normalised sum of
    ``substeps`` normals keyed on (seed, id, step·substeps + b).
    """
    n = ids.shape[0]
    amplitude = noise.amplitude
    if noise.substeps == 1:
        fill_gaussian_pairs(noise.seed, ids, alive, step, STREAM_THERMAL, cand, nx_, ny_)
        for i in range(n):
            nx_[i] *= amplitude
            ny_[i] *= amplitude
    else:
        substeps = noise.substeps
        inv_sqrt_sub = 1.0 / math.sqrt(substeps)
        for i in range(n):
            if alive[i]:
                sx = 0.0
                sy = 0.0
                for b in range(substeps):
                    zx, zy = gaussian_pair(noise.seed, ids[i], step * substeps + b, STREAM_THERMAL)
                    sx += zx
                    sy += zy
                nx_[i] = amplitude * sx * inv_sqrt_sub
                ny_[i] = amplitude * sy * inv_sqrt_sub


@numba.njit(**JIT)  # not inlined: compiled once, not at every call site
def draw_radius_normals(noise, ids, alive, step, cand, z_, spare):
    """Standard normals for the radii's noise into ``z_``, keyed on (seed, id, step).

    A sub-stream of their own (the first of each pair; ``spare`` takes the second), summed over
    sub-steps and normalised as the positions' noise is.
    """
    substeps = noise.substeps
    if substeps == 1:
        fill_gaussian_pairs(noise.seed, ids, alive, step, STREAM_RADIUS, cand, z_, spare)
        return
    inv_sqrt_sub = 1.0 / math.sqrt(substeps)
    for i in range(ids.shape[0]):
        if alive[i]:
            s = 0.0
            for b in range(substeps):
                z, _ = gaussian_pair(noise.seed, ids[i], step * substeps + b, STREAM_RADIUS)
                s += z
            z_[i] = s * inv_sqrt_sub
        else:
            z_[i] = 0.0


@numba.njit(**JIT)  # not inlined: compiled once, not at every call site
def scale_radius_noise(r, alive, breathing, nx_, ny_):
    """Scale each centre's noise to its radius's diffusion: ξ·√(D(Rₙ)/D₀).

    The amplitude is taken at the step's start (Itô). The centre's noise depends on the radius
    only, and the radius's noise on nothing, so no spurious drift arises: the Itô and
    Stratonovich readings agree, and the radii and centres still sample exp(−E/k_BT).
    """
    table = breathing.mobility[5]
    inv_h = 1.0 / breathing.spacing
    last = table.shape[0] - 1
    for i in range(r.shape[0]):
        if alive[i]:
            scale = _lerp(table, min(max((r[i] - breathing.r_min) * inv_h, 0.0), last - 1e-9))
            nx_[i] *= scale
            ny_[i] *= scale


@numba.njit(inline="always")
def _step_weights(breathing, z):
    """φ₁, φ₂ and √φ_σ at z ≥ 0: from their table, or past it their forms without e^{−z}."""
    coordinate = z / breathing.z_spacing
    last = breathing.phi.shape[1] - 1
    if coordinate < last:
        return (
            _lerp(breathing.phi[0], coordinate),
            _lerp(breathing.phi[1], coordinate),
            _lerp(breathing.phi[2], coordinate),
        )
    return 1.0 / z, (z - 1.0) / (z * z), math.sqrt(0.5 / z)


@numba.njit(**JIT)  # not inlined: compiled once, not at every call site
def radius_predictor(r, vr0, kr, z_, alive, breathing, dt, thermal, lam, e2, rp):
    """The radii's exponential predictor: exact for a radius in a harmonic well.

    Each radius's stiffness, frozen at the step's start, is λΓ_R = max(E_self''(Rₙ), 0) + ``kr``
    (s² times the slopes of the laws it touches, :func:`pair_forces_breathing`), and with
    z = λ dt that linear part is integrated exactly (exponential time differencing):
        R̃ = Rₙ + dt φ₁(z) v₀ + √(2 k_BT dt/Γ_R · φ_σ(z)) ζ,
        φ₁ = (1 − e^{−z})/z,   φ_σ = (1 − e^{−2z})/(2z),
    v₀ = F_R(Rₙ)/Γ_R. In a harmonic well this is the exact Ornstein–Uhlenbeck step, so no
    stiffness of the radius limits the time step; for λ → 0 it is Euler–Maruyama. ``lam``
    and ``e2`` = dt φ₂(z), φ₂ = (e^{−z} − 1 + z)/z², are kept for the corrector. The
    weights come from a table in z (:class:`~skygas.engine.terms.BreathingTerm`).
    """
    inv_h = 1.0 / breathing.spacing
    last = breathing.curvature.shape[0] - 1
    amplitude = math.sqrt(2.0 * breathing.kt * breathing.inv_friction * dt) if thermal else 0.0
    for i in range(r.shape[0]):
        if not alive[i]:
            rp[i] = r[i]
            continue
        coordinate = min(max((r[i] - breathing.r_min) * inv_h, 0.0), last - 1e-9)
        stiffness = max(_lerp(breathing.curvature, coordinate), 0.0) + kr[i]
        lam[i] = stiffness * breathing.inv_friction
        phi1, phi2, root_phis = _step_weights(breathing, lam[i] * dt)
        e2[i] = dt * phi2
        rp[i] = r[i] + dt * phi1 * vr0[i] + amplitude * root_phis * z_[i]


@numba.njit(**JIT)  # not inlined: compiled once, not at every call site
def radius_corrector(r, rp, vr0, vr1, lam, e2, alive):
    """The radii's exponential corrector (ETD2): R' = R̃ + dt φ₂ [N(R̃) − N(Rₙ)].

    N(R) = F_R(R)/Γ_R + λ(R − Rₙ) is what the frozen linear part leaves; it is constant in a
    harmonic well, where the predictor is already exact.
    """
    for i in range(r.shape[0]):
        if alive[i]:
            rp[i] += e2[i] * (vr1[i] + lam[i] * (rp[i] - r[i]) - vr0[i])


@numba.njit(inline="always")
def reflect_radius(value, breathing):
    """``value`` [nm] reflected back into [r_min, r_max]; and whether it had to be."""
    lo = breathing.r_min
    hi = breathing.r_max
    if value < lo:
        return min(2.0 * lo - value, hi), True
    if value > hi:
        return max(2.0 * hi - value, lo), True
    return value, False


# -- forces --------------------------------------------------------------------------------------
@numba.njit(inline="always")
def interior_floor(xi, yi, margin_i, terms, wall_cutoff):
    """A lower bound on a skyrmion's distance to the device boundary [nm] while within its margin.

    The bound holds while it stays within its margin s_i of (xi, yi), if it is also certain to stay
    beyond the wall-force cutoff there; −1 otherwise (and always when a term reads the grid
    everywhere: the drift from the grid).

    The interpolated fields change by at most √2 per nm (bilinear interpolation of values that
    differ by at most one spacing h between neighbouring nodes), with one spacing more for
    safety where exact values meet the distance transform. A skyrmion with
        d_wall − √2 s_i − h ≥ wall cutoff   and   d_boundary − √2 s_i − h > 0
    feels no wall force and cannot leave while the neighbour list stays valid, and with a
    uniform drift nothing else in the grid concerns it: the force passes skip its lookup.
    """
    if terms.drift.from_grid:
        return -1.0
    grid = terms.grid
    gh = grid.spacing
    field = field_at(grid.fields, (xi - grid.x0) / gh, (yi - grid.y0) / gh)
    slack = math.sqrt(2.0) * margin_i + gh
    if field[CH_WALL_DIST] - slack >= wall_cutoff and field[CH_DOMAIN] - slack > 0.0:
        return field[CH_DOMAIN] - slack
    return -1.0


@numba.njit(inline="always")
def interior_floors(x, y, alive, terms, margin, floor):
    """:func:`interior_floor` of every skyrmion (−1 for empty slots)."""
    # a breathing skyrmion larger than R₀ meets the walls earlier
    wall_cutoff = terms.wall.cutoff + terms.breathing.wall_reach
    for i in range(x.shape[0]):
        floor[i] = interior_floor(x[i], y[i], margin[i], terms, wall_cutoff) if alive[i] else -1.0


@numba.njit(inline="always")
def pair_forces(x, y, pair, owner, start, pair_j, n_owners, fx, fy, counters):
    """Pair forces (pN) of the neighbour list into ``fx, fy`` (overwritten).

    The table holds |F|/r in r², so F = (|F|/r)(dx, dy) needs no square root or division.
    """
    for i in range(x.shape[0]):
        fx[i] = 0.0
        fy[i] = 0.0
    table = pair.table
    cut2 = pair.cutoff * pair.cutoff
    inv_h2 = 1.0 / pair.spacing_r2
    evaluated = 0
    branch_free = start[n_owners] > BRANCH_FREE_ENTRIES
    for e in range(n_owners):
        i = U(owner[e])
        xi = x[i]
        yi = y[i]
        fxi = 0.0  # accumulate in registers: one store per owner, not one per pair
        fyi = 0.0
        for p in range(start[e], start[e + 1]):
            j = U(pair_j[U(p)])
            dx = xi - x[j]
            dy = yi - y[j]
            r2 = dx * dx + dy * dy
            inside = r2 < cut2
            if branch_free or inside:  # the compiler makes two loops, one without the branch
                f = _lerp(table, min(r2, cut2) * inv_h2)
                f = f if inside else 0.0
                fxi += f * dx
                fyi += f * dy
                fx[j] -= f * dx
                fy[j] -= f * dy
                evaluated += inside
        fx[i] += fxi
        fy[i] += fyi
    counters.pair_evaluations += evaluated


@numba.njit(**JIT)  # not inlined: compiled once, not at every call site
def pair_forces_breathing(
    x, y, r, pair, breathing, owner, start, pair_j, n_owners, fx, fy, fr, kr, stiffen
):
    """Pair forces of breathing skyrmions: on the centres into ``fx, fy``, on the radii into ``fr``.

    All overwritten, with ``kr`` if ``stiffen``: each radius's stiffness from the law,
    s_p² Σⱼ κ(ρ), κ = −d|F|/dρ ≥ 0 [pN/nm] (its step takes it into its exact linear part,
    :func:`radius_predictor`; the corrector's pass does not need it). The law acts on the
    gap ρ = d − s_p (Rᵢ + Rⱼ − 2R₀) (:class:`~skygas.physics.materials.BreathingSpec`): the
    centres feel |F|(ρ) along the line
    between them, each radius −∂E/∂Rᵢ = −s_p |F|(ρ). The neighbour list reaches ``pair_reach``
    farther than the law, for the largest radii. A gap below ``closest`` reads the law there.
    Returns the pairs evaluated within the law's reach.
    """
    for i in range(x.shape[0]):
        fx[i] = 0.0
        fy[i] = 0.0
        fr[i] = 0.0
        kr[i] = 0.0
    table = pair.table
    law_cut = pair.cutoff
    list_cut = law_cut + breathing.pair_reach
    list_cut2 = list_cut * list_cut
    inv_h2 = 1.0 / pair.spacing_r2
    shift = breathing.pair_shift
    shift2 = shift * shift
    r0 = breathing.r0
    closest = breathing.closest
    evaluated = 0
    for e in range(n_owners):
        i = U(owner[e])
        xi = x[i]
        yi = y[i]
        gi = r[i] - r0
        fxi = 0.0
        fyi = 0.0
        fri = 0.0
        kri = 0.0
        # with branches (measured: the branch-free form of pair_forces, which computes every
        # entry, is twice as slow here, where an entry costs a square root and a division)
        for p in range(start[e], start[e + 1]):
            j = U(pair_j[U(p)])
            dx = xi - x[j]
            dy = yi - y[j]
            d2 = dx * dx + dy * dy
            if d2 < list_cut2:
                inv_d = 1.0 / math.sqrt(d2)
                gap = d2 * inv_d - shift * (gi + r[j] - r0)
                if gap < law_cut:
                    gap = max(gap, closest)
                    # the table holds g = |F|/ρ in ρ²: |F| = ρ g, d|F|/dρ = g + 2ρ² dg/d(ρ²)
                    g, slope = _lerp_slope(table, gap * gap * inv_h2)
                    magnitude = g * gap
                    along = magnitude * inv_d
                    fxi += along * dx
                    fyi += along * dy
                    fx[j] -= along * dx
                    fy[j] -= along * dy
                    fri -= shift * magnitude
                    fr[j] -= shift * magnitude
                    if stiffen:
                        stiffness = shift2 * max(-(g + 2.0 * gap * gap * slope * inv_h2), 0.0)
                        kri += stiffness
                        kr[j] += stiffness
                    evaluated += 1
        fx[i] += fxi
        fy[i] += fyi
        fr[i] += fri
        kr[i] += kri
    return evaluated


@numba.njit(inline="always")
def wall_force(wall, field):
    """The wall term's force [pN] at a grid lookup ``field``.

    |F|(d) along the inward normal within the cutoff, zero beyond it.
    """
    d = field[CH_WALL_DIST]
    if d < wall.cutoff:
        fw = _lerp(wall.table, max(d, 0.0) / wall.spacing)
        return fw * field[CH_NORMAL_X], fw * field[CH_NORMAL_Y]
    return 0.0, 0.0


@numba.njit(inline="always")
def wall_magnitude(wall, d):
    """|F| [pN] of the wall law at distance ``d`` [nm] (0 beyond the cutoff), and −d|F|/dd ≥ 0."""
    if d < wall.cutoff:
        value, slope = _lerp_slope(wall.table, max(d, 0.0) / wall.spacing)
        return value, max(-slope / wall.spacing, 0.0)
    return 0.0, 0.0


@numba.njit(**JIT)  # not inlined: compiled once, not at every call site
def add_breathing_wall_forces(x, y, r, alive, terms, vx, vy, vr, kr, floor):
    """A breathing skyrmion's wall law at the gap w − s_w(R − R₀): on its centre and radius.

    :func:`add_one_body_forces` adds the law at the centre's distance w, as for a rigid
    skyrmion (its loop stays the one rigid runs compile, bit for bit); this adds the
    difference |F|(w − s_w ΔR) − |F|(w) along the normal, −s_w |F|(w − s_w ΔR) to the
    radius's force and s_w² κ to its stiffness ``kr``. Skyrmions with ``floor[i] > 0`` are
    beyond the law's reach at any radius.
    """
    grid = terms.grid
    inv_gh = 1.0 / grid.spacing
    breathing = terms.breathing
    shift = breathing.wall_shift
    for i in range(x.shape[0]):
        if not alive[i] or floor[i] > 0.0:
            continue
        field = field_at(grid.fields, (x[i] - grid.x0) * inv_gh, (y[i] - grid.y0) * inv_gh)
        d = field[CH_WALL_DIST]
        shifted, stiffness = wall_magnitude(terms.wall, d - shift * (r[i] - breathing.r0))
        extra = shifted - wall_magnitude(terms.wall, d)[0]
        vx[i] += extra * field[CH_NORMAL_X]
        vy[i] += extra * field[CH_NORMAL_Y]
        vr[i] -= shift * shifted
        kr[i] += shift * shift * stiffness


@numba.njit(inline="always")
def drive_force(drift, vsx, vsy):
    """The drift term's force [pN] for a spin-drift velocity v_s [nm/ns]: μ(g ε + b I)·v_s."""
    return drift.drive_g * vsy + drift.drive_b * vsx, -drift.drive_g * vsx + drift.drive_b * vsy


@numba.njit(inline="always")
def landscape_force(landscape, xi, yi):
    """The landscape term's force −∇U [pN] at (xi, yi) [nm]."""
    inv_h = 1.0 / landscape.spacing
    gx, gy = hermite_gradient(
        landscape.coefficients, (xi - landscape.x0) * inv_h, (yi - landscape.y0) * inv_h, inv_h
    )
    return -gx, -gy


@numba.njit(inline="always")
def add_one_body_forces(x, y, alive, terms, mobility, vx, vy, domain, floor):
    """Add the one-body terms (wall, drive, constant force) and turn the totals into velocities.

    The forces in ``vx, vy`` become velocities in place, v = M·F. The signed boundary distance at
    each position goes into ``domain`` (it shares the cache lines of the wall lookup, and lets the
    step's acceptance skip a lookup); a skyrmion with ``floor[i] > 0`` (:func:`interior_floor`)
    skips the lookup and gets that lower bound.
    """
    grid = terms.grid
    inv_gh = 1.0 / grid.spacing
    drift = terms.drift
    vsx = drift.vs_x
    vsy = drift.vs_y
    for i in range(x.shape[0]):
        if not alive[i]:
            continue
        fx = vx[i]
        fy = vy[i]
        if floor[i] > 0.0:
            domain[i] = floor[i]
        else:
            field = field_at(grid.fields, (x[i] - grid.x0) * inv_gh, (y[i] - grid.y0) * inv_gh)
            domain[i] = field[CH_DOMAIN]
            wx, wy = wall_force(terms.wall, field)
            fx += wx
            fy += wy
            if drift.from_grid:
                vsx = field[CH_DRIFT_X]
                vsy = field[CH_DRIFT_Y]
        dx, dy = drive_force(drift, vsx, vsy)
        fx += dx
        fy += dy
        # v = (a F − g εF)/(a² + g²)
        vx[i] = mobility.a * fx - mobility.g * fy
        vy[i] = mobility.a * fy + mobility.g * fx
    # The constant force's velocity M·F_ext, added in a loop of its own: in the loop above the
    # compiler may regroup the sum of the forces (fastmath), and a run without the force keeps
    # the bits it had before the term existed.
    cfx, cfy = terms.constant.fx, terms.constant.fy
    if cfx != 0.0 or cfy != 0.0:
        cvx = mobility.a * cfx - mobility.g * cfy
        cvy = mobility.a * cfy + mobility.g * cfx
        for i in range(x.shape[0]):
            if alive[i]:
                vx[i] += cvx
                vy[i] += cvy


@numba.njit(inline="always")
def add_landscape_forces(x, y, alive, landscape, fx, fy):
    """Add the landscape term's force −∇U to ``fx, fy``.

    A loop of its own: the one-body loop stays as short as without a landscape (the compiler keeps
    it vectorised).
    """
    for i in range(x.shape[0]):
        if alive[i]:
            lx, ly = landscape_force(landscape, x[i], y[i])
            fx[i] += lx
            fy[i] += ly


@numba.njit(**JIT)  # not inlined: compiled once, not at every call site
def add_radius_velocities(r, alive, breathing, vr):
    """Add each radius's self force −E_self'(R) to ``vr`` and turn it into dR/dt = F_R/Γ_R."""
    inv_h = 1.0 / breathing.spacing
    last = breathing.self_force.shape[0] - 1
    for i in range(r.shape[0]):
        if alive[i]:
            coordinate = min(max((r[i] - breathing.r_min) * inv_h, 0.0), last - 1e-9)
            vr[i] = (vr[i] + _lerp(breathing.self_force, coordinate)) * breathing.inv_friction


@numba.njit(**JIT)  # not inlined: compiled once, not at every call site
def apply_radius_mobility(x, y, r, alive, terms, vx, vy):
    """Each breathing skyrmion's velocity at its own 𝒟(R): M₀F in ``vx, vy`` becomes M(R)F'.

    :func:`add_one_body_forces` turned the forces into velocities with the material's 𝒟 (its
    loop stays the one rigid runs compile, bit for bit); here v' = P v − Q εv re-weights them
    with the mobility at the radius, and the dissipative drive's change, (c − 1) μb v_s with
    c = 𝒟(R)/𝒟(R₀), is added through M(R) (:class:`~skygas.engine.terms.BreathingTerm`).
    """
    breathing = terms.breathing
    table = breathing.mobility
    drift = terms.drift
    grid = terms.grid
    inv_gh = 1.0 / grid.spacing
    inv_h = 1.0 / breathing.spacing
    last = table.shape[1] - 1
    vsx = drift.vs_x
    vsy = drift.vs_y
    driven = drift.drive_b != 0.0 and (drift.from_grid or vsx != 0.0 or vsy != 0.0)
    for i in range(x.shape[0]):
        if not alive[i]:
            continue
        coordinate = min(max((r[i] - breathing.r_min) * inv_h, 0.0), last - 1e-9)
        p = _lerp(table[0], coordinate)
        q = _lerp(table[1], coordinate)
        wx = vx[i]
        wy = vy[i]
        vx[i] = p * wx - q * wy
        vy[i] = p * wy + q * wx
        if driven:
            if drift.from_grid:
                field = field_at(grid.fields, (x[i] - grid.x0) * inv_gh, (y[i] - grid.y0) * inv_gh)
                vsx = field[CH_DRIFT_X]
                vsy = field[CH_DRIFT_Y]
            extra = _lerp(table[4], coordinate) * drift.drive_b
            fx = extra * vsx
            fy = extra * vsy
            a = _lerp(table[2], coordinate)
            g = _lerp(table[3], coordinate)
            vx[i] += a * fx - g * fy
            vy[i] += a * fy + g * fx


@numba.njit(**JIT)  # not inlined: compiled once, not at every call site
def add_wall_film_forces(x, y, r, alive, terms, vx, vy, vr, kr, floor, stiffen):
    """The wall law as the missing film's field: −∇U on the centres, −s_w ∂U/∂δ on the radii.

    Rigid skyrmions read the one layer (δ = 0). A breathing skyrmion's film is eroded by
    δ = s_w(R − R₀), interpolated between four layers by the Catmull–Rom rule
    (:func:`skygas.fields.landscape.wall_film.catmull_rom`), which also
    gives the radius's force and, if ``stiffen``, its stiffness s_w² ∂²U/∂δ² (≥ 0) in ``kr``.
    Skyrmions with ``floor[i] > 0`` are beyond the walls' reach at any radius.
    """
    film = terms.wall_film
    breathing = terms.breathing
    inv_h = 1.0 / film.spacing
    shift = breathing.wall_shift
    last = film.layers - 3
    for i in range(x.shape[0]):
        if not alive[i] or floor[i] > 0.0:
            continue
        fx = (x[i] - film.x0) * inv_h
        fy = (y[i] - film.y0) * inv_h
        if not breathing.active:
            gx, gy = hermite_gradient(film.coefficients[0], fx, fy, inv_h)
            vx[i] -= gx
            vy[i] -= gy
            continue
        s = (shift * (r[i] - breathing.r0) - film.delta0) / film.delta_step
        k = min(max(int(math.floor(s)), 1), last)
        value, slope, curve = catmull_rom(min(max(s - k, 0.0), 1.0))
        sx = 0.0
        sy = 0.0
        du = 0.0
        d2u = 0.0
        for m in range(4):
            cells = film.coefficients[k - 1 + m]
            u = hermite_value(cells, fx, fy)
            gx, gy = hermite_gradient(cells, fx, fy, inv_h)
            sx += value[m] * gx
            sy += value[m] * gy
            du += slope[m] * u
            d2u += curve[m] * u
        vx[i] -= sx
        vy[i] -= sy
        inv_d = 1.0 / film.delta_step
        vr[i] -= shift * du * inv_d
        if stiffen:
            kr[i] += shift * shift * max(d2u, 0.0) * inv_d * inv_d


@numba.njit(**JIT)  # not inlined: compiled once, not at every call site
def add_stray_radius_forces(x, y, r, alive, breathing, vx, vy, vr, kr, stiffen):
    """A breathing skyrmion in the edges' stray field: a(R) U_s on its centre and radius.

    The landscape already applied −∇U_s (a = 1); here the centre gets −(a(R) − 1)∇U_s, the
    radius −a'(R) U_s and, if ``stiffen``, the stiffness max(a''(R) U_s, 0) in ``kr``
    (:class:`skygas.physics.materials.BreathingSpec`, ``moment_deficit``).
    """
    stray = breathing.stray
    inv_h = 1.0 / stray.spacing
    inv_g = 1.0 / breathing.spacing
    last = breathing.area_excess.shape[0] - 1
    for i in range(x.shape[0]):
        if not alive[i]:
            continue
        fx = (x[i] - stray.x0) * inv_h
        fy = (y[i] - stray.y0) * inv_h
        u = hermite_value(stray.coefficients, fx, fy)
        gx, gy = hermite_gradient(stray.coefficients, fx, fy, inv_h)
        coordinate = min(max((r[i] - breathing.r_min) * inv_g, 0.0), last - 1e-9)
        excess = _lerp(breathing.area_excess, coordinate)
        vx[i] -= excess * gx
        vy[i] -= excess * gy
        vr[i] -= _lerp(breathing.area_slope, coordinate) * u
        if stiffen:
            kr[i] += max(_lerp(breathing.area_curvature, coordinate) * u, 0.0)


@numba.njit(inline="always")
def force_pass(
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
    vx,
    vy,
    vr,
    kr,
    counters,
    domain,
    floor,
    stiffen,
):
    """Deterministic velocity [nm/ns] of every alive skyrmion from the sum of all force terms.

    A breathing model's radii get theirs too, dR/dt [nm/ns] in ``vr``, and in ``kr`` (if
    ``stiffen``: the predictor's pass) the stiffness [pN/nm] the laws add to each radius. See
    :func:`add_one_body_forces` for ``domain`` and ``floor``.
    """
    breathing = terms.breathing
    if breathing.active:
        counters.pair_evaluations += pair_forces_breathing(
            x, y, r, terms.pair, breathing, owner, start, pair_j, n_owners, vx, vy, vr, kr, stiffen
        )
    else:
        pair_forces(x, y, terms.pair, owner, start, pair_j, n_owners, vx, vy, counters)
    if terms.landscape.active:
        add_landscape_forces(x, y, alive, terms.landscape, vx, vy)
    if terms.wall_film.active:
        add_wall_film_forces(x, y, r, alive, terms, vx, vy, vr, kr, floor, stiffen)
    elif breathing.active:
        add_breathing_wall_forces(x, y, r, alive, terms, vx, vy, vr, kr, floor)
    if breathing.stray.active:
        add_stray_radius_forces(x, y, r, alive, breathing, vx, vy, vr, kr, stiffen)
    add_one_body_forces(x, y, alive, terms, mobility, vx, vy, domain, floor)
    if breathing.active:
        if breathing.mobility_varies:
            apply_radius_mobility(x, y, r, alive, terms, vx, vy)
        add_radius_velocities(r, alive, breathing, vr)


# -- exits and walls -----------------------------------------------------------------------------
@numba.njit(inline="always")
def segments_cross(px, py, qx, qy, ax, ay, bx, by):
    """True if segment p→q crosses segment a→b (proper or touching)."""
    d1 = (bx - ax) * (py - ay) - (by - ay) * (px - ax)
    d2 = (bx - ax) * (qy - ay) - (by - ay) * (qx - ax)
    d3 = (qx - px) * (ay - py) - (qy - py) * (ax - px)
    d4 = (qx - px) * (by - py) - (qy - py) * (bx - px)
    return d1 * d2 <= 0.0 and d3 * d4 <= 0.0


@numba.njit(inline="always")
def crossed_port(x0, y0, x1, y1, ports):
    """Index of the port the move (x0, y0) → (x1, y1) crosses, or −1."""
    for p in range(ports.shape[0]):
        if segments_cross(x0, y0, x1, y1, ports[p, 0], ports[p, 1], ports[p, 2], ports[p, 3]):
            return p
    return -1


@numba.njit(inline="always")
def is_inside(grid, px, py):
    """True if (px, py) [nm] lies inside the device boundary (walls and ports)."""
    inv_gh = 1.0 / grid.spacing
    return field_at(grid.fields, (px - grid.x0) * inv_gh, (py - grid.y0) * inv_gh)[CH_DOMAIN] >= 0.0


# -- recording -----------------------------------------------------------------------------------
@numba.njit(inline="always")
def record_frame(x, y, alive, ids, f, frames_x, frames_y, frames_id):
    """Frame ``f``: positions [nm] (NaN where a slot is empty) and ids (−1 where empty)."""
    for i in range(x.shape[0]):
        if alive[i]:
            frames_x[f, i] = x[i]
            frames_y[f, i] = y[i]
            frames_id[f, i] = ids[i]
        else:
            frames_x[f, i] = np.nan
            frames_y[f, i] = np.nan
            frames_id[f, i] = -1


@numba.njit(**JIT)  # not inlined: compiled once, not at every call site
def record_radii(r, alive, f, frames_r):
    """Frame ``f`` of a breathing model's radii [nm] (NaN where a slot is empty)."""
    for i in range(r.shape[0]):
        frames_r[f, i] = r[i] if alive[i] else np.nan
