"""Contacts at arbitrary potentials: superposition of unit solutions against direct solves."""

from __future__ import annotations

import numpy as np
import pytest

from skygas.fields.current import ContactBasis, solve_contacts, solve_current
from skygas.reservoir.chamber import build_chamber
from skygas.reservoir.config import ChamberSpec


@pytest.fixture(scope="module")
def triangle():
    return build_chamber(ChamberSpec(size=300e-9, contact_width=60e-9))


@pytest.fixture(scope="module")
def basis(triangle):
    return ContactBasis(triangle, ["A", "B", "C"], cell_size=5e-9)


def test_superposition_equals_a_direct_solve(triangle, basis):
    volts = {"A": 0.37e-3, "B": -1.21e-3, "C": 0.05e-3}
    direct = solve_contacts(triangle, volts, cell_size=5e-9)
    summed = basis.flow(volts)
    jx_d, jy_d, phi_d, inside = direct.cell_fields
    jx_s, jy_s, phi_s, _ = summed.cell_fields
    scale = np.max(np.hypot(jx_d, jy_d))
    assert np.max(np.abs(jx_s - jx_d)) < 1e-10 * scale
    assert np.max(np.abs(jy_s - jy_d)) < 1e-10 * scale
    assert np.max(np.abs(phi_s - phi_d)[inside]) < 1e-12
    for k in volts:
        assert summed.contact_currents[k] == pytest.approx(
            direct.contact_currents[k], rel=1e-9, abs=1e-18
        )
    assert basis.power(volts) == pytest.approx(direct.power, rel=1e-9)


def test_contact_currents_obey_kirchhoff_and_the_conductance_is_symmetric(basis):
    g = basis.conductance
    assert np.abs(g.sum(axis=0)).max() < 1e-9 * np.abs(g).max()  # currents sum to zero
    assert np.allclose(g, g.T, rtol=1e-9)  # reciprocity
    assert np.all(np.linalg.eigvalsh(g)[1:] > 0)  # P = VᵀGV ≥ 0, one zero mode


def test_unit_solution_matches_the_source_sink_solver(triangle, basis):
    # contact A at 1 V, B and C at 0 V is solve_current's source A, sinks B and C at 1 V
    solution = solve_current(triangle, 1e9, source="A", sink=["B", "C"], cell_size=5e-9)
    unit = basis.units[0]
    x = np.linspace(-60e-9, 60e-9, 7)
    jx_u, jy_u = unit.current_density_at(x, 0.2 * x)
    jx_s, jy_s = solution.current_density_at(x, 0.2 * x)
    ratio = 1.0 / solution.voltage
    assert np.allclose(jx_u, jx_s * ratio, rtol=1e-9, atol=1e-6 * np.abs(jx_u).max())
    assert np.allclose(jy_u, jy_s * ratio, rtol=1e-9, atol=1e-6 * np.abs(jy_u).max())
    assert unit.contact_currents["A"] == pytest.approx(solution.total_current * ratio, rel=1e-6)


def test_equal_potentials_carry_no_current(triangle):
    flow = solve_contacts(triangle, {"A": 1e-3, "B": 1e-3}, cell_size=5e-9)
    assert flow.power == 0.0 and flow.mean_current_density() == 0.0


@pytest.mark.parametrize(
    "shape, contacts", [("triangle", "ABC"), ("square", "ABCD"), ("disk", "ABC")]
)
def test_chambers_have_their_contacts_on_the_outline(shape, contacts):
    spec = ChamberSpec(shape=shape, size=300e-9, contact_width=60e-9)
    outline = build_chamber(spec)
    assert outline.port_names() == list(contacts)
    for segment in outline.ports.values():
        assert segment.length == pytest.approx(60.0, rel=1e-9)  # nm
        assert outline.region.boundary.distance(segment.centroid) < 1e-6
