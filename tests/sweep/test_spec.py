"""Sweep files: validation before any run, and seeds that depend only on the file."""

from __future__ import annotations

import numpy as np
import pytest

from skygas.cli import main
from skygas.core.errors import InputError
from skygas.sweep import load_sweep, parse_sweep
from skygas.sweep.spec import derive_seeds

BASE = {"preset": "paper", "duration": 1e-6, "output": {"trajectory_window": 0.0}}


def sweep(grid=None, points=None, **head):
    data = {"sweep": {"seed": 3, "replicas": 2, **head}, "base": dict(BASE)}
    if grid is not None:
        data["grid"] = grid
    if points is not None:
        data["points"] = points
    return data


def test_grid_points_configs_and_seeds():
    s = parse_sweep(
        sweep(
            {
                "current_density": [1e11, 2e11, 3e11],
                "signal.p": [0.3, 0.6],
                "device.chamber_diameter": {"start": 5e-7, "stop": 1e-6, "num": 2},
            }
        )
    )
    assert s.shape == (3, 2, 2) and s.dims == (
        "current_density",
        "signal_p",
        "device_chamber_diameter",
    )
    assert len(s.runs) == 12 * 2
    run = next(r for r in s.runs if r.index == (2, 1, 0) and r.replica == 1)
    assert run.config.current_density == 3e11 and run.config.signal.p == 0.6
    assert run.config.device.chamber_diameter == 5e-7 and run.config.duration == 1e-6
    assert run.config.spin_drift_coefficient == 1.84e-10  # the preset applies underneath
    seeds = [r.seed for r in s.runs]
    assert len(set(seeds)) == len(seeds) and all(0 <= x < 2**63 for x in seeds)
    assert all(r.config.seed == r.seed for r in s.runs)


def test_seeds_follow_seed_sequence_spawn():
    expected = np.random.SeedSequence(5).spawn(3)[2].spawn(4)[1].generate_state(1, np.uint64)
    assert derive_seeds(5, 3, 4)[2, 1] == int(expected[0] >> np.uint64(1))
    # the seed of a point does not depend on how many replicas follow it
    assert derive_seeds(5, 3, 4)[1, 0] == derive_seeds(5, 3, 2)[1, 0]


def test_log_range_and_explicit_list():
    s = parse_sweep(
        sweep({"current_density": {"start": 1e10, "stop": 1e12, "num": 3, "spacing": "log"}})
    )
    assert np.allclose(s.values[0], [1e10, 1e11, 1e12])
    s = parse_sweep(
        sweep(
            points=[
                {"current_density": 1e11, "material": "S2"},
                {"current_density": 2e11, "material": "S2"},
            ]
        )
    )
    assert s.layout == "list" and s.shape == (2,) and s.point_dims == ("point",)


@pytest.mark.parametrize(
    "data, field",
    [
        (sweep({"current_densty": [1e11]}), "grid.current_densty"),
        (sweep({"device.chamber_diamter": [1e-6]}), "grid.device.chamber_diamter"),
        (sweep({"current_density": []}), "grid.current_density"),
        (
            sweep({"current_density": {"start": 1e11, "stop": 2e11, "num": 0}}),
            "grid.current_density.num",
        ),
        (sweep({"current_density": ["fast"]}), "current_density"),
        (sweep({"signal.p": [0.5, 1.5]}), "signal.p"),
        (sweep({"current_density": 1e11}), "grid.current_density"),
        (sweep({"current_density": [1e11]}, replicas=0), "sweep.replicas"),
        (sweep({"current_density": [1e11]}, replicas="2"), "sweep.replicas"),
        (sweep({"seed": [1, 2]}), "grid.seed"),
        (sweep(), "grid"),
        ({"sweep": {}, "grids": {"current_density": [1e11]}}, "grids"),
        (sweep({"current_density": [1e11]}, replica=2), "sweep.replica"),
        (sweep({"material": ["S2", "NoSuchMaterial"]}), "material"),
        (sweep({"device.chamber_diameter": [1e-6, 8e-8]}), "conduit_width"),
        (sweep(points=[{"current_density": 1e11}, {"signal.p": 0.3}]), "points[1]"),
    ],
)
def test_bad_sweep_files_name_the_field(data, field):
    with pytest.raises(InputError) as err:
        parse_sweep(data)
    assert field in str(err.value)


def test_cli_rejects_bad_file_before_running(tmp_path, capsys, monkeypatch):
    import skygas.sweep.execute as execute

    def never(*args, **kwargs):
        raise AssertionError("a run started")

    monkeypatch.setattr(execute, "run_point", never)
    path = tmp_path / "bad.toml"
    path.write_text(
        '[sweep]\nreplicas = 1\n[base]\npreset = "paper"\n'
        '[grid]\ncurrent_density = [1e11, 2e11]\n"signal.p" = [0.5, 7]\n'
    )
    assert main(["sweep", str(path), "--out", str(tmp_path / "store")]) == 2
    assert "signal.p" in capsys.readouterr().err
    assert not (tmp_path / "store").exists()


def test_load_sweep_relative_config(tmp_path):
    (tmp_path / "base.toml").write_text('preset = "paper"\nduration = 1e-6\n')
    (tmp_path / "s.toml").write_text(
        '[sweep]\nconfig = "base.toml"\n[grid]\ntemperature = [100.0, 300.0]\n'
    )
    s = load_sweep(tmp_path / "s.toml")
    assert [r.config.temperature for r in s.runs] == [100.0, 300.0]
    assert "temperature" in s.source_text


def test_set_changes_the_file_and_is_recorded(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(
        '[sweep]\nreplicas = 3\n[base]\npreset = "paper"\nduration = 4e-5\n'
        '[grid]\n"signal.p" = [0.2, 0.5]\n'
    )
    sweep = load_sweep(
        path,
        [
            "sweep.replicas=2",
            "base.duration=1e-6",
            "base.output.trajectory_window=0.0",
            "grid.signal.p=[0.8]",
        ],
    )
    assert sweep.replicas == 2 and sweep.n_points == 1
    config = sweep.runs[0].config
    assert config.duration == 1e-6 and config.output.trajectory_window == 0.0
    assert config.signal.p == 0.8
    assert load_sweep(path).fingerprint() != sweep.fingerprint()
    with pytest.raises(InputError, match="--set"):
        load_sweep(path, ["duration=1e-6"])
    with pytest.raises(InputError, match="--set"):
        load_sweep(path, ["base.duration=1e-6 s"])
