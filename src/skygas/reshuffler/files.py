"""A reshuffler run to files, through the run driver (:mod:`skygas.runs.run_driver`).

:func:`run_reshuffler` (what ``skygas reshuffle`` calls) writes into ``out_dir``:
``reshuffler.nc`` (events, snapshots, analyses; every parameter, the seed and the version in
its attributes), ``summary.json``, ``device.png``, ``running_correlation.png`` and
``occupancy.png``. While running it keeps ``checkpoint.npz``; see
:func:`skygas.runs.run_driver.drive` for checkpoints, interruption and ``resume``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from skygas.reshuffler.analysis import ReshufflerResult, summarize
from skygas.reshuffler.config import ReshufflerConfig
from skygas.reshuffler.run import ReshufflerRun
from skygas.runs.run_driver import (
    PiecewiseRunJob,
    drive,
    run_record,
    write_figure,
    write_json,
    write_netcdf,
)


class ReshufflerJob(PiecewiseRunJob):
    """A :class:`~skygas.reshuffler.run.ReshufflerRun` as a job of the run driver.

    Its work is counted in µs of simulated time.
    """

    work_unit = "µs"
    time_scale = 1e6
    result_files: tuple[str, ...] = ("reshuffler.nc", "summary.json")

    def __init__(self, config: ReshufflerConfig, figures: bool = True):
        # every check happens in build, before any stepping
        super().__init__(config, ReshufflerRun.build(config))
        self.figures = figures

    def finish(self, out: Path | None) -> ReshufflerResult:
        """Analyse the run and write its dataset, summary and figures into ``out``.

        With ``out=None`` the run is only analysed.
        """
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
            record = run_record(self)
            write_figure(out / "device.png", lambda tmp: plot_device(self.run, tmp), record)
            write_figure(
                out / "running_correlation.png",
                lambda tmp: plot_running_correlation(result.dataset, tmp),
                record,
            )
            write_figure(
                out / "occupancy.png", lambda tmp: plot_occupancy(result.dataset, tmp), record
            )
        return result


def run_reshuffler(
    config: ReshufflerConfig,
    out_dir: str | Path | None = None,
    *,
    figures: bool = True,
    **drive_options: Any,
) -> ReshufflerResult:
    """Run ``config``; with ``out_dir``, write the dataset, summary, figures (and checkpoints).

    Without ``out_dir`` the run is only analysed (nothing is written, nothing to resume).
    ``drive_options`` are those of :func:`~skygas.runs.run_driver.drive`.
    """
    job = ReshufflerJob(config, figures)
    if out_dir is None:
        job.run.advance()
        return job.finish(None)
    return drive(job, out_dir, **drive_options)
