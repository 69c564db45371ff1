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
    """The folder of ``skygas calibrate S6`` (model.toml, summary.json, report.html, …).

    With 6 pair distances instead of the default 11 (the pair law is the largest stage: a
    third of the solver time less); every check and the validation run as by default.
    """
    pytest.importorskip("magnumnp")
    from skygas import cli

    out = tmp_path_factory.mktemp("cal") / "s6"
    argv = ["calibrate", "S6", "--pair-distances", "6", "--out", str(out), "--quiet"]
    assert cli.main(argv) == 0
    return out
