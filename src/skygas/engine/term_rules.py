"""The rules a one-body force term carries with it, beside its kernel record.

The compiled kernel adds a fixed set of force records (:class:`~skygas.engine.terms.ForceTerms`),
as numba wants. What the Python side must know about a term lives here, in one descriptor per
term, so that a new term cannot forget one of them:

- :meth:`record`: the record the kernel reads (internal units), and :meth:`parameters`, its
  entry in :meth:`Simulation.parameters() <skygas.engine.Simulation.parameters>` (SI);
- :meth:`speed_bound`: the largest speed [nm/ns] it gives a free skyrmion, which sizes the
  neighbour list's margins (a term that moves skyrmions faster than the margins allow makes
  the list rebuild every few steps);
- :meth:`stiffness`: its largest force gradient [pN/nm], which bounds the time step
  (τ = friction/stiffness, docs/physics.md §5);
- :meth:`per_step`: how far it moves a free skyrmion in one step, in diameters, for the sanity
  check that every command runs before a run (``skygas.runs.sanity``).

The current's drift keeps its own path (its speed comes from the current field); its speed
bound is added to those of the terms here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from skygas.core import units
from skygas.engine.terms import ConstantForceTerm, Mobility


@dataclass(frozen=True)
class ConstantForce:
    """A uniform external force F = (F_x, F_y) [N] on every skyrmion: the force of a magnetic
    field gradient on the skyrmion's moment, or of gravity-like tilts of the energy (a film
    whose thickness or anisotropy varies linearly). It enters the Thiele equation beside the
    other forces, so a free skyrmion moves at v = M·F (M the mobility, docs/physics.md §1):
    at the angle of the skyrmion Hall effect to F."""

    force: tuple[float, float] = (0.0, 0.0)

    #: the configuration's name of the term (``[forces] external_force = [F_x, F_y]``)
    name = "external_force"

    def record(self) -> ConstantForceTerm:
        return ConstantForceTerm(self.force[0] * units.N_TO_PN, self.force[1] * units.N_TO_PN)

    def setting(self) -> list[float]:
        """The force as a configuration gives it, (F_x, F_y) [N]."""
        return [float(self.force[0]), float(self.force[1])]

    def parameters(self) -> dict[str, list[float]]:
        return {"external_force_N": self.setting()}

    def speed_bound(self, mobility: Mobility) -> float:
        """|M·F| [nm/ns]: M is a scaled rotation, so |v| = |F|·|(a, g)|."""
        f = self.record()
        return math.hypot(f.fx, f.fy) * math.hypot(mobility.a, mobility.g)

    def stiffness(self) -> float:
        """0 [pN/nm]: a uniform force has no gradient and never limits the time step."""
        return 0.0

    def per_step(self, mobility: Mobility, dt_ns: float, diameter_nm: float) -> float:
        """Diameters a free skyrmion moves in one step under this force alone."""
        return self.speed_bound(mobility) * dt_ns / diameter_nm
