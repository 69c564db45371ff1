"""The calibration that several modules read (S6 on 2 nm cells, with its checks and validation).

Session-scoped and defined here, so that every module that reads it shares one run per test
worker (two modules on two workers still make two runs).
"""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def calibrated(tmp_path_factory):
    """The folder of ``skygas calibrate S6`` (model.toml, summary.json, report.html, …)."""
    pytest.importorskip("magnumnp")
    from skygas import cli

    out = tmp_path_factory.mktemp("cal") / "s6"
    assert cli.main(["calibrate", "S6", "--out", str(out), "--quiet"]) == 0
    return out
