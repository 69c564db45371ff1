"""Image sequences in: a multi-page TIFF stack or a folder of images, read lazily with pims.

What is accepted: grey-scale frames of integers (uint8, uint16, int16, ...) or real floats
(a Kerr difference image), at least 2 frames of at least 8 × 8 pixels, all of one shape. What
is refused, with one line that says how to convert: colour (RGB/RGBA) frames, complex or
boolean pixels, stacks with more axes (channels, z), a single frame, an empty folder, a path
that does not exist.

The pixel size and the frame interval, when the command line does not give them, come from the
movie itself: first a sidecar ``<movie>.json`` (``pixel_size_m``, ``frame_interval_s``;
written by ``skygas render``), then a TIFF's ImageJ metadata (``unit`` with the resolution
tags, ``finterval`` in seconds). Where each came from is recorded.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from skygas.core.errors import InputError

#: the image files a folder is read from
IMAGE_SUFFIXES = (".tif", ".tiff", ".png", ".jpg", ".jpeg", ".bmp")
STACK_SUFFIXES = (".tif", ".tiff")
#: metres per length unit, as ImageJ writes units
_UNITS = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "μm": 1e-6, "micron": 1e-6, "nm": 1e-9}
_CONVERT = (
    "convert it to a grey-scale stack first, e.g. in Fiji (Image ▸ Type ▸ 16-bit) or in Python: "
    "tifffile.imwrite('grey.tif', stack.mean(axis=-1).astype('uint16'))"
)


@dataclass
class Movie:
    """An opened image sequence.

    ``frames``: the pims sequence (``frames[i]`` a 2-D array); ``path``; ``n_frames``;
    ``shape`` (rows, columns); ``dtype``; ``pixel_size`` [m] and ``frame_interval`` [s] found in
    the movie (None if not) with ``sources`` saying where from; ``files`` the files read.
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
        """Frame ``i`` as a float64 array (rows, columns), refused if it differs from the first."""
        image = np.asarray(self.frames[i])
        if image.shape != self.shape:
            name = self.files[i] if len(self.files) == self.n_frames else f"frame {i}"
            raise InputError(
                "MOVIE",
                str(name),
                f"frames of one shape {self.shape} (this one is {image.shape})",
                "crop or resample the images to one size",
            )
        image = image.astype(float)
        if not np.all(np.isfinite(image)):
            raise InputError(
                "MOVIE",
                str(self.path),
                f"finite pixel values (frame {i} holds NaN or infinities)",
                "replace them, e.g. by the frame's median",
            )
        return image

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


def _image_files(folder: Path) -> list[Path]:
    return sorted(p for p in folder.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES and p.is_file())


def open_movie(path: str | Path) -> Movie:
    """Open the TIFF stack or folder of images at ``path`` (see the module docstring).

    Parameters
    ----------
    path : str or Path
        A ``.tif``/``.tiff`` stack, or a folder of ``.tif``, ``.png``, ``.jpg`` or ``.bmp``
        images read in name order.

    Returns
    -------
    Movie
        The opened sequence (frames are read when asked for).

    Raises
    ------
    InputError
        For a missing path, an empty folder, another file type, an unreadable file, colour,
        complex or boolean pixels, a single frame or frames smaller than 8 × 8.
    """
    import pims

    path = Path(path)
    if not path.exists():
        raise InputError(
            "MOVIE", str(path), "an existing TIFF stack or folder of images", "check the path"
        )
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
            return open_movie(files[0])  # a folder holding one stack
        opener = lambda: pims.ImageSequence([str(f) for f in files])  # noqa: E731
    elif path.suffix.lower() in STACK_SUFFIXES:
        files = [path]
        opener = lambda: pims.TiffStack(str(path))  # noqa: E731
    else:
        raise InputError(
            "MOVIE",
            str(path),
            "a TIFF stack (.tif, .tiff) or a folder of images",
            "export the movie as a TIFF stack (Fiji: File ▸ Save As ▸ Tiff...)",
        )
    try:
        frames = opener()
        first = np.asarray(frames[0])
    except InputError:
        raise
    except Exception as err:  # pims and tifffile raise many kinds for a damaged file
        raise InputError(
            "MOVIE",
            str(path),
            f"a readable image file ({type(err).__name__}: {err})",
            "check that the file is a complete TIFF or image",
        ) from None
    _check_pixels(path, first)
    n = len(frames)
    if n < 2:
        raise InputError(
            "MOVIE",
            str(path),
            f"a movie of at least 2 frames (this one has {n})",
            "give the whole image sequence; one frame has no motion to track",
        )
    movie = Movie(frames, path, n, first.shape, first.dtype, files=files)
    _read_scales(movie)
    return movie


def _check_pixels(path: Path, first: np.ndarray) -> None:
    dtype = first.dtype
    if first.ndim == 3 and first.shape[-1] in (3, 4):
        raise InputError(
            "MOVIE",
            str(path),
            f"grey-scale frames (these are colour, shape {first.shape})",
            _CONVERT,
        )
    if first.ndim != 2:
        raise InputError(
            "MOVIE",
            str(path),
            f"a stack of 2-D grey-scale frames (each frame here has shape {first.shape})",
            "save one channel and one z-plane as a plain T × Y × X stack",
        )
    if not (np.issubdtype(dtype, np.integer) or np.issubdtype(dtype, np.floating)):
        raise InputError(
            "MOVIE",
            str(path),
            f"integer or real floating-point pixels (these are {dtype})",
            "take the magnitude or the real part, e.g. numpy.abs(stack).astype('float32')",
        )
    if min(first.shape) < 8:
        raise InputError(
            "MOVIE", str(path), f"frames of at least 8 × 8 pixels (these are {first.shape})"
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
            with tifffile.TiffFile(movie.path) as tif:
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
