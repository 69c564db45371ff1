"""From calibration energies to force laws: tables, the paper's forms, the straight edge.

**Pair law.** E(d) = E_pair − 2E_single + E_uniform at each measured centre distance d (the
guiding centres that the project's detector finds in the relaxed pair; they are held where
asked, within a fraction of a cell). **Short-range wall law.**
E(x) = E_single(x) − E_single(centre) against the measured distance x of the guiding centre
from the calibration film's edge (compensated film: the edge acts only at short range).

**Forces.** F = −dE/dd from a cubic spline through ln E (exact for an exponential, the
laws' decay at long range; E stays positive for a repulsion), tabulated on a fine grid over
the measured range, and continued beyond the farthest point with the exponential decay of the
last three points until the force is far below the engine's cutoff (1e-4 F₀). Below the closest
measured distance the engine holds the force constant
(:class:`skygas.physics.materials.ForceTableSpec`); the wall law first goes on along its tangent
there, F(x) = F(x₀) + F'(x₀)(x − x₀), down to x₀/2 (:data:`WALL_CONTINUATION`): an edge single
held nearer than x₀ leaves through the edge (S2 below 0.69 d_sk), but a skyrmion that its
neighbours push comes nearer (S2 to 0.62 d_sk in the validation rectangle), and a wall held at
F(x₀) there let the model's skyrmion run on into it (S2's rectangle: 0.30 d_sk of RMS error,
0.164 with the tangent). The tangent keeps the law's steepest slope, which sets the engine's
time step, the measured one. The pair law stays held: closer than its first point a pair
merges.

**Straight edge.** A skyrmion near one straight edge of a real (uncompensated) film feels the
short-range law plus the first-order energy in the edge's stray field,
U(x) = μ₀M_s t ∫ w(|r' − r|) H(x') dA' over the film x' > 0, H(x') = (M_s/π)·atan(h/x')
(h = t/2, :mod:`skygas.fields.landscape.stray_field`): what the paper's wall law describes, and what
:func:`straight_edge_force` returns, to fit the paper's form and compare with the paper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import interpolate

from skygas.core.units import MU_0

#: The farthest tabulated force [F₀]: far below the engine's default cutoff (1e-3 F₀).
TABLE_FLOOR = 1e-4
#: Table nodes over the measured range.
TABLE_NODES = 96
#: The wall law continues along its tangent below its first measured distance x₀, down to
#: this fraction of x₀ (module docstring), on this many nodes.
WALL_CONTINUATION = 0.5
CONTINUATION_NODES = 12


@dataclass(frozen=True)
class EnergyCurve:
    """Energies [J] against distances [m] (sorted, distinct), and which were left out and why.

    ``dropped``: list of (distance, reason).
    """

    distance: np.ndarray
    energy: np.ndarray
    dropped: tuple[tuple[float, str], ...] = ()


@dataclass(frozen=True)
class ForceLaw:
    """A tabulated repulsion: ``distance`` [m], ``force`` [N].

    ``measured`` is the range [m] the energies covered (beyond: exponential continuation with decay
    length ``decay`` [m]).
    """

    distance: np.ndarray
    force: np.ndarray
    measured: tuple[float, float]
    decay: float

    def __call__(self, d):
        """|F| [N] at ``d`` [m], as the engine interpolates it (PCHIP, held below, 0 beyond)."""
        d = np.asarray(d, float)
        f = interpolate.PchipInterpolator(self.distance, self.force)(
            np.clip(d, self.distance[0], self.distance[-1])
        )
        return np.where(d > self.distance[-1], 0.0, f)


def curve(points: list[tuple[float, float]], dropped=()) -> EnergyCurve:
    """An :class:`EnergyCurve` from (distance, energy) pairs (duplicates averaged)."""
    points = sorted(points)
    d = np.array([p[0] for p in points])
    e = np.array([p[1] for p in points])
    keep = np.concatenate([[True], np.diff(d) > 1e-12])
    return EnergyCurve(d[keep], e[keep], tuple(dropped))


def force_law(energy: EnergyCurve, force_scale: float, continued: bool = False) -> ForceLaw:
    """F(d) = −dE/dd (see the module docstring); ``force_scale`` F₀ [N] sets the floor.

    ``continued``: the table also runs below the first measured distance along the law's
    tangent there, down to :data:`WALL_CONTINUATION` of it (the wall law; module docstring).
    """
    d, e = energy.distance, energy.energy
    positive = e > 0
    if not positive.all():  # the far tail vanished into rounding: keep what is above it
        last = int(np.argmin(positive))
        d, e = d[:last], e[:last]
    if len(d) < 4:
        raise ValueError("fewer than 4 positive energies: no repulsion to tabulate")
    spline = interpolate.CubicSpline(d, np.log(e), bc_type="not-a-knot")
    nodes = np.linspace(d[0], d[-1], TABLE_NODES)
    force = -spline(nodes, 1) * np.exp(spline(nodes))
    force = np.maximum(force, 0.0)
    slope = np.polyfit(d[-3:], np.log(e[-3:]), 1)[0]  # ln E ≈ c − d/λ at the far end
    decay = -1.0 / slope if slope < 0 else (d[-1] - d[0])
    tail: list[float] | np.ndarray = []
    if force[-1] > TABLE_FLOOR * force_scale:
        reach = decay * math.log(force[-1] / (TABLE_FLOOR * force_scale))
        tail = np.linspace(d[-1], d[-1] + reach, 24)[1:]
    far = force[-1] * np.exp(-(np.asarray(tail) - d[-1]) / decay)
    near = near_force = np.empty(0)
    if continued:
        near = np.linspace(WALL_CONTINUATION * d[0], d[0], CONTINUATION_NODES + 1)[:-1]
        tangent = -spline(d[0], 2) * np.exp(spline(d[0])) + spline(d[0], 1) * force[0]
        # F = −(ln E)′ E and E′ = −F, so F′ = −(ln E)″ E + (ln E)′ F; a wall's F′ < 0
        near_force = force[0] + min(float(tangent), 0.0) * (near - d[0])
    return ForceLaw(
        np.concatenate([near, nodes, tail]),
        np.concatenate([near_force, force, far]),
        (float(d[0]), float(d[-1])),
        float(decay),
    )


def projected_profile(profile_radius, profile_deficit, u: np.ndarray) -> np.ndarray:
    """W(u) = ∫ w(√(u² + v²)) dv [m]: the deficit profile integrated across a line."""
    r = np.asarray(profile_radius, float)
    w = np.asarray(profile_deficit, float)
    v = np.linspace(0.0, r[-1], 400)
    rho = np.hypot(np.asarray(u, float)[:, None], v[None, :])
    return 2.0 * np.trapezoid(np.interp(rho, r, w, right=0.0), v, axis=1)


def halfplane_stray_energy(
    x, saturation_magnetization: float, thickness: float, profile_radius, profile_deficit
) -> np.ndarray:
    """U(x) [J] of a skyrmion at distance x [m] from the straight edge of a half-plane film.

    First order in its deficit (module docstring); 0 far from the edge.
    """
    h = 0.5 * thickness
    reach = float(profile_radius[-1])
    out = []
    for xc in np.atleast_1d(np.asarray(x, float)):
        xp = np.linspace(max(xc - reach, 0.0), xc + reach, 801)[1:]
        field = saturation_magnetization / math.pi * np.arctan(h / xp)
        weight = projected_profile(profile_radius, profile_deficit, xp - xc)
        out.append(MU_0 * saturation_magnetization * thickness * np.trapezoid(field * weight, xp))
    return np.array(out)


def straight_edge_force(
    wall: ForceLaw,
    x: np.ndarray,
    saturation_magnetization: float,
    thickness: float,
    profile_radius,
    profile_deficit,
) -> np.ndarray:
    """|F| [N] of a straight edge of a real film at distances ``x`` [m].

    The short-range law plus −dU/dx of the edge's stray field (module docstring).
    """
    x = np.asarray(x, float)
    step = 0.25e-9
    u_plus = halfplane_stray_energy(
        x + step, saturation_magnetization, thickness, profile_radius, profile_deficit
    )
    u_minus = halfplane_stray_energy(
        np.maximum(x - step, 1e-12),
        saturation_magnetization,
        thickness,
        profile_radius,
        profile_deficit,
    )
    return wall(x) + (u_minus - u_plus) / (2 * step)


def paper_form_fits(
    pair: ForceLaw, edge_x: np.ndarray, edge_force: np.ndarray, diameter: float, force_scale: float
) -> dict:
    """The paper's forms fitted to the tabulated laws over their measured ranges.

    With :func:`skygas.micromag.fit_pair_law` and :func:`~skygas.micromag.fit_wall_law`: the
    coefficients, the range [d_sk] and the rms residual of ln|F|, or why there is no fit.
    """
    from skygas.core.errors import InputError
    from skygas.micromag.forces import fit_pair_law, fit_wall_law

    out: dict[str, dict[str, Any]] = {}
    lo, hi = pair.measured
    d = np.linspace(max(lo, diameter), hi, 40)  # the paper's forms start at one diameter
    samples = {"pair": (d, pair(d)), "wall": (edge_x, edge_force)}
    for law, (dist, force) in samples.items():
        try:
            fit = (fit_pair_law if law == "pair" else fit_wall_law)(
                dist / diameter, force, force_scale
            )
        except InputError as err:
            out[law] = {"coefficients": None, "why": str(err)}
            continue
        out[law] = {
            "coefficients": [float(c) for c in fit.coefficients],
            "uncertainties": [float(u) for u in fit.uncertainties],
            "range_d_sk": [float(dist.min() / diameter), float(dist.max() / diameter)],
            "rms_log_residual": float(fit.rms_log_residual),
            "note": fit.note,
        }
    return out
