"""The options every long-running command shares.

``--resume``, ``--overwrite``, ``--strict``, ``--quiet``, ``--checkpoint-seconds``, handed to
:func:`skygas.runs.run_driver.drive` and to the sanity checks (:mod:`skygas.runs.sanity`), and
``--force``, handed to the estimates every device checks before it allocates anything
(:mod:`skygas.core.estimates`) through the context :func:`limits_from_flags`.
"""

from __future__ import annotations

from contextlib import contextmanager

from skygas.core.errors import InputError, require
from skygas.core.estimates import run_limits
from skygas.runs.checkpoint_interval import CHECKPOINT_SECONDS


def add_run_options(parser, quiet: bool = True) -> None:
    """Add the run driver's options to a sub-command's parser.

    ``--checkpoint-seconds`` has the one default of every command,
    :data:`~skygas.runs.checkpoint_interval.CHECKPOINT_SECONDS`.
    """
    parser.add_argument(
        "--resume",
        action="store_true",
        help="continue the interrupted run saved in OUT/checkpoint.npz",
    )
    parser.add_argument(
        "--overwrite",
        action="store_true",
        help="replace the finished results (or the interrupted run) of the same "
        "command in OUT; other files in OUT are kept",
    )
    parser.add_argument(
        "--strict",
        action="store_true",
        help="refuse a run that the sanity checks only warn about (a "
        "temperature or current outside the model's range, a large drift per "
        "time step, wall escapes; docs/physics.md §5)",
    )
    if quiet:
        parser.add_argument("--quiet", action="store_true", help="no progress bar")
    add_force_option(parser)
    parser.add_argument(
        "--checkpoint-seconds",
        type=float,
        default=CHECKPOINT_SECONDS,
        metavar="S",
        help="wall time between periodic checkpoints [s] "
        f"(default {CHECKPOINT_SECONDS:g}; 0: after every piece of the run)",
    )


def add_dask_options(parser) -> None:
    """Add ``--scheduler``, ``--workers``, ``--serial`` and ``--quiet`` (sweeps and studies)."""
    add_scheduler_option(parser)
    parser.add_argument(
        "--workers",
        type=int,
        default=None,
        help="worker processes of the local cluster (default: one per core)",
    )
    parser.add_argument("--serial", action="store_true", help="run in this process, without Dask")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def add_scheduler_option(parser) -> None:
    """Add ``--scheduler``: a running Dask scheduler instead of a local cluster.

    Sweeps, studies and calibrations.
    """
    parser.add_argument(
        "--scheduler",
        default=None,
        help="address of a running Dask scheduler (default: a local cluster)",
    )


def add_force_option(parser) -> None:
    """Add ``--force``: start a run expected to take more than 24 hours."""
    parser.add_argument(
        "--force",
        action="store_true",
        help="start a run expected to take more than 24 hours on this machine (a run that "
        "does not fit in memory is refused all the same)",
    )


def limits_from_flags(args, announce: bool = True):
    """The limits of the runs a command builds (:func:`~skygas.core.estimates.run_limits`).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line: ``--force`` forces long runs; ``--quiet`` silences the
        estimate line.
    announce : bool
        False when the command prints machine-readable output (``--json``).

    Returns
    -------
    contextlib.AbstractContextManager
        A context to build and run the command's runs in.
    """
    return run_limits(
        force=bool(getattr(args, "force", False)),
        announce=announce and not getattr(args, "quiet", False),
    )


def run_options(args, progress: bool = True) -> dict:
    """The keyword arguments of :func:`skygas.runs.run_driver.drive` given on the command line.

    ``progress=False`` when the command prints machine-readable output instead.
    """
    seconds = args.checkpoint_seconds
    require(seconds >= 0, "--checkpoint-seconds", seconds, "a wall time >= 0 in seconds")
    return {
        "resume": args.resume,
        "overwrite": args.overwrite,
        "strict": args.strict,
        "checkpoint_seconds": seconds,
        "progress": progress and not getattr(args, "quiet", False),
    }


@contextmanager
def named_by_flags(args, flags: dict[str, str]):
    """Name a configuration error after the command-line option that set the field.

    ``flags`` maps an option's attribute (``"current_density"``) to the configuration field it sets
    (``"current_density"``, ``"device.chamber_diameter"``); only options given count.
    """
    given = {
        field: "--" + option.replace("_", "-")
        for option, field in flags.items()
        if getattr(args, option, None) is not None
    }
    try:
        yield
    except InputError as err:
        flag = given.get(getattr(err, "loc", err.field))
        if flag is None:
            raise
        raise InputError(flag, err.value, err.allowed, err.hint) from None
