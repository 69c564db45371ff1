"""A reshuffler run to files: progress, checkpoints, resume, dataset, figures, summary.

:func:`run_reshuffler` (what ``skygas reshuffle`` calls) writes into ``out_dir``:
``reshuffler.nc`` (events, snapshots, analyses; every parameter in its attributes),
``summary.json``, ``device.png``, ``running_correlation.png`` and ``occupancy.png``.
While running it keeps ``checkpoint.npz`` (saved every ``checkpoint_seconds`` and when
interrupted); ``resume=True`` continues from it bit-identically when the configuration is the
same, and the file is removed once the results are written.
"""

from __future__ import annotations

import json
from pathlib import Path

from skygas.reshuffler.analysis import ReshufflerResult, summarize
from skygas.reshuffler.config import ReshufflerConfig
from skygas.reshuffler.figures import (
    plot_device,
    plot_occupancy,
    plot_running_correlation,
)
from skygas.reshuffler.run import CHECKPOINT, ReshufflerRun
from skygas.runner import load_checkpoint, save_checkpoint, write_netcdf


def run_reshuffler(config: ReshufflerConfig, out_dir: str | Path | None = None, *,
                   progress: bool = True, resume: bool = False,
                   checkpoint_seconds: float = 60.0, figures: bool = True) -> ReshufflerResult:
    """Run ``config``; with ``out_dir``, write the dataset, summary, figures (and checkpoints)."""
    run = ReshufflerRun.build(config)  # every check happens here, before any stepping
    out = Path(out_dir) if out_dir is not None else None
    ckpt = None
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        ckpt = out / CHECKPOINT
        if resume and ckpt.exists():
            load_checkpoint(run, config, ckpt)
    bar = None
    if progress:
        from tqdm import tqdm

        total_us = run.total_steps * run.sim.time_step * 1e6
        bar = tqdm(total=round(total_us, 6), unit="µs", desc="simulated", leave=False,
                   initial=round(run.sim.time * 1e6, 6))

    def on_progress(t: float) -> None:
        bar.update(round(t * 1e6, 6) - bar.n)  # tqdm throttles the redraws

    try:
        run.advance(progress=on_progress if bar else None,
                    checkpoint=(lambda r: save_checkpoint(r, config, ckpt)) if ckpt else None,
                    checkpoint_seconds=checkpoint_seconds)
    except KeyboardInterrupt:
        if ckpt is not None:
            save_checkpoint(run, config, ckpt)
        raise
    finally:
        if bar is not None:
            bar.close()
    result = summarize(run)
    if out is not None:
        write_netcdf(result.dataset, out / "reshuffler.nc")
        (out / "summary.json").write_text(json.dumps(result.summary, indent=2))
        if figures:
            plot_device(run, out / "device.png")
            plot_running_correlation(result.dataset, out / "running_correlation.png")
            plot_occupancy(result.dataset, out / "occupancy.png")
        ckpt.unlink(missing_ok=True)
    return result
