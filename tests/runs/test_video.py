"""The H.264 writer of animate and track: quiet on success, one OSError on failure."""

from __future__ import annotations

import errno

import numpy as np
import pytest

from skygas.runs.video import _ffmpeg_error, encode_mp4


def _frames(n: int = 5):
    return (np.full((32, 48, 3), 40 * k, np.uint8) for k in range(n))


def test_a_movie_is_written_without_a_word(tmp_path, capfd):
    path = tmp_path / "m.mp4"
    encode_mp4(path, _frames(), (48, 32), 25)
    assert path.stat().st_size > 0
    out, err = capfd.readouterr()
    assert out == "" and err == ""


def test_a_failed_encoding_is_one_oserror_and_no_chatter(tmp_path, capfd):
    with pytest.raises(OSError) as err:
        encode_mp4(tmp_path / "missing" / "m.mp4", _frames(), (48, 32), 25)
    assert "ffmpeg" in str(err.value) or err.value.errno is not None
    assert capfd.readouterr().err == ""


def test_a_full_disk_in_ffmpegs_words_is_enospc():
    text = "[out#0/mp4 @ 0x55] Error writing trailer: No space left on device\n"
    error = _ffmpeg_error(text, 1)
    assert error.errno == errno.ENOSPC
