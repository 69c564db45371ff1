"""Bad landscape parameters get one clear line through the command line before any work:
``skygas: error: <file>: potentials.<k>.<field> = <value> is not allowed: expected …``, exit
status 2, no traceback, no step taken; grid files named relative to the configuration."""

from __future__ import annotations

import numpy as np
import pytest

from skygas.cli import main
from skygas.core.errors import InputError
from skygas.engine import Simulation
from skygas.fields.landscape import Gaussian, parse_potentials
from skygas.runs.config import load_config

CONFIG = """\
seed = 1
duration = 2e-9
record_interval = 1e-9

[geometry]
kind = "shapes"
shapes = [{{ kind = "rectangle", width = 400e-9, height = 300e-9 }}]

[skyrmions]
positions = [[0.0, 0.0]]

[[potentials]]
kind = "disorder"
rms_kT = 1.0
correlation_length = 40e-9

[[potentials]]
{table}
"""

GAUSSIAN = 'kind = "gaussian"\ncenter = [0.0, 0.0]\n'
GRID = 'kind = "grid"\npath = "{file}"\n'


@pytest.fixture
def no_stepping(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("a simulation was stepped before validation finished")

    monkeypatch.setattr(Simulation, "run", refuse)


def write_grids(folder):
    """Energy maps [J] next to the configuration."""
    np.save(folder / "flat.npy", np.zeros(50))
    np.save(folder / "small.npy", np.zeros((3, 3)))
    np.save(folder / "tiny.npy", np.zeros((10, 10)))  # 90 nm at 10 nm: not the device
    np.save(folder / "nan.npy", np.full((120, 120), np.nan))
    np.save(folder / "map.npy", 1e-21 * np.random.default_rng(0).random((120, 120)))


@pytest.mark.parametrize(
    "table, field, hint",
    [
        (GAUSSIAN + "amplitude_kT = -3.0\nsigma = -1e-8", "potentials.1.sigma", "a number > 0"),
        (GAUSSIAN + "amplitude_kT = nan\nsigma = 1e-8", "potentials.1.amplitude_kT", "finite"),
        (GAUSSIAN + "sigma = 1e-8", "potentials.1", "amplitude"),
        ('kind = "gausian"\namplitude_kT = 1.0', "potentials.1.kind", "'gaussian'"),
        (
            'kind = "disorder"\nrms_kT = -1.0\ncorrelation_length = 4e-8',
            "potentials.1.rms_kT",
            "a number >= 0",
        ),
        (
            'kind = "periodic"\namplitude_kT = 1.0\nwavelength = 0.0',
            "potentials.1.wavelength",
            "a number > 0",
        ),
        (
            'kind = "band"\nheight_kT = 3.0\nedge_width = 5e-9\nstart = [0.0, 0.0]\n'
            "end = [0.0, 0.0]\nwidth = 1e-7",
            "potentials.1",
            "start and end must differ",
        ),
        (GRID.format(file="flat.npy") + "spacing = 1e-8", "potentials.1.path", "2-D array"),
        (GRID.format(file="small.npy") + "spacing = 1e-8", "potentials.1.path", "4×4"),
        (GRID.format(file="nan.npy") + "spacing = 1e-8", "potentials.1.path", "finite"),
        (GRID.format(file="nothere.npy") + "spacing = 1e-8", "potentials.1.path", "existing"),
        (GRID.format(file="map.npy"), "potentials.1.spacing", "required"),
        (
            GRID.format(file="tiny.npy") + "spacing = 1e-8\norigin = [-5e-8, -5e-8]",
            "potentials.1.path",
            "covering the device",
        ),
    ],
)
def test_bad_potentials_get_one_line_before_any_work(
    table, field, hint, tmp_path, capsys, no_stepping
):
    write_grids(tmp_path)
    config = tmp_path / "run.toml"
    config.write_text(CONFIG.format(table=table))
    out = tmp_path / "out"
    assert main(["simulate", str(config), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert err.startswith("skygas: error: ") and f"{field} = " in err and hint in err, err
    assert not (out / "trajectories.nc").exists()


def test_a_relative_grid_path_is_taken_from_the_configurations_folder(tmp_path, monkeypatch):
    write_grids(tmp_path)
    config = tmp_path / "run.toml"
    config.write_text(
        CONFIG.format(table=GRID.format(file="map.npy") + "spacing = 1e-8\norigin = [-6e-7, -6e-7]")
    )
    monkeypatch.chdir(tmp_path.parent)  # not the configuration's folder
    cfg = load_config(config)
    assert cfg.potentials[1].path == str(tmp_path / "map.npy")
    sim = cfg.build()
    assert np.ptp(sim.landscape.nodes[..., 0]) > 0


def test_the_python_api_names_the_same_fields():
    with pytest.raises(InputError) as err:
        parse_potentials(
            [
                Gaussian(amplitude_kT=-1.0, center=(0, 0), sigma=1e-8),
                {"kind": "gaussian", "amplitude_kT": 1.0, "center": [0, 0], "sigma": float("nan")},
            ]
        )
    assert err.value.field == "potentials.1.sigma"
    with pytest.raises(InputError) as err:
        parse_potentials(["gaussian"])
    assert err.value.field == "potentials.0"
