"""Sanity checks: is a run inside the range where the model means something.

The limits are those of docs/physics.md §5 ("Where the model is meaningful"). A run outside
them is still computed, with one warning line per finding on stderr
(``skygas: warning: <field> = <value>: <why>; <what to do>``); with ``strict=True``
(``--strict`` on the command line) the first finding is refused instead, as an
:class:`~skygas.core.errors.InputError`, before anything is written.

Checked before the run (:func:`before_run`):

- the temperature: above :data:`MAX_TEMPERATURE` the wall law is used where it is not valid
  (a skyrmion one diameter from a wall has U_wall = 4.9 k_BT at 600 K);
- the current density: above :data:`MAX_CURRENT_DENSITY`, the paper's largest (skyrmions are
  taken as rigid; no deformation, no mass); above :data:`MAX_HOLDING_CURRENT_DENSITY` where a
  device holds skyrmions back (the neuron's closed gate), a skyrmion is pressed closer than
  one diameter to the one it pushes;
- the drift per time step: above :data:`MAX_DRIFT_PER_STEP` skyrmion diameters a skyrmion
  crosses the range of its neighbours' forces in one step; above
  :data:`~skygas.engine.simulation.MAX_STEP_DIAMETERS` the finding says that the engine cannot
  integrate it (a uniform drive that far is refused by the engine itself).

Checked after the run (:func:`after_run`): wall escapes, steps that would have carried a
skyrmion through a wall (undone by the kernel, counted). More than :data:`MAX_WALL_ESCAPE_RATE`
of the skyrmion-steps say that the time step is too long for the forces and the temperature;
a rarer escape is a thermal kick that the wall law's range missed, and holding one skyrmion
for one step in a million changes no observable. Under ``strict`` the rate is also checked
during the run (:func:`during_run`), so that a refusal comes as soon as it is certain rather
than after the whole run.

Lengths are not warned about but refused: a length outside 1 pm … 1 m is not a device size
(:data:`skygas.core.config_types.MIN_LENGTH`).
"""

from __future__ import annotations

import math
import sys
from typing import Any

from skygas.core.errors import InputError
from skygas.engine.simulation import MAX_STEP_DIAMETERS

#: Highest temperature [K] the wall law holds at (docs/physics.md §5, Temperature).
MAX_TEMPERATURE = 600.0
#: The paper's largest current density [A/m²] (docs/physics.md §5, Current).
MAX_CURRENT_DENSITY = 3.8e11
#: Largest current density [A/m²] where skyrmions are held back (a closed gate).
MAX_HOLDING_CURRENT_DENSITY = 1e11
#: Largest drift per time step [skyrmion diameters] (0.46 at 3.8×10¹¹ A/m² and 0.25 ns).
MAX_DRIFT_PER_STEP = 0.5
#: Wall escapes tolerated per skyrmion-step (each is a step of one skyrmion undone).
MAX_WALL_ESCAPE_RATE = 1e-6
#: Skyrmion-steps a run must have taken before :func:`during_run` judges its rate.
MIN_SKYRMION_STEPS_TO_JUDGE = 1_000_000


def _simulation(job: Any):
    sim = getattr(job, "sim", None)
    if sim is None:
        sim = getattr(getattr(job, "run", None), "sim", None)
    return sim


def findings_before_run(config: Any, sim: Any = None) -> list[InputError]:
    """What a configuration has outside the model's range, as errors naming each field.

    ``sim``, the configuration's built simulation, gives the time step and the skyrmion's
    size.
    """
    found: list[InputError] = []
    temperature = getattr(config, "temperature", None)
    if temperature is not None and temperature > MAX_TEMPERATURE:
        found.append(
            InputError(
                "temperature",
                temperature,
                f"at most {MAX_TEMPERATURE:g} K, where the wall law "
                "still holds (docs/physics.md §5)",
                "give a material measured at that temperature, or lower it",
            )
        )
    currents = {
        name: getattr(config, name, None) for name in ("current_density", "release_current_density")
    }
    for name, value in currents.items():
        if value is not None and value > MAX_CURRENT_DENSITY:
            found.append(
                InputError(
                    name,
                    value,
                    f"at most {MAX_CURRENT_DENSITY:g} A/m², the paper's range where "
                    "skyrmions stay rigid (docs/physics.md §5)",
                    "lower the current",
                )
            )
    holding = (
        currents["current_density"] if currents["release_current_density"] is not None else None
    )  # only the neuron has both: its current_density holds skyrmions at the gate
    if holding is not None and MAX_HOLDING_CURRENT_DENSITY < holding <= MAX_CURRENT_DENSITY:
        found.append(
            InputError(
                "current_density",
                holding,
                f"at most {MAX_HOLDING_CURRENT_DENSITY:g} A/m² where "
                "skyrmions are held back (pressed closer than one diameter above it; "
                "docs/physics.md §5)",
                "lower the holding current",
            )
        )
    speed = drift_speed(config)
    if sim is not None and speed > 0:
        d_sk = sim.thiele.skyrmion_diameter
        per_step = speed * sim.time_step / d_sk
        if per_step > MAX_DRIFT_PER_STEP:
            found.append(
                _integrable(
                    InputError(
                        "time_step",
                        sim.time_step,
                        f"a drift of at most {MAX_DRIFT_PER_STEP:g} skyrmion diameters per "
                        f"step (v_s = {speed:.3g} m/s moves {per_step:.3g} diameters)",
                        "shorten the time step or lower the current",
                    ),
                    per_step,
                )
            )
    if sim is not None:  # the force terms a configuration sets (a constant force)
        settings = sim.term_settings()
        for name, per_step in sim.term_steps().items():
            if per_step > MAX_DRIFT_PER_STEP:
                found.append(
                    _integrable(
                        InputError(
                            name,
                            settings[name],
                            f"a force that moves a free skyrmion at most "
                            f"{MAX_DRIFT_PER_STEP:g} diameters per step (it moves "
                            f"{per_step:.3g} at a time step of {sim.time_step:.3g} s)",
                            "shorten the time step or weaken the force",
                        ),
                        per_step,
                    )
                )
    return found


def _integrable(finding: InputError, per_step: float) -> InputError:
    """``finding``, saying that the engine cannot integrate it when over the limit.

    Over :data:`~skygas.engine.simulation.MAX_STEP_DIAMETERS` diameters per step.
    """
    if per_step <= MAX_STEP_DIAMETERS:
        return finding
    hard = InputError(
        finding.field,
        finding.value,
        f"{finding.allowed}; beyond {MAX_STEP_DIAMETERS:g} diameter per step the engine "
        "cannot integrate it",
        finding.hint,
    )
    hard.cannot_integrate = True  # type: ignore[attr-defined]
    return hard


def drift_speed(config: Any) -> float:
    """The largest spin-current drift speed |v_s| [m/s] of a configuration (0 without one)."""
    velocity = getattr(getattr(config, "drift", None), "velocity", None)
    if velocity is not None:
        return math.hypot(*velocity)
    given = [getattr(config, name, None) for name in ("current_density", "release_current_density")]
    currents = [c for c in given if c is not None]
    if not currents:
        return 0.0
    xi = (
        config.drift_coefficient()
        if hasattr(config, "drift_coefficient")
        else getattr(config, "spin_drift_coefficient", None)
    )
    return 0.0 if xi is None else xi * max(currents)


def report(findings: list[InputError], strict: bool) -> None:
    """Refuse the first finding (``strict``) or print each as a warning line."""
    if strict and findings:
        raise findings[0]
    for finding in findings:
        print(f"skygas: warning: {finding}", file=sys.stderr)


def before_run(job: Any, strict: bool = False) -> None:
    """The checks of a run driver job (its ``config`` and simulation) before it starts."""
    config = getattr(job, "config", None)
    if config is not None:
        report(findings_before_run(config, _simulation(job)), strict)


def _escape_finding(sim: Any) -> InputError | None:
    """The wall-escape finding of ``sim``, if its rate is above :data:`MAX_WALL_ESCAPE_RATE`."""
    escapes = getattr(sim, "wall_escapes", 0) if sim is not None else 0
    moved = max(1, getattr(sim, "skyrmion_steps", 0))
    if escapes <= MAX_WALL_ESCAPE_RATE * moved:
        return None
    return InputError(
        "time_step",
        sim.time_step,
        f"a run with at most {MAX_WALL_ESCAPE_RATE:g} wall escapes per skyrmion-step "
        f"({escapes} of {moved} skyrmion-steps would have crossed a wall and were undone)",
        "shorten the time step, or lower the temperature or the current",
    )


def during_run(job: Any, strict: bool = False) -> None:
    """Under ``strict``, refuse a run whose wall-escape rate is already too high.

    Judged once the run has taken :data:`MIN_SKYRMION_STEPS_TO_JUDGE` skyrmion-steps; without
    ``strict`` nothing is checked before the end (:func:`after_run` warns).
    """
    sim = _simulation(job)
    if not strict or sim is None:
        return
    if getattr(sim, "skyrmion_steps", 0) < MIN_SKYRMION_STEPS_TO_JUDGE:
        return
    finding = _escape_finding(sim)
    if finding is not None:
        raise finding


def after_run(job: Any, strict: bool = False) -> None:
    """The checks of a finished run: the rate of wall escapes."""
    finding = _escape_finding(_simulation(job))
    if finding is not None:
        report([finding], strict)
