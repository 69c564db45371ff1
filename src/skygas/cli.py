"""Command-line interface: a thin layer over the Python API.

Each command group is a module of :mod:`skygas.commands` that exposes
``register(subparsers)``; this module only collects them. Every command is one call into the
library (imported when the command runs, so building the parser imports no numerics), and
anything the CLI does can be done from Python as well.

**One error path.** Every failure the user can fix prints one line on stderr,

    skygas: error: <field> = <value>: <why>; <what to do>

and exits with status 2: invalid input (:class:`~skygas.core.errors.InputError`), an output path
that cannot be written (any :class:`OSError`), and a job too large to compute
(:class:`OverflowError`, :class:`MemoryError`; the commands estimate their memory before
allocating, :mod:`skygas.core.resources`). Anything else is a bug in skygas: one line saying so,
exit status 70 (``EX_SOFTWARE``). ``skygas --debug COMMAND ...`` shows the traceback instead.
An ``--out`` folder that the failing command created is removed again when it is still empty,
so a refused command leaves nothing behind. A command that reads a run or a sweep store checks
its ``--out`` against what it reads (``check_out``, :mod:`skygas.outputs.out_paths`) before
anything is created or locked.
"""

from __future__ import annotations

import argparse
import importlib
import re
import signal
import sys
import time
from contextlib import nullcontext
from pathlib import Path

from skygas._version import __version__
from skygas.core.errors import InputError, RunFinished, RunInterrupted, WriteFailed

# Modules that add the sub-commands other than the kinds of run (each defines
# ``register(subparsers)``); the kinds' own are named by the registry (DeviceKind.cli).
_COMMAND_MODULES = [
    "skygas.commands.check_timestep",
    "skygas.commands.reshuffle",  # skygas demo
    "skygas.commands.sweep",
    "skygas.commands.optimize",
    "skygas.commands.animate",
    "skygas.commands.report",
    "skygas.commands.export",
    "skygas.commands.analyze",
    "skygas.commands.sc",
    "skygas.commands.micromag",
    "skygas.commands.calibrate",
    "skygas.commands.infer",
    "skygas.commands.track",
]

#: exit status of a failure the user can fix (argparse's own, for the same kind of mistake)
EXIT_INPUT = 2
#: exit status of an unexpected exception, a bug in skygas (``EX_SOFTWARE`` of sysexits.h)
EXIT_INTERNAL = 70

#: commands whose ``--out`` is a file, not a folder
_FILE_OUT_COMMANDS = {"animate", "export", "report", "render"}

#: commands that read a run or a sweep store: ``--overwrite`` lets them replace an existing
#: ``--out`` file (never an input, a run's results or anything in a store;
#: :mod:`skygas.outputs.out_paths`)
_READING_COMMANDS = {"animate", "export", "report", "render"}

#: commands whose ``--out`` keeps its own record instead of a manifest (a sweep store and a
#: study folder resume)
_OWN_OUT_RULES = {"sweep", "optimize"}

#: commands whose lock file lies beside their ``--out`` (a sweep store is renamed into place)
_LOCK_BESIDE = {"sweep"}

#: one example per command, shown at the end of its ``--help`` (the kinds' from the registry)
EXAMPLES = {
    "check-timestep": "skygas check-timestep examples/neuron.toml",
    "demo": "skygas demo --out out/demo",
    "sweep": "skygas sweep examples/sweeps/quick-current.toml --out out/sweep.zarr --workers 2",
    "plot": "skygas plot out/sweep.zarr --out out/sweep-figures",
    "optimize": "skygas optimize examples/optimize/reshuffler-rate.toml --out out/opt "
    "--workers 2 --trials 40",
    "animate": "skygas animate out/reshuffler --out out/reshuffler/movie.mp4 --window 0:2e-6",
    "report": "skygas report out/reshuffler",
    "export": "skygas export out/chamber --format extxyz --out out/chamber.xyz",
    "analyze": "skygas analyze out/chamber --json",
    "sc": "skygas sc demo --out out/sc",
    "sc demo": "skygas sc demo --n-bits 1024 --out out/sc",
    "micromag": "skygas micromag samples",
    "micromag inspect": "skygas micromag inspect m000000.ovf",
    "micromag fit": "skygas micromag fit snapshots/ --out out/fit",
    "micromag samples": "skygas micromag samples",
    "calibrate": "skygas calibrate S2 --out out/cal",
    "infer": "skygas infer out/track/tracks.csv --pixel-size 14e-9 --frame-interval 2e-9 "
    "--outline examples/tracking/chamber-movie-outline.csv --temperature 300 --out out/infer",
    "track": "skygas track examples/tracking/chamber-movie.tif --out out/track",
    "render": "skygas render out/chamber --out out/chamber.tif --pixel-size 14e-9",
}


def _kind_examples() -> dict[str, str]:
    """The example command line of each kind of run (the registry's)."""
    from skygas.devices.registry import KINDS

    return {k.name: k.example for k in KINDS.values() if k.example}


# A number as a flag's value: argparse's own pattern (``^-\d+$|^-\d*\.\d+$``) has no exponent
# and takes ``--current-density -1e11`` for an option.
_NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-(inf|nan)$", re.IGNORECASE)


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """Shows each option's default and keeps the examples' line breaks.

    The default is left out when the option's help already gives it, or it has none.
    """

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        default = action.default
        if (
            "default" in text
            or default in (None, False, argparse.SUPPRESS)
            or action.option_strings == []
            and action.nargs in ("?", "*")
        ):
            return text
        if isinstance(action, (argparse._HelpAction, argparse._VersionAction)):
            return text
        return f"{text} (default: %(default)s)"


class Parser(argparse.ArgumentParser):
    """The parser of ``skygas`` and of every sub-command (sub-parsers take their parent's class).

    Negative numbers with an exponent (``-1e11``, ``-2.5E-9``, ``-inf``) are values, never options,
    and ``--help`` shows the defaults.
    """

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", HelpFormatter)
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = _NEGATIVE_NUMBER


def _subparser_actions(parser: argparse.ArgumentParser):
    return [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]


def _complete_subparsers(parser: argparse.ArgumentParser, prefix: str = "") -> None:
    """Give every sub-command its example, and ``--overwrite`` to those writing an ``--out`` folder.

    The run commands have theirs from :func:`~skygas.commands.run_options.add_run_options`; the
    commands that read a run and write one file (:data:`_READING_COMMANDS`) get one that lets
    them replace an existing file.
    """
    examples = {**_kind_examples(), **EXAMPLES}
    for action in _subparser_actions(parser):
        for name, sub in action.choices.items():
            key = f"{prefix}{name}"
            if key in examples and not sub.epilog:
                sub.epilog = f"example:\n  {examples[key]}"
            options = sub._option_string_actions
            if (
                "--out" in options
                and "--overwrite" not in options
                and key.split()[0] not in _FILE_OUT_COMMANDS | _OWN_OUT_RULES
            ):
                sub.add_argument(
                    "--overwrite",
                    action="store_true",
                    help="replace the finished results of the same command in OUT",
                )
            elif "--out" in options and "--overwrite" not in options and key in _READING_COMMANDS:
                sub.add_argument(
                    "--overwrite",
                    action="store_true",
                    help="replace an existing OUT file (never an input, a run's results or a "
                    "file in a sweep store)",
                )
            _complete_subparsers(sub, f"{key} ")


def build_parser() -> argparse.ArgumentParser:
    """The ``skygas`` parser with every sub-command registered and completed."""
    parser = Parser(
        prog="skygas",
        description="Stochastic Thiele simulation of skyrmion gases and skyrmionic devices.",
        epilog="Bad input: one line 'skygas: error: ...' and exit status 2; a bug in skygas: "
        "exit status 70 (add --debug for the traceback).",
    )
    parser.add_argument("--version", action="version", version=f"skygas {__version__}")
    parser.add_argument(
        "--debug", action="store_true", help="show the Python traceback of any error"
    )
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    from skygas.devices.registry import KINDS

    for kind in KINDS.values():  # each kind of run's own command, as the registry names it
        if kind.cli:
            module, _, function = kind.cli.partition(":")
            getattr(importlib.import_module(module), function)(subparsers, kind)
    for name in _COMMAND_MODULES:
        importlib.import_module(name).register(subparsers)
    _complete_subparsers(parser)
    return parser


def command_name(args: argparse.Namespace) -> str:
    """The sub-command as typed (``"reshuffle"``, ``"sc demo"``)."""
    words = [args.command]
    for attr in ("sc_command", "micromag_command"):
        if getattr(args, attr, None):
            words.append(getattr(args, attr))
    return " ".join(words)


def _output_folder(args: argparse.Namespace) -> Path | None:
    out = getattr(args, "out", None)
    if out is None or args.command in _FILE_OUT_COMMANDS:
        return None
    return Path(out)


def _check_output_folder(out: Path, given: str) -> Path | None:
    """Refuse an ``--out`` that is an existing file; return the first folder it will create.

    The first folder of ``out`` that does not exist yet (what this command will create), or None.
    An empty ``--out`` (``given``, as typed: it would mean the current folder without saying
    so; ``--out .`` says so and is accepted) and a name that cannot be written as UTF-8 text
    (bytes of another encoding on the command line) are refused too.
    """
    if not given.strip():
        raise InputError(
            "--out",
            given,
            "a folder name (an empty --out would write into the current folder)",
            "name the folder for the results, e.g. --out results (or --out . on purpose)",
        )
    try:
        str(out).encode("utf-8")
    except UnicodeEncodeError as err:
        raise InputError(
            "--out",
            str(out),
            f"a folder name that is valid text (character {err.start} is a byte that is not UTF-8)",
            "choose a name of plain letters, digits, '-' and '_'",
        ) from None
    if out.exists() and not out.is_dir():
        raise InputError(
            "--out", str(out), "a folder (this is an existing file)", "choose another --out"
        )
    created = None
    for folder in [out, *out.parents]:
        if folder.exists():
            if not folder.is_dir():
                raise InputError(
                    "--out", str(out), f"a folder path ({folder} is a file)", "choose another --out"
                )
            break
        created = folder
    return created


def _remove_if_empty(created: Path | None, out: Path) -> None:
    """Remove the folders of ``out`` up to ``created`` that this command made and left empty.

    Never a file, never a folder that holds one.
    """
    if created is None:
        return
    for folder in [out, *out.parents]:
        try:
            folder.rmdir()  # only succeeds on an empty folder
        except OSError:
            return
        if folder == created:
            return


def describe_error(err: BaseException, args: argparse.Namespace | None = None) -> tuple[str, int]:
    """The one line printed for ``err`` (without the ``skygas: `` prefix) and the exit status."""
    if isinstance(err, InputError):
        return f"error: {err}", EXIT_INPUT
    if isinstance(err, WriteFailed):
        return f"error: {err}", err.exit_status
    if isinstance(err, OSError) and err.errno is not None:
        name = str(err.filename) if err.filename is not None else ""
        out = str(getattr(args, "out", None) or "")
        if out and name and (name.startswith(out) or out.startswith(name)):
            field, value = "--out", out  # the folder itself, or one of its parents
        else:
            field, value = "path", name
        return (
            f"error: {field} = {value!r}: expected a path that can be used ({name} gives: "
            f"{err.strerror}); choose a path in a folder that exists and that you can "
            "write to"
        ), EXIT_INPUT
    if isinstance(err, (OverflowError, MemoryError)):
        return (
            f"error: input = (too large): the job asks for more than this machine can "
            f"compute ({type(err).__name__}: {err}); use a shorter duration, fewer "
            "skyrmions, streams or frames"
        ), EXIT_INPUT
    return (
        f"internal error: {type(err).__name__}: {err}; this is a bug in skygas: rerun "
        "with --debug for the traceback"
    ), EXIT_INTERNAL


def _honour_interrupts() -> None:
    """Make SIGINT raise KeyboardInterrupt even when the shell started skygas with it ignored.

    A non-interactive shell starts ``skygas ... &`` with SIGINT ignored, and Python then keeps
    it ignored: ``kill -INT`` (or a scheduler's interrupt) would be lost, and the command would
    run on. Every command saves or discards its work on KeyboardInterrupt, so take it back.
    """
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


def main(argv: list[str] | None = None) -> int:
    """Run the command line ``argv`` (default: ``sys.argv[1:]``); returns the exit status.

    The output folder is checked and claimed first (its manifest written when the command succeeds);
    an error is printed as one line (:func:`describe_error`), with the traceback only under
    ``--debug``, and a folder the command created and left empty is removed.
    """
    parser = build_parser()
    args = parser.parse_args(argv)
    _honour_interrupts()
    from skygas.runs import folder_lock, manifest

    manifest.set_command(command_name(args), sys.argv[1:] if argv is None else list(argv))
    out = _output_folder(args)
    with_manifest = out is not None and args.command not in _OWN_OUT_RULES
    created = None
    started = time.time()
    try:
        # a command's own checks of its --out against its inputs, before anything is touched
        check_out = getattr(args, "check_out", None)
        if check_out is not None:
            check_out(args)
        if out is not None:
            created = _check_output_folder(out, str(args.out))
        # one run per folder: held from the first look at the folder to the last file written
        lock = (
            folder_lock.hold(out, command_name(args), beside=args.command in _LOCK_BESIDE)
            if out is not None
            else nullcontext()
        )
        with lock:
            if with_manifest:
                assert out is not None  # with_manifest needs an output folder
                manifest.claim(
                    out,
                    command_name(args),
                    overwrite=getattr(args, "overwrite", False),
                    resume=getattr(args, "resume", False),
                )
            status = int(args.func(args) or 0)
            if with_manifest and status == 0:
                assert out is not None  # with_manifest needs an output folder
                manifest.finish_command(out, args, started)
        return status
    except RunInterrupted as err:
        print(f"skygas: {err}", file=sys.stderr)
        return err.exit_status
    except RunFinished as err:  # --resume of a finished run: nothing to do, and that is fine
        print(f"skygas: {err}", file=sys.stderr)
        return 0
    except KeyboardInterrupt:
        if out is not None:
            _remove_if_empty(created, out)  # a folder made for this run and left empty
        print("skygas: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # stdout closed early (``skygas ... | head``): nothing to say
        sys.stderr.close()
        return 1
    except Exception as err:
        if out is not None:
            _remove_if_empty(created, out)
        if args.debug:
            raise
        line, status = describe_error(err, args)
        print(f"skygas: {line}", file=sys.stderr)
        return status
    finally:
        manifest.set_command(None, None)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
