"""The options every long-running command shares (``--resume``, ``--quiet``,
``--checkpoint-seconds``), handed to :func:`skygas.run_driver.drive`."""

from __future__ import annotations

from skygas.errors import require


def add_run_options(parser, checkpoint_seconds: float = 30.0, quiet: bool = True) -> None:
    """Add the run driver's options to a sub-command's parser."""
    parser.add_argument("--resume", action="store_true",
                        help="continue the interrupted run saved in OUT/checkpoint.npz")
    if quiet:
        parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.add_argument("--checkpoint-seconds", type=float, default=checkpoint_seconds,
                        metavar="S", help="wall time between periodic checkpoints [s] "
                        f"(default {checkpoint_seconds:g}; 0: after every piece of the run)")


def run_options(args, progress: bool = True) -> dict:
    """The keyword arguments of :func:`skygas.run_driver.drive` given on the command line;
    ``progress=False`` when the command prints machine-readable output instead."""
    seconds = args.checkpoint_seconds
    require(seconds >= 0, "--checkpoint-seconds", seconds, "a wall time >= 0 in seconds")
    return {"resume": args.resume, "checkpoint_seconds": seconds,
            "progress": progress and not getattr(args, "quiet", False)}
