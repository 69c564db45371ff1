"""The tabulated force laws of a run, and the time step they allow.

:class:`ForceModel` tabulates the pair and wall laws of :mod:`skygas.forces` in internal units
(nm, pN). :func:`relaxation_time` is the fastest force relaxation τ_min; steps longer than
``MAX_STEP_FRACTION`` · τ_min are refused and ``SUGGESTED_STEP_FRACTION`` · τ_min is the
default (checked by :func:`skygas.timestep.check_time_step`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from skygas import units
from skygas.forces import DEFAULT_CUTOFF_FRACTION, ForceTable, pair_law, wall_law
from skygas.materials import Material, ThieleParameters
from skygas.memo import Memo, frozen

#: Time steps longer than this fraction of τ_min are refused (see Simulation.max_time_step).
MAX_STEP_FRACTION = 1.0
#: Suggested time step as a fraction of τ_min.
SUGGESTED_STEP_FRACTION = 0.1
#: Skyrmions closer than this many diameters are "on top of each other" and refused. The same
#: distance bounds the range where the force laws' stiffness sets the time-step limit: the
#: laws are not valid below about one diameter (paper, "Boundary Effects"), and skyrmions
#: pushed that close annihilate rather than bounce (the annihilation model handles them).
MIN_PLACEMENT_SEPARATION = 0.5

# Force tables per law, coefficients, F₀, d_sk and cutoff fraction (see skygas.memo): finding a
# law's cutoff scans it at 2·10⁵ points, 10 ms per model.
_FORCE_TABLES = Memo("force_tables", maxsize=8)


@dataclass(frozen=True)
class ForceModel:
    """The tabulated pair and wall laws (internal units) and how they were made."""

    pair: ForceTable
    wall: ForceTable
    pair_law: str
    pair_law_params: dict
    cutoff_fraction: float

    @classmethod
    def build(cls, material: Material, thiele: ThieleParameters, pair_law_name: str = "paper",
              pair_law_params: dict | None = None,
              cutoff_fraction: float = DEFAULT_CUTOFF_FRACTION) -> "ForceModel":
        params = dict(pair_law_params or {})
        f0 = thiele.force_scale_internal
        d_sk = thiele.skyrmion_diameter_internal
        key = (pair_law_name, tuple(material.pair_law), tuple(material.wall_law),
               repr(sorted(params.items())), f0, d_sk, float(cutoff_fraction))

        def tabulate() -> tuple[ForceTable, ForceTable]:
            # 8192 nodes in r²: relative error < 5e-5 from r = d_sk/4 on (64 kB, in L2 cache)
            pair = ForceTable.from_law(pair_law(pair_law_name, material.pair_law, **params),
                                       f0, d_sk, cutoff_fraction, n_points=8192, squared=True)
            wall = ForceTable.from_law(wall_law(material.wall_law), f0, d_sk, cutoff_fraction)
            frozen(pair.values, wall.values)
            return pair, wall

        # each model gets its own (writable) copy of the shared tables: the kernels take
        # writable arrays (a read-only one would compile a second variant of every kernel)
        pair, wall = (replace(table, values=table.values.copy())
                      for table in _FORCE_TABLES.get(key, tabulate))
        return cls(pair, wall, pair_law_name, params, cutoff_fraction)

    def max_stiffness(self, closest: float = 0.0) -> float:
        """Largest |dF/dr| [pN/nm] of either tabulated law at distances r ≥ ``closest`` [nm]."""
        slopes = [0.0]
        for table in (self.pair, self.wall):
            if table.cutoff <= closest:  # a law that is zero there has no slope
                continue
            r = np.linspace(closest, table.cutoff, 20_001)
            slopes.append(float(np.max(np.abs(np.diff(table(r)))) / (r[1] - r[0])))
        return max(slopes)


def relaxation_time(thiele: ThieleParameters, forces: ForceModel,
                    landscape_curvature: float = 0.0) -> float:
    """τ_min [s]: the fastest force relaxation, 1/(κ_max |M|).

    κ_max is the steepest slope |dF/dr| of either force law at distances of at least
    MIN_PLACEMENT_SEPARATION skyrmion diameters (from another skyrmion or from a wall), or the
    largest curvature |∂²U| [pN/nm] of an energy landscape if that is steeper, and
    |M| = 1/√(G² + (α𝒟k)²) the mobility: a skyrmion displaced on the steepest part of a law
    relaxes back (spiralling, when G ≠ 0) at the rate κ_max|M|. Closer than that the laws are
    not valid (paper, "Boundary Effects"), so their slope there does not limit the step; a
    step that carries a skyrmion across a wall is undone and counted (``wall_escapes``).
    """
    a, g = thiele.friction_internal, thiele.gyrocoupling_internal
    closest = MIN_PLACEMENT_SEPARATION * thiele.skyrmion_diameter_internal
    stiffness = max(forces.max_stiffness(closest), landscape_curvature)
    rate = stiffness / math.hypot(a, g)  # 1/ns
    return math.inf if rate == 0 else 1.0 / rate / units.S_TO_NS


def default_time_step(thiele: ThieleParameters, forces: ForceModel, interval: float) -> float:
    """The suggested step SUGGESTED_STEP_FRACTION · τ_min [s], shortened so that ``interval``
    [s] (a recording or injection interval) is a whole number of steps."""
    suggested = SUGGESTED_STEP_FRACTION * relaxation_time(thiele, forces)
    return interval / math.ceil(interval / suggested - 1e-9)
