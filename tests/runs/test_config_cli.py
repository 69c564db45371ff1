"""Configuration validation (before any stepping) and the ``skygas simulate`` command end to end.

Every invalid input must be refused with an InputError whose field names the offending entry,
and the CLI must turn it into exit code 2 and a one-line message on stderr.
"""

import json
import tomllib

import numpy as np
import pytest
import xarray as xr

from skygas._version import __version__
from skygas.cli import main
from skygas.core.errors import InputError
from skygas.engine import Simulation
from skygas.physics.geometry import disk
from skygas.runs.config import load_config, parse_config
from skygas.runs.runner import run_simulation

RADIUS = 150e-9

TINY_TOML = """\
seed = 7
temperature = 300.0
duration = 5e-9
record_interval = 1e-9
material = "S2"

[geometry]
kind = "shapes"
shapes = [{ kind = "disk", diameter = 300e-9 }]

[skyrmions]
positions = [[0.0, 0.0], [70e-9, 0.0], [-40e-9, 60e-9]]
"""


def tiny_config() -> dict:
    return tomllib.loads(TINY_TOML)


@pytest.fixture
def no_stepping(monkeypatch):
    """Fail loudly if anything advances a simulation."""

    def refuse(*args, **kwargs):
        raise AssertionError("a simulation was stepped before validation finished")

    monkeypatch.setattr(Simulation, "_advance", refuse)


def _refused(data: dict, tmp_path) -> InputError:
    """Validate and build ``data`` as ``skygas simulate`` would; return the InputError."""
    with pytest.raises(InputError) as err:
        run_simulation(parse_config(data), tmp_path / "out", progress=False)
    assert not (tmp_path / "out" / "trajectories.nc").exists()
    return err.value


# -- invalid inputs -----------------------------------------------------------------------------
@pytest.mark.parametrize(
    "update, field",
    [
        ({"temperature": -1.0}, "temperature"),
        ({"temperature": "hot"}, "temperature"),  # wrong type
        ({"seed": -3}, "seed"),
        ({"seed": 1.5}, "seed"),  # wrong type
        ({"duration": -1e-9}, "duration"),
        ({"duration": "long"}, "duration"),  # wrong type
        ({"tempreature": 300.0}, "tempreature"),  # unknown extra field
        ({"integrator": "rk4"}, "integrator"),
        ({"film_thickness": 0.0}, "film_thickness"),
    ],
)
def test_invalid_top_level_values_are_named(update, field, no_stepping):
    with pytest.raises(InputError) as err:
        parse_config({**tiny_config(), **update})
    assert err.value.field == field
    assert str(err.value).startswith(f"{field} = ")
    assert ": expected" in str(err.value)


@pytest.mark.parametrize(
    "section, update, field",
    [
        ("skyrmions", {"positions": "here"}, "skyrmions.positions"),  # wrong type
        ("skyrmions", {"random_count": -2}, "skyrmions.random_count"),
        ("skyrmions", {"colour": "red"}, "skyrmions.colour"),  # unknown extra field
        ("geometry", {"kind": "blob"}, "geometry.kind"),  # unknown tag
        # pydantic puts the union tags in the path: geometry.<kind>.shapes.<i>.<kind>.diameter
        (
            "geometry",
            {"shapes": [{"kind": "disk", "diameter": -2e-7}]},
            "geometry.shapes.shapes.0.disk.diameter",
        ),
    ],
)
def test_invalid_nested_values_are_named(section, update, field, no_stepping):
    data = tiny_config()
    data[section] = {**data[section], **update}
    with pytest.raises(InputError) as err:
        parse_config(data)
    assert err.value.field == field


def test_missing_duration_is_named():
    data = tiny_config()
    del data["duration"]
    with pytest.raises(InputError) as err:
        parse_config(data)
    assert err.value.field == "duration"
    assert "required" in str(err.value)


def test_missing_skyrmions_table_is_named():
    data = tiny_config()
    del data["skyrmions"]
    with pytest.raises(InputError) as err:
        parse_config(data)
    assert err.value.field == "skyrmions"


def test_negative_temperature_is_refused_by_the_engine_too():
    with pytest.raises(InputError) as err:
        Simulation(disk(diameter=2 * RADIUS), "S2", temperature=-5.0)
    assert err.value.field == "temperature"
    with pytest.raises(InputError) as err:
        Simulation(disk(diameter=2 * RADIUS), "S2", temperature=float("nan"))
    assert err.value.field == "temperature"
    with pytest.raises(InputError) as err:
        Simulation(disk(diameter=2 * RADIUS), "S2", seed=-1)
    assert err.value.field == "seed"


def test_unknown_material_is_named(no_stepping, tmp_path):
    err = _refused({**tiny_config(), "material": "S9"}, tmp_path)
    assert err.field == "material" and "S9" in str(err)
    err = _refused({**tiny_config(), "material": str(tmp_path / "missing.toml")}, tmp_path)
    assert err.field == "material"


def test_invalid_material_table_is_named(no_stepping, tmp_path):
    data = {**tiny_config(), "material": {"base": "S2", "saturation_magnetization": -1.0}}
    err = _refused(data, tmp_path)
    assert err.field == "material.saturation_magnetization"


def test_material_table_and_file_are_used(tmp_path):
    path = tmp_path / "film.toml"
    path.write_text('[material]\nbase = "S2"\nname = "wide"\nskyrmion_radius = 25e-9\n')
    for material in ({"base": "S2", "name": "wide", "skyrmion_radius": 25e-9}, str(path)):
        sim = parse_config({**tiny_config(), "material": material}).build()
        assert sim.material.name == "wide"
        assert sim.thiele.skyrmion_diameter == pytest.approx(50e-9, rel=1e-12)


def test_skyrmion_outside_the_geometry_is_named(no_stepping, tmp_path):
    data = tiny_config()
    data["skyrmions"]["positions"] = [[0.0, 0.0], [0.0, 2 * RADIUS]]
    err = _refused(data, tmp_path)
    assert err.field == "skyrmions[1]"
    assert "inside the device outline" in str(err)


def test_skyrmions_on_top_of_each_other_are_named(no_stepping, tmp_path):
    data = tiny_config()
    data["skyrmions"]["positions"] = [[0.0, 0.0], [60e-9, 0.0], [60e-9, 1e-9]]
    err = _refused(data, tmp_path)
    assert err.field == "skyrmions[2]"


def test_add_skyrmions_validation():
    sim = Simulation(disk(diameter=2 * RADIUS), "S2", seed=1)
    d_sk = sim.thiele.skyrmion_diameter
    sim.add_skyrmions([[0.0, 0.0]])
    # on top of an existing skyrmion: closer than 0.5 d_sk
    with pytest.raises(InputError) as err:
        sim.add_skyrmions([[0.45 * d_sk, 0.0]])
    assert err.value.field == "skyrmions[0]"
    with pytest.raises(InputError) as err:
        sim.add_skyrmions([[RADIUS * 1.01, 0.0]])
    assert err.value.field == "skyrmions[0]"
    with pytest.raises(InputError):
        sim.add_skyrmions([[float("nan"), 0.0]])
    assert sim.count == 1  # nothing was inserted by the refused calls
    ids = sim.add_skyrmions([[0.55 * d_sk, 0.0], [-0.55 * d_sk, 0.0]])
    assert list(ids) == [1, 2] and sim.count == 3
    _, pos = sim.positions()
    np.testing.assert_allclose(pos[1:], [[0.55 * d_sk, 0.0], [-0.55 * d_sk, 0.0]], rtol=1e-12)


def test_time_step_above_the_limit_is_named(no_stepping, tmp_path):
    sim = parse_config(tiny_config()).build()
    limit = sim.max_time_step()
    assert 0 < sim.time_step <= limit
    err = _refused({**tiny_config(), "time_step": 2 * limit}, tmp_path)
    assert err.field == "time_step"
    with pytest.raises(InputError) as err:
        Simulation(disk(diameter=2 * RADIUS), "S2", time_step=2 * limit)
    assert err.value.field == "time_step"
    # the limit itself is accepted
    assert Simulation(disk(diameter=2 * RADIUS), "S2", time_step=limit).time_step == limit


def test_validation_happens_before_any_file_is_written(no_stepping, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(TINY_TOML.replace("temperature = 300.0", "temperature = -4.0"))
    with pytest.raises(InputError) as err:
        load_config(bad)
    assert err.value.field == "bad.toml: temperature"


# -- CLI ----------------------------------------------------------------------------------------
def test_cli_simulate_end_to_end(tmp_path, capsys):
    config = tmp_path / "tiny.toml"
    config.write_text(TINY_TOML)
    out = tmp_path / "run"
    code = main(["simulate", str(config), "--out", str(out), "--quiet"])
    assert code == 0
    assert (out / "trajectories.png").is_file()
    assert not (out / "checkpoint.npz").exists()

    with xr.open_dataset(out / "trajectories.nc") as ds:
        ds.load()
    assert ds.x.dims == ("time", "skyrmion") and ds.y.dims == ("time", "skyrmion")
    assert ds.x.attrs["units"] == "m" and ds.y.attrs["units"] == "m"
    assert ds.time.attrs["units"] == "s"
    assert ds.sizes["skyrmion"] == 3
    # a frame at t = 0 and one on every nanosecond up to the end, 5 ns, in seconds
    t = ds.time.values
    assert len(t) == 6 and t[0] == 0.0
    np.testing.assert_allclose(t, np.arange(6) * 1e-9, rtol=1e-12, atol=0)
    # positions in metres, inside the 150 nm disk, the first frame where they were placed
    x, y = ds.x.values, ds.y.values
    assert np.all(np.isfinite(x)) and np.all(np.isfinite(y))
    assert np.all(np.hypot(x, y) < RADIUS)
    start = np.array([[0.0, 0.0], [70e-9, 0.0], [-40e-9, 60e-9]])
    np.testing.assert_allclose(np.column_stack([x[0], y[0]]), start, rtol=1e-15, atol=1e-24)
    # provenance
    assert int(ds.attrs["seed"]) == 7
    assert ds.attrs["skygas_version"] == __version__
    params = json.loads(ds.attrs["parameters_json"])
    assert params["seed"] == 7 and params["temperature_K"] == 300.0
    assert params["material"]["name"] == "S2"
    assert params["skygas_version"] == __version__

    summary = json.loads((out / "summary.json").read_text())
    assert summary["seed"] == 7 and summary["skygas_version"] == __version__
    assert summary["skyrmions_initial"] == 3
    assert summary["simulated_time_s"] == pytest.approx(5e-9, rel=0.01)
    assert summary["config"]["duration"] == 5e-9
    # the command reports where the results are
    assert str(out.resolve()) in capsys.readouterr().out


def test_cli_same_seed_is_reproducible(tmp_path):
    config = tmp_path / "tiny.toml"
    config.write_text(TINY_TOML.replace("duration = 5e-9", "duration = 2e-9"))
    for name in ("a", "b"):
        assert main(["simulate", str(config), "--out", str(tmp_path / name), "--quiet"]) == 0
    with (
        xr.open_dataset(tmp_path / "a" / "trajectories.nc") as a,
        xr.open_dataset(tmp_path / "b" / "trajectories.nc") as b,
    ):
        np.testing.assert_array_equal(a.x.values, b.x.values)
        np.testing.assert_array_equal(a.y.values, b.y.values)


@pytest.mark.parametrize(
    "old, new, field",
    [
        ("temperature = 300.0", "temperature = -4.0", "temperature"),
        ('material = "S2"', 'material = "S9"', "material"),
        ("duration = 5e-9\n", "", "duration"),
        ("seed = 7", "seed = 7\nwobble = 1", "wobble"),
        ("[0.0, 0.0], [70e-9, 0.0]", "[0.0, 0.0], [0.0, 0.0]", "skyrmions[1]"),
        ("[-40e-9, 60e-9]", "[-400e-9, 60e-9]", "skyrmions[2]"),
    ],
)
def test_cli_invalid_config_exits_2_naming_the_field(
    old, new, field, tmp_path, capsys, no_stepping
):
    assert old in TINY_TOML
    config = tmp_path / "bad.toml"
    config.write_text(TINY_TOML.replace(old, new))
    out = tmp_path / "run"
    code = main(["simulate", str(config), "--out", str(out), "--quiet"])
    assert code == 2
    err = capsys.readouterr().err
    assert err.startswith("skygas: error: ")
    assert field in err and ": expected" in err
    assert len(err.strip().splitlines()) == 1
    assert not (out / "trajectories.nc").exists()


def test_cli_missing_config_file_exits_2(tmp_path, capsys):
    code = main(["simulate", str(tmp_path / "nope.toml"), "--out", str(tmp_path / "o")])
    assert code == 2
    assert "skygas: error: config = " in capsys.readouterr().err
