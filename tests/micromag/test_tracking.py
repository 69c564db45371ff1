"""Linking snapshots into trajectories, with skyrmions that appear and vanish."""

import math

import pytest

from skygas.errors import InputError
from skygas.micromag import Skyrmion, Snapshot, link


def _snap(points, time):
    sks = tuple(Skyrmion(x, y, 1.0, -1.0, 20.0, 3.0, 1.0, i + 1) for i, (x, y) in
                enumerate(points))
    return Snapshot(sks, None, -float(len(sks)), time)


def test_appearing_and_vanishing_skyrmions():
    # A moves right, B moves up from frame 2 on (nucleated), A vanishes after frame 4;
    # detections are listed in a shuffled order to make sure order is not used.
    frames = []
    for f in range(7):
        points = []
        if f <= 4:
            points.append((0.0 + 0.3 * f, 0.0))
        if f >= 2:
            points.append((5.0, 0.2 * f))
        frames.append(_snap(points[::-1] if f % 2 else points, time=f * 1e-10))
    tracks = link(frames, max_step=1.0)
    assert len(tracks) == 2
    a, b = tracks
    assert a.frames == [0, 1, 2, 3, 4] and b.frames == [2, 3, 4, 5, 6]
    assert a.positions[:, 0] == pytest.approx([0.0, 0.3, 0.6, 0.9, 1.2])
    assert b.positions[:, 1] == pytest.approx([0.4, 0.6, 0.8, 1.0, 1.2])
    assert b.times == pytest.approx([2e-10, 3e-10, 4e-10, 5e-10, 6e-10])


def test_assignment_minimises_total_displacement():
    # Greedy nearest-neighbour would give the first track the detection at 0.9 and break the
    # second; the optimal assignment keeps both tracks.
    frames = [_snap([(0.0, 0.0), (1.0, 0.0)], 0.0), _snap([(0.5, 0.0), (1.4, 0.0)], 1.0)]
    a, b = link(frames, max_step=0.6)
    assert a.positions[:, 0] == pytest.approx([0.0, 0.5])
    assert b.positions[:, 0] == pytest.approx([1.0, 1.4])


def test_gate_and_memory():
    frames = [_snap([(0.0, 0.0)], 0.0), _snap([], 1.0), _snap([(0.1, 0.0)], 2.0),
              _snap([(5.0, 0.0)], 3.0)]
    assert [t.frames for t in link(frames, max_step=1.0)] == [[0], [2], [3]]
    assert [t.frames for t in link(frames, max_step=1.0, memory=1)] == [[0, 2], [3]]


def test_bad_options():
    with pytest.raises(InputError, match="max_step"):
        link([], max_step=0.0)
    with pytest.raises(InputError, match="times"):
        link([_snap([], 0.0)], max_step=1.0, times=[0.0, 1.0])
    assert math.isnan(link([_snap([(0, 0)], math.nan)], 1.0)[0].times[0])
