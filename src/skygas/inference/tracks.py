"""Tracks in trackpy's format: read, checked, converted to SI and freed of drift.

trackpy (and most particle trackers) write one row per detected position: ``frame`` (an
integer), ``particle`` (the track it was linked into), ``x`` and ``y`` in **pixels**, plus
columns of their own (``mass``, ``size``, ...), which are ignored here. They come as a pandas
DataFrame, a CSV file, an HDF5 file (pandas' ``to_hdf``, needs PyTables) or a Parquet file (needs
pyarrow). :func:`load_tracks` checks them before any work, converts pixels to metres with the
pixel size (given, or the one the ``track.json`` of a ``skygas track`` folder records:
:func:`pixel_size_for`) and frames to seconds with the frame interval, and removes a common
drift of the whole field of view with trackpy's own :func:`trackpy.compute_drift` and
:func:`trackpy.subtract_drift` when the drift is larger than the wandering of the gas's centre
of mass (:func:`drift_is_significant`).
"""

from __future__ import annotations

import hashlib
import json
import math
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from skygas.analysis.frames import Frames
from skygas.core.errors import InputError, require
from skygas.core.resources import require_memory

#: The columns a track table must have.
REQUIRED_COLUMNS = ("frame", "particle", "x", "y")
#: The table ``skygas track`` writes into its output folder, read when that folder is given.
TRACK_FOLDER_TABLE = "tracks.csv"
#: The record ``skygas track`` writes beside its table: the pixel size the tracks were made with.
TRACK_FOLDER_RECORD = "track.json"
#: A pixel size given and the one track.json records agree within this relative difference
#: (14e-9 typed, 1.4000000000000001e-08 read from a TIFF's resolution tag).
PIXEL_SIZE_RTOL = 1e-6
#: Bytes the inference holds per position of the movie (its tables, steps and force fields):
#: 0.65 KiB measured on the shipped chamber movie repeated four times (48 000 positions), with
#: room to spare. A table is refused before any work when its frames, full, would not fit.
BYTES_PER_POSITION = 1024
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
    path = track_file(source)
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


def track_file(source) -> Path:
    """The file of tracks ``source`` names: itself, or the tracks.csv of a ``skygas track`` folder.

    Raises
    ------
    InputError
        If there is no such file.
    """
    path = Path(str(source))
    if path.is_dir():
        table = path / TRACK_FOLDER_TABLE
        require(
            table.is_file(),
            "tracks",
            str(source),
            f"a track table, or a folder of `skygas track` that holds {TRACK_FOLDER_TABLE} "
            "(this folder has none)",
            "run skygas track MOVIE --out FOLDER first, or give the table's file",
        )
        return table
    require(path.is_file(), "tracks", str(source), "an existing .csv, .h5 or .parquet file")
    return path


def track_record(source) -> Path | None:
    """The track.json of the ``skygas track`` folder that ``source`` names, or None.

    ``source`` names a folder when it is the folder or the folder's tracks.csv
    (:data:`TRACK_FOLDER_TABLE`); a table of another name, a DataFrame or a folder without
    track.json has no record.
    """
    if not isinstance(source, (str, Path)):
        return None
    path = Path(str(source))
    if path.is_dir():
        folder = path
    elif path.name == TRACK_FOLDER_TABLE:
        folder = path.parent
    else:
        return None
    record = folder / TRACK_FOLDER_RECORD
    return record if record.is_file() else None


def recorded_pixel_size(record: Path) -> float | None:
    """The pixel size [m] a track.json records; None when its movie carried none.

    Raises
    ------
    InputError
        If ``record`` is not a track.json as ``skygas track`` writes it, or its pixel size is
        not a length in metres.
    """
    try:
        value = json.loads(record.read_text(encoding="utf-8"))["pixel_size_m"]
    except (OSError, UnicodeDecodeError, ValueError, KeyError, TypeError):
        raise InputError(
            "tracks",
            str(record),
            "a track.json as skygas track writes it, holding pixel_size_m",
            "give --pixel-size, or run skygas track again to write it anew",
        ) from None
    if value is None:
        return None
    require(
        isinstance(value, (int, float)) and not isinstance(value, bool),
        "pixel_size_m",
        value,
        f"a pixel size in metres in {record}",
        "give --pixel-size, or run skygas track again to write it anew",
    )
    return metres("pixel_size_m", float(value), f"the pixel size {record} records")


def pixel_size_for(source, given: float | None) -> tuple[float | None, str | None]:
    """The pixel size [m] of the tracks ``source``, and a line saying so when track.json gave it.

    For the folder of ``skygas track`` (or its tracks.csv) its track.json records the pixel size
    the tracks were made with: used when none is ``given``, and a ``given`` one that differs
    (by more than :data:`PIXEL_SIZE_RTOL`) is refused. Otherwise ``given`` (None when there is
    none: :func:`load_tracks` asks for it).

    Returns
    -------
    pixel_size : float or None
        Metres per pixel.
    note : str or None
        "pixel size 14 nm from FOLDER/track.json (no --pixel-size given)" when track.json gave it.

    Raises
    ------
    InputError
        A ``given`` pixel size that is not the one track.json records; with none given, a
        track.json that cannot be read.
    """
    from skygas.core.quantities import format_value

    record = track_record(source)
    if record is None:
        return given, None
    if given is None:
        recorded = recorded_pixel_size(record)
        if recorded is None:
            return None, None
        shown = format_value(recorded, unit="m", digits=4)
        return recorded, f"pixel size {shown} from {record} (no --pixel-size given)"
    try:
        recorded = recorded_pixel_size(record)
    except InputError:  # a track.json that cannot be read says nothing against a given size
        return given, None
    if recorded is not None and not math.isclose(given, recorded, rel_tol=PIXEL_SIZE_RTOL):
        raise InputError(
            "--pixel-size",
            given,
            f"the pixel size the tracks were made with, {recorded!r} m ({record} records it)",
            "leave --pixel-size out to use it, or track the movie again with the right "
            "--pixel-size",
        )
    return given, None


def metres(field: str, value: float, hint: str | None = None) -> float:
    """``value`` [m], checked as the devices check every length they are given.

    Outside 1 pm … 1 m (:func:`skygas.core.config_types.length_problem`) a number was almost
    surely given in another unit; the refusal says which it probably was ("did you mean
    14e-9?"). ``hint`` says what the length is, where the field alone does not.
    """
    from skygas.core.config_types import length_problem

    require(bool(np.isfinite(value) and value > 0), field, value, "a length > 0 in metres", hint)
    problem = length_problem(value)
    require(problem is None, field, value, str(problem), hint)
    return float(value)


def check_table(table, source: str):
    """``table``, checked row by row before any work.

    Refused (:class:`InputError`, one line naming the column, the first bad row and the file):
    a missing column, no rows, a value that is not a number, a position or number that is not
    finite, a frame or particle number that is not whole, a negative frame, frames that would
    not fit in memory (:data:`BYTES_PER_POSITION`), fewer than two frames, a particle twice in a
    frame. Rows are counted from 1 after the header.
    """
    missing = [c for c in REQUIRED_COLUMNS if c not in table.columns]
    require(
        not missing,
        f"tracks.{missing[0]}" if missing else "tracks",
        source,
        f"a table with columns {', '.join(REQUIRED_COLUMNS)} (trackpy's format; x, y in pixels); "
        f"this one has {', '.join(map(str, table.columns)) or 'no columns'}",
        "link the features with trackpy.link first, or rename the columns",
    )
    require(
        len(table) > 0,
        "tracks",
        source,
        "a table with at least one row of frame, particle, x, y (this one has its header only)",
        "track the movie first (skygas track, or trackpy.locate and trackpy.link)",
    )
    for column in REQUIRED_COLUMNS:
        _require_numbers(table, column, source)
        _require_rows(
            table,
            column,
            source,
            np.isfinite(table[column].to_numpy(float, na_value=np.nan)),
            "finite numbers",
            "remove or fix those rows (pandas: tracks.dropna()); a tracker writes finite "
            "positions and frame and particle numbers only",
        )
    frame = table["frame"].to_numpy(float)
    _require_rows(table, "frame", source, frame == np.round(frame), "whole frame numbers")
    _require_rows(table, "frame", source, frame >= 0, "frame numbers >= 0")
    particle = table["particle"].to_numpy(float)
    _require_rows(table, "particle", source, particle == np.round(particle), "whole numbers")
    _require_fits(table, source)
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


def _require_numbers(table, column: str, source: str) -> None:
    """Refuse a column holding something that is not a number, naming its first such row."""
    import pandas as pd

    if pd.api.types.is_numeric_dtype(table[column]) and not pd.api.types.is_bool_dtype(
        table[column]
    ):
        return
    values = table[column]
    bad = pd.to_numeric(values, errors="coerce").isna().to_numpy() | values.map(
        lambda v: isinstance(v, bool)
    ).to_numpy(bool)
    if not bad.any():  # numbers written as text (a DataFrame's strings)
        raise InputError(f"tracks.{column}", str(values.dtype), f"numbers, not text ({source})")
    row = int(np.argmax(bad))
    raise InputError(
        f"tracks.{column}",
        _plain(values.iloc[row]),
        f"numbers in every row (row {row + 1} of {source} holds this)",
        "fix that row, or remove it",
    )


def _require_rows(
    table, column: str, source: str, ok: np.ndarray, allowed: str, hint: str | None = None
) -> None:
    """Refuse ``column`` unless ``ok`` holds in every row, naming the first row where not."""
    if ok.all():
        return
    bad = np.flatnonzero(~ok)
    more = f", and {len(bad) - 1} more row(s)" if len(bad) > 1 else ""
    raise InputError(
        f"tracks.{column}",
        _plain(table[column].iloc[bad[0]]),
        f"{allowed} in every row (row {bad[0] + 1} of {source}{more})",
        hint or "fix those rows, or remove them",
    )


def _plain(value):
    """A table's value as Python writes it (``True``, not ``np.True_``)."""
    return value.item() if isinstance(value, np.generic) else value


def _require_fits(table, source: str) -> None:
    """Refuse frames that, each as full as the fullest, would not fit in memory.

    The inference's arrays grow with the positions, and its frames run from the first frame
    number to the last: a stray frame number (10¹² in a movie of 400 frames) would ask for
    terabytes. Checked before anything is allocated.
    """
    frame = table["frame"].to_numpy(float)
    first, last = float(frame.min()), float(frame.max())
    span = last - first + 1
    fullest = int(table.groupby("frame", sort=False).size().max())
    row = int(np.argmax(frame)) + 1
    require_memory(
        "tracks.frame",
        last,
        span * fullest * BYTES_PER_POSITION,
        f"frames {first:.0f} to {last:.0f} (row {row} of {source}) with up to {fullest} "
        "skyrmions each",
        "frames are numbered one per image of the movie: fix the frame column",
    )


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
        Metres per pixel, 1 pm … 1 m (:func:`metres`); for a ``skygas track`` folder, the one
        its track.json records (:func:`pixel_size_for`: a different one is refused; without
        one, the refusal names the recorded value).
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
    # the command line takes track.json's pixel size (pixel_size_for) before it reads the
    # outline; here a different one is refused, and a missing one asked for with its value
    if pixel_size is None:
        recorded, _ = pixel_size_for(source, None)
        raise InputError(
            "--pixel-size",
            None,
            "the size of one pixel in metres (trackpy's x, y are in pixels)",
            f"give --pixel-size {recorded!r}, the pixel size {track_record(source)} records"
            if recorded is not None
            else "give --pixel-size, e.g. --pixel-size 10e-9",
        )
    pixel_size_for(source, pixel_size)
    metres("--pixel-size", pixel_size)
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
    lengths = _period(period)
    name = "DataFrame" if not isinstance(source, (str, Path)) else str(track_file(source))
    table = check_table(read_table(source), name)
    # imported once the input is judged: trackpy alone takes seconds to import
    import trackpy

    from skygas.inference.film import detect_periodic

    table = table.sort_values(["frame", "particle"]).reset_index(drop=True)
    first = int(table["frame"].min())
    n_frames = int(table["frame"].max()) - first + 1
    box = None
    if isinstance(period, str):
        box = detect_periodic(_frames(table, pixel_size, frame_interval, first, n_frames))
    elif lengths is not None:
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


def _period(period) -> np.ndarray | None:
    """The sides (L_x, L_y) [m] of a periodic box given, checked; None for "auto" or none."""
    if isinstance(period, str):
        require(period == "auto", "--periodic", period, "auto, or two lengths L_x L_y [m]")
        return None
    if period is None:
        return None
    lengths = np.asarray(period, float)
    require(
        lengths.shape == (2,), "--periodic", period, "two lengths L_x L_y [m] of the periodic box"
    )
    return np.array([metres("--periodic", float(side)) for side in lengths])


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
