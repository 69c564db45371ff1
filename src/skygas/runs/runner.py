"""``skygas simulate`` as a job of the run driver (:mod:`skygas.runs.run_driver`).

:func:`run_simulation` writes into ``out_dir``:

- ``trajectories.nc``: the :meth:`~skygas.engine.Simulation.trajectories` Dataset (netCDF4;
  attributes hold every parameter, the seed, the version and the configuration);
- ``trajectories.png``: the outline with the trajectories;
- ``summary.json``: counts, timings, the seed, the version and every parameter;
- ``checkpoint.npz`` while running (removed when the results are written); see
  :func:`skygas.runs.run_driver.drive` for checkpoints, interruption and ``resume``.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from skygas._version import __version__
from skygas.core.resources import require_memory, step_count
from skygas.core.state_keys import nest, unnest
from skygas.runs.config import SimulationConfig
from skygas.runs.run_driver import (
    PiecewiseRunJob,
    drive,
    run_record,
    steps_to_piece_end,
    write_figure,
    write_json,
    write_netcdf,
)

#: Pieces per run: each returns to Python once (progress, checkpoints, interruption).
PIECES = 100


class SimulationRun:
    """A configured simulation cut into :data:`PIECES` pieces of equal length [steps]; piece
    ``k`` covers steps [k·L, (k+1)·L), whatever run (first or resumed) gets there
    (:func:`~skygas.runs.run_driver.steps_to_piece_end`)."""

    def __init__(self, config: SimulationConfig):
        self.config = config
        self.sim = config.build()  # validates everything before any stepping
        self.total_steps = step_count(config.duration, self.sim.time_step)
        # recorded frames: per skyrmion, x and y (float64) and its id (int64)
        frames = self.total_steps * self.sim.time_step / config.record_interval
        require_memory(
            "record_interval",
            config.record_interval,
            24.0 * (frames + 1) * max(1, self.sim.count),
            "the recorded frames",
            "record less often, or run for a shorter duration",
        )
        self.piece_steps = max(1, self.total_steps // PIECES)
        self.wall_time = 0.0

    def advance_piece(self) -> None:
        sim = self.sim
        n = steps_to_piece_end(sim.step, self.piece_steps, self.total_steps)
        start = time.perf_counter()
        sim.run(n * sim.time_step, record_interval=self.config.record_interval)
        self.wall_time += time.perf_counter() - start

    def state_dict(self) -> dict[str, np.ndarray]:
        state = nest("sim_", self.sim.state_dict())
        state["wall_time"] = np.array(self.wall_time)
        return state

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        self.sim.load_state_dict(unnest("sim_", state))
        self.wall_time = float(state["wall_time"])


class SimulationJob(PiecewiseRunJob):
    """``skygas simulate``: a :class:`SimulationRun` as a job of the run driver (work in ns of
    simulated time)."""

    result_files: tuple[str, ...] = ("trajectories.nc", "summary.json")

    def __init__(self, config: SimulationConfig):
        super().__init__(config, SimulationRun(config))

    @property
    def sim(self):
        """The run's :class:`~skygas.engine.Simulation`."""
        return self.run.sim

    @property
    def wall_time(self) -> float:
        """Wall time spent stepping [s]."""
        return self.run.wall_time

    def summary(self) -> dict:
        sim = self.sim
        return {
            "skygas_version": __version__,
            "seed": self.config.seed,
            "skyrmions_initial": sim.ids_issued,  # `simulate` creates skyrmions only at the start
            "skyrmions_present": sim.count,
            "exits": len(sim.exits),
            "wall_escapes": sim.wall_escapes,
            "simulated_time_s": sim.time,
            "time_step_s": sim.time_step,
            "steps": sim.step,
            "wall_time_s": self.wall_time,
            "pair_evaluations": sim.pair_evaluations,
            "config": json.loads(self.config_json()),
            **({"operations": ops} if (ops := sim.operation_summaries()) else {}),
        }

    def finish(self, out: Path) -> dict:
        """Write the dataset, the figure and the summary (each atomically)."""
        from skygas.runs.plotting import plot_trajectories

        ds = self.sim.trajectories()
        ds.attrs["config_json"] = self.config_json()
        write_netcdf(ds, out / "trajectories.nc")
        write_figure(
            out / "trajectories.png",
            lambda tmp: plot_trajectories(ds, self.sim.outline, tmp, landscape=self.sim.landscape),
            run_record(self),
        )
        summary = self.summary()
        write_json(out / "summary.json", summary)
        return summary


def run_simulation(
    config: SimulationConfig,
    out_dir: str | Path,
    *,
    progress: bool = True,
    resume: bool = False,
    checkpoint_seconds: float = 30.0,
    overwrite: bool = False,
    strict: bool = False,
) -> dict:
    """Build, run and save the simulation described by ``config``; returns the summary."""
    return drive(
        SimulationJob(config),
        out_dir,
        resume=resume,
        progress=progress,
        checkpoint_seconds=checkpoint_seconds,
        overwrite=overwrite,
        strict=strict,
    )
