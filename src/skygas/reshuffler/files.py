"""A reshuffler run to files, through the run driver (:mod:`skygas.run_driver`).

:func:`run_reshuffler` (what ``skygas reshuffle`` calls) writes into ``out_dir``:
``reshuffler.nc`` (events, snapshots, analyses; every parameter, the seed and the version in
its attributes), ``summary.json``, ``device.png``, ``running_correlation.png`` and
``occupancy.png``. While running it keeps ``checkpoint.npz``; see
:func:`skygas.run_driver.drive` for checkpoints, interruption and ``resume``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from skygas.reshuffler.analysis import ReshufflerResult, summarize
from skygas.reshuffler.config import ReshufflerConfig
from skygas.reshuffler.run import ReshufflerRun
from skygas.run_driver import drive, write_atomic, write_json, write_netcdf


class ReshufflerJob:
    """A :class:`~skygas.reshuffler.run.ReshufflerRun` as a job of the run driver (work in
    µs of simulated time)."""

    work_unit = "µs"

    def __init__(self, config: ReshufflerConfig, figures: bool = True):
        self.config = config
        self.figures = figures
        self.run = ReshufflerRun.build(config)  # every check happens here, before any stepping
        self.work_total = self._us(self.run.total_steps)

    def _us(self, steps: int) -> float:
        return steps * self.run.sim.time_step * 1e6

    def work_done(self) -> float:
        return self._us(self.run.sim.step)

    def advance_piece(self) -> None:
        self.run.advance_piece()

    def state_dict(self) -> dict[str, np.ndarray]:
        return self.run.state_dict()

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        self.run.load_state_dict(state)

    def config_json(self) -> str:
        return self.config.model_dump_json()

    def seed(self) -> int:
        return self.config.seed

    def finish(self, out: Path | None) -> ReshufflerResult:
        result = summarize(self.run)
        if out is None:
            return result
        from skygas.reshuffler.figures import (
            plot_device,
            plot_occupancy,
            plot_running_correlation,
        )

        write_netcdf(result.dataset, out / "reshuffler.nc")
        write_json(out / "summary.json", result.summary)
        if self.figures:
            write_atomic(out / "device.png", lambda tmp: plot_device(self.run, tmp))
            write_atomic(out / "running_correlation.png",
                         lambda tmp: plot_running_correlation(result.dataset, tmp))
            write_atomic(out / "occupancy.png", lambda tmp: plot_occupancy(result.dataset, tmp))
        return result


def run_reshuffler(config: ReshufflerConfig, out_dir: str | Path | None = None, *,
                   progress: bool = True, resume: bool = False,
                   checkpoint_seconds: float = 60.0, figures: bool = True) -> ReshufflerResult:
    """Run ``config``; with ``out_dir``, write the dataset, summary, figures (and checkpoints).
    Without ``out_dir`` the run is only analysed (nothing is written, nothing to resume)."""
    job = ReshufflerJob(config, figures)
    if out_dir is None:
        job.run.advance()
        return job.finish(None)
    return drive(job, out_dir, resume=resume, progress=progress,
                 checkpoint_seconds=checkpoint_seconds)
