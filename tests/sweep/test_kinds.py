"""Sweeps of every kind a study can run: a neuron, a reservoir and a plain simulation.

The sweep's machinery (seeds, store, resume) is the reshuffler's (tests/sweep/test_execute.py);
here: each kind's points are built and checked by its own hooks, its runs store its own numbers,
the numbers are right where they are known exactly, and the figures and report follow.
"""

from __future__ import annotations

import hashlib
import json
import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest
import zarr

from skygas.cli import main
from skygas.core.errors import InputError
from skygas.devices.registry import study_kind
from skygas.sweep import load_sweep, open_sweep, parse_sweep, plot_sweep, run_sweep

NEURON_SWEEP = textwrap.dedent("""
    [sweep]
    device = "neuron"
    seed = 3
    replicas = 2

    [base]
    duration = 2e-7

    [[base.inputs]]
    kind = "poisson"
    rate = 5e7

    [grid]
    "inputs.0.rate" = [5e7, 2e8]
""")

# a closed chamber: no skyrmion can leave, so a census of the whole chamber reads its filling
SIMULATE_SWEEP = textwrap.dedent("""
    [sweep]
    device = "simulate"
    seed = 5

    [base]
    duration = 5e-9
    record_interval = 1e-9
    material = "S2"
    [base.geometry]
    kind = "chamber"
    chamber_diameter = 5e-7
    conduit_width = 1e-7
    conduit_length = 5e-8
    closed = true
    [[base.operations]]
    kind = "census"
    name = "all"
    interval = 1e-9

    [grid]
    "skyrmions.random_count" = [3, 8]
    temperature = [100.0, 300.0]
""")

RESERVOIR_SWEEP = textwrap.dedent("""
    [sweep]
    device = "reservoir"
    seed = 9

    [base]
    material = "S2"
    hold_time = 5e-7
    [base.study]
    n_inputs = 24
    warmup_inputs = 2

    [[points]]
    temperature = 100.0
    [[points]]
    temperature = 300.0
""")


def _write(tmp_path, text, name="s.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("text", "device"),
    [(NEURON_SWEEP, "neuron"), (SIMULATE_SWEEP, "simulate"), (RESERVOIR_SWEEP, "reservoir")],
)
def test_each_kind_builds_its_points_with_its_own_hooks(text, device):
    import tomllib

    sweep = parse_sweep(tomllib.loads(text))
    hooks = study_kind(device).study
    assert sweep.device == device
    assert sweep.quantities[: len(hooks.quantities)] == hooks.quantities
    assert all(isinstance(run.config, hooks.model()) for run in sweep.runs)
    # seeds are the kind's: below its limit, and set in each run's configuration
    assert all(
        0 <= run.seed < hooks.seed_limit and run.config.seed == run.seed for run in sweep.runs
    )
    assert len({run.seed for run in sweep.runs}) == len(sweep.runs)


def test_a_census_adds_its_counts_to_a_simulations_numbers():
    import tomllib

    sweep = parse_sweep(tomllib.loads(SIMULATE_SWEEP))
    assert sweep.quantities[-3:] == ("all_mean_count", "all_min_count", "all_max_count")


def test_an_unknown_device_is_refused_in_one_line(tmp_path, capsys):
    path = _write(tmp_path, NEURON_SWEEP.replace('device = "neuron"', 'device = "toaster"'))
    assert main(["sweep", str(path), "--out", str(tmp_path / "out.zarr")]) == 2
    err = capsys.readouterr().err
    assert "sweep.device" in err and "toaster" in err and "neuron" in err
    assert len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out.zarr").exists()


def test_a_field_of_another_device_is_refused_naming_the_device():
    import tomllib

    data = tomllib.loads(NEURON_SWEEP)
    data["grid"] = {"signal.p": [0.2, 0.5]}  # the reshuffler's, not the neuron's
    with pytest.raises(InputError) as err:
        parse_sweep(data)
    assert "grid.signal.p" in str(err.value) and "neuron configuration" in str(err.value)


def test_a_point_the_device_refuses_is_named():
    import tomllib

    data = tomllib.loads(NEURON_SWEEP)
    data["grid"] = {"rule.threshold": [12, -1]}
    with pytest.raises(InputError) as err:
        parse_sweep(data)
    assert "rule.threshold = -1" in str(err.value)


def test_the_reshufflers_fingerprint_is_unchanged_by_other_kinds(tiny_sweep_file):
    # the formula stores of earlier versions were written with: a store resumes only if equal
    sweep = load_sweep(tiny_sweep_file)
    digest = hashlib.sha256()
    digest.update(json.dumps([sweep.fields, sweep.layout, sweep.replicas]).encode())
    for run in sweep.runs:
        digest.update(run.config.model_dump_json().encode())
    assert sweep.fingerprint() == digest.hexdigest()[:20]


def test_a_config_file_is_changed_by_base_and_its_seed_set_aside(tmp_path):
    (tmp_path / "chamber.toml").write_text(
        "seed = 2024\n"
        + SIMULATE_SWEEP.split("[base]\n")[1].split("[[base.operations]]")[0].replace("[base.", "[")
    )
    path = _write(
        tmp_path,
        '[sweep]\ndevice = "simulate"\nconfig = "chamber.toml"\n'
        "[base]\nduration = 2e-9\n[base.geometry]\nchamber_diameter = 6e-7\n"
        "[base.skyrmions]\nrandom_count = 2\n"
        "[grid]\ntemperature = [100.0, 200.0]\n",
    )
    sweep = load_sweep(path)
    config = sweep.runs[0].config
    assert config.duration == 2e-9  # changed by [base]
    assert config.geometry.chamber_diameter == 6e-7  # a table merged key by key
    assert config.geometry.closed is True  # kept from the file
    assert config.seed == sweep.runs[0].seed != 2024
    path.write_text(path.read_text().replace("[base]\n", "[base]\nseed = 4\n"))
    with pytest.raises(InputError, match="base.seed"):
        load_sweep(path)


@pytest.mark.slow
def test_a_simulation_sweep_counts_every_skyrmion_of_a_closed_chamber(tmp_path):
    sweep = load_sweep(_write(tmp_path, SIMULATE_SWEEP))
    run_sweep(sweep, tmp_path / "s.zarr", serial=True, progress=False)
    ds = open_sweep(tmp_path / "s.zarr")
    assert ds.attrs["device"] == "simulate" and bool((ds["done"] == 1).all())
    filling = ds["skyrmions_random_count"].broadcast_like(ds["done"])
    # exact: a closed chamber keeps every skyrmion, and the census counts the whole chamber
    for name in ("skyrmions_initial", "skyrmions_present", "all_min_count", "all_max_count"):
        np.testing.assert_array_equal(ds[name].values, filling.values, err_msg=name)
    np.testing.assert_array_equal(ds["all_mean_count"].values, filling.values)
    assert float(ds["exits"].max()) == 0.0
    # 5 ns of 1 ns censuses: the start is not read (the first reading is after 1 ns)
    np.testing.assert_array_equal(ds["simulated_time_s"].values, 5e-9)

    result = plot_sweep(ds, tmp_path / "figures")
    assert [os.path.basename(f) for f in result["figures"]] == ["quantities.png"]
    assert "all_mean_count" in result["plotted"]
    rows = result["points"]
    assert len(rows) == 4 and {r["skyrmions.random_count"] for r in rows} == {3, 8}
    csv = (tmp_path / "figures" / "points.csv").read_text()
    assert "skyrmions.random_count" in csv and "all_mean_count_sem" in csv


@pytest.mark.slow
def test_a_neuron_sweep_on_two_workers_matches_serial_and_is_reported(tmp_path):
    sweep = load_sweep(_write(tmp_path, NEURON_SWEEP))
    run_sweep(sweep, tmp_path / "serial.zarr", serial=True, progress=False)
    run_sweep(sweep, tmp_path / "dask.zarr", workers=2, progress=False)
    a, b = open_sweep(tmp_path / "serial.zarr"), open_sweep(tmp_path / "dask.zarr")
    for name in [*sweep.quantities, "seed", "done"]:
        if name != "wall_time_s":
            np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
    # the input's rate is what the configuration asks for
    np.testing.assert_allclose(
        a["input_rate_Hz"].values, a["inputs_0_rate"].broadcast_like(a["done"]).values
    )
    # more input, more injected skyrmions: each replica's 4× rate gives more (Poisson, ≥ 10 vs
    # ~ 40 expected in 200 ns: a reversal is a 5σ event)
    injected = a["n_injected"].values
    assert (injected[1] > injected[0]).all()

    figures = tmp_path / "figures"
    assert main(["plot", str(tmp_path / "serial.zarr"), "--out", str(figures)]) == 0
    report = (figures / "report.html").read_text()
    assert "Replica means at each point" in report and "inputs.0.rate" in report
    assert (figures / "quantities.png").exists()


@pytest.mark.slow
def test_a_killed_neuron_sweep_resumes_to_the_same_results(tmp_path):
    path = _write(
        tmp_path, NEURON_SWEEP.replace("duration = 2e-7", "duration = 1e-6")
    )  # long enough that the poll below sees the first run before the last
    store = tmp_path / "killed.zarr"
    cli = [sys.executable, "-m", "skygas.cli", "sweep", str(path), "--out", str(store)]
    proc = subprocess.Popen(
        [*cli, "--workers", "1", "--quiet"],
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and proc.poll() is None:
            if (store / "done" / "zarr.json").exists():
                if int(np.asarray(zarr.open_group(store)["done"][...]).sum()) >= 1:
                    break
            time.sleep(0.05)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    done_before = np.asarray(zarr.open_group(store)["done"][...]).astype(bool)
    assert 1 <= done_before.sum() < 4, "the sweep was not interrupted midway"
    resumed = subprocess.run(
        [*cli, "--serial", "--quiet"], capture_output=True, text=True, timeout=300
    )
    assert resumed.returncode == 0, resumed.stderr
    assert f"{int(done_before.sum())} already done" in resumed.stdout
    reference = tmp_path / "reference.zarr"
    run_sweep(load_sweep(path), reference, serial=True, progress=False)
    a, b = open_sweep(store), open_sweep(reference)
    for name in ("firing_rate_Hz", "n_injected", "n_annihilated", "max_count", "seed", "done"):
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)


@pytest.mark.slow
def test_a_reservoir_sweep_stores_accuracies(tmp_path):
    sweep = load_sweep(_write(tmp_path, RESERVOIR_SWEEP))
    run_sweep(sweep, tmp_path / "r.zarr", serial=True, progress=False)
    ds = open_sweep(tmp_path / "r.zarr")
    assert ds["done"].dims == ("point", "replica")
    accuracy = ds["xor_accuracy"].values
    # a test accuracy is a fraction of the held inputs tested
    assert ((0 <= accuracy) & (accuracy <= 1)).all()
    result = plot_sweep(ds, tmp_path / "figures")
    assert result["points"][0]["temperature"] == 100.0
