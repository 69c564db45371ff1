"""The hypothesis knobs (skygas.physics.hypothesis) against exact results of the Thiele equation.

- dynamics time scale s (k → k/s): the free diffusion constant is s× the SI one, the drift
  under a uniform v_s is the SI one (solution of the 2×2 Thiele system), F₀ is unchanged;
- noise scale n: D is n× the SI one and the deterministic dynamics are untouched.

The engine is given ``config.thiele_parameters()`` and ``config.noise_temperature()``, as a
reshuffler run does. Statistical checks use 4 standard errors (docs of tests/engine).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from skygas.core import units
from skygas.core.errors import InputError
from skygas.engine import Simulation
from skygas.physics.geometry import rectangle
from skygas.physics.materials import preset
from skygas.reshuffler.config import load_reshuffler_config

S2 = preset("S2")
NO_PAIRS = {"pair_law": "lin-reichhardt", "pair_law_params": {"amplitude": 0.0}}


def si_diffusion(temperature: float) -> float:
    """D [nm²/ns] of S2 in a 2 nm film from the SI coefficients, computed here from scratch:
    D = k_BT α𝒟k/(G² + (α𝒟k)²), k = M_s t_F/γ, G = −4πQk."""
    thiele = load_reshuffler_config(preset="default").thiele_parameters()
    k = S2.saturation_magnetization * 2e-9 / units.GYROMAGNETIC_RATIO
    a = S2.damping * thiele.dissipation * k
    g = 4 * math.pi * S2.topological_charge * k
    return units.BOLTZMANN * temperature * a / (a * a + g * g) * units.M2_PER_S_TO_NM2_PER_NS


def thiele_drift(thiele, v_s: np.ndarray) -> np.ndarray:
    """ẋ from (Gε + α𝒟k I)·ẋ = μ(Gε + η𝒟k I)·v_s, ε = [[0, 1], [−1, 0]] (a 2×2 solve)."""
    eps = np.array([[0.0, 1.0], [-1.0, 0.0]])
    lhs = thiele.gyrocoupling * eps + thiele.friction * np.eye(2)
    rhs = thiele.mu * (
        thiele.gyrocoupling * eps + thiele.eta * thiele.dissipation * thiele.k * np.eye(2)
    )
    return np.linalg.solve(lhs, rhs @ v_s)


def config(**hypothesis):
    overrides = {f"hypothesis.{k}": v for k, v in hypothesis.items()}
    overrides["thiele.eta"] = 0.3  # η ≠ α: a skyrmion Hall angle, so the drift is a real test
    return load_reshuffler_config(preset="default", overrides=overrides)


def measured_diffusion(cfg, interval: float) -> tuple[float, float]:
    """D [nm²/ns] and its standard error from free skyrmions 500 nm apart (no pair force)."""
    sim = Simulation(
        rectangle(12e-6, 12e-6),
        cfg.resolved_material(),
        temperature=cfg.noise_temperature(),
        thiele=cfg.thiele_parameters(),
        time_step=2e-12,
        seed=5,
        grid_spacing=30e-9,
        **NO_PAIRS,
    )
    c = (np.arange(20) - 9.5) * 500e-9
    gx, gy = np.meshgrid(c, c)
    sim.add_skyrmions(np.column_stack([gx.ravel(), gy.ravel()]))
    steps = []
    for _ in range(3):
        _, start = sim.positions()
        sim.run(interval)
        _, end = sim.positions()
        steps.append((end - start) * units.M_TO_NM)
    sq = np.sum(np.concatenate(steps) ** 2, axis=1)
    t_ns = interval * units.S_TO_NS
    return sq.mean() / (4 * t_ns), sq.std(ddof=1) / math.sqrt(len(sq)) / (4 * t_ns)


@pytest.mark.parametrize(
    "knobs, factor", [({"dynamics_time_scale": 30.0}, 30.0), ({"noise_scale": 30.0}, 30.0)]
)
def test_each_knob_multiplies_the_free_diffusion_constant(knobs, factor):
    cfg = config(**knobs)
    exact = factor * si_diffusion(300.0)
    # the analytic D of the scaled coefficients, and the engine's diffusion, both match
    d_formula = (
        cfg.thiele_parameters().diffusion_constant(cfg.noise_temperature())
        * units.M2_PER_S_TO_NM2_PER_NS
    )
    assert d_formula == pytest.approx(exact, rel=1e-12)
    d_est, se = measured_diffusion(cfg, 1e-9)
    assert abs(d_est - exact) < 4 * se, (d_est, exact, se)
    assert se / exact < 0.03  # sharp enough to tell 30× from anything else


@pytest.mark.parametrize("knobs", [{"dynamics_time_scale": 30.0}, {"noise_scale": 30.0}])
def test_drift_under_a_uniform_current_is_unchanged(knobs):
    plain, scaled = config(), config(**knobs)
    v_s = np.array([40.0, 0.0])  # m/s
    exact = thiele_drift(plain.thiele_parameters(), v_s)
    assert np.allclose(thiele_drift(scaled.thiele_parameters(), v_s), exact, rtol=1e-12)
    # the engine at T = 0 follows it (one free skyrmion, far from the walls)
    sim = Simulation(
        rectangle(6e-6, 6e-6),
        plain.resolved_material(),
        temperature=0.0,
        thiele=scaled.thiele_parameters(),
        time_step=5e-12,
        drift_velocity=tuple(v_s),
        grid_spacing=30e-9,
        **NO_PAIRS,
    )
    sim.add_skyrmions(np.array([[-1e-6, 0.0]]))
    _, start = sim.positions()
    sim.run(20e-9)
    _, end = sim.positions()
    assert np.allclose((end - start)[0] / 20e-9, exact, rtol=1e-6, atol=1e-9)
    # forces keep their scale; the mobility of a force grows by s
    s = scaled.hypothesis.dynamics_time_scale
    p, q = plain.thiele_parameters(), scaled.thiele_parameters()
    assert q.force_scale == p.force_scale
    assert math.hypot(p.friction, p.gyrocoupling) / math.hypot(
        q.friction, q.gyrocoupling
    ) == pytest.approx(s, rel=1e-12)


@pytest.mark.parametrize(
    "field, value",
    [
        ("dynamics_time_scale", 0.0),
        ("noise_scale", -1.0),
        ("dynamics_time_scale", float("inf")),
        ("noise_scale", float("nan")),
    ],
)
def test_bad_knob_values_are_refused(field, value):
    with pytest.raises(InputError, match=f"hypothesis.{field}"):
        config(**{field: value})


def test_the_knobs_are_recorded_in_every_summary():
    from skygas.reshuffler.analysis import summarize
    from skygas.reshuffler.run import ReshufflerRun

    cfg = load_reshuffler_config(
        preset="paper-figures", overrides={"duration": 5e-8, "current_density": 3.8e11}
    )
    run = ReshufflerRun.build(cfg)
    run.advance()
    summary = summarize(run, dataset=False).summary
    assert summary["dynamics_time_scale"] == cfg.hypothesis.dynamics_time_scale > 1
    assert summary["noise_scale"] == 1.0
    assert summary["free_diffusion_m2_s"] == pytest.approx(
        cfg.hypothesis.dynamics_time_scale * si_diffusion(300.0) / units.M2_PER_S_TO_NM2_PER_NS,
        rel=1e-9,
    )
