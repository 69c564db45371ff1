"""Mean velocity and the skyrmion Hall angle of a driven gas.

The mean velocity is the pooled displacement over a lag of τ, divided by τ:
v = Σ Δr / (n τ), over every skyrmion and time origin. The Hall angle is the angle from the
drive direction (the spin-drift velocity v_s, or the current) to v:
θ_H = atan2(v_s × v, v_s · v), positive counter-clockwise. The Thiele equation with a uniform
v_s gives θ_H = 0 for η = α and a non-zero angle otherwise
(:meth:`~skygas.physics.materials.ThieleParameters.hall_angle`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skygas.analysis.frames import Frames
from skygas.analysis.jackknife import jackknife_error


@dataclass(frozen=True)
class MeanVelocity:
    """``velocity`` (vx, vy) [m/s] ± ``error`` [m/s]; ``n`` displacements over ``lag_time``."""

    velocity: np.ndarray
    error: np.ndarray
    n: int
    lag_time: float

    @property
    def speed(self) -> float:
        """|v| [m/s], the speed of the mean velocity."""
        return float(np.hypot(*self.velocity))

    def hall_angle(self, drive=(1.0, 0.0)) -> float:
        """θ_H [rad] from the direction ``drive`` to the mean velocity."""
        return hall_angle(self.velocity, drive)

    def hall_angle_error(self, drive=(1.0, 0.0)) -> float:
        """Standard error of θ_H [rad], propagated from the velocity error (small errors)."""
        v = self.velocity
        # ∂θ/∂v is the unit vector perpendicular to v over |v|
        return float(np.hypot(v[1] * self.error[0], v[0] * self.error[1]) / max(v @ v, 1e-300))

    def as_dict(self, drive=None) -> dict:
        """The result as a JSON-able dict, SI units in the keys; with ``drive``, θ_H too."""
        out = {
            "velocity_m_s": self.velocity.tolist(),
            "velocity_error_m_s": self.error.tolist(),
            "speed_m_s": self.speed,
            "displacements": self.n,
            "lag_time_s": self.lag_time,
        }
        if drive is not None and np.any(drive):
            out.update(
                {
                    "drive_direction": list(map(float, drive)),
                    "hall_angle_rad": self.hall_angle(drive),
                    "hall_angle_error_rad": self.hall_angle_error(drive),
                }
            )
        return out


def hall_angle(velocity, drive=(1.0, 0.0)) -> float:
    """atan2(drive × velocity, drive · velocity) [rad]."""
    vx, vy = velocity
    dx, dy = drive
    return float(np.arctan2(dx * vy - dy * vx, dx * vx + dy * vy))


def mean_velocity(frames: Frames, lag: int = 1) -> MeanVelocity:
    """Mean velocity [m/s] over every displacement of ``lag`` frames (overlapping origins).

    The errors are delete-one-skyrmion jackknife errors.
    """
    dt = frames.frame_interval() * lag
    a, b = frames.pairs_at_lag(lag)
    _, group = np.unique(frames.ids[a], return_inverse=True)
    n_groups = int(group.max()) + 1 if len(group) else 0
    values = np.column_stack(
        [np.ones(len(a)), frames.x[b] - frames.x[a], frames.y[b] - frames.y[a]]
    )
    sums = np.zeros((n_groups, 3))
    for c in range(3):
        sums[:, c] = np.bincount(group, weights=values[:, c], minlength=n_groups)

    def velocity_of(total):
        return total[..., 1:] / np.maximum(total[..., :1], 1) / dt

    total = sums.sum(axis=0)
    return MeanVelocity(velocity_of(total), jackknife_error(sums, velocity_of), len(a), dt)
