"""From measured D and Hall angle to the Thiele parameters of a model material.

The engine's free skyrmion (docs/physics.md §1, :class:`~skygas.physics.materials.ThieleParameters`)
has D = k_BT a/(a² + G²) with a = α𝒟k, and the Hall angle of a force-driven skyrmion
θ_H = atan2(G, a) (:mod:`skygas.inference.mobility`). Given the measured D and θ_H:

    a = k_BT cos²θ_H / D,    G = k_BT sin θ_H cos θ_H / D.

G = −4πQk fixes k = |G|/4π and the charge sign (Q = −1 for G > 0); the model keeps the base
material's M_s and film thickness t (a reshuffler's current drive depends on M_s) and records the
k the data need as an effective gyromagnetic ratio γ = M_s t / k (k = M_s t/γ is how the engine
computes k); 𝒟 = a/(αk) with the base material's damping α. A Hall angle not distinct from zero
(within two standard errors) makes the model antiferromagnetic (G = 0) with a = k_BT/D.
"""

from __future__ import annotations

import math

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
