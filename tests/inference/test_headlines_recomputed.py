"""Every number of ``skygas infer``'s headline, recomputed here from the files it wrote.

One real run (module fixture): free Brownian walkers, drawn here with NumPy, in a walled square
far larger than their excursions, tracked with a Gaussian localisation error and written as
trackpy's table. ``skygas infer`` (no pair law, no wall law asked for) keeps no force for them,
so that its D, its localisation error and their jackknife errors are the covariance estimator's
of the raw steps, which this file computes itself from tracks.csv, as it computes the short-lag
MSD fit and the movie's MSD(τ)/4τ of the self-check. Numbers the tracks alone cannot give (the
model's run, the held-out likelihoods, the Boltzmann cross-check) are read from inference.json,
and the verdicts are recomputed from them with the tolerances the report states. A stated
number agrees when it lies within half a unit of its last printed digit of the recomputed one
(so does its error). The MSD figure's points and lines are read back from its matplotlib
objects.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import re

import numpy as np
import pandas as pd
import pytest
import xarray as xr
from tests.outputs.test_headlines_recomputed import _numbers, agrees, captions, headline

from skygas.cli import main

pytestmark = pytest.mark.slow

PIXEL = 1e-7  # m
FRAME = 0.01  # s
TEMPERATURE = 300.0  # K
D_TRUE = 0.31e-12  # m²/s
SIGMA_TRUE = 20e-9  # m, per coordinate
WALKERS = 8  # fewer than 16 tracks: the jackknife is over blocks of time only
FRAMES = 640
SIDE = 400  # pixels: the walled square
#: the inference's blocks of time (its jackknife, the short-lag fit's blocked errors) and the
#: self-check's; the short-lag fit's lags; the self-check's lags (those with 8 blocks of at least
#: 4 lags each), as docs/inference.md states them
BLOCKS, CHECK_BLOCKS = 16, 8
FIT_LAGS = (1, 2, 3)
CHECK_LAGS = [lag for lag in (1, 3, 10, 30, 100) if CHECK_BLOCKS * 4 * lag <= FRAMES]
#: the self-check's tolerances, as the report states them
MAX_Z, MSD_TOLERANCE, MAX_CHI2 = 3.0, 0.2, 3.0


def walkers() -> pd.DataFrame:
    """Free walkers with D_TRUE, seen with SIGMA_TRUE, as trackpy's table (pixels)."""
    rng = np.random.default_rng(20261129)
    steps = rng.normal(0.0, math.sqrt(2 * D_TRUE * FRAME), (FRAMES, WALKERS, 2))
    steps[0] = 0.0
    start = np.column_stack([np.linspace(120, 280, WALKERS), np.full(WALKERS, 200.0)]) * PIXEL
    seen = start + np.cumsum(steps, axis=0) + rng.normal(0.0, SIGMA_TRUE, steps.shape)
    f, p = np.meshgrid(np.arange(FRAMES), np.arange(WALKERS), indexing="ij")
    return pd.DataFrame(
        {
            "frame": f.ravel(),
            "particle": p.ravel(),
            "x": seen[..., 0].ravel() / PIXEL,
            "y": seen[..., 1].ravel() / PIXEL,
        }
    )


@pytest.fixture(scope="module")
def inferred(tmp_path_factory):
    """``skygas infer`` on the walkers: its folder, the figures drawn, its standard output."""
    from skygas.inference import report

    root = tmp_path_factory.mktemp("infer-headline")
    walkers().to_csv(root / "tracks.csv", index=False)
    square = pd.DataFrame({"x": [0, SIDE, SIDE, 0], "y": [0, 0, SIDE, SIDE]}) * PIXEL
    square.to_csv(root / "outline.csv", index=False)
    drawn = []
    png = report._png

    def keep(fig):
        drawn.append(fig)
        return png(fig)

    out = io.StringIO()
    with pytest.MonkeyPatch.context() as patch, contextlib.redirect_stdout(out):
        patch.setattr(report, "_png", keep)
        argv = [
            "infer", root / "tracks.csv", "--pixel-size", PIXEL, "--frame-interval", FRAME,
            "--temperature", TEMPERATURE, "--outline", root / "outline.csv", "--walls", "none",
            "--pair", "none", "--drift", "no", "--check-frames", FRAMES, "--out", root / "out",
        ]  # fmt: skip
        assert main([str(a) for a in argv]) == 0
    return root, drawn, out.getvalue()


# -- the statistics, written here ------------------------------------------------------------
def positions(path) -> tuple[np.ndarray, np.ndarray]:
    """x, y [m] of a tracks table, (frames, walkers): every walker is in every frame."""
    table = pd.read_csv(path).sort_values(["frame", "particle"])
    frames, walkers_ = table["frame"].nunique(), table["particle"].nunique()
    assert len(table) == frames * walkers_
    x = table["x"].to_numpy().reshape(frames, walkers_) * PIXEL
    y = table["y"].to_numpy().reshape(frames, walkers_) * PIXEL
    return x, y


def block_of(frames: int, blocks: int) -> np.ndarray:
    """The contiguous, nearly equal block of time of each frame 0 … frames − 1."""
    edges = np.rint(np.linspace(0, frames, blocks + 1)).astype(int)
    return np.searchsorted(edges, np.arange(frames), side="right") - 1


def jackknife(per_block: np.ndarray) -> float:
    """Standard error from the leave-one-block-out values."""
    n = len(per_block)
    return math.sqrt((n - 1) / n * np.sum((per_block - per_block.mean()) ** 2))


def covariance_estimator(x, y) -> dict[str, float]:
    """D and σ by the covariance estimator with their leave-one-block-out jackknife errors.

    Each step n → n + 1 with the step before it: D = (⟨Δr²⟩ + 2⟨Δr_n·Δr_{n−1}⟩)/4Δt and
    σ² = −⟨Δr_n·Δr_{n−1}⟩/2 per coordinate (Vestergaard, Blainey & Flyvbjerg 2014), each step
    in the block of time of the frame it starts from.
    """
    dx, dy = np.diff(x, axis=0), np.diff(y, axis=0)
    square = dx[1:] ** 2 + dy[1:] ** 2
    lagged = dx[1:] * dx[:-1] + dy[1:] * dy[:-1]
    block = block_of(len(x), BLOCKS)[1:-1]
    s = np.array([square[block == b].sum() for b in range(BLOCKS)])
    c = np.array([lagged[block == b].sum() for b in range(BLOCKS)])
    n = np.array([square[block == b].size for b in range(BLOCKS)])

    def d_and_s2(keep):
        sq, lag = s[keep].sum() / n[keep].sum(), c[keep].sum() / n[keep].sum()
        return (sq + 2 * lag) / (4 * FRAME), -lag / 2

    d, s2 = d_and_s2(np.ones(BLOCKS, bool))
    out = [d_and_s2(np.arange(BLOCKS) != b) for b in range(BLOCKS)]
    d_err, s2_err = (
        jackknife(np.array([o[0] for o in out])),
        jackknife(np.array([o[1] for o in out])),
    )
    return {
        "D": d,
        "D_error": d_err,
        "sigma": math.sqrt(s2),
        "sigma_error": s2_err / (2 * math.sqrt(s2)),
    }


def msd_fit(x, y) -> tuple[float, float]:
    """D of MSD(τ) = 4σ² + 4Dτ + cτ² through lags 1–3, with its error over blocks of time.

    The error: the standard deviation of the fits to each block's MSD (displacements by the
    block of the frame they start from) over √blocks.
    """
    tau = np.array(FIT_LAGS) * FRAME
    sums = np.zeros((BLOCKS, len(FIT_LAGS)))
    counts = np.zeros((BLOCKS, len(FIT_LAGS)))
    block = block_of(len(x), BLOCKS)
    for k, lag in enumerate(FIT_LAGS):
        r2 = (x[lag:] - x[:-lag]) ** 2 + (y[lag:] - y[:-lag]) ** 2
        for b in range(BLOCKS):
            mine = block[: len(x) - lag] == b
            sums[b, k], counts[b, k] = r2[mine].sum(), r2[mine].size

    def slope(msd):
        return np.polyfit(tau, msd, 2)[1] / 4

    per_block = np.array([slope(sums[b] / counts[b]) for b in range(BLOCKS) if counts[b].all()])
    return slope(sums.sum(0) / counts.sum(0)), per_block.std(ddof=1) / math.sqrt(len(per_block))


def movie_msd(x, y) -> tuple[np.ndarray, np.ndarray]:
    """The self-check's MSD(τ)/4τ of the movie at CHECK_LAGS and its error over 8 blocks."""
    values, errors = [], []
    block = block_of(len(x), CHECK_BLOCKS)
    for lag in CHECK_LAGS:
        r2 = (x[lag:] - x[:-lag]) ** 2 + (y[lag:] - y[:-lag]) ** 2
        means = [r2[block[: len(x) - lag] == b].mean() for b in range(CHECK_BLOCKS)]
        scale = 4 * lag * FRAME
        values.append(r2.mean() / scale)
        errors.append(np.std(means, ddof=1) / math.sqrt(CHECK_BLOCKS) / scale)
    return np.array(values), np.array(errors)


def after(text: str, words: str) -> str:
    """``text`` from just after ``words`` (the numbers of a sentence, not those of its label)."""
    assert words in text, (words, text)
    return text.split(words, 1)[1]


# -- the tests ---------------------------------------------------------------------------------
def test_infer_headline_is_recomputed_from_the_tracks(inferred):
    root, _, stdout = inferred
    out = root / "out"
    s = json.loads((out / "inference.json").read_text())
    # the premise of the recomputation: no force kept, so D is the raw steps' estimator
    assert s["model_selection"]["terms"] == [] and s["film"]["kind"] == "walls"
    assert not s["sampling_correction"]["applied"]
    rows, _ = headline(out / "report.html")
    x, y = positions(root / "tracks.csv")
    cve = covariance_estimator(x, y)

    # the checks lead, in the report and on the terminal
    labels = list(rows)
    assert labels[0] == "frames resolve the motion (D, Hall angle, forces)"
    assert stdout.splitlines()[0].startswith(labels[0] + ": passed: ")
    # no force: no drift within a frame, which the frames then trivially resolve
    frames_row = rows[labels[0]]
    assert frames_row.startswith("passed: ")
    agrees(after(frames_row, "adds "), 0.0)
    assert "(below 5 %)" in frames_row

    # D from the noise: the covariance estimator of the tracks, with its jackknife error
    agrees(rows["diffusion constant D (from the noise)"], cve["D"], cve["D_error"], "m²/s")
    agrees(rows["localisation error"], cve["sigma"], cve["sigma_error"], "m")
    d_fit, d_fit_error = msd_fit(x, y)
    agrees(
        rows["D of the short-lag MSD fit (lags 1–3, 4σ² + 4Dτ + cτ²)"], d_fit, d_fit_error, "m²/s"
    )
    # and the model written has that D: a free skyrmion of model.toml diffuses with it
    from skygas.physics.materials import derive_thiele, load_material

    model = derive_thiele(load_material(str(out / "model.toml")))
    assert model.diffusion_constant(TEMPERATURE) == pytest.approx(cve["D"], rel=1e-6)
    # no force that turns: the Hall angle is not fixed, and the model keeps the base material's
    base = derive_thiele(load_material("S2"))
    kept = math.degrees(math.atan2(base.gyrocoupling, base.friction))
    hall = rows["Hall angle"]
    assert hall.startswith("none (not fixed")
    agrees(after(hall, "base material's "), kept)
    assert math.degrees(math.atan2(model.gyrocoupling, model.friction)) == pytest.approx(kept)

    # the self-check: the movie's MSD(τ)/4τ recomputed, the model's run read from the file
    m = s["consistency_check"]["msd"]
    assert m["lag_time_s"] == pytest.approx(np.array(CHECK_LAGS) * FRAME)
    movie, movie_error = movie_msd(x, y)
    assert m["movie_msd_over_4tau_m2_s"] == pytest.approx(movie, rel=1e-9)
    assert m["movie_error_m2_s"] == pytest.approx(movie_error, rel=1e-9)
    model_msd, model_error = (
        np.array(m["model_msd_over_4tau_m2_s"]),
        np.array(m["model_error_m2_s"]),
    )
    z = (model_msd - movie) / np.hypot(movie_error, model_error)
    k = int(np.argmax(np.abs(z)))
    row = rows["self-check: MSD(τ)/4τ within its errors"]
    assert row.startswith("passed: " if np.all(np.abs(z) <= MAX_Z) else "FAILED: ")
    stated = _numbers(after(row, " is "))
    agrees(stated[0].text, z[k])  # the sign: a leading − is read, a + is not printed as a sign
    assert (z[k] < 0) == after(row, " is ").startswith("−")
    agrees(stated[1].text, CHECK_LAGS[k] * FRAME, unit="s")
    relative = model_msd / movie - 1
    k = int(np.argmax(np.abs(relative)))
    row = rows["self-check: MSD(τ)/4τ within 20 %"]
    assert row.startswith("passed: " if np.all(np.abs(relative) <= MSD_TOLERANCE) else "FAILED: ")
    stated = _numbers(after(row, " is "))
    agrees(stated[0].text, relative[k])
    assert (relative[k] < 0) == after(row, " is ").startswith("−")
    agrees(stated[1].text, CHECK_LAGS[k] * FRAME, unit="s")
    agrees(stated[2].text, model_msd[k], unit="m²/s")
    agrees(stated[3].text, movie[k], movie_error[k], unit="m²/s")
    # g(r) without a pair law: shown, not judged
    assert rows["self-check: g(r)"].startswith("shown, not judged")
    density = s["consistency_check"]["density"]
    if density["chi2_per_node"] is not None:
        row = rows["self-check: density map"]
        assert row.startswith("passed: " if density["chi2_per_node"] <= MAX_CHI2 else "FAILED: ")
        stated = _numbers(after(row, "χ² per node "))
        agrees(stated[0].text, density["chi2_per_node"])
        assert stated[1].value == density["nodes_compared"]
    # the verdicts of inference.json's machine-readable list are the report's
    for check in s["consistency_check"]["checks"]:
        assert rows[check["name"]].startswith("passed: " if check["passed"] else "FAILED: ")

    # what only the model's fit knows: as inference.json records it
    landscape = s["model_selection"]["candidates"]["landscape"]
    forces = rows["forces the data show (held-out log-likelihood each adds)"]
    assert forces.startswith("landscape: left out, ")
    agrees(after(forces, "left out, "), landscape["delta_log_likelihood"], landscape["error"])
    assert rows["pair force mid-range"] == "—" and rows["wall force mid-range"] == "—"
    # the shares of the film sampled: the masks of landscape.nc on its grid
    with xr.open_dataset(out / "landscape.nc") as ds:
        h = float(ds.x[1] - ds.x[0])
        sampled, well = float(ds.sampled.sum()) * h * h, float(ds.well_sampled.sum()) * h * h
    area = s["landscape"]["film_area_m2"]
    shares = rows["share of the film sampled; well sampled"].split(";")
    agrees(shares[0], sampled / area)
    agrees(shares[1], well / area)
    cross = s["boltzmann_cross_check"]
    if "rms_difference_kT" in cross:
        row = rows["landscape: forces against Boltzmann inversion"]
        agrees(row, cross["rms_difference_kT"])
        if cross["correlation"] is not None:
            agrees(after(row, "correlation "), cross["correlation"])


def test_the_msd_figure_draws_the_ds_it_names_and_says_its_verdict(inferred):
    root, drawn, _ = inferred
    out = root / "out"
    x, y = positions(root / "tracks.csv")
    cve = covariance_estimator(x, y)
    d_fit, _ = msd_fit(x, y)
    (fig,) = [f for f in drawn if f.axes and f.axes[0].get_ylabel() == "MSD/4τ [m²/s]"]
    ax = fig.axes[0]
    lines = {line.get_label(): line.get_ydata() for line in ax.get_lines()}
    # each horizontal line sits at the D it is labelled with
    assert np.allclose(lines["D of the model (from the noise of the steps)"], cve["D"], rtol=1e-9)
    assert np.allclose(lines["D of the short-lag MSD fit (lags 1–3)"], d_fit, rtol=1e-9)
    assert not any("before the correction" in label for label in lines)  # none was made
    # the movie's points are the movie's MSD(τ)/4τ
    movie_points = [c for c in ax.containers if c.get_label() == "movie"][0][0]
    movie, _ = movie_msd(x, y)
    assert np.allclose(movie_points.get_ydata(), movie, rtol=1e-9)
    assert np.allclose(movie_points.get_xdata(), np.array(CHECK_LAGS) * FRAME)
    # the caption names the lines and gives the verdict against the stated tolerances
    s = json.loads((out / "inference.json").read_text())
    m = s["consistency_check"]["msd"]
    relative = np.array(m["model_msd_over_4tau_m2_s"]) / movie - 1
    (caption,) = [c for c in captions(out / "report.html") if c.startswith("MSD(τ)/4τ")]
    assert (
        "solid, the model's D" in caption and "dashed, the slope D of the quadratic fit" in caption
    )
    within = "Passed" if np.all(np.abs(relative) <= MSD_TOLERANCE) else "FAILED"
    assert f"{within} (MSD(τ)/4τ within 20 %)" in caption
    assert re.search(r"(Passed|FAILED) \(MSD\(τ\)/4τ within its errors\)", caption)
