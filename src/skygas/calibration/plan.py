"""What a calibration computes: its configuration, its films, and the list of solves.

A calibration is a set of independent constrained relaxations plus one LLG run, all of them
of the same material.

**The reference environment.** A skyrmion's size depends on the stray field it sits in, and a
film's own stray field depends on where its edges are: in a finite film the demagnetising field
is weaker than an infinite film's −M_s by H_dev(r), about M_s t/D in the middle of a device of
width D and more near its edges (:mod:`skygas.fields.landscape.stray_field`). For soft skyrmions
this matters a great deal: the S2 skyrmion (2 nm cells) has a radius of 26 nm in the middle of a
300 nm film, 39 nm in the middle of a 1024 nm disk and 52 nm in an infinite film. The laws
are therefore calibrated in *compensated* films (:class:`~skygas.calibration.solver.Film`):
an extra field cancels the film's own H_dev, so that the film's edges act only at short range,
and a uniform ``reference_field`` H_ref = M_s h/√(a² + h²) (h = t/2, a = D/2: H_dev at the
centre of a disk of the ``reference_diameter`` D) puts every skyrmion in the environment of
the interior of the device the model is for. The particle model then adds the gradient of the
device's own stray field (its constant part is H_ref, already in the laws).

**Stage 1, the isolated skyrmion** (needs nothing): a square film of side ``L₀`` with one
skyrmion held at its centre, and the same film uniform; the same pair in a film 1.25 times
larger checks that the edges did not matter. ``L₀`` is 20 times the longer of Δ_eff and A/|D|, and
grown (to 11 radii) until it is at least 10 skyrmion radii; a grown film starts from the
profile relaxed in the smaller one. The same skyrmion at H_ref ± 1 mT/μ₀ measures how
its size follows the field.

**The breathing scan** (needs the radii at H_ref ± 1 mT/μ₀): the isolated skyrmion, and the
uniform film, at a few more field offsets b, chosen from the measured d ln R/dB to aim at
radii :data:`SCAN_TARGETS` off the isolated one. A uniform extra field is a Lagrange multiplier
on the reversed area: relaxed at H_ref + b the skyrmion sits at the radius where its
self-energy (at H_ref) balances the extra field's Zeeman force, which gives E_self(R) and, from
the relaxed profiles at neighbouring radii, 𝒟_RR = ∫ ∂_R m·∂_R m dA. At the offset that aims at
:data:`SHIFTED_TARGET` (a skyrmion about 15 % smaller), a few pairs and edge singles in the
calibration film (*shifted*) measure how the laws move with the radius.

**Stage 2, the laws** (needs the measured diameter d_sk): one rectangular *calibration film*
of (pair range + 2.5) × 3.5 d_sk, open boundaries, an odd number of cells each way so that its
centre row maps to itself under the half-turn about the film's centre (a symmetry of the film
for either DMI). In it:

- *singles*: one skyrmion whose guiding centre is held at cell i of the centre row
  (:meth:`~skygas.calibration.solver.FilmSolver.relax`). The singles near the left edge give
  the edge law E(x);
- *pairs*: two skyrmions held at cells i and nx − 1 − i of the centre row, d = (nx − 1 − 2i)
  cells apart. By the half-turn symmetry both feel the film exactly as the single at cell i
  does, so the pair energy is E(d) = E_pair − 2E_single(i) + E_uniform: every interaction
  with the film's edges, the long-range stray field included, cancels;
- the uniform film.

**Mesh check**: a smaller film (3.5 × 2.5 d_sk) with a pair at ≈ 1.5 d_sk, its single and the
uniform film, each at the calibration's cell size and at half of it.

**Stray-field check**: singles at a few distances from the left edge of the calibration film
whose compensation spares that edge's stray field (a real straight edge in an otherwise
infinite film), and its uniform state: their energy against the model's, short-range law plus
first-order stray-field energy.

**Validation** (needs d_sk): a compensated disk (with H_ref) of ``disk_radius`` d_sk, or a
rectangle, with ``skyrmions`` skyrmions at fixed, asymmetric positions, relaxed with their
guiding centres held, then released: LLG at T = 0.

Every relaxation after stage 1 starts from the isolated skyrmion's own relaxed profile (its
helicity and m_z(r)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np
from pydantic import Field, model_validator

from skygas.calibration.material import MicromagneticMaterial
from skygas.calibration.solver import Film
from skygas.core.config_types import Length, PositiveFloat, StrictModel
from skygas.core.units import MU_0

#: Relaxations stop below max|m × (m × H')| of this [A/m]. Pair energies of S2 (4 nm cells,
#: 1.3–5 d_sk) at 30 A/m differ from those at 10 A/m by less than 4e-5 of themselves, with
#: 30 % fewer iterations; at 100 A/m by up to 3e-3.
CALIBRATION_TORQUE_TOLERANCE = 30.0
#: The paper's chamber diameter [m], the default reference device.
REFERENCE_DIAMETER = 1024e-9
#: Field step [T] of the size-sensitivity solves.
SENSITIVITY_STEP = 1e-3
#: Distances from the edge [d_sk] of the stray-field check.
STRAY_CHECK_GRID = (1.2, 2.0)
#: Relative radius changes the breathing scan aims at (besides ±SENSITIVITY_STEP), from the
#: measured d ln R/dB taken as constant: more room below the isolated radius, where
#: neighbours and edges press a skyrmion, than above it. The relation is not linear (a
#: shrinking skyrmion stiffens, a growing one softens), so the radii reached differ: −45 %
#: reaches about −33 %, as deep as the validation's skyrmions are squeezed by two neighbours
#: and an edge (65-80 % of R₀; −30 % alone reached −24 %, and the table held them there).
SCAN_TARGETS = (-0.45, -0.3, -0.15, 0.1, 0.2)
#: The scan's offset that aims at this change also holds the laws at a second radius.
SHIFTED_TARGET = -0.15
#: The scan's largest field offset [T] (a stiff skyrmion would otherwise be pushed past its
#: collapse or its elliptic instability).
SCAN_MAX_FIELD = 0.1
#: Pair distances [d_sk] measured at the second radius: within the measured pair law once
#: shifted by the radius change, and with their singles ≥ 3.4 d_sk from the calibration
#: film's edges, where the edge energy is below half a percent of the pair energy.
SHIFTED_PAIR_GRID = (1.2, 1.45, 1.75)
#: Distances from the left edge [d_sk] of the singles measured at the second radius.
SHIFTED_EDGE_GRID = (1.0, 1.2, 1.4)

#: Distances from the left edge [d_sk] of the singles that sample the edge law. Down to 0.6: a
#: skyrmion squeezed by its neighbours comes to 0.62–0.72 d_sk of an edge in the validation
#: rectangles, and below its first point the law only goes on along its tangent
#: (:data:`skygas.calibration.laws.WALL_CONTINUATION`). A single that leaves through the edge
#: while it relaxes is dropped (and reported): S6's at 0.56 d_sk, S2's at 0.59 and 0.64.
EDGE_GRID = (0.6, 0.65, 0.7, 0.8, 0.9, 1.0, 1.15, 1.3, 1.5, 1.75, 2.0, 2.5)
#: Side [radii] of the isolated skyrmion's film once its radius is known; a film is large
#: enough while it is at least ISOLATED_MIN_SIDE radii (the margin keeps a radius measured in
#: the larger film from asking for yet another one).
ISOLATED_SIDE = 11.0
ISOLATED_MIN_SIDE = 10.0
#: Margin [d_sk] between a pair's skyrmions and the calibration film's edges.
PAIR_MARGIN = 1.25
#: Pair distances relaxed for the pair law (``CalibrationConfig.pair_distances``), and the
#: fewest allowed: the law's spline through ln E(d) needs four points.
PAIR_DISTANCES = 11
MIN_PAIR_DISTANCES = 4
#: Height of the calibration film [d_sk].
FILM_HEIGHT = 3.5


class ValidationSpec(StrictModel):
    """The micromagnetic many-skyrmion run the model is checked against (T = 0, no current).

    ``skyrmions`` in a rectangle of ``width`` × ``height`` diameters (``shape`` =
    ``"rectangle"``, the default), where the default three start near each other and each near
    an edge, or in a disk of ``disk_radius`` diameters; snapshots every
    ``snapshot_interval`` [s]; the run stops once every skyrmion has travelled ``min_travel``
    diameters along its path, or at ``max_duration`` [s]. Half a diameter by default: long
    enough for the pair and edge laws to move every skyrmion by a distance that the RMS goal
    (0.1 d_sk) resolves five times over, and the LLG's time (the calibration's longest chain)
    is about 2.7 times shorter than for one diameter, since the skyrmions slow down as they
    part (S6: 0.45 ns against 1.2 ns).
    """

    skyrmions: int = Field(3, ge=1, le=7)
    #: the rectangle by default: its skyrmions feel the edges as well as each other, and its
    #: film has half the disk's cells (4 × 3 against 5 × 5 d_sk), so the LLG, the
    #: calibration's longest chain, takes half the time
    shape: Literal["disk", "rectangle"] = "rectangle"
    disk_radius: float = Field(2.5, ge=1.0, le=10.0)
    width: float = Field(4.0, ge=2.0, le=20.0)
    height: float = Field(3.0, ge=2.0, le=20.0)
    snapshot_interval: PositiveFloat = 50e-12
    min_travel: float = Field(0.5, gt=0, le=5.0)
    max_duration: PositiveFloat = 10e-9
    llg_tolerance: float = Field(1e-5, gt=0, lt=1e-2)


class CalibrationConfig(StrictModel):
    """Everything that decides a calibration's results (not how fast it runs).

    ``pair_range``: the pair law's distances [d_sk] from closest approach to the farthest;
    ``pair_distances``: how many pairs are relaxed across it (fewer: a coarser pair table and a
    faster calibration; tests that compare two calibrations use 5);
    ``torque_tolerance``: a relaxation stops below max|m × (m × H)| [A/m];
    ``mesh_check``: repeat the isolated skyrmion and one pair distance at half the cell size;
    ``validate``: run the micromagnetic many-skyrmion dynamics; ``compile``: magnum.np's
    compiled field terms (the same physics; the last bits differ, so a run resumes only with
    the setting it started with); ``reference_diameter``: the device whose interior the model
    is for [m] (see the module docstring).
    """

    material: MicromagneticMaterial
    reference_diameter: Length = REFERENCE_DIAMETER
    pair_range: tuple[float, float] = (1.0, 6.0)
    pair_distances: int = Field(PAIR_DISTANCES, ge=MIN_PAIR_DISTANCES, le=50)
    torque_tolerance: PositiveFloat = CALIBRATION_TORQUE_TOLERANCE
    mesh_check: bool = True
    validate_dynamics: bool = True
    validation: ValidationSpec = ValidationSpec()
    compile: bool = False

    @property
    def reference_field(self) -> float:
        """H_ref [A/m]: H_dev at the centre of a disk of the reference diameter."""
        h = 0.5 * self.material.film_thickness
        a = 0.5 * self.reference_diameter
        return self.material.saturation_magnetization * h / math.hypot(a, h)

    @model_validator(mode="after")
    def _ranges(self) -> CalibrationConfig:
        lo, hi = self.pair_range
        if not 0.6 <= lo < hi <= 12:
            raise ValueError(
                f"pair_range|{list(self.pair_range)}|two distances 0.6 ≤ closest < "
                "farthest ≤ 12 skyrmion diameters"
            )
        # the laws are for a device's interior: a device narrower than the film that one
        # skyrmion needs alone has none (its stray field would crush the skyrmion instead)
        side = isolated_side(self.material)
        if self.reference_diameter < side:
            raise ValueError(
                f"reference_diameter|{self.reference_diameter:g}|a device at least as wide as "
                f"the film one skyrmion of this material needs alone, {side:.3g} m (20 × the "
                "longer of the wall width and A/D)"
            )
        return self

    def seed(self) -> int:
        """0: a calibration is deterministic, nothing in it is random."""
        return 0  # deterministic: nothing random in a calibration


# -- the solves ---------------------------------------------------------------------------------
@dataclass(frozen=True)
class Template:
    """A starting profile: the isolated skyrmion's m_z(r) and helicity.

    m_z at ``radius`` [m] is ``mz``; the helicity [rad] is 0 or π: Néel, ±π/2: Bloch.
    """

    radius: tuple[float, ...]
    mz: tuple[float, ...]
    helicity: float


@dataclass(frozen=True)
class Relaxation:
    """One constrained relaxation: skyrmions with their guiding centres held at cell centres.

    The centres of the cells ``cores`` (none: the uniform film). They start from ``template`` scaled
    radially by ``scale`` or, without one, from the ansatz with radius ``radius`` and wall width
    ``width`` [m]; ``keep``: return the relaxed texture; ``cost``: expected wall time relative to a
    20 000-cell solve.
    """

    name: str
    film: Film
    cores: tuple[tuple[int, int], ...] = ()
    radius: float = 0.0
    width: float = 0.0
    template: Template | None = None
    scale: float = 1.0
    keep: bool = False
    cost: float = 1.0


@dataclass
class Stage:
    """A named group of solves."""

    name: str
    solves: list[Relaxation] = field(default_factory=list)


def odd(n: float) -> int:
    """The odd integer nearest to ``n`` (at least 3)."""
    k = max(3, int(round(n)))
    return k if k % 2 else k + 1


def _cost(film: Film, cell: float) -> float:
    """A solve's expected cost: cells, and iterations ∝ 1/cell (the stiffest mode)."""
    return film.nx * film.ny / 20_000 * cell / film.cell_size


def reference_film(
    config: CalibrationConfig,
    nx: int,
    ny: int,
    cell: float | None = None,
    disk: bool = False,
    offset: float = 0.0,
    real_left_edge: bool = False,
) -> Film:
    """A film in the reference environment (compensated, H_ref).

    ``offset`` [A/m] is added; with ``real_left_edge`` that edge keeps its stray field.
    """
    return Film(
        nx,
        ny,
        cell or config.material.cell_size,
        disk=disk,
        compensated=True,
        reference_field=config.reference_field + offset,
        real_left_edge=real_left_edge,
    )


def isolated_side(material: MicromagneticMaterial) -> float:
    """Side [m] of the first isolated-skyrmion film: 20 × the longer of Δ_eff and A/|D|."""
    return 20.0 * max(material.wall_width, material.dmi_length)


def isolated_film(
    config: CalibrationConfig,
    radius: float | None = None,
    scale: float = 1.0,
    cell: float | None = None,
    offset: float = 0.0,
) -> Film:
    """The square film of stage 1 (``radius``: the measured one, if known)."""
    material = config.material
    side = isolated_side(material)
    if radius is not None:
        side = max(side, ISOLATED_SIDE * radius)
    cell = cell or material.cell_size
    n = odd(scale * side / cell)
    return reference_film(config, n, n, cell, offset=offset)


def initial_radius(material: MicromagneticMaterial) -> float:
    """A first guess of the radius [m]: 2A/|D|.

    The radius of a skyrmion whose energy is dominated by exchange and DMI.
    """
    return 2.0 * material.dmi_length


def _centre(film: Film) -> tuple[int, int]:
    return (film.nx - 1) // 2, (film.ny - 1) // 2


def isolated_stage(
    config: CalibrationConfig, prefix: str, film: Film, template: Template | None = None
) -> Stage:
    """The isolated skyrmion and the uniform film, in ``film``."""
    material = config.material
    cost = _cost(film, material.cell_size)
    width = max(material.bare_wall_width, 2 * film.cell_size)
    return Stage(
        prefix,
        [
            Relaxation(f"{prefix}/uniform", film, (), keep=True, cost=0.1 * cost),
            Relaxation(
                f"{prefix}/single",
                film,
                (_centre(film),),
                initial_radius(material),
                width,
                template,
                keep=True,
                cost=cost,
            ),
        ],
    )


def calibration_film(
    config: CalibrationConfig,
    diameter: float,
    pair_range: tuple[float, float],
    cell: float | None = None,
    real_left_edge: bool = False,
    margin: float = PAIR_MARGIN,
    height: float = FILM_HEIGHT,
    offset: float = 0.0,
) -> Film:
    """The stage-2 film: (farthest pair + 2 ``margin``) × ``height`` diameters, odd cells.

    ``offset`` [A/m] is added to the reference field.
    """
    cell = cell or config.material.cell_size
    width = (pair_range[1] + 2 * margin) * diameter
    return reference_film(
        config,
        odd(width / cell),
        odd(height * diameter / cell),
        cell,
        offset=offset,
        real_left_edge=real_left_edge,
    )


def pair_cells(
    film: Film, diameter: float, pair_range: tuple[float, float], count: int = PAIR_DISTANCES
) -> list[int]:
    """Cells i of the pairs (i, nx − 1 − i), for ``count`` distances across ``pair_range`` [d_sk].

    From the closest to the farthest, denser at short range where the law changes fastest.
    """
    lo, hi = pair_range
    targets = np.exp(np.linspace(math.log(lo), math.log(hi), count)) * diameter
    cells = sorted(
        {int(round((film.nx - 1 - d / film.cell_size) / 2)) for d in targets}, reverse=True
    )
    return [i for i in cells if 0 <= i < (film.nx - 1) // 2]


def edge_cells(film: Film, diameter: float, grid=EDGE_GRID) -> list[int]:
    """Cells i of the singles at distances ``grid`` [d_sk] from the left edge."""
    cells = {int(round(x * diameter / film.cell_size - 0.5)) for x in grid}
    return sorted(i for i in cells if 0 <= i <= (film.nx - 1) // 2)


def _pair(
    name: str, film: Film, i: int, template: Template, radius: float, width: float, cost: float
) -> Relaxation:
    row = (film.ny - 1) // 2
    d = (film.nx - 1 - 2 * i) * film.cell_size
    # two full profiles overlapping at close range would merge: start them smaller
    scale = min(1.0, max(0.5 * d - width, 2 * film.cell_size) / radius)
    return Relaxation(
        name,
        film,
        ((i, row), (film.nx - 1 - i, row)),
        radius,
        width,
        template,
        scale,
        cost=1.2 * cost,
    )


def laws_stage(config: CalibrationConfig, radius: float, width: float, template: Template) -> Stage:
    """Stage 2: the calibration film's uniform state, singles and pairs."""
    diameter = 2 * radius
    film = calibration_film(config, diameter, config.pair_range)
    row = (film.ny - 1) // 2
    pairs = pair_cells(film, diameter, config.pair_range, config.pair_distances)
    singles = sorted(set(edge_cells(film, diameter)) | set(pairs) | {(film.nx - 1) // 2})
    cost = _cost(film, config.material.cell_size)
    stage = Stage("laws", [Relaxation("laws/uniform", film, (), cost=0.1 * cost)])
    for i in singles:
        stage.solves.append(
            Relaxation(f"laws/single/{i}", film, ((i, row),), radius, width, template, cost=cost)
        )
    for i in pairs:
        stage.solves.append(_pair(f"laws/pair/{i}", film, i, template, radius, width, cost))
    return stage


def sensitivity_stage(config: CalibrationConfig, film: Film, template: Template) -> Stage:
    """The isolated skyrmion at H_ref ± SENSITIVITY_STEP/μ₀: how its size follows the field.

    With the uniform film at each field (the breathing scan's first two points; the textures are
    kept for 𝒟_RR).
    """
    stage = Stage("sensitivity")
    for sign, label in ((1, "plus"), (-1, "minus")):
        stage.solves += _scan_point(config, film, template, sign * SENSITIVITY_STEP, label)
    return stage


def _scan_point(
    config: CalibrationConfig,
    film: Film,
    template: Template,
    field_T: float,
    label: str,
    scale: float = 1.0,
) -> list[Relaxation]:
    """The isolated skyrmion (kept) and the uniform film at H_ref + ``field_T``/μ₀."""
    cost = _cost(film, config.material.cell_size)
    shifted = reference_film(config, film.nx, film.ny, film.cell_size, offset=field_T / MU_0)
    return [
        Relaxation(
            f"sensitivity/{label}",
            shifted,
            (_centre(shifted),),
            template=template,
            scale=scale,
            keep=True,
            cost=cost,
        ),
        Relaxation(f"sensitivity/uniform/{label}", shifted, (), cost=0.1 * cost),
    ]


def measured_slope(plus: dict | None, minus: dict | None, radius: float) -> float | None:
    """The slope d ln R/dB [1/T] of the sensitivity solves; None unless both hold one skyrmion."""
    if plus is None or minus is None:
        return None
    if len(plus["skyrmions"]) != 1 or len(minus["skyrmions"]) != 1:
        return None
    r_plus, r_minus = plus["skyrmions"][0]["radius"], minus["skyrmions"][0]["radius"]
    return (r_plus - r_minus) / (2 * SENSITIVITY_STEP) / radius


def scan_fields(slope: float) -> list[tuple[float, float]]:
    """(field offset [T], aimed relative radius change) of the breathing scan.

    For ``slope`` = d ln R/dB [1/T] (< 0 for a skyrmion whose core opposes the field; none
    otherwise); offsets capped at ±:data:`SCAN_MAX_FIELD`.
    """
    if not (math.isfinite(slope) and slope < 0):
        return []
    return [
        (max(-SCAN_MAX_FIELD, min(SCAN_MAX_FIELD, target / slope)), target)
        for target in SCAN_TARGETS
    ]


def shifted_field(slope: float) -> float | None:
    """The scan's offset [T] that aims at :data:`SHIFTED_TARGET`; None without a scan."""
    for field_T, target in scan_fields(slope):
        if target == SHIFTED_TARGET:
            return field_T
    return None


def scan_stage(config: CalibrationConfig, film: Film, template: Template, slope: float) -> Stage:
    """The breathing scan beyond ±SENSITIVITY_STEP: ``sensitivity/scan/k`` and their uniforms.

    Each starts from the template scaled to the radius it aims at.
    """
    stage = Stage("sensitivity")
    for k, (field_T, target) in enumerate(scan_fields(slope)):
        stage.solves += _scan_point(config, film, template, field_T, f"scan/{k}", 1.0 + target)
    return stage


def shifted_stage(
    config: CalibrationConfig, radius: float, width: float, template: Template, field_T: float
) -> Stage:
    """The laws at a second radius: the calibration film at H_ref + ``field_T``/μ₀.

    Its uniform state, the single at its centre, singles at :data:`SHIFTED_EDGE_GRID` from the
    left edge and pairs at :data:`SHIFTED_PAIR_GRID` (their singles are not solved: the pair
    energy takes the centre single's, corrected by the edge law, see
    :mod:`skygas.calibration.breathing`).
    """
    diameter = 2 * radius
    film = calibration_film(config, diameter, config.pair_range, offset=field_T / MU_0)
    row = (film.ny - 1) // 2
    centre = (film.nx - 1) // 2
    cost = _cost(film, config.material.cell_size)
    scale = 1.0 + SHIFTED_TARGET
    stage = Stage("shifted", [Relaxation("shifted/uniform", film, (), cost=0.1 * cost)])
    for i in sorted(set(edge_cells(film, diameter, SHIFTED_EDGE_GRID)) | {centre}):
        stage.solves.append(
            Relaxation(
                f"shifted/single/{i}", film, ((i, row),), radius, width, template, scale, cost=cost
            )
        )
    pairs = {round((film.nx - 1 - d * diameter / film.cell_size) / 2) for d in SHIFTED_PAIR_GRID}
    for i in sorted(p for p in pairs if 0 <= p < centre):
        pair = _pair(f"shifted/pair/{i}", film, i, template, radius, width, cost)
        stage.solves.append(replace(pair, scale=pair.scale * scale))
    return stage


def breathing_solves(
    config: CalibrationConfig,
    radius: float,
    width: float,
    template: Template,
    isolated: Film,
    slope: float,
) -> list[Relaxation]:
    """The breathing scan and the laws at a second radius, for d ln R/dB = ``slope`` [1/T]."""
    solves = scan_stage(config, isolated, template, slope).solves
    field_T = shifted_field(slope)
    if field_T is not None:
        solves += shifted_stage(config, radius, width, template, field_T).solves
    return solves


def stray_check_stage(
    config: CalibrationConfig, radius: float, width: float, template: Template
) -> Stage:
    """Singles near the real left edge of the calibration film, to check the stray-field energy.

    The film's compensation leaves that straight edge's stray field; with its uniform state and its
    centre single, they check the model's first-order stray-field energy.
    """
    diameter = 2 * radius
    film = calibration_film(config, diameter, config.pair_range, real_left_edge=True)
    row = (film.ny - 1) // 2
    cost = _cost(film, config.material.cell_size)
    stage = Stage("stray", [Relaxation("stray/uniform", film, (), cost=0.1 * cost)])
    for i in sorted(set(edge_cells(film, diameter, STRAY_CHECK_GRID)) | {(film.nx - 1) // 2}):
        stage.solves.append(
            Relaxation(f"stray/single/{i}", film, ((i, row),), radius, width, template, cost=cost)
        )
    return stage


def mesh_stage(config: CalibrationConfig, radius: float, width: float, template: Template) -> Stage:
    """The mesh check: a pair at ≈ 1.5 d_sk at the calibration's cell and at half of it.

    The pair, its single and the uniform film at each cell (the single is also the isolated skyrmion
    of the comparison).
    """
    stage = Stage("mesh")
    diameter = 2 * radius
    for label, cell in (
        ("coarse", config.material.cell_size),
        ("fine", 0.5 * config.material.cell_size),
    ):
        # a smaller film than the laws': the check compares two meshes in the same film
        film = calibration_film(config, diameter, (1.5, 1.5), cell, margin=1.0, height=2.5)
        row = (film.ny - 1) // 2
        i = int(round((film.nx - 1 - 1.5 * diameter / cell) / 2))
        cost = _cost(film, config.material.cell_size)
        stage.solves += [
            Relaxation(f"mesh/{label}/uniform", film, (), cost=0.1 * cost),
            Relaxation(
                f"mesh/{label}/single", film, ((i, row),), radius, width, template, cost=cost
            ),
            _pair(f"mesh/{label}/pair", film, i, template, radius, width, cost),
        ]
    return stage


def enlarged_stage(config: CalibrationConfig, radius: float, template: Template) -> Stage:
    """The isolated skyrmion again in a film 1.25 times larger (were the edges far enough?)."""
    return isolated_stage(config, "enlarged", isolated_film(config, radius, scale=1.25), template)


def validation_film(config: CalibrationConfig, diameter: float) -> Film:
    """The validation's film, in the reference environment.

    A disk of ``disk_radius`` diameters in a square mesh of odd side, or a rectangle of
    ``width`` × ``height`` diameters (odd numbers of cells).
    """
    v, cell = config.validation, config.material.cell_size
    if v.shape == "rectangle":
        nx, ny = odd(v.width * diameter / cell), odd(v.height * diameter / cell)
        return reference_film(config, nx, ny)
    n = odd(2 * v.disk_radius * diameter / cell)
    return reference_film(config, n, n, disk=True)


#: The rectangle's default three skyrmions [diameters from its lower-left corner; the third's y
#: from its top edge]: 1.3–1.4 apart, each 0.8–0.95 from one edge (two by the bottom edge, one
#: by the top) and at least 1.3 from any other, so that each slides along its edge. Not in a
#: corner: there the two edges and the neighbours balance, and an S2 skyrmion 0.8 from two
#: edges moved 0.03 d_sk in 1.25 ns of LLG while the others moved 0.15–0.21.
RECTANGLE_TRIANGLE = ((1.3, 0.8), (2.6, 0.9), (1.9, -0.95))
#: Closest start to a rectangle's edges [diameters]: near enough that the edge law acts.
RECTANGLE_MARGIN = 0.8


def _gaps(points) -> list[float]:
    """The distances between every two of ``points`` [m]."""
    return [math.dist(a, b) for k, a in enumerate(points) for b in points[k + 1 :]]


def _spaced(points, diameter: float) -> bool:
    """Whether the closest two of ``points`` are 1.3–1.8 diameters apart (or there is one)."""
    gaps = _gaps(points)
    return not gaps or 1.3 * diameter <= min(gaps) <= 1.8 * diameter


def _rectangle_positions(film: Film, diameter: float, count: int) -> list[tuple[float, float]]:
    """:func:`validation_positions` in a rectangle."""
    width, height = film.size
    if count == 3:
        points = [
            (u * diameter, (v if v > 0 else height / diameter + v) * diameter)
            for u, v in RECTANGLE_TRIANGLE
        ]
        margin = RECTANGLE_MARGIN * diameter - 1e-12
        inside = all(
            margin <= x <= width - margin and margin <= y <= height - margin for x, y in points
        )
        if inside and min(_gaps(points)) >= 1.29 * diameter:
            return points
    margin = RECTANGLE_MARGIN * diameter
    rng = np.random.default_rng(54321 + count)
    for _ in range(20_000 if width > 2 * margin and height > 2 * margin else 0):
        xs = margin + (width - 2 * margin) * rng.random(count)
        ys = margin + (height - 2 * margin) * rng.random(count)
        points = list(zip(xs, ys, strict=True))
        if _spaced(points, diameter):
            return [(float(x), float(y)) for x, y in points]
    from skygas.core.errors import InputError

    raise InputError(
        "validation.width",
        width / diameter,
        f"a rectangle large enough for {count} skyrmions 1.3 diameters apart and "
        f"{RECTANGLE_MARGIN:g} from its edges",
    )


def validation_positions(film: Film, diameter: float, count: int) -> list[tuple[float, float]]:
    """Fixed, asymmetric starting positions [m] of the validation's skyrmions.

    Skyrmions 1.3–1.8 diameters apart and at least 0.9 diameters from a disk's rim (0.8 from a
    rectangle's edges), drawn once from a fixed seed (the same for every run of the same size);
    three of them have fixed places (:data:`RECTANGLE_TRIANGLE` in a rectangle).
    """
    if not film.disk:
        return _rectangle_positions(film, diameter, count)
    cx, cy = 0.5 * film.size[0], 0.5 * film.size[1]
    reach = film.radius - 0.9 * diameter
    if count == 3:  # the default: an irregular triangle, off the disk's centre
        # 1.3–1.4 diameters apart: close enough that they move a diameter in a few ns
        unit = [(-0.75, -0.25), (0.5, -0.55), (0.05, 0.8)]
        points = [(cx + u * diameter, cy + v * diameter) for u, v in unit]
        if all(math.hypot(x - cx, y - cy) <= reach for x, y in points):
            return points
    rng = np.random.default_rng(12345 + count)
    for _ in range(20_000):
        r = reach * np.sqrt(rng.random(count))
        phi = 2 * math.pi * rng.random(count)
        points = list(zip(cx + r * np.cos(phi), cy + r * np.sin(phi), strict=True))
        if reach > 0 and _spaced(points, diameter):
            return [(float(x), float(y)) for x, y in points]
    from skygas.core.errors import InputError

    raise InputError(
        "validation.disk_radius",
        film.radius / diameter,
        f"a disk large enough for {count} skyrmions 1.3 diameters apart",
    )


def validation_start(
    config: CalibrationConfig, radius: float, width: float, template: Template
) -> Relaxation:
    """The validation's starting state: its skyrmions relaxed with their guiding centres held."""
    film = validation_film(config, 2 * radius)
    points = validation_positions(film, 2 * radius, config.validation.skyrmions)
    cores = tuple(film.cell_of(x, y) for x, y in points)
    return Relaxation(
        "validation/start",
        film,
        cores,
        radius,
        width,
        template,
        keep=True,
        cost=_cost(film, config.material.cell_size),
    )


def sized_solves(
    config: CalibrationConfig, radius: float, width: float, template: Template, isolated: Film
) -> list[Relaxation]:
    """Every relaxation planned once the isolated skyrmion's size is known.

    The laws, the film-size and field-sensitivity checks (on ``isolated``, the isolated
    skyrmion's film), the edge stray field, the mesh check (``config.mesh_check``) and the
    validation's start (``config.validate_dynamics``), in that order.
    """
    solves = laws_stage(config, radius, width, template).solves
    solves += enlarged_stage(config, radius, template).solves
    solves += sensitivity_stage(config, isolated, template).solves
    solves += stray_check_stage(config, radius, width, template).solves
    if config.mesh_check:
        solves += mesh_stage(config, radius, width, template).solves
    if config.validate_dynamics:
        solves.append(validation_start(config, radius, width, template))
    return solves
