"""The sanity check of wall escapes counts them against the skyrmion-steps taken."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from skygas.core.errors import InputError
from skygas.engine import Simulation
from skygas.physics.geometry import disk
from skygas.runs import sanity


def _job(escapes: int, moved: int):
    sim = SimpleNamespace(wall_escapes=escapes, skyrmion_steps=moved, time_step=1e-10, step=1)
    return SimpleNamespace(sim=sim)


def test_a_rare_escape_is_accepted_and_a_frequent_one_is_refused(capsys):
    sanity.after_run(_job(7, 40_000_000), strict=True)  # 1.75e-7 per skyrmion-step
    assert capsys.readouterr().err == ""
    with pytest.raises(InputError, match="41 of 40000000 skyrmion-steps"):
        sanity.after_run(_job(41, 40_000_000), strict=True)
    sanity.after_run(_job(41, 40_000_000), strict=False)
    assert capsys.readouterr().err.startswith("skygas: warning: time_step = ")


def test_strict_refuses_during_the_run_once_the_rate_is_judged():
    sanity.during_run(_job(5, 999_999), strict=True)  # too few skyrmion-steps to judge
    sanity.during_run(_job(5, 2_000_000), strict=False)  # only under --strict
    with pytest.raises(InputError, match="wall escapes per skyrmion-step"):
        sanity.during_run(_job(5, 2_000_000), strict=True)


def test_the_engine_counts_skyrmion_steps_exactly():
    sim = Simulation(disk(diameter=1e-6), "S2", temperature=300.0, seed=1)
    d = sim.thiele.skyrmion_diameter_internal
    sim.state.insert_nm(np.array([[0.0, 0.0], [3 * d, 0.0], [0.0, 3 * d]]))
    sim.run(40 * sim.time_step)
    assert sim.skyrmion_steps == 3 * 40
    saved = sim.state_dict()
    again = Simulation(disk(diameter=1e-6), "S2", temperature=300.0, seed=1)
    again.load_state_dict(saved)
    assert again.skyrmion_steps == 120
