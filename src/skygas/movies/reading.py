"""Image sequences in: a multi-page TIFF stack or a folder of numbered images, read lazily.

What is accepted: grey-scale frames of integers (uint8, uint16, int16, ...) or real floats
(a Kerr difference image) within the range of 32-bit floats, at least 2 frames, all of one
shape and large enough to hold a skyrmion with film around it
(:func:`skygas.movies.choices.required_side`), along one axis of a stack (an ImageJ
hyperstack may have more axes only where they have length 1), or one numbered file each
(``frame_000.png``, ``frame_001.png``, ...: read in the order of their numbers, which must run
without a gap). What is refused, with one line naming the file and what to do: colour
(RGB/RGBA) frames, complex or boolean pixels, stacks with more axes (time and z, channels), a
TIFF that is cut short or damaged, an unreadable frame file, NaN or infinite pixels, a movie
whose frames are all uniform, a single frame, an empty folder, a path that does not exist.
:func:`open_movie` judges what the headers tell (no pixel read beyond the first frame);
:func:`check_frames` reads every frame once, before any tracking.

The pixel size and the frame interval, when the command line does not give them, come from the
movie itself: first a sidecar ``<movie>.json`` (``pixel_size_m``, ``frame_interval_s``;
written by ``skygas render``), then a TIFF's ImageJ metadata (``unit`` with the resolution
tags, ``finterval`` in seconds). Where each came from is recorded.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import re
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from skygas.core.errors import InputError

#: the image files a folder is read from
IMAGE_SUFFIXES = (".tif", ".tiff", ".png", ".jpg", ".jpeg", ".bmp")
STACK_SUFFIXES = (".tif", ".tiff")
#: the largest pixel value accepted: the range of 32-bit floats. The tracker's statistics
#: (third moments, power spectra) are computed in float64 and stay finite below it; only the
#: contrast matters to them, so a movie beyond it loses nothing by being rescaled
MAX_PIXEL_VALUE = float(np.finfo(np.float32).max)
#: metres per length unit, as ImageJ writes units
_UNITS = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "μm": 1e-6, "micron": 1e-6, "nm": 1e-9}
_CONVERT = (
    "convert it to a grey-scale stack first, e.g. in Fiji (Image ▸ Type ▸ 16-bit) or in Python: "
    "tifffile.imwrite('grey.tif', stack.mean(axis=-1).astype('uint16'))"
)
#: what tifffile logs about a TIFF whose page chain or shape is broken (a file cut short)
_DAMAGE = ("invalid page offset", "corrupt", "failed to reshape")
#: the names of a TIFF's axes (tifffile's letters)
_AXES = {"T": "time", "Z": "z", "C": "channels", "Q": "pages", "I": "images", "S": "samples"}


@dataclass
class Movie:
    """An opened image sequence.

    ``frames``: the frames, read when indexed (``frames[i]`` the raw array of frame ``i``);
    ``path``; ``n_frames``; ``shape`` (rows, columns); ``dtype``; ``pixel_size`` [m] and
    ``frame_interval`` [s] found in the movie (None if not) with ``sources`` saying where from;
    ``files`` the files read.
    """

    frames: Any
    path: Path
    n_frames: int
    shape: tuple[int, int]
    dtype: np.dtype
    pixel_size: float | None = None
    frame_interval: float | None = None
    sources: dict[str, str] = field(default_factory=dict)
    files: list[Path] = field(default_factory=list)

    def frame(self, i: int) -> np.ndarray:
        """Frame ``i`` as a float64 array (rows, columns), refused if it is not like the first.

        Refused (:class:`InputError`) when its file cannot be read, its shape differs from the
        first frame's, or a pixel is NaN, infinite or beyond :data:`MAX_PIXEL_VALUE`.
        """
        try:
            image = np.asarray(self.frames[i])
        except InputError:
            raise
        except Exception as err:  # tifffile, zlib and PIL raise many kinds for damaged data
            raise self._unreadable(i, err) from None
        if image.shape != self.shape:
            raise InputError(
                "MOVIE",
                str(self._name(i)),
                f"frames of one shape {self.shape} (this one is {image.shape})",
                "crop or resample the images to one size",
            )
        image = image.astype(float)
        largest = float(np.max(np.abs(image))) if image.size else 0.0
        if not np.isfinite(largest):
            raise InputError(
                "MOVIE",
                str(self._name(i)),
                f"finite pixel values (frame {i} holds NaN or infinities)",
                "replace them, e.g. by the frame's median",
            )
        if largest > MAX_PIXEL_VALUE:
            raise InputError(
                "MOVIE",
                str(self._name(i)),
                f"pixel values within ±{MAX_PIXEL_VALUE:.2g}, the range of 32-bit floats "
                f"(frame {i} holds {largest:.3g})",
                "rescale the movie, e.g. stack / stack.std(): only the contrast matters",
            )
        return image

    def _name(self, i: int) -> Path | str:
        """The file of frame ``i`` (a folder's frame), or the movie's path."""
        return self.files[i] if len(self.files) == self.n_frames > 1 else self.path

    def _unreadable(self, i: int, err: Exception) -> InputError:
        if len(self.files) == self.n_frames > 1:
            return InputError(
                "MOVIE",
                str(self.files[i]),
                f"a readable image, frame {i} of the movie ({type(err).__name__}: {err})",
                "export this frame again (or drop it and renumber the frames after it)",
            )
        return InputError(
            "MOVIE",
            str(self.path),
            f"a readable TIFF (frame {i} cannot be decoded: {type(err).__name__}: {err})",
            "the file is damaged or cut short: copy or export it again",
        )

    def file_hash(self) -> str:
        """SHA-256 of the input: the stack's bytes, or each file's name and bytes in order."""
        h = hashlib.sha256()
        for f in self.files:
            if len(self.files) > 1:
                h.update(f.name.encode())
            with open(f, "rb") as handle:
                while chunk := handle.read(1 << 20):
                    h.update(chunk)
        return h.hexdigest()


class _StackFrames:
    """The pages of a TIFF's first series, each read when indexed (the file kept open)."""

    def __init__(self, tif, pages) -> None:
        self._tif = tif  # keeps the file open for the pages
        self._pages = pages

    def __len__(self) -> int:
        return len(self._pages)

    def __getitem__(self, i: int) -> np.ndarray:
        with _tifffile_log():  # a damaged page raises; nothing reaches stderr
            return self._pages[i].asarray()


class _FileFrames:
    """One image file per frame, each read when indexed."""

    def __init__(self, files: list[Path]) -> None:
        self._files = files

    def __len__(self) -> int:
        return len(self._files)

    def __getitem__(self, i: int) -> np.ndarray:
        f = self._files[i]
        if f.suffix.lower() in STACK_SUFFIXES:
            import tifffile

            with _tifffile_log():
                return tifffile.imread(f)
        from PIL import Image

        with warnings.catch_warnings():
            # PIL warns of frames over 89 megapixels (a "decompression bomb"): the memory a
            # frame takes is judged by skygas.movies.estimate, and over 179 it raises anyway
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            with Image.open(f) as image:
                return np.asarray(image)  # decodes the whole file: a truncated one raises here


class _Collect(logging.Handler):
    """A log handler that keeps the messages of warnings and worse in a list."""

    def __init__(self, messages: list[str]) -> None:
        super().__init__(logging.WARNING)
        self.messages = messages

    def emit(self, record: logging.LogRecord) -> None:
        self.messages.append(record.getMessage())


@contextmanager
def _tifffile_log() -> Iterator[list[str]]:
    """Collect what tifffile logs meanwhile instead of printing it: its words on a damaged file.

    tifffile reports a broken page chain or a stack that lost its shape as log warnings and
    reads on; :func:`_open_stack` turns those into a refusal, and other remarks of tifffile
    (on unusual tags) are dropped: nothing of a library reaches stderr.
    """
    messages: list[str] = []
    logger = logging.getLogger("tifffile")
    handler, propagate = _Collect(messages), logger.propagate
    logger.addHandler(handler)
    logger.propagate = False
    try:
        yield messages
    finally:
        logger.removeHandler(handler)
        logger.propagate = propagate


def _image_files(folder: Path) -> list[Path]:
    return sorted(p for p in folder.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES and p.is_file())


def _frame_order(folder: Path, files: list[Path]) -> list[Path]:
    """``files`` in the order of their numbers (``frame_9`` before ``frame_10``), gaps refused.

    Files that are not all one name with a number (``frame_000.png``, ``frame_001.png``) are
    read in name order. A number missing between the first and the last is refused: the
    frames after it would be tracked one frame interval too early.
    """
    parts = [re.fullmatch(r"(.*?)(\d+)", f.stem) for f in files]
    if len(files) < 2 or any(p is None for p in parts):
        return files
    names = {(p.group(1), f.suffix.lower()) for p, f in zip(parts, files, strict=True) if p}
    if len(names) > 1:
        return files
    numbered = sorted((int(p.group(2)), f) for p, f in zip(parts, files, strict=True) if p)
    missing = (numbered[-1][0] - numbered[0][0] + 1) - len(numbered)
    for (a, fa), (b, fb) in zip(numbered, numbered[1:], strict=False):
        if b == a:
            raise InputError(
                "MOVIE",
                str(folder),
                f"one file per frame number ({fa.name} and {fb.name} are both frame {a})",
                "remove one of them",
            )
        if b > a + 1:
            more = f"; {missing} numbers are missing in all" if missing > b - a - 1 else ""
            raise InputError(
                "MOVIE",
                str(folder),
                f"frames numbered without a gap ({_gap(a, b)}: {fa.name} is followed by "
                f"{fb.name}{more})",
                "restore the missing frames; if they were dropped and the others are evenly "
                "spaced in time, renumber the files without gaps",
            )
    return [f for _, f in numbered]


def _gap(a: int, b: int) -> str:
    return f"frame {a + 1} is missing" if b == a + 2 else f"frames {a + 1} to {b - 1} are missing"


def open_movie(path: str | Path, diameter: int | None = None) -> Movie:
    """Open the TIFF stack or folder of images at ``path`` (see the module docstring).

    Only the headers and the first frame are read; :func:`check_frames` reads the rest.

    Parameters
    ----------
    path : str or Path
        A ``.tif``/``.tiff`` stack, or a folder of ``.tif``, ``.png``, ``.jpg`` or ``.bmp``
        images, one per frame, read in the order of their numbers.
    diameter : int, optional
        trackpy's feature diameter [px], if given: the frames must hold such a skyrmion
        (:func:`skygas.movies.choices.required_side`).

    Returns
    -------
    Movie
        The opened sequence (frames are read when asked for).

    Raises
    ------
    InputError
        For a missing path, an empty folder, a gap in the frames' numbers, another file type,
        a damaged or cut TIFF, an unreadable first frame, colour, complex or boolean pixels,
        a hyperstack, a single frame or frames too small to hold a skyrmion.
    """
    path = Path(path)
    if not path.exists():
        raise InputError(
            "MOVIE", str(path), "an existing TIFF stack or folder of images", "check the path"
        )
    frames: Any
    if path.is_dir():
        files = _image_files(path)
        if not files:
            raise InputError(
                "MOVIE",
                str(path),
                f"a folder holding images ({', '.join(IMAGE_SUFFIXES)}); this one holds none",
                "give the folder of the movie's frames, or the TIFF stack itself",
            )
        if len(files) == 1 and files[0].suffix.lower() in STACK_SUFFIXES:
            return open_movie(files[0], diameter)  # a folder holding one stack
        files = _frame_order(path, files)
        frames, axes, shape, dtype = _open_files(files)
    elif path.suffix.lower() in STACK_SUFFIXES:
        files = [path]
        frames, axes, shape, dtype = _open_stack(path)
    else:
        raise InputError(
            "MOVIE",
            str(path),
            "a TIFF stack (.tif, .tiff) or a folder of images",
            "export the movie as a TIFF stack (Fiji: File ▸ Save As ▸ Tiff...)",
        )
    one_page = path.suffix.lower() in STACK_SUFFIXES and len(frames) == 1
    _check_pixels(path, shape, axes, dtype, diameter, single_page=one_page)
    n = len(frames)
    if n < 2:
        raise InputError(
            "MOVIE",
            str(path),
            f"a movie of at least 2 frames (this one has {n})",
            "give the whole image sequence; one frame has no motion to track",
        )
    movie = Movie(frames, path, n, (int(shape[0]), int(shape[1])), np.dtype(dtype), files=files)
    _read_scales(movie)
    return movie


def _open_files(files: list[Path]) -> tuple[_FileFrames, str, tuple[int, ...], np.dtype]:
    """The frames of a folder's ``files``, with the axes, shape and type of the first one."""
    frames = _FileFrames(files)
    try:
        first = np.asarray(frames[0])
    except Exception as err:  # PIL and tifffile raise many kinds for a damaged file
        raise InputError(
            "MOVIE",
            str(files[0]),
            f"a readable image ({type(err).__name__}: {err})",
            "export this frame again (or drop it and renumber the frames after it)",
        ) from None
    colour = first.ndim == 3 and first.shape[-1] in (3, 4)
    axes = "YXS" if colour else "YX".rjust(first.ndim, "Q")[-first.ndim :]
    return frames, axes, first.shape, first.dtype


def _open_stack(path: Path) -> tuple[_StackFrames, str, tuple[int, ...], np.dtype]:
    """The frames of the TIFF at ``path``, their axes, shape and type, or why it is refused.

    Refused: a file tifffile cannot open, one whose page chain or data run past its end (cut
    short), and a stack with more than one axis besides the frames' own (an ImageJ hyperstack
    of time and z, say; an axis of length 1 is fine).
    """
    import tifffile

    def damaged(why: str) -> InputError:
        return InputError(
            "MOVIE",
            str(path),
            f"a complete TIFF file ({why})",
            "the file is damaged or cut short: copy or export it again",
        )

    tif = None
    try:
        with _tifffile_log() as messages:
            try:
                tif = tifffile.TiffFile(path)
                series = tif.series[0]
                pages: list[Any] = list(series.pages)
                ends = [
                    o + c
                    for p in pages
                    if p is not None
                    for o, c in zip(p.dataoffsets, p.databytecounts, strict=True)
                ]
            except Exception as err:  # tifffile raises many kinds for a damaged file
                raise damaged(f"{type(err).__name__}: {err}") from None
        if None in pages:
            raise damaged(f"page {pages.index(None)} of its {len(pages)} is missing")
        page = pages[0]
        _check_stack(path, messages, ends, series, page.axes, damaged)
    except InputError:
        if tif is not None:
            tif.close()
        raise
    return _StackFrames(tif, pages), page.axes, tuple(page.shape), page.dtype


def _check_stack(path: Path, messages: list[str], ends: list[int], series, axes: str, damaged):
    """Refuse a TIFF cut short (tifffile's words, data past the end) or with two frame axes."""
    broken = [m for m in messages if any(word in m for word in _DAMAGE)]
    if broken:
        raise damaged(f"tifffile: {broken[0].split('> ', 1)[-1]}")
    size = os.path.getsize(path)
    if ends and max(ends) > size:
        raise damaged(f"its data run to byte {max(ends)}, past its end at byte {size}")
    lead = len(series.axes) - len(axes)
    extra = [(a, n) for a, n in zip(series.axes[:lead], series.shape[:lead], strict=True) if n > 1]
    if len(extra) > 1:
        named = ", ".join(f"{_AXES.get(a, a)} {n}" for a, n in extra)
        raise InputError(
            "MOVIE",
            str(path),
            "one time axis of 2-D grey-scale frames (this stack has axes "
            f"{series.axes}, shape {' × '.join(map(str, series.shape))}: {named})",
            "save one z-plane or channel as a T × Y × X stack, e.g. Fiji's Image ▸ "
            "Hyperstacks ▸ Reduce Dimensionality, or tifffile.imwrite('movie.tif', "
            f"tifffile.imread('{path.name}')[:, 0])",
        )


def _check_pixels(
    path: Path,
    shape: tuple[int, ...],
    axes: str,
    dtype: np.dtype,
    diameter: int | None,
    single_page: bool = False,
) -> None:
    """Refuse frames too small for a skyrmion, in colour, not 2-D, boolean or complex.

    The size comes first: a stack of a few tiny grey frames saved without
    ``photometric='minisblack'`` reads as one small colour image, and is too small either way.
    """
    from skygas.movies.choices import required_side

    dtype = np.dtype(dtype)
    sides = [n for a, n in zip(axes, shape, strict=False) if a in "YX"]
    side = required_side(diameter)
    if sides and min(sides) < side:
        why, hint = (
            (f"for --diameter {diameter}", "give a smaller --diameter")
            if diameter is not None
            else ("to find its size from the data", "give --diameter (odd, >= 3)")
        )
        raise InputError(
            "MOVIE",
            str(path),
            f"frames large enough to hold a skyrmion: at least {side} × {side} px {why} "
            f"(these are {' × '.join(map(str, sides[::-1]))} px, array shape {tuple(shape)})",
            f"{hint} if the frames hold 2 × diameter + 1 px a side, or record larger frames",
        )
    if "S" in axes:
        stack_hint = (
            "; a stack of 3 or 4 grey frames written without photometric='minisblack' also "
            "reads as one colour image"
            if single_page
            else ""
        )
        raise InputError(
            "MOVIE",
            str(path),
            f"grey-scale frames (these are colour, shape {tuple(shape)})",
            _CONVERT + stack_hint,
        )
    if len(shape) != 2:
        raise InputError(
            "MOVIE",
            str(path),
            f"a stack of 2-D grey-scale frames (each frame here has shape {tuple(shape)})",
            "save one channel and one z-plane as a plain T × Y × X stack",
        )
    if dtype == np.bool_:
        raise InputError(
            "MOVIE",
            str(path),
            "grey levels (these pixels are boolean, a mask: it has no noise level to set the "
            "detection threshold from, nor the grey levels that place a skyrmion to a "
            "fraction of a pixel)",
            "track the grey-scale movie the mask was made from; to track the mask all the "
            "same, save it as 0/255: tifffile.imwrite('mask.tif', stack.astype('uint8') * 255) "
            "and give --minmass",
        )
    if not (np.issubdtype(dtype, np.integer) or np.issubdtype(dtype, np.floating)):
        raise InputError(
            "MOVIE",
            str(path),
            f"integer or real floating-point pixels (these are {dtype})",
            "take the magnitude or the real part, e.g. numpy.abs(stack).astype('float32')",
        )


def check_frames(movie: Movie, progress: bool = False) -> None:
    """Read every frame of ``movie`` once and refuse the movie before any tracking.

    Each frame must be readable, of the first frame's shape, finite and within
    :data:`MAX_PIXEL_VALUE` (:meth:`Movie.frame`); at least one frame must vary (a movie of
    uniform frames holds nothing to track). Reading is a small part of tracking: a frame is
    decoded in well under a tenth of the time trackpy takes to search it.
    """
    from tqdm import tqdm

    levels: set[float] = set()
    varies = False
    # the bar only shows past a second: a refusal of a short movie stays the only line
    for i in tqdm(
        range(movie.n_frames),
        unit="frame",
        desc="checked",
        leave=False,
        disable=not progress,
        delay=1.0,
    ):
        image = movie.frame(i)
        if not varies:
            lo, hi = float(image.min()), float(image.max())
            varies = hi > lo
            levels.add(lo)
    if not varies:
        level = f"one grey level, {levels.pop():g}" if len(levels) == 1 else "uniform"
        raise InputError(
            "MOVIE",
            str(movie.path),
            f"frames whose pixels vary (all {movie.n_frames} frames are {level}): nothing to track",
            "check that this is the movie meant, recorded with the light on",
        )


def _read_scales(movie: Movie) -> None:
    """Fill in the pixel size and frame interval from a sidecar JSON or the TIFF's tags."""
    sidecar = movie.path.with_suffix(".json") if movie.path.is_file() else None
    if sidecar is not None and sidecar.is_file():
        try:
            meta = json.loads(sidecar.read_text())
        except (OSError, ValueError) as err:
            raise InputError(
                "MOVIE",
                str(sidecar),
                f"the movie's sidecar as JSON (this one is unreadable: {err})",
                "repair or remove it",
            ) from None
        for key, attr in (("pixel_size_m", "pixel_size"), ("frame_interval_s", "frame_interval")):
            value = meta.get(key) if isinstance(meta, dict) else None
            if isinstance(value, (int, float)) and value > 0:
                setattr(movie, attr, float(value))
                movie.sources[attr] = str(sidecar.name)
    if movie.path.suffix.lower() in STACK_SUFFIXES and movie.path.is_file():
        import tifffile

        try:
            with _tifffile_log(), tifffile.TiffFile(movie.path) as tif:
                ij = tif.imagej_metadata or {}
                resolution = tif.pages[0].resolution
        except Exception:  # the frames were read: only the tags are missing  # noqa: BLE001
            return
        unit = str(ij.get("unit", "")).replace("\\u00B5", "µ")
        if movie.pixel_size is None and unit in _UNITS and resolution and resolution[0] > 0:
            movie.pixel_size = _UNITS[unit] / float(resolution[0])
            movie.sources["pixel_size"] = "TIFF resolution tags (ImageJ unit)"
        interval = ij.get("finterval")
        if movie.frame_interval is None and isinstance(interval, (int, float)) and interval > 0:
            movie.frame_interval = float(interval)
            movie.sources["frame_interval"] = "TIFF ImageJ finterval"
