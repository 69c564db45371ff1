"""Wall time of ``skygas track`` on the shipped movie, stage by stage.

Prints the seconds to open the movie and choose the settings, to locate the skyrmions in
every frame, to link them, and to write the overlay movie, the figures and the report.

Run: ``.venv/bin/python benchmarks/bench_tracking.py [MOVIE]`` (default
examples/tracking/chamber-movie.tif).
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    from skygas.movies.choices import choose
    from skygas.movies.reading import open_movie
    from skygas.movies.track_run import _summary, _write
    from skygas.movies.tracking import link, locate_all

    path = sys.argv[1] if len(sys.argv) > 1 else ROOT / "examples/tracking/chamber-movie.tif"
    t0 = time.perf_counter()
    movie = open_movie(path)
    choices = choose(movie)
    t1 = time.perf_counter()
    features = locate_all(movie, choices, progress=False)
    t2 = time.perf_counter()
    tracks = link(features, choices)
    t3 = time.perf_counter()
    with tempfile.TemporaryDirectory() as out:
        summary = _summary(movie, choices, tracks, None, None, {}, False)
        _write(Path(out), movie, choices, tracks, summary)
    t4 = time.perf_counter()
    print(
        f"{movie.n_frames} frames of {movie.shape[1]} × {movie.shape[0]} px, "
        f"{len(features)} features"
    )
    print(f"open + choose settings: {t1 - t0:6.2f} s")
    print(
        f"locate:                 {t2 - t1:6.2f} s "
        f"({1e3 * (t2 - t1) / movie.n_frames:.1f} ms/frame)"
    )
    print(f"link:                   {t3 - t2:6.2f} s")
    print(f"write (overlay, report):{t4 - t3:6.2f} s")
    print(f"total:                  {t4 - t0:6.2f} s")


if __name__ == "__main__":
    main()
