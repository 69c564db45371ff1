"""What tracking a movie will cost, judged from its size before its frames are searched.

Frames are read one at a time, so a movie's memory is not its size on disk:

- while the choices are made, the ten sample frames are held with three filtered copies each
  and their power spectra (:mod:`skygas.movies.choices`): :data:`FRAME_BYTES_PER_PIXEL` per
  pixel of one frame, checked as soon as the movie is opened;
- the located skyrmions are kept (trackpy's table, its linking, the sorted copy):
  :data:`FEATURE_BYTES` each, checked once the sample frames have shown how many a frame holds.

Time is trackpy's search of every pixel of every frame (its ``locate``, python engine), with the
linking and the overlay: :data:`SECONDS_PER_PIXEL` per pixel of a frame, for the movie's frames
and the :data:`CHOICE_FRAMES` frames searched to make the choices. Memory beyond the
machine's (:func:`~skygas.core.resources.memory_limit`) is refused, always; a time beyond
:data:`~skygas.core.estimates.MAX_SECONDS` unless forced (``--force``,
:func:`~skygas.core.estimates.run_limits`).
"""

from __future__ import annotations

import sys

from skygas.core.errors import InputError
from skygas.core.estimates import (
    ANNOUNCE_SECONDS,
    MAX_SECONDS,
    current_limits,
    format_duration,
)
from skygas.core.resources import format_bytes, require_memory

#: wall time [s] of the whole command per pixel of a frame. Measured with trackpy 0.7 on a
#: 2-core machine: 3.6 µs on 40 frames of 516 × 480 px (1 200 skyrmions a frame), 6.5 µs on the
#: shipped 400 frames of 86 × 80 px (where the overlay, scaled up 4×, weighs more); a frame
#: of pure noise, all local maxima, takes trackpy up to 7 µs a pixel. A rough figure: the
#: estimate says whether a movie takes minutes or days
SECONDS_PER_PIXEL = 4e-6
#: frames searched to make the choices: ten samples, the frame after each, four noise frames
CHOICE_FRAMES = 24
#: memory [bytes] per pixel of one frame while the choices are made: measured 749 (ten
#: float64 samples, three filtered copies of each, their power spectra, trackpy's work)
FRAME_BYTES_PER_PIXEL = 800
#: memory [bytes] per located skyrmion: 72 in trackpy's table, 141 at the peak of its linking
#: (measured), and the copies made when the frames' tables are joined and sorted
FEATURE_BYTES = 500


def _pixels(movie) -> int:
    return int(movie.shape[0]) * int(movie.shape[1])


def _what(movie) -> str:
    return f"{movie.n_frames} frames of {movie.shape[1]} × {movie.shape[0]} px"


def check_size(movie) -> float:
    """Refuse a movie whose frames do not fit in memory or that takes too long; its seconds.

    Called once the movie is opened, before any frame beyond the first is read.

    Raises
    ------
    InputError
        A frame too large for memory (always), or an expected time over
        :data:`~skygas.core.estimates.MAX_SECONDS` when not forced.
    """
    pixels = _pixels(movie)
    require_memory(
        "MOVIE",
        str(movie.path),
        FRAME_BYTES_PER_PIXEL * pixels,
        f"the sample frames of {movie.shape[1]} × {movie.shape[0]} px",
        "crop the frames to the region of interest",
    )
    seconds = SECONDS_PER_PIXEL * pixels * (movie.n_frames + CHOICE_FRAMES)
    if not (seconds <= MAX_SECONDS) and not current_limits().force:
        raise InputError(
            "MOVIE",
            str(movie.path),
            f"a movie tracked in at most {format_duration(MAX_SECONDS)} on this machine "
            f"(this one, {_what(movie)}, takes about {format_duration(seconds)})",
            "track a part of it (crop the frames, or split the movie), or give --force to "
            "track it all the same",
        )
    return seconds


def check_features(movie, per_frame: float, seconds: float) -> None:
    """Refuse a movie whose skyrmions' tables do not fit in memory; announce a long tracking.

    ``per_frame``: the most skyrmions found in a sample frame; ``seconds``: from
    :func:`check_size`. The announcement (one line on stderr, under :func:`run_limits` with
    ``announce``) comes when the tracking is about to start.
    """
    features = per_frame * movie.n_frames
    memory = FRAME_BYTES_PER_PIXEL * _pixels(movie) + FEATURE_BYTES * features
    require_memory(
        "MOVIE",
        str(movie.path),
        memory,
        f"the tables of about {features:.3g} skyrmions ({per_frame:.0f} a frame)",
        "track a part of the movie (split it into shorter movies)",
    )
    if current_limits().announce and seconds >= ANNOUNCE_SECONDS:
        print(
            f"skygas: estimate: {_what(movie)}, about {format_duration(seconds)} on this "
            f"machine, {format_bytes(memory)}",
            file=sys.stderr,
            flush=True,
        )
