"""``skygas infer`` end to end on a small simulated gas: the files, their contents, the model."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest


@pytest.mark.slow
def test_infer_writes_a_model_every_device_reads(tmp_path):
    import xarray as xr

    from skygas.inference.synthetic import simulated_tracks
    from skygas.physics.materials import derive_thiele, load_material

    gas = simulated_tracks(skyrmions=8, frames=400, seed=2, frame_interval=2e-9)
    gas.tracks.to_csv(tmp_path / "tracks.csv", index=False)
    w, h = gas.width, gas.height
    pd.DataFrame({"x": [0, w, w, 0], "y": [0, 0, h, h]}).to_csv(
        tmp_path / "outline.csv", index=False
    )
    args = [
        sys.executable, "-m", "skygas.cli", "infer", "tracks.csv", "--pixel-size",
        str(gas.pixel_size), "--frame-interval", "2e-9", "--outline", "outline.csv",
        "--temperature", "300", "--out", "out", "--ibi-iterations", "1", "--ibi-frames", "200",
        "--json",
    ]  # fmt: skip
    proc = subprocess.run(args, cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    brief = json.loads(proc.stdout)
    out = tmp_path / "out"
    summary = json.loads((out / "inference.json").read_text())
    assert summary["diffusion_constant"] == brief["diffusion_constant"] > 0
    assert summary["diffusion_constant_error"] > 0
    assert summary["provenance"]["command_line"].startswith("skygas infer tracks.csv")
    assert len(summary["input"]["sha256"]) == 64
    ds = xr.open_dataset(out / "landscape.nc")
    assert set(ds.data_vars) >= {"U", "U_error", "pinning", "well_sampled"}
    assert ds.x.attrs["units"] == "m" and ds.U.attrs["units"] == "k_BT"
    # the model: a free skyrmion of it has the measured D and Hall angle
    material = load_material(str(out / "model.toml"))
    t = derive_thiele(material)
    assert t.diffusion_constant(300) == pytest.approx(summary["diffusion_constant"], rel=1e-9)
    if not material.antiferromagnetic:
        assert math.atan2(t.gyrocoupling, t.friction) == pytest.approx(
            summary["hall_angle"], abs=1e-9
        )
    assert material.wall_table is None or np.all(np.array(material.wall_table.force) >= 0)
    assert "report.html" in {p.name for p in out.iterdir()}
    # a device runs on it
    run = subprocess.run(
        [sys.executable, "-m", "skygas.cli", "reshuffle", "--material", "out/model.toml",
         "--out", "rs", "--duration", "5e-8"],
        cwd=tmp_path, capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr
