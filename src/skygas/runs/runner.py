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
import math
from pathlib import Path
from typing import Any

from skygas.core.errors import InputError
from skygas.core.estimates import check
from skygas.core.resources import require_memory, step_count
from skygas.engine.force_model import whole_steps
from skygas.runs.config import SimulationConfig
from skygas.runs.device_run import DeviceRun
from skygas.runs.machine_speed import optimistic_estimate, run_estimate
from skygas.runs.run_driver import (
    PiecewiseRunJob,
    drive,
    run_record,
    write_figure,
    write_json,
    write_netcdf,
)

#: Pieces per run: each returns to Python once (progress, checkpoints, interruption).
PIECES = 100


def simulation_memory(config: SimulationConfig, skyrmions: int) -> float:
    """Bytes of the frames a simulation records.

    One frame every ``record_interval`` and one at the start; per skyrmion its x and y
    (float64) and its id (int64): 24 bytes.

    Parameters
    ----------
    config : SimulationConfig
        The run.
    skyrmions : int
        Skyrmions placed at the start (none are created later).

    Returns
    -------
    float
        24 × (duration / record_interval + 1) × max(1, skyrmions).
    """
    frames = config.duration / config.record_interval
    return 24.0 * (frames + 1) * max(1, skyrmions)


class SimulationRun(DeviceRun):
    """A configured simulation, cut into :data:`PIECES` pieces of equal length [steps].

    A :class:`~skygas.runs.device_run.DeviceRun` with the configuration's ``[[operations]]``
    attached.
    """

    pieces = PIECES

    def __init__(self, config: SimulationConfig):
        # estimates before anything is built (core.estimates): the steps are at least the
        # recorded frames (the default step divides the record interval), exact below
        lower = step_count(config.duration, config.time_step or config.record_interval)
        skyrmions = len(config.skyrmions.positions) + config.skyrmions.random_count
        memory = simulation_memory(config, skyrmions)
        require_memory(
            "record_interval",
            config.record_interval,
            memory,
            "the recorded frames",
            "record less often, or run for a shorter duration",
        )
        check(
            optimistic_estimate(lower, skyrmions, memory),
            "duration",
            config.duration,
            "the run",
            "use a shorter duration",
            announce=False,
        )
        super().__init__(config, config.build())  # validates everything before any stepping
        dt = self.sim.time_step
        if whole_steps(config.record_interval, dt) is None:  # an explicit time_step
            raise InputError(
                "time_step",
                dt,
                f"a step that divides record_interval ({config.record_interval:g} s) into whole "
                f"steps, e.g. {config.record_interval / math.ceil(config.record_interval / dt):.6g}"
                " s, so that the frames fall on its multiples; or leave time_step out (it is then "
                "chosen so)",
            )
        self.record_interval = config.record_interval
        check(
            run_estimate(self.total_steps, skyrmions, memory),
            "duration",
            config.duration,
            "the run",
            "use a shorter duration",
        )
        self.attach_operations(config.operations)

    @property
    def total_steps(self) -> int:
        """Steps of the configured duration."""
        return step_count(self.config.duration, self.sim.time_step)


class SimulationJob(PiecewiseRunJob):
    """``skygas simulate``.

    A :class:`SimulationRun` as a job of the run driver (work in ns of simulated time).
    """

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
        """Counts, times, the seed, the version, the configuration and the operations' summaries."""
        sim = self.sim
        summary = self.run.base_summary()
        operations = summary.pop("operations", None)
        summary.update(
            {
                "skyrmions_initial": sim.ids_issued,  # skyrmions are created only at the start
                "skyrmions_present": sim.count,
                "exits": len(sim.exits),
                "wall_escapes": sim.wall_escapes,
                "pair_evaluations": sim.pair_evaluations,
                "config": json.loads(self.config_json()),
                **({"operations": operations} if operations else {}),
            }
        )
        return summary

    def finish(self, out: Path) -> dict:
        """Write the dataset, the figure and the summary (each atomically)."""
        from skygas.figures.plotting import plot_trajectories

        ds = self.run.add_operation_data(self.sim.trajectories())
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
    **drive_options: Any,
) -> dict:
    """Build, run and save the simulation described by ``config``; returns the summary.

    ``drive_options`` are those of :func:`~skygas.runs.run_driver.drive` (``resume``,
    ``progress``, ``checkpoint_seconds``, ``overwrite``, ``strict``, ``then``).
    """
    return drive(SimulationJob(config), out_dir, **drive_options)
