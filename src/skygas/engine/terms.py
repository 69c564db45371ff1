"""The force terms of the Thiele equation and the other records the compiled kernel reads.

All in internal units: nm, ns, pN.

Each record is a typed, immutable :class:`~typing.NamedTuple` that the kernel receives as one
argument and reads by field name, so a parameter can be followed by name from the configuration
to the arithmetic that uses it (``temperature`` → :func:`noise_term` → ``NoiseTerm.amplitude``
→ :func:`skygas.engine.stages.draw_noise`). The records are rebuilt, not edited, when a
parameter changes during a run (a gate switching the drift field).

Force terms, summed into the total force F on each skyrmion before it is turned into a
velocity by the mobility (:class:`Mobility`):

- :class:`PairTerm`: the skyrmion–skyrmion law, tabulated (paper, Lin–Reichhardt or a user's
  law, :mod:`skygas.physics.forces`), summed over a neighbour list;
- :class:`WallTerm`: the skyrmion–wall law along the inward wall normal of the field grid;
- :class:`DriftTerm`: the current's drive μ(G ε + η𝒟k I)·v_s, v_s uniform or from the grid;
- :class:`LandscapeTerm`: an external potential's force −∇U (gates, pinning, disorder;
  :mod:`skygas.fields.landscape`), the exact gradient of its bicubic Hermite interpolant;
- :class:`WallFilmTerm`: the wall law as the missing film's field (``wall_geometry =
  "film"``, :mod:`skygas.fields.landscape.wall_film`), in place of :class:`WallTerm`'s
  nearest-wall force;
- :class:`BreathingTerm`: a breathing model's radii, their self force, and their share of
  the laws and of the edges' stray field.

The per-node fields (wall distance and normal, boundary distance, drift) share one packed grid,
:class:`FieldGrid`, read with one bilinear lookup (:mod:`skygas.fields._field_lookup`).

**Adding a force term**: declare its record here (fields in internal units, documented), add
it to :class:`ForceTerms`, and add its contribution in one place,
:func:`skygas.engine.stages.add_one_body_forces` (or a pair pass beside
:func:`~skygas.engine.stages.pair_forces`); nothing else in the kernel changes. A one-body term
that reads the grid must keep skyrmions from skipping their lookup (see
:func:`~skygas.engine.stages.interior_floor`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from skygas.core import units

# The field grid's channels (float32, nm and nm/ns; 8 per node, see skygas.fields._field_lookup).
CH_WALL_DIST = 0  # signed distance to the nearest wall
CH_NORMAL_X = 1  # inward wall normal
CH_NORMAL_Y = 2
CH_DOMAIN = 3  # signed distance to the boundary (walls and ports), > 0 inside
CH_DRIFT_X = 4  # spin-drift velocity v_s
CH_DRIFT_Y = 5  # (channels 6 and 7 are free)


class Mobility(NamedTuple):
    """The inverse of the Thiele friction matrix (G ε + a I), a = α𝒟k, g = G [pN·ns/nm].

    V = M·F = (a F − g εF)/(a² + g²), εF = (F_y, −F_x).
    """

    a: float  # a/(a² + g²) [nm/(pN·ns)]
    g: float  # g/(a² + g²) [nm/(pN·ns)]


class NoiseTerm(NamedTuple):
    """Thermal noise: an isotropic velocity noise of diffusion constant D = k_BT a/(a² + g²).

    Drawn from Philox keyed on (seed, skyrmion id, step).
    """

    seed: int  # key of the counter-based generator
    amplitude: float  # √(2 D dt) per axis [nm]
    substeps: int  # Brownian sub-increments summed per step (1 = plain)
    thermal: bool  # False at T = 0: no noise is drawn


class PairTerm(NamedTuple):
    """Skyrmion–skyrmion repulsion: ``table[k]`` is |F|/r [pN/nm] at r² = k·spacing_r2."""

    table: np.ndarray
    spacing_r2: float  # table spacing in r² [nm²]
    cutoff: float  # [nm]


class WallTerm(NamedTuple):
    """Skyrmion–wall repulsion along the inward normal.

    ``table[k]`` is |F| [pN] at wall distance k·spacing.
    """

    table: np.ndarray
    spacing: float  # [nm]
    cutoff: float  # [nm]


class DriftTerm(NamedTuple):
    """The current's drive force μ(g ε + b I)·v_s, b = η𝒟k.

    With v_s [nm/ns] uniform (``vs_x``, ``vs_y``) or read from the grid (``from_grid``).
    """

    drive_g: float  # μ g [pN·ns/nm]
    drive_b: float  # μ b [pN·ns/nm]
    vs_x: float  # uniform v_s [nm/ns] (ignored when from_grid)
    vs_y: float
    from_grid: bool


class LandscapeTerm(NamedTuple):
    """An external potential.

    The polynomial coefficients of its interpolant in every cell of a grid of origin (x0, y0)
    and spacing h [nm], ``coefficients[j, i, 4b + a]`` of tᵃuᵇ [pN·nm]
    (:mod:`skygas.fields.landscape.hermite`).
    """

    coefficients: np.ndarray
    x0: float
    y0: float
    spacing: float
    active: bool  # False: no landscape (``nodes`` is a placeholder)


class ConstantForceTerm(NamedTuple):
    """A uniform external force F [pN] on every skyrmion.

    The same everywhere and at every step (a field gradient, a tilted film): one of the one-body
    forces.
    """

    fx: float
    fy: float


class FieldGrid(NamedTuple):
    """The packed per-node fields ``fields[j, i.

    Channel]`` (float32) on a grid of origin (x0, y0) and spacing [nm].
    """

    fields: np.ndarray
    x0: float
    y0: float
    spacing: float


class BreathingTerm(NamedTuple):
    """The radius Rᵢ of each skyrmion as a degree of freedom (a breathing model), or none.

    Γ_R dR/dt = F_R + ξ with F_R = −∂E/∂R: the self force −E_self'(R) tabulated here, and the
    pair and wall laws' share (the laws act on the gap d − s(Rᵢ + Rⱼ − 2R₀) and w − s_w(R − R₀),
    :class:`skygas.physics.materials.BreathingSpec`). R is kept in [r_min, r_max] (a step
    that would leave is reflected back). The exponential step's weights are tabulated in
    z = λ dt up to the table's end, past which their z → ∞ forms hold
    (:func:`skygas.engine.stages.radius_predictor`).
    """

    active: bool  # False: rigid skyrmions (every other field is a placeholder)
    r0: float  # the isolated radius R₀ [nm] (new skyrmions start with it)
    r_min: float  # the table's range [nm]
    r_max: float
    self_force: np.ndarray  # −dE_self/dR [pN] at r_min + k·spacing
    curvature: np.ndarray  # E_self''(R) [pN/nm] at the same radii (the exact linear part)
    spacing: float  # [nm]
    phi: np.ndarray  # (3, nodes): φ₁, φ₂, √φ_σ of z = λ dt at z = k·z_spacing (the step's weights)
    z_spacing: float
    inv_friction: float  # 1/Γ_R [nm/(pN·ns)]
    kt: float  # k_B T [pN·nm] (the noise: √(2 k_BT dt/Γ_R) per step)
    pair_shift: float  # s_p
    wall_shift: float  # s_w
    pair_reach: float  # how much farther [nm] a pair interacts than at R₀: 2 s_p (r_max − R₀)
    wall_reach: float  # the same for the walls: s_w (r_max − R₀)
    closest: float  # smallest gap [nm] the pair law is read at (its table's valid range)
    # the edge stray field's scale a(R) = A_m(R)/A_m(R₀) on the self force's grid, less 1 (the
    # landscape holds a = 1), and its first and second derivatives [1/nm, 1/nm²]
    area_excess: np.ndarray
    area_slope: np.ndarray
    area_curvature: np.ndarray
    stray: LandscapeTerm  # the edge stray field U_s alone (inactive: no stray field)
    # the centre's mobility at the radius (𝒟(R), BreathingSpec.dissipation), on the self
    # force's grid; False: 𝒟 is the same at every radius, and the table is a placeholder
    mobility_varies: bool
    # rows: P, Q, which turn the velocity M₀F of the material's 𝒟 into M(R)F (v' = P v − Q εv);
    # A_R, G_R, the mobility M(R) [nm/(pN·ns)]; c − 1, c = 𝒟(R)/𝒟(R₀) (the dissipative
    # drive's change); √(D(R)/D₀), the scale of the centre's noise
    mobility: np.ndarray


class WallFilmTerm(NamedTuple):
    """The wall law as the missing film's field, in layers of erosion δ, or none.

    ``coefficients[k]`` are the Hermite cells of U_δ at δ_k = ``delta0`` + k·``delta_step``
    [nm] (:mod:`skygas.fields.landscape.wall_film`), on a grid of origin (x0, y0) and
    ``spacing`` [nm]; one layer (δ = 0) for rigid skyrmions, ≥ 4 for breathing ones.
    """

    active: bool  # False: the wall law acts from the nearest wall (WallTerm)
    coefficients: np.ndarray  # (layers, ny − 1, nx − 1, 16) float32
    x0: float
    y0: float
    spacing: float
    delta0: float
    delta_step: float
    layers: int


#: No wall film: the wall law acts from the nearest wall only.
NO_WALL_FILM = WallFilmTerm(False, np.zeros((1, 1, 1, 16), np.float32), 0.0, 0.0, 1.0, 0.0, 1.0, 1)


def wall_film_term(film, grid) -> WallFilmTerm:
    """:class:`WallFilmTerm` of a :class:`~skygas.fields.landscape.wall_film.WallFilm`."""
    return WallFilmTerm(
        True,
        film.coefficients,
        grid.x0,
        grid.y0,
        grid.spacing,
        film.delta0,
        film.delta_step,
        len(film.deltas),
    )


class ForceTerms(NamedTuple):
    """Every force term of a run, as the kernel sees them."""

    pair: PairTerm
    wall: WallTerm
    drift: DriftTerm
    landscape: LandscapeTerm
    grid: FieldGrid
    constant: ConstantForceTerm
    breathing: BreathingTerm
    wall_film: WallFilmTerm = NO_WALL_FILM


def _no_landscape() -> LandscapeTerm:
    return LandscapeTerm(np.zeros((1, 1, 16), dtype=np.float32), 0.0, 0.0, 1.0, False)


#: The breathing term of rigid skyrmions.
RIGID = BreathingTerm(
    False,
    0.0,
    0.0,
    1.0,
    np.zeros(2),
    np.zeros(2),
    1.0,
    np.zeros((3, 2)),
    1.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    np.zeros(2),
    np.zeros(2),
    np.zeros(2),
    _no_landscape(),
    False,
    np.zeros((6, 2)),
)


class Stepper(NamedTuple):
    """The integrator of one kernel call: its step, scheme and recording interval."""

    dt: float  # [ns]
    heun: bool  # True: stochastic Heun; False: Euler–Maruyama
    record_every: int  # steps between recorded frames (0 = never)


class NeighborCells(NamedTuple):
    """The Verlet list's margins and the cell list that builds it (:mod:`.neighbors`)."""

    skin: float  # [nm]; the smallest margin s_i is half of it
    margin_steps: float  # steps of motion at its latest velocity a margin should cover
    margin_max: float  # largest margin s_i [nm] (cell size ≥ cutoff + 2·margin_max)
    x0: float  # cell-list origin [nm]
    y0: float
    size: float  # cell size [nm]
    ncx: int  # cells along x and y
    ncy: int


class PlannedInsertions(NamedTuple):
    """Insertions the kernel makes at the start of given steps while the site is clear.

    An injector's nucleations: see :class:`skygas.engine.scheduler.PlannedInsertions`.
    """

    steps: np.ndarray  # global step of each insertion (increasing)
    x: np.ndarray  # [nm]
    y: np.ndarray  # [nm]
    ids: np.ndarray  # out: the id given to each insertion made
    clearance2: float  # squared clearance [nm²]: no skyrmion closer than this


#: Counters one kernel call adds to (a one-element structured array).
COUNTERS = np.dtype(
    [
        ("pair_evaluations", np.int64),  # pair forces evaluated inside the cutoff
        ("wall_escapes", np.int64),  # steps that crossed a wall (undone)
        ("exits", np.int64),  # skyrmions that left through a port
        ("frames", np.int64),  # frames recorded
        ("neighbor_rebuilds", np.int64),  # neighbour-list builds
        ("steps", np.int64),  # steps taken (fewer than asked if a planned insertion
        #   cannot be made)
        ("inserted", np.int64),  # planned insertions made
        ("next_id", np.int64),  # in: id of the next inserted skyrmion; out: the one after
        ("skyrmion_steps", np.int64),  # steps of one skyrmion taken, summed over skyrmions
        ("radius_reflections", np.int64),  # radius steps reflected back into the table's range
    ]
)


def mobility(thiele) -> Mobility:
    """:class:`Mobility` of :class:`~skygas.physics.materials.ThieleParameters`."""
    a, g = thiele.friction_internal, thiele.gyrocoupling_internal
    return Mobility(a / (a * a + g * g), g / (a * a + g * g))


def noise_term(thiele, temperature: float, dt_ns: float, seed: int, substeps: int) -> NoiseTerm:
    """:class:`NoiseTerm` at ``temperature`` [K] for a step ``dt_ns`` [ns]."""
    a, g = thiele.friction_internal, thiele.gyrocoupling_internal
    kt = units.thermal_energy_internal(temperature)
    # √(2 D dt) per axis; the kernel sums `substeps` normals and rescales.
    amplitude = math.sqrt(2.0 * kt * a / (a * a + g * g) * dt_ns)
    return NoiseTerm(int(seed), amplitude, int(substeps), temperature > 0)


def pair_term(table) -> PairTerm:
    """:class:`PairTerm` of a squared-layout :class:`~skygas.physics.forces.ForceTable`."""
    return PairTerm(table.values, table.spacing, table.cutoff)


def wall_term(table) -> WallTerm:
    """:class:`WallTerm` of a :class:`~skygas.physics.forces.ForceTable`."""
    return WallTerm(table.values, table.spacing, table.cutoff)


def drift_term(thiele, velocity=(0.0, 0.0), from_grid: bool = False) -> DriftTerm:
    """:class:`DriftTerm`: uniform v_s = ``velocity`` [nm/ns], or from the grid."""
    return DriftTerm(
        thiele.mu * thiele.gyrocoupling_internal,
        thiele.mu * thiele.drive_friction_internal,
        float(velocity[0]),
        float(velocity[1]),
        bool(from_grid),
    )


def landscape_term(field=None) -> LandscapeTerm:
    """:class:`LandscapeTerm` of a :class:`~skygas.fields.landscape.LandscapeField` (or none)."""
    if field is None or not field.terms:
        return _no_landscape()
    return LandscapeTerm(field.coefficients, field.grid.x0, field.grid.y0, field.grid.spacing, True)


def field_grid(fields: np.ndarray, grid) -> FieldGrid:
    """:class:`FieldGrid` of packed ``fields`` on a :class:`~skygas.fields.wall_field.Grid`."""
    return FieldGrid(fields, grid.x0, grid.y0, grid.spacing)
