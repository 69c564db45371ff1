"""`skygas calibrate`: from a film's micromagnetic parameters to a particle model.

:func:`calibrate` runs magnum.np (:mod:`skygas.calibration.solver`) for the material's isolated
skyrmion, its pair and edge interactions and a many-skyrmion validation run, and writes the
particle model (``model.toml``), every number (``summary.json``) and a report. See
``docs/calibration.md``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from skygas.runs.checkpoint_interval import CHECKPOINT_SECONDS

__all__ = ["calibrate", "CalibrationConfig", "MicromagneticMaterial", "load_micromagnetic_material"]

#: Most solver processes a calibration starts (each holds torch and its films' solvers).
MAX_WORKERS = 256


def __getattr__(name: str):
    if name in ("CalibrationConfig", "ValidationSpec"):
        from skygas.calibration import plan

        return getattr(plan, name)
    if name in ("MicromagneticMaterial", "load_micromagnetic_material"):
        from skygas.calibration import material

        return getattr(material, name)
    raise AttributeError(name)


def calibrate(
    material,
    out: str | Path,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    overwrite: bool = False,
    progress: bool = True,
    strict: bool = False,
    checkpoint_seconds: float = CHECKPOINT_SECONDS,
    **settings: Any,
) -> dict[str, Any]:
    """Calibrate ``material`` into the folder ``out``: its particle model, numbers and report.

    Interrupted (Ctrl-C), it resumes with ``resume=True``.

    Parameters
    ----------
    material : str, Path, dict or MicromagneticMaterial
        A preset name, a TOML file, a mapping or a
        :class:`~skygas.calibration.material.MicromagneticMaterial`.
    out : str or Path
        The output folder.
    workers : int, optional
        Solver processes of a local Dask cluster, ≥ 0 (default: 2 on a CPU, 0 on a GPU; 0
        solves in this process). Not with ``scheduler``.
    scheduler : str, optional
        The address of a running Dask scheduler (``tcp://HOST:8786``) whose workers solve
        instead of a local cluster's; refused in one line if it does not answer within
        :data:`skygas.runs.cluster.CONNECT_TIMEOUT` seconds.
    resume : bool
        Continue an interrupted calibration from its checkpoint in ``out``.
    overwrite : bool
        Replace the finished results in ``out`` (or the interrupted run, without ``resume``)
        instead of refusing them.
    progress : bool
        Show a progress bar.
    strict : bool
        The sanity checks (:mod:`skygas.runs.sanity`) refuse the run instead of warning.
    checkpoint_seconds : float
        Wall time [s] between periodic checkpoints (0: after every piece).
    **settings
        Fields of :class:`~skygas.calibration.plan.CalibrationConfig` (``reference_diameter``,
        ``validate_dynamics``, ``mesh_check``, ``validation={...}``, ...).

    Returns
    -------
    dict
        The contents of ``out/summary.json``.

    Raises
    ------
    InputError
        If the material, a setting or ``workers`` is invalid, ``scheduler`` does not answer
        (or comes with ``workers``), or the micromagnetic solver is not installed.
    """
    from pydantic import ValidationError

    from skygas.calibration.estimate import check_calibration
    from skygas.calibration.material import load_micromagnetic_material, split_error
    from skygas.calibration.pipeline import CalibrationJob
    from skygas.calibration.plan import CalibrationConfig
    from skygas.calibration.solver import cpu_workers, default_workers, require_installed
    from skygas.core.errors import require
    from skygas.runs.run_driver import drive

    try:
        config = CalibrationConfig(material=load_micromagnetic_material(material), **settings)
    except ValidationError as err:
        raise split_error(err) from None
    require(
        workers is None or (isinstance(workers, int) and 0 <= workers <= MAX_WORKERS),
        "--workers",
        workers,
        f"an integer from 0 to {MAX_WORKERS} (0: solve in this process, as on a GPU)",
    )
    if scheduler is not None:
        require(
            isinstance(scheduler, str) and bool(scheduler.strip()),
            "--scheduler",
            scheduler,
            "the address of a running Dask scheduler (tcp://HOST:8786)",
        )
        require(
            workers is None,
            "--workers",
            workers,
            "no --workers with --scheduler (the scheduler's workers solve)",
            f"drop --workers, or drop --scheduler to solve on a local cluster of {workers} "
            "processes",
        )
    require_installed()
    if scheduler is None:
        # memory and time, before any solver starts (and before torch is imported to find a
        # GPU: the CPU's processes, more than the one that drives a GPU)
        check_calibration(config, cpu_workers() if workers is None else workers)
        job = CalibrationJob(config, workers=default_workers() if workers is None else workers)
    else:
        job = CalibrationJob(config, scheduler=scheduler)
    try:
        if scheduler is not None:
            # the scheduler answers (or is refused in one line) before anything is written,
            # and its workers' threads are the calibration's processes
            job.workers = job.connect().capacity()
            check_calibration(config, job.workers, remote=True)
        return drive(
            job,
            out,
            resume=resume,
            overwrite=overwrite,
            progress=progress,
            checkpoint_seconds=checkpoint_seconds,
            strict=strict,
        )
    finally:
        job.close()
