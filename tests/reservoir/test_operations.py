"""A reservoir study takes ``[[operations]]`` as every device run does: each stream's simulation
carries them, and their summaries are in the study's summary, stream by stream."""

from __future__ import annotations

import pytest

from skygas.core.errors import InputError
from skygas.reservoir.config import reservoir_config
from skygas.reservoir.study import run_study

#: two skyrmions, a short Boolean and a short temporal stream, a census of the whole chamber
#: every 10 ns and one of a disk around the bottom-left contact
CONFIG = {
    "n_skyrmions": 2,
    "hold_time": 2e-7,
    "sensors": {"sample_interval": 2e-9},
    "study": {"n_inputs": 8, "temporal_inputs": 8, "workers": 1},
    "operations": [
        {"kind": "census", "name": "chamber", "interval": 1e-8},
        {
            "kind": "census",
            "name": "corner",
            "interval": 1e-8,
            "center": [-1.2e-7, -7e-8],
            "radius": 6e-8,
        },
    ],
}


def test_each_stream_counts_every_skyrmion_of_the_closed_chamber():
    config = reservoir_config(CONFIG)
    summary, _ = run_study(config)
    operations = summary["operations"]
    assert sorted(operations) == ["boolean0", "temporal0"]
    st = config.study
    for stream, inputs, hold in (
        ("boolean0", st.n_inputs + st.warmup_inputs, config.hold_time),
        ("temporal0", st.temporal_inputs + st.warmup_inputs, st.temporal_hold_time),
    ):
        chamber, corner = operations[stream]["chamber"], operations[stream]["corner"]
        # the contacts are walls for skyrmions: none leaves, none comes
        assert chamber["min_count"] == chamber["max_count"] == 2, chamber
        # one reading every 10 ns of the stream's simulated time (its first at t = 0)
        assert abs(chamber["readings"] - inputs * hold / 1e-8) <= 1, chamber
        assert corner["readings"] == chamber["readings"]
        assert 0 <= corner["min_count"] <= corner["mean_count"] <= corner["max_count"] <= 2


def test_an_operation_with_a_device_s_own_name_is_refused_in_one_line():
    bad = {**CONFIG, "operations": [{"kind": "census", "name": "injector", "interval": 1e-8}]}
    with pytest.raises(InputError, match="operations"):
        reservoir_config(bad)


def test_a_stream_run_by_the_device_run_skeleton_equals_one_held_in_one_go():
    """A stream is a DeviceRun whose pieces are whole inputs: advanced piece by piece through
    the skeleton (DeviceRun.advance), it holds the same inputs to the same state as
    hold_inputs in one call, its operations included."""
    import numpy as np

    from skygas.reservoir.device import StreamRun
    from skygas.reservoir.streams import device_for, stream_specs

    config = reservoir_config(CONFIG)
    device = device_for(config)
    (spec,), _ = stream_specs(config, n_temporal=0)
    whole, pieces = StreamRun(device, spec), StreamRun(device, spec)
    whole.hold_inputs(spec.n_total)
    pieces.advance(pieces=3)  # 10 inputs in pieces of 4, 4 and 2
    assert pieces.sim.step == pieces.total_steps == whole.sim.step
    assert pieces.position == whole.position == spec.n_total
    a, b = whole.state_dict(), pieces.state_dict()
    for key in a:
        if key not in ("wall_time", "cpu_seconds"):
            assert np.array_equal(a[key], b[key]), key
