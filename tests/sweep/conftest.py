"""A tiny sweep shared by the sweep tests: 500 nm chambers (a fast current solve), 1 µs runs."""

from __future__ import annotations

import textwrap

import pytest

TINY_SWEEP = textwrap.dedent("""
    [sweep]
    seed = 11
    replicas = 2

    [base]
    preset = "paper"
    duration = 1e-6
    [base.device]
    chamber_diameter = 5e-7
    [base.output]
    trajectory_window = 0.0
    running_points = 20
    [base.current]
    cell_size = 5e-9

    [grid]
    current_density = [1.2e11, 1.7e11]
    "signal.p" = [0.62]
""")


@pytest.fixture
def tiny_sweep_file(tmp_path):
    path = tmp_path / "tiny.toml"
    path.write_text(TINY_SWEEP)
    return path
