"""A user's operation on a reshuffler run, added from Python without touching the device: its
state is checkpointed under its name and restored bit-identically, and its summary appears in
the run's summary."""

from __future__ import annotations

import numpy as np
import pytest

from skygas.core.errors import InputError
from skygas.reshuffler import load_reshuffler_config
from skygas.reshuffler.analysis import summarize
from skygas.reshuffler.files import ReshufflerJob
from skygas.runs.run_driver import load_checkpoint, save_checkpoint


class Census:
    """Counts the skyrmions present every ``every`` steps."""

    name = "census"

    def __init__(self, every: int = 97):
        self.every, self.times, self.counts = every, [], []

    def next_step(self, step):
        return (step // self.every + 1) * self.every

    def act(self, sim):
        self.times.append(sim.time)
        self.counts.append(sim.count)

    def state_dict(self):
        return {"times": np.array(self.times), "counts": np.array(self.counts, dtype=np.int64)}

    def load_state_dict(self, state):
        self.times = [float(t) for t in state["times"]]
        self.counts = [int(c) for c in state["counts"]]

    def summary(self):
        return {"readings": len(self.counts), "largest_count": max(self.counts, default=0)}


def _job(census):
    config = load_reshuffler_config(None, preset="paper", overrides={"duration": 4e-7, "seed": 5})
    job = ReshufflerJob(config, figures=False)
    job.run.sim.operations.append(census)
    return job


def test_a_user_operation_is_checkpointed_and_summarised(tmp_path):
    whole = Census()
    reference = _job(whole)
    reference.run.advance()

    first = Census()
    interrupted = _job(first)
    interrupted.run.advance(stop_after_step=reference.run.total_steps // 2)
    assert 0 < len(first.counts) < len(whole.counts)
    path = tmp_path / "checkpoint.npz"
    save_checkpoint(interrupted, path)

    second = Census()
    resumed = _job(second)
    load_checkpoint(resumed, path)
    assert second.counts == first.counts  # restored under its name
    resumed.run.advance()

    assert second.counts == whole.counts and second.times == whole.times
    np.testing.assert_array_equal(resumed.run.sim.positions()[1], reference.run.sim.positions()[1])
    summary = summarize(resumed.run, dataset=False).summary
    assert summary["operations"] == {
        "census": {"readings": len(whole.counts), "largest_count": max(whole.counts)}
    }
    assert summary["n_detected"] == summarize(reference.run, dataset=False).summary["n_detected"]


def test_a_run_without_user_operations_saves_only_the_device_s_own():
    job = _job(Census())
    job.run.sim.operations.pop()
    saved = {k.split(".")[1] for k in job.state_dict() if k.startswith("sim_op.")}
    assert saved == {"injector"}  # the device's injector, checkpointed under its name
    assert "operations" not in summarize(job.run, dataset=False).summary


def test_two_operations_of_one_name_are_refused():
    job = _job(Census())
    job.run.sim.operations.append(Census())
    with pytest.raises(InputError, match="operation name"):
        job.state_dict()
