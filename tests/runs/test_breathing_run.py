"""A breathing material given as a TOML file runs through ``skygas simulate`` end to end.

The radii land in trajectories.nc beside the positions, the run records which model it ran,
and a user can switch a breathing material back to rigid in the configuration.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
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


NEURON = (
    "duration = 40e-9\n[device]\nchamber_diameter = 400e-9\nconduit_width = 80e-9\n"
    "[rule]\nthreshold = 4\nreset_level = 1\nrelease_time = 10e-9\n"
    "[annihilation]\nbase_rate = 2e7\ncompression_sensitivity = 0.0\n"
    "[transfer]\nrates = [1e7, 3e8]\nduration = 20e-9\n"
    "[[inputs]]\nkind = 'poisson'\nrate = 3e8\n"
)
RESERVOIR = (
    "hold_time = 1e-7\n[sensors]\nsample_interval = 2e-9\n"
    "[study]\nn_inputs = 12\ntemporal_inputs = 12\nworkers = 1\n"
)


@pytest.mark.parametrize("device", ["reshuffle", "neuron", "reservoir"])
def test_every_device_runs_a_breathing_film(device, tmp_path, monkeypatch):
    """The devices take the model from their material: each builds breathing simulations."""
    from skygas.engine import Simulation

    built = []
    init = Simulation.__init__

    def spy(self, *args, **kwargs):
        init(self, *args, **kwargs)
        built.append(self.particle_model)

    monkeypatch.setattr(Simulation, "__init__", spy)
    film = tmp_path / "soft.toml"
    _film(film)
    out = str(tmp_path / "out")
    if device == "reshuffle":
        args = ["reshuffle", "--material", str(film), "--duration", "0.3e-6", "--out", out]
    else:
        config = tmp_path / "device.toml"
        text = NEURON if device == "neuron" else RESERVOIR
        config.write_text(f'material = "{film}"\n' + text)
        args = [device, str(config), "--out", out]
    assert main([*args, "--quiet"]) == 0
    assert built and set(built) == {"breathing"}
