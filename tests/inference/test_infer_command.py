"""``skygas infer`` end to end on tracks skygas's engine did not make: files, model, self-check."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from . import independent_gas as ig


def _infer(tmp_path, *options, tracks="tracks.csv", out="out"):
    args = [
        sys.executable, "-m", "skygas.cli", "infer", tracks, "--pixel-size", "1e-7",
        "--frame-interval", "0.01", "--temperature", "300", "--out", out, *options,
    ]  # fmt: skip
    return subprocess.run(args, cwd=tmp_path, capture_output=True, text=True, timeout=900)


@pytest.mark.slow
def test_infer_writes_a_model_every_device_reads(tmp_path):
    import xarray as xr

    from skygas.physics.materials import derive_thiele, load_material

    w = 20e-6
    spec = ig.GasSpec(
        skyrmions=30,
        frames=800,
        width=w,
        height=w,
        boundary="walls",
        hall_angle=math.radians(60),
        wells=ig.random_wells(15, w, w, 3.0, 1.5e-6, seed=2, margin=-3e-6),
        wall=(5.0, 1e-6),
    )
    gas = ig.simulate(spec)
    gas.tracks.to_csv(tmp_path / "tracks.csv", index=False)
    pd.DataFrame({"x": [0, w, w, 0], "y": [0, 0, w, w]}).to_csv(
        tmp_path / "outline.csv", index=False
    )
    proc = _infer(tmp_path, "--outline", "outline.csv", "--check-frames", "400", "--json")
    assert proc.returncode == 0, proc.stderr
    brief = json.loads(proc.stdout)
    out = tmp_path / "out"
    summary = json.loads((out / "inference.json").read_text())
    assert summary["diffusion_constant"] == brief["diffusion_constant"] > 0
    assert summary["provenance"]["command_line"].startswith("skygas infer tracks.csv")
    assert len(summary["input"]["sha256"]) == 64
    assert summary["film"]["kind"] == "walls"
    assert "landscape" in summary["model_selection"]["terms"]
    ds = xr.open_dataset(out / "landscape.nc")
    assert {"U", "U_error", "well_sampled", "sampled"} <= set(ds.data_vars)
    assert ds.x.attrs["units"] == "m" and ds.U.attrs["units"] == "k_BT"
    # the model: a free skyrmion of it has the inferred D and Hall angle; every number of it
    # is in inference.json
    material = load_material(str(out / "model.toml"))
    t = derive_thiele(material)
    assert t.diffusion_constant(300) == pytest.approx(summary["diffusion_constant"], rel=1e-9)
    assert math.atan2(t.gyrocoupling, t.friction) == pytest.approx(
        summary["hall_angle_in_model"], abs=1e-9
    )
    import tomllib

    model = tomllib.loads((out / "model.toml").read_text())
    (table,) = model["potentials"]
    assert table == summary["model"]["landscape"]  # as inference.json gives it
    values = np.load(out / table["path"])
    assert np.isfinite(values).any() and values.shape == ds.U.shape
    # a device runs on it
    run = subprocess.run(
        [sys.executable, "-m", "skygas.cli", "reshuffle", "--material", "out/model.toml",
         "--out", "rs", "--duration", "5e-8"],
        cwd=tmp_path, capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr


@pytest.mark.slow
def test_a_wrong_model_fails_its_self_check_loudly(tmp_path):
    """Skyrmions that do not interact, given the paper's S2 pair law on purpose.

    A run of that model keeps its skyrmions apart, the movie's do not: the self-check's g(r)
    fails, the terminal says so, and ``--strict`` exits with status 1.
    """
    w = 1.2e-6
    spec = ig.GasSpec(
        skyrmions=40,
        frames=600,
        frame_interval=2e-9,
        substeps=4,
        width=w,
        height=w,
        diffusion=4.38e-9,
        hall_angle=math.radians(77),
        boundary="periodic",
        pixel_size=5e-9,
    )
    gas = ig.simulate(spec)
    gas.tracks.to_csv(tmp_path / "tracks.csv", index=False)
    common = ["--pixel-size", "5e-9", "--frame-interval", "2e-9", "--pair", "material",
              "--check-frames", "600"]  # fmt: skip
    args = [sys.executable, "-m", "skygas.cli", "infer", "tracks.csv", "--temperature", "300"]
    proc = subprocess.run(
        [*args, *common, "--out", "out", "--strict"],
        cwd=tmp_path, capture_output=True, text=True, timeout=900,
    )  # fmt: skip
    assert proc.returncode == 1, proc.stderr
    assert "skygas: warning: the model fails its self-check: g(r)" in proc.stderr
    summary = json.loads((tmp_path / "out" / "inference.json").read_text())
    assert not summary["consistency_check"]["passed"]
    assert "pair_correlation" in summary["consistency_check"]["failed"]
    # the data say how strong the material's law is: nothing like it (its scale near 0)
    assert abs(summary["pair"]["material_law_scale"]) < 0.3
    report = (tmp_path / "out" / "report.html").read_text()
    assert "FAILED" in report


def test_a_successful_infer_is_quiet_and_leaves_only_its_files(tmp_path):
    """Five free walkers: the run succeeds with nothing on stderr, warnings shown (-W default:
    no library's warning reaches the user), and the folder holds its files, no partial one."""
    rng = np.random.default_rng(1)
    n, frames = 5, 60
    x, y = np.cumsum(rng.normal(0, 1, (2, frames, n)), axis=1) + 50 + 10 * np.arange(n)
    f, p = np.meshgrid(np.arange(frames), np.arange(n), indexing="ij")
    table = {"frame": f.ravel(), "particle": p.ravel(), "x": x.ravel(), "y": y.ravel()}
    pd.DataFrame(table).to_csv(tmp_path / "tracks.csv", index=False)
    args = [
        sys.executable, "-W", "default", "-m", "skygas.cli", "infer", "tracks.csv",
        "--pixel-size", "1e-7", "--frame-interval", "0.01", "--temperature", "300",
        "--check-frames", "50", "--quiet", "--out", "out",
    ]  # fmt: skip
    proc = subprocess.run(args, cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == ""
    names = {p.name for p in (tmp_path / "out").iterdir()}
    assert names == {
        "inference.json",
        "landscape.nc",
        "landscape-map.npy",
        "model.toml",
        "report.html",
        "manifest.json",
    }
