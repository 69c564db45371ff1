"""From energies to force laws, the edge's stray field, and the model file."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from skygas.calibration import laws
from skygas.calibration.model_file import dumps, write_model
from skygas.core.errors import InputError
from skygas.core.units import MU_0


def test_force_of_an_exponential_energy_and_its_continuation():
    """E = E₀ e^{−d/λ} gives F = E/λ exactly; beyond the data the table continues with the
    same decay down to 1e-4 F₀."""
    lam, e0, f0 = 7e-9, 3e-19, 1e-12
    d = np.linspace(20e-9, 80e-9, 11)
    law = laws.force_law(laws.curve(list(zip(d, e0 * np.exp(-d / lam), strict=True))), f0)
    x = np.linspace(20e-9, 80e-9, 50)
    assert law(x) == pytest.approx(e0 / lam * np.exp(-x / lam), rel=1e-4)
    assert law.decay == pytest.approx(lam, rel=1e-9)
    assert law.force[-1] <= laws.TABLE_FLOOR * f0 * 1.0001
    far = np.linspace(90e-9, law.distance[-1], 5)
    assert law(far) == pytest.approx(e0 / lam * np.exp(-far / lam), rel=1e-3)
    assert law(law.distance[-1] * 1.01) == 0.0


def test_the_wall_law_goes_on_along_its_tangent_below_its_first_point():
    """E = E₀ e^{−d/λ}: below d₀ the continued table is F(d₀)(1 + (d₀ − d)/λ), the tangent,
    down to d₀/2; above d₀ it is the table without continuation, and no node is steeper
    than the measured law at d₀ (the engine's step follows the steepest slope)."""
    lam, e0, f0 = 7e-9, 3e-19, 1e-12
    d = np.linspace(20e-9, 80e-9, 11)
    energy = laws.curve(list(zip(d, e0 * np.exp(-d / lam), strict=True)))
    held, continued = laws.force_law(energy, f0), laws.force_law(energy, f0, continued=True)
    assert continued.distance[0] == pytest.approx(laws.WALL_CONTINUATION * d[0])
    assert continued.measured == held.measured
    below = np.linspace(continued.distance[0], d[0], 7)
    tangent = e0 / lam * np.exp(-d[0] / lam) * (1 + (d[0] - below) / lam)
    assert continued(below) == pytest.approx(tangent, rel=1e-3)
    assert held(below) == pytest.approx(np.full(7, held.force[0]))  # held, without it
    above = np.linspace(d[0], d[-1], 40)
    assert continued(above) == pytest.approx(held(above), rel=1e-12)
    slopes = np.abs(np.diff(continued.force) / np.diff(continued.distance))
    assert slopes.max() <= e0 / lam**2 * np.exp(-d[0] / lam) * 1.001


def test_energies_that_fall_into_rounding_are_cut():
    d = np.linspace(1e-8, 6e-8, 8)
    e = np.exp(-d / 5e-9)
    e[-2:] = [-1e-30, 0.0]
    law = laws.force_law(laws.curve(list(zip(d, e, strict=True))), 1e-12)
    assert law.measured[1] == pytest.approx(d[-3])


def test_half_plane_stray_energy_far_from_the_edge_is_the_point_dipole_limit():
    """Far from the edge U = μ₀M_s t A_m H(x), H = (M_s/π) atan(h/x) ≈ M_s h/(πx)."""
    ms, t = 1.45e6, 2e-9
    r = np.linspace(0, 60e-9, 601)
    w = 1 - np.cos(2 * np.arctan(math.sinh(20 / 5) / np.sinh(np.maximum(r, 1e-30) / 5e-9)))
    w[-1] = 0.0
    area = np.trapezoid(w * 2 * np.pi * r, r)
    for x in (300e-9, 600e-9):
        u = laws.halfplane_stray_energy(x, ms, t, r, w)[0]
        assert u == pytest.approx(
            MU_0 * ms * t * area * ms / math.pi * math.atan(t / 2 / x), rel=2e-2
        )


def test_half_plane_energy_agrees_with_the_engines_stray_field_on_a_large_film():
    """The calibration's straight-edge energy and the engine's stray-field term
    (skygas.fields.landscape.stray_field) are the same formula: on a film much larger than the
    distances involved, their differences between two distances from one edge agree."""
    from skygas.fields.landscape.stray_field import stray_field_energy

    ms, t, cell = 1.45e6, 2e-9, 2e-9
    r = np.linspace(0, 40e-9, 401)
    w = np.clip(2 * np.exp(-((r / 12e-9) ** 2)), 0, 2)
    w[-1] = 0.0
    inside = np.ones((301, 601))  # 600 nm high, 1200 nm wide: the left edge dominates
    u = stray_field_energy(inside, cell, t, ms, r, w)
    row = 150
    x1, x2 = 30e-9, 80e-9
    engine = u[row, int(round(x1 / cell))] - u[row, int(round(x2 / cell))]
    mine = np.diff(laws.halfplane_stray_energy([x2, x1], ms, t, r, w))[0]
    assert engine == pytest.approx(mine, rel=3e-2)


def test_model_file_round_trips_and_refuses_an_invalid_material(tmp_path):
    from skygas.physics.materials import load_material, preset

    base = preset("S2").model_dump()
    base["pair_table"] = {"distance": [1e-8, 2e-8, 3e-8, 4e-8], "force": [4e-12, 2e-12, 1e-12, 0.0]}
    path = write_model(
        tmp_path / "model.toml",
        base,
        {"provenance": {"solver": "x"}},
        ["a header"],
        {"provenance": "a comment"},
    )
    loaded = load_material(path)
    assert loaded.pair_table.force == (4e-12, 2e-12, 1e-12, 0.0)
    assert tomllib.loads(path.read_text())["provenance"]["solver"] == "x"
    bad = dict(base, wall_law=[-1.0, 2.0])
    with pytest.raises(InputError, match="wall_law"):
        write_model(tmp_path / "bad.toml", bad, {}, [], {})
    assert not (tmp_path / "bad.toml").exists()
    assert tomllib.loads(dumps({"a": np.float64(1.5), "b": [np.float64(2.0)]})) == {
        "a": 1.5,
        "b": [2.0],
    }


def _single(x, charge=-0.999, radius=11e-9, held=None):
    held = x if held is None else held
    return {
        "centres": [[held, 60e-9]],
        "skyrmions": [{"x": x, "y": 60e-9, "radius": radius, "charge": charge}],
        "energy": 1e-19 * math.exp(-held / 7e-9),
    }


def test_the_edge_law_drops_singles_that_left_where_they_were_held():
    """A single that left through the edge is dropped with its reason, whatever the detector
    then finds: no skyrmion, a fraction of one, or charge spread over the film without a
    contour far from where it was held (what S2's single held 0.6 d_sk from the edge left)."""
    from skygas.calibration.analysis import energy_curves

    results = {
        "laws/uniform": {"energy": 0.0, "centres": [], "skyrmions": []},
        "laws/single/60": _single(121e-9),  # the film's centre
        "laws/single/10": _single(21e-9),
        "laws/single/12": _single(25e-9),
        "laws/single/14": _single(29e-9),
        "laws/single/16": _single(33e-9),
        "laws/single/4": _single(121.4e-9, charge=-0.99, radius=math.nan, held=9e-9),
        "laws/single/5": _single(12e-9, charge=-0.4),
        "laws/single/6": {"centres": [[13e-9, 60e-9]], "skyrmions": [], "energy": 0.0},
        "laws/single/7": _single(30e-9, held=15e-9),  # a whole skyrmion, but not held there
        "laws/pair/16": {
            "centres": [[33e-9, 60e-9], [209e-9, 60e-9]],
            "skyrmions": [_single(x)["skyrmions"][0] for x in (33e-9, 209e-9)],
            "energy": 1e-20,
        },
    }
    _, wall = energy_curves(results)
    assert wall.distance == pytest.approx([21e-9, 25e-9, 29e-9, 33e-9, 121e-9])
    assert [d for d, _ in wall.dropped] == pytest.approx([9e-9, 12e-9, 13e-9, 15e-9])
    assert {why for _, why in wall.dropped} == {"the skyrmion left through the edge"}
