"""Shared synthetic fields for the micromagnetics tests."""

from types import SimpleNamespace

import numpy as np
import pytest

from skygas.micromag import synthetic

CELL = 1e-9  # m
RADIUS = 10e-9  # m, the ansatz's m_z = 0 radius
WALL_WIDTH = 3e-9  # m
# Sub-cell offsets on purpose: the detector must not snap to cell centres.
CENTRES = [(40.37e-9, 50.81e-9), (110.13e-9, 52.52e-9)]


@pytest.fixture(scope="session")
def profile():
    """The constants of the synthetic two-skyrmion field (SI)."""
    return SimpleNamespace(cell=CELL, radius=RADIUS, wall_width=WALL_WIDTH, centres=CENTRES)


@pytest.fixture(scope="session")
def two_skyrmions():
    """Two core-down skyrmions (Q = −1 each) in an up film, 150 × 100 cells of 1 nm."""
    return synthetic.skyrmion_field((100, 150), CELL, CENTRES, RADIUS, WALL_WIDTH, time=1.5e-9)


@pytest.fixture
def rng():
    return np.random.default_rng(20240607)
