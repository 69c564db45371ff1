"""The disk layer of the set-up memo (skygas.core.disk_cache): what a new process loads from disk is
bit for bit what it would have built, read-only, and found only by the code that wrote it.

Each test points the cache at its own empty directory. ``clear_memos()`` stands for a new
process (the in-process memo forgets everything; the disk keeps it); one test uses a real
second process.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest

from skygas.core import disk_cache
from skygas.core.memo import clear_memos, memo_stats, set_memo_enabled
from skygas.fields.current import solve_current
from skygas.fields.wall_field import Grid, WallField
from skygas.reshuffler.device import ReshufflerGeometry, drift_field_on_grid

SMALL = ReshufflerGeometry(chamber_diameter=500e-9)
GRID = Grid(-400.0, -700.0, 2.4, 340, 590)
J = 1.7e11


@pytest.fixture
def cache_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("SKYGAS_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.delenv("SKYGAS_DISK_CACHE", raising=False)
    clear_memos()
    yield tmp_path / "cache"
    clear_memos()


def setup_values():
    """The three persisted set-up values of SMALL, as a run builds them."""
    wall = WallField.build(SMALL.device_outline(), 2.4, 60.0)
    solution = solve_current(SMALL.chamber(), J, cell_size=5e-9)
    drift = drift_field_on_grid(SMALL, solution, GRID, 1.3e-10)
    return wall, solution, drift


def arrays(values):
    wall, solution, drift = values
    return [
        wall.wall_distance,
        wall.normal_x,
        wall.normal_y,
        wall.domain_distance,
        solution._jx,
        solution._jy,
        solution._phi,
        *drift,
    ]


def uncached():
    previous = set_memo_enabled(False)
    try:
        return setup_values()
    finally:
        set_memo_enabled(previous)


def assert_same_arrays(a, b):
    for x, y in zip(arrays(a), arrays(b), strict=True):
        assert x.dtype == y.dtype and x.shape == y.shape
        assert np.array_equal(x, y, equal_nan=True)


def disk_hits() -> dict[str, int]:
    return {
        name: memo_stats()[name]["disk_hits"]
        for name in ("wall_field", "current", "drift_unit_sample")
    }


def test_loaded_setup_is_identical_read_only_and_not_rebuilt(cache_dir):
    fresh = uncached()
    built = setup_values()
    assert disk_hits() == {"wall_field": 0, "current": 0, "drift_unit_sample": 0}
    assert any(cache_dir.rglob("output.pkl"))
    clear_memos()  # a new process: only the disk remembers
    loaded = setup_values()
    assert disk_hits() == {"wall_field": 1, "current": 1, "drift_unit_sample": 1}
    assert sum(s["built"] for s in memo_stats().values()) <= 2  # force tables, wall channels
    assert_same_arrays(fresh, built)
    assert_same_arrays(fresh, loaded)
    wall, solution, _ = loaded
    with pytest.raises(ValueError):
        wall.wall_distance[0, 0] = 1.0
    # the solution's per-call values (here: J, and what scales with it) are recomputed
    assert solution.current_density == J


def test_another_process_loads_what_this_one_built(cache_dir):
    """The real use: a second Python process (as a Dask worker is) finds the entries."""
    built = setup_values()
    script = textwrap.dedent(f"""
        import numpy as np
        from skygas.core.memo import memo_stats
        from skygas.fields.wall_field import WallField
        from skygas.reshuffler.device import ReshufflerGeometry
        wall = WallField.build(ReshufflerGeometry(chamber_diameter=500e-9).device_outline(),
                               2.4, 60.0)
        assert memo_stats()["wall_field"]["disk_hits"] == 1, memo_stats()
        np.save({str(cache_dir.parent / "wall.npy")!r}, wall.wall_distance)
    """)
    subprocess.run([sys.executable, "-c", script], check=True)
    other = np.load(cache_dir.parent / "wall.npy")
    assert np.array_equal(other, built[0].wall_distance)


def test_code_of_another_version_does_not_find_the_entries(cache_dir, monkeypatch):
    setup_values()
    clear_memos()
    monkeypatch.setattr(disk_cache, "_fingerprint", "0" * 64)  # as after any source change
    setup_values()
    assert disk_hits() == {"wall_field": 0, "current": 0, "drift_unit_sample": 0}


def test_fingerprint_covers_the_package_source():
    fingerprint = disk_cache.code_fingerprint()
    assert len(fingerprint) == 64 and int(fingerprint, 16) >= 0
    assert fingerprint == disk_cache.code_fingerprint()


def test_an_unreadable_entry_is_built_again(cache_dir, caplog):
    fresh = uncached()
    setup_values()
    for path in cache_dir.rglob("output.pkl"):
        path.write_bytes(b"not a pickle")
    clear_memos()
    again = setup_values()
    assert "Exception while loading" in caplog.text
    assert disk_hits() == {"wall_field": 0, "current": 0, "drift_unit_sample": 0}
    assert_same_arrays(fresh, again)


def test_turned_off_writes_nothing(cache_dir, monkeypatch):
    monkeypatch.setenv("SKYGAS_DISK_CACHE", "0")
    assert disk_cache.location() is None
    setup_values()
    assert not cache_dir.exists()


def test_a_location_that_cannot_be_a_directory_warns_once_and_runs(cache_dir, monkeypatch):
    blocker = cache_dir.parent / "a-file"
    blocker.write_text("")
    monkeypatch.setenv("SKYGAS_CACHE_DIR", str(blocker / "cache"))
    monkeypatch.setattr(disk_cache, "_warned", False)
    fresh = uncached()
    with pytest.warns(RuntimeWarning, match="disk cache off"):
        values = setup_values()
    assert_same_arrays(fresh, values)
