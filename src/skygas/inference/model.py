"""From measured D and Hall angle to the Thiele parameters of a model material.

The engine's free skyrmion (docs/physics.md §1, :class:`~skygas.physics.materials.ThieleParameters`)
has D = k_BT a/(a² + G²) with a = α𝒟k, and the Hall angle of a force-driven skyrmion
θ_H = atan2(G, a) (:mod:`skygas.inference.dynamics`). Given the measured D and θ_H:

    a = k_BT cos²θ_H / D,    G = k_BT sin θ_H cos θ_H / D.

G = −4πQk fixes k = |G|/4π and the charge sign (Q = −1 for G > 0); the model keeps the base
material's M_s and film thickness t (a reshuffler's current drive depends on M_s) and records the
k the data need as an effective gyromagnetic ratio γ = M_s t / k (k = M_s t/γ is how the engine
computes k); 𝒟 = a/(αk) with the base material's damping α. A Hall angle not distinct from zero
(within two standard errors) makes the model antiferromagnetic (G = 0) with a = k_BT/D.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from skygas.core import units
from skygas.physics.materials import Material, resolve_film_thickness


def thiele_fields(
    diffusion: float, hall_angle: float, hall_error: float, base: Material, temperature: float
) -> dict:
    """Material fields that give a free skyrmion the measured D [m²/s] and θ_H [rad] at T [K]."""
    kt = units.BOLTZMANN * temperature
    t = resolve_film_thickness(base)
    gamma0 = base.gyromagnetic_ratio or units.GYROMAGNETIC_RATIO
    if not math.isfinite(hall_angle) or abs(hall_angle) <= 2 * (hall_error or 0.0):
        k = base.saturation_magnetization * t / gamma0
        a = kt / diffusion
        return {
            "antiferromagnetic": True,
            "dissipation": a / (base.damping * k),
            "film_thickness": t,
        }
    a = kt * math.cos(hall_angle) ** 2 / diffusion
    g = kt * math.sin(hall_angle) * math.cos(hall_angle) / diffusion
    k = abs(g) / (4 * math.pi)
    return {
        "antiferromagnetic": False,
        "topological_charge": -1 if g > 0 else 1,
        "gyromagnetic_ratio": base.saturation_magnetization * t / k,
        "dissipation": a / (base.damping * k),
        "film_thickness": t,
    }


def model_material(
    name: str, base: Material, thiele: dict, pair_table: dict | None, wall_table: dict | None
) -> dict:
    """The ``[material]`` table: the base material with the inferred Thiele fields and tables."""
    data = base.model_dump(exclude_none=True)
    data.update(thiele)
    data["name"] = name
    data.pop("stray_field", None)
    for key, table in (("pair_table", pair_table), ("wall_table", wall_table)):
        if table is not None:
            data[key] = table
        else:
            data.pop(key, None)
    return data


#: A table of zero force: no interaction (pair), or an edge that only stops skyrmions (wall).
ZERO_TABLE = {"distance": [1e-9, 2e-9, 3e-9, 4e-9], "force": [0.0, 0.0, 0.0, 0.0]}
#: Points of a written force table.
TABLE_POINTS = 24


@dataclass(frozen=True)
class Model:
    """A model as written.

    The ``[material]`` table, the ``[[potentials]]``, the landscape's map [k_BT] that their
    ``measured`` table names (NaN where not sampled), the drive [N], notes.
    """

    material: dict
    potentials: list
    map_values: np.ndarray
    drive_force: tuple[float, float]
    notes: tuple[str, ...]


def force_table(basis, theta: np.ndarray, kt: float) -> tuple[dict, bool]:
    """The engine's table of a radial force (|F| [N] on distances [m]) and whether it was clipped.

    ``basis`` a :class:`~skygas.inference.basis.RadialBasis` with coefficients ``theta`` [k_BT/m];
    the engine's tables are repulsions, so a negative force is written as 0.
    """
    r = np.linspace(basis.lo, basis.hi, TABLE_POINTS)
    f = basis.force(r, theta) * kt
    return {"distance": r.tolist(), "force": np.maximum(f, 0.0).tolist()}, bool(np.any(f < 0))


def build(
    numbers,
    basis,
    terms,
    base: Material,
    temperature: float,
    *,
    hall_fixed: bool,
    hall_error: float,
    landscape: dict | None,
    map_values: np.ndarray,
) -> Model:
    """The model of ``numbers`` (:class:`~skygas.inference.sampling.ModelNumbers`).

    ``basis`` and ``terms`` the force model's; ``base`` the base material (with the model's
    skyrmion radius); ``landscape`` the ``[[potentials]]`` table of the map, or None, and
    ``map_values`` the map the movie read [k_BT], written scaled by the numbers'
    ``landscape_scale`` (its rms with it). The pair
    law is the fitted table, the base material's (``material_pair``), or a zero table (no
    interaction); the wall law is the fitted table or a zero one.
    """
    kt = units.BOLTZMANN * temperature
    theta = numbers.theta
    thiele = thiele_fields(
        numbers.diffusion, numbers.hall_angle, hall_error if hall_fixed else 0.0, base, temperature
    )
    notes = []
    pair_table: dict | None = ZERO_TABLE
    if "pair" in terms and basis.pair is not None:
        pair_table, clipped = force_table(basis.pair, theta[basis.columns["pair"]], kt)
        if clipped:
            notes.append("the fitted pair force turns attractive in places: written as 0 there")
    elif "material_pair" in terms:
        pair_table = None
    wall_table = ZERO_TABLE
    if "wall" in terms and basis.wall is not None:
        wall_table, clipped = force_table(basis.wall, theta[basis.columns["wall"]], kt)
        if clipped:
            notes.append("the fitted wall force turns attractive in places: written as 0 there")
    material = model_material("inferred", base, thiele, pair_table, wall_table)
    drive = (0.0, 0.0)
    if "drive" in terms:
        fd = theta[basis.columns["drive"]] * kt
        drive = (float(fd[0]), float(fd[1]))
    scale = numbers.landscape_scale
    potentials = []
    if landscape:
        potentials = [{**landscape, "rms_kT": landscape["rms_kT"] * abs(scale)}]
    return Model(material, potentials, map_values * scale, drive, tuple(notes))
