"""The inference's parts against exact or analytic answers (docs/inference.md).

Statistical checks use tolerances of 3–4 standard errors, stated at each assertion.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from skygas.core import units
from skygas.core.errors import InputError
from skygas.inference import diffusion, landscape, model, tracks, wall
from skygas.physics.geometry import rectangle
from skygas.physics.materials import derive_thiele, load_material, preset


def test_d_and_the_localisation_error_of_free_walks_within_3_standard_errors():
    rng = np.random.default_rng(1)
    n, frames, d, dt, sigma = 40, 3000, 2e-9, 1e-8, 5e-9
    xy = np.cumsum(rng.normal(0, math.sqrt(2 * d * dt), (frames, n, 2)), axis=0)
    noisy = xy + rng.normal(0, sigma, xy.shape)
    f, p = np.meshgrid(np.arange(frames), np.arange(n), indexing="ij")
    table = pd.DataFrame(
        {
            "frame": f.ravel(),
            "particle": p.ravel(),
            "x": noisy[..., 0].ravel() / 1e-8,
            "y": noisy[..., 1].ravel() / 1e-8,
        }
    )
    data = tracks.load_tracks(table, 1e-8, dt, subtract_drift="no")
    est = diffusion.estimate_diffusion(data.frames)
    assert abs(est.diffusion_constant - d) < 3 * est.error
    assert abs(est.sigma - sigma) < 4 * est.sigma_error
    assert est.error < 0.05 * d  # the blocks resolve it
    assert np.median(est.per_skyrmion) == pytest.approx(d, rel=0.1)


def test_trackpy_drift_is_subtracted_when_significant_and_kept_when_not():
    rng = np.random.default_rng(2)
    n, frames, dt = 30, 400, 1e-8
    xy = np.cumsum(rng.normal(0, 2e-9, (frames, n, 2)), axis=0) + rng.uniform(0, 1e-6, (1, n, 2))
    f, p = np.meshgrid(np.arange(frames), np.arange(n), indexing="ij")

    def table(shift):
        moved = xy + shift[:, None, :]
        return pd.DataFrame(
            {
                "frame": f.ravel(),
                "particle": p.ravel(),
                "x": moved[..., 0].ravel() / 1e-8,
                "y": moved[..., 1].ravel() / 1e-8,
            }
        )

    drift = np.column_stack([np.arange(frames) * 1e-9, np.zeros(frames)])  # 0.4 µm in total
    moved = tracks.load_tracks(table(drift), 1e-8, dt)
    assert moved.drift_subtracted
    assert moved.drift[-1, 0] == pytest.approx(drift[-1, 0], rel=0.1)
    still = tracks.load_tracks(table(np.zeros((frames, 2))), 1e-8, dt)
    assert not still.drift_subtracted


def test_missing_columns_and_single_frames_are_refused():
    with pytest.raises(InputError, match="tracks.frame"):
        tracks.load_tracks(pd.DataFrame({"particle": [0], "x": [1.0], "y": [1.0]}), 1e-8, 1e-8)
    one = pd.DataFrame({"frame": [0, 0], "particle": [0, 1], "x": [1.0, 2.0], "y": [1.0, 2.0]})
    with pytest.raises(InputError, match="at least two frames"):
        tracks.load_tracks(one, 1e-8, 1e-8)
    with pytest.raises(InputError, match="--pixel-size"):
        tracks.load_tracks(one, None, 1e-8)


def test_boltzmann_inversion_of_independent_samples_of_a_known_landscape():
    """Positions drawn from ρ ∝ exp(−U) of U = 2 cos(2πx/λ) (k_BT): U recovered within 4σ + bias."""
    from skygas.analysis.frames import Frames

    rng = np.random.default_rng(3)
    side, lam = 1e-6, 250e-9
    x = rng.uniform(0, side, 600_000)
    u_true = 2 * np.cos(2 * np.pi * x / lam)
    keep = rng.uniform(0, 1, len(x)) < np.exp(-u_true - 2)
    x = x[keep]
    y = rng.uniform(0, side, len(x))
    frames_n = 200
    count = np.full(frames_n, len(x) // frames_n)
    take = count.sum()
    fr = Frames(np.arange(frames_n) * 1.0, count, np.arange(take) % count[0], x[:take], y[:take])
    outline = rectangle(side, side, center=(side / 2, side / 2))
    m = landscape.boltzmann_inversion(fr, outline, 10e-9)
    gx, _ = np.meshgrid(m.grid.x, m.grid.y)
    truth = 2 * np.cos(2 * np.pi * gx / lam)
    interior = m.well_sampled & (np.abs(gx - side / 2) < side / 2 - 3 * m.bandwidth)
    diff = m.u[interior] - truth[interior]
    diff -= diff.mean()
    # smoothing by the kernel b lowers a cosine's amplitude by exp(−(2πb/λ)²/2) (Gaussian kernel)
    shrink = 1 - math.exp(-0.5 * (2 * math.pi * m.bandwidth / lam) ** 2)
    rms = math.sqrt(np.mean(diff**2))
    assert rms < 2 * (shrink * 2 / math.sqrt(2)) + 4 * np.median(m.error[interior])
    assert m.well_sampled.mean() > 0.5


def test_a_uniform_gas_has_no_wall_potential():
    from skygas.analysis.frames import Frames

    rng = np.random.default_rng(4)
    side, n = 1e-6, 200_000
    fr = Frames(
        np.arange(100.0),
        np.full(100, n // 100),
        np.arange(n) % (n // 100),
        rng.uniform(0, side, n),
        rng.uniform(0, side, n),
    )
    w = wall.wall_profile(fr, rectangle(side, side, center=(side / 2, side / 2)), 10e-9)
    ok = np.isfinite(w.w) & np.isfinite(w.error) & (w.error > 0)
    z = w.w[ok] / w.error[ok]
    assert np.mean(np.abs(z) < 3) > 0.95  # W = 0 within 3σ in (nearly) every bin
    assert wall.inradius(rectangle(side, side)) == pytest.approx(side / 2, rel=0.01)


@pytest.mark.parametrize("angle", [1.2, -0.4])
def test_the_model_material_has_the_measured_d_and_hall_angle_exactly(angle):
    d, temperature = 3.1e-13, 296.0  # Zázvorka et al.'s 0.31 µm²/s
    base = preset("S2")
    fields = model.thiele_fields(d, angle, 0.01, base, temperature)
    material = load_material(model.model_material("m", base, fields, None, None))
    t = derive_thiele(material)
    assert t.diffusion_constant(temperature) == pytest.approx(d, rel=1e-12)
    assert math.atan2(t.gyrocoupling, t.friction) == pytest.approx(angle, abs=1e-12)
    assert material.saturation_magnetization == base.saturation_magnetization


def test_a_hall_angle_within_two_errors_of_zero_makes_an_antiferromagnet():
    fields = model.thiele_fields(1e-12, 0.01, 0.02, preset("S2"), 300.0)
    t = derive_thiele(load_material(model.model_material("m", preset("S2"), fields, None, None)))
    assert t.gyrocoupling == 0
    assert t.diffusion_constant(300.0) == pytest.approx(1e-12, rel=1e-12)
    assert units.BOLTZMANN > 0


def test_a_mask_outline_covers_its_pixels(tmp_path):
    import matplotlib.image

    from skygas.inference.outline import read_outline

    mask = np.zeros((20, 30))
    mask[2:12, 5:25] = 1
    path = tmp_path / "mask.png"
    matplotlib.image.imsave(path, mask, cmap="gray")
    outline = read_outline(path, 1e-8)
    assert outline.region.area == pytest.approx(10 * 20 * 100.0)  # nm², 10 nm pixels
    x0, y0, _, _ = outline.region.bounds
    assert (x0, y0) == pytest.approx((45.0, 15.0))  # pixel 5 starts at x = 4.5 px


def test_force_balance_restores_a_crowded_gas_landscape():
    """30 skyrmions of S2 in 1.44 µm² on a 1.5 k_BT landscape: the neighbours flatten −ln ρ.

    With the true pair law, U = −ln ρ + Φ (∇Φ the neighbours' mean push, crowding.py) has the
    landscape's amplitude back within the kernel's smoothing (std ratio 0.8–1.1; here 0.96,
    where −ln ρ alone reads 0.49) and follows it closely (correlation > 0.85; here 0.93, −ln ρ
    alone 0.78).
    """
    from scipy.interpolate import RegularGridInterpolator

    from skygas.inference import crowding
    from skygas.inference.synthetic import simulated_tracks

    gas = simulated_tracks(skyrmions=30, frames=4000, seed=1)
    data = tracks.load_tracks(gas.tracks, gas.pixel_size, gas.frame_interval, subtract_drift="no")
    fr = data.frames
    lmap = landscape.boltzmann_inversion(fr, gas.outline, gas.pixel_size / 2)
    law = crowding.material_law({}, gas.material, gas.temperature)  # the true (paper) law
    phi, _, _ = crowding.crowding_potential(fr, lmap, law, 300e-9)
    g = lmap.grid
    gx, gy = np.meshgrid(g.x, g.y)
    truth = RegularGridInterpolator((gas.landscape_y, gas.landscape_x), gas.landscape_kt)
    true_u = truth(np.column_stack([gy.ravel(), gx.ravel()])).reshape(gx.shape)
    area = lmap.well_sampled & (wall.wall_distance(gas.outline, gx, gy) >= 150e-9)
    assert area.sum() > 1000

    def amplitude_and_correlation(u):
        a, b = u[area] - u[area].mean(), true_u[area] - true_u[area].mean()
        return np.std(a) / np.std(b), np.corrcoef(a, b)[0, 1]

    raw_amp, raw_corr = amplitude_and_correlation(lmap.u)
    amp, corr = amplitude_and_correlation(lmap.u + phi)
    assert raw_amp < 0.7  # the crowding is there to undo
    assert 0.8 < amp < 1.1
    assert corr > 0.85 and corr > raw_corr


def test_the_bias_spread_between_correction_rounds_is_their_standard_deviation():
    from skygas.inference.sampling import _bias_spread

    rounds = [
        {
            "model_diffusion_constant": 2.0,
            "read_diffusion_constant": 2.0,
            "model_hall_angle": 0.0,
            "read_hall_angle": 0.1,
        },
        {
            "model_diffusion_constant": 4.0,
            "read_diffusion_constant": 4.4,
            "model_hall_angle": 0.2,
            "read_hall_angle": 0.2,
        },
    ]
    d_spread, hall_spread = _bias_spread(rounds, 3.0)
    # read/made: 1.0 and 1.1 → sd 0.1/√2 of D = 3; turns 0.1 and 0.0 → sd 0.1/√2
    assert d_spread == pytest.approx(3.0 * 0.1 / math.sqrt(2))
    assert hall_spread == pytest.approx(0.1 / math.sqrt(2))
    assert _bias_spread(rounds[:1], 3.0) == (0.0, 0.0)
