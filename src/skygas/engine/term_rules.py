"""The rules a force term carries with it, beside its kernel record.

The compiled kernel adds a fixed set of force records (:class:`~skygas.engine.terms.ForceTerms`),
as numba wants. What the Python side must know about a term lives here, in one descriptor per
term (:class:`TermRules`): the pair law, the wall law, the current's drift, the energy landscape
and the uniform external force. A new term cannot forget one of its rules:

- :meth:`record`: the record the kernel reads (internal units), and :meth:`parameters`, its
  entry in :meth:`Simulation.parameters() <skygas.engine.Simulation.parameters>` (SI);
- :meth:`speed_bound`: the largest speed [nm/ns] it gives a free skyrmion, which sizes the
  neighbour list's margins (a term that moves skyrmions faster than the margins allow makes
  the list rebuild every few steps);
- :meth:`stiffness`: its largest force gradient [pN/nm], which bounds the time step
  (τ = friction/stiffness, docs/physics.md §5);
- :meth:`per_step`: how far it moves a free skyrmion in one step, in diameters, for the sanity
  check that every command runs before a run (``skygas.runs.sanity``), which names the term by
  its ``config_field`` (``None``: the term is checked elsewhere, or moves no free skyrmion).

:class:`~skygas.engine.Simulation` holds its descriptors in ``term_rules``; the neighbour
list's margins add up their speed bounds, and the time step is limited by the largest
stiffness (:func:`~skygas.engine.force_model.relaxation_time`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any, ClassVar, Protocol

import numpy as np

from skygas.core import units
from skygas.engine import terms as T
from skygas.engine.force_model import law_stiffness
from skygas.engine.terms import ConstantForceTerm, Mobility

if TYPE_CHECKING:
    from skygas.fields.landscape import LandscapeField
    from skygas.physics.forces import ForceTable


class TermRules(Protocol):
    """What every force term's descriptor provides (see the module docstring)."""

    #: the term's name
    name: ClassVar[str]
    #: the configuration field that sets it, which the sanity check names, or ``None``
    config_field: ClassVar[str | None]

    def record(self) -> Any:
        """The record the kernel reads (internal units)."""
        ...

    def setting(self) -> Any:
        """The term's value as a configuration gives it."""
        ...

    def parameters(self) -> dict[str, Any]:
        """Its entries in ``Simulation.parameters()`` (SI, JSON-able)."""
        ...

    def speed_bound(self, mobility: Mobility) -> float:
        """The largest speed [nm/ns] it gives a free skyrmion."""
        ...

    def stiffness(self) -> float:
        """Its largest force gradient [pN/nm]."""
        ...

    def per_step(self, mobility: Mobility, dt_ns: float, diameter_nm: float) -> float:
        """Diameters a free skyrmion moves in one step under this term alone."""
        ...


@dataclass(frozen=True)
class _MovesNoFreeSkyrmion:
    """Rules shared by the terms that exert no force on a lone skyrmion away from walls and gates.

    No speed bound, nothing for the per-step check.
    """

    def speed_bound(self, mobility: Mobility) -> float:
        """0 [nm/ns]: the term does not move a free skyrmion."""
        return 0.0

    def per_step(self, mobility: Mobility, dt_ns: float, diameter_nm: float) -> float:
        """0 diameters per step (see :meth:`speed_bound`)."""
        return 0.0


@dataclass(frozen=True)
class PairLaw(_MovesNoFreeSkyrmion):
    """The pair repulsion F(r) between skyrmions, tabulated (docs/physics.md §2).

    Parameters
    ----------
    law
        The law's resolved name (``"paper"``, ``"lin-reichhardt"``, ``"table"``).
    table
        Its table in internal units (squared layout, cut off at ``table.cutoff`` [nm]).
    params, cutoff_fraction
        The law's parameters and the cutoff's fraction of F₀, as configured.
    closest
        Distance [nm] below which the law is not valid and its slope does not count.
    """

    law: str
    table: ForceTable
    params: dict = field(default_factory=dict)
    cutoff_fraction: float = 0.0
    closest: float = 0.0

    name: ClassVar[str] = "pair_law"
    config_field: ClassVar[str | None] = None

    def record(self) -> T.PairTerm:
        """The kernel's :class:`~skygas.engine.terms.PairTerm`."""
        return T.pair_term(self.table)

    def setting(self) -> str:
        """The law's name."""
        return self.law

    def parameters(self) -> dict[str, Any]:
        """The law, its parameters, the cutoff fraction and the cutoff distance [m]."""
        return {
            "pair_law": self.law,
            "pair_law_params": self.params,
            "cutoff_fraction": self.cutoff_fraction,
            "pair_cutoff_m": self.table.cutoff / units.M_TO_NM,
        }

    def stiffness(self) -> float:
        """The largest |dF/dr| [pN/nm] beyond :attr:`closest`."""
        return law_stiffness(self.table, self.law, self.closest)


@dataclass(frozen=True)
class WallLaw(_MovesNoFreeSkyrmion):
    """The repulsion F(d) of the walls at distance d, tabulated (docs/physics.md §2).

    Parameters
    ----------
    law
        The law's resolved name (``"paper"`` or ``"table"``).
    table
        Its table in internal units, cut off at ``table.cutoff`` [nm].
    closest
        Distance [nm] below which the law is not valid and its slope does not count.
    geometry
        ``"nearest"``: the law acts along the nearest wall's normal (this term's record);
        ``"film"``: it acts as the missing film's field (:class:`~skygas.engine.terms.
        WallFilmTerm`), and this term's record carries a zero table (its cutoff still bounds
        the walls' reach, and its slopes the step).
    """

    law: str
    table: ForceTable
    closest: float = 0.0
    geometry: str = "nearest"

    name: ClassVar[str] = "wall_law"
    config_field: ClassVar[str | None] = None

    def record(self) -> T.WallTerm:
        """The kernel's :class:`~skygas.engine.terms.WallTerm`."""
        term = T.wall_term(self.table)
        if self.geometry == "film":
            return term._replace(table=np.zeros_like(term.table))
        return term

    def setting(self) -> str:
        """The law's name."""
        return self.law

    def parameters(self) -> dict[str, Any]:
        """The law, its cutoff distance [m] and how it meets the outline."""
        return {
            "wall_law": self.law,
            "wall_cutoff_m": self.table.cutoff / units.M_TO_NM,
            "wall_geometry": self.geometry,
        }

    def stiffness(self) -> float:
        """The largest |dF/dr| [pN/nm] beyond :attr:`closest`."""
        return law_stiffness(self.table, self.law, self.closest)


@dataclass(frozen=True)
class CurrentDrift:
    """The spin current's drive μ(g ε + b I)·v_s, with v_s uniform or on the field grid.

    Parameters
    ----------
    term
        The kernel's :class:`~skygas.engine.terms.DriftTerm`.
    max_speed
        The largest |v_s| [nm/ns = m/s]: the uniform one, or the largest on the grid.

    The sanity check of a drift per step reads the configuration's current (the largest a
    device switches to), so ``config_field`` is ``None`` here.
    """

    term: T.DriftTerm
    max_speed: float = 0.0

    name: ClassVar[str] = "drift_velocity"
    config_field: ClassVar[str | None] = None

    def record(self) -> T.DriftTerm:
        """The kernel's :class:`~skygas.engine.terms.DriftTerm`."""
        return self.term

    def setting(self) -> str | list[float]:
        """``"field"`` for a drift field on the grid, else the uniform (v_x, v_y) [m/s]."""
        return "field" if self.term.from_grid else [self.term.vs_x, self.term.vs_y]

    def parameters(self) -> dict[str, Any]:
        """The drift, as :meth:`setting` gives it."""
        return {"drift": self.setting()}

    def speed_bound(self, mobility: Mobility) -> float:
        """|M·D·v_s| [nm/ns] at the largest |v_s|: both matrices are scaled rotations."""
        drive = math.hypot(self.term.drive_g, self.term.drive_b)
        return self.max_speed * drive * math.hypot(mobility.a, mobility.g)

    def stiffness(self) -> float:
        """0 [pN/nm]: the drive does not depend on the skyrmion's displacement."""
        return 0.0

    def per_step(self, mobility: Mobility, dt_ns: float, diameter_nm: float) -> float:
        """Diameters a free skyrmion drifts in one step at the largest |v_s|."""
        return self.speed_bound(mobility) * dt_ns / diameter_nm


@dataclass(frozen=True)
class Landscape(_MovesNoFreeSkyrmion):
    """The energy landscape U(x, y): its force −∇U (docs/physics.md §1).

    Parameters
    ----------
    landscape
        The :class:`~skygas.fields.landscape.LandscapeField` (every potential, summed).
    time_step_counts
        Whether its curvature limits the suggested time step. The landscape's curvature
        always bounds the largest accepted step; the *suggested* step counts it only when
        the material's edge stray field is in it, so that runs without it keep the step they
        always had.

    Its forces act where potentials are steep; a free skyrmion far from them feels none, so
    it has no speed bound (its curvature bounds the step instead).
    """

    landscape: LandscapeField
    time_step_counts: bool = True

    name: ClassVar[str] = "potentials"
    config_field: ClassVar[str | None] = None

    def record(self) -> T.LandscapeTerm:
        """The kernel's :class:`~skygas.engine.terms.LandscapeTerm`."""
        return T.landscape_term(self.landscape)

    def setting(self) -> list[dict]:
        """The potentials, described."""
        return self.landscape.describe()

    def parameters(self) -> dict[str, Any]:
        """The potentials, described."""
        return {"landscape": self.landscape.describe()}

    def stiffness(self) -> float:
        """The largest curvature |∂²U| [pN/nm] on the grid."""
        return self.landscape.max_curvature()


@dataclass(frozen=True)
class ConstantForce:
    """A uniform external force F = (F_x, F_y) [N] on every skyrmion.

    The force of a magnetic field gradient on the skyrmion's moment, or of gravity-like tilts of
    the energy (a film whose thickness or anisotropy varies linearly). It enters the Thiele
    equation beside the other forces, so a free skyrmion moves at v = M·F (M the mobility,
    docs/physics.md §1): at the angle of the skyrmion Hall effect to F.
    """

    force: tuple[float, float] = (0.0, 0.0)

    #: the configuration's name of the term (``[forces] external_force = [F_x, F_y]``)
    name: ClassVar[str] = "external_force"
    config_field: ClassVar[str | None] = "forces.external_force"

    def record(self) -> ConstantForceTerm:
        """The kernel's :class:`~skygas.engine.terms.ConstantForceTerm` [pN]."""
        return ConstantForceTerm(self.force[0] * units.N_TO_PN, self.force[1] * units.N_TO_PN)

    def setting(self) -> list[float]:
        """The force as a configuration gives it, (F_x, F_y) [N]."""
        return [float(self.force[0]), float(self.force[1])]

    def parameters(self) -> dict[str, list[float]]:
        """The force [N]."""
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


#: Nodes of the self force's table over the radius range (linear interpolation between them).
RADIUS_TABLE_NODES = 1024
#: The exponential step's weights are tabulated for z = λ dt in [0, PHI_Z_MAX] at this many
#: nodes (spacing 0.005: their linear interpolation is within 3·10⁻⁶ of the closed forms);
#: past it, e^{−z} < 10⁻¹⁷ and the forms without it hold.
PHI_Z_MAX = 40.0
PHI_Z_NODES = 8001


def step_weights(z: np.ndarray) -> np.ndarray:
    """(3, len(z)): φ₁ = (1 − e^{−z})/z, φ₂ = (e^{−z} − 1 + z)/z², √φ_σ, φ_σ = (1 − e^{−2z})/2z.

    The weights of the radius's exponential step (:func:`skygas.engine.stages.radius_predictor`),
    with their Taylor series below z = 10⁻³ (where the closed forms lose digits).
    """
    z = np.asarray(z, float)
    small = z < 1e-3
    safe = np.where(small, 1.0, z)
    decay = np.exp(-safe)
    phi1 = np.where(small, 1 - z / 2 + z**2 / 6 - z**3 / 24, -np.expm1(-safe) / safe)
    phi2 = np.where(small, 0.5 - z / 6 + z**2 / 24 - z**3 / 120, (decay - 1 + safe) / safe**2)
    phis = np.where(small, 1 - z + 2 * z**2 / 3 - z**3 / 3, -np.expm1(-2 * safe) / (2 * safe))
    return np.array([phi1, phi2, np.sqrt(phis)])


@dataclass(frozen=True)
class Breathing(_MovesNoFreeSkyrmion):
    """The radius of each skyrmion as a degree of freedom (docs/physics.md §2), or rigid ones.

    Parameters
    ----------
    spec
        The material's :class:`~skygas.physics.materials.BreathingSpec`, or ``None`` for rigid
        skyrmions (the record is :data:`~skygas.engine.terms.RIGID`, nothing else counts).
    radius0
        R₀ [m], the material's isolated radius, which the laws were measured at.
    radius_dissipation
        𝒟_RR (dimensionless): the spec's, or the thin-wall estimate the caller made.
    k
        M_s t_F/γ [kg/s]; with the damping α, Γ_R = α 𝒟_RR k.
    damping
        α.
    temperature
        T [K].
    closest
        The smallest gap [nm] the pair law is read at.
    pair_stiffness, wall_stiffness
        The laws' largest slopes [pN/nm] beyond the closest approach (as the centres count
        them, :class:`PairLaw`, :class:`WallLaw`).
    """

    spec: Any = None
    radius0: float = 0.0
    radius_dissipation: float = 0.0
    k: float = 0.0
    damping: float = 0.0
    temperature: float = 0.0
    closest: float = 0.0
    pair_stiffness: float = 0.0
    wall_stiffness: float = 0.0
    #: the edge stray field U_s alone, which the radius feels through a(R) (None: no stray field)
    stray: Any = None
    #: the centre's 𝒟 at R₀ (the material's) and G [kg/s]: with the spec's 𝒟(R) table, the
    #: centre's mobility at each radius
    dissipation: float = 0.0
    gyrocoupling: float = 0.0

    name: ClassVar[str] = "breathing"
    config_field: ClassVar[str | None] = None

    @property
    def active(self) -> bool:
        """True for a breathing model."""
        return self.spec is not None

    @property
    def friction(self) -> float:
        """Γ_R = α 𝒟_RR k [kg/s]."""
        return self.damping * self.radius_dissipation * self.k

    @property
    def growth(self) -> float:
        """How much larger [nm] than R₀ a radius may grow: the table's end less R₀ (0 if rigid)."""
        if not self.active:
            return 0.0
        return max(self.spec.radius[-1] * units.M_TO_NM - self.radius0 * units.M_TO_NM, 0.0)

    @property
    def wall_reach(self) -> float:
        """How much farther [nm] the wall law reaches a skyrmion than at R₀: s_w times growth."""
        return float(self.spec.wall_shift) * self.growth if self.active else 0.0

    @property
    def mobility_varies(self) -> bool:
        """True when the centre's 𝒟 follows the radius (the spec's ``dissipation`` table)."""
        return self.active and self.spec.dissipation is not None

    @cached_property
    def _centre_scale(self) -> np.ndarray:
        """c(R) = 𝒟(R)/𝒟(R₀) at the radii of the kernel's tables (the self force's grid)."""
        _, _, spacing, r_min, _ = self._self_force()
        grid = r_min + spacing * np.arange(RADIUS_TABLE_NODES)
        return self.spec.dissipation_ratio(self.radius0 * units.M_TO_NM, units.M_TO_NM)(grid)

    def _centre_mobility(self) -> np.ndarray:
        """The kernel's mobility rows (:class:`~skygas.engine.terms.BreathingTerm`).

        With a = α𝒟k and g = G (internal units), M(R) = (a(R) I − g ε)/(a(R)² + g²), the
        inverse of (g ε + a(R) I), in the kernel's components A = a/(a² + g²),
        G = g/(a² + g²), a(R) = c(R) a₀. A velocity v = M₀F becomes
        M(R)M₀⁻¹v = P v − Q εv with P = (A_R A₀ + G_R G₀)/(A₀² + G₀²) and
        Q = (G_R A₀ − A_R G₀)/(A₀² + G₀²), since M₀⁻¹ = a₀ I + g ε.
        """
        if not self.mobility_varies:
            return T.RIGID.mobility
        c = self._centre_scale
        a0 = self.damping * self.dissipation * self.k * units.KG_PER_S_TO_INTERNAL
        g = self.gyrocoupling * units.KG_PER_S_TO_INTERNAL
        a = c * a0
        big_a0, big_g0 = a0 / (a0 * a0 + g * g), g / (a0 * a0 + g * g)
        big_a, big_g = a / (a * a + g * g), g / (a * a + g * g)
        norm = big_a0 * big_a0 + big_g0 * big_g0
        p = (big_a * big_a0 + big_g * big_g0) / norm
        q = (big_g * big_a0 - big_a * big_g0) / norm
        # D ∝ a/(a² + g²) = A
        return np.array([p, q, big_a, big_g, c - 1.0, np.sqrt(big_a / big_a0)])

    @property
    def mobility_gain(self) -> float:
        """Max over the table of |M(R)|/|M(R₀)| = √(a₀² + g²)/√(a(R)² + g²) (1 without 𝒟(R)).

        The centres' fastest relaxation speeds up by it where 𝒟(R) is smallest; the time step
        counts it (:meth:`skygas.engine.Simulation.relaxation_time`).
        """
        if not self.mobility_varies:
            return 1.0
        a0 = self.damping * self.dissipation * self.k
        g = self.gyrocoupling
        return float(max(1.0, np.max(math.hypot(a0, g) / np.hypot(self._centre_scale * a0, g))))

    def _self_force(self) -> tuple[np.ndarray, np.ndarray, float, float, float]:
        """−dE_self/dR [pN] and E_self'' [pN/nm] on a uniform grid; its spacing, r_min, r_max [nm].

        The energy is interpolated with a not-a-knot cubic spline: its curvature is continuous
        (the integrator's linear part, :func:`skygas.engine.stages.radius_predictor`, follows
        it), and a harmonic table is reproduced exactly.
        """
        from scipy.interpolate import CubicSpline

        radius = np.asarray(self.spec.radius, float) * units.M_TO_NM
        energy = np.asarray(self.spec.energy, float) * units.J_TO_PN_NM
        grid = np.linspace(radius[0], radius[-1], RADIUS_TABLE_NODES)
        spline = CubicSpline(radius, energy)
        force = -spline.derivative()(grid)
        curvature = spline.derivative(2)(grid)
        return force, curvature, float(grid[1] - grid[0]), float(radius[0]), float(radius[-1])

    def record(self) -> T.BreathingTerm:
        """The kernel's :class:`~skygas.engine.terms.BreathingTerm`."""
        if not self.active:
            return T.RIGID
        force, curvature, spacing, r_min, r_max = self._self_force()
        # the edge stray field's scale a(R) and its derivatives on the self force's grid
        grid = r_min + spacing * np.arange(len(force))
        area = self.spec.area_ratio(self.radius0 * units.M_TO_NM, units.M_TO_NM)
        scale, slope, bend = (f(grid) for f in area)
        r0 = self.radius0 * units.M_TO_NM
        spec = self.spec
        z = np.linspace(0.0, PHI_Z_MAX, PHI_Z_NODES)
        return T.BreathingTerm(
            True,
            r0,
            r_min,
            r_max,
            force,
            curvature,
            spacing,
            step_weights(z),
            float(z[1] - z[0]),
            1.0 / (self.friction * units.KG_PER_S_TO_INTERNAL),
            units.thermal_energy_internal(self.temperature),
            float(spec.pair_shift),
            float(spec.wall_shift),
            2.0 * float(spec.pair_shift) * self.growth,
            self.wall_reach,
            self.closest,
            scale - 1.0,
            slope,
            bend,
            T.RIGID.stray if self.stray is None else self.stray,
            self.mobility_varies,
            self._centre_mobility(),
        )

    def setting(self) -> str:
        """``"breathing"`` or ``"rigid"``."""
        return "breathing" if self.active else "rigid"

    def parameters(self) -> dict[str, Any]:
        """The model, and for a breathing one Γ_R [kg/s], 𝒟_RR, s_p, s_w, the radius range [m]."""
        if not self.active:
            return {}
        out: dict[str, Any] = {
            "particle_model": "breathing",
            "radius_friction_kg_per_s": self.friction,
            "radius_dissipation": self.radius_dissipation,
            "pair_shift": float(self.spec.pair_shift),
            "wall_shift": float(self.spec.wall_shift),
            "radius_range_m": [float(self.spec.radius[0]), float(self.spec.radius[-1])],
        }
        if self.mobility_varies:  # the centre's 𝒟 follows the radius
            out["centre_dissipation_range"] = [
                float(min(self.spec.dissipation)),
                float(max(self.spec.dissipation)),
            ]
        return out

    def stiffness(self) -> float:
        """2 max(s_p κ_pair, s_w κ_wall) [pN/nm]: the laws through the radii, for the step.

        The radius's own relaxation never limits the step: its step
        (:func:`skygas.engine.stages.radius_predictor`) takes the radius's whole stiffness,
        E_self'' plus s² times the slopes of the laws it touches, into the exactly integrated
        linear part, and what stays explicit there, the couplings to the neighbours' radii, is
        damped by it (an amplification of at most |e^{−z} ± (μ/λ)(1 − e^{−z})| ≤ 1 for a
        coupling μ ≤ λ). What does limit it is the centres: the gap between two skyrmions moves
        with their distance and with both radii, s_p each, so the law's slope reaches the
        centres' explicit step up to (1 + 2 s_p) times; counted here as 2 s κ beside the law's
        own κ, which halves the rigid model's step at s = 1. Measured
        (tests/engine/test_breathing.py): six skyrmions squeezed to half their radius in a disk
        follow, at this step, the path of a step four times shorter within 10⁻³ d_sk; at the
        rigid step they strayed by 4·10⁻³ d_sk over 400 steps.
        """
        if not self.active:
            return 0.0
        s_p, s_w = float(self.spec.pair_shift), float(self.spec.wall_shift)
        return 2.0 * max(s_p * self.pair_stiffness, s_w * self.wall_stiffness)
