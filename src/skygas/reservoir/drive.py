"""Inputs → contact voltages → current pattern → drift field, and the energy each input costs.

A symbol is a tuple of bits, one per input contact. Bit b on input contact k puts
V_k = levels[b]·V₀ on it; every other contact is at 0 V. The current pattern is the
superposition Σ_k V_k·(unit flow k) of the unit solutions of the current solver
(:class:`~skygas.fields.current.ContactBasis`: contact k at 1 V, the others at 0 V), and the
skyrmions drift with v_s = ξ·j (docs/physics.md §1).

V₀ is set by ``drive.current_density`` J: the chamber-mean |j| of the unit pattern "first input
contact at V₀, every other contact at 0 V" is J. The Joule power of a symbol is P = Vᵀ G V
(G the conductance matrix) and its energy is P·hold_time.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from skygas.core.errors import require
from skygas.fields.current import ContactBasis, ContactFlow
from skygas.physics.geometry import Outline
from skygas.reservoir.config import DriveSpec


@dataclass(frozen=True)
class Drive:
    """The contact voltages and current patterns of every input symbol."""

    basis: ContactBasis
    spec: DriveSpec
    unit_voltage: float  # V₀ [V]

    @classmethod
    def build(cls, outline: Outline, spec: DriveSpec) -> Drive:
        """The drive of ``spec``'s contacts on ``outline`` (the unit current patterns solved)."""
        for k, name in enumerate(spec.input_contacts):
            require(
                name in outline.ports,
                f"drive.input_contacts[{k}]",
                name,
                f"a contact of the chamber: {outline.port_names()}",
            )
        require(
            len(set(spec.input_contacts)) == len(spec.input_contacts)
            and len(outline.ports) > len(spec.input_contacts),
            "drive.input_contacts",
            spec.input_contacts,
            "different contacts, leaving at least one at 0 V",
        )
        basis = ContactBasis(
            outline,
            outline.port_names(),
            cell_size=spec.cell_size,
            conductor_thickness=spec.conductor_thickness,
            resistivity=spec.resistivity,
        )
        first = basis.units[basis.contacts.index(spec.input_contacts[0])]
        unit_voltage = spec.current_density / first.mean_current_density()
        return cls(basis, spec, unit_voltage)

    @property
    def symbols(self) -> list[tuple[int, ...]]:
        """Every input symbol (bits of the input contacts), in binary order."""
        return list(itertools.product((0, 1), repeat=len(self.spec.input_contacts)))

    def potentials(self, symbol) -> dict[str, float]:
        """Contact potentials [V] for ``symbol``."""
        volts = {name: 0.0 for name in self.basis.contacts}
        for name, bit in zip(self.spec.input_contacts, symbol, strict=True):
            volts[name] = self.spec.levels[int(bit)] * self.unit_voltage
        return volts

    def flow(self, symbol) -> ContactFlow:
        """The current flow while ``symbol`` is held."""
        return self.basis.flow(self.potentials(symbol))

    def drift_fields(self, grid) -> dict[tuple[int, ...], tuple[np.ndarray, np.ndarray]]:
        """v_s = ξ·j [m/s] on the engine's field ``grid`` for every symbol."""
        xi = self.spec.spin_drift_coefficient
        return {s: self.flow(s).drift_velocity(grid, xi) for s in self.symbols}

    def power(self, symbol) -> float:
        """Joule power [W] while ``symbol`` is applied."""
        return self.basis.power(self.potentials(symbol))

    def record(self, hold_time: float) -> dict:
        """Voltages, powers.

        Mean |j| and energy per operation (the mean over equiprobable symbols of
        P·hold_time) [SI].
        """
        per = {}
        for s in self.symbols:
            flow = self.flow(s)
            per["".join(map(str, s))] = {
                "potentials_V": self.potentials(s),
                "power_W": self.power(s),
                "mean_current_density_A_per_m2": flow.mean_current_density(),
                "max_current_density_A_per_m2": float(
                    np.max(np.hypot(*flow.cell_fields[:2])[flow.cell_fields[3]])
                ),
                "energy_J": self.power(s) * hold_time,
            }
        return {
            "unit_voltage_V": self.unit_voltage,
            "conductance_matrix_S": self.basis.conductance.tolist(),
            "contacts": list(self.basis.contacts),
            "energy_per_operation_J": float(np.mean([p["energy_J"] for p in per.values()])),
            "symbols": per,
        }
