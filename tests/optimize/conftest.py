"""Study files on the analytic device (:mod:`skygas.optimize.analytic`): cheap trials."""

from __future__ import annotations

import textwrap

import pytest

ANALYTIC_STUDY = textwrap.dedent("""
    [study]
    device = "analytic"
    seed = 4
    startup_trials = 8
    {study}

    [base]
    noise = {noise}
    delay = {delay}

    [space]
    x = {{ low = -1.0, high = 1.0 }}
    y = {{ low = -1.0, high = 1.0 }}
    {space}

    [[objectives]]
    name = "f"
    expression = "f"
    {objectives}
""")


@pytest.fixture
def write_study(tmp_path):
    """Write a study file of the analytic device; returns its path."""

    def write(name="study.toml", *, study="", space="", objectives="", noise=0.0, delay=0.0):
        path = tmp_path / name
        text = ANALYTIC_STUDY.format(
            study=study, space=space, objectives=objectives, noise=noise, delay=delay
        )
        path.write_text(text)
        return path

    return write
