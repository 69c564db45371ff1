"""The N-body stochastic Thiele engine.

Equation of motion (PHYSICS.md §1; SI, sign convention in ``docs/conventions.md``), for each
skyrmion i:

    (G ε + α𝒟k I)·ẋᵢ = μ (G ε + η𝒟k I)·v_s(xᵢ) + F_th,i + Σⱼ F_ss(xᵢ − xⱼ) + F_wall(xᵢ)

with ⟨F_th,a(t) F_th,b(t')⟩ = 2α𝒟k k_B T δ_ab δ(t − t'). Solving the 2×2 system gives
ẋ = M·F with M = (α𝒟k I − G ε)/((α𝒟k)² + G²); the noise enters as the isotropic velocity noise
M·F_th of diffusion constant D = k_B T α𝒟k/((α𝒟k)² + G²).

Integrator: **stochastic Heun** (predictor–corrector trapezoidal rule, the noise increment drawn
once per step and used in both stages). The noise is additive, so the Itô and Stratonovich
solutions coincide and Heun converges to both. Orders: 2 for deterministic dynamics (T = 0);
strong order 1 and weak order 2 with noise. Euler–Maruyama (strong 1 with additive noise, weak 1,
deterministic 1) is offered for comparison only. Heun is inaccurate, like any explicit scheme,
when the time step approaches the fastest force-relaxation time τ_min (see
:meth:`Simulation.max_time_step`); steps above τ_min are refused.

State: fixed-capacity structure of arrays (x, y in nm, an alive mask, a persistent integer id
per skyrmion) that grows on demand, so skyrmions can be inserted and removed during a run.
Noise is drawn from Philox4x32-10 keyed on (seed, id, step) (:mod:`skygas._rng`), so results do
not depend on storage order, insertions or removals.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Callable, NamedTuple, Protocol

import numpy as np

from skygas import _kernels as K
from skygas import units
from skygas._field_lookup import empty_fields
from skygas._version import __version__
from skygas.errors import InputError, require
from skygas.exit_log import ExitLog
from skygas.forces import DEFAULT_CUTOFF_FRACTION, ForceTable, pair_law, wall_law
from skygas.geometry import Outline
from skygas.materials import Material, ThieleParameters, derive_thiele, load_material
from skygas.memo import Memo, frozen
from skygas.wall_field import WallField

if TYPE_CHECKING:
    import xarray as xr

#: Time steps longer than this fraction of τ_min are refused (see Simulation.max_time_step).
MAX_STEP_FRACTION = 1.0
#: Suggested time step as a fraction of τ_min.
SUGGESTED_STEP_FRACTION = 0.1
#: Skyrmions closer than this many diameters are "on top of each other" and refused. The same
#: distance bounds the range where the force laws' stiffness sets the time-step limit: the
#: laws are not valid below about one diameter (paper, "Boundary Effects"), and skyrmions
#: pushed that close annihilate rather than bounce (the annihilation model handles them).
MIN_PLACEMENT_SEPARATION = 0.5
#: Neighbour-list skin in skyrmion diameters (the list is rebuilt after a skyrmion moves
#: half of it; larger skins rebuild less often but carry more pairs beyond the cutoff). At
#: 300 K a skyrmion of S2 diffuses ~1 nm per suggested step: with 0.25 the list of 100
#: skyrmions was rebuilt every 3 steps, with 1.0 every 25, and the step was 15-20 % faster
#: (benchmarks/bench_engine.py, 100 and 1000 skyrmions).
NEIGHBOR_SKIN = 1.0
#: A skyrmion that drifts fast gets a wider margin in the neighbour list, room for this many
#: steps of its motion (a current pushes skyrmions along a conduit by several nm per step,
#: which would otherwise force a rebuild at every step) ...
NEIGHBOR_MARGIN_STEPS = 8.0
#: ... up to this many skyrmion diameters (wider margins make larger cells and longer lists).
NEIGHBOR_MARGIN_MAX = 1.25

INTEGRATORS = {"heun": 0, "euler-maruyama": 1}
#: Free slots beyond the last occupied one that a kernel call with planned insertions sees.
PLAN_SLOTS = 4
#: Systems with more skyrmions than this are sorted spatially before each kernel call.
SORT_ABOVE = 256


# Force tables per law, coefficients, F₀, d_sk and cutoff fraction (see skygas.memo): finding a
# law's cutoff scans it at 2·10⁵ points, 10 ms per model.
_FORCE_TABLES = Memo("force_tables", maxsize=8)
# The wall channels of the kernels' packed grid, per wall field (WallField.key; see
# skygas.memo): each run of a device copies them instead of re-packing four float64 fields.
_WALL_CHANNELS = Memo("wall_channels", maxsize=4)


def _packed_wall_channels(wall_field: WallField) -> np.ndarray:
    """The packed float32 grid (:func:`~skygas._field_lookup.empty_fields`) with the wall
    channels filled in and no drift (read-only)."""
    packed = empty_fields(wall_field.grid.ny, wall_field.grid.nx)
    packed[..., K.CH_WALL_DIST] = wall_field.wall_distance
    packed[..., K.CH_NORMAL_X] = wall_field.normal_x
    packed[..., K.CH_NORMAL_Y] = wall_field.normal_y
    packed[..., K.CH_DOMAIN] = wall_field.domain_distance
    frozen(packed)
    return packed


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


def relaxation_time(thiele: ThieleParameters, forces: ForceModel) -> float:
    """τ_min [s]: the fastest force relaxation, 1/(κ_max |M|).

    κ_max is the steepest slope |dF/dr| of either force law at distances of at least
    MIN_PLACEMENT_SEPARATION skyrmion diameters (from another skyrmion or from a wall), and
    |M| = 1/√(G² + (α𝒟k)²) the mobility: a skyrmion displaced on the steepest part of a law
    relaxes back (spiralling, when G ≠ 0) at the rate κ_max|M|. Closer than that the laws are
    not valid (paper, "Boundary Effects"), so their slope there does not limit the step; a
    step that carries a skyrmion across a wall is undone and counted (``wall_escapes``).
    """
    a, g = thiele.friction_internal, thiele.gyrocoupling_internal
    closest = MIN_PLACEMENT_SEPARATION * thiele.skyrmion_diameter_internal
    rate = forces.max_stiffness(closest) / math.hypot(a, g)  # 1/ns
    return math.inf if rate == 0 else 1.0 / rate / units.S_TO_NS


def default_time_step(thiele: ThieleParameters, forces: ForceModel, interval: float) -> float:
    """The suggested step SUGGESTED_STEP_FRACTION · τ_min [s], shortened so that ``interval``
    [s] (a recording or injection interval) is a whole number of steps."""
    suggested = SUGGESTED_STEP_FRACTION * relaxation_time(thiele, forces)
    return interval / math.ceil(interval / suggested - 1e-9)


class Operation(Protocol):
    """Something that acts on a simulation on a schedule (injectors, gates, writers).

    ``next_step(step)`` returns the step count at which the operation next wants to act: the
    engine stops there and calls ``act(sim)`` (a value ≤ ``step`` means "now", before any
    further stepping). An operation can change its schedule from one call to the next (an
    injector retrying an occupied site, a gate opening)."""

    def next_step(self, step: int) -> int: ...

    def act(self, sim: "Simulation") -> None: ...


class PlannedInsertions(Protocol):
    """An :class:`Operation` that can also hand its insertions to the compiled kernel.

    ``plan_insertions(step, limit)`` returns the insertions it would make at steps in
    (``step``, ``limit``), as ``(steps, positions_nm (k, 2), clearance_nm)``, each to be made at
    the start of its step if no skyrmion lies closer than the clearance to its position, or
    ``None`` when it needs Python for its next decisions (then it acts through ``act`` as
    usual). The kernel makes them in order and stops before the first one it cannot make (site
    occupied, or no free slot); ``planned_insertions_made(sim, ids)`` then reports the ids of
    those made, and the operation's ``next_step`` takes over from there. This saves a return to
    Python for every insertion (the reshuffler nucleates every 20 steps)."""

    def plan_insertions(self, step: int, limit: int): ...

    def planned_insertions_made(self, sim: "Simulation", ids: np.ndarray) -> None: ...


class Periodic:
    """Call ``action(sim)`` every ``period_steps`` steps (a convenience :class:`Operation`)."""

    def __init__(self, period_steps: int, action: Callable[["Simulation"], None]):
        require(period_steps >= 1, "period_steps", period_steps, "an integer >= 1")
        self.period_steps = int(period_steps)
        self.action = action

    def next_step(self, step: int) -> int:
        return (step // self.period_steps + 1) * self.period_steps

    def act(self, sim: "Simulation") -> None:
        self.action(sim)


class FrameBlock(NamedTuple):
    """The frames one kernel call recorded: ``f`` frames of the ``slots`` storage slots it saw.

    ``x``, ``y`` [nm] are NaN and ``ids`` is −1 where a slot was empty. The id in a slot can
    change from frame to frame (a skyrmion leaves, a new one is inserted in its slot)."""

    step: np.ndarray   # (f,) global step numbers
    time: np.ndarray   # (f,) [s]
    x: np.ndarray      # (f, slots) [nm]
    y: np.ndarray      # (f, slots) [nm]
    ids: np.ndarray    # (f, slots)

    def positions(self, f: int) -> tuple[np.ndarray, np.ndarray]:
        """Frame ``f`` as :meth:`Simulation.positions` gives the live state: (ids, positions
        [m] of shape (n, 2)) of the skyrmions present, ordered by id."""
        present = self.ids[f] >= 0
        return _by_id(self.ids[f][present], self.x[f][present], self.y[f][present])


def _by_id(ids: np.ndarray, x_nm: np.ndarray, y_nm: np.ndarray):
    """(ids in increasing order, positions [m] of shape (n, 2)) of the given skyrmions."""
    order = np.argsort(ids)
    return ids[order].copy(), np.column_stack([x_nm[order], y_nm[order]]) / units.M_TO_NM


class Simulation:
    """A skyrmion gas in a device outline.

    Parameters
    ----------
    outline: the device (:mod:`skygas.geometry`).
    material: a :class:`~skygas.materials.Material`, preset name or TOML path.
    temperature: T [K] (0 for deterministic dynamics).
    time_step: dt [s]; refused above :meth:`max_time_step`; ``None`` takes
        :meth:`suggested_time_step`.
    seed: non-negative integer; with the same seed a run is bit-identical.
    film_thickness: t_F [m] (default 2 nm, as in the paper).
    thiele: explicit Thiele parameters (otherwise derived from the material and film).
    drift_velocity: uniform spin-drift velocity v_s [m/s] (x, y).
    pair_law, pair_law_params, cutoff_fraction: see :mod:`skygas.forces`.
    grid_spacing: wall-field grid spacing [m] (default d_sk/16).
    integrator: ``"heun"`` (default) or ``"euler-maruyama"`` (for comparison only).
    brownian_substeps: draw each step's noise as the sum of this many sub-increments, so that
        runs with steps dt and dt/m share one Brownian path (strong-convergence studies).
    """

    def __init__(self, outline: Outline, material: Material | str = "S2", *,
                 temperature: float = 300.0, time_step: float | None = None, seed: int = 0,
                 film_thickness: float = 2e-9, thiele: ThieleParameters | None = None,
                 drift_velocity=(0.0, 0.0), pair_law: str = "paper",
                 pair_law_params: dict | None = None,
                 cutoff_fraction: float = DEFAULT_CUTOFF_FRACTION,
                 grid_spacing: float | None = None, integrator: str = "heun",
                 brownian_substeps: int = 1, capacity: int = 64):
        require(isinstance(outline, Outline), "geometry", outline, "a skygas Outline")
        require(np.isfinite(temperature) and temperature >= 0, "temperature", temperature,
                "a temperature >= 0 in kelvin")
        require(isinstance(seed, (int, np.integer)) and 0 <= seed < 2**63, "seed", seed,
                "an integer in [0, 2^63)")
        require(integrator in INTEGRATORS, "integrator", integrator, f"one of {list(INTEGRATORS)}")
        require(isinstance(brownian_substeps, (int, np.integer)) and brownian_substeps >= 1,
                "brownian_substeps", brownian_substeps, "an integer >= 1")
        self.outline = outline
        self.material = load_material(material)
        self.thiele = thiele or derive_thiele(self.material, film_thickness)
        self.temperature = float(temperature)
        self.seed = int(seed)
        self.integrator = integrator
        self.forces = ForceModel.build(self.material, self.thiele, pair_law, pair_law_params,
                                       cutoff_fraction)
        d_sk = self.thiele.skyrmion_diameter_internal
        spacing = d_sk / 16 if grid_spacing is None else grid_spacing * units.M_TO_NM
        require(spacing > 0 and spacing <= d_sk, "grid_spacing", grid_spacing,
                f"a spacing in (0, {d_sk * 1e-9:.3g}] m (at most one skyrmion diameter)")
        band = self.forces.wall.cutoff + 2 * spacing
        self.wall_field = WallField.build(outline, spacing, band)
        limit = self.max_time_step()
        if time_step is None:
            time_step = self.suggested_time_step()
        require(np.isfinite(time_step) and 0 < time_step <= limit, "time_step", time_step,
                f"a step in (0, {limit:.3g}] s: longer steps do not resolve the fastest force "
                f"relaxation τ_min = {limit:.3g} s (suggested ≤ {self.suggested_time_step():.3g} s)")
        self.time_step = float(time_step)

        # -- state (structure of arrays, internal units) -----------------------------------
        self._x = np.zeros(capacity)
        self._y = np.zeros(capacity)
        self._alive = np.zeros(capacity, dtype=np.bool_)
        self._ids = np.full(capacity, -1, dtype=np.int64)
        self._next_id = 0
        self.step = 0
        self.exits = ExitLog(outline.ports)
        self.wall_escapes = 0
        self.pair_evaluations = 0
        self.operations: list[Operation] = []
        self._frame_blocks: list[FrameBlock] = []

        # -- parameters for the kernels ------------------------------------------------------
        t = self.thiele
        a, g = t.friction_internal, t.gyrocoupling_internal
        kt = units.thermal_energy_internal(self.temperature)
        self._fp = np.zeros(K.FP_SIZE)
        self._fp[K.FP_DT] = self.time_step * units.S_TO_NS
        self._fp[K.FP_MOB_A] = a / (a * a + g * g)
        self._fp[K.FP_MOB_G] = g / (a * a + g * g)
        # √(2 D dt) per axis; the kernel sums `brownian_substeps` normals and rescales.
        self._fp[K.FP_NOISE] = math.sqrt(2.0 * kt * a / (a * a + g * g) * self._fp[K.FP_DT])
        self._fp[K.FP_DRIVE_G] = t.mu * g
        self._fp[K.FP_DRIVE_B] = t.mu * t.drive_friction_internal
        self._fp[K.FP_PAIR_H2] = self.forces.pair.spacing
        self._fp[K.FP_PAIR_CUT] = self.forces.pair.cutoff
        self._fp[K.FP_WALL_H] = self.forces.wall.spacing
        self._fp[K.FP_WALL_CUT] = self.forces.wall.cutoff
        grid = self.wall_field.grid
        self._fp[K.FP_GRID_X0], self._fp[K.FP_GRID_Y0] = grid.x0, grid.y0
        self._fp[K.FP_GRID_H] = grid.spacing
        self._ip = np.zeros(K.IP_SIZE, dtype=np.int64)
        self._ip[K.IP_SEED] = self.seed
        self._ip[K.IP_SUBSTEPS] = brownian_substeps
        self._ip[K.IP_SCHEME] = INTEGRATORS[integrator]
        self._ip[K.IP_THERMAL] = 1 if self.temperature > 0 else 0
        # Every per-node field in one interleaved float32 array: a bilinear lookup then reads
        # four 32-byte nodes (one vector load each, skygas._field_lookup) instead of twenty
        # scattered values.
        self._fields = empty_fields(grid.ny, grid.nx)
        self._fields[...] = _WALL_CHANNELS.get(WallField.key(outline, spacing, band),
                                               lambda: _packed_wall_channels(self.wall_field))
        self._grid_drift_max = 0.0  # largest |v_s| on the grid [nm/ns] (set_drift_field)
        self.set_uniform_drift(drift_velocity)
        ports = list(outline.ports.values())
        self._ports = np.array([[*p.coords[0], *p.coords[-1]] for p in ports]).reshape(-1, 4)
        self._fp[K.FP_SKIN] = NEIGHBOR_SKIN * d_sk
        self._fp[K.FP_MARGIN_STEPS] = NEIGHBOR_MARGIN_STEPS
        self._configure_neighbor_cells()
        self.neighbor_rebuilds = 0

    def _configure_neighbor_cells(self) -> None:
        """Largest neighbour-list margin and the cell list that goes with it.

        The margin cap covers NEIGHBOR_MARGIN_STEPS steps of the fastest free drift the
        current field can cause (at most NEIGHBOR_MARGIN_MAX diameters); without a drift it is
        the base half-skin. Cells are no smaller than cutoff + 2·cap and cover the field grid
        (skyrmions outside it are clamped into edge cells). Called whenever the drift changes.
        """
        fp = self._fp
        if self._ip[K.IP_DRIFT_GRID]:
            vs = self._grid_drift_max
        else:
            vs = math.hypot(fp[K.FP_VS_X], fp[K.FP_VS_Y])
        # |v| of a free skyrmion = |mobility|·|drive|·|v_s| (both matrices are scaled rotations)
        speed = vs * math.hypot(fp[K.FP_DRIVE_G], fp[K.FP_DRIVE_B]) * math.hypot(
            fp[K.FP_MOB_A], fp[K.FP_MOB_G])
        base = 0.5 * fp[K.FP_SKIN]
        cap = NEIGHBOR_MARGIN_MAX * self.thiele.skyrmion_diameter_internal
        fp[K.FP_MARGIN_MAX] = max(base, min(base + NEIGHBOR_MARGIN_STEPS * fp[K.FP_DT] * speed,
                                            cap))
        reach = fp[K.FP_PAIR_CUT] + 2.0 * fp[K.FP_MARGIN_MAX]
        grid = self.wall_field.grid
        width = grid.spacing * (grid.nx - 1)
        height = grid.spacing * (grid.ny - 1)
        ncx = max(1, int(width // reach))
        ncy = max(1, int(height // reach))
        fp[K.FP_CELL_X0], fp[K.FP_CELL_Y0] = grid.x0, grid.y0
        fp[K.FP_CELL_SIZE] = max(width / ncx, height / ncy)
        self._ip[K.IP_NCX], self._ip[K.IP_NCY] = ncx, ncy

    # -- time step -----------------------------------------------------------------------------
    def relaxation_time(self) -> float:
        """τ_min [s] of this simulation (see :func:`relaxation_time`)."""
        return relaxation_time(self.thiele, self.forces)

    def max_time_step(self) -> float:
        """Largest accepted time step [s]: MAX_STEP_FRACTION · τ_min."""
        return MAX_STEP_FRACTION * self.relaxation_time()

    def suggested_time_step(self) -> float:
        """A safe default [s]: SUGGESTED_STEP_FRACTION · τ_min. Check it with
        :func:`skygas.timestep.check_time_step`."""
        return SUGGESTED_STEP_FRACTION * self.relaxation_time()

    # -- drift ---------------------------------------------------------------------------------
    def set_uniform_drift(self, velocity) -> None:
        """Uniform spin-drift velocity v_s = (vx, vy) [m/s] (1 m/s = 1 nm/ns)."""
        v = np.asarray(velocity, dtype=float)
        require(v.shape == (2,) and np.all(np.isfinite(v)), "drift_velocity", velocity,
                "two finite numbers (vx, vy) in m/s")
        self._fp[K.FP_VS_X], self._fp[K.FP_VS_Y] = v
        self._ip[K.IP_DRIFT_GRID] = 0
        if self._fp[K.FP_SKIN] > 0:  # constructed: the cells follow the drift
            self._configure_neighbor_cells()

    def set_drift_field(self, vx: np.ndarray, vy: np.ndarray) -> None:
        """Spatial v_s [m/s] sampled on ``self.wall_field.grid`` (arrays of shape (ny, nx))."""
        shape = (self.wall_field.grid.ny, self.wall_field.grid.nx)
        for name, arr in (("vx", vx), ("vy", vy)):
            require(np.shape(arr) == shape and np.all(np.isfinite(arr)), f"drift_field.{name}",
                    np.shape(arr), f"a finite array of shape {shape} (the wall-field grid)")
        self._fields[..., K.CH_DRIFT_X] = vx
        self._fields[..., K.CH_DRIFT_Y] = vy
        vx, vy = np.asarray(vx, dtype=float), np.asarray(vy, dtype=float)
        self._grid_drift_max = math.sqrt(float(np.max(vx * vx + vy * vy)))
        self._ip[K.IP_DRIFT_GRID] = 1
        self._configure_neighbor_cells()

    # -- skyrmions -----------------------------------------------------------------------------
    @property
    def time(self) -> float:
        """Simulated time [s]."""
        return self.step * self.time_step

    @property
    def count(self) -> int:
        """Number of skyrmions present."""
        return int(self._alive.sum())

    @property
    def ids_issued(self) -> int:
        """Number of skyrmions created so far (ids are 0, 1, … in order of creation)."""
        return self._next_id

    def positions(self) -> tuple[np.ndarray, np.ndarray]:
        """(ids, positions [m] of shape (n, 2)) of the skyrmions present, ordered by id."""
        alive = self._alive
        return _by_id(self._ids[alive], self._x[alive], self._y[alive])

    def _grow(self, needed: int) -> None:
        cap = len(self._x)
        if needed <= cap:
            return
        new = max(needed, 2 * cap)
        for name, fill in (("_x", 0.0), ("_y", 0.0), ("_alive", False), ("_ids", -1)):
            old = getattr(self, name)
            arr = np.full(new, fill, dtype=old.dtype)
            arr[:cap] = old
            setattr(self, name, arr)

    def validate_positions(self, positions_nm: np.ndarray, field_name: str = "skyrmions",
                           check_existing: bool = True) -> None:
        """Refuse positions outside the device or on top of another skyrmion."""
        p = np.asarray(positions_nm, dtype=float).reshape(-1, 2)
        inside = self.outline.contains_nm(p[:, 0], p[:, 1])
        for n in np.nonzero(~inside | ~np.all(np.isfinite(p), axis=1))[0]:
            raise InputError(f"{field_name}[{n}]", (p[n] / units.M_TO_NM).tolist(),
                             "a position (m) inside the device outline")
        min_sep = MIN_PLACEMENT_SEPARATION * self.thiele.skyrmion_diameter_internal
        others = np.column_stack([self._x[self._alive], self._y[self._alive]]) \
            if check_existing else np.empty((0, 2))
        for n in range(len(p)):
            ref = np.vstack([p[:n], others])
            if len(ref) and np.min(np.hypot(*(ref - p[n]).T)) < min_sep:
                raise InputError(f"{field_name}[{n}]", (p[n] / units.M_TO_NM).tolist(),
                                 f"a position at least {min_sep * 1e-9:.3g} m "
                                 f"({MIN_PLACEMENT_SEPARATION} diameters) from other skyrmions")

    def add_skyrmions(self, positions, *, validate: bool = True) -> np.ndarray:
        """Insert skyrmions at ``positions`` [m] (shape (n, 2)); returns their new ids."""
        p = np.asarray(positions, dtype=float).reshape(-1, 2) * units.M_TO_NM
        if validate:
            self.validate_positions(p)
        return self._insert_nm(p)

    def _insert_nm(self, p: np.ndarray) -> np.ndarray:
        if len(p) == 1:  # the common case of an injector: one skyrmion into the first free slot
            slot = int(np.argmin(self._alive))
            if not self._alive[slot]:
                ident = self._next_id
                self._next_id += 1
                self._x[slot], self._y[slot] = p[0]
                self._alive[slot] = True
                self._ids[slot] = ident
                return np.array([ident], dtype=np.int64)
        free = np.nonzero(~self._alive)[0]
        if len(free) < len(p):
            self._grow(len(self._x) + len(p) - len(free))
            free = np.nonzero(~self._alive)[0]
        slots = free[: len(p)]
        new_ids = np.arange(self._next_id, self._next_id + len(p), dtype=np.int64)
        self._next_id += len(p)
        self._x[slots], self._y[slots] = p[:, 0], p[:, 1]
        self._alive[slots] = True
        self._ids[slots] = new_ids
        return new_ids

    def remove_skyrmions(self, ids) -> None:
        """Remove the skyrmions with the given ids (unknown ids raise)."""
        for ident in np.atleast_1d(ids):
            slot = np.nonzero(self._alive & (self._ids == ident))[0]
            require(len(slot) == 1, "skyrmion id", int(ident), "the id of a present skyrmion")
            self._alive[slot] = False

    # -- running -------------------------------------------------------------------------------
    def run(self, duration: float, record_interval: float | None = None,
            progress: Callable[[float], None] | None = None, chunk_steps: int = 20_000) -> None:
        """Advance by ``duration`` [s], recording positions every ``record_interval`` [s].

        Operations in :attr:`operations` act at the steps they ask for (see
        :class:`Operation`). ``progress(t)`` is called with the simulated time after each chunk.
        """
        require(np.isfinite(duration) and duration >= 0, "duration", duration,
                "a duration >= 0 in seconds")
        n_total = int(round(duration / self.time_step))
        record_every = 0
        if record_interval is not None:
            require(record_interval >= self.time_step, "record_interval", record_interval,
                    f"an interval >= the time step ({self.time_step:.3g} s)")
            record_every = max(1, int(round(record_interval / self.time_step)))
        end = self.step + n_total
        while self.step < end:
            due = [op.next_step(self.step) for op in self.operations]
            planner, plan = self._plan(due, min(end, self.step + chunk_steps))
            target = max(self.step, min([end, self.step + chunk_steps, *due]))
            self._planned_done = 0
            if target > self.step:
                self._advance(target - self.step, record_every, plan)
            if planner is not None:  # the index of the planning operation
                op = self.operations[planner]
                op.planned_insertions_made(self, plan[3][:self._planned_done])
                due[planner] = op.next_step(self.step)
            for op, when in zip(self.operations, due):
                if when <= self.step:
                    op.act(self)
            if progress is not None:
                progress(self.time)

    def _plan(self, due: list[int], horizon: int):
        """The first operation able to plan its insertions up to the next stop, and its plan
        (steps, x [nm], y [nm], ids out, clearance² [nm²]); ``due`` is updated so that the
        planner's own schedule does not stop the kernel. (None, None) if there is none."""
        for k, op in enumerate(self.operations):
            if due[k] <= self.step or not hasattr(op, "plan_insertions"):
                continue
            limit = min([horizon, *(d for j, d in enumerate(due) if j != k)])
            if limit <= self.step:
                return None, None
            planned = op.plan_insertions(self.step, limit)
            if planned is None:
                continue
            steps, pos, clearance = planned
            due[k] = limit
            plan = (np.asarray(steps, np.int64), np.ascontiguousarray(pos[:, 0], float),
                    np.ascontiguousarray(pos[:, 1], float), np.empty(len(steps), np.int64),
                    float(clearance) ** 2)
            return k, plan
        return None, None

    def _buffers(self, cap: int, exits: int) -> dict:
        """Per-call work arrays, reused while they are large enough (the reshuffler makes
        ~10⁴ kernel calls; allocating them each time would cost more than short calls).
        ``cap`` is the storage capacity, ``exits`` the most exits the call can record."""
        buf = getattr(self, "_buf", None)
        if buf is None or buf["no_frames"].shape[1] != cap:
            buf = self._buf = {
                "stats": np.zeros(K.ST_SIZE, dtype=np.int64),
                "no_frames": np.empty((1, cap)),
                "no_frame_ids": np.empty((1, cap), dtype=np.int64),
                "no_plan": (np.empty(0, np.int64), np.empty(0), np.empty(0),
                            np.empty(0, np.int64), 0.0),
            }
        if "exit_id" not in buf or len(buf["exit_id"]) < exits:
            size = max(exits, 2 * len(buf.get("exit_id", ())), 1)
            buf.update({"exit_id": np.empty(size, dtype=np.int64),
                        "exit_step": np.empty(size, dtype=np.int64),
                        "exit_port": np.empty(size, dtype=np.int64),
                        "exit_x": np.empty(size), "exit_y": np.empty(size)})
        return buf

    def _sort_spatially(self) -> None:
        """Store skyrmions in row-major order of the neighbour cells they sit in, packed at the
        front of the arrays. Neighbours then sit close in memory and consecutive skyrmions read
        nearby rows of the field grid, which keeps large systems in cache. Slots carry no
        meaning (noise is keyed on ids); only the order in which pair forces are summed
        changes, which moves results by floating-point rounding. Runs stay bit-reproducible."""
        slots = np.flatnonzero(self._alive)
        size = self._fp[K.FP_CELL_SIZE]
        cx = ((self._x[slots] - self._fp[K.FP_CELL_X0]) // size).astype(np.int64)
        cy = ((self._y[slots] - self._fp[K.FP_CELL_Y0]) // size).astype(np.int64)
        order = slots[np.lexsort((cx, cy))]
        n = len(order)
        for name in ("_x", "_y", "_ids"):
            arr = getattr(self, name)
            arr[:n] = arr[order]
        self._alive[:] = False
        self._alive[:n] = True
        self._ids[n:] = -1

    def _advance(self, n_steps: int, record_every: int, plan=None) -> None:
        occupied = np.flatnonzero(self._alive)
        if len(occupied) > SORT_ABOVE:
            self._sort_spatially()
            occupied = np.arange(len(occupied))
        # The kernel sees the slots up to the last occupied one: new skyrmions fill the lowest
        # free slot, so this range stays compact and loops skip the empty tail of the arrays.
        # Planned insertions get a few free slots more (the kernel stops if it runs out).
        used = int(occupied[-1]) + 1 if len(occupied) else 0
        if plan is not None and len(plan[0]):
            if len(self._x) < used + PLAN_SLOTS:
                self._grow(used + PLAN_SLOTS)
            used += PLAN_SLOTS
        else:
            plan = None
        # Each exit removes a skyrmion present at the start of the call or inserted during it.
        buf = self._buffers(len(self._x), used + (len(plan[0]) if plan is not None else 0))
        # frames fall on the global steps that are multiples of record_every
        n_frames = ((self.step + n_steps) // record_every - self.step // record_every
                    if record_every else 0)
        if n_frames:
            frames_x = np.empty((n_frames, used))
            frames_y = np.empty((n_frames, used))
            frames_id = np.empty((n_frames, used), dtype=np.int64)
        else:
            frames_x = frames_y = buf["no_frames"]
            frames_id = buf["no_frame_ids"]
        stats = buf["stats"]
        stats[:] = 0
        stats[K.ST_NEXT_ID] = self._next_id
        self._ip[K.IP_RECORD_EVERY] = record_every
        n_exit = K.advance(
            self._x[:used], self._y[:used], self._alive[:used], self._ids[:used], self.step,
            n_steps, self._fp, self._ip, self.forces.pair.values, self.forces.wall.values,
            self._fields, self._ports, frames_x, frames_y, frames_id, buf["exit_id"],
            buf["exit_step"], buf["exit_port"], buf["exit_x"], buf["exit_y"],
            *(plan or buf["no_plan"]), stats)
        n_steps = int(stats[K.ST_STEPS])
        self._planned_done = int(stats[K.ST_INSERTED])
        self._next_id = int(stats[K.ST_NEXT_ID])
        if n_exit:
            self.exits.append(buf["exit_id"][:n_exit], buf["exit_step"][:n_exit] * self.time_step,
                              buf["exit_port"][:n_exit], buf["exit_x"][:n_exit] / units.M_TO_NM,
                              buf["exit_y"][:n_exit] / units.M_TO_NM)
        recorded = int(stats[K.ST_FRAMES])  # fewer than n_frames if the call stopped early
        if recorded:
            first = (self.step // record_every + 1) * record_every
            steps = first + record_every * np.arange(recorded, dtype=np.int64)
            self._frame_blocks.append(FrameBlock(steps, steps * self.time_step,
                                                 frames_x[:recorded], frames_y[:recorded],
                                                 frames_id[:recorded]))
        self.step += n_steps
        self.wall_escapes += int(stats[K.ST_WALL_ESCAPES])
        self.pair_evaluations += int(stats[K.ST_PAIRS])
        self.neighbor_rebuilds += int(stats[K.ST_REBUILDS])

    # -- checkpoints ---------------------------------------------------------------------------
    def state_dict(self) -> dict[str, np.ndarray]:
        """The mutable state as plain arrays (positions in nm). With the same construction
        arguments, :meth:`load_state_dict` continues the run bit-identically, because the noise
        depends only on (seed, id, step)."""
        ds = self.trajectories()
        return {
            "x": self._x.copy(), "y": self._y.copy(), "alive": self._alive.copy(),
            "ids": self._ids.copy(),
            "counters": np.array([self._next_id, self.step, self.wall_escapes,
                                  self.pair_evaluations], dtype=np.int64),
            "frame_time": ds.time.values, "frame_x": ds.x.values, "frame_y": ds.y.values,
            "frame_ids": ds.skyrmion.values,
            "exit_skyrmion": ds.exit_skyrmion.values, "exit_time": ds.exit_time.values,
            "exit_port": ds.exit_port.values.astype(str),
            "exit_x": self.exits.arrays()["x"].copy(), "exit_y": self.exits.arrays()["y"].copy(),
        }

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        """Restore a state saved by :meth:`state_dict`."""
        self._x, self._y = state["x"].copy(), state["y"].copy()
        self._alive, self._ids = state["alive"].copy(), state["ids"].copy()
        self._next_id, self.step, self.wall_escapes, self.pair_evaluations = \
            (int(v) for v in state["counters"])
        self._frame_blocks = []
        times = state["frame_time"]
        if len(times):
            fx, fy = state["frame_x"] * units.M_TO_NM, state["frame_y"] * units.M_TO_NM
            columns = state.get("frame_ids", np.arange(fx.shape[1], dtype=np.int64))
            ids = np.where(np.isfinite(fx), np.asarray(columns, dtype=np.int64), -1)
            steps = np.rint(times / self.time_step).astype(np.int64)
            self._frame_blocks.append(FrameBlock(steps, times, fx, fy, ids))
        self.exits = ExitLog.from_arrays(self.outline.ports, state["exit_skyrmion"],
                                         state["exit_time"], state["exit_port"],
                                         state["exit_x"], state["exit_y"])

    # -- results -------------------------------------------------------------------------------
    def parameters(self) -> dict:
        """Every parameter needed to reproduce the run (JSON-able, SI units)."""
        return {
            "skygas_version": __version__,
            "seed": self.seed,
            "temperature_K": self.temperature,
            "time_step_s": self.time_step,
            "integrator": self.integrator,
            "brownian_substeps": int(self._ip[K.IP_SUBSTEPS]),
            "material": self.material.model_dump(mode="json"),
            "thiele": self.thiele.as_record(),
            "pair_law": self.forces.pair_law,
            "pair_law_params": self.forces.pair_law_params,
            "cutoff_fraction": self.forces.cutoff_fraction,
            "pair_cutoff_m": self.forces.pair.cutoff / units.M_TO_NM,
            "wall_cutoff_m": self.forces.wall.cutoff / units.M_TO_NM,
            "grid_spacing_m": self.wall_field.grid.spacing / units.M_TO_NM,
            "drift": ("field" if self._ip[K.IP_DRIFT_GRID] else
                      [self._fp[K.FP_VS_X], self._fp[K.FP_VS_Y]]),
            "geometry": self.outline.describe(),
        }

    @property
    def frame_blocks(self) -> tuple[FrameBlock, ...]:
        """The recorded frames, one :class:`FrameBlock` per kernel call, in time order."""
        return tuple(self._frame_blocks)

    def take_frames(self, first_block: int = 0) -> list[FrameBlock]:
        """Remove and return the frame blocks from index ``first_block`` on (a long run that
        keeps its own sparse record of positions takes them after each piece, so that the
        simulation does not hold them all)."""
        taken = self._frame_blocks[first_block:]
        del self._frame_blocks[first_block:]
        return taken

    def trajectories(self) -> xr.Dataset:
        """Recorded positions as a Dataset: ``x``, ``y`` [m] with dims (time, skyrmion), NaN
        where a skyrmion does not exist, ``time`` [s]; the ``skyrmion`` coordinate holds the
        ids of the skyrmions present in at least one frame. Exits as variables on dim
        ``exit``; attributes hold every parameter (``parameters_json``), the seed and the
        version."""
        blocks = self._frame_blocks
        times = np.concatenate([b.time for b in blocks]) if blocks else np.empty(0)
        # one column per skyrmion seen in a frame (a run that nucleates 10⁵ skyrmions but
        # records only its first microsecond has a few hundred)
        seen = np.unique(np.concatenate([b.ids[b.ids >= 0] for b in blocks])) if blocks \
            else np.empty(0, dtype=np.int64)
        x = np.full((len(times), len(seen)), np.nan)
        y = np.full((len(times), len(seen)), np.nan)
        row = 0
        for block in blocks:
            frame, slot = np.nonzero(block.ids >= 0)
            column = np.searchsorted(seen, block.ids[frame, slot])
            x[row + frame, column] = block.x[frame, slot] / units.M_TO_NM
            y[row + frame, column] = block.y[frame, slot] / units.M_TO_NM
            row += len(block.time)
        ex = self.exits.arrays()
        # imported here: a run that records no trajectory (a sweep's worker) never needs it
        import xarray as xr

        ds = xr.Dataset(
            {
                "x": (("time", "skyrmion"), x, {"units": "m", "long_name": "x position"}),
                "y": (("time", "skyrmion"), y, {"units": "m", "long_name": "y position"}),
                "exit_skyrmion": ("exit", ex["skyrmion"].copy()),
                "exit_time": ("exit", ex["time"].copy(), {"units": "s"}),
                "exit_port": ("exit", self.exits.port_labels()),
            },
            coords={"time": ("time", times, {"units": "s"}),
                    "skyrmion": seen.astype(np.int64)},
        )
        params = self.parameters()
        ds.attrs.update({
            "title": "skygas skyrmion trajectories",
            "skygas_version": __version__,
            "seed": self.seed,
            "temperature_K": self.temperature,
            "time_step_s": self.time_step,
            "simulated_time_s": self.time,
            "wall_escapes": self.wall_escapes,
            "parameters_json": json.dumps(params),
        })
        return ds
