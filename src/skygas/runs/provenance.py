"""The provenance record that every file a command writes carries.

One flat ``{str: str}`` record: the skygas version that made the data, the seed, a hash of the
configuration (and the configuration itself where the file has room for it), the command and
its command line. :func:`skygas.runs.run_driver.write_figure` puts it into a PNG's text chunks;
JSON files hold its keys, CSV files a leading ``# key: value`` block, the GSD export a
``log/skygas/provenance_json`` entry and the extended-XYZ export ``key=value`` pairs on the
comment line of each frame (see ``docs/outputs.md``).
"""

from __future__ import annotations

import json
import shlex
from collections.abc import Mapping
from typing import Any

from skygas._version import __version__
from skygas.runs import manifest
from skygas.runs.run_driver import fingerprint

#: the keys of a record that fit on one line (CSV comments, extended-XYZ comment lines)
SHORT_KEYS = ("skygas_version", "seed", "config_hash", "command", "command_line")


def command_line() -> str:
    """The running command line as typed (``"skygas plot s.zarr --out f"``); ``""`` from Python."""
    argv = manifest.current_argv()
    return "skygas " + shlex.join(argv) if argv else ""


def provenance(
    *,
    seed: Any,
    config_json: str | None = None,
    config_hash: str | None = None,
    skygas_version: str | None = None,
    source: str | None = None,
) -> dict[str, str]:
    """The provenance record of an output file.

    Parameters
    ----------
    seed : Any
        The seed of the data (the input run's seed, a sweep's root seed); ``None`` for data
        that need none (recorded as ``"none"``).
    config_json : str, optional
        The configuration as JSON; recorded, and hashed when ``config_hash`` is not given.
    config_hash : str, optional
        The configuration's hash (a sweep's fingerprint); default: the hash of
        ``config_json`` (:func:`~skygas.runs.run_driver.fingerprint`, as the run's manifest).
    skygas_version : str, optional
        The skygas version that made the data (an input run's); default: this one.
    source : str, optional
        The input the file was made from (a run folder, a sweep store).

    Returns
    -------
    dict of str to str
        ``skygas_version``, ``seed``, ``config_hash``, ``command``, ``command_line``,
        ``written_by`` (this skygas), then ``source`` and ``config_json`` when given.
    """
    if config_hash is None:
        config_hash = fingerprint(config_json) if config_json is not None else "none"
    record = {
        "skygas_version": str(skygas_version or __version__),
        "seed": "none" if seed is None else str(seed),
        "config_hash": str(config_hash),
        "command": manifest.current_command("python"),
        "command_line": command_line(),
        "written_by": f"skygas {__version__}",
    }
    if source is not None:
        record["source"] = str(source)
    if config_json is not None:
        record["config_json"] = config_json
    return record


def csv_header(record: Mapping[str, str]) -> str:
    """The ``# key: value`` comment lines (one per short key, newline-terminated) of a CSV file.

    Parameters
    ----------
    record : mapping of str to str
        A record of :func:`provenance`.

    Returns
    -------
    str
        The comment block; read the table with ``comment="#"`` (pandas) or skip lines starting
        with ``#``.
    """
    return "".join(f"# {key}: {record[key]}\n" for key in SHORT_KEYS if key in record)


def record_json(record: Mapping[str, str]) -> str:
    """``record`` as one line of JSON."""
    return json.dumps(dict(record), sort_keys=True)
