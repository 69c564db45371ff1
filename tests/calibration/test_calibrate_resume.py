"""`skygas calibrate` interrupted and resumed gives the same bits as a run left alone.

Apart from test_calibrate_cli.py (the module of the shared calibration): this test makes its own
two calibrations, and in a module of its own it can run on the other test worker meanwhile.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

pytest.importorskip("magnumnp")

from skygas import cli  # noqa: E402

pytestmark = pytest.mark.slow


def test_interrupted_and_resumed_gives_the_same_bits(tmp_path):
    # cells of 2.4 nm (the coarsest S6 allows): a quarter faster, and bits are bits
    args = ["S6", "--no-validate", "--no-mesh-check", "--quiet", "--checkpoint-seconds", "0"]
    args += ["--cell-size", "2.4e-9"]
    straight = tmp_path / "straight"
    assert cli.main(["calibrate", *args, "--out", str(straight)]) == 0
    broken = tmp_path / "broken"
    process = subprocess.Popen(
        [sys.executable, "-m", "skygas.cli", "calibrate", *args, "--out", str(broken)],
        stderr=subprocess.PIPE,
        text=True,
    )
    checkpoint = broken / "checkpoint.npz"
    deadline = time.time() + 120
    while time.time() < deadline and process.poll() is None:
        if checkpoint.exists():
            with np.load(checkpoint) as data:
                if len(json.loads(str(data["results"]))) >= 6:
                    break
        time.sleep(0.2)
    process.send_signal(signal.SIGINT)
    assert process.wait(timeout=120) == 130, process.stderr.read()
    assert checkpoint.exists() and not (broken / "model.toml").exists()
    assert cli.main(["calibrate", *args, "--out", str(broken), "--resume"]) == 0
    a = json.loads((straight / "summary.json").read_text())
    b = json.loads((broken / "summary.json").read_text())
    for key in ("pair", "wall_short_range"):
        assert a[key]["energy_J"] == b[key]["energy_J"]
        assert a[key]["table_force_N"] == b[key]["table_force_N"]
    assert a["isolated"] == b["isolated"]
