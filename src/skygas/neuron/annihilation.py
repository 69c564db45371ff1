r"""Annihilation and accidental nucleation of skyrmions (paper, "Skyrmion Neuron"; PHYSICS.md §3-4).

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

The rule is applied every ``check_interval`` :math:`\Delta t`: a skyrmion is removed with
probability :math:`1 - e^{-\Gamma_i \Delta t}` (exact for a rate constant over the interval).

Accidental nucleation (optional): a Poisson process of ``nucleation_rate`` :math:`\nu`
[1/(m² s)] per unit device area; a new skyrmion appears at a uniformly random point of the
outline at least one diameter from the walls and from every skyrmion (attempts that land
elsewhere are dropped and counted). The reshuffler's chambers can use the same operation.

Randomness comes from a NumPy generator seeded from ``SeedSequence((run seed, stream))``, never
from the engine's per-skyrmion noise streams.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

from skygas import units
from skygas.errors import require

#: SeedSequence stream tags (the second entry of the entropy tuple).
ANNIHILATION_STREAM = 0x616E6E
NUCLEATION_STREAM = 0x6E7563


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
        require(math.isfinite(self.base_rate) and self.base_rate >= 0, "annihilation.base_rate",
                self.base_rate, "a rate >= 0 in 1/s")
        require(math.isfinite(self.compression_sensitivity) and self.compression_sensitivity >= 0,
                "annihilation.compression_sensitivity", self.compression_sensitivity,
                "a number >= 0")
        for name in ("crowding_distance", "collapse_distance"):
            value = getattr(self, name)
            require(value is None or (math.isfinite(value) and value > 0),
                    f"annihilation.{name}", value, "a distance > 0 in metres (or unset)")
        require(math.isfinite(self.check_interval) and self.check_interval > 0,
                "annihilation.check_interval", self.check_interval, "an interval > 0 in seconds")
        require(math.isfinite(self.nucleation_rate) and self.nucleation_rate >= 0,
                "annihilation.nucleation_rate", self.nucleation_rate,
                "a rate >= 0 in 1/(m² s)")

    @classmethod
    def off(cls) -> "AnnihilationModel":
        """No annihilation and no nucleation: the count changes only by injection and exit."""
        return cls(base_rate=0.0, enabled=False)

    def lengths_nm(self, skyrmion_diameter: float) -> tuple[float, float]:
        """(r_c, d_min) [nm] for a skyrmion diameter [m]."""
        d = skyrmion_diameter
        r_c = self.crowding_distance if self.crowding_distance is not None \
            else CROWDING_DIAMETERS * d
        d_min = self.collapse_distance if self.collapse_distance is not None else d
        return r_c * units.M_TO_NM, d_min * units.M_TO_NM

    def record(self) -> dict:
        return {"base_rate_per_s": self.base_rate,
                "compression_sensitivity": self.compression_sensitivity,
                "crowding_distance_m": self.crowding_distance,
                "collapse_distance_m": self.collapse_distance,
                "check_interval_s": self.check_interval,
                "nucleation_rate_per_m2_s": self.nucleation_rate,
                "enabled": self.enabled}


#: Default crowding distance in skyrmion diameters (calibrated with the saturation protocol,
#: see CALIBRATED and docs/neuron.md).
CROWDING_DIAMETERS = 2.45


def compression(x_nm: np.ndarray, y_nm: np.ndarray, wall_nm: np.ndarray,
                crowding_nm: float) -> np.ndarray:
    """χ_i of every skyrmion (see the module docstring); positions and distances in nm."""
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


def collapse_victims(x_nm: np.ndarray, y_nm: np.ndarray, wall_nm: np.ndarray, d_min_nm: float,
                     rng: np.random.Generator) -> np.ndarray:
    """Indices of skyrmions that collapse at once: those within d_min/2 of a wall, then one
    randomly chosen member of each remaining pair closer than d_min, until none is left."""
    dead = wall_nm < d_min_nm / 2
    pts = np.column_stack([x_nm, y_nm])
    if len(pts) > 1:
        pairs = cKDTree(pts).query_pairs(d_min_nm, output_type="ndarray")
        for k in rng.permutation(len(pairs)):
            i, j = pairs[k]
            if dead[i] or dead[j]:
                continue
            dead[i if rng.random() < 0.5 else j] = True
    return np.flatnonzero(dead)


@dataclass
class Annihilator:
    """An :class:`~skygas.engine.Operation` applying an :class:`AnnihilationModel`.

    ``region`` (optional, a callable (x_nm, y_nm) → bool mask) restricts nucleation to part of
    the outline (e.g. the chamber, not the conduits). Logs every event as (time [s], x [m], y [m]).
    """

    model: AnnihilationModel
    seed: int
    interval_steps: int
    region: object = None
    annihilations: list = field(default_factory=list)
    nucleations: list = field(default_factory=list)
    nucleation_misses: int = 0
    _next: int = 0

    def __post_init__(self):
        self.rng = np.random.default_rng(np.random.SeedSequence((self.seed, ANNIHILATION_STREAM)))
        self.nuc_rng = np.random.default_rng(np.random.SeedSequence((self.seed, NUCLEATION_STREAM)))

    @classmethod
    def for_simulation(cls, model: AnnihilationModel, sim, region=None) -> "Annihilator":
        steps = max(1, int(round(model.check_interval / sim.time_step)))
        op = cls(model, sim.seed, steps, region)
        op._next = sim.step
        return op

    @property
    def n_annihilated(self) -> int:
        return len(self.annihilations)

    @property
    def n_nucleated(self) -> int:
        return len(self.nucleations)

    def next_step(self, step: int) -> int:
        return self._next if self.model.enabled else np.iinfo(np.int64).max

    def act(self, sim) -> None:
        self._next = sim.step + self.interval_steps
        dt = self.interval_steps * sim.time_step
        self._annihilate(sim, dt)
        if self.model.nucleation_rate > 0:
            self._nucleate(sim, dt)

    def _annihilate(self, sim, dt: float) -> None:
        slots = np.flatnonzero(sim._alive)
        if not len(slots):
            return
        x, y = sim._x[slots], sim._y[slots]
        wall = sim.wall_field.interpolate(x, y)[0]
        r_c, d_min = self.model.lengths_nm(sim.thiele.skyrmion_diameter)
        dead = np.zeros(len(slots), bool)
        dead[collapse_victims(x, y, wall, d_min, self.rng)] = True
        live = np.flatnonzero(~dead)
        dead[live[self._kinetic_monte_carlo(x[live], y[live], wall[live], r_c, dt)]] = True
        victims = slots[dead]
        t = sim.time
        for s in victims:
            self.annihilations.append((t, sim._x[s] / units.M_TO_NM, sim._y[s] / units.M_TO_NM))
        sim._alive[victims] = False

    def _kinetic_monte_carlo(self, x, y, wall, r_c: float, dt: float) -> np.ndarray:
        """Indices annihilated within dt, one event at a time (Gillespie, positions frozen over
        the interval): every removal relieves its neighbours' compression before the next."""
        model = self.model
        alive = np.ones(len(x), bool)
        t_left = dt
        while alive.any():
            idx = np.flatnonzero(alive)
            rate = np.full(len(idx), model.base_rate)
            if model.compression_sensitivity > 0:
                chi = compression(x[idx], y[idx], wall[idx], r_c)
                rate = rate * np.exp(model.compression_sensitivity * chi)
            total = float(rate.sum())
            if total <= 0:
                break
            wait = self.rng.exponential(1.0 / total)
            if wait > t_left:
                break
            t_left -= wait
            alive[idx[np.searchsorted(np.cumsum(rate), self.rng.random() * total)
                      .clip(max=len(idx) - 1)]] = False
        return np.flatnonzero(~alive)

    def _nucleate(self, sim, dt: float) -> None:
        area_m2 = sim.outline.area_nm2() / units.M_TO_NM**2
        n = self.nuc_rng.poisson(self.model.nucleation_rate * area_m2 * dt)
        if not n:
            return
        d_nm = sim.thiele.skyrmion_diameter_internal
        x0, y0, x1, y1 = sim.outline.bounds_nm
        for _ in range(n):
            p = self.nuc_rng.uniform((x0, y0), (x1, y1))
            ok = bool(sim.outline.contains_nm(p[0], p[1]))
            if ok and self.region is not None:
                ok = bool(self.region(p[0], p[1]))
            ok = ok and float(sim.wall_field.interpolate(p[:1], p[1:])[0][0]) >= d_nm
            alive = sim._alive
            if ok and alive.any():
                ok = float(np.min(np.hypot(sim._x[alive] - p[0], sim._y[alive] - p[1]))) >= d_nm
            if ok:
                sim._insert_nm(p[None, :])
                self.nucleations.append((sim.time, p[0] / units.M_TO_NM, p[1] / units.M_TO_NM))
            else:
                self.nucleation_misses += 1
