"""One run per output folder: ``OUT/.skygas.lock``, held for the run's whole life.

A run takes an exclusive operating-system lock (``flock``) on the lock file before it looks
at or writes anything in its folder, and keeps it until it ends. A second run into the same
folder, from this machine, is refused at once with one line that names the holder (its
command, process id and start time, which the holder writes into the lock file). The lock
dies with its process, however it ends (a kill -9 too), so a lock left by a dead process is
taken over by the next run without a word; the file itself is removed when the run ends.

The lock is re-entrant within a process: the command line takes it for the command's folder,
and the run driver (:func:`skygas.runs.run_driver.drive`) takes it for library callers, once.
On a system without ``fcntl`` (Windows) folders are not locked.
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from skygas.core.errors import InputError

try:
    import fcntl
except ImportError:  # pragma: no cover (Windows)
    fcntl = None  # type: ignore[assignment]

#: The lock file's name in a run folder.
LOCK = ".skygas.lock"

# folders whose lock this process holds: resolved path -> how many holders (re-entrance)
_held: dict[Path, int] = {}


def _holder_line(path: Path) -> str:
    """Who holds the lock at ``path``, in words (what the holder wrote into it)."""
    try:
        holder = json.loads(path.read_text())
        return (
            f"`skygas {holder['command']}`, process {holder['pid']}, started {holder['started_at']}"
        )
    except (OSError, ValueError, KeyError, TypeError):
        return "another process"


def _take(path: Path) -> int | None:
    """Open and lock ``path``; return the file descriptor, or None if another process holds it.

    A lock file removed by its previous holder between our open and our lock is opened again
    (its inode changed), so that two runs never hold two different files.
    """
    assert fcntl is not None
    while True:
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            return None
        try:
            same = os.stat(path).st_ino == os.fstat(fd).st_ino
        except FileNotFoundError:
            same = False
        if same:
            return fd
        os.close(fd)  # the holder removed it as we opened it: take the new one


@contextmanager
def hold(out: str | Path, command: str, *, beside: bool = False) -> Iterator[None]:
    """Hold the lock of folder ``out`` (created if need be) while the block runs.

    Parameters
    ----------
    out
        The run's output folder.
    command
        The command that runs (``"reshuffle"``), written into the lock for whoever finds it
        held.
    beside
        Keep the lock file beside the folder (``.NAME.skygas.lock`` in its parent) instead of
        inside it, and do not create the folder: for a sweep store, which is created under
        another name and renamed into place.

    Raises
    ------
    InputError
        If another process holds the folder's lock.
    """
    folder = Path(out)
    if beside:
        folder.parent.mkdir(parents=True, exist_ok=True)
    else:
        folder.mkdir(parents=True, exist_ok=True)
    key = folder.resolve()
    if fcntl is None or key in _held:
        _held[key] = _held.get(key, 0) + 1
        try:
            yield
        finally:
            _held[key] -= 1
            if not _held[key]:
                del _held[key]
        return
    path = folder.parent / f".{folder.name}{LOCK}" if beside else folder / LOCK
    fd = _take(path)
    if fd is None:
        raise InputError(
            "--out",
            str(out),
            f"a folder that no other run is using ({_holder_line(path)} is writing into it)",
            "wait for that run to end, or choose another --out",
        )
    holder = {
        "command": command,
        "pid": os.getpid(),
        "started_at": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
    }
    os.ftruncate(fd, 0)
    os.write(fd, json.dumps(holder).encode())
    _held[key] = 1
    try:
        yield
    finally:
        del _held[key]
        # removed while still locked: a process that opened it meanwhile sees a stale inode
        path.unlink(missing_ok=True)
        os.close(fd)
