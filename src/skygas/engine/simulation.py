"""The :class:`Simulation` façade: one run of a skyrmion gas in a device outline.

It owns the parts that each do one job and wires them together:

- the parameters: Thiele coefficients, the tabulated force laws (:class:`ForceModel`) and the
  kernel's typed records (:mod:`skygas.engine.terms`);
- the skyrmion store (:class:`~skygas.engine.store.SkyrmionStore`) and its public view
  ``sim.state`` (:class:`~skygas.engine.state.StateView`);
- the operations and their planning (:mod:`skygas.engine.scheduler`);
- the recorder of frames and exits (:class:`~skygas.engine.recorder.Recorder`).
"""

from __future__ import annotations

import dataclasses
import math
import sys
import warnings
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from skygas._version import __version__
from skygas.core import estimates, units
from skygas.core.errors import InputError, require
from skygas.core.memo import Memo, frozen
from skygas.core.resources import require_memory
from skygas.core.state_keys import from_arrays, nest, to_arrays, unnest
from skygas.engine import terms as T
from skygas.engine.force_model import (
    MAX_STEP_FRACTION,
    MIN_PLACEMENT_SEPARATION,
    ForceModel,
    default_time_step,
    law_stiffness,
    relaxation_time,
    suggested_time_step,
    whole_steps,
)
from skygas.engine.kernel import DirectCall, Frames, advance
from skygas.engine.recorder import FrameBlock, Recorder
from skygas.engine.scheduler import NO_PLAN, Operation, first_plan, named_operations
from skygas.engine.state import StateView
from skygas.engine.store import SkyrmionStore
from skygas.engine.term_rules import (
    Breathing,
    ConstantForce,
    CurrentDrift,
    Landscape,
    PairLaw,
    TermRules,
    WallLaw,
)
from skygas.fields._field_lookup import empty_fields
from skygas.fields.landscape import EdgeStrayField, LandscapeField, parse_potentials
from skygas.fields.wall_field import WallField
from skygas.physics.forces import DEFAULT_CUTOFF_FRACTION
from skygas.physics.geometry import Outline
from skygas.physics.materials import (
    Material,
    ThieleParameters,
    derive_thiele,
    load_material,
    resolve_film_thickness,
)

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

#: Neighbour-list skin in skyrmion diameters (the list is rebuilt after a skyrmion moves
#: half of it; larger skins rebuild less often but carry more pairs beyond the cutoff). At
#: 300 K a skyrmion of S2 diffuses ~1 nm per suggested step: with 0.25 the list of 100
#: skyrmions was rebuilt every 3 steps, with 1.0 every 25, and the step was 15-20 % faster
#: (benchmarks/bench_engine.py, 100 and 1000 skyrmions).
NEIGHBOR_SKIN = 1.0
#: The most skyrmion diameters one term may move a free skyrmion in one step: beyond it a
#: skyrmion jumps over its neighbours' range and through walls, and the integration means
#: nothing (the sanity check of a run warns from half of it, docs/physics.md §5).
MAX_STEP_DIAMETERS = 1.0
#: The largest share of skyrmion-steps that may be undone at a wall: the wall law is a force,
#: and when a drive or the step overpowers it, the undone steps leave skyrmions frozen at the
#: wall (a 300 m/s drift in a 500 nm disk: 99.9 % undone, no thermal motion left; a model
#: inferred from pinned pairs, checked on its own coarse step: 1.5 %).
MAX_UNDONE_SHARE = 0.1
#: Skyrmion-steps of one call of run() before its share of undone steps is judged.
MIN_STEPS_TO_JUDGE_UNDONE = 10_000

#: A skyrmion that drifts fast gets a wider margin in the neighbour list, room for this many
#: steps of its motion (a current pushes skyrmions along a conduit by several nm per step,
#: which would otherwise force a rebuild at every step) ...
NEIGHBOR_MARGIN_STEPS = 8.0
#: ... up to this many skyrmion diameters (wider margins make larger cells and longer lists).
NEIGHBOR_MARGIN_MAX = 1.25

INTEGRATORS = {"heun": 0, "euler-maruyama": 1}
#: The layers of a breathing model's wall film (``wall_geometry = "film"``) are this many
#: isolated radii apart in the erosion δ: for a law that decays as e^{−w/λ} with λ = 0.35 R₀
#: (a calibrated film's shortest, at its closest measured distance) the Catmull–Rom rule
#: between them errs by at most 5·10⁻⁵ of U.
WALL_FILM_LAYER_STEP = 0.05
#: Free slots beyond the last occupied one that a kernel call with planned insertions sees.
PLAN_SLOTS = 4
#: Index of each kernel counter in the counters read as plain integers.
COUNT = {name: k for k, name in enumerate(T.COUNTERS.names or ())}
#: Systems with more skyrmions than this are sorted spatially before each kernel call.
SORT_ABOVE = 256

# The wall channels of the kernels' packed grid, per wall field (WallField.key; see
# skygas.core.memo): each run of a device copies them instead of re-packing four float64 fields.
_WALL_CHANNELS = Memo("wall_channels", maxsize=4)


def _packed_wall_channels(wall_field: WallField) -> np.ndarray:
    """The packed float32 grid with the wall channels filled in and no drift (read-only).

    See :func:`~skygas.fields._field_lookup.empty_fields`.
    """
    packed = empty_fields(wall_field.grid.ny, wall_field.grid.nx)
    packed[..., T.CH_WALL_DIST] = wall_field.wall_distance
    packed[..., T.CH_NORMAL_X] = wall_field.normal_x
    packed[..., T.CH_NORMAL_Y] = wall_field.normal_y
    packed[..., T.CH_DOMAIN] = wall_field.domain_distance
    frozen(packed)
    return packed


class Simulation:
    """A skyrmion gas in a device outline.

    Operations (:attr:`operations`) act on the run at the steps they ask for and read and
    change skyrmions through :attr:`state`. :attr:`edge_stray_field` is the stray-field term
    the material added to the landscape (its last term), or ``None``. The equation of motion
    is docs/physics.md §1.

    Parameters
    ----------
    outline : Outline
        The device (:mod:`skygas.physics.geometry`).
    material : Material or str
        A :class:`~skygas.physics.materials.Material`, a preset name or a TOML path.
    temperature : float
        T [K] (0 for deterministic dynamics).
    time_step : float, optional
        dt [s]; refused above :meth:`max_time_step`; ``None`` takes
        :meth:`suggested_time_step`.
    seed : int
        A non-negative integer; with the same seed a run is bit-identical.
    film_thickness : float, optional
        t_F [m]; ``None``: the material's own (a calibrated model, which refuses any other),
        else 2 nm as in the paper.
    thiele : ThieleParameters, optional
        Explicit Thiele parameters (otherwise derived from the material and film).
    drift_velocity : (float, float)
        A uniform spin-drift velocity v_s [m/s] (x, y).
    pair_law : str, optional
        ``"paper"``, ``"lin-reichhardt"`` or ``"table"`` (the material's ``pair_table``);
        ``None``: the material's own, ``"table"`` when it has the table, else ``"paper"``
        (:func:`~skygas.engine.force_model.resolve_law_names`).
    pair_law_params : dict, optional
        The pair law's parameters (:mod:`skygas.physics.forces`).
    cutoff_fraction : float
        The force, as a fraction of F₀, below which the laws are cut off
        (:mod:`skygas.physics.forces`).
    grid_spacing : float, optional
        The wall-field grid spacing [m] (default d_sk/16).
    integrator : str
        ``"heun"`` (default) or ``"euler-maruyama"`` (for comparison only).
    brownian_substeps : int
        Draw each step's noise as the sum of this many sub-increments, so that runs with steps
        dt and dt/m share one Brownian path (strong-convergence studies).
    capacity : int
        The initial room in the store (it grows on demand).
    landscape : sequence
        External potentials (:mod:`skygas.fields.landscape`: objects or their TOML tables),
        added up on the field grid; their force −∇U enters like the pair and wall forces.
    wall_law : str, optional
        ``"paper"`` or ``"table"`` (the material's ``wall_table``); ``None`` as for
        ``pair_law``. With the table wall law, a material with a ``stray_field`` profile also
        gets the edge stray-field energy as a landscape term
        (:class:`~skygas.fields.landscape.kinds.EdgeStrayField`, docs/physics.md §2).
    step_interval : float, optional
        With ``time_step=None``, the suggested step is shortened so that this interval [s] (a
        recording or injection interval) is a whole number of steps
        (:func:`~skygas.engine.force_model.default_time_step`).
    external_force : (float, float)
        A uniform force (F_x, F_y) [N] on every skyrmion, e.g. of a field gradient
        (:class:`~skygas.engine.term_rules.ConstantForce`).
    particle_model : str, optional
        ``"rigid"`` or ``"breathing"`` (each skyrmion's radius a degree of freedom, for a
        material with a ``breathing`` table: :class:`~skygas.physics.materials.BreathingSpec`);
        ``None``: the material's own ``particle_model``.
    wall_geometry : str, optional
        ``"nearest"`` (the wall law along the nearest wall's normal) or ``"film"`` (the law as
        the missing film's field, every edge within reach:
        :mod:`skygas.fields.landscape.wall_film`); ``None``: the material's own.
    """

    def __init__(
        self,
        outline: Outline,
        material: Material | str = "S2",
        *,
        temperature: float = 300.0,
        time_step: float | None = None,
        seed: int = 0,
        film_thickness: float | None = None,
        thiele: ThieleParameters | None = None,
        drift_velocity=(0.0, 0.0),
        pair_law: str | None = None,
        pair_law_params: dict | None = None,
        cutoff_fraction: float = DEFAULT_CUTOFF_FRACTION,
        grid_spacing: float | None = None,
        integrator: str = "heun",
        brownian_substeps: int = 1,
        capacity: int = 64,
        landscape=(),
        wall_law: str | None = None,
        step_interval: float | None = None,
        external_force=(0.0, 0.0),
        particle_model: str | None = None,
        wall_geometry: str | None = None,
    ):
        require(isinstance(outline, Outline), "geometry", outline, "a skygas Outline")
        require(
            np.isfinite(temperature), "temperature", temperature, "a finite number (not inf or nan)"
        )
        require(temperature >= 0, "temperature", temperature, "a temperature >= 0 in kelvin")
        require(
            isinstance(seed, (int, np.integer)) and 0 <= seed < 2**63,
            "seed",
            seed,
            "an integer in [0, 2^63)",
        )
        require(integrator in INTEGRATORS, "integrator", integrator, f"one of {list(INTEGRATORS)}")
        require(
            isinstance(brownian_substeps, (int, np.integer)) and brownian_substeps >= 1,
            "brownian_substeps",
            brownian_substeps,
            "an integer >= 1",
        )
        force = np.asarray(external_force, dtype=float)  # checked as set_uniform_drift checks
        require(
            bool(force.shape == (2,) and np.all(np.isfinite(force))),
            "external_force",
            external_force,
            "two finite numbers [N], (F_x, F_y)",
        )
        self.outline = outline
        self.material = load_material(material)
        if thiele is not None:  # a calibrated model holds for its own film only
            resolve_film_thickness(self.material, thiele.film_thickness, "thiele.film_thickness")
        self.thiele = thiele or derive_thiele(self.material, film_thickness)
        self.temperature = float(temperature)
        self.seed = int(seed)
        self.integrator = integrator
        self.brownian_substeps = int(brownian_substeps)
        model = self._particle_model(particle_model)
        self.forces = ForceModel.build(
            # a breathing model reads its laws at the gap between domain walls
            self.material.breathing_laws() if model == "breathing" else self.material,
            self.thiele,
            pair_law,
            pair_law_params,
            cutoff_fraction,
            wall_law_name=wall_law,
        )
        d_sk = self.thiele.skyrmion_diameter_internal
        spacing = d_sk / 16 if grid_spacing is None else grid_spacing * units.M_TO_NM
        require(
            spacing > 0 and spacing <= d_sk,
            "grid_spacing",
            grid_spacing,
            f"a spacing in (0, {d_sk * 1e-9:.3g}] m (at most one skyrmion diameter)",
        )
        self._breathing_rules = self._build_breathing(model)
        band = self.forces.wall.cutoff + self._breathing_rules.wall_reach + 2 * spacing
        self.wall_field = WallField.build(outline, spacing, band)
        self.wall_film = self._build_wall_film(wall_geometry)
        self.landscape = self._build_landscape(parse_potentials(landscape))
        if self._breathing_rules.active and self.edge_stray_field is not None:
            # the radius feels the edges' stray field: U_s alone, scaled by a(R) in the kernel
            grid_ = self.wall_field.grid
            stray = T.LandscapeTerm(
                self.landscape.term_coefficients(self.landscape.terms.index(self.edge_stray_field)),
                grid_.x0,
                grid_.y0,
                grid_.spacing,
                True,
            )
            self._breathing_rules = dataclasses.replace(self._breathing_rules, stray=stray)
        # each force term's rules (:mod:`skygas.engine.term_rules`); the drift's are replaced
        # whenever the drift changes (set_uniform_drift, set_drift_field)
        closest = MIN_PLACEMENT_SEPARATION * d_sk
        f = self.forces
        self._pair_rules = PairLaw(
            f.pair_law, f.pair, f.pair_law_params, f.cutoff_fraction, closest
        )
        self._wall_rules = WallLaw(
            f.wall_law, f.wall, closest, "nearest" if self.wall_film is None else "film"
        )
        self._drift_rules = CurrentDrift(T.drift_term(self.thiele))
        # the landscape's curvature counts in the suggested step when the material's stray
        # field is in it; runs without it keep the step they always had
        self._landscape_rules = Landscape(self.landscape, self.edge_stray_field is not None)
        self._constant_rules = ConstantForce((float(force[0]), float(force[1])))
        limit = self.max_time_step()
        #: whether the step was chosen here (not given): :meth:`run` may then shorten it once,
        #: before the first step, so that the record interval is a whole number of steps
        self._step_chosen = time_step is None
        if time_step is None and step_interval is not None:
            require(
                np.isfinite(step_interval) and step_interval > 0,
                "step_interval",
                step_interval,
                "an interval > 0 in seconds",
            )
            stiffness = self._breathing_rules.mobility_gain * max(
                t.stiffness()
                for t in self.term_rules
                if not (isinstance(t, Landscape) and not t.time_step_counts)
            )
            time_step = default_time_step(self.thiele, stiffness, step_interval, self.temperature)
        if time_step is None:
            time_step = self.suggested_time_step()
        require(
            np.isfinite(time_step) and 0 < time_step <= limit,
            "time_step",
            time_step,
            f"a step in (0, {limit:.3g}] s: longer steps do not resolve the fastest force "
            f"relaxation τ_min = {limit:.3g} s (suggested ≤ {self.suggested_time_step():.3g} s)",
        )
        self.time_step = float(time_step)

        # -- the parts ------------------------------------------------------------------------
        self.store = SkyrmionStore(
            capacity, self.material.skyrmion_radius * units.M_TO_NM, self._breathing_rules.active
        )
        self.recorder = Recorder(outline.ports)
        self.operations: list[Operation] = []
        self.state = StateView(self)
        self.step = 0
        self.wall_escapes = 0
        #: the (terms, step) that check_integrable last accepted
        self._integrable_checked: tuple | None = None
        #: steps of one skyrmion taken, summed over the skyrmions (what wall escapes are
        #: counted against)
        self.skyrmion_steps = 0
        self.pair_evaluations = 0
        self.neighbor_rebuilds = 0
        #: radius steps of a breathing model reflected back into its table's range
        self.radius_reflections = 0

        # -- the kernel's records -------------------------------------------------------------
        self._dt_ns = self.time_step * units.S_TO_NS
        self._mobility = T.mobility(self.thiele)
        self._noise = T.noise_term(
            self.thiele, self.temperature, self._dt_ns, self.seed, self.brownian_substeps
        )
        # Every per-node field in one interleaved float32 array: a bilinear lookup then reads
        # four 32-byte nodes (one vector load each, skygas.fields._field_lookup) instead of twenty
        # scattered values.
        grid = self.wall_field.grid
        fields = empty_fields(grid.ny, grid.nx)
        fields[...] = _WALL_CHANNELS.get(
            WallField.key(outline, spacing, band), lambda: _packed_wall_channels(self.wall_field)
        )
        self._terms = T.ForceTerms(
            self._pair_rules.record(),
            self._wall_rules.record(),
            self._drift_rules.record(),
            self._landscape_rules.record(),
            T.field_grid(fields, grid),
            self._constant_rules.record(),
            self._breathing_rules.record(),
            T.NO_WALL_FILM if self.wall_film is None else T.wall_film_term(self.wall_film, grid),
        )
        ports = list(outline.ports.values())
        self._ports = np.array([[*p.coords[0], *p.coords[-1]] for p in ports]).reshape(-1, 4)
        self._counters = np.zeros(1, T.COUNTERS)
        # the same counters as plain integers: reading a record's fields one by one costs more
        # than a small device's step
        self._counts = self._counters.view(np.int64)
        self._advance_call = DirectCall(advance)
        self._neighbor_cells: T.NeighborCells | None = None  # set by set_uniform_drift
        self.set_uniform_drift(drift_velocity)

    def _particle_model(self, particle_model: str | None) -> str:
        """``"rigid"`` or ``"breathing"``: the one asked for, or the material's own."""
        material = self.material
        model = material.particle_model if particle_model is None else particle_model
        require(
            model in ("rigid", "breathing"),
            "particle_model",
            particle_model,
            "'rigid' or 'breathing' (or leave it out for the material's own)",
        )
        require(
            model == "rigid" or material.breathing is not None,
            "particle_model",
            model,
            f"'rigid': the material '{material.name}' has no [breathing] table (radius, energy)",
        )
        return model

    def _build_breathing(self, model: str) -> Breathing:
        """The radius's rules: a breathing model's, or rigid skyrmions' (``Breathing()``)."""
        material = self.material
        if model == "rigid":
            return Breathing()
        spec = material.breathing
        assert spec is not None
        r0 = material.skyrmion_radius
        require(
            spec.radius[0] <= r0 <= spec.radius[-1],
            "breathing.radius",
            [spec.radius[0], spec.radius[-1]],
            f"a range that spans the material's skyrmion_radius {r0:g} m",
        )
        dissipation = spec.radius_dissipation
        if dissipation is None:  # thin-wall estimate: ∂_R m lives in the wall, ∫ = 2πR·2/Δ
            width = material.wall_width or math.sqrt(
                material.exchange_stiffness / material.anisotropy
            )
            dissipation = 4.0 * math.pi * r0 / width
        closest = MIN_PLACEMENT_SEPARATION * self.thiele.skyrmion_diameter_internal
        thiele = self.thiele
        return Breathing(
            spec,
            r0,
            float(dissipation),
            thiele.k,
            thiele.damping,
            self.temperature,
            0.5 * closest,  # the tables hold from a quarter diameter
            law_stiffness(self.forces.pair, self.forces.pair_law, closest),
            law_stiffness(self.forces.wall, self.forces.wall_law, closest),
            dissipation=thiele.dissipation,
            gyrocoupling=thiele.gyrocoupling,
        )

    def _build_wall_film(self, wall_geometry: str | None):
        """The wall law as the missing film's field (``"film"``), or ``None`` (``"nearest"``).

        Rigid skyrmions get one layer (δ = 0); breathing ones layers of erosion δ spanning
        s_w times their radius table's range, :data:`WALL_FILM_LAYER_STEP` radii apart.
        """
        geometry = self.material.wall_geometry if wall_geometry is None else wall_geometry
        require(
            geometry in ("nearest", "film"),
            "wall_geometry",
            wall_geometry,
            "'nearest' or 'film' (or leave it out for the material's own)",
        )
        if geometry == "nearest":
            return None
        from skygas.fields.landscape.wall_film import WallFilm, layer_deltas

        rules = self._breathing_rules
        deltas = np.zeros(1)
        if rules.active:
            r0 = self.material.skyrmion_radius * units.M_TO_NM
            shrink = r0 - rules.spec.radius[0] * units.M_TO_NM
            deltas = layer_deltas(
                float(rules.spec.wall_shift), rules.growth, shrink, WALL_FILM_LAYER_STEP * r0
            )
            if len(deltas) < 4:  # a wall blind to the radius (s_w = 0): four equal layers
                deltas = np.arange(-1.0, 3.0)
        grid = self.wall_field.grid
        require_memory(
            "wall_geometry",
            "film",
            len(deltas) * grid.nx * grid.ny * 64.0,
            f"{len(deltas)} layers of the wall law's film field on {grid.nx} x {grid.ny} cells",
            "use wall_geometry = 'nearest', or a coarser grid_spacing",
        )
        table = self.forces.wall
        return WallFilm(
            self.wall_field.wall_distance,
            grid.spacing,
            table.values,
            table.spacing,
            table.cutoff,
            deltas,
        )

    def _build_landscape(self, terms: list) -> LandscapeField:
        """The landscape of the user's ``terms``, plus a calibrated material's edge stray field.

        The stray field (docs/physics.md §2) is added when the material's tabulated wall law is
        used.

        Only then: the paper's wall law is a fit of the whole interaction with a straight
        edge, stray field included, so adding the stray field to it would count it twice.
        The tabulated wall law of a calibrated model is the short-range rest, measured with
        the stray field taken out.
        """
        stray = self.material.stray_field
        self.edge_stray_field = None
        if stray is not None and self.forces.wall_law == "table":
            for k, term in enumerate(terms):
                require(
                    not isinstance(term, EdgeStrayField),
                    f"potentials.{k}.kind",
                    term.kind,
                    f"another kind: the material '{self.material.name}' adds "
                    "its own edge stray field with the table wall law",
                )
            self.edge_stray_field = EdgeStrayField(
                saturation_magnetization=self.material.saturation_magnetization,
                thickness=self.thiele.film_thickness,
                profile_radius=stray.profile_radius,
                profile_deficit=stray.profile_deficit,
            )
            # appended last: the indices of the user's terms (a gate's band) stay as given
            terms = [*terms, self.edge_stray_field]
        inside = reachable = None
        if any(getattr(term, "needs_film", False) for term in terms):
            distance = self.wall_field.wall_distance  # nm, > 0 inside and beyond ports
            spacing = self.wall_field.grid.spacing
            # the film's share of each node's cell: exact for edges along grid lines, and it
            # smooths a curved outline's staircase
            inside = np.clip(0.5 + distance / spacing, 0.0, 1.0)
            closest = MIN_PLACEMENT_SEPARATION * self.thiele.skyrmion_diameter_internal
            reachable = distance >= closest
        return LandscapeField(
            terms,
            self.wall_field.grid,
            self.temperature,
            self.seed,
            inside=inside,
            reachable=reachable,
        )

    def _configure_neighbor_cells(self) -> None:
        """Largest neighbour-list margin and the cell list that goes with it.

        The margin cap covers NEIGHBOR_MARGIN_STEPS steps of the fastest free drift the
        current field can cause (at most NEIGHBOR_MARGIN_MAX diameters); without a drift it is
        the base half-skin. Cells are no smaller than cutoff + 2·cap and cover the field grid
        (skyrmions outside it are clamped into edge cells). Called whenever the drift changes.
        """
        # the fastest a free skyrmion moves: the terms' speed bounds added up (the drift's and
        # a constant force's; the laws and the landscape move no free skyrmion)
        speed = sum(t.speed_bound(self._mobility) for t in self.term_rules)
        skin = NEIGHBOR_SKIN * self.thiele.skyrmion_diameter_internal
        base = 0.5 * skin
        cap = NEIGHBOR_MARGIN_MAX * self.thiele.skyrmion_diameter_internal
        margin_max = max(base, min(base + NEIGHBOR_MARGIN_STEPS * self._dt_ns * speed, cap))
        reach = self.forces.pair.cutoff + self._terms.breathing.pair_reach + 2.0 * margin_max
        grid = self.wall_field.grid
        width = grid.spacing * (grid.nx - 1)
        height = grid.spacing * (grid.ny - 1)
        ncx = max(1, int(width // reach))
        ncy = max(1, int(height // reach))
        self._neighbor_cells = T.NeighborCells(
            skin,
            NEIGHBOR_MARGIN_STEPS,
            margin_max,
            grid.x0,
            grid.y0,
            max(width / ncx, height / ncy),
            ncx,
            ncy,
        )

    @property
    def neighbor_cells(self) -> T.NeighborCells:
        """The neighbour list's margins and cells (:class:`~skygas.engine.terms.NeighborCells`).

        Assigning one (e.g. with zero margins, for a test against an exact list) replaces
        them until the drift changes.
        """
        assert self._neighbor_cells is not None  # set in __init__
        return self._neighbor_cells

    @neighbor_cells.setter
    def neighbor_cells(self, cells: T.NeighborCells) -> None:
        require(
            isinstance(cells, T.NeighborCells),
            "neighbor_cells",
            cells,
            "a skygas.engine.terms.NeighborCells record",
        )
        self._neighbor_cells = cells

    @property
    def term_rules(self) -> tuple[TermRules, ...]:
        """Every force term's descriptor (:mod:`skygas.engine.term_rules`), in the kernel's order.

        Pair law, wall law, drift, landscape, external force, the radius's (breathing).
        """
        return (
            self._pair_rules,
            self._wall_rules,
            self._drift_rules,
            self._landscape_rules,
            self._constant_rules,
            self._breathing_rules,
        )

    @property
    def force_terms(self) -> T.ForceTerms:
        """The force terms as the kernel sees them (:mod:`skygas.engine.terms`; read-only)."""
        return self._terms

    # -- time step -----------------------------------------------------------------------------
    def relaxation_time(self) -> float:
        """τ_min [s] of this simulation (see :func:`relaxation_time`).

        The largest stiffness of its force terms (:attr:`term_rules`), the laws' slopes and
        the landscape's curvature among them; times a breathing model's
        :attr:`~skygas.engine.term_rules.Breathing.mobility_gain` where the centre's 𝒟
        follows its radius.
        """
        return relaxation_time(self.thiele, self._stiffness())

    def _stiffness(self) -> float:
        """The largest stiffness of the force terms [pN/nm], times the mobility's gain."""
        return self._breathing_rules.mobility_gain * max(t.stiffness() for t in self.term_rules)

    def max_time_step(self) -> float:
        """Largest accepted time step [s]: MAX_STEP_FRACTION · τ_min."""
        return MAX_STEP_FRACTION * self.relaxation_time()

    def suggested_time_step(self) -> float:
        """A safe default [s]: SUGGESTED_STEP_FRACTION · τ_min.

        Without any stiff force (τ_min infinite), the step in which a free skyrmion moves a
        tenth of its diameter (:func:`~skygas.engine.force_model.free_time_step`). Check it
        with :func:`skygas.runs.timestep.check_time_step`.
        """
        return suggested_time_step(self.thiele, self._stiffness(), self.temperature)

    # -- landscape -----------------------------------------------------------------------------
    def set_landscape_enabled(self, term, on: bool) -> None:
        """Switch a landscape term (index, or the ``name`` of a band) off or on.

        The change acts from the next step (no recompilation).
        """
        self.landscape.set_enabled(term, on)

    # -- drift ---------------------------------------------------------------------------------
    def set_uniform_drift(self, velocity) -> None:
        """Uniform spin-drift velocity v_s = (vx, vy) [m/s] (1 m/s = 1 nm/ns)."""
        v = np.asarray(velocity, dtype=float)
        require(
            bool(v.shape == (2,) and np.all(np.isfinite(v))),
            "drift_velocity",
            velocity,
            "two finite numbers (vx, vy) in m/s",
        )
        self._drift_rules = CurrentDrift(T.drift_term(self.thiele, v), math.hypot(v[0], v[1]))
        self._terms = self._terms._replace(drift=self._drift_rules.record())
        self._configure_neighbor_cells()

    def set_drift_field(self, vx: np.ndarray, vy: np.ndarray) -> None:
        """Spatial v_s [m/s] sampled on ``self.wall_field.grid`` (arrays of shape (ny, nx))."""
        shape = (self.wall_field.grid.ny, self.wall_field.grid.nx)
        for name, arr in (("vx", vx), ("vy", vy)):
            require(
                bool(np.shape(arr) == shape and np.all(np.isfinite(arr))),
                f"drift_field.{name}",
                np.shape(arr),
                f"a finite array of shape {shape} (the wall-field grid)",
            )
        fields = self._terms.grid.fields
        fields[..., T.CH_DRIFT_X] = vx
        fields[..., T.CH_DRIFT_Y] = vy
        vx, vy = np.asarray(vx, dtype=float), np.asarray(vy, dtype=float)
        largest = math.sqrt(float(np.max(vx * vx + vy * vy)))
        self._drift_rules = CurrentDrift(T.drift_term(self.thiele, from_grid=True), largest)
        self._terms = self._terms._replace(drift=self._drift_rules.record())
        self._configure_neighbor_cells()

    # -- skyrmions -----------------------------------------------------------------------------
    @property
    def time(self) -> float:
        """Simulated time [s]."""
        return self.step * self.time_step

    @property
    def count(self) -> int:
        """Number of skyrmions present."""
        return self.store.count

    @property
    def ids_issued(self) -> int:
        """Number of skyrmions created so far (ids are 0, 1, … in order of creation)."""
        return self.store.next_id

    @property
    def annihilations(self):
        """Skyrmions removed by operations (:class:`~skygas.engine.store.AnnihilationLog`)."""
        return self.store.annihilations

    @property
    def exits(self):
        """Skyrmions that left through a port (:class:`~skygas.engine.exit_log.ExitLog`)."""
        return self.recorder.exits

    def positions(self) -> tuple[np.ndarray, np.ndarray]:
        """(ids, positions [m] of shape (n, 2)) of the skyrmions present, ordered by id."""
        return self.store.positions()

    @property
    def particle_model(self) -> str:
        """``"breathing"`` if each skyrmion carries its radius, else ``"rigid"``."""
        return self._breathing_rules.setting()

    def radii(self) -> tuple[np.ndarray, np.ndarray]:
        """(ids, radii [m]) of the skyrmions present, ordered by id.

        A breathing model's own radii; rigid skyrmions all have the material's radius.
        """
        return self.store.radii()

    def validate_positions(
        self, positions, field_name: str = "skyrmions", check_existing: bool = True
    ) -> None:
        """Refuse positions outside the device or on top of another skyrmion.

        Parameters
        ----------
        positions : array_like
            (n, 2) positions (x, y) [m].
        field_name : str
            The name the error gives them (``field_name[k]`` for the k-th).
        check_existing : bool
            Also keep them clear of the skyrmions already present.

        Raises
        ------
        InputError
            For the first position that is not finite, not inside the outline, or closer than
            MIN_PLACEMENT_SEPARATION skyrmion diameters to another.
        """
        p = np.asarray(positions, dtype=float).reshape(-1, 2) * units.M_TO_NM
        self._validate_positions_nm(p, field_name, check_existing)

    def _validate_positions_nm(
        self, positions_nm: np.ndarray, field_name: str = "skyrmions", check_existing: bool = True
    ) -> None:
        """:meth:`validate_positions` of positions [nm]."""
        p = np.asarray(positions_nm, dtype=float).reshape(-1, 2)
        inside = self.outline._contains_nm(p[:, 0], p[:, 1])
        for k in np.nonzero(~inside | ~np.all(np.isfinite(p), axis=1))[0]:
            raise InputError(
                f"{field_name}[{k}]",
                (p[k] / units.M_TO_NM).tolist(),
                "a position (m) inside the device outline",
            )
        min_sep = MIN_PLACEMENT_SEPARATION * self.thiele.skyrmion_diameter_internal
        others = self.store.present_nm() if check_existing else np.empty((0, 2))
        for n in range(len(p)):
            ref = np.vstack([p[:n], others])
            if len(ref) and np.min(np.hypot(*(ref - p[n]).T)) < min_sep:
                raise InputError(
                    f"{field_name}[{n}]",
                    (p[n] / units.M_TO_NM).tolist(),
                    f"a position at least {min_sep * 1e-9:.3g} m "
                    f"({MIN_PLACEMENT_SEPARATION} diameters) from other skyrmions",
                )

    def add_skyrmions(self, positions, *, validate: bool = True) -> np.ndarray:
        """Insert skyrmions at ``positions`` [m] (shape (n, 2)); returns their new ids."""
        p = np.asarray(positions, dtype=float).reshape(-1, 2) * units.M_TO_NM
        if validate:
            self._validate_positions_nm(p)
        return self.store.insert(p)

    def add_random(
        self, count: int, min_separation: float = 1.0, seed: int | None = None
    ) -> np.ndarray:
        """Insert ``count`` skyrmions at random, uniformly over the outline; returns their ids.

        Parameters
        ----------
        count : int
            How many to insert.
        min_separation : float
            Their least distance, in skyrmion diameters, from each other, from the skyrmions
            already present and from the walls.
        seed : int, optional
            The placement's seed (default: one drawn from the simulation's seed and the number
            of skyrmions created so far, so that a run is reproducible).

        Raises
        ------
        InputError
            If ``count`` is not a non-negative integer, or the skyrmions do not fit.
        """
        from skygas.physics.geometry import _random_positions_nm

        require(
            isinstance(count, (int, np.integer)) and count >= 0,
            "count",
            count,
            "an integer >= 0",
        )
        require(
            np.isfinite(min_separation) and min_separation > 0,
            "min_separation",
            min_separation,
            "a distance > 0 in skyrmion diameters",
        )
        if seed is None:
            seed = int(
                np.random.SeedSequence([self.seed, 0xADD, self.ids_issued]).generate_state(1)[0]
            )
        d = min_separation * self.thiele.skyrmion_diameter_internal
        _, present = self.store.positions()
        points = _random_positions_nm(
            self.outline,
            int(count),
            d,
            d,
            np.random.default_rng(seed),
            occupied=present * units.M_TO_NM,
        )
        return self.store.insert(points)

    def remove_skyrmions(self, ids, reason: str = "removed") -> None:
        """Remove the skyrmions with the given ids (unknown ids raise).

        See :meth:`StateView.annihilate`.
        """
        self.state.annihilate(ids, reason)

    # -- running -------------------------------------------------------------------------------
    def run(
        self,
        duration: float,
        record_interval: float | None = None,
        progress: Callable[[float], None] | None = None,
        chunk_steps: int = 20_000,
    ) -> None:
        """Advance by ``duration`` [s], recording positions every ``record_interval`` [s].

        Frames fall on the multiples of ``record_interval`` (counted from t = 0), the start of
        the run included when it is one and was not recorded yet: a fresh simulation's
        trajectory begins with its frame at t = 0 and ends with the frame at its last step.

        With a ``record_interval``, the interval and ``duration`` must be whole numbers of
        time steps, so that the frames and the end fall exactly where they are asked for. A
        step the simulation chose itself (``time_step=None``) is shortened once, before the
        first recorded step (a burn-in may come before), to the next one that divides
        ``record_interval``, with a warning (pass
        ``step_interval=record_interval`` to the constructor to have it chosen so from the
        start, as ``skygas simulate`` does); a step given explicitly is never changed.

        Operations in :attr:`operations` act at the steps they ask for (see
        :class:`~skygas.engine.scheduler.Operation`). ``progress(t)`` is called with the
        simulated time after each chunk.

        Parameters
        ----------
        duration : float
            The time to advance [s], ≥ 0; without a record interval, the nearest whole number
            of time steps.
        record_interval : float, optional
            The time between frames [s] (:meth:`trajectories`); ``None`` records none.
        progress : callable, optional
            Called with the simulated time [s] after each chunk.
        chunk_steps : int
            The most steps of one call of the compiled kernel.

        Raises
        ------
        InputError
            If ``duration`` is negative or not finite, or, with a record interval, if the
            interval or ``duration`` is not a whole number of an explicitly given time step.
        """
        require(
            np.isfinite(duration) and duration >= 0,
            "duration",
            duration,
            "a duration >= 0 in seconds",
        )
        record_every = 0
        if record_interval is not None:
            record_every = self.recording_steps(record_interval)
            require(
                whole_steps(duration, self.time_step) is not None,
                "duration",
                duration,
                f"a whole number of time steps ({self.time_step:.6g} s) when recording, "
                f"e.g. a multiple of record_interval ({record_interval:g} s)",
            )
        n_total = int(round(duration / self.time_step))
        if not estimates.inside_limits():  # a device or command checked its run already
            self._check_estimate(duration, n_total, record_every)
        if record_every and self.step % record_every == 0:
            self._record_start()
        end = self.step + n_total
        idle = 0  # passes in a row that acted without stepping
        escapes, moved = self.wall_escapes, self.skyrmion_steps
        while self.step < end:
            self.check_integrable()  # each pass: an operation may have changed the drive
            due = [op.next_step(self.step) for op in self.operations]
            idle = _check_forward(self.operations, due, self.step, idle)
            planner, plan = first_plan(
                self.operations, due, self.step, min(end, self.step + chunk_steps)
            )
            target = max(self.step, min([end, self.step + chunk_steps, *due]))
            made = 0
            if target > self.step:
                made = self._advance(target - self.step, record_every, plan)
                self._check_undone(self.wall_escapes - escapes, self.skyrmion_steps - moved)
            if planner is not None:  # the index of the planning operation
                op = self.operations[planner]
                op.planned_insertions_made(self, plan.ids[:made])
                due[planner] = op.next_step(self.step)
            for op, when in zip(self.operations, due, strict=True):
                if when <= self.step:
                    op.act(self)
            if progress is not None:
                progress(self.time)

    def _check_estimate(self, duration: float, steps: int, record_every: int) -> None:
        """The estimate of a run called from plain Python, checked as the command line does.

        Memory of the frames above the machine's share is refused; a run expected to take
        longer than a day (at the measuring machine's speed, docs/performance.md) is refused
        unless run inside ``skygas.core.estimates.run_limits(force=True)``; one of a minute
        or more is announced on stderr (``skygas: estimate: ...``) before it starts.
        """
        slots = max(1, self.store.capacity)
        frames = steps // record_every + 1 if record_every else 0
        # x, y (float64) and ids (int64) per slot and frame: what trajectories() holds
        memory = frames * slots * 24.0
        estimate = estimates.Estimate(
            steps=float(steps),
            memory=memory,
            seconds=steps * estimates.step_seconds(self.count),
        )
        require_memory(
            "duration", duration, memory, f"{frames} recorded frames", "record less often"
        )
        if estimate.seconds > estimates.MAX_SECONDS and not estimates.current_limits().force:
            raise InputError(
                "duration",
                duration,
                f"a run of at most {estimates.format_duration(estimates.MAX_SECONDS)} (this "
                f"one: {steps:.3g} steps of {self.time_step:.3g} s, about "
                f"{estimates.format_duration(estimate.seconds)})",
                f"durations are in seconds (did you mean {duration:g}e-9?); to run it anyway, "
                "call run() inside skygas.core.estimates.run_limits(force=True)",
            )
        if estimate.seconds >= estimates.ANNOUNCE_SECONDS:
            print(estimate.line(), file=sys.stderr, flush=True)

    def check_integrable(self) -> None:
        """Refuse a uniform term moving a free skyrmion over :data:`MAX_STEP_DIAMETERS` per step.

        :meth:`run` checks it before every kernel call (an operation may change the drive);
        the command line's sanity check calls it before the run starts.

        Raises
        ------
        InputError
            Naming the term (``drift_velocity``, ``external_force``, ...), its setting, and
            how far it moves a skyrmion in one step.
        """
        checked = (self._terms, self._dt_ns)
        last = self._integrable_checked
        if last is not None and last[0] is self._terms and last[1] == self._dt_ns:
            return  # the same terms (replaced whenever a drive changes) and step: nothing new
        d_sk = self.thiele.skyrmion_diameter_internal
        for term in self.term_rules:
            if term.setting() == "field":
                # a drift field's largest speed is at a corner's current crowding, where few
                # skyrmions go: judged by the walls' undone steps instead (_check_undone)
                continue
            per_step = term.per_step(self._mobility, self._dt_ns, d_sk)
            require(
                per_step <= MAX_STEP_DIAMETERS,
                term.name,
                term.setting(),
                f"a term that moves a free skyrmion at most {MAX_STEP_DIAMETERS:g} skyrmion "
                f"diameter per time step: it moves {per_step:.3g} in one step of "
                f"{self.time_step:.3g} s, which the engine cannot integrate",
                "lower it (a velocity is in m/s, a force in N), or give a shorter time_step",
            )
        self._integrable_checked = checked

    def _check_undone(self, escapes: int, moved: int) -> None:
        """Refuse a run in which walls undid over :data:`MAX_UNDONE_SHARE` of the steps.

        The share is of the skyrmion-steps since the run began, judged after
        :data:`MIN_STEPS_TO_JUDGE_UNDONE`.

        Raises
        ------
        InputError
            Naming the term that moves skyrmions most per step (or the time step).
        """
        if moved < MIN_STEPS_TO_JUDGE_UNDONE or escapes <= MAX_UNDONE_SHARE * moved:
            return
        d_sk = self.thiele.skyrmion_diameter_internal
        moves = {t.name: t.per_step(self._mobility, self._dt_ns, d_sk) for t in self.term_rules}
        name = max(moves, key=lambda k: moves[k])
        term = next(t for t in self.term_rules if t.name == name)
        field, value = (name, term.setting()) if moves[name] > 0 else ("time_step", self.time_step)
        raise InputError(
            field,
            value,
            f"a drive the walls can hold: {100 * escapes / moved:.3g} % of the skyrmion-steps "
            f"({escapes} of {moved}) would have carried a skyrmion through a wall and were "
            "undone, so skyrmions sit frozen at the wall",
            f"lower it, or shorten the time step ({self.time_step:.3g} s); at most "
            f"{100 * MAX_UNDONE_SHARE:g} % may be undone",
        )

    def recording_steps(self, record_interval: float) -> int:
        """The time steps between two frames recorded every ``record_interval`` [s].

        A step the simulation chose itself is shortened first, unless an operation is attached,
        to the longest one that divides the interval (see :meth:`run`); after a run without
        frames (a burn-in), the clock moves on to the next multiple of the new step.

        Raises
        ------
        InputError
            If ``record_interval`` is shorter than the step or not a whole number of steps.
        """
        require(
            np.isfinite(record_interval) and record_interval >= self.time_step,
            "record_interval",
            record_interval,
            f"an interval >= the time step ({self.time_step:.3g} s)",
        )
        if (
            whole_steps(record_interval, self.time_step) is None
            and self._step_chosen
            and not self.operations
        ):
            # the longest step up to the present one that divides the interval
            fitted = record_interval / math.ceil(record_interval / self.time_step - 1e-9)
            warnings.warn(
                f"skygas: time step shortened from {self.time_step:.6g} s to {fitted:.6g} s, "
                f"so that record_interval = {record_interval:g} s is a whole number of steps "
                f"(Simulation(..., step_interval={record_interval:g}) chooses it so)",
                stacklevel=3,
            )
            self._refit_time_step(fitted)
        every = whole_steps(record_interval, self.time_step)
        require(
            every is not None,
            "record_interval",
            record_interval,
            f"a whole multiple of the time step ({self.time_step:.6g} s); give the "
            "Simulation step_interval=record_interval instead of a time_step, or a time_step "
            "that divides it",
        )
        return max(1, every or 0)

    def _refit_time_step(self, time_step: float) -> None:
        """Change a step the simulation chose itself to ``time_step`` [s] (shorter), mid-run too.

        The time is the step count times the step, and the noise of a step depends on (seed,
        id, step). After a run with the old step (a burn-in), the count moves to the first
        step of the new length at or after the present time, so the clock stays right to
        less than one new step (the skyrmions do not move over that sliver) and, the new step
        being the shorter, no step's noise is drawn twice.
        """
        elapsed = self.time
        self._set_time_step(time_step)
        if self.step:
            self.step = max(self.step, math.ceil(elapsed / self.time_step - 1e-9))

    def _set_time_step(self, time_step: float) -> None:
        """Change dt [s] before the first step (the noise and neighbour margins follow it)."""
        self._step_chosen = False
        self.time_step = float(time_step)
        self._dt_ns = self.time_step * units.S_TO_NS
        self._noise = T.noise_term(
            self.thiele, self.temperature, self._dt_ns, self.seed, self.brownian_substeps
        )
        self._configure_neighbor_cells()

    def _record_start(self) -> None:
        """Record a frame of the present state at the current step, unless it has one."""
        if self.recorder.last_frame_step == self.step:
            return
        store = self.store
        used = store.used_slots()
        alive = store.alive[:used]
        self.recorder.add_frames(
            Frames(
                np.where(alive, store.x[:used], np.nan)[None, :],
                np.where(alive, store.y[:used], np.nan)[None, :],
                np.where(alive, store.ids[:used], -1).astype(np.int64)[None, :],
                np.where(alive, store.radius[:used], np.nan)[None, :]
                if self._breathing_rules.active
                else np.empty((0, 0)),
            ),
            1,
            self.step,
            1,
            self.time_step,
        )

    def _advance(self, n_steps: int, record_every: int, plan=None) -> int:
        """One kernel call of up to ``n_steps`` steps; returns the planned insertions made."""
        store = self.store
        if store.count > SORT_ABOVE:
            cells = self._neighbor_cells
            assert cells is not None  # set in __init__
            store.sort_into_cells(cells.x0, cells.y0, cells.size)
        # The kernel sees the slots up to the last occupied one: new skyrmions fill the lowest
        # free slot, so this range stays compact and loops skip the empty tail of the arrays.
        # Planned insertions get a few free slots more (the kernel stops if it runs out).
        used = store.used_slots()
        if plan is not None and len(plan.steps):
            store.grow(used + PLAN_SLOTS)
            used += PLAN_SLOTS
        else:
            plan = NO_PLAN
        # frames fall on the global steps that are multiples of record_every
        n_frames = (
            (self.step + n_steps) // record_every - self.step // record_every if record_every else 0
        )
        frames = self.recorder.frame_buffer(
            n_frames, used, store.capacity, self._breathing_rules.active
        )
        # each exit removes a skyrmion present at the start of the call or inserted during it
        exits = self.recorder.exit_buffer(used + len(plan.steps))
        counts = self._counts
        counts[:] = 0
        counts[COUNT["next_id"]] = store.next_id
        stepper = T.Stepper(self._dt_ns, self.integrator == "heun", record_every)
        # the arguments whose types could change; the frames and exits are the recorder's
        # buffers, of fixed types, and a call with planned insertions is dispatched
        key = (
            (store.x, store.y, store.radius, store.alive, store.ids, self._noise)
            + (self._mobility, self._terms, self._neighbor_cells, self._ports, self._counters)
            if plan is NO_PLAN
            else None
        )
        n_exit = self._advance_call(
            key,
            store.x[:used],
            store.y[:used],
            store.radius[:used],
            store.alive[:used],
            store.ids[:used],
            self.step,
            n_steps,
            stepper,
            self._noise,
            self._mobility,
            self._terms,
            self._neighbor_cells,
            self._ports,
            frames,
            exits,
            plan,
            self._counters,
        )
        c = counts.tolist()
        store.next_id = c[COUNT["next_id"]]
        self.recorder.add_exits(exits, n_exit, self.time_step)
        if record_every:
            # fewer than n_frames if the call stopped early
            self.recorder.add_frames(
                frames,
                c[COUNT["frames"]],
                (self.step // record_every + 1) * record_every,
                record_every,
                self.time_step,
            )
        self.step += c[COUNT["steps"]]
        self.wall_escapes += c[COUNT["wall_escapes"]]
        self.skyrmion_steps += c[COUNT["skyrmion_steps"]]
        self.pair_evaluations += c[COUNT["pair_evaluations"]]
        self.neighbor_rebuilds += c[COUNT["neighbor_rebuilds"]]
        self.radius_reflections += c[COUNT["radius_reflections"]]
        return c[COUNT["inserted"]]

    # -- checkpoints ---------------------------------------------------------------------------
    def state_dict(self) -> dict[str, np.ndarray]:
        """The mutable state as plain arrays: an opaque checkpoint for :meth:`load_state_dict`.

        The arrays hold the engine's values exactly as stored (positions in its internal unit,
        nanometres), so that a resumed run is bit-identical; read positions [m] with
        :meth:`positions` or :attr:`state`, not from here. With the same construction
        arguments, :meth:`load_state_dict` continues the run bit-identically, because the noise
        depends only on (seed, id, step).
        """
        state = {
            **nest("store_", self.store.state_dict()),
            **nest("record_", self.recorder.state_dict()),
            "counters": np.array(
                [
                    self.step,
                    self.wall_escapes,
                    self.pair_evaluations,
                    self.neighbor_rebuilds,
                    self.skyrmion_steps,
                ],
                dtype=np.int64,
            ),
            # which landscape terms are switched on (a gate can be open or closed)
            "landscape_enabled": np.array(self.landscape.enabled, dtype=bool),
            # the step, which run() may have fitted to a record interval
            "time_step": np.array(self.time_step),
        }
        # each named operation's own state, under its name (the user's operations too); values
        # that are not arrays travel as JSON text
        for name, op in named_operations(self.operations).items():
            if hasattr(op, "state_dict"):
                state.update(nest(f"op.{name}.", to_arrays(op.state_dict())))
        return state

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        """Restore a state saved by :meth:`state_dict`.

        A simulation that chose its own step takes the saved one (which :meth:`run` may have
        fitted to a record interval); one given another step explicitly refuses the state.
        """
        saved_step = state.get("time_step")
        if saved_step is not None and float(saved_step) != self.time_step:
            require(
                self._step_chosen and self.step == 0,
                "time_step",
                self.time_step,
                f"the step of the saved state ({float(saved_step):.6g} s)",
            )
            self._set_time_step(float(saved_step))
        self.store.load_state_dict(unnest("store_", state))
        self.recorder.load_state_dict(unnest("record_", state))
        counters = [int(v) for v in state["counters"]]
        self.step, self.wall_escapes, self.pair_evaluations, self.neighbor_rebuilds = counters[:4]
        if "record_frame_last_step" not in state and self.step > 0:
            # a checkpoint of a version that recorded no frame at the start of a run: it
            # continues as it began, without one at the step it resumes from
            self.recorder.last_frame_step = self.step
        self.skyrmion_steps = counters[4] if len(counters) > 4 else 0
        for term, on in enumerate(state.get("landscape_enabled", ())):
            self.landscape.set_enabled(term, bool(on))
        for name, op in named_operations(self.operations).items():
            if hasattr(op, "load_state_dict"):
                op.load_state_dict(from_arrays(unnest(f"op.{name}.", state)))

    def operation_summaries(self) -> dict[str, dict]:
        """``summary()`` of every named operation that has one, by name.

        The devices report them in their summaries under ``"operations"``.
        """
        return {
            name: op.summary()
            for name, op in named_operations(self.operations).items()
            if hasattr(op, "summary")
        }

    def operation_data(self) -> dict[str, tuple[tuple[str, ...], np.ndarray]]:
        """The data every named operation with a ``data()`` method adds to a run's result file.

        Returns
        -------
        dict
            ``"<name>_<variable>"`` → (dimension names, array), the form
            :class:`xarray.Dataset` takes for its variables. An operation's ``data()`` returns
            ``{variable: (dims, array)}``; its dimension names are prefixed with its name too,
            so that two operations never share a dimension by accident.
        """
        data: dict[str, tuple[tuple[str, ...], np.ndarray]] = {}
        for name, op in named_operations(self.operations).items():
            if hasattr(op, "data"):
                for variable, dims, array in _operation_variables(name, op.data()):
                    data[f"{name}_{variable}"] = (tuple(f"{name}_{d}" for d in dims), array)
        return data

    # -- results -------------------------------------------------------------------------------
    def parameters(self) -> dict:
        """Every parameter needed to reproduce the run (JSON-able, SI units).

        The run's own, then each force term's entries (:meth:`TermRules.parameters
        <skygas.engine.term_rules.TermRules.parameters>`).
        """
        return {
            "skygas_version": __version__,
            "seed": self.seed,
            "temperature_K": self.temperature,
            "time_step_s": self.time_step,
            "integrator": self.integrator,
            "brownian_substeps": self.brownian_substeps,
            "material": self.material.model_dump(mode="json"),
            "thiele": self.thiele.as_record(),
            "edge_stray_field": self.edge_stray_field is not None,
            "grid_spacing_m": self.wall_field.grid.spacing / units.M_TO_NM,
            "geometry": self.outline.describe(),
            **{k: v for term in self.term_rules for k, v in term.parameters().items()},
        }

    def term_steps(self) -> dict[str, float]:
        """Per force term that a configuration sets (its ``config_field``).

        The diameters a free skyrmion moves in one step under it alone (the sanity check
        before a run, docs/physics.md §5).
        """
        d_sk = self.thiele.skyrmion_diameter_internal
        return {
            t.config_field: t.per_step(self._mobility, self._dt_ns, d_sk)
            for t in self.term_rules
            if t.config_field is not None
        }

    def term_settings(self) -> dict[str, object]:
        """Per force term that a configuration sets, its value as the configuration gives it.

        Keyed by the term's ``config_field``.
        """
        return {t.config_field: t.setting() for t in self.term_rules if t.config_field is not None}

    @property
    def frame_blocks(self) -> tuple[FrameBlock, ...]:
        """The recorded frames, one :class:`FrameBlock` per kernel call, in time order."""
        return tuple(self.recorder.blocks)

    def take_frames(self, first_block: int = 0) -> list[FrameBlock]:
        """Remove and return the frame blocks from index ``first_block`` on.

        A long run that keeps its own sparse record of positions takes them after each piece,
        so that the simulation does not hold them all.
        """
        return self.recorder.take_frames(first_block)

    def plot(self, ax=None, landscape: bool = True, title: str | None = None) -> Figure:
        """Draw the skyrmions present now over the outline, in µm.

        Each skyrmion is a disc of its diameter; walls are black, ports red with their names,
        and the energy landscape, if any, lies underneath coloured by U/k_BT. The drawing is
        that of the command line's figures (:mod:`skygas.figures.plotting`).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Draw on it (default: a new figure).
        landscape : bool
            Draw the energy landscape under the skyrmions (when there is one).
        title : str, optional
            The title (default: the count, the temperature and the simulated time).

        Returns
        -------
        matplotlib.figure.Figure
            The figure drawn on; save it with ``fig.savefig(path)``. The recorded frames are
            drawn by :func:`skygas.plot` of :meth:`trajectories`.
        """
        from skygas.figures.plotting import state_figure

        return state_figure(self, ax, landscape, title)

    def trajectories(self) -> xr.Dataset:
        """Recorded positions as a Dataset.

        ``x``, ``y`` [m] with dims (time, skyrmion), NaN where a skyrmion does not exist,
        ``time`` [s]; the ``skyrmion`` coordinate holds the ids of the skyrmions present in
        at least one frame; a breathing model's radii as ``radius`` [m] on the same dims.
        Exits as variables on dim ``exit``; attributes hold every parameter
        (``parameters_json``), the seed and the version.
        """
        return self.recorder.trajectories(
            {
                "seed": self.seed,
                "temperature_K": self.temperature,
                "time_step_s": self.time_step,
                "simulated_time_s": self.time,
                "wall_escapes": self.wall_escapes,
            },
            self.parameters(),
        )


#: Passes of the run loop in a row at one step (operations acting, nothing stepping) after which
#: an operation that keeps asking for that step is taken to be stuck.
STUCK_PASSES = 100


def _check_forward(operations, due: list[int], step: int, idle: int) -> int:
    """The count of passes in a row at ``step`` with an operation due; refuse a stuck one.

    An operation may ask for the present step (``next_step(step) <= step``: act now) and act
    several times at one step, but one that never asks for a later step would hold the run
    at ``step`` for ever: after :data:`STUCK_PASSES` passes it is refused, by name.
    """
    now = [op for op, when in zip(operations, due, strict=True) if when <= step]
    if not now:
        return 0
    idle += 1
    if idle > STUCK_PASSES:
        op = now[0]
        name = getattr(op, "name", None) or type(op).__name__
        raise InputError(
            f"operation {name!r}: next_step({step})",
            due[operations.index(op)],
            f"a step after {step} once it has acted (it asked for step {step} or earlier "
            f"{STUCK_PASSES} times in a row): an operation's schedule must move forward",
        )
    return idle


def _operation_variables(name: str, returned) -> list[tuple[str, tuple[str, ...], np.ndarray]]:
    """(variable, dims, array) of an operation's ``data()``, checked.

    A dict of ``{variable: (dims, array)}`` with as many dimension names as the array has axes.
    """
    expected = "a dict {variable: (dimension names, array)}, e.g. {'n': (('time',), counts)}"
    field = f"operation {name!r}: data()"
    if not isinstance(returned, dict):
        raise InputError(field, type(returned).__name__, expected)
    out = []
    for variable, entry in returned.items():
        ok = isinstance(variable, str) and isinstance(entry, tuple) and len(entry) == 2
        dims, array = entry if ok else ((), None)
        if isinstance(dims, str):
            dims = (dims,)
        ok = ok and all(isinstance(d, str) for d in dims)
        try:
            values = np.asarray(array)
        except Exception:
            ok = False
        ok = ok and values.dtype.kind in "biufcUSM" and values.ndim == len(dims)
        if not ok:
            raise InputError(f"{field}[{variable!r}]", _short(entry), expected)
        out.append((variable, tuple(dims), values))
    return out


def _short(value) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
