"""``skygas track`` on odd but valid input, and stopped half-way.

Numbered frames are read in the order of their numbers; an ImageJ hyperstack whose extra axis
has length 1 is a movie; Ctrl-C (SIGINT) stops a tracking wherever it is, in the foreground or
started in the background, and leaves no file half-written. The refusals are in
tests/bad_inputs/test_track.py.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = ROOT / "examples" / "tracking" / "chamber-movie.tif"


def _good(frames: int = 8) -> np.ndarray:
    import tifffile

    return tifffile.imread(SHIPPED, key=range(frames))


def test_numbered_frames_are_read_in_the_order_of_their_numbers(tmp_path):
    from PIL import Image

    from skygas.movies.reading import open_movie

    good = _good(12)
    for i, image in enumerate(good):
        Image.fromarray(image).save(tmp_path / f"frame_{i}.png")  # frame_10 sorts before frame_2
    movie = open_movie(tmp_path)
    assert [f.name for f in movie.files][9:] == ["frame_9.png", "frame_10.png", "frame_11.png"]
    assert np.array_equal(movie.frame(10), good[10])


def test_a_hyperstack_with_one_z_plane_is_a_movie(tmp_path):
    import tifffile

    from skygas.movies.reading import open_movie

    good = _good(6)
    path = tmp_path / "one-plane.tif"
    tifffile.imwrite(path, good[:, None], imagej=True, metadata={"axes": "TZYX"})
    movie = open_movie(path)
    assert movie.n_frames == 6 and movie.shape == good.shape[1:]
    assert np.array_equal(movie.frame(5), good[5])


def test_render_refuses_lengths_that_are_not_metres():
    from skygas.core.errors import InputError
    from skygas.movies.render import RenderSettings

    with pytest.raises(InputError, match=r"--pixel-size = 14.*did you mean 14e-9"):
        RenderSettings(pixel_size=14.0).checked()
    with pytest.raises(InputError, match=r"--psf-sigma"):
        RenderSettings(pixel_size=14e-9, psf_sigma=20.0).checked()


def _interrupt_reading(monkeypatch):
    from skygas.movies import reading

    read = reading._StackFrames.__getitem__

    def interrupted(self, i):
        if i == 5:
            raise KeyboardInterrupt
        return read(self, i)

    monkeypatch.setattr(reading._StackFrames, "__getitem__", interrupted)


def _interrupt_locating(monkeypatch):
    import trackpy

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(trackpy, "locate", interrupted)


def _interrupt_encoding(monkeypatch):
    from skygas.movies import overlay

    draw = overlay.overlay_frames

    def interrupted(*args, **kwargs):
        for k, image in enumerate(draw(*args, **kwargs)):
            if k == 3:
                raise KeyboardInterrupt
            yield image

    monkeypatch.setattr(overlay, "overlay_frames", interrupted)


@pytest.mark.parametrize(
    ("interrupt", "finished"),
    [(_interrupt_reading, []), (_interrupt_locating, []), (_interrupt_encoding, ["tracks.csv"])],
    ids=["reading", "locating", "encoding"],
)
def test_ctrl_c_stops_track_and_leaves_no_half_written_file(
    interrupt, finished, tmp_path, monkeypatch
):
    import tifffile

    from skygas import cli

    tifffile.imwrite(tmp_path / "good.tif", _good(), photometric="minisblack")
    interrupt(monkeypatch)
    out = tmp_path / "out"
    assert cli.main(["track", str(tmp_path / "good.tif"), "--out", str(out), "--quiet"]) == 130
    written = sorted(p.name for p in out.iterdir()) if out.exists() else []
    assert written == finished  # the files finished before the interrupt, no partial one


def test_track_started_in_the_background_stops_on_sigint(tmp_path):
    """A shell starts ``skygas track ... &`` with SIGINT ignored: ``kill -INT`` still stops it."""
    import tifffile

    movie = _good(400)
    tifffile.imwrite(
        tmp_path / "long.tif", np.concatenate([movie, movie]), photometric="minisblack"
    )
    proc = subprocess.Popen(
        [sys.executable, "-m", "skygas.cli", "track", "long.tif", "--out", "out", "--quiet"],
        cwd=tmp_path,
        env={**os.environ},
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN),
    )
    time.sleep(5)  # past start-up, into the checks or the search of 800 frames (~20 s)
    assert proc.poll() is None, "track ended before it could be interrupted"
    proc.send_signal(signal.SIGINT)
    _, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 130, stderr
    assert stderr.strip() == "skygas: interrupted"
    assert not (tmp_path / "out" / "track.json").exists()
