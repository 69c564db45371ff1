"""One driver for every long run: progress bar, periodic checkpoints, interruption, resume.

A *job* (``skygas simulate``, ``reshuffle``, ``neuron``, ``saturation``) is cut into *pieces*
of work; between two pieces its state is consistent (the compiled kernel has returned, every
Python record of the piece is complete). :func:`drive` runs the pieces and owns everything
around them:

- the progress bar (``tqdm``, in the job's unit of work, usually simulated time);
- periodic checkpoints: ``OUT/checkpoint.npz``, saved after the first piece that ends more
  than ``checkpoint_seconds`` of wall time after the previous save, through a temporary file
  and :func:`os.replace`, so a crash (even SIGKILL) leaves the previous checkpoint intact;
- interruption: while the job runs, SIGINT (Ctrl-C) and SIGTERM only raise a flag. The flag is
  looked at after each piece, where the state is consistent; the driver then saves the
  checkpoint and raises :class:`RunInterrupted` (the command line prints how to resume and
  exits with 128 + the signal number, 130 for Ctrl-C). A second signal before the piece ends
  stops at once without saving (the last periodic checkpoint stays valid). The previous
  handlers are restored when the job stops;
- resume: ``resume=True`` loads the checkpoint if there is one, after checking that it was
  written by the same configuration (a fingerprint of the validated configuration); a run
  resumed from a checkpoint is bit-identical to one left alone, because pieces start at fixed
  steps and every random stream is part of the state;
- results: the job's :meth:`Job.finish` is the one place where result files are written (each
  through :func:`write_atomic`); the checkpoint is removed only after it has returned;
- the output folder: finished results, an interrupted run (a checkpoint) or another command's
  results (``OUT/manifest.json``, :mod:`skygas.runs.manifest`) are never replaced silently:
  ``resume=True`` continues an interrupted run, ``overwrite=True`` starts again in place of the
  job's own result files and checkpoint (nothing else in the folder is deleted). The manifest
  is written when the run starts and completed when its results are written.

The checkpoint records the configuration, the seed and the skygas version besides the state.
"""

from __future__ import annotations

import hashlib
import json
import os
import signal
import threading
import time
import zipfile
from collections.abc import Callable
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from skygas._version import __version__
from skygas.core.errors import InputError, RunInterrupted, WriteFailed
from skygas.core.estimates import announce_pending, checked_estimate, current_limits
from skygas.core.json_values import plain
from skygas.runs import folder_lock
from skygas.runs.checkpoint_interval import CHECKPOINT_SECONDS
from skygas.runs.pace import Pace

CHECKPOINT = "checkpoint.npz"


class Job(Protocol):
    """What :func:`drive` needs from a run.

    ``work_total`` and :meth:`work_done` measure the run in ``work_unit`` (e.g. ``"µs"`` of
    simulated time, or ``"runs"``); the job is finished when ``work_done() >= work_total``.
    :meth:`advance_piece` does one piece and returns with the state consistent;
    :meth:`state_dict` holds NumPy arrays only (what :func:`numpy.savez` stores) and
    :meth:`load_state_dict` restores it; :meth:`config_json` is the validated configuration
    (its hash tells whether a checkpoint belongs to this run); :meth:`finish` writes the
    results into the output directory and returns what the caller reports; ``result_files``
    names the files whose presence means a finished run (never overwritten). The driver only
    reads ``work_total``, ``work_unit`` and ``result_files`` (a job may compute
    ``work_total`` as it goes, in a property).
    """

    @property
    def work_total(self) -> float:
        """The whole run's work, in :attr:`work_unit`."""
        ...

    @property
    def work_unit(self) -> str:
        """The unit of the progress bar (``"ns"``, ``"µs"``, ``"runs"``)."""
        ...

    @property
    def result_files(self) -> tuple[str, ...]:
        """Names of the files whose presence in the folder means a finished run."""
        ...

    def work_done(self) -> float:
        """The work done so far, in :attr:`work_unit`."""
        ...

    def advance_piece(self) -> None:
        """Do one piece of the run and return with the state consistent."""
        ...

    def state_dict(self) -> dict[str, np.ndarray]:
        """The whole mutable state, as NumPy arrays only."""
        ...

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        """Restore what :meth:`state_dict` saved."""
        ...

    def config_json(self) -> str:
        """The validated configuration, as JSON."""
        ...

    def seed(self) -> int:
        """The run's seed."""
        ...

    def finish(self, out_dir: Path) -> Any:
        """Write the results into ``out_dir`` and return what the caller reports."""
        ...


def steps_to_piece_end(step: int, piece: int, end: int) -> int:
    """Steps from ``step`` to the next multiple of ``piece`` [steps] or to ``end``.

    Whichever comes first: the length of the next piece of a run.

    Pieces start at multiples of the piece length, whatever run (first or resumed) gets there,
    so a resumed run re-enters the compiled kernel at the same steps as one never stopped and
    continues bit-identically (where the kernel is re-entered matters to rounding: the
    neighbour list is rebuilt there).
    """
    return min(piece - step % piece, end - step)


class PiecewiseRunJob:
    """A :class:`Job` for a device run that already steps in pieces.

    ``run`` has ``sim`` (the :class:`~skygas.engine.Simulation`), ``total_steps``,
    ``advance_piece()`` and ``state_dict()`` / ``load_state_dict()``; ``config`` is its
    validated pydantic configuration (with a ``seed``). Work is simulated time in ``work_unit``
    (``time_scale`` units per second). Subclasses add :meth:`finish`.
    """

    work_unit = "ns"
    time_scale = 1e9

    def __init__(self, config, run):
        self.config = config
        self.run = run
        self.work_total = self._time(run.total_steps)

    def _time(self, steps: int) -> float:
        return steps * self.run.sim.time_step * self.time_scale

    def work_done(self) -> float:
        """Simulated time so far, in :attr:`work_unit`."""
        return self._time(self.run.sim.step)

    def advance_piece(self) -> None:
        """One piece of the run (``run.advance_piece()``)."""
        self.run.advance_piece()

    def state_dict(self) -> dict[str, np.ndarray]:
        """The run's state (``run.state_dict()``)."""
        return self.run.state_dict()

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        """Restore the run's state."""
        self.run.load_state_dict(state)

    def config_json(self) -> str:
        """The validated configuration, as JSON."""
        return self.config.model_dump_json()

    def seed(self) -> int:
        """The configuration's seed."""
        return self.config.seed


def fingerprint(config_json: str) -> str:
    """A hash of a configuration's JSON: a checkpoint only resumes the run that wrote it."""
    return hashlib.sha256(config_json.encode()).hexdigest()[:16]


# -- atomic files -----------------------------------------------------------------------------
def write_atomic(path: str | Path, write: Callable[[Path], Any]) -> Path:
    """Call ``write(tmp)`` on a temporary path beside ``path``, then rename it to ``path``.

    A finished file is never partial, whatever stops the process. The temporary name keeps the
    suffix (writers such as :func:`numpy.savez` and matplotlib choose the format by it).
    """
    path = Path(path)
    tmp = partial_path(path)
    try:
        write(tmp)
        os.replace(tmp, path)
    except OSError as err:  # disk full, no permission, folder gone: one line, the path named
        raise WriteFailed(path, err.strerror or str(err)) from None
    except RuntimeError as err:  # netCDF's HDF errors (a full disk among them)
        if "HDF" not in str(err) and "NetCDF" not in str(err):
            raise
        raise WriteFailed(path, str(err)) from None
    finally:
        tmp.unlink(missing_ok=True)
    return path


def run_record(job: Job) -> dict[str, str]:
    """What every file of a run records: the skygas version, the seed and the configuration."""
    return {
        "skygas_version": __version__,
        "seed": str(job.seed()),
        "config_json": job.config_json(),
    }


def write_figure(path: str | Path, plot: Callable[[Path], Any], record: dict[str, str]) -> Path:
    """Write the PNG that ``plot(tmp)`` draws, atomically.

    With ``record`` (see :func:`run_record`) in its text chunks (``PIL.Image.open(path).text``).
    """

    def write(tmp: Path) -> None:
        from PIL import Image, PngImagePlugin

        plot(tmp)
        info = PngImagePlugin.PngInfo()
        for key, value in record.items():
            info.add_itxt(key, value)  # international text: UTF-8 (µ, ², ...)
        with Image.open(tmp) as image:
            image.load()
        image.save(tmp, format="PNG", pnginfo=info, dpi=image.info.get("dpi", (72, 72)))

    return write_atomic(path, write)


def partial_path(path: Path) -> Path:
    """The temporary file :func:`write_atomic` writes before renaming it to ``path``.

    A process killed while writing leaves it behind.
    """
    return path.with_name(f".{path.stem}.partial{path.suffix}")


def write_json(path: str | Path, data: Any, indent: int | None = 2) -> Path:
    """Write ``data`` as standard JSON, atomically.

    NaN and ±inf, which JSON has no words for, are written ``null``
    (:func:`skygas.core.json_values.plain`); other non-JSON numbers as floats.
    """
    text = json.dumps(plain(data), indent=indent, default=float, allow_nan=False)
    return write_atomic(path, lambda tmp: tmp.write_text(text))


def write_netcdf(ds, path: str | Path) -> Path:
    """Write an xarray Dataset to netCDF, atomically."""
    return write_atomic(path, lambda tmp: ds.to_netcdf(tmp))


def json_array(value: Any) -> np.ndarray:
    """A JSON-able value as a 0-d string array (how non-array state enters a checkpoint)."""
    return np.array(json.dumps(value))


def from_json_array(array: np.ndarray) -> Any:
    """The value :func:`json_array` stored."""
    return json.loads(str(array))


# -- checkpoints --------------------------------------------------------------------------------
#: the checkpoint's array that holds the hash of the others
_HASH_KEY = "sha256"


def _arrays_hash(arrays: dict[str, Any]) -> str:
    """A sha256 over the arrays' names, dtypes, shapes and bytes, in key order (hex digits)."""
    digest = hashlib.sha256()
    for key in sorted(arrays):
        if key == _HASH_KEY:
            continue
        array = np.ascontiguousarray(np.asarray(arrays[key]))
        digest.update(f"{key}|{array.dtype.str}|{array.shape}|".encode())
        digest.update(array.tobytes())
    return digest.hexdigest()


def save_checkpoint(job: Job, path: Path) -> None:
    """Save the job's state with its configuration, seed and version, atomically.

    One more array, ``sha256``, holds a hash of all the others (:func:`_arrays_hash`), which
    :func:`load_checkpoint` checks: a file damaged since is refused rather than resumed from.
    """
    config = job.config_json()
    # Any values: typed as arrays, mypy would match the ``**`` below against savez's bool
    # ``allow_pickle`` (the keys are array names; the assertion rules out a clash)
    state: dict[str, Any] = job.state_dict()
    meta: dict[str, Any] = {
        "fingerprint": np.array(fingerprint(config)),
        "config_json": np.array(config),
        "seed": np.array(job.seed()),
        "skygas_version": np.array(__version__),
    }
    clash = set(meta) & set(state) | ({_HASH_KEY} & set(state))
    assert not clash, f"job state uses reserved checkpoint keys {clash}"
    arrays = {**meta, **state}
    arrays[_HASH_KEY] = np.array(_arrays_hash(arrays))
    write_atomic(path, lambda tmp: np.savez(tmp, **arrays))


def _damaged(path: Path, why: str) -> InputError:
    return InputError(
        "--resume",
        str(path),
        f"a checkpoint skygas wrote and nothing changed since (this one is {why})",
        "run with --overwrite to start again",
    )


def _unreadable(path: Path, err: Exception) -> str:
    """Why the checkpoint at ``path`` could not be read, in a few words."""
    try:
        with open(path, "rb") as file:
            head = file.read(4)
    except OSError as cause:
        return f"unreadable: {cause.strerror}"
    if not head:
        return "unreadable: the file is empty"
    if not head.startswith(b"PK"):
        return "unreadable: not a checkpoint (no npz archive)"
    return f"unreadable: truncated or damaged ({err})"


def load_checkpoint(job: Job, path: Path) -> None:
    """Restore a checkpoint written by :func:`save_checkpoint` for the same configuration.

    Refuse one written by another configuration, and one that cannot be read or whose hash
    does not match its arrays (truncated, emptied, a bit flipped), with one
    :class:`InputError` each.
    """
    try:
        # opened here: numpy leaves a file it opened itself open when it is not an archive
        with open(path, "rb") as file, np.load(file, allow_pickle=False) as data:
            arrays = {k: data[k] for k in data.files}
    except (zipfile.BadZipFile, ValueError, EOFError, OSError, KeyError) as err:
        raise _damaged(path, _unreadable(path, err)) from None
    if _HASH_KEY in arrays and str(arrays.pop(_HASH_KEY)) != _arrays_hash(arrays):
        raise _damaged(path, "damaged: its arrays do not match the hash written with them")
    if "fingerprint" not in arrays:
        raise _damaged(path, "damaged: it has no configuration fingerprint")
    if str(arrays["fingerprint"]) != fingerprint(job.config_json()):
        raise InputError(
            "--resume",
            str(path),
            "a checkpoint written by the same configuration and options "
            "(this one belongs to another run: use another --out, or delete it "
            "to start again)",
        )
    state = {
        k: v
        for k, v in arrays.items()
        if k not in ("fingerprint", "config_json", "seed", "skygas_version")
    }
    try:
        job.load_state_dict(state)
    except KeyError as err:
        raise _damaged(path, f"damaged: the array {err} is missing") from None


# -- signals ----------------------------------------------------------------------------------
class _DeferredSignals:
    """Turns SIGINT and SIGTERM into a flag (``received``) while active.

    A second signal raises :class:`KeyboardInterrupt` at once. Outside the main thread signals
    cannot be handled, and nothing is changed.
    """

    SIGNALS = (signal.SIGINT, signal.SIGTERM)

    def __init__(self) -> None:
        self.received: int | None = None
        self._previous: dict = {}

    def _handle(self, signum, frame) -> None:
        if self.received is not None:
            raise KeyboardInterrupt
        self.received = signum

    def __enter__(self) -> _DeferredSignals:
        if threading.current_thread() is threading.main_thread():
            for s in self.SIGNALS:
                self._previous[s] = signal.signal(s, self._handle)
        return self

    def __exit__(self, *exc) -> None:
        for s, handler in self._previous.items():
            signal.signal(s, handler)
        self._previous.clear()


@contextmanager
def _progress_bar(job: Job, enabled: bool):
    if not enabled:
        yield lambda: None
        return
    import sys

    from tqdm import tqdm

    from skygas.core.kernel_cache import engine_compiled
    from skygas.runs.machine_speed import COMPILING_LINE

    # a run of the engine whose time loop is not in the cache yet compiles it in its first piece
    steps_the_engine = getattr(getattr(job, "run", None), "sim", None) is not None
    compiling = steps_the_engine and not engine_compiled()
    if compiling:
        print(COMPILING_LINE, file=sys.stderr)

    # a job may say when its rate can be measured (a calibration: once two solves finished);
    # until then the bar shows no remaining time, and its clock starts there
    waiting = not getattr(job, "rate_measured", True)
    bar_format = getattr(job, "progress_format", None)
    bar = tqdm(
        total=round(job.work_total, 6),
        unit=job.work_unit,
        desc=getattr(job, "work_description", "simulated"),
        leave=False,
        initial=round(job.work_done(), 6),
        bar_format=bar_format.replace("{remaining}", "?") if waiting and bar_format else bar_format,
    )

    def update() -> None:
        nonlocal compiling, waiting
        bar.total = round(job.work_total, 6)  # a job may learn its size as it goes
        # a job may say what it is doing now (a calibration's stage)
        bar.set_description(getattr(job, "work_description", "simulated"), refresh=False)
        done = round(job.work_done(), 6)
        if waiting and getattr(job, "rate_measured", True):
            waiting = False
            compiling = True  # the same restart of the clock, below
            bar.bar_format = bar_format
        if compiling:
            # the first piece included the compilation (or the start-up): the rate, and so
            # the remaining time, is measured afresh from here, on the work alone
            compiling = False
            now = time.time()  # tqdm's clock
            bar.n = bar.initial = done
            bar.start_t = bar.last_print_t = now
            bar.refresh()
            return
        bar.update(done - bar.n)  # tqdm throttles the redraws

    try:
        yield update
    finally:
        bar.close()


# -- the driver ---------------------------------------------------------------------------------
def _prepare_folder(job: Job, out: Path, resume: bool, overwrite: bool) -> Path | None:
    """Check what ``out`` holds before anything is written (see the module docstring).

    Return the checkpoint to resume from, if any. With ``overwrite``, the job's own result files
    and checkpoint are removed (after every check has passed).
    """
    from skygas.runs import manifest

    command = manifest.current_command(type(job).__name__)
    manifest.claim(out, command, fingerprint(job.config_json()), overwrite=overwrite, resume=resume)
    ckpt = out / CHECKPOINT
    finished = [name for name in job.result_files if (out / name).exists()]
    if overwrite and not (resume and ckpt.exists()):
        for name in finished:
            (out / name).unlink()
        ckpt.unlink(missing_ok=True)
        return None
    if finished and not ckpt.exists():
        raise InputError(
            "--out",
            str(out),
            f"a folder without finished results ({finished[0]} is there)",
            "add --overwrite to replace them, or choose another --out",
        )
    if ckpt.exists():
        if not resume:
            raise InputError(
                "--out",
                str(out),
                f"a folder without an interrupted run ({ckpt.name} is there)",
                "add --resume to continue it, --overwrite to start again, or choose another --out",
            )
        return ckpt
    return None


def drive(
    job: Job,
    out_dir: str | Path,
    *,
    resume: bool = False,
    progress: bool = True,
    checkpoint_seconds: float = CHECKPOINT_SECONDS,
    overwrite: bool = False,
    strict: bool = False,
    then: Callable[[Path], Any] | None = None,
) -> Any:
    """Run ``job`` to its end and return ``job.finish(out_dir)`` (see the module docstring).

    ``resume``: continue from ``OUT/checkpoint.npz`` when there is one. Without it, an existing
    checkpoint is refused (it holds an interrupted run that a fresh start would overwrite), and
    so are finished results (``job.result_files``) and another command's folder.
    ``overwrite``: replace the job's finished results (or its interrupted run, without
    ``resume``) instead of refusing them.
    ``checkpoint_seconds``: wall time [s] between periodic checkpoints (0: after every piece;
    default :data:`~skygas.runs.checkpoint_interval.CHECKPOINT_SECONDS`).
    ``strict``: the sanity checks (:mod:`skygas.runs.sanity`) refuse the run (before it starts; wall
    escapes once its results are written) instead of warning.
    ``then``: what else to write once the results are there (a report, a movie): it belongs
    to the final write, so a kill during it is completed by ``--resume`` too.
    Raises :class:`RunInterrupted` after saving the checkpoint when SIGINT/SIGTERM arrives.
    """
    from skygas.runs import manifest, sanity

    if not (checkpoint_seconds >= 0):
        raise InputError("checkpoint_seconds", checkpoint_seconds, "a wall time >= 0 in seconds")
    sanity.before_run(job, strict)
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise InputError(
            "--out", str(out), "a folder (this is an existing file)", "choose another --out"
        )
    command = manifest.current_command(type(job).__name__)
    with folder_lock.hold(out, command):  # one run per folder, for the run's whole life
        result = _run_in_folder(
            job, out, command, resume, overwrite, progress, checkpoint_seconds, then, strict
        )
    sanity.after_run(job, strict)
    return result


def _run_in_folder(
    job: Job,
    out: Path,
    command: str,
    resume: bool,
    overwrite: bool,
    progress: bool,
    checkpoint_seconds: float,
    then: Callable[[Path], Any] | None,
    strict: bool,
) -> Any:
    """The part of :func:`drive` that runs while the folder's lock is held."""
    from skygas.runs import manifest, sanity

    resume_from = _prepare_folder(job, out, resume, overwrite)
    ckpt = out / CHECKPOINT
    config_hash = fingerprint(job.config_json())
    started = time.time()
    if resume_from is not None:  # read (and checked) before anything in the folder changes
        load_checkpoint(job, resume_from)
    manifest.write(out, command, config_hash, started_at=started)
    announce_pending()  # the run is accepted: its estimate, if it is long, before the progress
    # for a run of the engine, whose work is simulated time at a cost per step that only a
    # crowding gas changes (a calibration's units of work take unequal times by design); not
    # under --quiet or --json
    steps_the_engine = getattr(getattr(job, "run", None), "sim", None) is not None
    watched = steps_the_engine and current_limits().announce
    pace = Pace(checked_estimate() if watched else None, job.work_total)
    last_save = time.perf_counter()
    try:
        with _DeferredSignals() as signals, _progress_bar(job, progress) as update:
            while job.work_done() < job.work_total:
                job.advance_piece()
                update()
                pace.after_piece(job.work_done())
                sanity.during_run(job, strict)  # --strict refuses as soon as it is certain
                if signals.received is not None:
                    save_checkpoint(job, ckpt)
                    raise RunInterrupted(signals.received, ckpt)
                if (
                    job.work_done() < job.work_total
                    and time.perf_counter() - last_save >= checkpoint_seconds
                ):
                    save_checkpoint(job, ckpt)
                    last_save = time.perf_counter()
            if signals.received is not None:  # arrived while loading, or nothing left to do
                save_checkpoint(job, ckpt)
                raise RunInterrupted(signals.received, ckpt)
            # The final state, kept until every result is written: a kill at any moment of
            # the writing leaves a run that --resume completes without recomputing.
            save_checkpoint(job, ckpt)
        try:
            result = job.finish(out)
            if then is not None:
                then(out)
        except KeyboardInterrupt:  # Ctrl-C while the results are written
            raise RunInterrupted(signal.SIGINT, ckpt) from None
        # written last: a folder whose manifest says finished holds every result
        manifest.write(out, command, config_hash, started_at=started, finished_at=time.time())
    except WriteFailed as err:
        raise err.with_hint(_kept_after_failure(ckpt)) from None
    ckpt.unlink(missing_ok=True)
    partial_path(ckpt).unlink(missing_ok=True)  # left by a process killed while saving
    return result


def _kept_after_failure(ckpt: Path) -> str:
    """What a run that could not write a file keeps, and what to do (free space, resume)."""
    if ckpt.exists():
        return (
            f"the run is kept in {ckpt}: make room (or fix the folder's permissions), then "
            "run the same command with --resume"
        )
    return "no state of the run could be saved: make room, then run it again"
