"""Small finished runs, made once per test session, for the output tests."""

from __future__ import annotations

import pytest

SIMULATION = {
    "seed": 4,
    "temperature": 300.0,
    "duration": 30e-9,
    "record_interval": 1e-9,
    "material": "S2",
    "geometry": {
        "kind": "chamber",
        "chamber_diameter": 1024e-9,
        "conduit_width": 100e-9,
        "conduit_length": 50e-9,
        "closed": True,
    },
    "skyrmions": {"random_count": 20, "min_separation": 1.5},
}


@pytest.fixture(scope="session")
def simulation_run(tmp_path_factory):
    """A 30 ns closed-chamber run with 20 skyrmions: trajectories.nc and its files."""
    from skygas.runs.config import parse_config
    from skygas.runs.runner import run_simulation

    out = tmp_path_factory.mktemp("simulation")
    run_simulation(parse_config(SIMULATION), out, progress=False)
    return out


@pytest.fixture(scope="session")
def reshuffler_run(tmp_path_factory):
    """A 0.4 µs reshuffler run recording snapshots every 4 ns: reshuffler.nc and its files."""
    from skygas.reshuffler.config import load_reshuffler_config
    from skygas.reshuffler.files import run_reshuffler

    out = tmp_path_factory.mktemp("reshuffler")
    config = load_reshuffler_config(
        overrides={"duration": 0.4e-6, "output.snapshot_interval": 4e-9}
    )
    run_reshuffler(config, out, progress=False)
    return out
