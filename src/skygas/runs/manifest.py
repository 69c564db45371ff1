"""``OUT/manifest.json``: which command wrote an output folder, with which configuration.

Every command that writes into an ``--out`` folder records there, before it starts, the
command (``"reshuffle"``, ``"sc demo"``), its command line, the skygas version, a hash of its
validated configuration and the start time; the end time is added once its results are
written. The manifest is how a folder's results are kept apart:

- a folder whose manifest names **another command** is refused (its files would be mixed with
  this command's);
- a folder with **finished results** is refused unless ``--overwrite`` is given (the command's
  own result files are then replaced; nothing else in the folder is deleted);
- ``--overwrite`` on a folder **without a manifest** that holds files is refused: nothing says
  which of them the command wrote;
- ``--resume`` continues an unfinished run of the same configuration (the checkpoint's own
  fingerprint, :mod:`skygas.runs.run_driver`, says whether it belongs to it); on a finished
  run it has nothing to do (:class:`~skygas.core.errors.RunFinished`).

A sweep store is not a run folder: it records its sweep's fingerprint and the version in its
own attributes (:mod:`skygas.sweep.store`), and resumes by design.
"""

from __future__ import annotations

import hashlib
import json
import time
from pathlib import Path
from typing import Any

from skygas._version import __version__
from skygas.core.errors import InputError, RunFinished

MANIFEST = "manifest.json"

# The command being run by the command line (set by skygas.cli.main), and whether a manifest
# has been written for it yet; None when the library is used from Python.
_context: dict[str, Any] = {"command": None, "argv": None, "written": False}


def set_command(command: str | None, argv: list[str] | None) -> None:
    """Name the command-line command now running (``None``: none)."""
    _context.update(command=command, argv=argv, written=False)


def current_argv() -> list[str] | None:
    """The arguments of the command-line command now running (``None`` from Python)."""
    argv = _context["argv"]
    return None if argv is None else list(argv)


def current_command(default: str) -> str:
    """The running command-line command, or ``default`` (a job's name) from Python."""
    return _context["command"] or default


def read(out: str | Path) -> dict | None:
    """The manifest of folder ``out``, or None if it has none (or it cannot be read)."""
    try:
        return json.loads((Path(out) / MANIFEST).read_text())
    except (OSError, ValueError):
        return None


def claim(
    out: str | Path,
    command: str,
    config_hash: str | None = None,
    *,
    overwrite: bool = False,
    resume: bool = False,
) -> dict | None:
    """Check that ``command`` may write into ``out`` (see the module docstring).

    Returns the folder's manifest (None without one). Raises :class:`InputError` with one line
    otherwise.
    """
    found = read(out)
    if found is None:
        if overwrite and (held := _files_in(out)):
            # nothing says which of them this command wrote: none is deleted
            raise InputError(
                "--out",
                str(out),
                f"a folder whose files --overwrite may replace (it holds {held[0]} and "
                f"{len(held) - 1} more file(s) but no {MANIFEST} saying what wrote them)",
                "choose another --out, or empty it first",
            )
        return None
    other = found.get("command")
    if other != command:
        raise InputError(
            "--out",
            str(out),
            f"a folder for `skygas {command}` results (it holds the results of `skygas {other}`)",
            "choose another --out",
        )
    finished = found.get("finished_at") is not None
    if finished and resume and not overwrite:
        if config_hash is None:
            return found  # the run driver decides, knowing the configuration
        if found.get("config_hash") == config_hash:
            raise RunFinished(out, command)
    if finished and not overwrite:
        raise InputError(
            "--out",
            str(out),
            f"a folder without finished results (a finished `skygas {command}` run is there)",
            "add --overwrite to replace them, or choose another --out",
        )
    if resume and config_hash is not None and found.get("config_hash") not in (None, config_hash):
        raise InputError(
            "--resume",
            str(out),
            "a folder written by the same configuration and "
            "options (this one belongs to another run)",
            "choose another --out, or add --overwrite to start again",
        )
    return found


def _files_in(out: str | Path) -> list[str]:
    """The names of the visible entries of folder ``out`` (none if it does not exist)."""
    try:
        return sorted(p.name for p in Path(out).iterdir() if not p.name.startswith("."))
    except OSError:
        return []


def write(
    out: str | Path,
    command: str,
    config_hash: str | None,
    *,
    started_at: float,
    finished_at: float | None = None,
) -> Path:
    """Write ``OUT/manifest.json`` atomically (times in seconds since 1970, UTC)."""
    from skygas.runs.run_driver import write_json

    data = {
        "command": command,
        "command_line": _context["argv"] if _context["command"] == command else None,
        "skygas_version": __version__,
        "config_hash": config_hash,
        "started_at": _iso(started_at),
        "finished_at": None if finished_at is None else _iso(finished_at),
    }
    path = write_json(Path(out) / MANIFEST, data)
    _context["written"] = True
    return path


def _iso(seconds: float) -> str:
    return time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime(seconds))


def options_hash(args) -> str:
    """A hash of a command's options, for commands that have no configuration file of their own.

    Where the options name files, of the names only.
    """
    skip = {"func", "debug", "quiet", "overwrite", "resume", "out", "json"}
    options = {k: v for k, v in sorted(vars(args).items()) if k not in skip}
    text = json.dumps(options, default=str, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def finish_command(out: str | Path, args, started_at: float) -> None:
    """After a command-line command succeeded: write its manifest, unless it wrote one itself.

    The run driver writes one itself, with the configuration's hash.
    """
    if _context["written"] or not Path(out).is_dir():
        return
    now = time.time()
    write(out, _context["command"], options_hash(args), started_at=started_at, finished_at=now)
