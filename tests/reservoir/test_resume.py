"""``skygas reservoir`` runs through the run driver: a study, stopped (an error after a
periodic checkpoint, as a ``kill -9`` would leave it, then SIGINT) and resumed, gives
the numbers of a run left alone, cut into other pieces; Ctrl-C at the terminal, which reaches
the worker processes too, stops with a checkpoint and the line that says how to resume."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from skygas.core.errors import InputError, RunInterrupted
from skygas.reservoir.config import reservoir_config
from skygas.reservoir.files import ReservoirJob, run_reservoir
from skygas.reservoir.study import run_study
from skygas.runs.run_driver import CHECKPOINT, drive

#: a short study (held 0.2 µs, 1800 steps per input) of one Boolean and one temporal stream,
#: with a census (an operation: its state is checkpointed with the stream's)
SHORT = {
    "hold_time": 2e-7,
    "sensors": {"sample_interval": 2e-9},
    "study": {"n_inputs": 16, "temporal_inputs": 16, "workers": 1},
    "operations": [{"kind": "census", "name": "chamber", "interval": 1e-8}],
}
#: pieces of 2 or 3 inputs: a stream takes several pieces
SMALL_PIECES = 5000


def _numbers(data):
    """A result record without the measured times."""
    if isinstance(data, dict):
        return {k: _numbers(v) for k, v in data.items() if k not in ("wall_seconds", "cpu_seconds")}
    if isinstance(data, list):
        return [_numbers(v) for v in data]
    return data


def _results(out):
    return {name: _numbers(json.loads((out / name).read_text())) for name in RESULTS}


RESULTS = ("summary.json",)


def _stopping(config, at: int, how: str) -> ReservoirJob:
    """The job of the study in small pieces, stopped after piece ``at``: by
    SIGINT to itself (the driver saves a checkpoint at the end of the piece), or by an error
    (the last periodic checkpoint stays, as after a kill)."""
    job = ReservoirJob(config, piece_steps=SMALL_PIECES)
    advance, pieces = job.advance_piece, [0]

    def advance_piece():
        advance()
        pieces[0] += 1
        if pieces[0] == at:
            if how == "error":
                raise RuntimeError("killed")
            os.kill(os.getpid(), signal.SIGINT)

    job.advance_piece = advance_piece  # type: ignore[method-assign]
    return job


def test_an_interrupted_study_resumes_to_the_same_numbers(tmp_path):
    config = reservoir_config(SHORT)
    whole = run_reservoir(config, tmp_path / "whole", progress=False)
    assert not (tmp_path / "whole" / CHECKPOINT).exists()

    out = tmp_path / "stopped"
    # the Boolean stream takes 9 pieces (2 inputs each, warm-ups included), then the temporal
    # one. Killed in piece 6, with periodic checkpoints after every piece: piece 5's is there
    with pytest.raises(RuntimeError, match="killed"):
        with _stopping(config, at=6, how="error") as job:
            assert job.piece_inputs[0] == 2
            temporal_piece = job.piece_inputs[1]
            drive(job, out, progress=False, checkpoint_seconds=0)
    with np.load(out / CHECKPOINT) as saved:
        assert list(saved["done"]) == [10, 0]
    # resumed, then Ctrl-C in the fifth piece: the Boolean stream's last four, then the
    # temporal stream's first
    with pytest.raises(RunInterrupted) as stop:
        with _stopping(config, at=5, how="signal") as job:
            drive(job, out, resume=True, progress=False, checkpoint_seconds=1e9)
    assert stop.value.exit_status == 130 and "--resume" in str(stop.value)
    with np.load(out / CHECKPOINT) as saved:
        assert list(saved["done"]) == [18, min(temporal_piece, 18)]
        assert int(saved["stream1_position"]) == min(temporal_piece, 18)
    # a checkpoint resumes only its own configuration
    with pytest.raises(InputError, match="same configuration"):
        run_reservoir(reservoir_config({**SHORT, "seed": 1}), out, resume=True, progress=False)
    resumed = run_reservoir(config, out, resume=True, progress=False)
    assert not (out / CHECKPOINT).exists()
    assert _results(out) == _results(tmp_path / "whole")
    assert _numbers(resumed) == _numbers(whole)
    # the same study as the in-memory one, whose streams run in one go
    study, _ = run_study(config)
    assert _numbers(study) == _results(out)["summary.json"]
    assert resumed["operations"]["boolean0"]["chamber"]["readings"] > 0
    for name in ("occupation.png", "accuracy.png"):
        assert (out / name).is_file()


#: the command line with pieces of 200 000 steps (11 inputs of 2 µs, some 60 ms)
SMALL_PIECES_CLI = """
import sys
import skygas.reservoir.files
skygas.reservoir.files.PIECE_STEPS = 200_000
from skygas.cli import main
sys.exit(main(sys.argv[1:]))
"""


def _pool_study(tmp_path) -> list[str]:
    """A study of two streams in two worker processes, 9 or 10 pieces each, no temporal
    stream."""
    config = tmp_path / "pool.toml"
    config.write_text(
        "hold_time = 2e-6\n[study]\nn_inputs = 200\ntemporal_inputs = 0\nworkers = 2\n"
    )
    return [sys.executable, "-c", SMALL_PIECES_CLI, "reservoir", str(config), "--no-report"]


def _group_ends(group: int, seconds: float) -> bool:
    """Whether every process of ``group`` is gone within ``seconds``."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        table = subprocess.run(["ps", "-eo", "pgid="], capture_output=True, text=True).stdout
        if str(group) not in table.split():
            return True
        time.sleep(0.1)
    return False


def test_ctrl_c_reaches_the_workers_too_and_still_leaves_a_checkpoint(tmp_path):
    out = tmp_path / "out"
    argv = [*_pool_study(tmp_path), "--out", str(out), "--checkpoint-seconds", "0", "--quiet"]
    # a session of its own: Ctrl-C at a terminal signals the whole process group
    proc = subprocess.Popen(argv, stderr=subprocess.PIPE, text=True, start_new_session=True)
    deadline = time.monotonic() + 240
    while not (out / CHECKPOINT).exists() and proc.poll() is None:
        assert time.monotonic() < deadline
        time.sleep(0.05)
    assert proc.poll() is None, proc.stderr.read()
    os.killpg(proc.pid, signal.SIGINT)
    # a worker compiling the engine's kernels (about a minute on an idle core, twice that
    # beside the other test worker) takes the signal once the compiler returns
    code = proc.wait(300)
    err = proc.stderr.read()
    assert code == 130, err
    assert "interrupted by SIGINT" in err and "--resume" in err and "Traceback" not in err
    assert (out / CHECKPOINT).exists() and not (out / "summary.json").exists()
    assert _group_ends(proc.pid, seconds=10), "worker processes left behind"
