"""``infer`` on gases simulated without skygas (``independent_gas``): the truth comes back.

Each assertion compares with the generator's truth within a stated number of the inference's
own standard errors, so that the tests hold for any machine's trajectories. The figures for
larger movies and for an external particle code are in docs/inference.md
(benchmarks/roundtrip_infer.py).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from . import independent_gas as ig

W = 24e-6
BASE = dict(
    frames=1500,
    frame_interval=10e-3,
    substeps=2,
    width=W,
    height=W,
    diffusion=0.31e-12,
    hall_angle=math.radians(60),
    localisation_error=20e-9,
)


def _infer(spec: ig.GasSpec, **options):
    gas = ig.simulate(spec)
    outline = None
    if spec.boundary == "walls" and spec.field_of_view is None:
        from skygas.physics.geometry import rectangle

        outline = rectangle(spec.width, spec.height, center=(spec.width / 2, spec.height / 2))
    options.setdefault("check_frames", None)
    result = gas.infer(outline=outline, **options)
    return gas, result, result.summary


def _hall_within(s: dict, truth: float, sigmas: float = 3.0) -> bool:
    return abs(s["hall_angle"] - truth) < max(sigmas * s["hall_angle_error"], math.radians(2))


@pytest.mark.slow
def test_an_interacting_pinned_gas_gives_back_d_its_hall_angle_and_its_pair_force():
    """40 skyrmions, K₁ repulsion and Gaussian wells in a periodic box (tracks that wrap).

    The box is found, the landscape and the pair force kept, the drive and walls not; D within
    3 standard errors, the Hall angle within 3 (or 2°), the pair force within 3 of its errors
    wherever it is measured (error ≤ 20 %). The landscape's error covers its distance from the
    truth where it is sampled (rms of the ratio below 2.5).
    """
    spec = ig.GasSpec(
        **{**BASE, "substeps": 3},
        skyrmions=40,
        boundary="periodic",
        wells=ig.random_wells(25, W, W, 3.0, 1.5e-6, seed=3),
        pair=("k1", 17.6e6, 1e-6),
        pair_cutoff=6e-6,
    )
    gas, result, s = _infer(spec)
    assert s["film"]["kind"] == "periodic"
    assert s["film"]["period_m"] == pytest.approx([W, W], rel=0.005)
    assert set(s["model_selection"]["terms"]) == {"landscape", "pair"}
    assert abs(s["diffusion_constant"] - spec.diffusion) < 3 * s["diffusion_constant_error"]
    assert _hall_within(s, spec.hall_angle)
    pair = s["pair"]["fitted"]
    r, f, err = (np.array(pair[k]) for k in ("r_m", "force_N", "force_error_N"))
    kt = ig.BOLTZMANN * spec.temperature
    measured = (f > 0) & (err <= 0.2 * f)  # a movie this short fixes the force to 5 % nowhere
    assert measured.sum() >= 3
    assert np.all(np.abs(f[measured] - kt * ig.pair_force(spec, r[measured])) < 3 * err[measured])
    fmap = result.map
    # errors are relative to the mean over the well-sampled area, or over the sampled one where
    # no node is well sampled (a movie this short)
    area = fmap.well_sampled if fmap.well_sampled.any() else fmap.sampled
    assert area.sum() >= 20
    gx, gy = np.meshgrid(fmap.grid.x, fmap.grid.y)
    truth = ig.landscape(spec, gx, gy)[area]
    u = s["model"]["landscape_scale"] * fmap.u[area]
    z = (u - u.mean() - (truth - truth.mean())) / fmap.error[area]
    # the nodes' errors are strongly correlated (a smooth map): an rms z of 2.5 is far in the
    # tail of a χ² with the few independent values a well-sampled area holds
    assert np.sqrt(np.mean(z**2)) < 2.5, np.sqrt(np.mean(z**2))


@pytest.mark.slow
def test_a_walled_film_shows_its_wall_and_a_free_view_shows_none():
    """Wells in a walled square: the wall is kept, its potential at the closest distance the
    truth within 3 of its errors. The same kind of film seen through a window that tracks leave
    and enter: no wall, no drive, no interaction."""
    spec = ig.GasSpec(
        **BASE,
        skyrmions=40,
        boundary="walls",
        wells=ig.random_wells(25, W, W, 3.0, 1.5e-6, seed=5, margin=-4.5e-6),
        wall=(5.0, 1.0e-6),
    )
    _, _, s = _infer(spec)
    assert s["film"]["kind"] == "walls"
    assert "wall" in s["model_selection"]["terms"]
    assert "pair" not in s["model_selection"]["terms"]
    wall = s["wall"]["fitted"]
    d0, far = wall["r_m"][0], wall["basis"]["farthest_m"]
    truth = ig.wall_potential(spec, d0) - ig.wall_potential(spec, far)
    assert abs(wall["potential_kT"][0] - truth) < 3 * wall["potential_error_kT"][0]
    assert abs(s["diffusion_constant"] - spec.diffusion) < 3 * s["diffusion_constant_error"]

    free = ig.GasSpec(
        **{**BASE, "width": 40e-6, "height": 40e-6},
        skyrmions=80,
        boundary="periodic",
        field_of_view=(10e-6, 10e-6, 30e-6, 30e-6),
    )
    _, _, s = _infer(free, check_frames=1500)
    assert s["film"]["kind"] == "open"
    assert s["model_selection"]["terms"] == []
    assert s["hall_angle"] is None  # no force turns: the data cannot fix it
    assert abs(s["diffusion_constant"] - free.diffusion) < 3 * s["diffusion_constant_error"]
    assert s["consistency_check"]["passed"], s["consistency_check"]["failed"]


@pytest.mark.slow
def test_a_drive_through_a_pinned_film_is_a_drive_not_a_drift_of_the_view():
    """A uniform force across Gaussian wells in a periodic box (out of equilibrium): trackpy
    sees a drift, but taking it out would blur the wells; the drive is kept and within 3 of its
    errors, and no Boltzmann cross-check is made."""
    spec = ig.GasSpec(
        **BASE,
        skyrmions=40,
        boundary="periodic",
        wells=ig.random_wells(25, W, W, 3.0, 1.5e-6, seed=6),
        drive=(0.8e6, 0.3e6),
    )
    _, _, s = _infer(spec)
    assert not s["input"]["drift_subtracted"]
    assert "drive" in s["model_selection"]["terms"] and "landscape" in s["model_selection"]["terms"]
    kt = ig.BOLTZMANN * spec.temperature
    force, err = np.array(s["drive"]["force_N"]), np.array(s["drive"]["force_error_N"])
    assert np.all(np.abs(force - kt * np.array(spec.drive)) < 3 * err)
    assert not s["equilibrium"] and s["boltzmann_cross_check"] is None
    assert _hall_within(s, spec.hall_angle)
