"""Cached kernels compiled from other source are deleted before any is loaded."""

from __future__ import annotations

from skygas.core import kernel_cache


def _package(tmp_path):
    cached = tmp_path / "engine" / "__pycache__"
    cached.mkdir(parents=True)
    for name in ("kernel.advance-1.py311.nbi", "kernel.advance-1.py311.1.nbc", "kernel.pyc"):
        (cached / name).write_text("x")
    return cached


def _check(monkeypatch, tmp_path, fingerprint):
    monkeypatch.setattr(kernel_cache, "_package", lambda: tmp_path)
    monkeypatch.setattr(kernel_cache, "code_fingerprint", lambda: fingerprint)
    monkeypatch.setattr(kernel_cache, "_checked", False)
    kernel_cache.drop_stale_kernels()


def test_kernels_of_other_source_are_deleted_and_the_stamp_written(monkeypatch, tmp_path):
    cached = _package(tmp_path)
    _check(monkeypatch, tmp_path, "new")
    assert sorted(p.name for p in cached.iterdir()) == ["kernel.pyc"]  # Python bytecode stays
    assert (tmp_path / "__pycache__" / kernel_cache.STAMP).read_text() == "new"


def test_kernels_of_the_same_source_are_kept(monkeypatch, tmp_path):
    cached = _package(tmp_path)
    stamp = tmp_path / "__pycache__" / kernel_cache.STAMP
    stamp.parent.mkdir()
    stamp.write_text("same")
    _check(monkeypatch, tmp_path, "same")
    assert len(list(cached.iterdir())) == 3
    _check(monkeypatch, tmp_path, "changed")
    assert len(list(cached.iterdir())) == 1
