"""Ctrl-C reaches every command, also when the shell started it in the background.

A non-interactive shell starts ``skygas ... &`` with SIGINT ignored; the command line takes it
back, so that ``kill -INT`` stops a track or an infer as it stops a device run (exit 130).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import numpy as np

from skygas import cli


def test_an_ignored_sigint_is_taken_back():
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        cli._honour_interrupts()
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    finally:
        signal.signal(signal.SIGINT, previous)


def test_infer_started_with_sigint_ignored_stops_on_sigint(tmp_path):
    rng = np.random.default_rng(0)
    frames, n = 4000, 40
    xy = np.cumsum(rng.normal(0, 0.5, (frames, n, 2)), axis=0) + 500
    f, p = np.meshgrid(np.arange(frames), np.arange(n), indexing="ij")
    rows = np.column_stack([f.ravel(), p.ravel(), xy.reshape(-1, 2)])
    np.savetxt(tmp_path / "tracks.csv", rows, delimiter=",", header="frame,particle,x,y",
               comments="", fmt=["%d", "%d", "%.4f", "%.4f"])  # fmt: skip
    args = ["infer", "tracks.csv", "--pixel-size", "1e-8", "--frame-interval", "1e-3",
            "--temperature", "300", "--out", "out"]  # fmt: skip
    proc = subprocess.Popen(
        [sys.executable, "-m", "skygas.cli", *args],
        cwd=tmp_path,
        env={**os.environ, "PYTHONWARNINGS": "ignore"},
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN),
    )
    time.sleep(6)  # past start-up, into the inference
    assert proc.poll() is None, "infer ended before it could be interrupted"
    proc.send_signal(signal.SIGINT)
    _, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 130, stderr
    assert "interrupted" in stderr
    assert not (tmp_path / "out" / "model.toml").exists()
