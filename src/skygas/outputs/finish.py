"""What every run command does once its results are written: the movie and the report.

The movie when asked, into the run's output directory, like the report.

:func:`finish_outputs` is that one call. :func:`recording_overrides` gives the configuration
overrides that make a run record frames often enough for a smooth movie
(:data:`~skygas.outputs.movie.MOVIE_FRAME_INTERVAL`).
"""

from __future__ import annotations

import json
import time
from pathlib import Path

from skygas.outputs.movie import MOVIE_FRAME_INTERVAL

#: frames of the movie a run command writes: the first ones, every one of them (smooth); use
#: ``skygas animate --stride`` or ``--window`` for another part of a long run
RUN_MOVIE_FRAMES = 1200


def recording_overrides(animate: bool) -> dict:
    """Reshuffler configuration overrides for ``--animate``.

    Snapshots every :data:`MOVIE_FRAME_INTERVAL` instead of the default 100 ns.
    """
    return {"output.snapshot_interval": MOVIE_FRAME_INTERVAL} if animate else {}


def movie_record_interval(animate: bool) -> float | None:
    """The record interval [s] of an engine run for ``--animate`` (None: record nothing)."""
    return MOVIE_FRAME_INTERVAL if animate else None


def finish_outputs(out_dir: str | Path, *, animate: bool = False, report: bool = True) -> dict:
    """Write ``movie.mp4`` (with ``animate``) and ``report.html`` (with ``report``).

    Into ``out_dir``, from the result file already there (a neuron run recorded for a movie writes
    its positions as ``frames.nc`` when it finishes). Returns what was written and how long each
    took [s].
    """
    out = Path(out_dir)
    done: dict = {}
    if not (animate or report):
        return done
    from skygas.outputs.records import RESULT_FILES, load_run

    if animate and any((out / name).exists() for name in RESULT_FILES):
        from skygas.outputs.movie import render_movie

        start = time.perf_counter()
        record = load_run(out)
        frames = record.frames
        if frames.n_frames:
            end = frames.time[min(RUN_MOVIE_FRAMES, frames.n_frames) - 1]
            info = render_movie(record, out / "movie.mp4", stride=1, end=end)
            done["movie"] = info.as_dict() | {"seconds": time.perf_counter() - start}
    if report:
        from skygas.outputs.report import write_report

        start = time.perf_counter()
        done["report"] = {
            "path": str(write_report(out, out / "report.html")),
            "seconds": time.perf_counter() - start,
        }
    (out / "outputs.json").write_text(json.dumps(done, indent=2))
    return done
