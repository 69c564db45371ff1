"""The demo writes its figures and a result file with parameters, seed and version."""

import argparse
import json

import numpy as np
import pytest
from PIL import Image

from skygas._version import __version__
from skygas.cli import _COMMAND_MODULES
from skygas.commands.sc import register
from skygas.core.errors import InputError
from skygas.sc import DelayIsolator, ShuffleBuffer, run_demo, squaring_curve


def test_squaring_curve_gives_p_then_p_squared():
    p = np.linspace(0, 1, 6)
    curve = squaring_curve(ShuffleBuffer(64), p, 4096, n_trials=8, seed=1)
    # x AND x is x itself: exactly its p-value. 8 x 4096 bits: the binomial error of the mean
    # is below 0.004, so 0.02 is a safe band for both curves.
    assert np.allclose(curve["identical_inputs"], p, atol=0.02)
    assert np.allclose(curve["decorrelated_inputs"], p**2, atol=0.02)


def test_run_demo_writes_figures_and_provenance(tmp_path):
    summary = run_demo(
        tmp_path, seed=5, n_bits=512, decorrelators=[DelayIsolator(1), ShuffleBuffer(32)]
    )
    record = json.loads((tmp_path / "summary.json").read_text())
    assert record["skygas_version"] == __version__ and record["seed"] == 5
    assert record["parameters"]["n_bits"] == 512
    for name in record["figures"].values():
        assert (tmp_path / name).stat().st_size > 1000
        with Image.open(tmp_path / name) as png:  # provenance in the PNG's text chunks
            assert png.text["seed"] == "5" and png.text["skygas_version"] == __version__
            assert png.text["config_hash"] == record["config_hash"]
            assert json.loads(png.text["config_json"])["n_bits"] == 512
    names = [row["name"] for row in summary["comparison"]]
    assert names == ["delay isolator (k=1)", "shuffle buffer (D=32)"]
    telegraph = {row["name"]: row["telegraph"]["scc"] for row in summary["comparison"]}
    assert telegraph["shuffle buffer (D=32)"] < telegraph["delay isolator (k=1)"]


def _parser():
    # Only this command group: the top-level CLI also imports the other groups' modules.
    parser = argparse.ArgumentParser(prog="skygas")
    register(parser.add_subparsers(dest="command", required=True))
    return parser


def test_cli_is_registered_and_runs_the_demo(tmp_path):
    assert "skygas.commands.sc" in _COMMAND_MODULES
    out = tmp_path / "demo"
    args = _parser().parse_args(["sc", "demo", "--out", str(out), "--seed", "3", "--n-bits", "256"])
    assert args.func(args) == 0
    assert json.loads((out / "summary.json").read_text())["seed"] == 3
    assert (out / "report.html").stat().st_size > 10_000
    bad = _parser().parse_args(["sc", "demo", "--out", str(out), "--n-bits", "10"])
    with pytest.raises(InputError) as err:
        bad.func(bad)
    assert err.value.field == "--n-bits"


def test_squaring_error_after_a_deep_shuffle_matches_the_ideal_reshuffle_limit():
    from skygas.sc import bernoulli_stream, ideal_reshuffle_squaring_error, p_value

    p, n_bits, trials = 0.6, 4096, 400
    x = bernoulli_stream(p, n_bits, shape=(trials,), seed=21)
    copy = ShuffleBuffer(256)(x, seed=22)
    rms = np.sqrt(np.mean((p_value(x & copy) - p * p) ** 2))
    # 400 trials: the RMS itself has a relative standard error of about 1/sqrt(800) = 3.5%.
    assert abs(rms / ideal_reshuffle_squaring_error(p, n_bits) - 1) < 0.15
    # ... and it is clearly above the binomial limit of two independent inputs.
    assert rms > 1.1 * np.sqrt(p**2 * (1 - p**2) / n_bits)
