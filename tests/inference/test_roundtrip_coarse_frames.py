"""``infer`` on a gas recorded with frames too far apart, simulated without skygas
(``independent_gas``): runs of the model correct what the frames' steps misread.

Apart from test_roundtrip.py so that the two can run on different test workers.
"""

from __future__ import annotations

import math

import pytest

from . import independent_gas as ig
from .test_roundtrip import _hall_within, _infer


@pytest.mark.slow
def test_frames_too_far_apart_are_corrected_by_runs_of_the_model():
    """Wells a skyrmion drifts across in a few frames (the drift within a frame is about a
    third of the steps' spread). Read off the steps, D is high and the Hall angle low by many
    errors; after the runs of the model the truth is within 3 errors (or 2°)."""
    w = 8e-6
    spec = ig.GasSpec(
        skyrmions=30,
        frames=1000,
        frame_interval=40e-3,
        substeps=20,
        width=w,
        height=w,
        diffusion=0.31e-12,
        hall_angle=math.radians(-70),
        boundary="periodic",
        wells=ig.random_wells(12, w, w, 3.0, 0.6e-6, seed=7),
        localisation_error=10e-9,
    )
    _, _, s = _infer(spec, check_frames=1000)
    correction = s["sampling_correction"]
    assert correction["made"] and correction["drift_share_of_raw_d"] > 0.1
    d, d_err = s["diffusion_constant"], s["diffusion_constant_error"]
    read = s["diffusion_constant_as_read"]
    assert abs(d - spec.diffusion) < 3 * d_err
    assert abs(read - spec.diffusion) > abs(d - spec.diffusion)
    assert _hall_within(s, spec.hall_angle)
