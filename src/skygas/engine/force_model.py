"""The tabulated force laws of a run, and the time step they allow.

:class:`ForceModel` tabulates the pair and wall laws of :mod:`skygas.physics.forces` in internal
units (nm, pN). :func:`relaxation_time` is the fastest force relaxation τ_min; steps longer than
``MAX_STEP_FRACTION`` · τ_min are refused and ``SUGGESTED_STEP_FRACTION`` · τ_min is the
default (checked by :func:`skygas.runs.timestep.check_time_step`).
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from skygas.core import units
from skygas.core.errors import InputError
from skygas.core.memo import Memo, frozen
from skygas.physics.forces import (
    DEFAULT_CUTOFF_FRACTION,
    ForceTable,
    pair_law,
    tabulated_law,
    wall_law,
)
from skygas.physics.materials import ForceTableSpec, Material, ThieleParameters

#: Time steps longer than this fraction of τ_min are refused (see Simulation.max_time_step).
MAX_STEP_FRACTION = 1.0
#: Suggested time step as a fraction of τ_min.
SUGGESTED_STEP_FRACTION = 0.1
#: Without any stiff force, a step moves a free skyrmion this many diameters (rms).
FREE_STEP_DIAMETERS = 0.1
#: Skyrmions closer than this many diameters are "on top of each other" and refused. The same
#: distance bounds the range where the force laws' stiffness sets the time-step limit: the
#: laws are not valid below about one diameter (paper, "Boundary Effects"), and skyrmions
#: pushed that close annihilate rather than bounce (the annihilation model handles them).
MIN_PLACEMENT_SEPARATION = 0.5

#: The pair laws and wall laws a run may name (``forces.pair_law``, ``forces.wall_law``).
PAIR_LAWS = ("paper", "lin-reichhardt", "table")
WALL_LAWS = ("paper", "table")

# Force tables per law, coefficients, F₀, d_sk and cutoff fraction (see skygas.core.memo): finding a
# law's cutoff scans it at 2·10⁵ points, 10 ms per model.
_FORCE_TABLES = Memo("force_tables", maxsize=8)


def _resolve(
    name: str | None,
    table: ForceTableSpec | None,
    laws: tuple[str, ...],
    field: str,
    table_field: str,
    material: Material,
) -> str:
    if name is None:  # the material's own law
        return "paper" if table is None else "table"
    if name not in laws:
        raise InputError(
            field,
            name,
            " or ".join(f"'{n}'" for n in laws)
            + " (default: 'table' when the material has a table, else 'paper')",
        )
    if name == "table" and table is None:
        raise InputError(
            field,
            name,
            f"a law the material '{material.name}' has: it has no "
            f"{table_field} (use 'paper', or a calibrated model)",
        )
    return name


def resolve_law_names(
    material: Material, pair_law_name: str | None = None, wall_law_name: str | None = None
) -> tuple[str, str]:
    """The pair and wall laws a run uses.

    A name given, or ``None`` for the material's own (``"table"`` when it has ``pair_table`` /
    ``wall_table``, else ``"paper"``). ``"table"`` for a material without that table is refused.
    """
    return (
        _resolve(
            pair_law_name, material.pair_table, PAIR_LAWS, "forces.pair_law", "pair_table", material
        ),
        _resolve(
            wall_law_name, material.wall_table, WALL_LAWS, "forces.wall_law", "wall_table", material
        ),
    )


def _table_key(table: ForceTableSpec) -> str:
    """A digest of a table's numbers (for the memo's key)."""
    data = np.concatenate([np.asarray(table.distance, float), np.asarray(table.force, float)])
    return hashlib.sha256(data.tobytes()).hexdigest()


def _checked(table: ForceTableSpec | None) -> ForceTableSpec:
    """A material's table where its law is ``"table"``.

    :func:`resolve_law_names` refuses ``"table"`` for a material without it.
    """
    assert table is not None
    return table


def _search_range(table: ForceTableSpec, d_sk_nm: float) -> float:
    """Diameters to search a table law's cutoff in: the default 50, or past the table's end."""
    return max(50.0, 1.01 * table.distance[-1] * units.M_TO_NM / d_sk_nm)


@dataclass(frozen=True)
class ForceModel:
    """The tabulated pair and wall laws (internal units) and how they were made.

    ``pair_law`` and ``wall_law`` are the resolved names (:func:`resolve_law_names`), the ones
    results record.
    """

    pair: ForceTable
    wall: ForceTable
    pair_law: str
    pair_law_params: dict
    cutoff_fraction: float
    wall_law: str = "paper"

    @classmethod
    def build(
        cls,
        material: Material,
        thiele: ThieleParameters,
        pair_law_name: str | None = None,
        pair_law_params: dict | None = None,
        cutoff_fraction: float = DEFAULT_CUTOFF_FRACTION,
        wall_law_name: str | None = None,
    ) -> ForceModel:
        """Tabulate the laws of ``material`` with F₀ and d_sk of ``thiele``.

        ``None`` names take the material's own law (:func:`resolve_law_names`).
        """
        pair_law_name, wall_law_name = resolve_law_names(material, pair_law_name, wall_law_name)
        params = dict(pair_law_params or {})
        f0 = thiele.force_scale_internal
        d_sk = thiele.skyrmion_diameter_internal
        key: tuple[Any, ...] = (
            pair_law_name,
            tuple(material.pair_law),
            tuple(material.wall_law),
            repr(sorted(params.items())),
            f0,
            d_sk,
            float(cutoff_fraction),
        )
        if "table" in (pair_law_name, wall_law_name):  # the paper-law keys stay as they were
            key += (
                wall_law_name,
                _table_key(_checked(material.pair_table)) if pair_law_name == "table" else None,
                _table_key(_checked(material.wall_table)) if wall_law_name == "table" else None,
            )

        def table_law(table: ForceTableSpec):
            return tabulated_law(
                table.distance, table.force, thiele.skyrmion_diameter, thiele.force_scale
            )

        def tabulate() -> tuple[ForceTable, ForceTable]:
            # 8192 nodes in r²: relative error < 5e-5 from r = d_sk/4 on (64 kB, in L2 cache)
            if pair_law_name == "table":
                pair = ForceTable.from_law(
                    table_law(_checked(material.pair_table)),
                    f0,
                    d_sk,
                    cutoff_fraction,
                    n_points=8192,
                    squared=True,
                    d_max=_search_range(_checked(material.pair_table), d_sk),
                )
            else:
                pair = ForceTable.from_law(
                    pair_law(pair_law_name, material.pair_law, **params),
                    f0,
                    d_sk,
                    cutoff_fraction,
                    n_points=8192,
                    squared=True,
                )
            if wall_law_name == "table":
                wall = ForceTable.from_law(
                    table_law(_checked(material.wall_table)),
                    f0,
                    d_sk,
                    cutoff_fraction,
                    d_max=_search_range(_checked(material.wall_table), d_sk),
                )
            else:
                wall = ForceTable.from_law(wall_law(material.wall_law), f0, d_sk, cutoff_fraction)
            frozen(pair.values, wall.values)
            return pair, wall

        # each model gets its own (writable) copy of the shared tables: the kernels take
        # writable arrays (a read-only one would compile a second variant of every kernel)
        pair, wall = (
            replace(table, values=table.values.copy()) for table in _FORCE_TABLES.get(key, tabulate)
        )
        return cls(pair, wall, pair_law_name, params, cutoff_fraction, wall_law_name)

    def max_stiffness(self, closest: float = 0.0) -> float:
        """Largest |dF/dr| [pN/nm] of either law at r ≥ ``closest`` [nm] (:func:`law_stiffness`)."""
        return max(
            0.0,
            law_stiffness(self.pair, self.pair_law, closest),
            law_stiffness(self.wall, self.wall_law, closest),
        )


def law_stiffness(table: ForceTable, law_name: str, closest: float = 0.0) -> float:
    """Largest |dF/dr| [pN/nm] of one tabulated law at distances r ≥ ``closest`` [nm].

    A table law (``law_name == "table"``) ends with a drop to 0 at its last distance: a bounded
    jump of the force, not a stiffness (an explicit step across it stays stable), so its slope
    is measured up to the last node of the engine's table that holds a force, before the
    one-node ramp down to 0. The paper laws keep their measure (they fall to 10⁻³ F₀ there).
    A law that is zero beyond ``closest`` has no slope (0).
    """
    end = _last_force_node(table) if law_name == "table" else table.cutoff
    if end <= closest:
        return 0.0
    r = np.linspace(closest, end, 20_001)
    return float(np.max(np.abs(np.diff(table(r)))) / (r[1] - r[0]))


def _last_force_node(table: ForceTable) -> float:
    """Distance [nm] of the last node of ``table`` with a non-zero force."""
    held = np.nonzero(table.values)[0]
    if len(held) == 0:
        return 0.0
    coord = held[-1] * table.spacing
    return min(float(np.sqrt(coord) if table.squared else coord), table.cutoff)


def relaxation_time(thiele: ThieleParameters, stiffness: float) -> float:
    """τ_min [s]: the fastest force relaxation, 1/(κ_max |M|).

    κ_max = ``stiffness`` [pN/nm] is the largest of the force terms' stiffnesses
    (:mod:`skygas.engine.term_rules`): the steepest slope |dF/dr| of either force law at
    distances of at least MIN_PLACEMENT_SEPARATION skyrmion diameters (from another skyrmion
    or from a wall), or the largest curvature |∂²U| of an energy landscape, and
    |M| = 1/√(G² + (α𝒟k)²) the mobility: a skyrmion displaced on the steepest part of a law
    relaxes back (spiralling, when G ≠ 0) at the rate κ_max|M|. Closer than that the laws are
    not valid (paper, "Boundary Effects"), so their slope there does not limit the step; a
    step that carries a skyrmion across a wall is undone and counted (``wall_escapes``).
    """
    a, g = thiele.friction_internal, thiele.gyrocoupling_internal
    rate = stiffness / math.hypot(a, g)  # 1/ns
    return math.inf if rate == 0 else 1.0 / rate / units.S_TO_NS


def free_time_step(thiele: ThieleParameters, temperature: float) -> float:
    """The step [s] of a model with no stiff force: (f·d_sk)²/(4D).

    In it a free skyrmion moves f = FREE_STEP_DIAMETERS of its diameter (rms, two dimensions).

    A model without pair, wall or landscape forces (a zero table: skyrmions that do not
    interact) has no relaxation time; its walls still stop skyrmions, and a step must not jump
    them far. Infinite at T = 0 (nothing moves).
    """
    d = thiele.diffusion_constant(temperature) if temperature > 0 else 0.0
    return math.inf if d <= 0 else (FREE_STEP_DIAMETERS * thiele.skyrmion_diameter) ** 2 / (4 * d)


def suggested_time_step(thiele: ThieleParameters, stiffness: float, temperature: float) -> float:
    """SUGGESTED_STEP_FRACTION · τ_min [s], or :func:`free_time_step` without a stiff force."""
    suggested = SUGGESTED_STEP_FRACTION * relaxation_time(thiele, stiffness)
    return suggested if math.isfinite(suggested) else free_time_step(thiele, temperature)


def default_time_step(
    thiele: ThieleParameters, stiffness: float, interval: float, temperature: float = 0.0
) -> float:
    """The suggested step [s] (:func:`suggested_time_step`), fitted to ``interval``.

    τ_min is :func:`relaxation_time` of ``stiffness`` [pN/nm]; the step is shortened so that
    ``interval`` [s] (a recording or injection interval) is a whole number of steps (one
    step per interval when nothing limits it).
    """
    suggested = suggested_time_step(thiele, stiffness, temperature)
    if not math.isfinite(suggested):
        return interval
    return interval / math.ceil(interval / suggested - 1e-9)


def whole_steps(interval: float, time_step: float) -> int | None:
    """``interval`` [s] in time steps of ``time_step`` [s], or ``None`` if not a whole number.

    Whole to a relative 10⁻⁹: an interval that is a multiple of the step up to rounding counts.
    """
    ratio = interval / time_step
    if not math.isfinite(ratio):
        return None
    k = round(ratio)
    return int(k) if abs(ratio - k) <= 1e-9 * max(1.0, ratio) else None
