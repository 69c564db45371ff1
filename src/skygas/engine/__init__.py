"""The N-body stochastic Thiele engine.

The equation of motion, the overdamped stochastic Thiele equation of every skyrmion with the
current's drive, thermal noise, the pair and wall forces, the landscape's −∇U and the external
force, is written out in docs/physics.md §1 (with its units and signs); the engine integrates
ẋ = M·F, M = (α𝒟k I − G ε)/((α𝒟k)² + G²), with the noise as an isotropic velocity noise of
diffusion constant D = k_B T α𝒟k/((α𝒟k)² + G²).

Integrator: **stochastic Heun** (predictor–corrector trapezoidal rule, the noise increment drawn
once per step and used in both stages). The noise is additive, so the Itô and Stratonovich
solutions coincide and Heun converges to both. Orders: 2 for deterministic dynamics (T = 0);
strong order 1 and weak order 2 with noise. Euler–Maruyama (strong 1 with additive noise, weak 1,
deterministic 1) is offered for comparison only. Heun is inaccurate, like any explicit scheme,
when the time step approaches the fastest force-relaxation time τ_min (see
:meth:`Simulation.max_time_step`); steps above τ_min are refused. The integrators state
their orders in :data:`INTEGRATOR_ORDERS`.

Noise is drawn from Philox4x32-10 keyed on (seed, id, step) (:mod:`skygas.engine._rng`), so results
do not depend on storage order, insertions or removals.

The package, layer by layer:

- :mod:`~skygas.engine.terms`: the force terms and the other typed records the kernel reads
  (adding a force term starts here);
- :mod:`~skygas.engine.neighbors`, :mod:`~skygas.engine.stages`, :mod:`~skygas.engine.kernel`:
  the compiled loop, one named stage at a time (private);
- :mod:`~skygas.engine.force_model`: the tabulated laws and the time step they allow;
- :mod:`~skygas.engine.store`: the skyrmions (positions, ids, annihilation log);
- :mod:`~skygas.engine.state`: ``sim.state``, the documented way to read and change them;
- :mod:`~skygas.engine.scheduler`: operations and planned insertions;
- :mod:`~skygas.engine.recorder`: frames, exits, the trajectories Dataset;
- :mod:`~skygas.engine.simulation`: the :class:`Simulation` façade that wires them.
"""

from __future__ import annotations

from skygas.engine.force_model import (
    MAX_STEP_FRACTION,
    MIN_PLACEMENT_SEPARATION,
    SUGGESTED_STEP_FRACTION,
    ForceModel,
    default_time_step,
    relaxation_time,
)
from skygas.engine.recorder import FrameBlock
from skygas.engine.scheduler import Operation, Periodic, PlannedInsertions
from skygas.engine.simulation import INTEGRATORS, Simulation
from skygas.engine.state import StateView

#: What each integrator is (diffrax-style): its strong and weak order with additive noise,
#: its order without noise, and the stochastic calculus it converges to (the noise is
#: additive, so Itô and Stratonovich coincide).
INTEGRATOR_ORDERS = {
    "heun": {
        "strong": 1.0,
        "weak": 2.0,
        "deterministic": 2.0,
        "calculus": "Itô = Stratonovich (additive noise)",
    },
    "euler-maruyama": {
        "strong": 1.0,
        "weak": 1.0,
        "deterministic": 1.0,
        "calculus": "Itô = Stratonovich (additive noise)",
    },
}

__all__ = [
    "INTEGRATORS",
    "INTEGRATOR_ORDERS",
    "MAX_STEP_FRACTION",
    "MIN_PLACEMENT_SEPARATION",
    "SUGGESTED_STEP_FRACTION",
    "ForceModel",
    "FrameBlock",
    "Operation",
    "Periodic",
    "PlannedInsertions",
    "Simulation",
    "StateView",
    "default_time_step",
    "relaxation_time",
]
