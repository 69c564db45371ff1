"""The exception that user-facing validation raises, and the one an interrupted run raises.

Every check on user input (a config file, a CLI option, an array handed to the API) raises
:class:`InputError` *before* any long computation starts. The message always names the field,
the offending value and what is allowed, so that a user can fix the input without reading code;
the command line prints it as one line, ``skygas: error: <field> = <value>: <why>; <what to
do>``, and exits with status 2 (see :mod:`skygas.cli`).
"""

from __future__ import annotations

import signal
from pathlib import Path
from typing import Any

#: Longest text [characters] an error line gives a value: a table or a long list (a calibrated
#: model's force table, kilobytes of numbers) is cut there, so that the line stays readable.
VALUE_CHARS = 120


def brief(value: Any) -> str:
    """``repr(value)``, cut to :data:`VALUE_CHARS` characters.

    A long table is named by its keys, a long list says its length.
    """
    text = repr(value)
    if len(text) <= VALUE_CHARS:
        return text
    size = ""
    if isinstance(value, dict):
        text = "a table of " + ", ".join(map(str, value))
    elif isinstance(value, (list, tuple, set)):
        size = f" ({len(value)} entries)"
    return text if len(text) <= VALUE_CHARS else f"{text[: VALUE_CHARS - 3]}...{size}"


class InputError(ValueError):
    """Invalid user input.

    The message reads ``<field> = <value>: expected <allowed>``, then ``; <hint>`` if there is one.

    Parameters
    ----------
    field : str
        Dotted name of the offending field (``"temperature"``, ``"skyrmions[3].x"``).
    value : Any
        The value that was given.
    allowed : str
        A short phrase saying what would be accepted (``"a number >= 0 (kelvin)"``).
    hint : str, optional
        What to do about it (``"choose another --out"``).
    """

    #: the dotted field path of a configuration error, without its source; set only by
    #: :func:`skygas.core.config_types.to_input_error` (read with ``getattr(err, "loc", ...)``)
    loc: str

    def __init__(self, field: str, value: Any, allowed: str, hint: str | None = None):
        self.field = field
        self.value = value
        self.allowed = allowed
        self.hint = hint
        text = f"{field} = {brief(value)}: expected {allowed}"
        super().__init__(text if hint is None else f"{text}; {hint}")


def require(condition: bool, field: str, value: Any, allowed: str, hint: str | None = None) -> None:
    """Raise :class:`InputError` unless ``condition`` holds."""
    if not condition:
        raise InputError(field, value, allowed, hint)


class RunInterrupted(KeyboardInterrupt):
    """A run stopped by SIGINT/SIGTERM after saving its checkpoint where its state was consistent.

    See :func:`skygas.runs.run_driver.drive`. ``signum``: the signal received; ``checkpoint``: the
    saved file. The command line prints the message and exits with :attr:`exit_status`.
    """

    def __init__(self, signum: int, checkpoint: Path | None):
        self.signum = signum
        self.checkpoint = checkpoint
        where = (
            f"state saved in {checkpoint}; run the same command with --resume to continue"
            if checkpoint is not None
            else "no checkpoint was saved"
        )
        super().__init__(f"interrupted by {signal.Signals(signum).name}: {where}")

    @property
    def exit_status(self) -> int:
        """The shell's status for a process ended by a signal: 128 + its number (130: Ctrl-C)."""
        return 128 + self.signum


class WriteFailed(Exception):
    """A file could not be written: the disk is full, a folder is not writable, a path is gone.

    The command line prints one line, ``skygas: error: could not write <path> (<cause>);
    <what is kept and what to do>``, and exits with :attr:`exit_status` (74, ``EX_IOERR`` of
    sysexits.h). ``path`` is the file, ``cause`` the operating system's words.
    """

    exit_status = 74

    def __init__(self, path: str | Path, cause: str, hint: str | None = None):
        self.path = Path(path)
        self.cause = cause
        self.hint = hint
        text = f"could not write {self.path} ({cause})"
        super().__init__(text if hint is None else f"{text}; {hint}")

    def with_hint(self, hint: str) -> WriteFailed:
        """The same failure, with what is kept and what to do."""
        return WriteFailed(self.path, self.cause, hint)


class RunFinished(Exception):
    """``--resume`` on a folder whose run is finished: there is nothing left to do.

    Raised before any work; the command line prints its message and exits with status 0 (a
    Ctrl-C that came just after the last result was written, then ``--resume``, ends well).
    """

    def __init__(self, out: str | Path, command: str):
        self.out = Path(out)
        super().__init__(
            f"the `skygas {command}` run in {self.out} is finished: nothing to resume "
            "(add --overwrite to run it again)"
        )
