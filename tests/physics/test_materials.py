"""Material presets and the Thiele parameters derived from them.

Reference values come from the paper's Appendix C tables ("Material Parameters" and "Skx-Skx
Repulsion"), transcribed below in SI units, and from the definitions in docs/physics.md §1. Every
derived quantity is recomputed here from those definitions, not taken from the code.
"""

import math

import numpy as np
import pytest
from pydantic import ValidationError

from skygas.core.errors import InputError
from skygas.physics.materials import (
    Material,
    derive_thiele,
    load_material,
    preset,
    preset_names,
)

GAMMA = 1.7595e11  # rad/(s T), docs/physics.md §1
K_B = 1.380649e-23  # J/K

# Appendix C, "Material Parameters": M_s [MA/m], A_ex ["fJ/m" in the table header, but the
# values are the main text's pJ/m], D [mJ/m²], K [MJ/m³], B [mT], R_skx [nm];
# "Skx-Skx Repulsion": a2, a1, a0.
PAPER_TABLE = {
    "S1": (1.4, 27.5, 2.05, 1.45, 0, 23.2, (1.245, 1.249, -3.449)),
    "S2": (1.45, 27.5, 2.05, 1.45, 20, 19.1, (2.709, -5.643, 0.964)),
    "S3": (1.4, 27.5, 2.6, 1.45, 20, 30.3, (2.488, -1.899, -2.676)),
    "S4": (1.4, 27.5, 2.6, 1.60, -15, 14.9, (1.13, 2.171, -6.623)),
    "S5": (1.5, 25.0, 2.4, 1.60, 30, 27.9, (2.219, -1.159, -3.358)),
    "S6": (1.0, 5.0, 2.05, 0.9, 150, 11.9, (0.059, 10.757, -16.738)),
    "S7": (1.2, 8.0, 2.1, 0.9, 150, 14.9, (0.766, 5.452, -11.894)),
}
# Methods: the single wall-law fit, highest power first (docs/physics.md §2).
PAPER_WALL_LAW = (0.001419, -0.02631, 0.24135, -1.1609, 3.3547, -2.1786)

LEVI_CIVITA = np.array([[0.0, 1.0], [-1.0, 0.0]])


def thin_wall_d(material_row):
    """𝒟 = 2π(R/Δ + Δ/R), Δ = √(A/K), from a PAPER_TABLE row."""
    _, a_ex, _, k_u, _, radius, _ = material_row
    delta = math.sqrt(a_ex * 1e-12 / (k_u * 1e6))
    r = radius * 1e-9
    return 2 * math.pi * (r / delta + delta / r)


# -- presets ------------------------------------------------------------------------------------
def test_all_seven_presets_exist():
    assert preset_names() == ["S1", "S2", "S3", "S4", "S5", "S6", "S7"]


@pytest.mark.parametrize("name", sorted(PAPER_TABLE))
def test_preset_matches_the_paper_table(name):
    m_s, a_ex, dmi, k_u, b_mt, radius_nm, pair = PAPER_TABLE[name]
    mat = preset(name)
    assert mat.name == name
    assert mat.saturation_magnetization == pytest.approx(m_s * 1e6, rel=1e-12)
    assert mat.exchange_stiffness == pytest.approx(a_ex * 1e-12, rel=1e-12)
    assert mat.dmi == pytest.approx(dmi * 1e-3, rel=1e-12)
    assert mat.anisotropy == pytest.approx(k_u * 1e6, rel=1e-12)
    assert mat.applied_field == pytest.approx(b_mt * 1e-3, rel=1e-12, abs=1e-15)
    assert mat.skyrmion_radius == pytest.approx(radius_nm * 1e-9, rel=1e-12)
    assert mat.skyrmion_diameter == pytest.approx(2 * radius_nm * 1e-9, rel=1e-12)
    assert mat.pair_law == pytest.approx(pair, abs=0)
    assert mat.wall_law == pytest.approx(PAPER_WALL_LAW, abs=0)
    # the paper's skyrmion: Q = −1 (G = −4π in its units), α = 0.1, a ferromagnet
    assert mat.topological_charge == -1
    assert mat.damping == 0.1
    assert mat.antiferromagnetic is False


def test_load_material_accepts_a_preset_name_and_a_material():
    assert load_material("S2") == preset("S2")
    mat = preset("S5")
    assert load_material(mat) is mat


# -- derived Thiele parameters ------------------------------------------------------------------
@pytest.mark.parametrize("name", sorted(PAPER_TABLE))
@pytest.mark.parametrize("film", [1e-9, 2e-9])
def test_derived_thiele_parameters_follow_the_definitions(name, film):
    row = PAPER_TABLE[name]
    th = derive_thiele(preset(name), film)
    k = row[0] * 1e6 * film / GAMMA
    assert th.k == pytest.approx(k, rel=1e-12)
    # G = −4πQk with Q = −1: positive, |G|/k = 4π
    assert th.gyrocoupling > 0
    assert th.gyrocoupling / th.k == pytest.approx(4 * math.pi, rel=1e-12)
    assert th.dissipation == pytest.approx(thin_wall_d(row), rel=1e-12)
    d_sk = 2 * row[5] * 1e-9
    assert th.skyrmion_diameter == pytest.approx(d_sk, rel=1e-12)
    assert th.force_scale == pytest.approx(row[1] * 1e-12 * film / d_sk, rel=1e-12)
    assert th.damping == 0.1 and th.eta == th.damping and th.mu == 1.0
    assert th.film_thickness == film


def test_s2_force_scale_is_about_1p4_piconewton():
    # docs/physics.md §2: F0 = A_ex t_F / d_sk ≈ 1.4 pN for S2 with t_F = 2 nm.
    th = derive_thiele(preset("S2"), 2e-9)
    assert th.force_scale == pytest.approx(27.5e-12 * 2e-9 / 38.2e-9, rel=1e-12)
    assert abs(th.force_scale - 1.4e-12) < 0.05e-12
    assert th.force_scale_internal == pytest.approx(th.force_scale * 1e12, rel=1e-12)  # pN
    assert th.skyrmion_diameter_internal == pytest.approx(38.2, rel=1e-12)  # nm


def test_positive_charge_reverses_the_gyrocoupling():
    mat = preset("S2").model_copy(update={"topological_charge": 1})
    th = derive_thiele(mat, 2e-9)
    assert th.gyrocoupling == pytest.approx(-4 * math.pi * th.k, rel=1e-12)


def test_overrides_replace_the_defaults():
    th = derive_thiele(
        preset("S2"),
        2e-9,
        dissipation=7.5,
        force_scale=2e-12,
        skyrmion_diameter=50e-9,
        eta=0.3,
        mu=0.5,
    )
    assert (th.dissipation, th.force_scale, th.skyrmion_diameter, th.eta, th.mu) == (
        7.5,
        2e-12,
        50e-9,
        0.3,
        0.5,
    )
    # a wall width given on the material replaces √(A/K) in the thin-wall estimate
    mat = preset("S2").model_copy(update={"wall_width": 5e-9})
    r = 19.1e-9
    assert derive_thiele(mat).dissipation == pytest.approx(
        2 * math.pi * (r / 5e-9 + 5e-9 / r), rel=1e-12
    )


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"film_thickness": 0.0}, "film_thickness"),
        ({"film_thickness": -2e-9}, "film_thickness"),
        ({"dissipation": -1.0}, "dissipation"),
        ({"force_scale": 0.0}, "force_scale"),
        ({"skyrmion_diameter": -1e-9}, "skyrmion_diameter"),
    ],
)
def test_invalid_derivation_arguments_are_refused(kwargs, field):
    with pytest.raises(InputError) as err:
        derive_thiele(preset("S2"), **kwargs)
    assert err.value.field == field and field in str(err.value)


@pytest.mark.parametrize("name", ["S2", "S6"])
@pytest.mark.parametrize("temperature", [0.0, 4.2, 300.0])
def test_diffusion_constant_formula(name, temperature):
    # docs/physics.md §1: D = k_B T α𝒟 / (k (G̃² + (α𝒟)²)), G̃ = −4πQ (only G̃² enters)
    row = PAPER_TABLE[name]
    film = 2e-9
    k = row[0] * 1e6 * film / GAMMA
    ad = 0.1 * thin_wall_d(row)
    expected = K_B * temperature * ad / (k * ((4 * math.pi) ** 2 + ad**2))
    th = derive_thiele(preset(name), film)
    assert th.diffusion_constant(temperature) == pytest.approx(expected, rel=1e-12, abs=0)


def test_s2_diffusion_constant_order_of_magnitude():
    # A sanity anchor independent of the formula's algebra: k ≈ 1.65e-14 kg/s, 𝒟 ≈ 21.
    d = derive_thiele(preset("S2"), 2e-9).diffusion_constant(300.0)
    assert 1e-9 < d < 1e-6  # m²/s


def test_antiferromagnetic_variant_has_no_gyrocoupling_and_faster_diffusion():
    fm = preset("S2")
    afm = fm.antiferromagnetic_variant()
    assert afm.antiferromagnetic and not fm.antiferromagnetic
    assert afm.name != fm.name
    th_fm, th_afm = derive_thiele(fm, 2e-9), derive_thiele(afm, 2e-9)
    assert th_afm.gyrocoupling == 0.0
    assert th_afm.k == th_fm.k and th_afm.dissipation == th_fm.dissipation
    ad = 0.1 * thin_wall_d(PAPER_TABLE["S2"])
    ratio = ((4 * math.pi) ** 2 + ad**2) / ad**2
    assert th_afm.diffusion_constant(300.0) / th_fm.diffusion_constant(300.0) == pytest.approx(
        ratio, rel=1e-12
    )
    # without gyrocoupling there is no Hall angle, whatever η
    afm_eta = derive_thiele(afm, 2e-9, eta=0.5)
    assert afm_eta.hall_angle() == 0.0


def _drift_by_linear_solve(th, v_s):
    """Solve (G ε + α𝒟k I) v = μ (G ε + η𝒟k I) v_s for v."""
    g, k, dd = th.gyrocoupling, th.k, th.dissipation
    lhs = g * LEVI_CIVITA + th.damping * dd * k * np.eye(2)
    rhs = th.mu * (g * LEVI_CIVITA + th.eta * dd * k * np.eye(2)) @ np.asarray(v_s, float)
    return np.linalg.solve(lhs, rhs)


@pytest.mark.parametrize("name", ["S2", "S4", "S6"])
@pytest.mark.parametrize("eta", [0.0, 0.05, 0.2, 1.0])
def test_hall_angle_solves_the_linear_system(name, eta):
    th = derive_thiele(preset(name), 2e-9, eta=eta, mu=1.3)
    v = _drift_by_linear_solve(th, [1.0, 0.0])
    expected = math.atan2(v[1], v[0])
    assert th.hall_angle() == pytest.approx(expected, rel=1e-10, abs=1e-13)
    assert abs(expected) > 1e-3  # η ≠ α really gives a Hall angle


def test_hall_angle_vanishes_for_eta_equal_alpha():
    th = derive_thiele(preset("S2"), 2e-9)
    assert th.eta == th.damping
    assert th.hall_angle() == 0.0
    # and the drift is exactly μ v_s (docs/physics.md §1)
    th = derive_thiele(preset("S2"), 2e-9, mu=0.7)
    assert _drift_by_linear_solve(th, [3.0, -2.0]) == pytest.approx([2.1, -1.4], rel=1e-12)


# -- user materials -----------------------------------------------------------------------------
USER_MATERIAL = {
    "name": "my-film",
    "saturation_magnetization": 1.1e6,
    "exchange_stiffness": 15e-12,
    "dmi": 3.0e-3,
    "anisotropy": 1.2e6,
    "applied_field": 0.05,
    "skyrmion_radius": 25e-9,
    "damping": 0.2,
    "pair_law": [2.0, -3.0, 0.5],
    "wall_law": [0.5, -1.0, 2.0],
    "topological_charge": 1,
}


def _toml_value(v):
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return repr(v)


def _write_toml(path, data, table=None):
    lines = [f"[{table}]"] if table else []
    lines += [f"{key} = {_toml_value(value)}" for key, value in data.items()]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("table", ["material", None])
def test_user_toml_material_round_trip(tmp_path, table):
    path = _write_toml(tmp_path / "film.toml", USER_MATERIAL, table)
    mat = load_material(path)
    assert mat == Material(**USER_MATERIAL)
    assert load_material(str(path)) == mat
    dumped = mat.model_dump()
    for key, value in USER_MATERIAL.items():
        expected = tuple(value) if isinstance(value, list) else value
        assert dumped[key] == expected, key
    th = derive_thiele(mat, 3e-9)
    assert th.k == pytest.approx(1.1e6 * 3e-9 / GAMMA, rel=1e-12)
    assert th.gyrocoupling == pytest.approx(-4 * math.pi * th.k, rel=1e-12)  # Q = +1
    # JSON-mode dump (as recorded in result files) loads back to the same material
    assert load_material(mat.model_dump(mode="json")) == mat


def test_base_preset_with_overrides(tmp_path):
    path = _write_toml(
        tmp_path / "thin.toml",
        {"base": "S2", "name": "S2-thick", "skyrmion_radius": 30e-9},
        "material",
    )
    mat = load_material(path)
    s2 = preset("S2")
    assert mat.name == "S2-thick"
    assert mat.skyrmion_radius == 30e-9
    assert mat.saturation_magnetization == s2.saturation_magnetization
    assert mat.pair_law == s2.pair_law and mat.wall_law == s2.wall_law
    assert load_material({"base": "S3", "damping": 0.05}) == preset("S3").model_copy(
        update={"damping": 0.05}
    )


def test_unknown_preset_is_refused():
    with pytest.raises(InputError) as err:
        load_material("S9")
    assert err.value.field == "material" and "S9" in str(err.value)
    with pytest.raises(InputError) as err:
        preset("s2")
    assert err.value.field == "material"
    with pytest.raises(InputError) as err:
        load_material({"base": "S8", "damping": 0.2})
    assert "S8" in str(err.value)


def test_missing_toml_file_is_refused(tmp_path):
    with pytest.raises(InputError) as err:
        load_material(tmp_path / "nope.toml")
    assert err.value.field == "material"


def test_negative_saturation_magnetisation_is_refused(tmp_path):
    bad = {**USER_MATERIAL, "saturation_magnetization": -1.0e6}
    with pytest.raises(InputError) as err:
        load_material(bad)
    assert err.value.field == "material.saturation_magnetization"
    assert "saturation_magnetization" in str(err.value)
    with pytest.raises(InputError) as err:
        load_material(_write_toml(tmp_path / "bad.toml", bad, "material"))
    assert "saturation_magnetization" in err.value.field
    with pytest.raises(ValidationError, match="saturation_magnetization"):
        Material(**bad)


def test_wall_law_with_negative_leading_coefficient_is_refused():
    # lowest power first, the paper's b vector would have a negative leading coefficient
    reversed_law = list(reversed(PAPER_WALL_LAW))
    assert reversed_law[0] < 0
    with pytest.raises(InputError) as err:
        load_material({"base": "S2", "wall_law": reversed_law})
    assert err.value.field == "material.wall_law"
    assert "highest power first" in str(err.value)
    with pytest.raises(ValidationError, match="wall_law"):
        Material(**{**USER_MATERIAL, "wall_law": [-0.5, 1.0]})


@pytest.mark.parametrize(
    "key, value",
    [
        ("exchange_stiffness", 0.0),
        ("anisotropy", -1.0),
        ("skyrmion_radius", 0.0),
        ("damping", -0.1),
        ("topological_charge", 2),
        ("pair_law", [1.0, 2.0]),
        ("colour", "blue"),
    ],
)
def test_other_invalid_material_fields_are_named(key, value):
    with pytest.raises(InputError) as err:
        load_material({**USER_MATERIAL, key: value})
    assert err.value.field.startswith(f"material.{key}")
