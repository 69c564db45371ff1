"""Bad input to ``skygas calibrate``: refused in one line before any solver starts.

The subprocess cases run the real command line (:func:`.catalogue.refused`): exit status 2, one
``skygas: error:`` line naming the option and what to do, the folder left as it was. What a
subprocess cannot reach runs in-process: a worker killed by the kernel (the calibration must say
so, not wait for it for ever), the estimate of a forced long calibration, and a calibrated model
(``model.toml``) whose table is broken, read by a device.
"""

from __future__ import annotations

import os
import signal
import time
from importlib.util import find_spec

import pytest

from skygas.core.errors import InputError

from .catalogue import assert_one_line, refused, run, snapshot

#: what a job may use in these cases: the same refusals on every machine
SMALL_MACHINE = {"SKYGAS_MEMORY_LIMIT": str(4 * 2**30)}

CASES = {
    # 10 pm cells: films of 1.8e8 cells, a terabyte (a worker grew past 20 GB and was killed)
    "cells too fine for the memory": (
        ["--cell-size", "1e-11"],
        "--cell-size = 1e-11",
        "fits in memory",
    ),
    "cells too fine to finish in a day": (
        ["--cell-size", "2e-10"],
        "--cell-size = 2e-10",
        "at most 24 h",
        "--force",
    ),
    "a validation run in nanoseconds": (
        ["--validation-duration", "10"],
        "--validation-duration = 10.0",
        "at most 24 h",
    ),
    "a reference device smaller than the skyrmion's film": (
        ["--reference-diameter", "10e-9"],
        "--reference-diameter = 1e-08",
        "at least as wide as the film",
    ),
    "a cell size in nanometres": (["--cell-size", "2"], "--cell-size = 2.0", "2e-9"),
    "a reference diameter in nanometres": (
        ["--reference-diameter", "1024"],
        "--reference-diameter = 1024.0",
        "did you mean 1024e-9",
    ),
    "a reference diameter below a picometre": (
        ["--reference-diameter", "1e-13"],
        "--reference-diameter = 1e-13",
        "between 1e-12 m and 1 m",
    ),
    "more skyrmions than the validation disk holds": (
        ["--skyrmions", "7"],
        "--skyrmions = 7",
        "fewer skyrmions",
    ),
    "more skyrmions than the validation rectangle holds": (
        ["--validation-shape", "rectangle", "--skyrmions", "6"],
        "--skyrmions = 6",
        "rectangle of 4 × 3 diameters",
        "fewer skyrmions",
    ),
    "a validation that stops before the skyrmions move": (
        ["--validation-travel", "0"],
        "--validation-travel = 0.0",
        "> 0",
    ),
    "fewer pair distances than the pair law needs": (
        ["--pair-distances", "3"],
        "--pair-distances = 3",
        ">= 4",
    ),
    # nothing listens on port 1: refused once Dask has tried for CONNECT_TIMEOUT seconds
    "a scheduler with no answer": (
        ["--scheduler", "tcp://127.0.0.1:1"],
        "--scheduler = 'tcp://127.0.0.1:1'",
        "a Dask scheduler that answers",
        "drop --scheduler",
    ),
    "workers of a local cluster and a scheduler": (
        ["--workers", "2", "--scheduler", "tcp://127.0.0.1:1"],
        "--workers = 2",
        "no --workers with --scheduler",
    ),
}


@pytest.mark.parametrize("name", list(CASES))
def test_a_bad_calibration_is_refused_in_one_line(name, tmp_path):
    args, *expected = CASES[name]
    refused(["calibrate", "S6", "--out", "out", *args], tmp_path, *expected)


def test_more_workers_than_the_memory_holds_are_refused(tmp_path):
    before = snapshot(tmp_path)
    proc = run(["calibrate", "S6", "--out", "out", "--workers", "20"], tmp_path, SMALL_MACHINE)
    assert_one_line(proc, "--workers = 20", "20 solver processes", "use fewer --workers")
    assert snapshot(tmp_path) == before


def test_a_long_calibration_starts_when_forced():
    from skygas.calibration.estimate import check_calibration
    from skygas.calibration.material import load_micromagnetic_material
    from skygas.calibration.plan import CalibrationConfig
    from skygas.core.estimates import MAX_SECONDS, run_limits

    config = CalibrationConfig(material=load_micromagnetic_material("S6", cell_size=2e-10))
    with pytest.raises(InputError, match="--force"):
        check_calibration(config, 2)
    with run_limits(force=True):
        assert check_calibration(config, 2).seconds > MAX_SECONDS
    # memory is never forced
    fine = CalibrationConfig(material=load_micromagnetic_material("S6", cell_size=1e-11))
    with run_limits(force=True), pytest.raises(InputError, match="fits in memory"):
        check_calibration(fine, 2)


# the solver is looked for, not imported: importing torch here would take seconds
@pytest.mark.skipif(find_spec("magnumnp") is None, reason="the solver is not installed")
def test_a_worker_killed_by_the_kernel_is_said_in_one_line():
    from skygas.calibration.material import load_micromagnetic_material
    from skygas.calibration.pipeline import CalibrationJob
    from skygas.calibration.plan import CalibrationConfig

    material = load_micromagnetic_material("S6", cell_size=2.4e-9)
    config = CalibrationConfig(material=material, validate_dynamics=False, mesh_check=False)
    job = CalibrationJob(config, workers=1)
    try:
        job.advance_piece()  # the local Dask cluster starts and takes the first solve
        pids = job.connect().pids()
        assert pids, "no worker process started"
        for pid in pids:
            os.kill(pid, signal.SIGKILL)  # as the kernel's out-of-memory killer does
        deadline = time.monotonic() + 20
        with pytest.raises(InputError, match="--workers = 1: .*killed by SIGKILL.*memory"):
            while time.monotonic() < deadline:
                job.advance_piece()
    finally:
        job.close()


def _model(distances: int, forces: int) -> str:
    """A calibrated model's ``[material]`` table whose pair table has these many entries."""
    d = [1e-8 * (1 + 0.05 * k) for k in range(distances)]
    f = [1e-12 * (distances - k) for k in range(forces)]
    return (
        '[material]\nname = "cal"\nsaturation_magnetization = 5.8e5\n'
        "exchange_stiffness = 1.5e-11\ndmi = 3e-3\nanisotropy = 8e5\n"
        "skyrmion_radius = 1.2e-8\npair_law = [0.2, 0.4, 1.0]\nwall_law = [1.0, 0.0]\n"
        "film_thickness = 2e-9\n\n[material.pair_table]\n"
        f"distance = {d}\nforce = {f}\n"
    )


def test_a_broken_model_file_names_the_field_and_a_short_value(tmp_path):
    (tmp_path / "model.toml").write_text(_model(300, 299))
    line = refused(
        ["reshuffle", "--material", "model.toml", "--out", "out", "--duration", "1e-9"],
        tmp_path,
        "model.toml:material.pair_table",
        "one value per distance (300), not 299",
    )
    assert len(line) < 300, line  # not the 3–5 KB table pydantic holds
