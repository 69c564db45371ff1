"""Sensors, read-out and Boolean tasks on exact or synthetic inputs."""

from __future__ import annotations

import math

import numpy as np
import pytest

from skygas.reservoir.readout import accuracy_interval, fit_and_score, split
from skygas.reservoir.sensors import coverage, disk_overlap_area
from skygas.reservoir.tasks import BOOLEAN_NAMES, boolean_study, boolean_value


def test_disk_overlap_area_exact_cases():
    r = 3.0
    # equal disks d apart: 2r² acos(d/2r) − (d/2)√(4r² − d²)
    d = np.array([0.0, 1.0, 3.0, 5.9, 6.0, 7.0])
    exact = 2 * r * r * np.arccos(np.minimum(d / (2 * r), 1)) - d / 2 * np.sqrt(
        np.maximum(4 * r * r - d * d, 0)
    )
    assert np.allclose(disk_overlap_area(d, r, r), exact, rtol=1e-12, atol=1e-12)
    # a small disk inside a large one, touching from inside, and apart
    assert disk_overlap_area(np.array([0.5, 2.0, 7.0]), 1.0, 3.0) == pytest.approx(
        [math.pi, math.pi, 0.0]
    )


def test_disk_overlap_area_against_monte_carlo():
    rng = np.random.default_rng(3)
    p = rng.uniform(-2, 2, size=(400_000, 2))
    inside = (np.hypot(*p.T) < 1.5) & (np.hypot(p[:, 0] - 1.7, p[:, 1]) < 1.0)
    estimate = inside.mean() * 16
    error = math.sqrt(inside.mean() * (1 - inside.mean()) / len(p)) * 16
    assert abs(disk_overlap_area(np.array([1.7]), 1.5, 1.0)[0] - estimate) < 4 * error


def test_coverage_is_the_covered_fraction_of_the_sensor():
    x = np.array([[0.0, np.nan], [100.0, np.nan]])
    y = np.zeros_like(x)
    c = coverage(x, y, np.array([[0.0, 0.0]]), 20.0, 10.0)
    assert c[:, 0] == pytest.approx([0.25, 0.0])  # (10/20)² when inside, 0 when far


def test_split_is_a_seeded_partition():
    train, test = split(100, 0.3, seed=4)
    assert len(test) == 30 and len(np.intersect1d(train, test)) == 0
    assert np.array_equal(np.union1d(train, test), np.arange(100))
    assert np.array_equal(split(100, 0.3, seed=4)[1], test)
    assert not np.array_equal(split(100, 0.3, seed=5)[1], test)


@pytest.mark.parametrize("model", ["ridge", "logistic"])
def test_readout_is_perfect_on_a_linearly_separable_task(model):
    rng = np.random.default_rng(8)
    x = rng.normal(size=(3000, 5))
    w = np.array([1.0, -2.0, 0.5, 0.0, 3.0])
    margin = x @ w
    keep = np.abs(margin) > 3.0  # a clear gap between the classes (|w| = 3.8)
    x, label = x[keep], (margin[keep] > 0).astype(int)
    train, test = split(len(x), 0.4, seed=1)
    score = fit_and_score(x, label, train, test, model=model, regularization=1e-6)
    assert score["accuracy"] == 1.0
    assert score["margin_standard_errors"] > 10


def test_truth_tables_and_the_xor_of_separated_states():
    a, b = np.array([0, 0, 1, 1]), np.array([0, 1, 0, 1])
    assert BOOLEAN_NAMES[6] == "XOR" and list(boolean_value(6, a, b)) == [0, 1, 1, 0]
    assert list(boolean_value(8, a, b)) == [0, 0, 0, 1]  # AND
    assert list(boolean_value(14, a, b)) == [0, 1, 1, 1]  # OR
    assert {tuple(boolean_value(k, a, b)) for k in range(16)} == {
        tuple((k >> np.arange(4)) & 1) for k in range(16)
    }
    # one-hot states per input symbol (plus noise): every function is linearly separable
    rng = np.random.default_rng(2)
    bits = rng.integers(0, 2, size=(400, 2))
    states = np.eye(4)[2 * bits[:, 0] + bits[:, 1]] + 0.05 * rng.normal(size=(400, 4))
    train, test = split(400, 0.5, seed=0)
    scores = boolean_study(states, bits, train, test)
    assert list(scores)[0] == "XOR"
    assert all(s["accuracy"] == 1.0 for s in scores.values())


def test_a_random_landscape_is_one_device_in_one_stream():
    from skygas.reservoir.config import reservoir_config
    from skygas.reservoir.streams import run_streams

    pinned = reservoir_config(
        {
            "hold_time": 1e-7,
            "sensors": {"sample_interval": 5e-9},
            "study": {"n_inputs": 16, "temporal_inputs": 0, "workers": 2},
            "potentials": [
                {"kind": "random_pinning", "density": 1.7e14, "sigma": 19e-9, "depth_kT": 2.0}
            ],
        }
    )
    boolean, temporal = run_streams(pinned)
    assert len(boolean) == 1 and len(boolean[0].bits) == 16 and temporal == []


def test_the_accuracy_interval_is_wilsons():
    # all right on n inputs: [n/(n + z²), 1]; half right: 1/2 ± z/(2√(n + z²)) (closed forms)
    low, high = accuracy_interval([1.0, 0.0, 0.5], 10)
    np.testing.assert_allclose(low, [10 / 11, 0.0, 0.5 - 1 / (2 * np.sqrt(11))], atol=1e-12)
    np.testing.assert_allclose(high, [1.0, 1 / 11, 0.5 + 1 / (2 * np.sqrt(11))], atol=1e-12)
    # many inputs: the normal interval a ± √(a(1 − a)/n)
    low, high = accuracy_interval(0.8, 10**6, z=2.0)
    np.testing.assert_allclose([low, high], [0.8 - 0.0008, 0.8 + 0.0008], rtol=1e-5)
