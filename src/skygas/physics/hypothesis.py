"""Hypothesis knobs: transformations of the Thiele dynamics that are **not physics**.

They exist to test hypotheses about published results that the SI Thiele equation of the
published parameters does not reproduce (``docs/paper-reproduction.md``), e.g. "the paper's
skyrmions moved on a faster time scale than its own parameters give". Both default to 1 (no
change) and every result records them.

Thiele equation (:class:`~skygas.physics.materials.ThieleParameters`), with k = M_s t_F/γ:

    (G ε + α𝒟k I)·ẋ = μ (G ε + η𝒟k I)·v_s + F,    G = −4πQk,    F = F_ss + F_wall + F_th.

- **dynamics time scale** s: k → k/s (so G, α𝒟k and η𝒟k all shrink by s). The drift from the
  current is unchanged, since both sides of the v_s term scale alike: ẋ = μ Γ⁻¹Γ_η v_s with
  Γ = Gε + α𝒟kI, Γ_η = Gε + η𝒟kI. The mobility Γ⁻¹ of every force grows by s, and so does the
  free diffusion constant D = k_BT α𝒟k/(G² + (α𝒟k)²) (Einstein relation, same temperature):
  forces and thermal noise run s times faster, the drift from v_s does not. F₀, d_sk and the
  force laws are untouched. It is what one would get from reading the time of a γM-scaled
  equation in a unit s times too long.
- **noise scale** n: the thermal noise's temperature T → nT (an effective temperature of the
  noise only): D grows by n, the deterministic dynamics (forces, drift) are unchanged.
"""

from __future__ import annotations

import math
from dataclasses import replace

from pydantic import Field

from skygas.core.config_types import StrictModel
from skygas.physics.materials import ThieleParameters


class HypothesisSpec(StrictModel):
    """The hypothesis knobs of a run (both 1: the SI Thiele equation)."""

    dynamics_time_scale: float = Field(1.0, gt=0)  # s: k → k/s (finite: StrictModel)
    noise_scale: float = Field(1.0, gt=0)  # n: T_noise = n T

    def record(self) -> dict[str, float]:
        """Flat dict for result summaries."""
        return {"dynamics_time_scale": self.dynamics_time_scale, "noise_scale": self.noise_scale}


def scale_dynamics(thiele: ThieleParameters, time_scale: float) -> ThieleParameters:
    """The Thiele parameters with k → k/s and G → G/s (s = ``time_scale``).

    Mobility and free diffusion ×s, drift from v_s unchanged, F₀ and d_sk unchanged.
    """
    if not (math.isfinite(time_scale) and time_scale > 0):
        raise ValueError(f"time scale must be finite and > 0, got {time_scale!r}")
    return replace(thiele, k=thiele.k / time_scale, gyrocoupling=thiele.gyrocoupling / time_scale)


def noise_temperature(temperature: float, noise_scale: float) -> float:
    """The temperature [K] that sets the thermal noise: n T (D ∝ T at fixed mobility)."""
    if not (math.isfinite(noise_scale) and noise_scale > 0):
        raise ValueError(f"noise scale must be finite and > 0, got {noise_scale!r}")
    return temperature * noise_scale
