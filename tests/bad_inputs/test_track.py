"""``skygas track``: bad movies and options, refused in one line before any tracking.

One case per kind of bad input, each through the real command line (one line, exit 2, nothing
written; :mod:`tests.bad_inputs.catalogue`), on small files made here. What a subprocess cannot
reach is run in-process: a full disk (the lowest write made to fail) and a movie too long to
track in a day (the measured rate made slower).
"""

from __future__ import annotations

import errno
import warnings
from pathlib import Path

import numpy as np
import pytest

from .catalogue import assert_one_line, refused, run, snapshot

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = ROOT / "examples" / "tracking" / "chamber-movie.tif"


def _good(frames: int = 8) -> np.ndarray:
    """The first frames of the shipped movie (80 × 86 px, 30 dark skyrmions each)."""
    import tifffile

    return tifffile.imread(SHIPPED, key=range(frames))


def _png_folder(folder: Path, frames: np.ndarray, numbers) -> None:
    from PIL import Image

    folder.mkdir()
    for n, image in zip(numbers, frames, strict=False):
        Image.fromarray(image).save(folder / f"frame_{n:03d}.png")


def _write_movies(tmp_path: Path) -> None:
    """The movies the cases find in their working folder."""
    import tifffile

    good = _good()
    tifffile.imwrite(tmp_path / "good.tif", good, photometric="minisblack")
    data = (tmp_path / "good.tif").read_bytes()
    (tmp_path / "cut.tif").write_bytes(data[: len(data) // 2])
    _png_folder(tmp_path / "damaged", good[:4], range(4))
    png = tmp_path / "damaged" / "frame_002.png"
    png.write_bytes(png.read_bytes()[:200])
    _png_folder(tmp_path / "gap", good[:3], (0, 1, 3))
    tifffile.imwrite(tmp_path / "mask.tif", good < 100, photometric="minisblack")
    with warnings.catch_warnings():  # tifffile: (5, 4, 4) is stored as one RGBA image
        warnings.simplefilter("ignore", DeprecationWarning)
        tifffile.imwrite(tmp_path / "tiny.tif", good[:5, :4, :4])
    hyper = np.stack([good[:4]] * 3, axis=1)
    tifffile.imwrite(tmp_path / "hyper.tif", hyper, imagej=True, metadata={"axes": "TZYX"})
    tifffile.imwrite(
        tmp_path / "flat.tif", np.full((4, 32, 32), 7, np.uint8), photometric="minisblack"
    )
    tifffile.imwrite(tmp_path / "huge.tif", good.astype(float) * 1e302, photometric="minisblack")


CASES = {
    "a TIFF cut short": (["track", "cut.tif"], "complete TIFF", "cut short"),
    "a damaged frame in a folder": (["track", "damaged"], "frame_002.png", "readable image"),
    "boolean pixels": (["track", "mask.tif"], "boolean", "0/255"),
    "frames too small for a skyrmion": (["track", "tiny.tif"], "large enough to hold a skyrmion"),
    "a gap in the frames' numbers": (
        ["track", "gap"],
        "frame 2 is missing",
        "frame_001.png is followed by frame_003.png",
    ),
    "a hyperstack of time and z": (["track", "hyper.tif"], "one time axis", "TZYX", "z 3"),
    "a flat movie": (["track", "flat.tif", "--contrast", "dark"], "nothing to track"),
    "absurd pixel values": (["track", "huge.tif"], "range of 32-bit floats"),
    # trackpy warned once a frame here: the one line must be all of stderr
    "no skyrmion above the threshold": (["track", "good.tif", "--minmass", "1e9"], "none found"),
    "a pixel size in nanometres": (["track", "good.tif", "--pixel-size", "14"], "14e-9"),
    "a search range in metres": (["track", "good.tif", "--search-range", "5e-8"], "not metres"),
    "a search range beyond the frame": (["track", "good.tif", "--search-range", "500"], "diagonal"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_track_refuses_a_bad_movie_in_one_line(name, tmp_path):
    args, *expected = CASES[name]
    _write_movies(tmp_path)
    refused([*args, "--out", "OUT"], tmp_path, *expected)


def test_track_with_json_refuses_in_one_line_and_prints_nothing_on_stdout(tmp_path):
    _write_movies(tmp_path)
    before = snapshot(tmp_path)
    proc = run(["track", "good.tif", "--out", "OUT", "--pixel-size", "14", "--json"], tmp_path)
    assert_one_line(proc, "--pixel-size = 14.0", "14e-9")
    assert proc.stdout == ""  # a reader of the JSON gets nothing, not half an object
    assert snapshot(tmp_path) == before


def test_track_refuses_a_movie_larger_than_memory(tmp_path):
    _write_movies(tmp_path)
    before = snapshot(tmp_path)
    proc = run(
        ["track", "good.tif", "--out", "OUT", "--force"],
        tmp_path,
        env={"SKYGAS_MEMORY_LIMIT": "100000"},
    )
    assert_one_line(proc, "fits in memory", "crop the frames")  # --force does not force it
    assert snapshot(tmp_path) == before


def test_a_movie_of_more_than_a_day_needs_force(tmp_path, monkeypatch, capsys):
    import tifffile

    from skygas import cli
    from skygas.movies import estimate

    tifffile.imwrite(tmp_path / "good.tif", _good(), photometric="minisblack")
    monkeypatch.setattr(estimate, "SECONDS_PER_PIXEL", 1.0)  # 6880 px × 32 frames: 2.5 days
    args = ["track", str(tmp_path / "good.tif"), "--out", str(tmp_path / "out"), "--quiet"]
    assert cli.main(args) == 2
    line = assert_one_line_text(capsys.readouterr().err)
    assert "at most 24 h" in line and "2.5 days" in line and "--force" in line
    assert not (tmp_path / "out").exists()
    assert cli.main([*args, "--force"]) == 0
    assert capsys.readouterr().err == ""
    assert (tmp_path / "out" / "track.json").is_file()


def assert_one_line_text(stderr: str) -> str:
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("skygas: error: "), stderr
    return lines[0]


FAKE_FFMPEG = """#!/bin/sh
# ffmpeg on a full disk: it reads every frame, writes part of the file, fails at the trailer
for last; do :; done
cat > /dev/null
printf 'half an mp4' > "$last"
echo "[out#0/mp4 @ 0x5555] Error writing trailer: No space left on device" >&2
exit 1
"""


def _full_disk_run(tmp_path, capfd) -> tuple[int, str, Path]:
    import tifffile

    from skygas import cli

    tifffile.imwrite(tmp_path / "good.tif", _good(), photometric="minisblack")
    out = tmp_path / "out"
    status = cli.main(["track", str(tmp_path / "good.tif"), "--out", str(out), "--quiet"])
    err = capfd.readouterr().err  # the file descriptor: ffmpeg's own stderr counts too
    return status, assert_one_line_text(err), out


def test_a_full_disk_while_encoding_the_overlay_leaves_no_half_file(tmp_path, monkeypatch, capfd):
    import imageio_ffmpeg

    ffmpeg = tmp_path / "ffmpeg"
    ffmpeg.write_text(FAKE_FFMPEG)
    ffmpeg.chmod(0o755)
    monkeypatch.setattr(imageio_ffmpeg, "get_ffmpeg_exe", lambda: str(ffmpeg))
    status, line, out = _full_disk_run(tmp_path, capfd)
    assert status == 74
    assert "could not write" in line and "overlay.mp4 (No space left on device)" in line
    assert "Error writing trailer" not in line  # ffmpeg's words stay off the terminal
    # the files before it are complete; no half file under any name; no track.json
    assert sorted(p.name for p in out.iterdir()) == ["tracks.csv"]


def test_a_full_disk_at_the_first_write_leaves_nothing(tmp_path, monkeypatch, capfd):
    import pandas as pd

    def full(self, path, *args, **kwargs):
        Path(path).write_text("frame,parti")
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(pd.DataFrame, "to_csv", full)
    status, line, out = _full_disk_run(tmp_path, capfd)
    assert status == 74
    assert "tracks.csv (No space left on device)" in line and "half-written" in line
    assert not out.exists() or list(out.iterdir()) == []
