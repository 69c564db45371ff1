"""A simulated gas rendered as a microscope movie and tracked back (skygas.movies).

The gas: 20 skyrmions of S2 in a closed 700 nm square over a disorder landscape of 2 k_BT rms,
150 frames 2 ns apart, drawn at 14 nm per pixel through a PSF of σ = 20 nm with read and shot
noise (SNR of a skyrmion's depth to the noise ≈ 40). Its true positions are known to the bit,
so the tracker's localisation error, missed and false detections and wrong links are counted
exactly. Measured: 0.08 px RMS per axis, no wrong link (docs/tracking.md).
"""

from __future__ import annotations

import hashlib
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = ROOT / "examples" / "tracking" / "chamber-movie.tif"
PIXEL = 14e-9
FRAMES = 150


@pytest.fixture(scope="module")
def gas():
    """(positions per frame [m], skyrmion ids per frame, bounds [m], diameter [m])."""
    from skygas.analysis.frames import Frames
    from skygas.engine import Simulation
    from skygas.fields.landscape import Disorder
    from skygas.physics.geometry import rectangle

    sim = Simulation(
        rectangle(700e-9, 700e-9),
        "S2",
        temperature=300.0,
        seed=11,
        landscape=[Disorder(rms_kT=2.0, correlation_length=60e-9)],
    )
    sim.add_random(20, min_separation=1.5)
    sim.run((FRAMES + 0.5) * 2e-9, record_interval=2e-9)
    frames = Frames.from_trajectories(sim.trajectories())
    assert frames.n_frames >= FRAMES
    ids, xy = zip(*(frames.frame(f) for f in range(frames.n_frames)), strict=True)
    bounds = tuple(np.array(sim.outline.bounds_nm) * 1e-9)
    return list(xy), list(ids), bounds, sim.thiele.skyrmion_diameter


def _movie(gas, folder: Path, contrast: str = "dark", frames: int = FRAMES) -> tuple:
    from skygas.movies.render import RenderSettings, grid_for, render_frames, write_movie

    xy, _, bounds, diameter = gas
    grid = grid_for(bounds, PIXEL, diameter)
    settings = RenderSettings(
        pixel_size=PIXEL,
        psf_sigma=20e-9,
        contrast=contrast,
        noise=2.0,
        photons=20000,
        illumination_drift=0.05,
        seed=3,
    )
    movie = render_frames(xy[:frames], grid, diameter, settings)
    path = folder / f"{contrast}.tif"
    write_movie(path, movie, {"pixel_size_m": PIXEL, "frame_interval_s": 2e-9})
    return path, grid


def test_disc_profile_keeps_the_disc_area_and_is_one_inside_a_wide_disc():
    from skygas.movies.render import disc_profile

    r = np.linspace(0, 12, 4001)
    f = disc_profile(3.0, 0.8, r)
    # a convolution with a unit-area Gaussian keeps the integral: 2π ∫ f r dr = π R²
    assert 2 * np.pi * np.trapezoid(f * r, r) == pytest.approx(np.pi * 9.0, rel=1e-4)
    assert disc_profile(20.0, 1.0, np.array([0.0]))[0] == pytest.approx(1.0, abs=1e-7)
    assert disc_profile(0.0, 1.0, np.array([1.0]))[0] == pytest.approx(np.exp(-0.5))


def test_tracked_positions_and_links_match_the_simulated_gas(gas, tmp_path):
    from skygas.movies.accuracy import tracking_accuracy
    from skygas.movies.track_run import track_movie

    path, grid = _movie(gas, tmp_path)
    result = track_movie(path, tmp_path / "out", progress=False)
    xy, ids, _, _ = gas
    truth = [(ids[f], *grid.to_pixels(xy[f][:, 0], xy[f][:, 1])) for f in range(FRAMES)]
    a = tracking_accuracy(result.tracks.table, truth)
    assert np.all(a["rms_px"] < 0.1), a  # pixels, per axis
    assert np.all(np.abs(a["bias_px"]) < 0.02), a  # no bias
    assert a["missed"] <= 0.01 * a["positions"]
    assert a["false"] <= 0.005 * a["positions"]
    assert a["links_right"] / (a["links_right"] + a["links_wrong"]) > 0.99
    summary = json.loads((tmp_path / "out" / "track.json").read_text())
    assert summary["counts"]["tracks"] == result.summary["counts"]["tracks"] <= 25


def test_the_contrast_sign_is_found_for_dark_and_bright_skyrmions(gas, tmp_path):
    from skygas.movies.choices import choose
    from skygas.movies.reading import open_movie

    for contrast in ("dark", "bright"):
        path, _ = _movie(gas, tmp_path, contrast, frames=12)
        choices = choose(open_movie(path))
        assert choices.contrast == contrast
        assert choices.sources["contrast"] == "from the data"
        assert (choices.skewness < 0) == (contrast == "dark")


def test_the_choices_scales_and_input_are_recorded(gas, tmp_path):
    from skygas.movies.track_run import track_movie

    path, _ = _movie(gas, tmp_path, frames=20)
    track_movie(path, tmp_path / "a", progress=False, memory=1, frame_interval=5e-9)
    s = json.loads((tmp_path / "a" / "track.json").read_text())
    c = s["choices"]
    assert c["sources"] == {
        "contrast": "from the data",
        "diameter": "from the data",
        "minmass": "from the data",
        "search_range": "from the data",
        "memory": "given",
    }
    assert c["diameter"] % 2 == 1 and c["minmass"] > 0 and c["search_range"] > 0
    assert c["memory"] == 1 and c["drift_subtraction"] is False
    assert s["pixel_size_m"] == PIXEL and s["scale_sources"]["pixel_size"] == "dark.json"
    assert s["frame_interval_s"] == 5e-9 and s["scale_sources"]["frame_interval"] == "given"
    assert s["provenance"]["input_sha256"] == hashlib.sha256(path.read_bytes()).hexdigest()
    header = (tmp_path / "a" / "tracks.csv").read_text().splitlines()[0]
    assert header.startswith("frame,particle,x,y,mass,size")
    for name in ("overlay.mp4", "report.html", "detections.png", "track_lengths.png"):
        assert (tmp_path / "a" / name).stat().st_size > 0
    # without the sidecar, the TIFF's own tags give the same scales
    path.with_suffix(".json").unlink()
    from skygas.movies.reading import open_movie

    movie = open_movie(path)
    assert movie.pixel_size == pytest.approx(PIXEL, rel=1e-9)
    assert movie.frame_interval == pytest.approx(2e-9)
    assert "TIFF" in movie.sources["pixel_size"]


def test_a_stage_drift_is_removed_when_asked(gas, tmp_path):
    from skygas.movies.render import RenderSettings, grid_for, render_frames, write_movie
    from skygas.movies.track_run import track_movie

    xy, _, bounds, diameter = gas
    frames = 60
    shift = 0.1 * PIXEL  # per frame, along x: 6 px over the movie
    moved = [p + np.array([shift * t, 0.0]) for t, p in enumerate(xy[:frames])]
    grid = grid_for(bounds, PIXEL, diameter + shift * frames)
    movie = render_frames(
        moved, grid, diameter, RenderSettings(pixel_size=PIXEL, psf_sigma=20e-9, seed=5)
    )
    path = tmp_path / "drifting.tif"
    write_movie(path, movie, {"pixel_size_m": PIXEL, "frame_interval_s": 2e-9})
    result = track_movie(path, tmp_path / "out", drift=True, progress=False)
    drift = result.tracks.drift
    assert drift is not None
    # the gas's own mean step is a random walk of ~σ_step/√N per frame, ≲ 1 px over 60 frames
    assert drift[-1, 0] == pytest.approx(0.1 * (frames - 1), abs=1.0)
    assert abs(drift[-1, 1]) < 1.0


def test_track_and_render_from_the_command_line(tmp_path):
    out = tmp_path / "track"
    proc = subprocess.run(
        [sys.executable, "-m", "skygas.cli", "track", str(SHIPPED), "--out", str(out), "--quiet"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    assert "30 tracks" in proc.stdout and "pixel size 14 nm, frame interval 2 ns" in proc.stdout
    summary = json.loads((out / "track.json").read_text())
    assert summary["frames"] == 400 and summary["choices"]["contrast"] == "dark"
    # the shipped sidecars: the outline on the movie's pixel grid and as a polygon in metres
    meta = json.loads(SHIPPED.with_suffix(".json").read_text())
    assert meta["frame_interval_s"] == 2e-9 and meta["true_model"]["temperature_K"] == 300.0
    from PIL import Image

    mask = np.asarray(Image.open(SHIPPED.with_name("chamber-movie-outline.png")))
    assert mask.shape == tuple(meta["shape"][1:])
    import pandas as pd

    tracks = pd.read_csv(out / "tracks.csv")
    rows, cols = np.rint(tracks["y"]).astype(int), np.rint(tracks["x"]).astype(int)
    assert np.all(mask[rows, cols] == 255)  # every skyrmion inside the device


def test_a_folder_of_images_tracks_like_the_stack(gas, tmp_path):
    import tifffile
    from PIL import Image

    from skygas.movies.track_run import track_movie

    path, _ = _movie(gas, tmp_path, frames=20)
    frames = tifffile.imread(path)
    folder = tmp_path / "frames"
    folder.mkdir()
    for i, image in enumerate(frames):
        Image.fromarray(image).save(folder / f"frame-{i:03d}.png")
    stack = track_movie(path, tmp_path / "a", progress=False).tracks.table
    pngs = track_movie(folder, tmp_path / "b", pixel_size=PIXEL, progress=False)
    assert pngs.summary["frames"] == 20 and pngs.summary["scale_sources"]["pixel_size"] == "given"
    assert pngs.summary["scale_sources"]["frame_interval"] == "not known"
    assert np.allclose(pngs.tracks.table[["x", "y"]], stack[["x", "y"]])


def test_render_from_the_command_line_writes_the_movie_and_its_sidecars(tmp_path):
    import tifffile
    import xarray as xr
    from PIL import Image

    config = (ROOT / "examples" / "tracking" / "chamber.toml").read_text()
    config = config.replace("duration = 1400e-9", "duration = 20e-9")
    config = config.replace("random_count = 30", "random_count = 5")
    (tmp_path / "gas.toml").write_text(config)

    def skygas(*args):
        return subprocess.run(
            [sys.executable, "-m", "skygas.cli", *args],
            cwd=tmp_path,
            capture_output=True,
            text=True,
            timeout=300,
        )

    assert skygas("simulate", "gas.toml", "--out", "gas", "--quiet").returncode == 0
    render = ("render", "gas", "--out", "m.tif", "--pixel-size", "20e-9", "--start", "4e-9")
    proc = skygas(*render, "--stride", "2", "--contrast", "bright", "--dtype", "uint16", "--quiet")
    assert proc.returncode == 0, proc.stderr
    frames = tifffile.imread(tmp_path / "m.tif")
    meta = json.loads((tmp_path / "m.json").read_text())
    assert frames.dtype == np.uint16 and frames.shape == tuple(meta["shape"])
    # frames at 2, 4, …, 20 ns: from 4 ns, every second one
    assert frames.shape[0] == 5 and meta["frame_interval_s"] == 4e-9
    assert meta["first_time_s"] == pytest.approx(4e-9)
    assert meta["settings"]["contrast"] == "bright" and meta["pixel_size_m"] == 20e-9
    assert meta["true_model"]["diffusion_constant_m2_s"] > 0
    mask = np.asarray(Image.open(tmp_path / "m-outline.png")) == 255
    landscape = xr.open_dataset(tmp_path / "m-landscape.nc")
    assert np.array_equal(np.isfinite(landscape["U"].values), mask)
    # the polygon, in the tracks' frame, holds the mask's pixels: (x, y) = (j, i)·p
    import shapely

    polygon = shapely.Polygon(np.loadtxt(tmp_path / "m-outline.csv", delimiter=",", skiprows=1))
    i, j = np.nonzero(mask)
    # (the grid's pixel centres may lie on the outline: a thousandth of a pixel of slack)
    assert shapely.contains_xy(polygon.buffer(2e-11), j * 20e-9, i * 20e-9).all()
    again = skygas(*render)
    assert again.returncode == 2 and "--overwrite" in again.stderr


def test_a_float_movie_of_any_scale_tracks_like_its_counts(gas, tmp_path):
    """A Kerr difference image: signed floats of amplitude 10⁻⁵, tracked like its counts."""
    import tifffile

    from skygas.movies.track_run import track_movie

    path, _ = _movie(gas, tmp_path, frames=20)
    counts = tifffile.imread(path)
    tifffile.imwrite(tmp_path / "kerr.tif", (counts - 150.0) * 1e-5, photometric="minisblack")
    stack = track_movie(path, tmp_path / "a", progress=False).tracks.table
    kerr = track_movie(tmp_path / "kerr.tif", tmp_path / "b", progress=False).tracks.table
    assert len(kerr) == len(stack)
    assert np.allclose(kerr[["x", "y"]], stack[["x", "y"]], atol=1e-6)
