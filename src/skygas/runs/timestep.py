"""Is the time step small enough? A pathwise check of dt against dt/2.

Two rules protect a run:

1. **Refusal.** :class:`~skygas.engine.Simulation` refuses dt > τ_min, the fastest force
   relaxation time (steepest slope of the force laws times the mobility). Beyond it Heun no
   longer follows the relaxation and can become unstable.
2. **Check.** Below τ_min, accuracy still depends on what the run needs. :func:`check_time_step`
   runs the same configuration twice over a short ``duration``, with dt and with dt/2, on the
   *same* Brownian path (the dt run sums two half-step noise increments per step, see
   ``brownian_substeps``), and reports how far the two trajectories end up apart, in skyrmion
   diameters. A difference below ``tolerance`` (default 1 % of d_sk) means that halving the
   step changes nothing a device-level observable could see. The suggested default,
   dt = 0.1 τ_min, passes for the paper's material.

Keep ``duration`` short (a few ns): an interacting gas is chaotic, so any two trajectories,
however accurate, separate exponentially over long times.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass

import numpy as np

from skygas.core.resources import step_count
from skygas.engine import Simulation


@dataclass(frozen=True)
class TimeStepReport:
    """Outcome of :func:`check_time_step` (SI units; differences also in diameters)."""

    time_step: float
    relaxation_time: float
    duration: float
    skyrmions_compared: int
    rms_difference: float
    max_difference: float
    rms_difference_diameters: float
    max_difference_diameters: float
    tolerance_diameters: float
    passed: bool

    def as_dict(self) -> dict:
        """The report as a dict (SI units)."""
        return asdict(self)

    def summary(self) -> str:
        """One line: dt, τ_min, the dt vs dt/2 differences in diameters, and OK or TOO LARGE."""
        verdict = "OK" if self.passed else "TOO LARGE"
        return (
            f"time step {self.time_step:.3g} s (τ_min = {self.relaxation_time:.3g} s): "
            f"dt vs dt/2 over {self.duration:.3g} s differ by "
            f"{self.rms_difference_diameters:.2e} d_sk rms, "
            f"{self.max_difference_diameters:.2e} d_sk max "
            f"(tolerance {self.tolerance_diameters:g} d_sk): {verdict}"
        )


def check_time_step(
    build: Callable[[float | None, int], Simulation],
    duration: float = 2e-9,
    time_step: float | None = None,
    tolerance_diameters: float = 0.01,
) -> TimeStepReport:
    """Compare runs at dt and dt/2 sharing one Brownian path.

    ``build(time_step, brownian_substeps)`` must return a fresh simulation with the initial
    skyrmions placed; ``time_step=None`` asks for its default step.
    """
    coarse = build(time_step, 2)
    dt = coarse.time_step
    fine = build(dt / 2, 1)
    n_steps = max(1, step_count(duration, dt))
    coarse.run(n_steps * dt)  # n steps of dt and 2n of dt/2 end at the same instant
    fine.run(n_steps * dt)
    assert fine.step == 2 * coarse.step
    ids_c, pos_c = coarse.positions()
    ids_f, pos_f = fine.positions()
    common, ic, jf = np.intersect1d(ids_c, ids_f, return_indices=True)
    diff = np.hypot(*(pos_c[ic] - pos_f[jf]).T) if len(common) else np.zeros(0)
    d_sk = coarse.thiele.skyrmion_diameter
    rms = float(np.sqrt(np.mean(diff**2))) if len(diff) else 0.0
    worst = float(diff.max()) if len(diff) else 0.0
    return TimeStepReport(
        time_step=dt,
        relaxation_time=coarse.relaxation_time(),
        duration=coarse.time,
        skyrmions_compared=int(len(common)),
        rms_difference=rms,
        max_difference=worst,
        rms_difference_diameters=rms / d_sk,
        max_difference_diameters=worst / d_sk,
        tolerance_diameters=tolerance_diameters,
        passed=worst / d_sk <= tolerance_diameters,
    )


def check_config_time_step(
    config,
    duration: float = 2e-9,
    time_step: float | None = None,
    tolerance_diameters: float = 0.01,
) -> TimeStepReport:
    """:func:`check_time_step` for a :class:`~skygas.runs.config.SimulationConfig`."""

    def build(dt, substeps):
        return config.build(
            time_step=dt if dt is not None else config.time_step, brownian_substeps=substeps
        )

    return check_time_step(build, duration, time_step, tolerance_diameters)
