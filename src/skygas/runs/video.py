"""H.264 movies written with ffmpeg, as browsers play them, or one clear error.

ffmpeg (the binary that ``imageio-ffmpeg`` ships) reads raw RGB frames on its standard input.
Its messages are kept, not printed: a successful encoding says nothing, and a failed one
becomes one :class:`OSError` (``ENOSPC`` when the disk is full), which the command line turns
into its one line (exit status 74 with :func:`~skygas.runs.run_driver.write_atomic`, which
also removes the partial file). Used by ``skygas animate`` and ``skygas track``.
"""

from __future__ import annotations

import errno
import os
import subprocess
import tempfile
from collections.abc import Iterable
from pathlib import Path

import numpy as np


def encode_mp4(
    path: Path,
    images: Iterable[np.ndarray],
    size: tuple[int, int],
    fps: int,
    *,
    preset: str = "veryfast",
    crf: int = 32,
) -> None:
    """Encode RGB ``images`` (height, width, 3) uint8 as H.264 MP4 at ``path`` with ffmpeg.

    ``size`` (width, height) [px], multiples of 16; ``fps`` frames per second; the x264
    ``preset`` and constant rate factor ``crf`` (higher: smaller and coarser). ffmpeg's
    messages go to a temporary file, not the terminal; when it fails, the last of them becomes
    the :class:`OSError` raised (``ENOSPC`` for a full disk), and
    :func:`~skygas.runs.run_driver.write_atomic` removes the partial file. ffmpeg runs in a
    process group of its own: a Ctrl-C interrupts Python, which stops ffmpeg and lets the
    interrupt go on.
    """
    import imageio_ffmpeg

    width, height = size
    # yuv420p with the index at the front (+faststart): what browsers play inline
    command = [
        imageio_ffmpeg.get_ffmpeg_exe(),
        "-y",
        "-v",
        "error",
        "-f",
        "rawvideo",
        "-pix_fmt",
        "rgb24",
        "-s",
        f"{width}x{height}",
        "-r",
        str(fps),
        "-i",
        "-",
        "-vcodec",
        "libx264",
        "-pix_fmt",
        "yuv420p",
        "-preset",
        preset,
        "-crf",
        str(crf),
        "-movflags",
        "+faststart",
        str(path),
    ]
    with tempfile.TemporaryFile() as log:
        ffmpeg = subprocess.Popen(
            command,
            stdin=subprocess.PIPE,
            stdout=subprocess.DEVNULL,
            stderr=log,
            process_group=0,
        )
        assert ffmpeg.stdin is not None  # stdin=PIPE
        try:
            for image in images:
                ffmpeg.stdin.write(np.ascontiguousarray(image, dtype=np.uint8).tobytes())
            ffmpeg.stdin.close()
        except BrokenPipeError:  # ffmpeg stopped reading: its log says why
            pass
        except BaseException:  # an error while drawing, or Ctrl-C: stop ffmpeg, pass it on
            ffmpeg.kill()
            ffmpeg.wait()
            raise
        if ffmpeg.wait() != 0:
            log.seek(0)
            raise _ffmpeg_error(log.read().decode(errors="replace"), ffmpeg.returncode)


def _ffmpeg_error(text: str, status: int) -> OSError:
    """The OSError of a failed ffmpeg: ENOSPC for a full disk, else its last message."""
    lines = [line.split("] ", 1)[-1].strip() for line in text.splitlines() if line.strip()]
    for code in (errno.ENOSPC, errno.EDQUOT, errno.EACCES, errno.EROFS):
        if any(os.strerror(code) in line for line in lines):
            return OSError(code, os.strerror(code))
    last = lines[-1] if lines else f"ffmpeg ended with status {status}"
    return OSError(errno.EIO, f"ffmpeg: {last}")
