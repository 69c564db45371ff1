"""The time-step refusal and the dt-versus-dt/2 check."""

import pytest

from skygas.core.errors import InputError
from skygas.runs.config import parse_config
from skygas.runs.timestep import check_config_time_step

CONFIG = {
    "seed": 4,
    "temperature": 300.0,
    "duration": 2e-9,
    "geometry": {"kind": "chamber", "chamber_diameter": 400e-9, "closed": True},
    "skyrmions": {"random_count": 12, "min_separation": 1.1},
}


def test_suggested_step_passes_and_a_step_near_the_limit_fails():
    """The demonstration's 45 skyrmions in the 1024 nm chamber at 300 K, with the default
    tolerance (1 % of a diameter over 2 ns)."""
    from skygas.commands.simulate import default_demo_config

    config = default_demo_config()
    good = check_config_time_step(config)
    assert good.passed and good.skyrmions_compared == 45
    assert good.time_step <= 0.1 * good.relaxation_time
    coarse = check_config_time_step(config, time_step=0.8 * good.relaxation_time)
    assert not coarse.passed
    # halving a larger step changes more: the pathwise difference grows with the step
    assert coarse.max_difference > 3 * good.max_difference


def test_step_above_the_relaxation_limit_is_refused_before_running():
    config = parse_config({**CONFIG, "time_step": 5e-9})
    with pytest.raises(InputError, match="time_step"):
        config.build()
