"""A calibrated model as a material (``model.toml``): its TOML round trip, its film thickness,
its γ, the edge stray field it brings with its tabulated wall law, and ``skygas simulate``."""

import json
import math
import tomllib

import numpy as np
import pytest
from tests.engine.calibrated_model import calibrated_data, calibrated_material, model_toml

from skygas.cli import main
from skygas.core.errors import InputError
from skygas.engine import Simulation
from skygas.fields.landscape import EdgeStrayField
from skygas.neuron.config import NeuronConfig
from skygas.physics.geometry import disk
from skygas.physics.materials import derive_thiele, load_material, preset
from skygas.reshuffler.config import ReshufflerConfig
from skygas.runs.config import parse_config
from skygas.sweep.spec import _field_exists

CHAMBER_TOML = """\
material = "model.toml"
seed = 3
temperature = 300.0
duration = 2e-9
record_interval = 1e-9

[geometry]
kind = "chamber"
closed = true
chamber_diameter = 400e-9

[skyrmions]
positions = [[0.0, 0.0], [80e-9, 0.0], [-60e-9, 70e-9]]
"""


@pytest.fixture
def model_file(tmp_path):
    path = tmp_path / "model.toml"
    path.write_text(model_toml(calibrated_data(film=3e-9)))
    return path


def test_model_toml_round_trips_through_load_material(model_file):
    text = model_file.read_text()
    assert "[material.pair_table]" in text and "[material.stray_field]" in text
    tomllib.loads(text)  # plain TOML
    loaded = load_material(str(model_file))
    expected = calibrated_material(film=3e-9)
    assert loaded == expected  # every number exactly (repr round-trips a float)
    assert loaded.film_thickness == 3e-9
    assert loaded.pair_table.distance[-1] == expected.pair_table.distance[-1]
    assert len(loaded.stray_field.profile_radius) == len(expected.stray_field.profile_radius)


def test_model_runs_in_skygas_simulate(model_file, tmp_path):
    config = tmp_path / "run.toml"
    config.write_text(CHAMBER_TOML)
    out = tmp_path / "out"
    assert main(["simulate", str(config), "--out", str(out), "--quiet"]) == 0
    import xarray as xr

    with xr.open_dataset(out / "trajectories.nc") as ds:
        params = json.loads(ds.attrs["parameters_json"])
        assert np.all(np.isfinite(ds.x.values[-1]))
    assert (params["pair_law"], params["wall_law"], params["edge_stray_field"]) == (
        "table",
        "table",
        True,
    )
    assert params["thiele"]["thiele_film_thickness"] == 3e-9
    assert params["landscape"][-1]["kind"] == "edge_stray_field"
    assert params["landscape"][-1]["thickness"] == 3e-9


# -- film thickness -----------------------------------------------------------------------------
def test_configs_adopt_the_models_film_thickness(model_file):
    data = {**tomllib.loads(CHAMBER_TOML), "material": str(model_file)}
    assert parse_config(data).film_thickness == 3e-9
    assert parse_config(data).thiele_parameters().film_thickness == 3e-9
    assert parse_config({**data, "film_thickness": 3e-9}).film_thickness == 3e-9
    # the devices share MaterialFields, so they adopt it too
    assert ReshufflerConfig(material=str(model_file)).film_thickness == 3e-9
    assert NeuronConfig(material=str(model_file)).film_thickness == 3e-9
    # a material without film_thickness keeps the default (and any explicit value)
    assert parse_config({**data, "material": "S2"}).film_thickness == 2e-9
    assert parse_config({**data, "material": "S2", "film_thickness": 5e-9}).film_thickness == 5e-9


def test_another_film_thickness_is_refused_in_one_line(model_file):
    data = {**tomllib.loads(CHAMBER_TOML), "material": str(model_file), "film_thickness": 2e-9}
    with pytest.raises(InputError) as err:
        parse_config(data)
    message = str(err.value)
    assert err.value.field == "film_thickness" and "\n" not in message
    assert "the 3e-09 m film the model 'calibrated-S2' was calibrated for" in message
    model = calibrated_material(film=3e-9)
    with pytest.raises(InputError, match="film_thickness = 2e-09: expected the 3e-09 m film"):
        derive_thiele(model, film_thickness=2e-9)
    with pytest.raises(InputError, match="the 3e-09 m film"):
        Simulation(disk(diameter=400e-9), model, film_thickness=4e-9)
    with pytest.raises(InputError) as err:  # explicit Thiele parameters of another film
        Simulation(disk(diameter=400e-9), model, thiele=derive_thiele(preset("S2"), 2e-9))
    assert err.value.field == "thiele.film_thickness"
    # within the relative tolerance 1e-9: the same film
    assert derive_thiele(model, 3e-9 * (1 + 1e-12)).film_thickness == pytest.approx(
        3e-9, rel=1e-11, abs=0
    )
    assert derive_thiele(model).film_thickness == 3e-9


def test_gyromagnetic_ratio_sets_k():
    data = calibrated_data()
    base = derive_thiele(load_material(data))
    data["gyromagnetic_ratio"] = 2 * data["gyromagnetic_ratio"]
    halved = derive_thiele(load_material(data))
    assert halved.k == pytest.approx(base.k / 2, rel=1e-15, abs=0)
    s2 = derive_thiele(preset("S2"))
    assert s2.k == preset("S2").saturation_magnetization * 2e-9 / 1.7595e11


# -- the edge stray field -----------------------------------------------------------------------
def test_stray_field_is_added_with_the_table_wall_law_only():
    outline = disk(diameter=500e-9)
    model = calibrated_material()
    with_table = Simulation(outline, model)
    terms = with_table.landscape.terms
    assert len(terms) == 1 and isinstance(terms[0], EdgeStrayField)
    assert terms[0].thickness == model.film_thickness
    assert terms[0].saturation_magnetization == model.saturation_magnetization
    assert with_table.parameters()["edge_stray_field"] is True
    paper_wall = Simulation(outline, model, wall_law="paper")
    assert paper_wall.landscape.terms == [] and paper_wall.edge_stray_field is None
    assert paper_wall.parameters()["edge_stray_field"] is False
    # without a profile there is nothing to add
    assert Simulation(outline, calibrated_material(stray=False)).landscape.terms == []
    # a user term comes first (its index is kept), and a second stray field is refused
    gauss = {"kind": "gaussian", "center": [0.0, 0.0], "sigma": 20e-9, "amplitude_kT": 1.0}
    sim = Simulation(outline, model, landscape=[gauss])
    assert [t.kind for t in sim.landscape.terms] == ["gaussian", "edge_stray_field"]
    with pytest.raises(InputError) as err:
        Simulation(outline, model, landscape=[terms[0]])
    assert err.value.field == "potentials.0.kind"


def test_stray_field_force_in_a_disk_points_to_the_centre():
    """The engine's interpolated force −∇U of the stray field: radial and inward everywhere
    a skyrmion can be (within 2° of −r̂), vanishing at the centre (below 1e-3 of its value at
    half the radius), and growing towards the wall."""
    radius = 250e-9
    sim = Simulation(disk(diameter=2 * radius), calibrated_material())
    angles = np.linspace(0.0, 2 * np.pi, 24, endpoint=False)
    radii = np.array([0.25, 0.5, 0.7, 0.85]) * radius
    points = np.array([[r * math.cos(a), r * math.sin(a)] for r in radii for a in angles])
    _, force = sim.landscape.energy_and_force(points)
    unit = points / np.linalg.norm(points, axis=1)[:, None]
    radial = np.sum(force * unit, axis=1)
    assert np.all(radial < 0)
    tangential = force[:, 1] * unit[:, 0] - force[:, 0] * unit[:, 1]
    assert np.max(np.abs(tangential) / np.abs(radial)) < math.tan(math.radians(2))
    magnitude = np.abs(radial).reshape(len(radii), -1).mean(axis=1)
    assert np.all(np.diff(magnitude) > 0)
    _, centre = sim.landscape.energy_and_force([[0.0, 0.0]])
    assert np.linalg.norm(centre) < 1e-3 * magnitude[1]


def test_the_time_step_counts_the_stray_field_where_skyrmions_can_be():
    """τ_min takes the stray field's curvature at ≥ 0.5 d_sk from the walls, as it takes the
    laws' slopes: the suggested step shrinks with it, but not to the curvature at the wall."""
    outline = disk(diameter=500e-9)
    with_field = Simulation(outline, calibrated_material())
    without = Simulation(outline, calibrated_material(stray=False))
    assert with_field.relaxation_time() < without.relaxation_time()
    field = with_field.landscape
    everywhere = field._samples[0]
    h = field.grid.spacing
    steepest = max(
        float(np.max(np.abs(np.diff(g, axis=a)))) / h
        for g in (everywhere.ux, everywhere.uy)
        for a in (0, 1)
    )
    assert field.max_curvature() < steepest
    assert with_field.time_step == pytest.approx(
        0.1 * with_field.relaxation_time(), rel=1e-12, abs=0
    )


def test_sweeps_and_devices_can_choose_the_wall_law(model_file):
    assert _field_exists(ReshufflerConfig, "forces.wall_law")
    assert _field_exists(ReshufflerConfig, "forces.pair_law")
    config = ReshufflerConfig(material=str(model_file), forces={"wall_law": "paper"})
    assert config.forces.simulation_arguments()["wall_law"] == "paper"
    with pytest.raises(InputError) as err:
        from pydantic import ValidationError

        from skygas.core.config_types import to_input_error

        try:
            ReshufflerConfig(forces={"wall_law": "lin-reichhardt"})
        except ValidationError as e:
            raise to_input_error(e) from None
    assert err.value.field == "forces.wall_law"


@pytest.mark.parametrize(
    ("update", "expected"),
    [
        ({"wall_geometry": "all"}, "wall_geometry = 'all': expected one of 'nearest' or 'film'"),
        ({"moment_deficit": [1e-15, 2e-15]}, "moment_deficit needs one value per radius (3)"),
        ({"moment_deficit": [3e-15, 2e-15, 1e-15]}, "moment_deficit (m²) must grow"),
        ({"dissipation": [20.0, 21.0]}, "dissipation needs one value per radius (3)"),
        ({"dissipation": [20.0, -1.0, 22.0]}, "breathing.dissipation.1"),
    ],
)
def test_a_bad_wall_geometry_or_reversed_area_is_one_line_before_any_run(
    tmp_path, capsys, update, expected
):
    """A model.toml whose wall geometry, A_m(R) or 𝒟(R) table is wrong: one line, exit 2."""
    data = calibrated_data()
    r0 = data["skyrmion_radius"]
    breathing = {"radius": [0.8 * r0, r0, 1.2 * r0], "energy": [1e-20, 0.0, 1e-20]}
    if "wall_geometry" in update:
        data.update(update)
    else:
        breathing.update(update)
    data["breathing"] = breathing
    (tmp_path / "model.toml").write_text(model_toml(data))
    (tmp_path / "run.toml").write_text(
        CHAMBER_TOML.replace("model.toml", str(tmp_path / "model.toml"))
    )
    out = tmp_path / "out"
    assert main(["simulate", str(tmp_path / "run.toml"), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("skygas: error:") and expected in err[0]
    assert not out.exists()
