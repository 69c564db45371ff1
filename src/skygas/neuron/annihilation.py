r"""Annihilation and accidental nucleation of skyrmions (paper, "Skyrmion Neuron").

See docs/physics.md §3-4.

The paper gives no annihilation rule; it says that skyrmions compressed by neighbours to length
scales near their diameter collapse (thermal fluctuations, dipolar strain, defects), and that a
1024 nm chamber at 300 K holds about 90 skyrmions of 39 nm. This module's **documented model**:

Each skyrmion *i* carries a compression

.. math::

    \chi_i = \sum_{j \ne i} \Big(1 - \frac{r_{ij}}{r_c}\Big)_+
             + \Big(1 - \frac{2\,d_{w,i}}{r_c}\Big)_+

(:math:`r_{ij}` the centre distance to skyrmion *j*, :math:`d_{w,i}` the distance to the nearest
wall, counted as an image neighbour at :math:`2 d_w`, :math:`r_c` the ``crowding_distance``,
:math:`(\cdot)_+ = \max(\cdot, 0)`) and annihilates as a thermally activated Poisson process of
rate

.. math::

    \Gamma_i = \Gamma_0 \, e^{c\,\chi_i},

:math:`\Gamma_0` the ``base_rate`` of an isolated skyrmion (the neuron's leak) and :math:`c` the
``compression_sensitivity`` (the barrier lowering per unit compression, in k_B T). Closer than
``collapse_distance`` :math:`d_\min` to another skyrmion (or :math:`d_\min/2` to a wall) collapse is
immediate: of each such pair a randomly chosen one disappears, until no pair is that close.

The rule is applied every ``check_interval`` :math:`\Delta t`, with the positions frozen over the
interval: first the immediate collapses, then kinetic Monte Carlo (Gillespie) over
:math:`\Delta t`. With total rate :math:`R = \sum_i \Gamma_i` over the living, the next event comes
after a wait :math:`\sim \mathrm{Exp}(R)`; if it falls inside the interval, skyrmion *i* dies with
probability :math:`\Gamma_i / R`, its neighbours' :math:`\chi` drop by its contribution, and the
next wait is drawn with the new rates. Removing one at a time matters at high density:
removing every skyrmion with probability :math:`1 - e^{-\Gamma_i \Delta t}` at once would kill
neighbours that the first removal had already relieved. The victims leave at the start of the
interval.
The arithmetic is compiled (:mod:`skygas.neuron._compiled`, a cell list for the pairs).

Accidental nucleation (optional): attempts form a Poisson process of ``nucleation_rate``
:math:`\nu` [1/(m² s)] per unit device area (mean :math:`\nu A \Delta t` per interval, A the
outline's area); each attempt falls at a uniformly random point of the outline and nucleates a
skyrmion there if the point is at least one diameter from the walls and from every skyrmion
(other attempts are dropped and counted as misses). In a sparse chamber the nucleation rate is
therefore :math:`\nu` times the area that lies at least one diameter inside the walls. The
reshuffler's chambers can use the same operation.

Randomness comes from a NumPy generator seeded from ``SeedSequence((run seed, stream))``, never
from the engine's per-skyrmion noise streams.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from scipy.spatial import cKDTree

from skygas.core import units
from skygas.core.errors import require
from skygas.neuron._compiled import annihilation_check, total_rate

if TYPE_CHECKING:
    from skygas.engine.simulation import Simulation

#: SeedSequence stream tags (the second entry of the entropy tuple).
ANNIHILATION_STREAM = 0x616E6E
NUCLEATION_STREAM = 0x6E7563
#: The reason under which the simulation logs this model's annihilations.
REASON = "annihilation"
#: The kernels' fixed arguments: wall-distance grid [nm], its x0, y0 and spacing [nm], r_c and
#: d_min [nm], base rate [1/s], compression sensitivity.
_FixedArguments = tuple[np.ndarray, float, float, float, float, float, float, float]


@dataclass(frozen=True)
class AnnihilationModel:
    """Parameters of the annihilation/nucleation rule (SI units at this edge).

    base_rate: Γ0 [1/s], rate of an isolated skyrmion (0: no leak).
    compression_sensitivity: c [dimensionless, k_B T per unit compression].
    crowding_distance: r_c [m]; ``None`` = CROWDING_DIAMETERS skyrmion diameters.
    collapse_distance: d_min [m]; ``None`` = one skyrmion diameter (the force laws' validity
        limit, paper "Boundary Effects").
    check_interval: Δt [s] between applications (rounded to whole time steps, at least one).
    nucleation_rate: ν [1/(m² s)] of accidental nucleation (0: none).
    enabled: False switches the whole rule off (exact particle conservation).
    """

    base_rate: float = 1e6
    compression_sensitivity: float = 0.0
    crowding_distance: float | None = None
    collapse_distance: float | None = None
    check_interval: float = 0.25e-9
    nucleation_rate: float = 0.0
    enabled: bool = True

    def __post_init__(self):
        require(
            math.isfinite(self.base_rate) and self.base_rate >= 0,
            "annihilation.base_rate",
            self.base_rate,
            "a rate >= 0 in 1/s",
        )
        require(
            math.isfinite(self.compression_sensitivity) and self.compression_sensitivity >= 0,
            "annihilation.compression_sensitivity",
            self.compression_sensitivity,
            "a number >= 0",
        )
        for name in ("crowding_distance", "collapse_distance"):
            value = getattr(self, name)
            require(
                value is None or (math.isfinite(value) and value > 0),
                f"annihilation.{name}",
                value,
                "a distance > 0 in metres (or unset)",
            )
        require(
            math.isfinite(self.check_interval) and self.check_interval > 0,
            "annihilation.check_interval",
            self.check_interval,
            "an interval > 0 in seconds",
        )
        require(
            math.isfinite(self.nucleation_rate) and self.nucleation_rate >= 0,
            "annihilation.nucleation_rate",
            self.nucleation_rate,
            "a rate >= 0 in 1/(m² s)",
        )

    @classmethod
    def off(cls) -> AnnihilationModel:
        """No annihilation and no nucleation: the count changes only by injection and exit."""
        return cls(base_rate=0.0, enabled=False)

    def _lengths_nm(self, skyrmion_diameter: float) -> tuple[float, float]:
        """(r_c, d_min) [nm] for a skyrmion diameter [m]."""
        d = skyrmion_diameter
        r_c = (
            self.crowding_distance if self.crowding_distance is not None else CROWDING_DIAMETERS * d
        )
        d_min = self.collapse_distance if self.collapse_distance is not None else d
        return r_c * units.M_TO_NM, d_min * units.M_TO_NM

    def record(self) -> dict:
        """The parameters as a dict for result files, SI units in the keys."""
        return {
            "base_rate_per_s": self.base_rate,
            "compression_sensitivity": self.compression_sensitivity,
            "crowding_distance_m": self.crowding_distance,
            "collapse_distance_m": self.collapse_distance,
            "check_interval_s": self.check_interval,
            "nucleation_rate_per_m2_s": self.nucleation_rate,
            "enabled": self.enabled,
        }


#: Default crowding distance in skyrmion diameters (calibrated with the saturation protocol,
#: see CALIBRATED and docs/neuron.md).
CROWDING_DIAMETERS = 2.45


def compression(
    x_nm: np.ndarray, y_nm: np.ndarray, wall_nm: np.ndarray, crowding_nm: float
) -> np.ndarray:
    """χ_i of every skyrmion (see the module docstring); positions and distances in nm.

    A readable reference for inspection and tests; runs use the compiled
    :func:`skygas.neuron._compiled.annihilation_check`, which computes the same χ.
    """
    n = len(x_nm)
    chi = np.clip(1.0 - 2.0 * wall_nm / crowding_nm, 0.0, None)
    if n > 1:
        pts = np.column_stack([x_nm, y_nm])
        pairs = cKDTree(pts).query_pairs(crowding_nm, output_type="ndarray")
        if len(pairs):
            r = np.hypot(*(pts[pairs[:, 0]] - pts[pairs[:, 1]]).T)
            w = 1.0 - r / crowding_nm
            chi += np.bincount(pairs[:, 0], w, n) + np.bincount(pairs[:, 1], w, n)
    return chi


@dataclass
class Annihilator:
    """An :class:`~skygas.engine.Operation` applying an :class:`AnnihilationModel`.

    ``region`` (optional, a callable (x_nm, y_nm) → bool mask) restricts nucleation to part of
    the outline (e.g. the chamber, not the conduits). Nucleations are logged here as (time [s],
    x [m], y [m]); annihilations go to the simulation's own log, ``sim.annihilations``, under
    the reason :data:`REASON` (read back through :attr:`annihilation_times`).
    """

    #: its name among a run's operations: the simulation checkpoints it under this name
    name: ClassVar[str] = "annihilator"

    model: AnnihilationModel
    seed: int
    interval_steps: int
    region: Callable[[float, float], Any] | None = None
    nucleations: list = field(default_factory=list)
    nucleation_misses: int = 0
    _next: int = 0
    simulation: Simulation | None = field(default=None, repr=False)  # set by for_simulation, act

    def __post_init__(self) -> None:
        self._victims = np.empty(0, np.int64)
        self._fixed: tuple[AnnihilationModel, Any, _FixedArguments] | None = None
        self.rng = np.random.default_rng(np.random.SeedSequence((self.seed, ANNIHILATION_STREAM)))
        self.nuc_rng = np.random.default_rng(np.random.SeedSequence((self.seed, NUCLEATION_STREAM)))

    @classmethod
    def for_simulation(cls, model: AnnihilationModel, sim, region=None) -> Annihilator:
        """The operation of ``model`` for ``sim``, first acting at its current step.

        ``check_interval`` is rounded to whole time steps (at least one); ``region`` is passed to
        the constructor.
        """
        steps = max(1, int(round(model.check_interval / sim.time_step)))
        op = cls(model, sim.seed, steps, region)
        op._next = sim.step
        op.simulation = sim
        return op

    @property
    def annihilation_times(self) -> np.ndarray:
        """Times [s] of this model's annihilations, in order (from ``sim.annihilations``)."""
        if self.simulation is None:  # not attached to a simulation yet
            return np.empty(0)
        return self.simulation.annihilations.times(REASON)

    @property
    def n_annihilated(self) -> int:
        """Skyrmions this rule removed so far (from the simulation's annihilation log)."""
        return self.simulation.annihilations.count(REASON) if self.simulation is not None else 0

    @property
    def n_nucleated(self) -> int:
        """Skyrmions nucleated so far."""
        return len(self.nucleations)

    def next_step(self, step: int) -> int:
        """The next check's step (the largest int64, never, when the rule is disabled)."""
        return self._next if self.model.enabled else np.iinfo(np.int64).max

    def act(self, sim) -> None:
        """Apply the rule over the next check interval: annihilation, then nucleation (if ν > 0)."""
        self.simulation = sim
        self._next = sim.step + self.interval_steps
        dt = self.interval_steps * sim.time_step
        self._annihilate(sim, dt)
        if self.model.nucleation_rate > 0:
            self._nucleate(sim, dt)

    def state_dict(self) -> dict:
        """The mutable state as JSON-able values: nucleation log, counters, schedule, generators.

        :meth:`load_state_dict` continues bit-identically. (The annihilations are in the
        simulation's checkpoint, with its log.)
        """
        return {
            "nucleations": [list(map(float, e)) for e in self.nucleations],
            "nucleation_misses": int(self.nucleation_misses),
            "next": int(self._next),
            "rng": self.rng.bit_generator.state,
            "nuc_rng": self.nuc_rng.bit_generator.state,
        }

    def load_state_dict(self, state: dict) -> None:
        """Restore the state :meth:`state_dict` saved."""
        self.nucleations = [tuple(e) for e in state["nucleations"]]
        self.nucleation_misses = int(state["nucleation_misses"])
        self._next = int(state["next"])
        self.rng.bit_generator.state = state["rng"]
        self.nuc_rng.bit_generator.state = state["nuc_rng"]

    def _fixed_arguments(self, sim) -> _FixedArguments:
        """The kernels' arguments that stay fixed during a run.

        Looked up once per model and simulation.
        """
        if self._fixed is None or self._fixed[0] is not self.model or self._fixed[1] is not sim:
            wall, grid = sim.wall_field.wall_distance, sim.wall_field.grid
            r_c, d_min = self.model._lengths_nm(sim.thiele.skyrmion_diameter)
            self._fixed = (
                self.model,
                sim,
                (
                    wall,
                    grid.x0,
                    grid.y0,
                    grid.spacing,
                    r_c,
                    d_min,
                    self.model.base_rate,
                    self.model.compression_sensitivity,
                ),
            )
        return self._fixed[2]

    def _annihilate(self, sim, dt: float) -> None:
        # the store's arrays are re-read every time: the engine replaces them when it grows
        store = sim.state.arrays_nm()
        args = (store.x, store.y, store.alive, *self._fixed_arguments(sim))
        total, candidates = total_rate(*args)
        first_wait = -1.0
        if not candidates:
            if total <= 0:
                return
            # the draw the Gillespie loop would make first; most checks end here
            first_wait = self.rng.exponential(1.0 / total)
            if first_wait > dt:
                return
        if len(self._victims) < len(store.alive):
            self._victims = np.empty(len(store.alive), np.int64)
        n = annihilation_check(*args, dt, self.rng, first_wait, self._victims)
        victims = self._victims[:n]
        sim.state.annihilate(store.ids[victims], REASON)

    def _nucleate(self, sim, dt: float) -> None:
        area_m2 = sim.outline.area()
        n = self.nuc_rng.poisson(self.model.nucleation_rate * area_m2 * dt)
        if not n:
            return
        d_nm = sim.thiele.skyrmion_diameter_internal
        for _ in range(n):
            p = self._uniform_point(sim.outline)
            ok = self.region is None or bool(self.region(p[0], p[1]))
            ok = ok and float(sim.wall_field.interpolate(p[:1], p[1:])[0][0]) >= d_nm
            if ok:
                ok = sim.state.is_site_clear_nm(p[0], p[1], d_nm)
            if ok:
                sim.state.insert_nm(p[None, :])
                self.nucleations.append((sim.time, p[0] / units.M_TO_NM, p[1] / units.M_TO_NM))
            else:
                self.nucleation_misses += 1

    def _uniform_point(self, outline) -> np.ndarray:
        """A point [nm] uniformly distributed over the outline.

        Rejection from its bounding box: the attempt rate ν·A already counts the outline's area, so
        a point outside it must be drawn again, not dropped.
        """
        x0, y0, x1, y1 = outline._bounds_nm
        while True:
            p = self.nuc_rng.uniform((x0, y0), (x1, y1))
            if outline._contains_nm(p[0], p[1]):
                return p
