"""Suite-wide settings."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session", autouse=True)
def private_disk_cache(tmp_path_factory):
    """The device set-up disk cache (skygas.core.disk_cache) of this test session: a fresh
    directory, so no test reads entries another session or the user's own runs left, and no test
    fills the user's cache. Dask workers started by tests inherit it through the environment."""
    mp = pytest.MonkeyPatch()
    mp.setenv("SKYGAS_CACHE_DIR", str(tmp_path_factory.mktemp("skygas-cache")))
    mp.delenv("SKYGAS_DISK_CACHE", raising=False)
    yield
    mp.undo()


def pytest_collection_modifyitems(config, items):
    """Keep together only the tests that share a costly fixture; spread the rest one by one.

    The suite runs on two workers with ``--dist loadgroup`` (Makefile). A test that uses a
    module- or class-scoped fixture (a run whose files several tests read) goes into that
    fixture's group, and so does one that uses a session-scoped fixture of this suite (the
    calibration that several modules read, tests/calibration/conftest.py): the fixture is then
    built once, on one worker. Every other test is handed to whichever worker is free. Kept by
    module instead (``loadscope``), the largest modules decided the suite's length: one worker
    ran on for minutes after the other had finished.
    """
    for item in items:
        info = getattr(item, "_fixtureinfo", None)
        if info is None:
            continue
        shared = sorted(
            f"{d.baseid}::{d.argname}" if d.scope == "session" else item.module.__name__
            for defs in info.name2fixturedefs.values()
            for d in defs
            if d.scope in ("module", "class", "package")
            # the suite's own session fixtures that a test asks for by name (not pytest's,
            # whose baseid is empty, nor the autouse cache directory every test has)
            or (d.scope == "session" and d.baseid and d.argname in info.argnames)
        )
        if shared:
            item.add_marker(pytest.mark.xdist_group(shared[0]))
