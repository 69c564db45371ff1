"""Movies: frames chosen as asked, disks of the real diameter where the skyrmions are, files
that decode with the promised length."""

from __future__ import annotations

import numpy as np
import pytest

from skygas.cli import main
from skygas.core.errors import InputError
from skygas.outputs.movie import (
    GROUP_COLOURS,
    _Canvas,
    choose_frames,
    frame_images,
    render_movie,
)
from skygas.outputs.records import load_run


def test_choose_frames_by_window_and_stride():
    times = np.arange(100) * 1e-9
    index, stride = choose_frames(times, start=10e-9, end=29.5e-9)
    assert stride == 1 and index[0] == 10 and index[-1] == 29
    index, stride = choose_frames(times, max_frames=30)
    assert stride == 4 and len(index) == 25  # the smallest stride that fits
    index, stride = choose_frames(times, stride=7)
    np.testing.assert_array_equal(index, np.arange(0, 100, 7))
    with pytest.raises(InputError, match="--window"):
        choose_frames(times, start=1.0)


def test_disks_have_the_real_diameter_at_the_recorded_positions(reshuffler_run):
    record = load_run(reshuffler_run)
    f = int(np.argmax(record.frames.count))
    canvas = _Canvas(record, 720)
    image = next(frame_images(record, [f]))
    ids, xy = record.frames.frame(f)
    groups = record.group_of(ids, xy[:, 0], xy[:, 1])
    radius_px = 0.5 * record.skyrmion_diameter * 1e6 * canvas.px_per_um
    assert radius_px == pytest.approx(canvas.radius_px)
    assert radius_px > 5  # a visible disk at this size
    centres = canvas.pixels(xy)
    for (px, py), g in zip(centres, groups, strict=True):
        # inside the disk (half a radius off centre) the pixel has the group's colour
        colour = image[int(round(py)), int(round(px + 0.5 * radius_px))]
        np.testing.assert_allclose(colour, GROUP_COLOURS[g], atol=2)
    # a skyrmion with no other within three radii: beyond its edge the colour is not its own
    gaps = np.hypot(*(centres[:, None, :] - centres[None, :, :]).transpose(2, 0, 1))
    np.fill_diagonal(gaps, np.inf)
    lone = int(np.argmax(gaps.min(axis=1)))
    assert gaps[lone].min() > 3 * radius_px
    px, py = centres[lone]
    outside = image[int(round(py)), int(round(px + 1.4 * radius_px))]
    assert np.abs(outside.astype(int) - GROUP_COLOURS[groups[lone]]).max() > 20


def test_mp4_decodes_with_every_frame(simulation_run, tmp_path):
    import imageio_ffmpeg

    out = tmp_path / "movie.mp4"
    assert (
        main(
            [
                "animate",
                str(simulation_run),
                "--out",
                str(out),
                "--window",
                "4.5e-9:24.5e-9",
                "--fps",
                "10",
            ]
        )
        == 0
    )
    reader = imageio_ffmpeg.read_frames(str(out))
    meta = reader.__next__()
    frames = sum(1 for _ in reader)
    assert frames == 20  # 5, 6, ..., 24 ns
    assert meta["fps"] == pytest.approx(10)
    assert meta["duration"] == pytest.approx(2.0, abs=0.15)
    assert out.stat().st_size < 20e6


def test_gif_fallback(simulation_run, tmp_path):
    from PIL import Image

    info = render_movie(load_run(simulation_run), tmp_path / "movie.gif", stride=3)
    with Image.open(info.path) as gif:
        assert gif.n_frames == info.frames == 11  # 0, 3, ..., 30 ns
        assert gif.size == info.size


def test_animate_refuses_bad_arguments_before_reading_the_run(tmp_path, capsys):
    assert main(["animate", str(tmp_path), "--out", str(tmp_path / "m.avi")]) == 2
    assert "--out" in capsys.readouterr().err
    assert (
        main(["animate", str(tmp_path), "--out", str(tmp_path / "m.mp4"), "--window", "3:1"]) == 2
    )
    assert "--window" in capsys.readouterr().err
    assert main(["animate", str(tmp_path), "--out", str(tmp_path / "m.mp4"), "--stride", "0"]) == 2
    assert "--stride" in capsys.readouterr().err
    assert main(["animate", str(tmp_path), "--out", str(tmp_path / "m.mp4")]) == 2
    assert "RUN" in capsys.readouterr().err
