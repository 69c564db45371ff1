"""``skygas reservoir`` as a job of the run driver (:mod:`skygas.runs.run_driver`).

:func:`run_reservoir` runs the study of a configuration and writes into ``out_dir``:

- ``summary.json``: the study's summary (:func:`~skygas.reservoir.study.study_summary`: every
  score and parameter, the seed and the version);
- ``occupation.png`` and ``accuracy.png``: where the skyrmion is while each input is held, and
  the accuracies (the command adds ``report.html``, :mod:`skygas.outputs.report`).

Accuracy against a parameter is a ``skygas sweep`` of
``device = "reservoir"``.

The work is the held inputs of the study's streams
(:func:`~skygas.reservoir.streams.stream_specs`), counted in µs of simulated time. A stream is
held a few inputs at a time (about :data:`PIECE_STEPS` engine steps), up to ``study.workers``
streams at once on Dask workers (:class:`~skygas.reservoir.streams.StreamPool`); a piece
of the job ends whenever one of them is done. The checkpoint holds the state of every stream
after its last finished part, so a run interrupted and resumed gives the numbers of a run left
alone (only the measured times differ): a stream's numbers do not depend on where it is cut,
nor on which process holds which part. See :func:`skygas.runs.run_driver.drive` for
checkpoints, interruption, resume and the folders it refuses.
"""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Any

import numpy as np

from skygas.core.state_keys import nest, unnest
from skygas.reservoir.config import ReservoirConfig
from skygas.reservoir.device import StreamSpec, stream_result
from skygas.reservoir.streams import StreamPool, device_for, stream_specs
from skygas.reservoir.study import score_streams, study_summary
from skygas.runs.run_driver import (
    drive,
    run_record,
    write_figure,
    write_json,
)

#: The study's summary: its presence means a finished study.
SUMMARY = "summary.json"
#: Engine steps (times skyrmions) a stream holds per piece: about a second of one core.
PIECE_STEPS = 3_000_000


class ReservoirJob:
    """A reservoir study as a job of the run driver.

    Work is counted in µs of simulated time (see the module docstring). The configuration is
    validated and its device built before any run.
    ``piece_steps`` sets the size of a piece (engine steps times skyrmions per stream); it
    changes no number. ``sim`` is a simulation of the device (never run), for the sanity checks
    before the run (:mod:`skygas.runs.sanity`: the temperature, a constant force per step). The
    job keeps its worker processes until :meth:`close` (or the end of a ``with`` block).

    Parameters
    ----------
    config
        The validated configuration.
    piece_steps
        Engine steps (times skyrmions) of one stream in one piece (default
        :data:`PIECE_STEPS`).
    scheduler
        A running Dask scheduler's address, whose workers hold the streams (default: a local
        cluster, :class:`~skygas.reservoir.streams.StreamPool`).
    """

    work_unit = "µs"
    result_files: tuple[str, ...] = (
        SUMMARY,
        "occupation.png",
        "accuracy.png",
    )

    def __init__(
        self,
        config: ReservoirConfig,
        *,
        piece_steps: int | None = None,
        scheduler: str | None = None,
    ):
        self.config = config
        inputs = _held_inputs(config)
        _check_estimate(config, inputs, config.time_step, announce=False)  # before any numerics
        self.device = device_for(config)  # validates everything before any run
        _check_estimate(config, inputs, self.device.time_step)
        self.sim = self.device.simulation(config.seed)
        boolean, temporal = stream_specs(config)
        self.specs: list[StreamSpec] = [*boolean, *temporal]
        self.n_boolean = len(boolean)
        self.n_study = len(self.specs)
        piece_steps = PIECE_STEPS if piece_steps is None else piece_steps
        dt = self.device.time_step
        self.piece_inputs = [
            max(1, piece_steps // max(1, round(s.hold / dt) * s.config.n_skyrmions))
            for s in self.specs
        ]
        self._hold_us = [s.hold * 1e6 for s in self.specs]
        self.work_total = self._work([s.n_total for s in self.specs])
        self.pool = StreamPool(config.study.workers, scheduler)
        #: inputs held per stream; the state of each stream started
        self.done = [0] * len(self.specs)
        self.states: dict[int, dict[str, np.ndarray]] = {}
        #: the pieces under way in the worker processes, by stream
        self.running: dict[int, Any] = {}
        self.study_wall_seconds = 0.0

    def __enter__(self) -> ReservoirJob:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        """Stop the worker processes (see :meth:`StreamPool.close`)."""
        self.running = {}
        self.pool.close()

    # -- the run driver's protocol -------------------------------------------------------------
    def _work(self, inputs: list[int]) -> float:
        return float(sum(n * hold for n, hold in zip(inputs, self._hold_us, strict=True)))

    def work_done(self) -> float:
        """Simulated time of the inputs held so far [µs]."""
        return self._work(self.done)

    def advance_piece(self) -> None:
        """Hold inputs until one stream's part is done; keep its state.

        The next inputs of the first unfinished streams are started until ``study.workers``
        run, then the first of them to be done is kept. The others carry on into the next
        piece (their work is lost if the run stops here: the state holds finished parts only).
        """
        started = time.perf_counter()
        for i, spec in enumerate(self.specs):
            if len(self.running) >= self.pool.workers:
                break
            if self.done[i] < spec.n_total and i not in self.running:
                n = min(self.piece_inputs[i], spec.n_total - self.done[i])
                self.running[i] = self.pool.submit(spec, self.states.get(i), n)
        finished = self.pool.first_done(self.running.values())
        for i, future in list(self.running.items()):
            if future in finished:
                del self.running[i]
                self.states[i] = self.pool.result(future)
                self.done[i] = int(self.states[i]["position"])
        self.study_wall_seconds += time.perf_counter() - started

    def state_dict(self) -> dict[str, np.ndarray]:
        """The job's state as NumPy arrays.

        Inputs held per stream, the streams' states (``stream<i>_``) and the study's wall time
        so far.
        """
        state = {
            "done": np.array(self.done, dtype=np.int64),
            "study_wall_seconds": np.array(self.study_wall_seconds),
        }
        for i, stream in self.states.items():
            state.update(nest(f"stream{i}_", stream))
        return state

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        """Continue from a state saved by :meth:`state_dict`."""
        self.done = [int(n) for n in state["done"]]
        assert len(self.done) == len(self.specs), "a checkpoint of another plan of streams"
        self.study_wall_seconds = float(state["study_wall_seconds"])
        self.states = {}
        for i in range(len(self.specs)):
            stream = unnest(f"stream{i}_", state)
            if stream:
                self.states[i] = stream

    def config_json(self) -> str:
        """The configuration (a checkpoint resumes only the same)."""
        return json.dumps({"reservoir": self.config.model_dump(mode="json")})

    def seed(self) -> int:
        """The configuration's seed."""
        return self.config.seed

    def finish(self, out: Path) -> dict:
        """Score the study and write the results, each file atomically.

        Returns the study's summary.
        """
        from skygas.reservoir.figures import plot_accuracies, plot_occupation

        self.close()
        started = time.perf_counter()
        results = [stream_result(self.specs[i].bits, self.states[i]) for i in range(self.n_study)]
        streams, temporal = results[: self.n_boolean], results[self.n_boolean :]
        scores = score_streams(self.config, streams, temporal)
        wall = self.study_wall_seconds + time.perf_counter() - started
        summary = study_summary(self.config, self.device, streams, temporal, scores, wall)
        record = run_record(self)
        write_json(out / SUMMARY, summary, indent=1)
        write_figure(
            out / "occupation.png",
            lambda tmp: plot_occupation(self.device, streams, tmp),
            record,
        )
        write_figure(out / "accuracy.png", lambda tmp: plot_accuracies(summary, tmp), record)
        return summary


def _held_inputs(config: ReservoirConfig) -> tuple[int, float]:
    """Inputs held in all (study and warm-ups) and their total hold time [s]."""
    st = config.study
    warm = st.warmup_inputs * max(1, st.workers)
    n = st.n_inputs + warm
    held = n * config.hold_time + (st.temporal_inputs + warm) * st.temporal_hold_time
    n += st.temporal_inputs + warm
    return n, held


def _check_estimate(
    config: ReservoirConfig, inputs: tuple[int, float], time_step: float | None, announce=True
) -> None:
    """Refuse a study that cannot fit or run (:mod:`skygas.core.estimates`); announce it.

    Memory: the input bits (int64 per input contact) and the frames of one hold (a read every
    ``sensors.sample_interval``). Steps: the total hold time over ``time_step`` (one step per
    input, a lower bound, before the time step is known).
    """
    from skygas.core.estimates import check
    from skygas.runs.machine_speed import optimistic_estimate, run_estimate

    n, held = inputs
    width = len(config.drive.input_contacts)
    frames = max(config.hold_time, config.study.temporal_hold_time) / min(
        config.sensors.sample_interval, config.study.temporal_sample_interval
    )
    memory = 8.0 * width * n + 24.0 * (frames + 1) * max(1, config.n_skyrmions)
    steps = n if time_step is None else held / time_step
    skyrmions = max(1, config.n_skyrmions)
    workers = config.study.workers
    estimate = (
        optimistic_estimate(steps / workers, skyrmions, memory)
        if time_step is None
        else run_estimate(steps, skyrmions, memory, runs=1, workers=1)
    )
    if time_step is not None:  # the streams run on the study's workers
        estimate = type(estimate)(estimate.steps, memory, estimate.seconds / workers)
    check(
        estimate,
        "study.n_inputs",
        config.study.n_inputs,
        f"{n:.3g} held inputs",
        "hold fewer inputs, or hold each for a shorter hold_time",
        announce=announce,
    )


def run_reservoir(
    config: ReservoirConfig,
    out_dir: str | Path,
    *,
    scheduler: str | None = None,
    **drive_options: Any,
) -> dict:
    """Run the study of ``config`` and write its files into ``out_dir``.

    Parameters
    ----------
    config
        The validated configuration.
    out_dir
        The output folder (see the module docstring for its files).
    scheduler
        The address of a running Dask scheduler whose workers hold the streams (default: a
        local cluster of ``study.workers`` processes; one: this process). The numbers do not
        depend on it.
    **drive_options
        Those of :func:`~skygas.runs.run_driver.drive` (``progress``, ``resume``,
        ``checkpoint_seconds``, ``overwrite``, ``strict``, ``then``): a finished folder is
        refused unless ``overwrite``, an interrupted one unless ``resume`` (or
        ``overwrite``); ``then`` writes more once the results are there (the command's HTML
        report).

    Returns
    -------
    dict
        The study's summary (what ``summary.json`` holds).
    """
    with ReservoirJob(config, scheduler=scheduler) as job:
        return drive(job, out_dir, **drive_options)
