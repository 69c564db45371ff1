"""Cost of the movie and the report of a 100 µs reshuffler run, on one core.

Runs the default reshuffler (``skygas reshuffle --animate``: snapshots every 4 ns) for
``--duration`` of simulated time (not timed), then times what ``--animate`` adds after the
results are written: the movie (first 1 200 frames, MP4) and the self-contained HTML report,
with this process and ffmpeg pinned to one core. Prints both wall times, their sum and the
CPU time they took (on a shared machine the wall time also counts other programs' turns on
the core), the movie's size and the report's size. Budget: at most 30 s together, and a
movie of at most 20 MB.

Run: ``.venv/bin/python benchmarks/bench_outputs.py [--duration 1e-4] [--out DIR] [--cpu 0]``.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--duration", type=float, default=1e-4, help="simulated time [s]")
    parser.add_argument("--out", default=None, help="run directory (default: a temporary one)")
    parser.add_argument("--cpu", type=int, default=0, help="the one core to run on")
    args = parser.parse_args()
    os.sched_setaffinity(0, {args.cpu})  # ffmpeg, started later, inherits it

    from skygas.outputs.finish import finish_outputs, recording_overrides
    from skygas.reshuffler.config import load_reshuffler_config
    from skygas.reshuffler.files import run_reshuffler

    out = Path(args.out or tempfile.mkdtemp(prefix="bench-outputs-"))
    overrides = {"duration": args.duration, **recording_overrides(True)}
    config = load_reshuffler_config(overrides=overrides)
    start = time.perf_counter()
    if not (out / "reshuffler.nc").exists():
        run_reshuffler(config, out, progress=False)
    print(
        f"reshuffler run: {args.duration * 1e6:g} µs simulated in "
        f"{time.perf_counter() - start:.1f} s (not part of the budget), results in {out}"
    )
    start, cpu = time.perf_counter(), _cpu_seconds()
    done = finish_outputs(out, animate=True, report=True)
    total, cpu = time.perf_counter() - start, _cpu_seconds() - cpu
    movie, report = done["movie"], done["report"]
    print(
        f"movie:  {movie['seconds']:6.1f} s  {movie['frames']} frames "
        f"({movie['width_px']}×{movie['height_px']}), {movie['bytes'] / 1e6:.2f} MB"
    )
    print(f"report: {report['seconds']:6.1f} s  {Path(report['path']).stat().st_size / 1e6:.2f} MB")
    print(
        f"total:  {total:6.1f} s wall on one core, {cpu:.1f} s CPU (this process and "
        f"ffmpeg; budget 30 s); movie {movie['bytes'] / 1e6:.2f} MB (budget 20 MB)"
    )


def _cpu_seconds() -> float:
    """CPU time of this process and its finished children (ffmpeg) [s]: unlike the wall
    time it does not grow when other programs share the core."""
    import resource

    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


if __name__ == "__main__":
    main()
