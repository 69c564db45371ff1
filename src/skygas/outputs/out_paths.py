"""Where the commands that read a run or a sweep store may write: never over what they read.

``skygas export``, ``animate``, ``report`` and ``plot`` read a finished run folder (a folder
holding ``manifest.json``) or a sweep store (a zarr v3 store: a folder holding ``zarr.json``)
and write something made from it. Before any work, their ``--out`` is refused (one line,
:class:`~skygas.core.errors.InputError`) when it is

- one of the command's inputs, or the input folder or store itself;
- inside a sweep store (with or without ``--overwrite``): figures and reports go beside it;
- inside a run folder, unless it is a file of the command's own kind (``.html`` for report,
  ``.mp4``/``.gif`` for animate, ``.gsd``/``.xyz``/``.extxyz`` for export): a run's results
  (``.nc``, ``.json``, ``.npz``, ``.png``, ``.csv``, its manifest) are never replaced;
- an existing file, unless ``--overwrite`` is given (or it is the command's own default output,
  such as the report ``skygas report RUN`` refreshes).

A folder ``--out`` (``skygas plot``) is refused inside a run folder or a sweep store; a folder
that holds results of another command, or finished ones without ``--overwrite``, is refused by
its manifest (:func:`skygas.runs.manifest.claim`).
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

from skygas.core.errors import InputError

#: the file that marks a run folder
RUN_MARK = "manifest.json"
#: the file that marks a zarr (v3) store, a sweep store among them
STORE_MARK = "zarr.json"


def _resolved(path: str | Path) -> Path:
    return Path(path).expanduser().resolve()


def is_store(path: str | Path) -> bool:
    """Whether ``path`` is a zarr store (a folder holding ``zarr.json``)."""
    return (Path(path) / STORE_MARK).is_file()


def is_run_folder(path: str | Path) -> bool:
    """Whether ``path`` is a run folder (a folder holding ``manifest.json``)."""
    return (Path(path) / RUN_MARK).is_file()


def enclosing(path: str | Path, *, include_self: bool = False) -> tuple[str, Path] | None:
    """The nearest folder above ``path`` that is a sweep store or a run folder.

    Parameters
    ----------
    path : str or Path
        An output path (it need not exist).
    include_self : bool
        Whether ``path`` itself counts.

    Returns
    -------
    tuple of (str, Path) or None
        ``("store", folder)`` (the outermost store) or ``("run", folder)`` (the nearest); a store
        anywhere above wins over a run folder (nothing is written into a store); None when there
        is neither.
    """
    target = _resolved(path)
    folders = [target, *target.parents] if include_self else list(target.parents)
    stores = [f for f in folders if is_store(f)]
    store = stores[-1] if stores else None  # the outermost: a store's groups are stores too
    if store is not None:
        return "store", store
    run = next((f for f in folders if is_run_folder(f)), None)
    return None if run is None else ("run", run)


def beside_store(store: str | Path, suffix: str) -> Path:
    """A file name beside ``store`` (``out/sweep.zarr`` → ``out/sweep-report.html``)."""
    store = Path(store)
    stem = store.stem if store.suffix.lower() == ".zarr" else store.name
    return store.with_name(f"{stem}{suffix}")


def check_file_out(
    out: str | Path,
    inputs: Iterable[str | Path],
    *,
    kinds: tuple[str, ...],
    overwrite: bool,
    default: bool = False,
) -> Path:
    """Refuse a file ``--out`` that would write over an input, a result or into a store.

    Parameters
    ----------
    out : str or Path
        The output file.
    inputs : iterable of str or Path
        What the command reads: run folders, result files, sweep stores.
    kinds : tuple of str
        The suffixes of the command's own files (``(".html", ".htm")``), the only files it
        writes inside a run folder.
    overwrite : bool
        Whether an existing file may be replaced (``--overwrite``).
    default : bool
        Whether ``out`` is the command's own default output (replaced without ``--overwrite``).

    Returns
    -------
    Path
        ``out``.

    Raises
    ------
    InputError
        One line naming ``--out``, what is expected and what to do (see the module docstring).
    """
    out = Path(out)
    target = _resolved(out)
    for source in inputs:
        src = _resolved(source)
        if target == src:
            raise InputError(
                "--out",
                str(out),
                "a path that is not one of the command's inputs",
                "choose another --out",
            )
        if src.is_dir() and is_store(src) and src in target.parents:
            raise InputError(
                "--out",
                str(out),
                f"a file outside the sweep store {source} (nothing is written into a store)",
                f"write it beside the store, e.g. --out {beside_store(source, '-' + out.name)}",
            )
    if out.is_dir():
        raise InputError("--out", str(out), "a file (this is a folder)", "choose a file name")
    found = enclosing(out)
    if found is not None and found[0] == "store":
        raise InputError(
            "--out",
            str(out),
            f"a file outside the sweep store {found[1]} (nothing is written into a store)",
            f"write it beside the store, e.g. --out {beside_store(found[1], '-' + out.name)}",
        )
    if found is not None and out.suffix.lower() not in kinds:
        raise InputError(
            "--out",
            str(out),
            f"a {' or '.join(kinds)} file, the only kind written into the run folder "
            f"{found[1]} (its results are never replaced)",
            "choose a file name of that kind, or a path outside the run folder",
        )
    if out.exists() and not (overwrite or default):
        raise InputError(
            "--out",
            str(out),
            "a file that does not exist yet",
            "add --overwrite to replace it, or choose another --out",
        )
    return out


def check_folder_out(out: str | Path, inputs: Iterable[str | Path]) -> Path:
    """Refuse a folder ``--out`` that is an input, or lies inside a sweep store or a run folder.

    Parameters
    ----------
    out : str or Path
        The output folder.
    inputs : iterable of str or Path
        What the command reads (sweep stores).

    Returns
    -------
    Path
        ``out``.

    Raises
    ------
    InputError
        One line naming ``--out``, what is expected and what to do.
    """
    out = Path(out)
    target = _resolved(out)
    for source in inputs:
        src = _resolved(source)
        if target == src or src in target.parents:
            raise InputError(
                "--out",
                str(out),
                f"a folder outside the input {source}",
                f"write beside it, e.g. --out {beside_store(source, '-figures')}",
            )
    found = enclosing(out, include_self=True)
    if found is not None and found[0] == "store":
        raise InputError(
            "--out",
            str(out),
            f"a folder outside the sweep store {found[1]} (nothing is written into a store)",
            f"write beside it, e.g. --out {beside_store(found[1], '-figures')}",
        )
    found = enclosing(out)
    if found is not None:
        raise InputError(
            "--out",
            str(out),
            f"a folder outside the run folder {found[1]} (a folder of its own)",
            "choose a path outside the run folder",
        )
    return out
