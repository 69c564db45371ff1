"""Study files: parameters, samplers and the checks made before anything runs."""

from __future__ import annotations

import sys

import pytest

from skygas.core.errors import InputError
from skygas.optimize.spec import load_study, parse_study


def _study(space: dict, device: str = "analytic", base: dict | None = None, **head) -> dict:
    return {
        "study": {"device": device, **head},
        "base": base or {},
        "space": space,
        "objectives": [{"expression": "f" if device == "analytic" else "correlation"}],
    }


def test_ranges_choices_and_log_scales_become_optuna_distributions():
    study = parse_study(
        _study(
            {
                "x": {"low": 0.1, "high": 10.0, "log": True},
                "y": {"low": -1.0, "high": 1.0, "step": 0.5},
                "z": {"low": -3, "high": 3},
                "shape": {"choices": ["a", "b"]},
            }
        )
    )
    kinds = {p.field: type(p.distribution()).__name__ for p in study.parameters}
    assert kinds == {
        "x": "FloatDistribution",
        "y": "FloatDistribution",
        "z": "IntDistribution",
        "shape": "CategoricalDistribution",
    }
    assert study.parameters[0].distribution().log
    assert study.sampler == "tpe"
    config = study.config({"x": 2.0, "z": 1, "shape": "b"}, seed=7)
    assert (config.x, config.z, config.shape, config.seed) == (2.0, 1, "b", 7)
    # each trial's seeds depend on the study's seed and the trial only
    assert study.run_seeds(3, 2) == study.run_seeds(3, 2) != study.run_seeds(4, 2)
    assert study.run_seeds(3, 2) != study.run_seeds(3, 2, stage=1)


def test_the_fingerprint_follows_what_defines_the_trials():
    one = parse_study(_study({"x": {"low": 0.0, "high": 1.0}}))
    assert one.fingerprint() == parse_study(_study({"x": {"low": 0.0, "high": 1.0}})).fingerprint()
    assert one.fingerprint() != parse_study(_study({"x": {"low": 0.0, "high": 2.0}})).fingerprint()
    assert (
        one.fingerprint()
        != parse_study(_study({"x": {"low": 0.0, "high": 1.0}}), seed=1).fingerprint()
    )
    # re-evaluation does not change the trials
    again = parse_study(_study({"x": {"low": 0.0, "high": 1.0}}, reevaluate=2))
    assert one.fingerprint() == again.fingerprint()


@pytest.mark.parametrize(
    ("space", "head", "expected"),
    [
        ({"x": {"low": 0.0, "high": 0.0}}, {}, "the range is empty"),
        ({"x": {"low": 1.0, "high": 0.0}}, {}, "the range is empty"),
        ({"x": {"low": 0.0, "high": 1.0, "log": True}}, {}, "log range"),
        ({"x": {"low": 0.0, "high": 1.0, "step": 2.0}}, {}, "space.x.step"),
        ({"x": {"choices": []}}, {}, "space.x.choices"),
        ({"x": {"low": 0.0}}, {}, "space.x.high"),
        ({"seed": {"low": 0, "high": 3}}, {}, "space.seed"),
        ({"nope": {"low": 0, "high": 3}}, {}, "space.nope"),
        ({"x": {"low": 0.0, "high": 1.0}}, {"sampler": "cmaes"}, "study.sampler"),
        ({"x": {"low": 0.0, "high": 1.0}}, {"replicas": 0}, "study.replicas"),
        ({"x": {"low": 0.0, "high": 1.0}}, {"trials": 3}, "study.trials"),
        ({"x": {"low": -1e308, "high": 1e308}}, {}, "space.x = .*width high − low"),
        ({"x": {"low": 0.0, "high": 1e200}}, {}, "space.x.high = 1e.200: expected a number <="),
        ({"x": {"low": 0.0, "high": 1.0}}, {"replicas": 10**9}, "study.replicas = 1000000000"),
        ({"x": {"low": 0.0, "high": 1.0}}, {"reevaluate": 10**9}, "study.reevaluate = "),
        ({"x": {"low": 0.0, "high": 1.0}}, {"reevaluate_replicas": 10**9}, "from 1 to 1000"),
        ({"x": {"low": 0.0, "high": 1.0}}, {"startup_trials": 10**9}, "study.startup_trials"),
    ],
)
def test_bad_spaces_and_settings_are_refused(space, head, expected):
    with pytest.raises(InputError, match=expected):
        parse_study(_study(space, **head))


def test_every_corner_of_the_space_is_validated_before_any_run():
    # a conduit wider than any chamber: the range's end is at fault, and named
    with pytest.raises(InputError, match="space.device.conduit_width.high = 2e-06: expected a w"):
        parse_study(
            _study(
                {
                    "device.chamber_diameter": {"low": 5e-7, "high": 1e-6},
                    "device.conduit_width": {"low": 5e-8, "high": 2e-6},
                },
                device="reshuffler",
                base={"preset": "paper"},
            )
        )
    # each end fits the middle of the other range, but the widest conduit not the smallest
    # chamber: the corner is named
    with pytest.raises(InputError, match="corner of \\[space\\]"):
        parse_study(
            _study(
                {
                    "device.chamber_diameter": {"low": 5e-7, "high": 1e-6},
                    "device.conduit_width": {"low": 5e-8, "high": 7e-7},
                },
                device="reshuffler",
                base={"preset": "paper"},
            )
        )
    with pytest.raises(InputError, match="space.noise.low = -1.0: expected a number >= 0"):
        parse_study(_study({"noise": {"low": -1.0, "high": 1.0}}))


def test_the_gaussian_process_sampler_without_torch_is_refused_in_one_line(monkeypatch):
    monkeypatch.setitem(sys.modules, "torch", None)  # import torch raises ImportError
    with pytest.raises(InputError, match="needs PyTorch"):
        parse_study(_study({"x": {"low": 0.0, "high": 1.0}}, sampler="gp"))


def test_the_examples_are_valid_studies():
    from pathlib import Path

    folder = Path(__file__).resolve().parents[2] / "examples" / "optimize"
    names = sorted(p.name for p in folder.glob("*.toml"))
    assert names == [
        "neuron-rate.toml",
        "reservoir-xor.toml",
        "reshuffler-front.toml",
        "reshuffler-rate.toml",
    ]
    samplers = {name: load_study(folder / name).sampler for name in names}
    assert samplers["reshuffler-front.toml"] == "nsga2"


@pytest.mark.parametrize("name", ["reshuffler", "neuron", "reservoir", "analytic"])
def test_every_device_prices_one_run_before_anything_is_built(name):
    from skygas.optimize.devices import device

    dev = device(name)
    estimate = dev.estimate(dev.point(dict(dev.default_base), {}, "base"))
    assert estimate.steps >= 1 and estimate.memory >= 0 and estimate.seconds >= 0
