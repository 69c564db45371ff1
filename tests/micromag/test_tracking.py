"""Linking snapshots into trajectories, with skyrmions that appear and vanish, and tracking
skyrmions in films whose edges tilt."""

import math

import numpy as np
import pytest

from skygas.core.errors import InputError
from skygas.micromag import Skyrmion, Snapshot, detect_skyrmions, link, synthetic


def _snap(points, time):
    sks = tuple(Skyrmion(x, y, 1.0, -1.0, 20.0, 3.0, 1.0, i + 1) for i, (x, y) in enumerate(points))
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
    frames = [
        _snap([(0.0, 0.0)], 0.0),
        _snap([], 1.0),
        _snap([(0.1, 0.0)], 2.0),
        _snap([(5.0, 0.0)], 3.0),
    ]
    assert [t.frames for t in link(frames, max_step=1.0)] == [[0], [2], [3]]
    assert [t.frames for t in link(frames, max_step=1.0, memory=1)] == [[0, 2], [3]]


def test_bad_options():
    with pytest.raises(InputError, match="max_step"):
        link([], max_step=0.0)
    with pytest.raises(InputError, match="times"):
        link([_snap([], 0.0)], max_step=1.0, times=[0.0, 1.0])
    assert math.isnan(link([_snap([(0, 0)], math.nan)], 1.0)[0].times[0])


# --- Films whose edges tilt -------------------------------------------------------------------

N = 130  # cells of 1 nm
RADIUS, WALL_WIDTH = 10e-9, 3e-9
DISK = np.hypot(*(np.mgrid[0:N, 0:N] + 0.5 - 65.0)) < 60.0  # radius 60 nm around (65, 65) nm


def _tilted_frames(mask, angle, polarity, start, shift):
    """Frames of two skyrmions moving by ``shift`` per frame in a film whose edges tilt by
    ``angle`` (decay length Δ, as the DMI boundary condition gives), and the true centres."""
    frames, truth = [], []
    for f in range(4):
        centres = [(x + f * shift[0], y + f * shift[1]) for x, y in start]
        field = synthetic.skyrmion_field(
            (N, N), 1e-9, centres, RADIUS, WALL_WIDTH, polarity=polarity, time=f * 1e-10, mask=mask
        )
        frames.append(detect_skyrmions(synthetic.edge_tilt(field, angle, WALL_WIDTH)))
        truth.append(centres)
    return frames, np.array(truth)


@pytest.mark.parametrize(
    "film, angle, polarity",
    [("disk", 0.5, 1), ("disk", -0.5, 1), ("disk", 0.8, -1), ("square", 0.8, 1)],
)
def test_centres_and_charges_unbiased_by_tilted_edges(film, angle, polarity):
    """A tilted disk rim holds charge (1 − cos θ)/2 ≈ 0.06–0.15; it must not pull the centres
    (the whole-Voronoi-region centre was 0.4–0.6 nm off here). Skyrmions 25–40 nm from the
    edge, corners of the square film (mesh border) included."""
    start = [(40.37e-9, 66.81e-9), (88.13e-9, 60.52e-9)]
    frames, truth = _tilted_frames(
        DISK if film == "disk" else None, angle, polarity, start, (-1.3e-9, 0.7e-9)
    )
    if film == "disk":  # the rim's own charge is really there: (1 − cos θ)/2 with θ between
        # the tilt at the outermost cell centres (half a cell in) and at the edge itself
        rim = [0.5 * (1 - math.cos(angle * math.exp(-s * 1e-9 / WALL_WIDTH))) for s in (0.5, 0)]
        assert rim[0] < abs(frames[0].total_charge + 2 * polarity) < rim[1]
        assert frames[0].edge_band_width > 3 * 1e-9
    tracks = link(frames, max_step=5e-9)
    assert len(tracks) == 2 and all(len(t) == 4 for t in tracks)
    for track in tracks:
        k = int(np.argmin(np.hypot(*(truth[0] - track.positions[0]).T)))
        error = np.hypot(*(track.positions - truth[:, k]).T)
        assert error.max() < 0.1e-9
        np.testing.assert_allclose(track.charge, -polarity, atol=2e-3)


def test_no_edge_band_without_tilt():
    field = synthetic.skyrmion_field(
        (N, N), 1e-9, [(60.3e-9, 64.2e-9)], RADIUS, WALL_WIDTH, mask=DISK
    )
    snap = detect_skyrmions(field)
    assert snap.edge_band_width == 0.0
    (sk,) = snap.skyrmions
    assert math.hypot(sk.x - 60.3e-9, sk.y - 64.2e-9) < 0.01e-9
