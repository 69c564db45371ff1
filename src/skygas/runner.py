"""Running a configured simulation to files: progress, checkpoints, resume, results.

:func:`run_simulation` is what ``skygas simulate`` calls. It writes into ``out_dir``:

- ``trajectories.nc``: the :meth:`~skygas.engine.Simulation.trajectories` Dataset (netCDF4);
- ``trajectories.png``: the outline with the trajectories;
- ``summary.json``: counts, timings and every parameter;
- ``checkpoint.npz`` while running (removed when the run completes): the engine state saved
  every ``checkpoint_seconds`` of wall time and on interruption. ``resume=True`` continues from
  it bit-identically (the noise depends only on seed, skyrmion id and step), provided the
  configuration is unchanged (checked by a fingerprint).
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from pathlib import Path

import numpy as np

from skygas._version import __version__
from skygas.config import SimulationConfig
from skygas.errors import InputError
from skygas.plotting import plot_trajectories

CHECKPOINT = "checkpoint.npz"


def config_fingerprint(config) -> str:
    """A hash of a validated (pydantic) configuration: a checkpoint only resumes the same run."""
    return hashlib.sha256(config.model_dump_json().encode()).hexdigest()[:16]


def save_checkpoint(state_owner, config, path: Path) -> None:
    """Save ``state_owner.state_dict()`` with the fingerprint of ``config``, atomically: a crash
    or an interruption while saving never leaves a half-written checkpoint."""
    tmp = path.with_suffix(".tmp.npz")
    np.savez(tmp, fingerprint=np.array(config_fingerprint(config)), **state_owner.state_dict())
    os.replace(tmp, path)


def load_checkpoint(state_owner, config, path: Path) -> None:
    """Restore a checkpoint written by :func:`save_checkpoint` for the same configuration."""
    with np.load(path, allow_pickle=False) as data:
        if str(data["fingerprint"]) != config_fingerprint(config):
            raise InputError("--resume", str(path),
                             "a checkpoint written by the same configuration")
        state_owner.load_state_dict({k: data[k] for k in data.files if k != "fingerprint"})


def write_netcdf(ds, path: Path) -> None:
    """Write ``ds`` to ``path`` through a temporary file, so a finished file is never partial."""
    tmp = path.with_suffix(".tmp.nc")
    ds.to_netcdf(tmp)
    os.replace(tmp, path)


def run_simulation(config: SimulationConfig, out_dir: str | Path, *, progress: bool = True,
                   resume: bool = False, checkpoint_seconds: float = 30.0) -> dict:
    """Build, run and save the simulation described by ``config``; returns the summary."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    sim = config.build()  # validates everything before any stepping
    ckpt = out / CHECKPOINT
    if resume and ckpt.exists():
        load_checkpoint(sim, config, ckpt)
    n_total = int(round(config.duration / sim.time_step))
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=round(config.duration * 1e9, 3), unit="ns", desc="simulated",
                   initial=round(sim.time * 1e9, 3))
    start = time.perf_counter()
    last_save = start
    # Pieces of about 1 % of the run keep the bar moving and bound the work lost on a crash.
    piece = max(1, n_total // 100)
    try:
        while sim.step < n_total:
            n = min(piece, n_total - sim.step)
            sim.run(n * sim.time_step, record_interval=config.record_interval)
            if bar is not None:
                bar.update(round(n * sim.time_step * 1e9, 3))
            if time.perf_counter() - last_save > checkpoint_seconds:
                save_checkpoint(sim, config, ckpt)
                last_save = time.perf_counter()
    except KeyboardInterrupt:
        save_checkpoint(sim, config, ckpt)
        raise
    finally:
        if bar is not None:
            bar.close()
    wall = time.perf_counter() - start
    ds = sim.trajectories()
    ds.attrs["config_json"] = config.model_dump_json()
    write_netcdf(ds, out / "trajectories.nc")
    plot_trajectories(ds, sim.outline, out / "trajectories.png", landscape=sim.landscape)
    summary = {
        "skygas_version": __version__,
        "seed": config.seed,
        "skyrmions_initial": sim.ids_issued,  # `simulate` creates skyrmions only at the start
        "skyrmions_present": sim.count,
        "exits": len(sim.exits),
        "wall_escapes": sim.wall_escapes,
        "simulated_time_s": sim.time,
        "time_step_s": sim.time_step,
        "steps": sim.step,
        "wall_time_s": wall,
        "pair_evaluations": sim.pair_evaluations,
        "config": json.loads(config.model_dump_json()),
    }
    (out / "summary.json").write_text(json.dumps(summary, indent=2))
    ckpt.unlink(missing_ok=True)
    return summary
