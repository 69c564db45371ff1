"""A breathing material given as a TOML file runs through ``skygas simulate`` end to end.

The radii land in trajectories.nc beside the positions, the run records which model it ran,
and a user can switch a breathing material back to rigid in the configuration.
"""

from __future__ import annotations

import json

import numpy as np
import xarray as xr

from skygas.cli import main
from skygas.physics.materials import preset

R0 = preset("S2").skyrmion_radius


def _film(path) -> None:
    """S2 with a harmonic E_self(R) (k = 4e-4 J/m², about S2's field sensitivity)."""
    radius = np.linspace(0.6 * R0, 1.4 * R0, 21)
    energy = 0.5 * 4e-4 * (radius - R0) ** 2
    path.write_text(
        '[material]\nbase = "S2"\nname = "soft-S2"\nparticle_model = "breathing"\n\n'
        "[material.breathing]\n"
        f"radius = {list(map(float, radius))}\nenergy = {list(map(float, energy))}\n"
    )


def _config(path, film, extra: str = "") -> None:
    path.write_text(
        f"seed = 3\ntemperature = 300.0\nduration = 20e-9\nrecord_interval = 2e-9\n"
        f'material = "{film}"\n\n'
        '[geometry]\nkind = "shapes"\nshapes = [{ kind = "disk", diameter = 400e-9 }]\n\n'
        "[skyrmions]\nrandom_count = 8\nmin_separation = 1.5\n"
        f"{extra}\n"
    )


def test_simulate_records_the_radii_of_a_breathing_film(tmp_path):
    film = tmp_path / "soft.toml"
    _film(film)
    config = tmp_path / "run.toml"
    _config(config, film)
    assert main(["simulate", str(config), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    with xr.open_dataset(tmp_path / "out" / "trajectories.nc") as ds:
        radius = ds["radius"].values
        assert ds["radius"].attrs["units"] == "m"
        assert radius.shape == ds["x"].shape
        assert np.array_equal(np.isnan(radius), np.isnan(ds["x"].values))
        params = json.loads(ds.attrs["parameters_json"])
    assert params["particle_model"] == "breathing"
    seen = radius[~np.isnan(radius)]
    # the first frame is R₀; later ones breathe thermally about it (σ = √(k_BT/k) ≈ 0.17 R₀
    # here), always inside the table
    assert np.all((seen >= 0.6 * R0) & (seen <= 1.4 * R0))
    assert np.nanstd(radius[-1]) > 0.02 * R0


def test_a_breathing_film_runs_rigid_when_the_configuration_says_so(tmp_path):
    film = tmp_path / "soft.toml"
    _film(film)
    config = tmp_path / "run.toml"
    _config(config, film, '[forces]\nparticle_model = "rigid"')
    assert main(["simulate", str(config), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    with xr.open_dataset(tmp_path / "out" / "trajectories.nc") as ds:
        assert "radius" not in ds
