"""Tracks in trackpy's format: read, checked, converted to SI and freed of drift.

trackpy (and most particle trackers) write one row per detected position: ``frame`` (an
integer), ``particle`` (the track it was linked into), ``x`` and ``y`` in **pixels**, plus
columns of their own (``mass``, ``size``, ...), which are ignored here. They come as a pandas
DataFrame, a CSV file, an HDF5 file (pandas' ``to_hdf``, needs PyTables) or a Parquet file (needs
pyarrow). :func:`load_tracks` checks them before any work, converts pixels to metres with the
pixel size and frames to seconds with the frame interval, and removes a common drift of the
whole field of view with trackpy's own :func:`trackpy.compute_drift` and
:func:`trackpy.subtract_drift` when the drift is larger than the wandering of the gas's centre
of mass (:func:`drift_is_significant`).
"""

from __future__ import annotations

import hashlib
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from skygas.analysis.frames import Frames
from skygas.core.errors import InputError, require

#: The columns a track table must have.
REQUIRED_COLUMNS = ("frame", "particle", "x", "y")
#: A drift is subtracted when its end-to-end displacement exceeds this many standard deviations
#: of the random wandering of the centre of mass of N independent skyrmions, √(4 D T / N).
DRIFT_SIGMAS = 3.0


@dataclass(frozen=True)
class Tracks:
    """Checked tracks in SI units.

    ``frames`` the positions [m] per frame (time [s] = frame · interval; unwrapped in a
    periodic box); ``table`` the input rows kept (trackpy's DataFrame, pixels); ``pixel_size``
    [m]; ``frame_interval`` [s]; ``drift`` (F, 2) [m] the drift trackpy found per frame
    (subtracted when ``drift_subtracted``); ``source`` what was read; ``sha256`` a hash of the
    rows used; ``box`` ((L_x, L_y), (x₀, y₀)) [m] of a periodic box, or None.
    """

    frames: Frames
    table: object
    pixel_size: float
    frame_interval: float
    drift: np.ndarray
    drift_subtracted: bool
    source: str
    sha256: str
    box: tuple | None = None


def read_table(source):
    """A track table from a DataFrame or a .csv, .h5/.hdf5 or .parquet file.

    Raises
    ------
    InputError
        If the file is missing or of another kind, or the reader it needs is not installed.
    """
    import pandas as pd

    if isinstance(source, pd.DataFrame):
        return source
    path = Path(str(source))
    require(path.is_file(), "tracks", str(source), "an existing .csv, .h5 or .parquet file")
    suffix = path.suffix.lower()
    try:
        if suffix in (".csv", ".txt"):
            return pd.read_csv(path, comment="#")
        if suffix in (".h5", ".hdf5", ".hdf"):
            return pd.read_hdf(path)
        if suffix in (".parquet", ".pq"):
            return pd.read_parquet(path)
    except ImportError as err:
        name = "tables (PyTables)" if suffix.startswith(".h") else "pyarrow"
        raise InputError(
            "tracks",
            str(path),
            f"a file whose reader is installed ({err.name or name} is missing)",
            f"pip install {name.split()[0]}, or save the tracks as CSV",
        ) from None
    except (ValueError, OSError, KeyError, UnicodeDecodeError) as err:
        raise InputError(
            "tracks", str(path), f"a readable track table ({type(err).__name__}: {err})"
        ) from None
    raise InputError("tracks", str(path), "a .csv, .h5/.hdf5 or .parquet file (trackpy's formats)")


def check_table(table, source: str):
    """The rows of ``table`` with finite positions, checked.

    Raises :class:`InputError` for a missing column, non-numeric values, no finite position or
    fewer than two frames.
    """
    import pandas as pd

    missing = [c for c in REQUIRED_COLUMNS if c not in table.columns]
    require(
        not missing,
        f"tracks.{missing[0]}" if missing else "tracks",
        source,
        f"a table with columns {', '.join(REQUIRED_COLUMNS)} (trackpy's format; x, y in pixels); "
        f"this one has {', '.join(map(str, table.columns)) or 'no columns'}",
        "link the features with trackpy.link first, or rename the columns",
    )
    for c in REQUIRED_COLUMNS:
        require(
            pd.api.types.is_numeric_dtype(table[c]),
            f"tracks.{c}",
            str(table[c].dtype),
            "numbers",
        )
    table = table.loc[np.isfinite(table["x"]) & np.isfinite(table["y"])]
    frame = table["frame"].to_numpy()
    require(
        bool(len(frame) > 0 and np.all(frame == np.round(frame)) and frame.min() >= 0),
        "tracks.frame",
        source,
        "whole frame numbers >= 0 and at least one finite position",
    )
    n_frames = int(np.unique(frame).size)
    require(
        n_frames >= 2,
        "tracks.frame",
        f"{n_frames} frame",
        "at least two frames (diffusion needs motion between frames)",
        "track a movie of many frames",
    )
    duplicated = table.duplicated(["frame", "particle"]).any()
    require(
        not duplicated,
        "tracks.particle",
        source,
        "one position per particle and frame (this table repeats a particle within a frame)",
        "link the features with trackpy.link",
    )
    return table


def drift_is_significant(drift: np.ndarray, diffusion: float, duration: float, n: float) -> bool:
    """Whether a drift is larger than the centre of mass of ``n`` skyrmions wanders by itself.

    ``drift`` (F, 2) [m] from trackpy; ``diffusion`` D [m²/s], ``duration`` T [s]: the centre of
    mass of n independent skyrmions moves by √(4DT/n) in T; a drift below
    :data:`DRIFT_SIGMAS` times that is that wandering, and subtracting it would take the
    skyrmions' own motion away.
    """
    if len(drift) < 2 or n <= 0:
        return False
    end = float(np.hypot(*(drift[-1] - drift[0])))
    return end > DRIFT_SIGMAS * np.sqrt(4.0 * diffusion * duration / n)


def _hash(table) -> str:
    import pandas as pd

    rows = table[list(REQUIRED_COLUMNS)].sort_values(["frame", "particle"])
    return hashlib.sha256(pd.util.hash_pandas_object(rows, index=False).to_numpy()).hexdigest()


def load_tracks(
    source,
    pixel_size: float | None,
    frame_interval: float | None,
    *,
    subtract_drift: str = "auto",
    period="auto",
    rough_diffusion=None,
) -> Tracks:
    """Read, check and convert tracks; unwrap a periodic box; remove a drift of the view.

    Parameters
    ----------
    source : DataFrame or path
        trackpy's table (``frame``, ``particle``, ``x``, ``y`` in pixels).
    pixel_size : float
        Metres per pixel, > 0.
    frame_interval : float
        Seconds between frames, > 0.
    subtract_drift : {"auto", "yes", "no"}
        ``"auto"`` subtracts trackpy's drift when it is significant
        (:func:`drift_is_significant`) and the positions, so moved, show a sharper landscape
        (:func:`drift_sharpens`): a drift of the field of view moves the landscape with the
        skyrmions, a drive (a current) moves the skyrmions across it.
    period : "auto", None or (L_x, L_y)
        A periodic box [m] whose wrapped positions are unwrapped; ``"auto"`` finds it from
        tracks that wrap (:func:`~skygas.inference.film.detect_periodic`).
    rough_diffusion : callable, optional
        ``rough_diffusion(frames)`` → D [m²/s] for the significance test (default: the MSD
        slope at lag 1).

    Returns
    -------
    Tracks
    """
    import trackpy

    from skygas.inference.film import detect_periodic

    require(
        pixel_size is not None,
        "--pixel-size",
        pixel_size,
        "the size of one pixel in metres (trackpy's x, y are in pixels)",
        "give --pixel-size, e.g. --pixel-size 10e-9",
    )
    assert pixel_size is not None
    require(
        np.isfinite(pixel_size) and pixel_size > 0, "--pixel-size", pixel_size, "a length > 0 [m]"
    )
    require(
        frame_interval is not None and np.isfinite(frame_interval) and frame_interval > 0,
        "--frame-interval",
        frame_interval,
        "the time between frames in seconds, > 0",
        "give --frame-interval, e.g. --frame-interval 5e-9",
    )
    assert frame_interval is not None
    require(
        subtract_drift in ("auto", "yes", "no"),
        "subtract_drift",
        subtract_drift,
        "auto, yes or no",
    )
    name = "DataFrame" if not isinstance(source, (str, Path)) else str(source)
    table = check_table(read_table(source), name)
    table = table.sort_values(["frame", "particle"]).reset_index(drop=True)
    first = int(table["frame"].min())
    n_frames = int(table["frame"].max()) - first + 1
    box = None
    if isinstance(period, str):
        require(period == "auto", "--periodic", period, "auto, or two lengths L_x L_y [m]")
        box = detect_periodic(_frames(table, pixel_size, frame_interval, first, n_frames))
    elif period is not None:
        lengths = np.asarray(period, float)
        require(
            bool(lengths.shape == (2,) and np.all(np.isfinite(lengths)) and np.all(lengths > 0)),
            "--periodic",
            period,
            "two lengths L_x L_y > 0 [m] of the periodic box",
        )
        x0 = float(table["x"].min()) * pixel_size
        y0 = float(table["y"].min()) * pixel_size
        box = ((float(lengths[0]), float(lengths[1])), (x0, y0))
    if box is not None:
        table = _unwrapped(table, np.asarray(box[0]) / pixel_size)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # trackpy's own pandas deprecations, not the user's
        drift_px = trackpy.compute_drift(table[list(REQUIRED_COLUMNS)].copy())
    drift = np.zeros((n_frames, 2))
    where = drift_px.index.to_numpy(int) - first
    drift[where] = drift_px[["x", "y"]].to_numpy() * pixel_size
    # frames without a drift estimate keep the last one
    known = np.zeros(n_frames, bool)
    known[where] = True
    known[0] = True
    drift = drift[np.maximum.accumulate(np.where(known, np.arange(n_frames), 0))]
    raw = _frames(table, pixel_size, frame_interval, first, n_frames)
    duration = (n_frames - 1) * frame_interval
    d = (
        rough_diffusion(raw)
        if rough_diffusion is not None
        else _lag_one_diffusion(raw, frame_interval)
    )
    subtract = subtract_drift == "yes"
    moved = None
    if subtract_drift != "no" and (
        subtract or drift_is_significant(drift, d, duration, float(np.mean(raw.count)))
    ):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            moved = trackpy.subtract_drift(table.copy(), drift_px).reset_index(drop=True)
        if not subtract:
            other = _frames(moved, pixel_size, frame_interval, first, n_frames)
            subtract = drift_sharpens(raw, other, box)
    if subtract:
        assert moved is not None
        table = moved
    frames = _frames(table, pixel_size, frame_interval, first, n_frames) if subtract else raw
    return Tracks(
        frames,
        table,
        float(pixel_size),
        float(frame_interval),
        drift,
        subtract,
        name,
        _hash(table),
        box,
    )


def _unwrapped(table, period_px: np.ndarray):
    """The table with each track's jumps across the periodic box undone (pixels)."""
    table = table.sort_values(["particle", "frame"]).copy()
    for axis, length in zip(("x", "y"), period_px, strict=True):
        pos = table[axis].to_numpy(float)
        step = np.diff(pos)
        same = table["particle"].to_numpy()[1:] == table["particle"].to_numpy()[:-1]
        wraps = np.where(same, np.round(step / length), 0.0)
        shift = np.concatenate([[0.0], np.cumsum(wraps)])
        # the shift accumulates within a track only
        track_start = np.concatenate([[True], ~same])
        base = np.maximum.accumulate(np.where(track_start, np.arange(len(pos)), 0))
        table[axis] = pos - length * (shift - shift[base])
    return table.sort_values(["frame", "particle"]).reset_index(drop=True)


def drift_sharpens(raw: Frames, moved: Frames, box=None) -> bool:
    """Whether the drift-corrected positions show a sharper landscape than the raw ones.

    Sharper: a higher held-out log-likelihood of the positions' density (the kernel density of
    :mod:`skygas.inference.landscape`, each on its own field of view; folded into the box if
    periodic). A drift of the stage moves the landscape with the skyrmions, and taking it out
    sharpens it; a drive moves the skyrmions across a landscape that stays, and taking it out
    blurs it.
    """
    from skygas.inference.film import field_of_view
    from skygas.inference.landscape import best_density_score

    def score(frames: Frames) -> float:
        if box is not None:
            (lx, ly), (x0, y0) = box
            frames = Frames(
                frames.time,
                frames.count,
                frames.ids,
                x0 + np.mod(frames.x - x0, lx),
                y0 + np.mod(frames.y - y0, ly),
            )
        return best_density_score(frames, field_of_view(frames, 1e-12))

    return score(moved) > score(raw)


def _lag_one_diffusion(frames: Frames, dt: float) -> float:
    a, b = frames.pairs_at_lag(1)
    if len(a) == 0:
        return 0.0
    return float(np.mean((frames.x[b] - frames.x[a]) ** 2 + (frames.y[b] - frames.y[a]) ** 2)) / (
        4 * dt
    )


def _frames(table, pixel_size: float, dt: float, first: int, n_frames: int) -> Frames:
    frame = table["frame"].to_numpy(np.int64) - first
    order = np.argsort(frame, kind="stable")
    frame = frame[order]
    count = np.bincount(frame, minlength=n_frames).astype(np.int64)
    return Frames(
        dt * np.arange(n_frames, dtype=float),
        count,
        table["particle"].to_numpy(np.int64)[order],
        table["x"].to_numpy(float)[order] * pixel_size,
        table["y"].to_numpy(float)[order] * pixel_size,
    )
