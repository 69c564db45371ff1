"""Every number of ``skygas track``'s report headline, recomputed here from the files it wrote.

The movie: the shipped one's first 40 frames cut to columns 30–69 (40 × 80 px), small enough
to track in seconds. Cut there, skyrmions leave and enter the view, so the per-frame counts and
the track lengths differ from one another (with the whole field, every track spans every frame
and every count is the same, which would check little). The command runs once, through the real
command line with ``--json``; each headline row is parsed (its numbers, in order) and compared
with a recount of tracks.csv by code of its own (frames per track from first to last, gaps
included; skyrmions per frame over every frame of the movie, empty ones too) and with the
movie's own size, read from the TIFF.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from tests.outputs.test_headlines_recomputed import _numbers, agrees, headline

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = ROOT / "examples" / "tracking" / "chamber-movie.tif"
FRAMES = 40
COLUMNS = slice(30, 70)


@pytest.fixture(scope="module")
def tracked(tmp_path_factory):
    """(folder, movie path, the completed process) of ``skygas track --json`` on the cut movie."""
    import tifffile

    root = tmp_path_factory.mktemp("track-headlines")
    movie = root / "cut.tif"
    frames = tifffile.imread(SHIPPED, key=range(FRAMES))[:, :, COLUMNS]
    tifffile.imwrite(movie, np.ascontiguousarray(frames), photometric="minisblack")
    out = root / "out"
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "skygas.cli",
            "track",
            str(movie),
            "--out",
            str(out),
            "--pixel-size",
            "14e-9",
            "--frame-interval",
            "2e-9",
            "--json",
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    return out, movie, proc


def _recount(out: Path, movie: Path) -> dict:
    """The headline's numbers from tracks.csv and the movie file, counted here."""
    import pandas as pd
    import tifffile

    stack = tifffile.imread(movie)
    n_frames, rows, columns = stack.shape
    table = pd.read_csv(out / "tracks.csv")
    per_frame = np.array([(table["frame"] == f).sum() for f in range(n_frames)])
    lengths = []
    for _, track in table.groupby("particle"):
        lengths.append(track["frame"].max() - track["frame"].min() + 1)
    lengths = np.array(lengths)
    return {
        "frames": [n_frames, columns, rows],
        "dtype": str(stack.dtype),
        "pixel size": [14e-9],
        "frame interval": [2e-9],
        "skyrmions per frame, mean (least – most)": [
            per_frame.mean(),
            per_frame.min(),
            per_frame.max(),
        ],
        "located skyrmions, all frames": [len(table)],
        "tracks": [table["particle"].nunique()],
        "track length, mean": [lengths.mean()],
        "track length, median / longest": [np.median(lengths), lengths.max()],
        "tracks spanning the whole movie": [int(np.sum(lengths == n_frames))],
    }


def test_every_headline_number_is_recounted_from_the_tracks(tracked):
    out, movie, _ = tracked
    rows, _ = headline(out / "report.html")
    expected = _recount(out, movie)
    dtype = expected.pop("dtype")
    assert set(rows) == set(expected), sorted(rows)  # a new row must be checked here too
    # the movie is cut so that the counts differ: the check below can tell them apart
    assert (
        expected["skyrmions per frame, mean (least – most)"][1]
        < expected["skyrmions per frame, mean (least – most)"][2]
    )
    assert expected["tracks spanning the whole movie"][0] < expected["tracks"][0]
    frames_text = rows["frames"]
    assert frames_text.endswith(f"({dtype})"), frames_text
    rows["frames"] = frames_text.removesuffix(f"({dtype})")
    for label, values in expected.items():
        stated = _numbers(rows[label])
        assert len(stated) == len(values), (label, rows[label])
        for number, value in zip(stated, values, strict=True):
            agrees(number.text, float(value))
    assert agrees(rows["pixel size"], 14e-9).unit == "m"
    assert agrees(rows["frame interval"], 2e-9).unit == "s"


def test_the_report_says_which_command_made_it_when_and_with_which_skygas(tracked):
    from skygas._version import __version__

    out, movie, _ = tracked
    page = (out / "report.html").read_text()
    made = re.search(r"<p class=made>(.*?)</p>", page)
    assert made, "no 'Made by' line"
    line = made.group(1)
    assert line.startswith(f"Made by <code class=command>skygas track {movie}"), line
    assert re.search(r" on \d{4}-\d\d-\d\d \d\d:\d\d UTC, with skygas ", line), line
    assert line.endswith(f"with skygas {__version__}."), line
    # nothing in the report in e-notation (1.4e-08): numbers carry SI prefixes or ×10ⁿ
    text = re.sub(r"<(script|video|figure)\b.*?</\1>", "", page, flags=re.S)
    text = re.sub(r"<pre>.*?</pre>", "", text, flags=re.S)  # track.json as it is
    text = re.sub(r"<code class=command>.*?</code>", "", text)  # the command line as typed
    assert "nm" in text and "ns" in text
    assert not re.search(r"\d[eE][-+]\d", text), re.search(r".{40}\d[eE][-+]\d.{20}", text)


def test_json_prints_what_track_json_holds_and_nothing_else(tracked):
    out, _, proc = tracked
    assert json.loads(proc.stdout) == json.loads((out / "track.json").read_text())
    assert "located" not in proc.stderr  # no progress bar
