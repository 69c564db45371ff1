"""The calibration the report and CLI tests read (S6 on 2 nm cells, with its checks and validation).

Session-scoped, so one run per test worker; every test that reads it is in
test_calibrate_cli.py, and ``--dist loadscope`` keeps a module on one worker, so the suite makes
it once (with its tests in two modules, two workers made it twice). A test that reads it belongs
in that module.
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
