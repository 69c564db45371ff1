"""What every case of the bad-input catalogue checks, shared by its sections (one per command).

A case runs the real command line in a subprocess and must end with exit status 2 (74 for a
disk that is full), exactly one line on stderr starting with ``skygas: error:`` (no traceback,
no library warning), and leave its working folder exactly as it was.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path


def snapshot(folder: Path) -> dict[str, bytes | None]:
    """Every path under ``folder`` with the bytes of the files (None for folders)."""
    return {
        str(p.relative_to(folder)): (p.read_bytes() if p.is_file() else None)
        for p in sorted(folder.rglob("*"))
    }


def run(
    args: list[str], cwd: Path, env: dict | None = None, timeout: float = 120
) -> subprocess.CompletedProcess:
    """``skygas ARGS`` in ``cwd``; warnings are not silenced, so a stray one fails the case."""
    return subprocess.run(
        [sys.executable, "-m", "skygas.cli", *args],
        cwd=cwd,
        env={**os.environ, **(env or {})},
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def assert_one_line(proc: subprocess.CompletedProcess, *expected: str, status: int = 2) -> str:
    """The process ended with ``status`` and one ``skygas: error:`` line holding ``expected``."""
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == status, proc.stderr
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("skygas: error: "), lines[0]
    for text in expected:
        assert text in lines[0], lines[0]
    assert "Traceback" not in proc.stderr
    return lines[0]


def refused(args: list[str], cwd: Path, *expected: str, status: int = 2) -> str:
    """Run ``args`` in ``cwd``: one line holding ``expected``, and the folder left unchanged."""
    before = snapshot(cwd)
    line = assert_one_line(run(args, cwd), *expected, status=status)
    assert snapshot(cwd) == before, "the folder changed"
    return line
