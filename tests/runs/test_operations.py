"""Operations added from a configuration's ``[[operations]]`` tables (skygas.runs.operations):
a built-in census and the user's own class from a file, in ``simulate``, ``reshuffle`` and
``neuron``, checkpointed, resumed bit-identically and reported, with no change to any device."""

from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr

from skygas.cli import main
from skygas.reshuffler import load_reshuffler_config
from skygas.reshuffler.analysis import summarize
from skygas.reshuffler.files import ReshufflerJob
from skygas.runs.run_driver import load_checkpoint, save_checkpoint

SIMULATE = """\
seed = 2
duration = 20e-9
record_interval = 1e-9
[geometry]
kind = "chamber"
closed = true
chamber_diameter = 500e-9
[skyrmions]
random_count = 5

[[operations]]
kind = "census"
name = "all"
interval = 2e-9

[[operations]]
kind = "census"
name = "nowhere"        # a disk far outside the chamber: never a skyrmion
interval = 5e-9
center = [5e-6, 0.0]
radius = 100e-9

[[operations]]
kind = "python"
name = "sensor"
target = "my_sensor.py:Sensor"
options = { every = 7 }
"""

SENSOR = '''
import numpy as np

class Sensor:
    """Sums x of all skyrmions every `every` steps."""

    def __init__(self, every):
        self.every, self.readings = every, []

    def next_step(self, step):
        return (step // self.every + 1) * self.every

    def act(self, sim):
        self.readings.append(float(sim.state.positions[:, 0].sum()))

    def state_dict(self):
        return {"readings": self.readings}          # JSON-able values are fine

    def load_state_dict(self, state):
        self.readings = list(state["readings"])

    def summary(self):
        return {"readings": len(self.readings)}

    def data(self):
        return {"x_sum": (("reading",), np.array(self.readings))}
'''


def test_simulate_runs_the_operations_of_its_configuration(tmp_path):
    (tmp_path / "my_sensor.py").write_text(SENSOR)
    config = tmp_path / "run.toml"
    config.write_text(SIMULATE)
    out = tmp_path / "out"
    assert main(["simulate", str(config), "--out", str(out), "--quiet"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    ops = summary["operations"]
    steps = summary["steps"]
    dt = summary["time_step_s"]
    every = round(2e-9 / dt)
    # a closed chamber keeps its 5 skyrmions: every reading counts all of them, none outside
    assert ops["all"]["readings"] == steps // every
    assert ops["all"]["min_count"] == ops["all"]["max_count"] == 5
    assert ops["nowhere"]["max_count"] == 0
    assert ops["sensor"] == {"readings": steps // 7}
    with xr.open_dataset(out / "trajectories.nc") as ds:
        np.testing.assert_array_equal(ds["all_count"].values, 5)
        assert ds["all_time"].dims == ("all_reading",)
        assert ds["sensor_x_sum"].size == steps // 7


def test_a_bad_operation_target_is_one_line_before_any_work(tmp_path, capsys):
    config = tmp_path / "run.toml"
    config.write_text(SIMULATE)  # my_sensor.py is missing
    out = tmp_path / "out"
    assert main(["simulate", str(config), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "operations.2.target" in err[0] and "my_sensor.py" in err[0]
    assert not out.exists()


def test_a_reservoir_operation_with_a_device_s_name_is_refused_in_one_line(tmp_path, capsys):
    """The reservoir takes [[operations]] (tests/reservoir/test_operations.py), under the same
    rules: a name the devices' own operations use is one line before any work."""
    config = tmp_path / "res.toml"
    config.write_text('[[operations]]\nkind = "census"\nname = "injector"\ninterval = 1e-9\n')
    assert main(["reservoir", str(config), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "operations" in err[0] and "injector" in err[0]
    assert not (tmp_path / "out").exists()


def _reshuffler_job():
    config = load_reshuffler_config(
        None,
        preset="paper",
        overrides={
            "duration": 4e-7,
            "seed": 5,
            "operations": [{"kind": "census", "name": "census", "interval": 10e-9}],
        },
    )
    return ReshufflerJob(config, figures=False)


def test_a_configured_census_on_a_reshuffler_run_resumes_bit_identically(tmp_path):
    reference = _reshuffler_job()
    reference.run.advance()
    interrupted = _reshuffler_job()
    interrupted.run.advance(stop_after_step=reference.run.total_steps // 2)
    save_checkpoint(interrupted, tmp_path / "checkpoint.npz")
    resumed = _reshuffler_job()
    load_checkpoint(resumed, tmp_path / "checkpoint.npz")
    resumed.run.advance()

    whole = summarize(reference.run).dataset
    again = summarize(resumed.run).dataset
    assert whole is not None and again is not None
    np.testing.assert_array_equal(again["census_count"].values, whole["census_count"].values)
    np.testing.assert_array_equal(again["census_time"].values, whole["census_time"].values)
    census = summarize(resumed.run, dataset=False).summary["operations"]["census"]
    assert census["readings"] == len(whole["census_count"]) == 40
    # the census counts what the run holds: never more than were injected
    assert 0 < census["max_count"] <= reference.run.injector.n_injected


@pytest.mark.parametrize(
    "command, name",
    [("neuron", "injector"), ("neuron", "controller"), ("simulate", "annihilator")],
)
def test_a_user_operation_may_not_take_a_device_operation_s_name(tmp_path, capsys, command, name):
    """Refused in every device (a configuration moves between devices), when it is read."""
    config = tmp_path / "run.toml"
    config.write_text(
        f'duration = 2e-8\n[[operations]]\nkind = "census"\nname = "{name}"\ninterval = 1e-9\n'
    )
    assert main([command, str(config), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "operations.0.name" in err[0] and name in err[0]
    assert not (tmp_path / "out").exists()


BROKEN = """\
class Raises:
    def next_step(self, step):
        return (step // 3 + 1) * 3

    def act(self, sim):
        raise ZeroDivisionError("my own bug")


class Past:
    def next_step(self, step):
        return step - 1

    def act(self, sim):
        pass


class BadData:
    def next_step(self, step):
        return (step // 3 + 1) * 3

    def act(self, sim):
        pass

    def data(self):
        return {"x": "not an array of numbers"}
"""


@pytest.mark.parametrize(
    "target, words",
    [
        ("Raises", ["operations.mine.act()", "ZeroDivisionError", "my own bug", "broken.py"]),
        ("Past", ["'mine'", "next_step", "must move forward"]),
        ("BadData", ["'mine'", "data()", "dimension names"]),
    ],
)
def test_a_user_operation_that_breaks_its_contract_is_one_line_naming_it(
    tmp_path, capsys, target, words
):
    (tmp_path / "broken.py").write_text(BROKEN)
    config = tmp_path / "run.toml"
    head = SIMULATE.split("[[operations]]")[0]
    config.write_text(
        head + f'[[operations]]\nkind = "python"\nname = "mine"\ntarget = "broken.py:{target}"\n'
    )
    out = tmp_path / "out"
    assert main(["simulate", str(config), "--out", str(out), "--quiet", "--no-report"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("skygas: error:"), err
    for word in words:
        assert word in err[0], (word, err[0])
    assert not (out / "trajectories.nc").exists()


def test_a_neuron_run_reports_and_saves_its_configured_census(tmp_path):
    config = tmp_path / "neuron.toml"
    config.write_text(
        'duration = 1e-7\n[transfer]\nrates = []\n[[operations]]\nkind = "census"\n'
        'name = "census"\ninterval = 5e-9\n'
    )
    out = tmp_path / "out"
    assert main(["neuron", str(config), "--out", str(out), "--quiet", "--no-transfer"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["operations"]["census"]["readings"] == 20
    with np.load(out / "trace.npz") as trace:
        assert len(trace["census_count"]) == 20
        # the neuron's own trace counts the chamber too; at common times they agree
        common = np.isin(trace["time"], trace["census_time"])
        assert common.any()
        counted = dict(zip(trace["census_time"], trace["census_count"], strict=True))
        for t, n in zip(trace["time"][common], trace["count"][common], strict=True):
            assert counted[t] == n
