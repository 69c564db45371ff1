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
