"""What a calibration will ask of the machine, checked before any solver starts.

A calibration's cost is set by its films (:mod:`skygas.calibration.plan`): their cells, and
the minimiser iterations a relaxation needs on them, which grow as the cells shrink. Most films
are sized in skyrmion diameters, known only once the isolated skyrmion is relaxed; they are
priced here at :data:`RADIUS_FACTOR` times the plan's first guess of its radius, 2A/|D|
(:func:`~skygas.calibration.plan.initial_radius`), so the estimate is an order of magnitude,
not a forecast. It is checked by :func:`skygas.core.estimates.check`, as every device's run
is: memory above what a job may use is refused (always), a wall time above 24 hours unless
forced (``--force``), and a long one is announced in one line.

Before the cost, the geometry is checked against itself: the validation film must hold its
skyrmions at their starting distances (a count that it cannot hold would otherwise be refused
only once the isolated skyrmion is known).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from skygas.calibration import plan
from skygas.calibration.material import DEFAULT_CELL_SIZE
from skygas.calibration.plan import CalibrationConfig, Relaxation, ValidationSpec
from skygas.calibration.solver import Film
from skygas.calibration.worker import SOLVERS_KEPT
from skygas.core.errors import InputError
from skygas.core.estimates import Estimate, check
from skygas.core.resources import memory_limit, require_memory

#: Peak memory of one relaxation [bytes per cell]. Measured with magnum.np 2.2 and torch 2.13
#: (CPU, one thread) on S2 films of 2 nm cells: resident memory above the process's own grew by
#: 1250–1350 B per cell on 301² cells with 0–1 guiding centres held, 1160–1560 on 601² with
#: 1–3 and 760–1210 on 1201² with 0–3 (the held centres' gradients are three fields each).
RELAXATION_BYTES_PER_CELL = 1600.0
#: Memory a built solver keeps [bytes per cell] (its state, field terms and FFT demagnetisation
#: kernel of the doubled mesh): 600–770 B per cell in the same measurement. A worker keeps the
#: solvers of its last few films (:data:`~skygas.calibration.worker.SOLVERS_KEPT`).
SOLVER_BYTES_PER_CELL = 800.0
#: A solver process before its first film [bytes]: torch and magnum.np imported, 420 MB.
PROCESS_BYTES = 450.0 * 2**20
#: Wall time of one minimiser iteration [s per cell]: 4.3–4.8 µs on 23 409 cells (S6's
#: isolated skyrmion at 2 and 0.5 nm), one torch thread of a development machine.
SECONDS_PER_CELL_ITERATION = 5e-6
#: Iterations of a relaxation on 2 nm cells, and how they grow as the cells shrink: S6's
#: isolated skyrmion took 255 iterations at 2 nm, 536 at 1 nm and 1712 at 0.5 nm (the same
#: film; the film's size does not change them: 264 in a film four times wider).
ITERATIONS_AT_2NM = 260.0
ITERATION_EXPONENT = 1.4
#: The relaxed radius against the plan's first guess 2A/|D|: 1.5 for S2 (39 nm against
#: 26.8 nm, docs/calibration.md) and 2.4 for S6 (11.5 nm against 4.9 nm).
RADIUS_FACTOR = 2.0
#: Wall time [s] of starting the solver processes (torch and magnum.np imported) and of
#: writing the results, measured at 15–20 s with two workers.
FIXED_SECONDS = 20.0
#: RKF45 steps per simulated second of the validation's LLG on 2 nm cells, ∝ 1/cell² (the
#: explicit stability limit), and their wall time [s per cell]: S2's validation took 28 911
#: steps for 7 ns in 3894 s on a 199 × 199 mesh (docs/calibration.md).
LLG_STEPS_PER_SECOND_AT_2NM = 28_911 / 7e-9
LLG_SECONDS_PER_CELL_STEP = 3894.0 / 28_911 / 199**2


def guessed_radius(config: CalibrationConfig) -> float:
    """The radius [m] the estimate sizes the films for (:data:`RADIUS_FACTOR` × 2A/|D|)."""
    return RADIUS_FACTOR * plan.initial_radius(config.material)


def iterations(cell_size: float) -> float:
    """Minimiser iterations of one relaxation on cells of ``cell_size`` [m] (a typical count)."""
    return ITERATIONS_AT_2NM * (2e-9 / cell_size) ** ITERATION_EXPONENT


def cells(film: Film) -> int:
    """Cells of ``film``'s mesh (a disk's empty corners included: the solver holds them)."""
    return film.nx * film.ny


def planned_solves(config: CalibrationConfig) -> list[Relaxation]:
    """Every relaxation of the calibration, its films sized at the guessed skyrmion radius."""
    radius = guessed_radius(config)
    width = config.material.wall_width
    # only the templates' radii matter to the plan's film sizes
    template = plan.Template((0.0, radius), (-1.0, 1.0), 0.0)
    first = plan.isolated_film(config)
    grown = plan.isolated_film(config, radius)
    solves = plan.isolated_stage(config, "isolated", first).solves
    if grown != first:
        solves += plan.isolated_stage(config, "isolated/grown", grown, template).solves
    solves += plan.sized_solves(config, radius, width, template, grown)
    # the breathing solves: their fields follow the measured sensitivity, their films do not
    return solves + plan.breathing_solves(config, radius, width, template, grown, -10.0)


def llg_steps(config: CalibrationConfig) -> float:
    """RKF45 steps of the validation run at its longest (``validation.max_duration``)."""
    if not config.validate_dynamics:
        return 0.0
    scale = (2e-9 / config.material.cell_size) ** 2
    return config.validation.max_duration * LLG_STEPS_PER_SECOND_AT_2NM * scale


def memory(solves: list[Relaxation], processes: int) -> tuple[float, int]:
    """Bytes of ``processes`` solver processes, and the largest film's cells.

    Each process may relax the largest film while it keeps the solvers of the largest others.
    """
    sizes = sorted({cells(s.film): None for s in solves}, reverse=True)
    largest = sizes[0]
    kept = sum(sizes[:SOLVERS_KEPT])
    one = (
        PROCESS_BYTES
        + SOLVER_BYTES_PER_CELL * kept
        + (RELAXATION_BYTES_PER_CELL - SOLVER_BYTES_PER_CELL) * largest
    )
    return processes * one, largest


@dataclass(frozen=True)
class CalibrationCost:
    """A calibration's :class:`~skygas.core.estimates.Estimate` and what makes it up.

    ``largest``: the largest film's cells; ``relax_seconds`` and ``llg_seconds``: the solver time
    [s] of the relaxations and of the validation's LLG, before they are shared by the workers.
    """

    estimate: Estimate
    largest: int
    relax_seconds: float
    llg_seconds: float


def calibration_cost(
    config: CalibrationConfig, workers: int, solves: list[Relaxation] | None = None
) -> CalibrationCost:
    """What the calibration will cost (:class:`CalibrationCost`).

    ``workers`` solver processes (0: one, this one) share the relaxations (``solves``, default
    :func:`planned_solves`); the validation's LLG is one chain, in one of them.
    """
    solves = planned_solves(config) if solves is None else solves
    relax_iterations = sum(cells(s.film) * iterations(s.film.cell_size) for s in solves)
    relax_seconds = relax_iterations * SECONDS_PER_CELL_ITERATION
    steps = llg_steps(config)
    llg_seconds = 0.0
    if config.validate_dynamics:
        disk = plan.validation_film(config, 2 * guessed_radius(config))
        llg_seconds = steps * cells(disk) * LLG_SECONDS_PER_CELL_STEP
    processes = max(1, workers)
    seconds = FIXED_SECONDS + max((relax_seconds + llg_seconds) / processes, llg_seconds)
    total_bytes, largest = memory(solves, processes)
    iterations_total = sum(iterations(s.film.cell_size) for s in solves) + steps
    estimate = Estimate(iterations_total, total_bytes, seconds)
    return CalibrationCost(estimate, largest, relax_seconds, llg_seconds)


def check_validation_film(config: CalibrationConfig) -> None:
    """Refuse a validation film that cannot hold its skyrmions at their starting distances.

    The check is in skyrmion diameters, so the guessed radius decides nothing but the rounding.
    """
    if not config.validate_dynamics:
        return
    v = config.validation
    diameter = 2 * guessed_radius(config)
    try:
        plan.validation_positions(plan.validation_film(config, diameter), diameter, v.skyrmions)
    except InputError:
        if v.shape == "rectangle":
            what = (
                f"as many skyrmions as the validation rectangle of {v.width:g} × {v.height:g} "
                f"diameters holds, 1.3–1.8 diameters apart and {plan.RECTANGLE_MARGIN:g} from "
                "its edges"
            )
        else:
            what = (
                f"as many skyrmions as the validation disk of radius {v.disk_radius:g} "
                "diameters holds, 1.3–1.8 diameters apart and 0.9 from its rim"
            )
        fix = "use fewer skyrmions (3 by default)"
        if v.shape == "rectangle":
            fix += ", or --validation-shape disk (a disk of radius 2.5 diameters holds up to 5)"
        raise InputError("validation.skyrmions", v.skyrmions, what, fix) from None


def _duration_decides(config: CalibrationConfig, cost: CalibrationCost) -> bool:
    """Whether the validation's duration, more than the cells, makes the calibration long.

    The LLG's time grows as its duration and as 1/cell⁴ (cells ∝ 1/cell², steps ∝ 1/cell²):
    the one further above its default is named.
    """
    if cost.llg_seconds <= cost.relax_seconds:
        return False
    duration = config.validation.max_duration / ValidationSpec().max_duration
    cells = (DEFAULT_CELL_SIZE / config.material.cell_size) ** 4
    return duration > cells


def check_calibration(config: CalibrationConfig, workers: int, remote: bool = False) -> Estimate:
    """Refuse a calibration that cannot fit or finish, before any solver starts.

    Memory above what a job may use is refused; a wall time above 24 hours unless forced
    (:func:`skygas.core.estimates.run_limits`); a long one is announced.

    ``remote``: the ``workers`` solver processes are a running Dask cluster's (``--scheduler``),
    not this machine's. Each of them must hold one process's films; that is the memory checked,
    against this machine's (the only one known here), and their number only shares the time.

    Returns
    -------
    Estimate
        The calibration's estimate.

    Raises
    ------
    InputError
        Naming ``validation.skyrmions`` for a disk too small, ``--workers`` for more solver
        processes than the memory holds, or ``cell_size`` for a calibration too large or too
        long.
    """
    check_validation_film(config)
    solves = planned_solves(config)
    cost = calibration_cost(config, workers, solves)
    processes = max(1, workers)
    estimate = cost.estimate
    if remote:
        estimate = replace(estimate, memory=memory(solves, 1)[0])
    elif memory(solves, 1)[0] <= memory_limit():  # one process fits: too many of them do not
        require_memory(
            "--workers",
            workers,
            cost.estimate.memory,
            f"{processes} solver processes, each with its own films",
            "use fewer --workers",
        )
    material = config.material
    films = f"relaxing films of up to {cost.largest:.3g} cells"
    if remote:
        what = f"each of the cluster's solver processes, {films}"
    else:
        what = f"{processes} solver process{'es' if processes > 1 else ''} {films}"
    if _duration_decides(config, cost):
        check(
            estimate,
            "validation.max_duration",
            config.validation.max_duration,
            what,
            f"use a shorter validation run (in seconds; the default is "
            f"{ValidationSpec().max_duration:g}), or --no-validate",
        )
    check(
        estimate,
        "cell_size",
        material.cell_size,
        what,
        f"use a larger cell_size (this material allows up to {material.largest_cell:.3g} m), "
        "or --no-mesh-check and --no-validate",
    )
    return estimate
