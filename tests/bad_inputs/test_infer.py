"""Bad input to ``skygas infer``: each refused in one line before any work, and a full disk.

The subprocess cases run the real command line (:func:`.catalogue.refused`): exit status 2, one
``skygas: error:`` line naming the file, the column or row and what to do, the folder left as
it was. A full disk cannot be reached from a subprocess: those cases run ``main()`` in-process
with the lowest write made to fail, as a full disk fails it.
"""

from __future__ import annotations

import collections
import errno
import shutil
from pathlib import Path

import numpy as np
import pytest

from .catalogue import refused

_ROWS = "".join(f"{f},{p},{20 + p + 0.1 * f},{30 + p}\n" for f in range(40) for p in range(3))
_HEADER = "frame,particle,x,y\n"
FILES = {
    "tracks.csv": _HEADER + _ROWS,
    "nan.csv": _HEADER + _ROWS + "40,0,nan,30\n",
    "inf.csv": _HEADER + _ROWS + "40,0,21,inf\n",
    "header.csv": _HEADER,
    "far-frame.csv": _HEADER + _ROWS + "1e12,0,20,30\n",
    "half-frame.csv": _HEADER + _ROWS + "40.5,0,20,30\n",
    "nanometres.csv": "x,y\n0,0\n1000,0\n1000,1000\n0,1000\n",
    "track-folder/track.json": "{}",
}
_INFER = ["infer", "--frame-interval", "5e-9", "--temperature", "300", "--out", "OUT"]
_PX = ["--pixel-size", "1e-8"]


def _masks(folder: Path) -> None:
    """A colour mask, an all-white and an all-black one (PNG, 40 × 40 pixels)."""
    from PIL import Image

    colour = np.zeros((40, 40, 3), np.uint8)
    colour[..., 0] = 255  # red outside
    colour[5:35, 5:35] = (0, 255, 0)  # green device
    Image.fromarray(colour).save(folder / "colour.png")
    Image.fromarray(np.full((40, 40), 255, np.uint8)).save(folder / "white.png")
    Image.fromarray(np.zeros((40, 40), np.uint8)).save(folder / "black.png")


CASES = {
    "a NaN position": ([*_INFER, "nan.csv", *_PX], "tracks.x = nan", "row 121 of nan.csv"),
    "an infinite position": ([*_INFER, "inf.csv", *_PX], "tracks.y = inf", "row 121"),
    "a header and no rows": ([*_INFER, "header.csv", *_PX], "header.csv", "header only"),
    "a frame number of 1e12": (
        [*_INFER, "far-frame.csv", *_PX],
        "tracks.frame",
        "fits in memory",
        "row 121 of far-frame.csv",
    ),
    "a frame number that is not whole": (
        [*_INFER, "half-frame.csv", *_PX],
        "tracks.frame = 40.5",
        "whole frame numbers",
    ),
    "a colour mask": (
        [*_INFER, "tracks.csv", *_PX, "--outline", "colour.png"],
        "colour.png",
        "one grey or 1-bit channel",
    ),
    "an all-white mask": (
        [*_INFER, "tracks.csv", *_PX, "--outline", "white.png"],
        "white.png",
        "all non-zero",
    ),
    "an all-black mask": (
        [*_INFER, "tracks.csv", *_PX, "--outline", "black.png"],
        "black.png",
        "all zero",
    ),
    "a pixel size in nanometres": (
        [*_INFER, "tracks.csv", "--pixel-size", "14"],
        "--pixel-size = 14.0",
        "did you mean 14e-9",
    ),
    "an outline in nanometres": (
        [*_INFER, "tracks.csv", *_PX, "--outline", "nanometres.csv"],
        "--outline",
        "did you mean 1000e-9",
        "nanometres.csv",
    ),
    "a periodic box in nanometres": (
        [*_INFER, "tracks.csv", *_PX, "--periodic", "1000", "1000"],
        "--periodic",
        "did you mean 1000e-9",
    ),
    "a skyrmion radius under a picometre": (
        [*_INFER, "tracks.csv", *_PX, "--skyrmion-radius", "1e-15"],
        "--skyrmion-radius",
        "did you mean nanometres",
    ),
    "a track folder without its table": (
        [*_INFER, "track-folder", *_PX],
        "track-folder",
        "tracks.csv",
    ),
}


@pytest.mark.parametrize("name", list(CASES))
def test_infer_refuses_in_one_line_before_any_work(name, tmp_path):
    args, *expected = CASES[name]
    for relative, text in FILES.items():
        (tmp_path / relative).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / relative).write_text(text)
    _masks(tmp_path)
    refused(args, tmp_path, *expected)


# -- a full disk ------------------------------------------------------------------------------
def _small_files():
    """The five files of an inference, small, made by the writers ``infer`` uses."""
    import xarray as xr

    from skygas.inference.files import OutputFile
    from skygas.runs.run_driver import write_atomic, write_json, write_netcdf

    dataset = xr.Dataset({"U": (("y", "x"), np.zeros((3, 4)))})

    def text(words: str) -> OutputFile:
        return OutputFile(lambda p: write_atomic(p, lambda tmp: tmp.write_text(words)), 0)

    return {
        "landscape-map.npy": text("map"),
        "model.toml": text("[material]\n"),
        "inference.json": OutputFile(lambda p: write_json(p, {"d": 1.0}), 0),
        "landscape.nc": OutputFile(lambda p: write_netcdf(dataset, p), int(dataset.nbytes)),
        "report.html": text("<html></html>"),
    }


def _infer_in_process(tmp_path, monkeypatch, capsys) -> tuple[int, list[str]]:
    """``skygas infer`` through ``main()``, its inference replaced by the small files."""
    import skygas.inference
    from skygas import cli
    from skygas.inference import files

    monkeypatch.setattr(skygas.inference, "infer", lambda *args, **kwargs: object())
    monkeypatch.setattr(files, "output_files", lambda result: _small_files())
    monkeypatch.chdir(tmp_path)
    (tmp_path / "tracks.csv").write_text(FILES["tracks.csv"])
    status = cli.main([*_INFER, "tracks.csv", *_PX, "--quiet"])
    return status, capsys.readouterr().err.strip().splitlines()


def _no_result(out: Path) -> None:
    """Nothing of the inference is left: no file under its real or its temporary name (and
    the folder, which the command made, removed)."""
    assert not out.exists(), sorted(p.name for p in out.iterdir())


def test_a_full_disk_leaves_no_result_and_says_so(tmp_path, monkeypatch, capsys):
    """The disk fills while the last file is written: no file is kept, one line, exit 74."""
    real = Path.write_text

    def full(self, *args, **kwargs):
        if "report" in self.name:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(self, *args, **kwargs)

    monkeypatch.setattr(Path, "write_text", full)
    status, err = _infer_in_process(tmp_path, monkeypatch, capsys)
    assert status == 74
    assert len(err) == 1, err
    assert err[0].startswith("skygas: error: could not write OUT/report.html")
    assert "(No space left on device)" in err[0]
    _no_result(tmp_path / "OUT")


def test_a_netcdf_file_hdf5_cannot_write_on_a_full_disk_is_the_full_disk(
    tmp_path, monkeypatch, capsys
):
    """HDF5 says only "HDF error"; with the disk full, the line says the disk is full."""
    import xarray as xr

    def hdf_error(self, path, *args, **kwargs):
        Path(path).write_bytes(b"\x89HDF")  # what it had written when the disk filled
        raise RuntimeError("NetCDF: HDF error")

    usage = collections.namedtuple("usage", "total used free")
    monkeypatch.setattr(xr.Dataset, "to_netcdf", hdf_error)
    monkeypatch.setattr(shutil, "disk_usage", lambda path: usage(2**30, 2**30, 0))
    status, err = _infer_in_process(tmp_path, monkeypatch, capsys)
    assert status == 74
    assert len(err) == 1, err
    assert "could not write OUT/landscape.nc (No space left on device)" in err[0]
    _no_result(tmp_path / "OUT")
