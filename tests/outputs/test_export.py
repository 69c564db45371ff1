"""GSD and extended-XYZ exports hold exactly the recorded frames, in nm."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from skygas.cli import main
from skygas.outputs.records import load_run


def recorded_frames(nc_path):
    """(time, ids, positions [m]) of each recorded frame, read straight from the netCDF."""
    with xr.open_dataset(nc_path) as ds:
        if "snapshot_count" in ds:
            edges = np.concatenate([[0], np.cumsum(ds.snapshot_count.values)])
            return [
                (
                    t,
                    ds.snapshot_skyrmion.values[a:b],
                    np.column_stack([ds.snapshot_x.values[a:b], ds.snapshot_y.values[a:b]]),
                )
                for t, a, b in zip(ds.snapshot_time.values, edges[:-1], edges[1:], strict=True)
            ]
        out = []
        for f, t in enumerate(ds.time.values):
            ok = np.isfinite(ds.x.values[f])
            out.append(
                (
                    t,
                    ds.skyrmion.values[ok],
                    np.column_stack([ds.x.values[f, ok], ds.y.values[f, ok]]),
                )
            )
        return out


@pytest.mark.parametrize("run", ["simulation_run", "reshuffler_run"])
def test_gsd_frames_equal_the_netcdf_record(run, request, tmp_path):
    import gsd.hoomd

    directory = request.getfixturevalue(run)
    nc = load_run(directory).path
    out = tmp_path / "run.gsd"
    assert main(["export", str(directory), "--format", "gsd", "--out", str(out)]) == 0
    expected = recorded_frames(nc)
    with gsd.hoomd.open(out) as traj:
        assert len(traj) == len(expected)
        for frame, (t, ids, xy) in zip(traj, expected, strict=True):
            assert frame.particles.N == len(ids)
            assert frame.configuration.dimensions == 2
            assert frame.log["skygas/time_s"][0] == t
            assert frame.log["skygas/length_unit_m"][0] == 1e-9
            np.testing.assert_array_equal(frame.log["particles/skygas_id"], ids)
            # float32 positions: 1e-7 relative of ~1000 nm
            np.testing.assert_allclose(frame.particles.position[:, :2], xy * 1e9, atol=1e-3)
            assert np.all(frame.particles.position[:, 2] == 0)
            half = np.array(frame.configuration.box[:2]) / 2
            assert np.all(np.abs(frame.particles.position[:, :2]) < half)


def test_extxyz_frames_equal_the_netcdf_record(reshuffler_run, tmp_path):
    out = tmp_path / "run.xyz"
    assert main(["export", str(reshuffler_run), "--format", "extxyz", "--out", str(out)]) == 0
    expected = recorded_frames(load_run(reshuffler_run).path)
    lines = out.read_text().splitlines()
    k = 0
    for t, ids, xy in expected:
        n = int(lines[k])
        header = lines[k + 1]
        assert "length_unit=nm" in header and "time_unit=s" in header and "Lattice=" in header
        assert float(header.split("Time=")[1].split()[0]) == pytest.approx(t, rel=1e-9)
        rows = [line.split() for line in lines[k + 2 : k + 2 + n]]
        assert n == len(ids)
        np.testing.assert_array_equal([int(r[4]) for r in rows], ids)
        written = np.reshape([[float(r[1]), float(r[2])] for r in rows], (-1, 2))  # may be empty
        np.testing.assert_allclose(written, xy * 1e9, atol=1e-6)
        k += 2 + n
    assert k == len(lines)


def test_export_refuses_a_missing_run_before_any_work(tmp_path, capsys):
    assert (
        main(
            ["export", str(tmp_path / "none"), "--format", "gsd", "--out", str(tmp_path / "x.gsd")]
        )
        == 2
    )
    assert "skygas: error: RUN" in capsys.readouterr().err
    assert not (tmp_path / "x.gsd").exists()


def _run_provenance(directory):
    """The seed, version and configuration hash of a run, from its result file and manifest."""
    import json

    record = load_run(directory)
    manifest = json.loads((directory / "manifest.json").read_text())
    return {
        "skygas_version": record.version,
        "seed": str(record.seed),
        "config_hash": manifest["config_hash"],
    }


def test_exports_record_the_run_provenance(simulation_run, tmp_path):
    import json

    import gsd.hoomd

    expected = _run_provenance(simulation_run)
    gsd_out, xyz_out = tmp_path / "run.gsd", tmp_path / "run.xyz"
    assert main(["export", str(simulation_run), "--format", "gsd", "--out", str(gsd_out)]) == 0
    with gsd.hoomd.open(gsd_out) as traj:
        for frame in (traj[0], traj[len(traj) - 1]):
            record = json.loads(bytes(frame.log["skygas/provenance_json"]).decode())
            assert {k: record[k] for k in expected} == expected
            assert record["command_line"].startswith("skygas export ")
    assert main(["export", str(simulation_run), "--format", "extxyz", "--out", str(xyz_out)]) == 0
    header = xyz_out.read_text().splitlines()[1]
    for key, value in expected.items():
        assert f" {key}={value} " in header
    assert 'skygas_command="skygas export ' in header
    assert not [p.name for p in tmp_path.iterdir() if ".partial" in p.name]


def test_an_existing_export_is_replaced_only_with_overwrite(simulation_run, tmp_path, capsys):
    out = tmp_path / "old.xyz"
    out.write_text("mine\n")
    args = ["export", str(simulation_run), "--format", "extxyz", "--out", str(out)]
    assert main(args) == 2
    assert "--overwrite" in capsys.readouterr().err
    assert out.read_text() == "mine\n"
    assert main([*args, "--overwrite"]) == 0
    assert out.read_text() != "mine\n"
    # into the run folder: a file of the command's own kind, never one of the run's results
    inside = simulation_run / "run.xyz"
    assert main(["export", str(simulation_run), "--format", "extxyz", "--out", str(inside)]) == 0
    inside.unlink()
