"""Locate skyrmions in every frame and link them into tracks, with trackpy.

The features of each frame come from ``trackpy.locate`` (the frame made spots-bright with the
film at 0, :func:`~skygas.movies.choices.spots_bright`; the settings of
:mod:`skygas.movies.choices`), one frame after the other with a progress bar; the tracks from
``trackpy.link`` (its search range and memory). Optionally the drift of the whole picture (a
microscope's stage) is removed: ``trackpy.compute_drift`` averages the frame-to-frame
displacement of all tracked skyrmions and ``trackpy.subtract_drift`` takes its running sum off
the positions. This is off by default: in a closed device the skyrmions' mean position moves
for real (its ensemble-averaged step is a random walk of size σ_step/√N per frame, bounded by
the walls), and subtracting it would add that walk to every track.

The result is trackpy's own table: one row per located skyrmion with ``frame``, ``particle``,
``x``, ``y`` (pixels: column and row of the frame, pixel centres at integers) and trackpy's
``mass``, ``size``, ``ecc``, ``signal``, ``raw_mass``, ``ep``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

#: the columns of tracks.csv, in order (trackpy's, frame and particle first)
COLUMNS = ("frame", "particle", "x", "y", "mass", "size", "ecc", "signal", "raw_mass", "ep")


@dataclass
class Tracks:
    """Linked tracks (``table``: trackpy's DataFrame, :data:`COLUMNS`) and the drift removed.

    ``drift`` (frames, 2) [px] or None when no drift was removed.
    """

    table: Any
    drift: np.ndarray | None = None

    @property
    def lengths(self) -> np.ndarray:
        """The number of frames each track spans (first to last, gaps included)."""
        t = self.table
        if not len(t):
            return np.zeros(0, int)
        g = t.groupby("particle")["frame"]
        return (g.max() - g.min() + 1).to_numpy()

    def per_frame(self, n_frames: int) -> np.ndarray:
        """Skyrmions located in each frame (n_frames,)."""
        frames = self.table["frame"].to_numpy().astype(int)
        return np.bincount(frames, minlength=n_frames)


#: what trackpy warns, once per frame, when it finds no candidate in a frame (a frame without
#: skyrmions, or all of them in its margins): a frame of a movie may well be empty, and the
#: skyrmions found in each frame are counted in track.json, so these say nothing new
_EMPTY_FRAME_WARNINGS = (
    "Image is completely black|Image contains no local maxima|"
    "All local maxima were in the margins|No maxima survived mass- and size-based filtering"
)


def locate_frame(image: np.ndarray, **options):
    """``trackpy.locate`` on one frame (python engine), without its warnings for an empty frame.

    ``options``: ``diameter``, ``minmass``, ``separation``, ``threshold``
    (:meth:`~skygas.movies.choices.Choices.locate_options`).
    """
    import warnings

    import trackpy

    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", _EMPTY_FRAME_WARNINGS, UserWarning)
        return trackpy.locate(image, engine="python", preprocess=True, **options)


def locate_all(movie, choices, progress: bool = True):
    """Trackpy's features of every frame of ``movie`` (a DataFrame with ``frame``).

    Parameters
    ----------
    movie : Movie
        The opened movie.
    choices : Choices
        The settings (:func:`skygas.movies.choices.choose`).
    progress : bool
        Show a progress bar (on a terminal).

    Returns
    -------
    pandas.DataFrame
        One row per feature.
    """
    import pandas as pd
    from tqdm import tqdm

    from skygas.movies.choices import spots_bright

    options = choices.locate_options()
    found = []
    for i in tqdm(
        range(movie.n_frames), unit="frame", desc="located", leave=False, disable=not progress
    ):
        f = locate_frame(spots_bright(movie.frame(i), choices.contrast), **options)
        f["frame"] = i
        found.append(f)
    return pd.concat(found, ignore_index=True)


def link(features, choices, *, drift: bool = False) -> Tracks:
    """Link ``features`` into tracks (trackpy), optionally removing the picture's drift.

    Parameters
    ----------
    features : pandas.DataFrame
        From :func:`locate_all`.
    choices : Choices
        Search range and memory.
    drift : bool
        Subtract the drift of the whole picture (``trackpy.compute_drift``).

    Returns
    -------
    Tracks
        The linked table in :data:`COLUMNS` order.
    """
    import trackpy

    trackpy.quiet()
    if len(features):
        table = trackpy.link(
            features,
            choices.search_range,
            memory=choices.memory,
            adaptive_stop=0.1,
            adaptive_step=0.9,
        )
    else:
        table = features.assign(particle=np.zeros(0, int))
    shift = None
    if drift and len(table):
        d = trackpy.compute_drift(table)
        n_frames = int(table["frame"].max()) + 1
        d = d.reindex(range(n_frames)).interpolate().fillna(0.0)
        table = trackpy.subtract_drift(table.copy(), d).reset_index(drop=True)
        shift = d[["x", "y"]].to_numpy()
    table = table[list(COLUMNS)].sort_values(["frame", "particle"]).reset_index(drop=True)
    table["frame"] = table["frame"].astype(int)
    table["particle"] = table["particle"].astype(int)
    return Tracks(table, shift)
