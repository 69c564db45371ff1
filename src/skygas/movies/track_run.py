"""``skygas track``: a movie in, its skyrmions' tracks out, with every choice recorded.

Writes into the output folder:

- ``tracks.csv``: trackpy's table (``frame, particle, x, y`` in pixels, then ``mass, size,
  ecc, signal, raw_mass, ep``), plain CSV that ``pandas.read_csv`` and ``skygas infer`` read;
- ``track.json``: the choices (contrast sign, feature diameter, mass threshold, search range,
  memory, drift) with the statistics they came from, the counts (features, tracks, per frame,
  track lengths in frames: a track's length runs from its first frame to its last, gaps
  included), the pixel size and frame interval with their source, and the provenance (skygas
  version, command line, SHA-256 of the input);
- ``overlay.mp4``: the movie with the located skyrmions circled and their tails, the frame's
  number and a scale bar below the picture;
- ``detections.png`` (the first frame and its detections), ``track_lengths.png`` (histogram)
  and ``report.html``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from skygas.core.errors import InputError


@dataclass
class TrackResult:
    """What :func:`track_movie` found: the ``summary`` (track.json) and the ``tracks``."""

    summary: dict
    tracks: object


#: the shortest search range [px]: a skyrmion's position is known to ~0.1 px (0.08 px RMS
#: measured, docs/tracking.md), so a shorter range cannot link even a skyrmion at rest; a
#: number this small is a length in metres given where pixels are meant
MIN_SEARCH_RANGE = 0.1


def check_scale(field: str, value: float | None, unit: str) -> None:
    """Refuse a pixel size or frame interval that is not a finite number > 0."""
    if value is not None and not (math.isfinite(value) and value > 0):
        raise InputError(field, value, f"a number > 0 in {unit}", f"e.g. {field} 14e-9")


def check_length(field: str, value: float | None) -> None:
    """Refuse a length [m] that is not > 0, or outside 1 pm … 1 m as every device length is."""
    from skygas.core.config_types import require_length

    check_scale(field, value, "metres")
    if value is not None:
        require_length(field, value)


def _check_options(pixel_size, frame_interval, diameter, minmass, search_range, memory) -> None:
    """Refuse the options given (before the movie is opened)."""
    check_length("--pixel-size", pixel_size)
    check_scale("--frame-interval", frame_interval, "seconds")
    if diameter is not None and (diameter < 3 or diameter % 2 == 0):
        raise InputError("--diameter", diameter, "an odd number of pixels >= 3")
    if minmass is not None and not (math.isfinite(minmass) and minmass >= 0):
        raise InputError("--minmass", minmass, "a mass >= 0")
    if search_range is not None and not (
        math.isfinite(search_range) and search_range >= MIN_SEARCH_RANGE
    ):
        raise InputError(
            "--search-range",
            search_range,
            f"a distance of at least {MIN_SEARCH_RANGE:g} px (a skyrmion's position is known "
            "to about 0.1 px)",
            "the search range is in pixels, not metres: e.g. --search-range 3",
        )
    if memory is not None and memory < 0:
        raise InputError("--memory", memory, "a number of frames >= 0")


def _check_search_range(movie, search_range: float | None) -> None:
    """Refuse a search range beyond the frame's diagonal: every skyrmion would be a candidate."""
    diagonal = math.hypot(*movie.shape)
    if search_range is not None and search_range > diagonal:
        raise InputError(
            "--search-range",
            search_range,
            f"a distance within the frame, at most its diagonal of {diagonal:.4g} px",
            "the search range is in pixels: the farthest a skyrmion moves between two frames",
        )


def track_movie(
    movie_path: str | Path,
    out: str | Path,
    *,
    pixel_size: float | None = None,
    frame_interval: float | None = None,
    contrast: str = "auto",
    diameter: int | None = None,
    minmass: float | None = None,
    search_range: float | None = None,
    memory: int | None = None,
    drift: bool = False,
    progress: bool = True,
) -> TrackResult:
    """Locate and link the skyrmions of the movie at ``movie_path``; write the files into ``out``.

    Parameters
    ----------
    movie_path : str or Path
        A TIFF stack or a folder of images (:func:`skygas.movies.reading.open_movie`).
    out : str or Path
        The output folder (created).
    pixel_size : float, optional
        Metres per pixel (default: the movie's own, if it records one).
    frame_interval : float, optional
        Seconds between frames (default: the movie's own, if it records one).
    contrast : {"auto", "dark", "bright"}
        The skyrmions' contrast.
    diameter, minmass, search_range, memory : optional
        trackpy's settings; each chosen from the data when not given
        (:func:`skygas.movies.choices.choose`).
    drift : bool
        Subtract the drift of the whole picture (``trackpy.compute_drift``).
    progress : bool
        Show progress bars (on a terminal).

    Returns
    -------
    TrackResult
        The summary written to track.json and the tracks.

    Raises
    ------
    InputError
        Before any tracking: an option out of range, a movie refused when opened or when its
        frames are read (:mod:`skygas.movies.reading`), too large for memory or, unless
        forced, for a day (:mod:`skygas.movies.estimate`).
    WriteFailed
        A file could not be written (a full disk); no file is left half-written.
    """
    from skygas.movies.choices import choose
    from skygas.movies.estimate import check_features, check_size
    from skygas.movies.reading import check_frames, open_movie
    from skygas.movies.tracking import link, locate_all

    _check_options(pixel_size, frame_interval, diameter, minmass, search_range, memory)
    movie = open_movie(movie_path, diameter)
    _check_search_range(movie, search_range)
    seconds = check_size(movie)
    check_frames(movie, progress=progress)
    sources = dict(movie.sources)
    if pixel_size is not None:
        sources["pixel_size"] = "given"
    if frame_interval is not None:
        sources["frame_interval"] = "given"
    pixel_size = pixel_size if pixel_size is not None else movie.pixel_size
    frame_interval = frame_interval if frame_interval is not None else movie.frame_interval
    choices = choose(
        movie,
        contrast=contrast,
        diameter=diameter,
        minmass=minmass,
        search_range=search_range,
        memory=memory,
    )
    check_features(movie, choices.most_per_sample_frame, seconds)
    features = locate_all(movie, choices, progress=progress)
    tracks = link(features, choices, drift=drift)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    summary = _summary(movie, choices, tracks, pixel_size, frame_interval, sources, drift)
    _write(out, movie, choices, tracks, summary)
    return TrackResult(summary, tracks)


def _summary(movie, choices, tracks, pixel_size, frame_interval, sources, drift) -> dict:
    from skygas.runs.provenance import provenance

    per_frame = tracks.per_frame(movie.n_frames)
    lengths = tracks.lengths
    record = provenance(seed=None, source=str(movie.path))
    record["input_sha256"] = movie.file_hash()
    return {
        "movie": str(movie.path),
        "frames": movie.n_frames,
        "frame_shape_px": list(movie.shape),
        "dtype": str(movie.dtype),
        "pixel_size_m": pixel_size,
        "frame_interval_s": frame_interval,
        "scale_sources": {
            "pixel_size": sources.get("pixel_size", "not known"),
            "frame_interval": sources.get("frame_interval", "not known"),
        },
        "choices": {**choices.as_dict(), "drift_subtraction": drift},
        "counts": {
            "features": int(len(tracks.table)),
            "tracks": int(len(lengths)),
            "per_frame_mean": float(per_frame.mean()),
            "per_frame_min": int(per_frame.min()),
            "per_frame_max": int(per_frame.max()),
            "track_length_mean_frames": float(np.mean(lengths)) if len(lengths) else 0.0,
            "track_length_median_frames": float(np.median(lengths)) if len(lengths) else 0.0,
            "track_length_max_frames": int(lengths.max()) if len(lengths) else 0,
            "tracks_spanning_whole_movie": int(np.sum(lengths == movie.n_frames)),
        },
        "drift_px": None
        if tracks.drift is None
        else {
            "largest": float(np.abs(tracks.drift).max()),
            "final": [float(v) for v in tracks.drift[-1]],
        },
        "warnings": choices.warnings,
        "provenance": record,
    }


def _write(out: Path, movie, choices, tracks, summary: dict) -> None:
    """Write the results, each under a temporary name renamed when complete, track.json last.

    A failed write (a full disk) leaves the files finished before it, none half-written, and
    no track.json: the folder says it is incomplete.
    """
    from skygas.core.errors import WriteFailed
    from skygas.movies.overlay import write_overlay
    from skygas.movies.report import track_report, write_figures
    from skygas.runs.run_driver import write_atomic, write_json

    try:
        write_atomic(out / "tracks.csv", lambda tmp: tracks.table.to_csv(tmp, index=False))
        summary["overlay"] = write_overlay(
            out / "overlay.mp4",
            movie,
            tracks,
            choices.diameter,
            pixel_size=summary["pixel_size_m"],
            frame_interval=summary["frame_interval_s"],
        )
        write_figures(out, movie, tracks, choices, summary)
        text = track_report(out, summary)
        write_atomic(out / "report.html", lambda tmp: tmp.write_text(text, encoding="utf-8"))
        write_json(out / "track.json", summary)
    except WriteFailed as err:
        raise err.with_hint(
            "no file is left half-written; make room (or choose another --out) and track again"
        ) from None
