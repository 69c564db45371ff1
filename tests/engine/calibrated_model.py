"""A calibrated-model material for the tests: S2 with tables that sample its own paper laws, a
film thickness, γ and a thin-wall skyrmion profile; and its ``model.toml`` text."""

from __future__ import annotations

import numpy as np

from skygas.physics.forces import paper_pair_force, paper_wall_force
from skygas.physics.materials import Material, derive_thiele, preset

FILM = 2e-9


def thin_wall_profile(radius: float, wall_width: float, n: int = 120):
    """(ρ [m], w = 1 − m_z) of the thin-wall profile θ = 2 atan(sinh(R/Δ)/sinh(ρ/Δ)), out to 4R
    (w ≈ 1e-7 there)."""
    rho = np.linspace(0.0, 4 * radius, n)
    theta = 2 * np.arctan2(np.sinh(radius / wall_width), np.sinh(rho / wall_width))
    return rho, 1.0 - np.cos(theta)


def calibrated_data(
    n_pair: int = 400, n_wall: int = 400, stray: bool = True, film: float | None = FILM
) -> dict:
    """The mapping of a calibrated S2: tables = the paper laws at the default F₀ and d_sk."""
    s2 = preset("S2")
    thiele = derive_thiele(s2)
    d_sk, f0 = thiele.skyrmion_diameter, thiele.force_scale
    r_pair = np.linspace(0.0, 6.0, n_pair) * d_sk
    r_wall = np.linspace(0.0, 7.5, n_wall) * d_sk
    data = {
        **s2.model_dump(),
        "name": "calibrated-S2",
        "gyromagnetic_ratio": 1.7595e11,
        "pair_table": {
            "distance": r_pair.tolist(),
            "force": (f0 * paper_pair_force(r_pair / d_sk, *s2.pair_law)).tolist(),
        },
        "wall_table": {
            "distance": r_wall.tolist(),
            "force": (f0 * paper_wall_force(r_wall / d_sk, s2.wall_law)).tolist(),
        },
    }
    if film is not None:
        data["film_thickness"] = film
    if stray:
        rho, w = thin_wall_profile(s2.skyrmion_radius, 4.35e-9)
        data["stray_field"] = {"profile_radius": rho.tolist(), "profile_deficit": w.tolist()}
    for key in ("dissipation", "wall_width"):
        if data[key] is None:
            del data[key]
    return data


def calibrated_material(**kwargs) -> Material:
    return Material(**calibrated_data(**kwargs))


def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    return repr(float(value)) if isinstance(value, float) else repr(value)


def model_toml(data: dict) -> str:
    """``data`` as the ``[material]`` table of a model.toml (sub-tables as
    ``[material.pair_table]`` …), TOML text that tomllib reads."""
    lines = ["[material]"]
    tables = {k: v for k, v in data.items() if isinstance(v, dict)}
    for key, value in data.items():
        if value is not None and key not in tables:
            lines.append(f"{key} = {_toml_value(value)}")
    for name, table in tables.items():
        lines += ["", f"[material.{name}]"]
        lines += [f"{key} = {_toml_value(value)}" for key, value in table.items()]
    return "\n".join(lines) + "\n"
