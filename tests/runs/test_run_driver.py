"""The run driver on a counting job: signals wait for the end of a piece, checkpoints and
results are atomic, handlers come back; and ``skygas saturation`` resumes exactly."""

from __future__ import annotations

import errno
import json
import os
import signal

import numpy as np
import pytest

from skygas.cli import main
from skygas.core.errors import InputError, RunFinished, RunInterrupted, WriteFailed
from skygas.runs.run_driver import CHECKPOINT, drive, write_atomic


class CountingJob:
    """Adds the piece number to a running sum; piece ``signal_at`` sends itself SIGINT
    half-way through (between two halves of its bookkeeping)."""

    work_unit = "pieces"
    result_files = ("result.json",)

    def __init__(self, pieces=5, signal_at=None, seed=0, signum=signal.SIGINT):
        self.work_total = float(pieces)
        self.done, self.total, self.halves = 0, 0, 0
        self.signal_at, self._seed, self.signum = signal_at, seed, signum

    def work_done(self):
        return float(self.done)

    def advance_piece(self):
        self.halves += 1
        if self.done == self.signal_at:
            os.kill(os.getpid(), self.signum)
        self.total += self.done
        self.halves += 1
        self.done += 1

    def state_dict(self):
        return {
            "done": np.array(self.done),
            "total": np.array(self.total),
            "halves": np.array(self.halves),
        }

    def load_state_dict(self, state):
        self.done, self.total, self.halves = (int(state[k]) for k in ("done", "total", "halves"))

    def config_json(self):
        return json.dumps({"pieces": self.work_total, "seed": self._seed})

    def seed(self):
        return self._seed

    def finish(self, out):
        write_atomic(
            out / "result.json", lambda tmp: tmp.write_text(json.dumps({"total": self.total}))
        )
        return self.total


def test_sigint_waits_for_the_end_of_the_piece_then_resume_finishes(tmp_path):
    before = signal.getsignal(signal.SIGINT)
    job = CountingJob(signal_at=2)
    with pytest.raises(RunInterrupted) as stop:
        drive(job, tmp_path, progress=False)
    assert stop.value.exit_status == 130 and "--resume" in str(stop.value)
    assert signal.getsignal(signal.SIGINT) is before  # the caller's handler is back
    with np.load(tmp_path / CHECKPOINT) as saved:
        # the piece that received the signal completed both halves before the save
        assert int(saved["done"]) == 3 and int(saved["halves"]) == 6
        assert int(saved["seed"]) == 0 and str(saved["skygas_version"])
    assert not (tmp_path / "result.json").exists()
    assert drive(CountingJob(), tmp_path, resume=True, progress=False) == 0 + 1 + 2 + 3 + 4
    assert not (tmp_path / CHECKPOINT).exists()
    # the results and the manifest, no temporary file left
    assert sorted(p.name for p in tmp_path.iterdir()) == ["manifest.json", "result.json"]
    # finished results are never overwritten; resuming them has nothing to do
    with pytest.raises(InputError, match="without finished results"):
        drive(CountingJob(), tmp_path, progress=False)
    with pytest.raises(RunFinished, match="nothing to resume"):
        drive(CountingJob(), tmp_path, resume=True, progress=False)


def test_sigterm_is_deferred_the_same_way(tmp_path):
    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(RunInterrupted) as stop:
        drive(CountingJob(signal_at=0, signum=signal.SIGTERM), tmp_path, progress=False)
    assert stop.value.exit_status == 143 and "SIGTERM" in str(stop.value)
    assert signal.getsignal(signal.SIGTERM) is before
    with np.load(tmp_path / CHECKPOINT) as saved:
        assert int(saved["done"]) == 1 and int(saved["halves"]) == 2


def test_a_second_signal_stops_at_once_and_keeps_the_periodic_checkpoint(tmp_path):
    class Twice(CountingJob):
        def advance_piece(self):
            if self.done == 3:
                os.kill(os.getpid(), signal.SIGINT)
                os.kill(os.getpid(), signal.SIGINT)
            super().advance_piece()

    with pytest.raises(KeyboardInterrupt) as stop:
        drive(Twice(), tmp_path, progress=False, checkpoint_seconds=0)
    assert not isinstance(stop.value, RunInterrupted)
    with np.load(tmp_path / CHECKPOINT) as saved:
        assert int(saved["done"]) == 3  # the checkpoint after the last complete piece


def test_checkpoints_belong_to_one_configuration(tmp_path):
    with pytest.raises(RunInterrupted):
        drive(CountingJob(signal_at=1), tmp_path, progress=False)
    with pytest.raises(InputError, match="same configuration"):
        drive(CountingJob(seed=1), tmp_path, resume=True, progress=False)
    with pytest.raises(InputError, match="--resume"):
        drive(CountingJob(), tmp_path, progress=False)


def test_a_failed_write_leaves_no_file_and_names_the_path_and_the_cause(tmp_path):
    def fail(tmp):
        tmp.write_text("half")
        raise OSError(errno.ENOSPC, "No space left on device")

    with pytest.raises(WriteFailed, match=r"could not write .*x\.json \(No space left on device\)"):
        write_atomic(tmp_path / "x.json", fail)
    assert list(tmp_path.iterdir()) == []


def test_saturation_resumes_exactly(tmp_path, monkeypatch, capsys):
    """``skygas saturation`` stopped by Ctrl-C after a relaxation gives, resumed, the
    uninterrupted run's numbers."""
    from skygas.neuron.saturation import SaturationProtocol

    argv = [
        "saturation",
        "--diameters",
        "2e-7",
        "--repetitions",
        "2",
        "--relax-time",
        "2e-10",
        "--quiet",
    ]
    assert main([*argv, "--out", str(tmp_path / "ref")]) == 0
    original = SaturationProtocol.run_trial

    def interrupted(self, k):
        if k == 5:
            os.kill(os.getpid(), signal.SIGINT)
        return original(self, k)

    monkeypatch.setattr(SaturationProtocol, "run_trial", interrupted)
    out = tmp_path / "out"
    assert main([*argv, "--out", str(out)]) == 130
    assert "--resume" in capsys.readouterr().err
    monkeypatch.setattr(SaturationProtocol, "run_trial", original)
    assert main([*argv, "--out", str(out), "--resume"]) == 0
    ref = json.loads((tmp_path / "ref" / "summary.json").read_text())
    assert ref["seed"] == 0 and "skygas_version" in ref
    assert json.loads((out / "summary.json").read_text()) == ref


QUICK_TOML = """\
seed = 4
duration = 5e-8
[geometry]
kind = "chamber"
closed = true
chamber_diameter = 400e-9
[skyrmions]
random_count = 3
"""


def test_a_full_disk_while_results_are_written_keeps_the_run_resumable(
    tmp_path, monkeypatch, capsys
):
    """No space left while the netCDF file is written: one line naming the file, the cause and
    what is kept (exit 74); with room again, --resume writes the results without rerunning."""
    import xarray as xr

    config = tmp_path / "run.toml"
    config.write_text(QUICK_TOML)
    out = tmp_path / "out"
    argv = ["simulate", str(config), "--out", str(out), "--quiet", "--no-report"]

    def full(self, path, *args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    with monkeypatch.context() as patch:
        patch.setattr(xr.Dataset, "to_netcdf", full)
        assert main(argv) == 74
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert "could not write" in err[0] and "trajectories.nc" in err[0]
    assert "No space left on device" in err[0] and "--resume" in err[0]
    assert (out / CHECKPOINT).is_file() and not (out / "trajectories.nc").exists()
    assert main([*argv, "--resume"]) == 0
    assert (out / "trajectories.nc").is_file() and not (out / CHECKPOINT).exists()


def test_overwrite_refuses_a_folder_of_files_without_a_manifest(tmp_path, capsys):
    """Nothing says which files of a folder without a manifest a command wrote: --overwrite
    deletes none of them and refuses in one line."""
    config = tmp_path / "run.toml"
    config.write_text(QUICK_TOML)
    out = tmp_path / "out"
    out.mkdir()
    (out / "summary.json").write_text("{}")  # somebody else's
    (out / "notes.txt").write_text("mine")
    assert main(["simulate", str(config), "--out", str(out), "--overwrite", "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no manifest.json" in err[0], err
    assert (out / "summary.json").read_text() == "{}" and (out / "notes.txt").exists()


def test_resume_of_a_finished_run_has_nothing_to_do(tmp_path, capsys):
    """A Ctrl-C just after the last result was written, then --resume: exit 0, one line, the
    results untouched."""
    config = tmp_path / "run.toml"
    config.write_text(QUICK_TOML)
    out = tmp_path / "out"
    argv = ["simulate", str(config), "--out", str(out), "--quiet", "--no-report"]
    assert main(argv) == 0
    before = (out / "summary.json").read_bytes()
    capsys.readouterr()
    assert main([*argv, "--resume"]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "nothing to resume" in err[0], err
    assert (out / "summary.json").read_bytes() == before


def test_a_bar_shows_no_remaining_time_until_the_job_can_measure_its_rate(monkeypatch):
    """A calibration's first solves are start-up: no projection from them, clock restarts."""
    import tqdm

    from skygas.runs import run_driver

    class Job:
        work_total = 10.0
        work_unit = "cost"
        progress_format = "{desc}{percentage:3.0f}%|{bar}| [{elapsed}<{remaining}]"
        rate_measured = False
        done = 0.0

        def work_done(self):
            return self.done

    made = []

    class Recorded(tqdm.tqdm):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            made.append(self)

    monkeypatch.setattr(tqdm, "tqdm", Recorded)
    job = Job()
    with run_driver._progress_bar(job, True) as update:
        (bar,) = made
        assert "{remaining}" not in bar.bar_format  # no projection yet
        job.done = 1.0
        update()
        assert "{remaining}" not in bar.bar_format
        job.rate_measured = True
        job.done = 2.0
        update()
        assert bar.bar_format == Job.progress_format  # the remaining time is back
        assert bar.n == bar.initial == 2.0  # and the rate is measured from here
