"""From ``skygas track`` to ``skygas infer``: the pixel size travels in track.json, ``--drift`` is
one option.

A track folder (the shipped movie's first 8 frames, tracked with a pixel size of 14 nm) is
handed to ``skygas infer`` without ``--pixel-size``: the pixel size comes from track.json, in one
line on stderr; a ``--pixel-size`` that differs is refused in one line naming both, before any
work. The inference itself is not run here (tests/inference test it): the command's call of
:func:`skygas.inference.infer` is replaced by one that records what it was given.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from skygas.core.errors import InputError

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = ROOT / "examples" / "tracking" / "chamber-movie.tif"
PIXEL = 14e-9


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    """The output folder of ``skygas track`` on 8 frames, pixel size 14 nm given."""
    import tifffile

    from skygas.movies.track_run import track_movie

    root = tmp_path_factory.mktemp("handoff")
    movie = root / "good.tif"
    tifffile.imwrite(movie, tifffile.imread(SHIPPED, key=range(8)), photometric="minisblack")
    track_movie(movie, root / "track", pixel_size=PIXEL, progress=False)
    return root / "track"


class _Stop(Exception):
    pass


def _infer_given(monkeypatch, capsys, args: list[str]) -> tuple[int, dict, str]:
    """Run ``skygas infer ARGS`` up to its call of the inference: status, its arguments, stderr."""
    import skygas.inference
    from skygas import cli

    seen: dict = {}

    def recorded(source, **kwargs):
        seen.update(kwargs, source=source)
        raise KeyboardInterrupt  # stop here: the command ends with status 130

    monkeypatch.setattr(skygas.inference, "infer", recorded)
    status = cli.main(["infer", *args])
    return status, seen, capsys.readouterr().err


@pytest.mark.parametrize("name", ["folder", "tracks.csv"])
def test_infer_takes_the_pixel_size_of_a_track_folder_and_says_so(
    name, folder, tmp_path, monkeypatch, capsys
):
    source = folder if name == "folder" else folder / "tracks.csv"
    recorded = json.loads((folder / "track.json").read_text())["pixel_size_m"]
    assert recorded == PIXEL
    args = [str(source), "--frame-interval", "2e-9", "--temperature", "300"]
    status, seen, err = _infer_given(monkeypatch, capsys, [*args, "--out", str(tmp_path / "o")])
    assert status == 130 and seen["pixel_size"] == recorded
    lines = [line for line in err.splitlines() if "pixel size" in line]
    assert lines == [
        f"skygas infer: pixel size 14 nm from {folder / 'track.json'} (no --pixel-size given)"
    ]
    # the same pixel size given: taken, and nothing said about it
    status, seen, err = _infer_given(
        monkeypatch, capsys, [*args, "--pixel-size", "14e-9", "--out", str(tmp_path / "p")]
    )
    assert status == 130 and seen["pixel_size"] == 14e-9 and "track.json" not in err


def test_a_pixel_size_that_is_not_track_json_s_is_refused_in_one_line(folder, tmp_path, capsys):
    from skygas import cli

    out = tmp_path / "o"
    args = ["infer", str(folder), "--pixel-size", "10e-9", "--frame-interval", "2e-9"]
    assert cli.main([*args, "--temperature", "300", "--out", str(out)]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("skygas: error: --pixel-size = 1e-08"), lines
    assert "1.4e-08" in lines[0] and str(folder / "track.json") in lines[0]
    assert not out.exists()  # refused before any work


def test_tracks_elsewhere_need_a_pixel_size_and_the_api_names_track_json_s(folder, tmp_path):
    from skygas.inference.tracks import load_tracks, pixel_size_for

    # a table of another name, or moved away from its track.json: no record to read
    moved = tmp_path / "mine.csv"
    shutil.copy(folder / "tracks.csv", moved)
    assert pixel_size_for(moved, None) == (None, None)
    shutil.copy(folder / "tracks.csv", tmp_path / "tracks.csv")
    assert pixel_size_for(tmp_path / "tracks.csv", None) == (None, None)
    # from Python, nothing is taken silently: the refusal names the value to give
    with pytest.raises(InputError, match=r"give --pixel-size 1\.4e-08, the pixel size .*track"):
        load_tracks(folder, None, 2e-9)
    with pytest.raises(InputError, match="--pixel-size"):
        load_tracks(folder / "tracks.csv", 2 * PIXEL, 2e-9)


def test_a_track_json_without_a_pixel_size_leaves_it_to_the_user(folder, tmp_path):
    from skygas.inference.tracks import pixel_size_for

    copy = tmp_path / "track"
    shutil.copytree(folder, copy)
    record = json.loads((copy / "track.json").read_text())
    (copy / "track.json").write_text(json.dumps({**record, "pixel_size_m": None}))
    assert pixel_size_for(copy, None) == (None, None)
    assert pixel_size_for(copy, 3e-9) == (3e-9, None)
    (copy / "track.json").write_text("{not json")
    with pytest.raises(InputError, match="track.json"):
        pixel_size_for(copy, None)
    assert pixel_size_for(copy, 3e-9) == (3e-9, None)  # a given size needs no record


@pytest.mark.parametrize(
    ("command", "typed", "read"),
    [
        ("track", "yes", "yes"),
        ("track", "no", "no"),
        ("track", "on", "yes"),
        ("track", "OFF", "no"),
        ("infer", "auto", "auto"),
        ("infer", "yes", "yes"),
        ("infer", "on", "yes"),
        ("infer", "off", "no"),
    ],
)
def test_drift_has_one_vocabulary_in_track_and_infer(command, typed, read):
    from skygas.cli import build_parser

    base = {
        "track": ["track", "m.tif", "--out", "o"],
        "infer": ["infer", "t.csv", "--temperature", "300", "--out", "o"],
    }[command]
    assert build_parser().parse_args([*base, "--drift", typed]).drift == read


def test_drift_refuses_other_words_and_track_has_no_auto(capsys):
    from skygas.cli import build_parser

    parser = build_parser()
    for args in (
        ["track", "m.tif", "--out", "o", "--drift", "auto"],
        ["infer", "t.csv", "--temperature", "300", "--out", "o", "--drift", "maybe"],
    ):
        with pytest.raises(SystemExit) as stop:
            parser.parse_args(args)
        assert stop.value.code == 2
        assert "argument --drift: invalid choice" in capsys.readouterr().err
    defaults = {
        c: parser.parse_args(b).drift
        for c, b in (
            ("track", ["track", "m.tif", "--out", "o"]),
            ("infer", ["infer", "t.csv", "--temperature", "300", "--out", "o"]),
        )
    }
    assert defaults == {"track": "no", "infer": "auto"}
