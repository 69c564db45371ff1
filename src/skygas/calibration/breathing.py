"""What a breathing skyrmion needs: E_self(R), 𝒟_RR, and how the laws move with the radius.

The breathing particle model (:class:`skygas.physics.materials.BreathingSpec`) gives each
skyrmion its radius R as a degree of freedom. The calibration measures what it needs from the
solves of :mod:`skygas.calibration.plan` (the breathing scan and the *shifted* laws):

**E_self(R), by a field scan.** A uniform extra field b [A/m] adds −μ₀M_s t b ∫ m_z dA to the
energy: relative to the uniform film, +μ₀M_s t b A_m with A_m = ∫(1 − m_z) dA the skyrmion's
reversed area (its moment deficit). It is a Lagrange multiplier on A_m: relaxed at H_ref + b,
the isolated skyrmion takes the radius R(b) that minimises E_self + μ₀M_s t b A_m, E_self its
energy at H_ref alone. For each offset B = μ₀b [T] of the scan,

    E_self(R(b)) = (E_single − E_uniform)(b) − M_s t B A_m(b),   A_m = M_uniform − M_single

(M = ∫ m_z dA of each relaxed texture, the uniform film relaxed at the same field: the film's
edges respond to b as well, and cancel to first order), i.e. each relaxed texture's energy
with the reference field only, above the uniform film's. The same curve follows, independently,
from the multiplier alone: dE_self/dA_m = −M_s t B at every scan point, so E_self is also
−M_s t ∫ B dA_m along the scan (the *integrated* energies, a check of the subtraction), and
the force on the radius is −dE_self/dR = M_s t B dA_m/dR ≈ 4πR M_s t B (A_m ≈ 2πR² for a
thin wall).

**𝒟_RR** = ∫ ∂_R m·∂_R m dA (dimensionless, as 𝒟 = ½∫(∂ₓm·∂ₓm + ∂ᵧm·∂ᵧm) dA), with ∂_R m
the central difference of the relaxed textures at H_ref ± 1 mT/μ₀ over their radii: the
derivative along the family of relaxed skyrmions, shape changes included. Beside it: the
rigidly shifted profile, m(r − R), whose ∂_R m = −∂_r m; the 360° wall ansatz with the
measured R and Δ, 2π∫(∂_R θ)² r dr; and the thin-wall limit 4πR/Δ.

**The shifts s_p, s_w.** At the scan's offset aiming at a skyrmion 15 % smaller, pairs and edge
singles in the calibration film give the laws at a second radius R₀ + ΔR. The model says
E_pair(d) = U_pair(d − 2 s_p ΔR) and E_wall(x) = U_wall(x − s_w ΔR), U the laws at R₀ (the
cubic spline through ln E of their energies): s is fitted by least squares in ln E, and its
rms ln-residual is reported with those of s = 0 (laws blind to the radius) and s = 1 (laws on
the gap between the domain walls). A pair's singles are not solved again: the pair energy
takes the centre single's and subtracts the edge energy of its two singles from the law at R₀
(their singles sit ≥ 3.4 d_sk from the edges, where it is below half a percent of the pair
energy; the largest share is reported).

**The laws at the gap.** The laws' pairs and edge singles are relaxed with their centres held,
and squeezed: each law is the force along its family of relaxed skyrmions. The radius R(d) of
each (the squeezed fit's rows, :func:`law_radii`) is written per table distance
(``pair_radius``, ``wall_radius``), and the model reads the law at the gap
d − 2s_p(R(d) − R₀): there ∂E/∂R = 0, so the measured force is the model's (the envelope
theorem, :meth:`skygas.physics.materials.Material.breathing_laws`).

**𝒟(R) of the centre**: each scan texture's 𝒟, as the skyrmion detection measures it
(:func:`centre_dissipation`), written as ``dissipation`` per table radius.

**The choice.** Where the validation ran both models against the same micromagnetic run, the
one with the smaller RMS centre error (:func:`choose_by_validation`); without a validation,
``particle_model = "breathing"`` when |d ln R/dB| exceeds :data:`BREATHING_SENSITIVITY`, else
``"rigid"``. The ``[material.breathing]`` table is written whenever it was measured.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy import integrate, interpolate, optimize

from skygas.calibration.analysis import valid_solve

#: |d ln R/dB| [per mT] above which the calibrated model is a breathing one. A skyrmion's
#: neighbours press on its radius as an extra field would: by the Lagrange relation
#: −dE_self/dR = 4πR M_s t B, a neighbour's pair force F at 1.5 d_sk (s = 1) acts like
#: B = F/(4πR M_s t), about 9 mT for S6 and 2 mT for S2 (summary.json's
#: ``breathing.neighbour_field_T``), and a device's own stray field near an edge is ten or
#: more mT above its interior's. Fields of about 5 mT are thus common; at 2 % per mT they
#: change the radius by 10 %, which moves a pair's gap by 2ΔR = 0.1 d_sk, the validation's
#: goal. S6 (0.7 % per mT) stays rigid, S2 (6.3 % per mT) breathes. A round number, not a
#: fit: ``breathing.neighbour_radius_change`` estimates each material's own change.
BREATHING_SENSITIVITY = 0.02
#: A scan point is used only while its skyrmion stays round (shortest / longest contour ray):
#: an elongating one is past the breathing mode's range (its elliptic instability).
SCAN_MIN_CIRCULARITY = 0.85
#: The neighbour distance [d_sk] of ``neighbour_field_T`` (a dense packing).
NEIGHBOUR_DISTANCE = 1.5
#: Largest shift fitted: the laws are not expected to move by more than a few radius changes.
MAX_SHIFT = 4.0


def _one_skyrmion(result: dict | None) -> dict | None:
    """The result's one skyrmion, None unless it kept it (:func:`analysis.valid_solve`)."""
    if result is None or not valid_solve(result, 1):
        return None
    return result["skyrmions"][0]


def _field_of(job, name: str) -> float:
    """The field offset B [T] of the planned solve ``name`` over the reference field."""
    from skygas.core.units import MU_0

    (task,) = [s for s in job.planned() if s.name == name]
    return MU_0 * (task.film.reference_field - job.config.reference_field)


def scan_points(job, iso) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """The breathing scan's points, sorted by radius, and those left out (with why).

    Each point: ``name``, ``field_T``, ``radius_m``, ``energy_J`` (E_self: the texture's energy
    with the reference field only, above the uniform film's), ``energy_at_field_J`` (above the
    uniform film at its own field), ``moment_deficit_m2`` (A_m, from the film's ∫ m_z dA),
    ``circularity``. The isolated skyrmion is the point at B = 0.
    """
    m = job.config.material
    ms_t = m.saturation_magnetization * m.film_thickness
    prefix = job.isolated_prefix()
    pairs = [(f"{prefix}/single", f"{prefix}/uniform", 0.0)]
    labels = ["plus", "minus"] + sorted(
        k.split("/", 1)[1]
        for k in job.results
        if k.startswith("sensitivity/scan/") and not k.startswith("sensitivity/uniform/")
    )
    for label in labels:
        single, uniform = f"sensitivity/{label}", f"sensitivity/uniform/{label}"
        if single in job.results and uniform in job.results:
            pairs.append((single, uniform, _field_of(job, single)))
    points, dropped = [], []
    for single, uniform, field_T in pairs:
        s, u = job.results[single], job.results[uniform]
        sk = _one_skyrmion(s)
        why = None
        if sk is None:
            why = "not one skyrmion (collapsed, split or grown into a stripe)"
        elif "moment_z" not in s or "moment_z" not in u:
            why = "solved before the moment ∫ m_z dA was recorded"
        elif not sk.get("circularity", 1.0) >= SCAN_MIN_CIRCULARITY:
            why = f"elongated (circularity {sk.get('circularity', math.nan):.2f})"
        if sk is None or why is not None:
            dropped.append({"name": single, "field_T": field_T, "why": why})
            continue
        deficit = u["moment_z"] - s["moment_z"]
        at_field = s["energy"] - u["energy"]
        points.append(
            {
                "name": single,
                "field_T": field_T,
                "radius_m": sk["radius"],
                "energy_J": at_field - ms_t * field_T * deficit,
                "energy_at_field_J": at_field,
                "moment_deficit_m2": deficit,
                "circularity": sk.get("circularity", math.nan),
                "dissipation": sk.get("dissipation", math.nan),
            }
        )
    points.sort(key=lambda p: p["radius_m"])
    # a table needs strictly increasing radii: a point out of order is a failed relaxation
    kept: list[dict[str, Any]] = []
    for p in points:
        if kept and p["radius_m"] <= kept[-1]["radius_m"]:
            dropped.append({"name": p["name"], "field_T": p["field_T"], "why": "radius not new"})
            continue
        kept.append(p)
    return kept, dropped


def integrated_energies(points: list[dict[str, Any]], ms_t: float) -> np.ndarray:
    """E_self at the scan points from the multiplier alone: −M_s t ∫ B dA_m [J].

    B(A_m) is interpolated by a cubic spline through the scan (in order of A_m) and integrated
    from the isolated skyrmion (B = 0), whose subtracted energy anchors the curve.
    """
    area = np.array([p["moment_deficit_m2"] for p in points])
    field = np.array([p["field_T"] for p in points])
    order = np.argsort(area)
    spline = interpolate.CubicSpline(area[order], field[order])
    k0 = int(np.argmin(np.abs(field)))
    anchor = points[k0]["energy_J"]
    return np.array([anchor - ms_t * float(spline.integrate(area[k0], a)) for a in area])


def ansatz_radius_dissipation(radius: float, wall_width: float) -> float:
    """2π∫(∂_R θ)² r dr of the 360° wall ansatz θ = 2 atan[sinh(R/Δ)/sinh(r/Δ)] (Δ fixed).

    ∂_R θ = 2 cosh(R/Δ) sinh(r/Δ) / (Δ (sinh²(r/Δ) + sinh²(R/Δ))).
    """
    s, c = math.sinh(radius / wall_width), math.cosh(radius / wall_width)

    def integrand(r: float) -> float:
        sh = math.sinh(r / wall_width)
        return (2.0 * c * sh / (wall_width * (sh * sh + s * s))) ** 2 * r

    edge = radius + 40.0 * wall_width
    parts = [(0.0, radius), (radius, edge)]
    return 2.0 * math.pi * sum(integrate.quad(integrand, a, b, limit=400)[0] for a, b in parts)


def difference_dissipation(
    m_plus: np.ndarray, m_minus: np.ndarray, step: float, cell: float, region: np.ndarray
) -> float:
    """∫ ∂_R m·∂_R m dA over ``region`` with ∂_R m = (m₊ − m₋)/``step`` (textures (nx, ny, 3)).

    ``step`` [m] is R₊ − R₋, ``cell`` [m] the cells' side.
    """
    dm = (np.asarray(m_plus) - np.asarray(m_minus)) / step
    return float(np.sum(np.sum(dm * dm, axis=-1)[region]) * cell * cell)


def _region(film, centre: tuple[float, float], radius: float) -> np.ndarray:
    """The cells within 4 radii of ``centre`` and two cells clear of the film's edges."""
    x, y = film.centres()
    reach = min(4.0 * radius, 0.5 * min(film.size) - 2 * film.cell_size)
    return (np.hypot(x - centre[0], y - centre[1]) <= reach) & film.magnetic()


def radius_dissipation(job, iso) -> dict[str, Any]:
    """𝒟_RR measured (central difference of the ±1 mT textures) and its estimates."""
    film = job.isolated_film()
    cell = film.cell_size
    centre = (iso.x, iso.y)
    region = _region(film, centre, iso.radius)
    out: dict[str, Any] = {
        "thin_wall": 4.0 * math.pi * iso.radius / iso.wall_width,
        "ansatz": ansatz_radius_dissipation(iso.radius, iso.wall_width),
        "wall_width_m": iso.wall_width,
    }
    # the rigidly shifted profile: ∂_R m = −∂_r m of the isolated skyrmion's texture
    prefix = job.isolated_prefix()
    m0 = job.textures[f"{prefix}/single"]
    x, y = film.centres()
    r = np.maximum(np.hypot(x - centre[0], y - centre[1]), 1e-30)
    gx, gy = np.gradient(m0, cell, axis=0), np.gradient(m0, cell, axis=1)
    dr = ((x - centre[0]) / r)[..., None] * gx + ((y - centre[1]) / r)[..., None] * gy
    out["shifted_profile"] = float(np.sum(np.sum(dr * dr, axis=-1)[region]) * cell * cell)
    plus, minus = (_one_skyrmion(job.results.get(f"sensitivity/{k}")) for k in ("plus", "minus"))
    textures = job.textures
    if plus and minus and "sensitivity/plus" in textures and "sensitivity/minus" in textures:
        step = plus["radius"] - minus["radius"]
        if step != 0:
            dm = (textures["sensitivity/plus"] - textures["sensitivity/minus"]) / step
            out["finite_difference"] = float(np.sum(np.sum(dm * dm, axis=-1)[region]) * cell * cell)
            out["radius_step_m"] = step
    out["value"] = out.get("finite_difference", out["shifted_profile"])
    out["method"] = (
        "central difference of the relaxed textures at H_ref ± 1 mT over their radii"
        if "finite_difference" in out
        else "the isolated profile shifted rigidly (∂_R m = −∂_r m)"
    )
    return out


def centre_dissipation(points: list[dict[str, Any]], iso) -> dict[str, Any]:
    """𝒟(R) of the centre along the scan beside the thin wall's 2π(R/Δ + Δ/R) at each radius.

    Each scan point's 𝒟 is its relaxed texture's ½∫(∂ₓm·∂ₓm + ∂ᵧm·∂ᵧm) dA over the skyrmion's
    neighbourhood (the skyrmion detection's), the same measure at every radius; the model
    uses the ratio to the isolated skyrmion's. The thin wall's estimate takes the isolated
    skyrmion's Δ at every radius (its wall keeps its width as the radius changes).
    """
    radius = np.array([p["radius_m"] for p in points])
    measured = np.array([p["dissipation"] for p in points])
    k0 = int(np.argmin(np.abs([p["field_T"] for p in points])))
    width = iso.wall_width
    thin = 2 * math.pi * (radius / width + width / radius)
    return {
        "radius_m": radius.tolist(),
        "measured": measured.tolist(),
        "ratio": (measured / measured[k0]).tolist(),
        "thin_wall_ratio": (thin / thin[k0]).tolist(),
    }


def _log_spline(curve):
    """(spline of ln E, lowest, highest distance) over ``curve``'s leading positive energies."""
    d, e = curve.distance, curve.energy
    positive = e > 0
    if not positive.all():
        last = int(np.argmin(positive))
        d, e = d[:last], e[:last]
    if len(d) < 4:
        return None
    return interpolate.CubicSpline(d, np.log(e), bc_type="not-a-knot"), float(d[0]), float(d[-1])


def fit_shift(curve, distance, energy, per_unit: float) -> dict[str, Any]:
    """Fit s in ln E_k = L(d_k − s·``per_unit``), L the spline of ln E of ``curve`` at R₀.

    ``per_unit`` [m] is what the argument moves per unit s: 2ΔR for a pair, ΔR for a wall.
    Returns s, its rms ln-residual, those at s = 0 and s = 1, and each point's own s.
    """
    spline = _log_spline(curve)
    d, e = np.asarray(distance, float), np.asarray(energy, float)
    use = e > 0
    out: dict[str, Any] = {
        "distance_m": d.tolist(),
        "energy_J": e.tolist(),
        "argument_per_shift_m": per_unit,
    }
    if spline is None or use.sum() < 1 or per_unit == 0:
        out["why"] = "too few positive energies to fit"
        return out
    law, lo, hi = spline
    d, e = d[use], np.log(e[use])
    # the shifted distances must stay within the measured law
    bounds = [(lo - x) / -per_unit if per_unit < 0 else (x - lo) / per_unit for x in d]
    bounds += [(hi - x) / -per_unit if per_unit < 0 else (x - hi) / per_unit for x in d]
    s_max = min(MAX_SHIFT, *[b for b in bounds if b > 0]) if any(b > 0 for b in bounds) else 0.0
    if s_max <= 0 or not all(lo <= x <= hi for x in d):
        out["why"] = "the points lie outside the law measured at the isolated radius"
        return out

    def rms(s: float) -> float:
        return float(np.sqrt(np.mean((e - law(d - s * per_unit)) ** 2)))

    best = optimize.minimize_scalar(rms, bounds=(0.0, s_max), method="bounded")
    each = []
    for x, y in zip(d, e, strict=True):
        f = lambda s, x=x, y=y: float(law(x - s * per_unit) - y)  # noqa: E731
        each.append(optimize.brentq(f, 0.0, s_max) if f(0.0) * f(s_max) < 0 else None)
    out.update(
        shift=float(best.x),
        rms_log_residual=rms(float(best.x)),
        rms_log_residual_unshifted=rms(0.0),
        rms_log_residual_at_one=rms(1.0) if s_max >= 1 else None,
        shift_per_point=each,
        shift_bound=s_max,
    )
    return out


def shift_fits(job, cal) -> dict[str, Any]:
    """s_p and s_w from the laws at the second radius (``shifted/...``) against those at R₀."""
    r = job.results
    singles = {int(k.rsplit("/", 1)[1]): v for k, v in r.items() if k.startswith("shifted/single/")}
    pairs = {int(k.rsplit("/", 1)[1]): v for k, v in r.items() if k.startswith("shifted/pair/")}
    ref_singles = [int(k.rsplit("/", 1)[1]) for k in r if k.startswith("laws/single/")]
    if not singles or "shifted/uniform" not in r or not ref_singles:
        return {"why": "the laws at a second radius were not solved"}
    centre = _one_skyrmion(singles[max(singles)])
    ref_centre = _one_skyrmion(r[f"laws/single/{max(ref_singles)}"])
    if centre is None or ref_centre is None:
        return {"why": "the centre single at the second radius is not one skyrmion"}
    delta = centre["radius"] - ref_centre["radius"]
    e_centre = singles[max(singles)]["energy"]
    uniform = r["shifted/uniform"]["energy"]
    film = [s.film for s in job.planned() if s.name == "shifted/uniform"][0]
    wall = cal.wall_energy
    out: dict[str, Any] = {
        "field_T": _field_of(job, "shifted/uniform"),
        "radius_m": centre["radius"],
        "reference_radius_m": ref_centre["radius"],
        "radius_change_m": delta,
        "relative_radius_change": delta / ref_centre["radius"],
    }
    # pairs: E = E_pair − 2(E_centre + U_wall(x_i)) + E_uniform, U_wall the law at R₀
    d, e, correction = [], [], []
    for i, pair in sorted(pairs.items()):
        if not valid_solve(pair, 2):
            continue
        a, b = pair["skyrmions"]
        x_i = (i + 0.5) * film.cell_size
        edge = float(np.interp(x_i, wall.distance, wall.energy, right=0.0))
        energy = pair["energy"] - 2 * e_centre + uniform - 2 * edge
        d.append(math.hypot(a["x"] - b["x"], a["y"] - b["y"]))
        e.append(energy)
        correction.append(2 * edge / energy if energy else math.nan)
    out["pair"] = fit_shift(cal.pair_energy, d, e, 2 * delta)
    out["pair"]["edge_correction_share_max"] = max(map(abs, correction), default=None)
    x, e = [], []
    for i, single in sorted(singles.items()):
        sk = _one_skyrmion(single)
        if i == max(singles) or sk is None:
            continue
        x.append(sk["x"])
        e.append(single["energy"] - e_centre)
    out["wall"] = fit_shift(wall, x, e, delta)
    return out


def _least_squares_shift(push: np.ndarray, force: np.ndarray) -> float | None:
    """The shift minimising Σ(push − s·F)²: the slope through the origin of push against F."""
    denominator = float(np.sum(force * force))
    return float(np.sum(push * force) / denominator) if denominator > 0 else None


def squeeze_shifts(job, cal, radius: np.ndarray, energy: np.ndarray) -> dict[str, Any]:
    """s_p and s_w from how far neighbours and edges squeeze the skyrmions of the laws' solves.

    No extra field: the pairs and edge singles of the calibration film, relaxed with their
    centres held, take the radii at which, by the breathing model, the self-energy's slope
    balances the law's push on the radius. With E = Σ E_self(Rᵢ) + U(g), g = d − s(Rᵢ + Rⱼ − 2R₀)
    for a pair (x − s(R − R₀) at an edge), ∂E/∂Rᵢ = 0 gives −E_self'(Rᵢ) = s·F, F = −U' the
    law's force at the held distance. Each solve gives the push −E_self'(R̄) (R̄ its skyrmions'
    mean radius, E_self the scan's table) and F; s is their least-squares slope through the
    origin, with each solve's own push/F. The radii are measured from the film's own isolated
    (centre) single, which the table's R₀ stands for. Solves whose radius lies outside the
    table, or whose force is below 1 % of the largest, are left out.
    """
    table = interpolate.CubicSpline(radius, energy)
    r = job.results
    singles = {int(k.rsplit("/", 1)[1]): v for k, v in r.items() if k.startswith("laws/single/")}
    if not singles:
        return {"why": "the laws' singles were not solved"}
    centre = _one_skyrmion(singles[max(singles)])
    if centre is None:
        return {"why": "the calibration film's centre single is not one skyrmion"}
    offset = float(cal.isolated.radius) - centre["radius"]  # film's R₀ → the table's

    def fit(rows: list[tuple[float, float, float]]) -> dict[str, Any]:
        rows = [row for row in rows if radius[0] <= row[1] <= radius[-1]]
        if rows:
            largest = max(f for _, _, f in rows)
            rows = [row for row in rows if row[2] > 0.01 * largest]
        if not rows:
            return {"why": "no solve squeezed within the radius table"}
        x, rbar, force = (np.array(c, float) for c in zip(*rows, strict=True))
        push = -table(rbar, 1)
        shift = _least_squares_shift(push, force)
        return {
            "distance_m": x.tolist(),
            "radius_m": rbar.tolist(),
            "force_N": force.tolist(),
            "push_N": push.tolist(),
            "shift": shift,
            "shift_per_point": (push / force).tolist(),
        }

    pairs = []
    for key, pair in r.items():
        if not key.startswith("laws/pair/") or not valid_solve(pair, 2):
            continue
        a, b = pair["skyrmions"]
        d = math.hypot(a["x"] - b["x"], a["y"] - b["y"])
        pairs.append((d, 0.5 * (a["radius"] + b["radius"]) + offset, float(cal.pair(d))))
    edges = []
    for i, single in singles.items():
        sk = _one_skyrmion(single)
        if i == max(singles) or sk is None:
            continue
        edges.append((sk["x"], sk["radius"] + offset, float(cal.wall(sk["x"]))))
    return {
        "what": "the radii that neighbours and edges give the laws' solves, no extra field",
        "pair": fit(sorted(pairs)),
        "wall": fit(sorted(edges)),
    }


def law_radii(squeezed: dict[str, Any], cal, radius0: float) -> dict[str, Any]:
    """The radius of the laws' skyrmions at each distance of the pair and wall tables.

    From the squeezed solves (:func:`squeeze_shifts`: each pair's mean radius, each edge
    single's, measured from the film's own centre single): PCHIP in the distance between them;
    below the first, its radius; beyond the last, R₀ + ΔR_last·F(d)/F(d_last), the linear
    response of a radius to the law's push −s F. Each table's entry ``radius_m`` is absent,
    with ``why``, when fewer than two solves were squeezed within the radius table.
    :meth:`skygas.physics.materials.Material.breathing_laws` reads the laws at the gaps these
    radii give.
    """
    out: dict[str, Any] = {}
    for law, table in (("pair", cal.pair), ("wall", cal.wall)):
        rows = squeezed.get(law, {})
        measured = np.asarray(rows.get("distance_m", []), float)
        if len(measured) < 2:
            out[law] = {"why": rows.get("why", "fewer than two squeezed solves")}
            continue
        change = np.asarray(rows["radius_m"], float) - radius0
        distance = np.asarray(table.distance, float)
        inside = interpolate.PchipInterpolator(measured, change)(
            np.clip(distance, measured[0], measured[-1])
        )
        last = float(table(measured[-1]))
        tail = change[-1] * np.asarray(table(distance)) / last if last > 0 else 0.0 * distance
        delta = np.where(distance > measured[-1], tail, inside)
        out[law] = {"radius_m": (radius0 + delta).tolist()}
    return out


def choose(sensitivity: dict[str, Any]) -> tuple[str, str]:
    """(particle model, why) from the sensitivity check's |d ln R/dB|."""
    if not sensitivity:
        return "rigid", "the field sensitivity was not measured"
    per_mt = abs(sensitivity["relative_change_per_mT"])
    threshold = BREATHING_SENSITIVITY
    if per_mt > threshold:
        return "breathing", (
            f"its radius changes by {per_mt * 100:.2f} % per mT, more than "
            f"{threshold * 100:g} % per mT: neighbours and edges change its size"
        )
    return "rigid", (
        f"its radius changes by {per_mt * 100:.2f} % per mT, at most {threshold * 100:g} % per "
        "mT: a rigid size is enough"
    )


def choose_by_validation(breathing: dict[str, Any], models: dict[str, Any]) -> str:
    """The particle model whose validation error is the smaller, written into ``breathing``.

    ``models``: the validation's :class:`~skygas.calibration.validation.Comparison` of each
    model (None where the micromagnetic run lost a skyrmion). Where both ran, the model with
    the smaller maximum RMS centre error is chosen, and ``breathing`` records it
    (``particle_model``, ``why``) beside the sensitivity's own choice
    (``by_sensitivity``); otherwise the sensitivity's choice stands. Returns the model.
    """
    rigid, soft = models.get("rigid"), models.get("breathing")
    if rigid is None or soft is None:
        return breathing["particle_model"]
    errors = {"rigid": float(rigid.error.max()), "breathing": float(soft.error.max())}
    best = min(errors, key=errors.__getitem__)
    other = "rigid" if best == "breathing" else "breathing"
    by_sensitivity = breathing["particle_model"]
    breathing["by_sensitivity"] = {"particle_model": by_sensitivity, "why": breathing["why"]}
    breathing["particle_model"] = best
    why = (
        f"the validation's RMS centre error is at most {errors[best]:.3f} d_sk with {best} "
        f"skyrmions, {errors[other]:.3f} d_sk with {other} ones"
    )
    if best != by_sensitivity:
        why += f" (by the field sensitivity alone it would be {by_sensitivity}: {breathing['why']})"
    breathing["why"] = why
    return best


def edge_check(cal, spec: dict[str, Any]) -> None:
    """The breathing model at the real straight edge, beside the rigid one.

    For each single of the stray-field check (and its film's centre single, at the check's
    ``centre_x_m``) the model's radius minimises E_self(R) + a(R) U_s(x) + U_wall(x − s_w(R −
    R₀)), U_s the first-order stray-field energy of the half-plane and U_wall the short-range
    law's energy (as the rigid model's, :func:`skygas.calibration.analysis._check_stray`), a(R)
    the engine's (:meth:`~skygas.physics.materials.BreathingSpec.area_ratio`); its energy
    there, relative to the centre single's, is written into the check's points as
    ``breathing_model_J`` with the radius ``breathing_radius_m`` (and the centre's as
    ``breathing_centre_radius_m``): what the micromagnetic singles' energies and radii test.
    """
    from skygas.calibration import laws
    from skygas.physics.materials import BreathingSpec, law_gap

    check = cal.checks.get("stray_field", {})
    if not check.get("points"):
        return
    m = cal.config.material
    r0 = float(cal.isolated.radius)
    radius = np.linspace(spec["radius"][0], spec["radius"][-1], 2001)
    self_energy = interpolate.CubicSpline(spec["radius"], spec["energy"])(radius)
    scale = BreathingSpec(**spec).area_ratio(r0)[0](radius)
    shift = float(spec.get("wall_shift", 1.0))
    wall_at, wall_energy = cal.wall_energy.distance, cal.wall_energy.energy
    if spec.get("wall_radius") is not None:  # the law at the gap: its force integrated
        wall_at = law_gap("wall", cal.wall.distance, spec["wall_radius"], r0, shift)
        force = np.asarray(cal.wall.force)
        steps = 0.5 * (force[1:] + force[:-1]) * np.diff(wall_at)
        wall_energy = np.append(np.cumsum(steps[::-1])[::-1], 0.0)

    def model(x: float) -> tuple[float, float]:
        stray = laws.halfplane_stray_energy(
            x, m.saturation_magnetization, m.film_thickness, cal.profile_radius, cal.profile_deficit
        )[0]
        short = np.interp(x - shift * (radius - r0), wall_at, wall_energy, right=0.0)
        total = self_energy + scale * stray + short
        k = int(np.argmin(total))
        return float(total[k]), float(radius[k])

    centre_energy, centre_radius = model(check["centre_x_m"])
    check["breathing_centre_radius_m"] = centre_radius
    for point in check["points"]:
        energy, at = model(point["x_m"])
        point["breathing_model_J"] = energy - centre_energy
        point["breathing_radius_m"] = at


def measure(job, cal) -> dict[str, Any]:
    """Everything breathing: the scan, E_self(R), 𝒟_RR, the shifts, the choice.

    ``spec`` holds the ``[material.breathing]`` table (absent when the scan has fewer than
    three usable points, or does not span the isolated radius).
    """
    iso = cal.isolated
    m = job.config.material
    ms_t = m.saturation_magnetization * m.film_thickness
    model, why = choose(cal.checks.get("sensitivity", {}))
    out: dict[str, Any] = {
        "particle_model": model,
        "why": why,
        "threshold_per_mT": BREATHING_SENSITIVITY,
        "reference_radius_m": iso.radius,
    }
    if cal.checks.get("sensitivity"):
        per_mt = cal.checks["sensitivity"]["relative_change_per_mT"]
        out["sensitivity_per_mT"] = per_mt
        # the field by which a neighbour at 1.5 d_sk presses on the radius (s = 1), and the
        # radius change it makes at the measured sensitivity
        force = float(cal.pair(NEIGHBOUR_DISTANCE * cal.diameter))
        field_T = force / (4 * math.pi * iso.radius * ms_t)
        out["neighbour_field_T"] = field_T
        out["neighbour_radius_change"] = per_mt * field_T * 1e3
    points, dropped = scan_points(job, iso)
    out["dropped"] = dropped
    if len(points) < 3 or not points[0]["radius_m"] <= iso.radius <= points[-1]["radius_m"]:
        out["note"] = (
            f"{len(points)} usable scan points "
            + ("" if len(points) < 3 else "that do not span the isolated radius")
            + ": no E_self(R) table"
        )
        out["particle_model"] = "rigid"
        out["why"] = "E_self(R) could not be measured (" + out["note"] + ")"
        out["points"] = points
        return out
    integrated = integrated_energies(points, ms_t)
    radius = np.array([p["radius_m"] for p in points])
    area = np.array([p["moment_deficit_m2"] for p in points])
    field = np.array([p["field_T"] for p in points])
    slope = interpolate.CubicSpline(radius, area)(radius, 1)  # dA_m/dR along the scan
    for p, e_int, da in zip(points, integrated, slope, strict=True):
        p["energy_integrated_J"] = float(e_int)
        p["lagrange_force_N"] = float(ms_t * p["field_T"] * da)
        p["thin_wall_force_N"] = float(4 * math.pi * p["radius_m"] * ms_t * p["field_T"])
    energy = np.array([p["energy_J"] for p in points])
    span = float(np.max(np.abs(energy - iso.energy))) or 1.0
    out["points"] = points
    out["energy_check"] = {
        "max_difference_J": float(np.max(np.abs(integrated - energy))),
        "relative_to_span": float(np.max(np.abs(integrated - energy)) / span),
        "what": "E_self by subtraction against −M_s t ∫ B dA_m along the scan",
    }
    out["radius_range_m"] = [float(radius[0]), float(radius[-1])]
    out["field_range_T"] = [float(field.min()), float(field.max())]
    out["radius_dissipation"] = radius_dissipation(job, iso)
    out["shifts"] = shift_fits(job, cal)
    out["shifts_squeezed"] = squeeze_shifts(job, cal, radius, energy)
    spec: dict[str, Any] = {
        "radius": radius.tolist(),
        "energy": energy.tolist(),
        "radius_dissipation": out["radius_dissipation"]["value"],
    }
    if np.all(np.diff(area) > 0):  # the stray field's scale a(R) = A_m(R)/A_m(R₀)
        spec["moment_deficit"] = area.tolist()
    centre = np.array([p["dissipation"] for p in points], float)
    if np.all(np.isfinite(centre) & (centre > 0)):  # the centre's 𝒟(R)
        spec["dissipation"] = centre.tolist()
        out["centre_dissipation"] = centre_dissipation(points, iso)
    # the model's shifts: the squeezed ones, measured as the model uses them (neighbours and
    # edges pressing on the radius); the field's where those could not be measured
    out["shift_measure"] = {}
    for key, law in (("pair_shift", "pair"), ("wall_shift", "wall")):
        measures = (("squeezed", out["shifts_squeezed"]), ("field", out["shifts"]))
        for measure_name, record in measures:
            shift = record.get(law, {}).get("shift")
            if shift is not None:
                spec[key] = float(np.clip(shift, 0.0, MAX_SHIFT))
                out["shift_measure"][law] = measure_name
                break
    # the laws were measured between squeezed skyrmions: the model reads them at the gap
    from skygas.physics.materials import law_gap

    out["law_radii"] = law_radii(out["shifts_squeezed"], cal, iso.radius)
    for law in ("pair", "wall"):
        radii = out["law_radii"][law].get("radius_m")
        if radii is None:
            continue
        shift = spec.get(f"{law}_shift", 1.0)
        gap = law_gap(law, getattr(cal, law).distance, radii, iso.radius, shift)
        if np.all(np.diff(gap) > 0):
            spec[f"{law}_radius"] = radii
        else:
            out["law_radii"][law]["why"] = "its gaps do not grow with the distance: not written"
    out["spec"] = spec
    edge_check(cal, spec)
    return out


__all__ = [
    "BREATHING_SENSITIVITY",
    "choose_by_validation",
    "ansatz_radius_dissipation",
    "centre_dissipation",
    "choose",
    "difference_dissipation",
    "fit_shift",
    "integrated_energies",
    "law_radii",
    "measure",
    "squeeze_shifts",
]
