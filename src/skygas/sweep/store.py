"""The zarr store of a sweep, filled run by run as runs finish; read as one xarray Dataset.

On disk (zarr v3), dimensions ``(*point_dims, replica)`` (one per swept field, or ``point`` for
a list of points) index the runs, and each run owns one chunk of each of its arrays:

- ``summary`` (…, ``quantity``): the run's summary numbers (float64, in the order of its
  attribute ``quantities``: the swept kind's, :attr:`Sweep.quantities <skygas.sweep.spec.
  Sweep.quantities>`);
- ``running_curves`` (…, ``curve``, ``running``), for a kind whose runs return curves: the
  curves (attribute ``curves``; the reshuffler's running correlation ρ and its times; NaN after
  a curve's end);
- ``finished_at`` (Unix time), ``session`` (which invocation of the sweep computed it) and
  ``done`` (0/1).

Packing the ~20 numbers of a run into two arrays makes a run five chunk writes instead of ~20,
which is what the client's CPU time per run goes into. :func:`open_sweep` unpacks them into one
variable per quantity (``correlation``, ``running_rho``, …).

A new store is written as metadata only: a chunk that was never written reads as its array's
fill value (NaN, ``done`` = 0, ``session`` = −1), so creating the store writes no per-run files
and each run later writes only its own chunks (stored uncompressed: a few numbers per chunk
are not worth compressing). zarr's local store replaces each chunk file atomically.

``done`` is the source of truth for resuming: a run's values are written first and its
``done`` element last, so a run interrupted while being written counts as not done and is
simply run again. A resumed sweep never rewrites ``finished_at`` or ``session`` for runs already
done. Only the client process writes (workers return results), so writes never race.

Attributes: the sweep file's text, the root seed, the swept fields, the package version and a
fingerprint of the resolved configurations; ``seed`` holds every run's derived seed.
"""

from __future__ import annotations

import asyncio
import json
import time
import warnings
from pathlib import Path
from typing import Any, cast

import numpy as np
import xarray as xr
import zarr
from zarr.core.sync import sync as _sync

from skygas._version import __version__
from skygas.core.errors import InputError
from skygas.sweep.spec import DEFAULT_DEVICE, Run, Sweep


def _coordinate(values) -> np.ndarray:
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        return np.asarray(values, dtype=np.float64)
    # names, tables, booleans: stored as their JSON text
    return np.asarray(
        [v if isinstance(v, str) else json.dumps(v, sort_keys=True) for v in values], dtype=str
    )


#: Layout of the arrays on disk (see the module docstring); stored in the attributes.
STORE_LAYOUT = 2


def _create(path: Path, sweep: Sweep) -> None:
    """Write a new, empty store at ``path``: coordinates, seeds, attributes and per-run metadata.

    The per-run arrays are metadata only: their chunks are absent until a run writes them.
    """
    dims = (*sweep.point_dims, "replica")
    shape = (*sweep.shape, sweep.replicas)
    curves = dict(sweep.curves)
    coords: dict[str, Any] = {"replica": np.arange(sweep.replicas)}
    if sweep.layout == "grid":
        for dim, values in zip(sweep.dims, sweep.values, strict=True):
            coords[dim] = (dim, _coordinate(values))
    else:
        coords["point"] = np.arange(sweep.shape[0])
        for dim, values in zip(sweep.dims, sweep.values, strict=True):
            coords[dim] = ("point", _coordinate(values))
    seeds = np.zeros(shape, dtype=np.int64)
    for run in sweep.runs:
        seeds[(*run.index, run.replica)] = run.seed
    fixed = xr.Dataset({"seed": (dims, seeds)}, coords=coords)
    fixed.attrs.update(
        {
            "title": f"skygas {sweep.device} sweep",
            "device": sweep.device,
            "skygas_version": __version__,
            "store_layout": STORE_LAYOUT,
            "root_seed": sweep.root_seed,
            "replicas": sweep.replicas,
            "layout": sweep.layout,
            "fields_json": json.dumps(dict(zip(sweep.dims, sweep.fields, strict=True))),
            "sweep_file": sweep.source_text,
            "base_config_json": json.dumps(sweep.base),
            "fingerprint": sweep.fingerprint(),
            "seed_derivation": "SeedSequence(root_seed).spawn(n_points)[i].spawn(replicas)[r]"
            ".generate_state(1, uint64)[0] >> 1, i in C order of the points",
            "sessions_json": "[]",
        }
    )
    fixed.to_zarr(
        path, mode="w", encoding={"seed": {"chunks": shape}}, consolidated=False, zarr_format=3
    )
    group = zarr.open_group(path, mode="r+")
    # name: (extra dimensions and their sizes, dtype, fill value, attributes)
    per_run: dict[str, tuple[dict[str, int], Any, float, dict[str, Any]]] = {
        "summary": (
            {"quantity": len(sweep.quantities)},
            np.float64,
            np.nan,
            {"quantities": list(sweep.quantities)},
        ),
        **(
            {
                "running_curves": (
                    {"curve": len(curves), "running": max(curves.values())},
                    np.float64,
                    np.nan,
                    {"curves": list(curves)},
                )
            }
            if curves
            else {}
        ),
        "finished_at": ({}, np.float64, np.nan, {"units": "s since 1970-01-01 UTC"}),
        "session": ({}, np.int32, -1, {}),
        "done": ({}, np.int8, 0, {}),
    }
    for name, (extra, dtype, fill, attrs) in per_run.items():
        group.create_array(
            name,
            shape=(*shape, *extra.values()),
            chunks=(1,) * len(shape) + tuple(extra.values()),
            dtype=dtype,
            fill_value=fill,
            compressors=None,
            dimension_names=[*dims, *extra],
            attributes=attrs,
        )


#: suffix of a store being created (renamed to its name once complete)
CREATING = ".creating"


class SweepStore:
    """A sweep's zarr store, opened for writing by the (single) client process."""

    def __init__(self, path: str | Path, sweep: Sweep):
        self.path = Path(path)
        self.sweep = sweep
        if not self.exists(self.path):
            if self.path.exists() and (not self.path.is_dir() or any(self.path.iterdir())):
                raise InputError(
                    "--out",
                    str(self.path),
                    "a new store or an existing sweep "
                    "store (this is a file or a folder of other files)",
                    "choose another --out",
                )
            # written under a temporary name and moved into place, so a store either exists
            # complete or not at all; a failure removes the temporary store
            import shutil

            tmp = self.path.with_name(self.path.name + CREATING)
            if tmp.exists():
                shutil.rmtree(tmp)
            try:
                _create(tmp, sweep)
                if self.path.is_dir():
                    self.path.rmdir()  # an empty folder given as --out
                tmp.rename(self.path)
            finally:
                if tmp.exists():
                    shutil.rmtree(tmp)
        self.group = zarr.open_group(self.path, mode="r+")
        found = self.group.attrs.get("fingerprint")
        if found != sweep.fingerprint():
            raise InputError(
                "--out",
                str(self.path),
                "a new store, or one written by this same sweep file "
                f"(the store's sweep differs: fingerprint {found})",
            )
        layout = self.group.attrs.get("store_layout", 1)
        if layout != STORE_LAYOUT:
            raise InputError(
                "--out",
                str(self.path),
                f"a store of layout {STORE_LAYOUT} (this one has layout {layout}, "
                "written by another skygas version: open_sweep still reads it; "
                "to continue the sweep, rerun it into a new store)",
            )
        # the per-run arrays that _create wrote (a group's item may also be a group)
        self._arrays = {
            name: cast(zarr.Array, self.group[name])
            for name in ("summary", "running_curves", "done", "finished_at", "session")
            if name in self.group
        }
        #: the numbers and curves its runs store, in their order on disk
        self.quantities = list(cast(list, self._arrays["summary"].attrs["quantities"]))
        curves = self._arrays.get("running_curves")
        self.curves = list(cast(list, curves.attrs["curves"])) if curves is not None else []
        self._async = {name: _async_of(array) for name, array in self._arrays.items()}

    @staticmethod
    def exists(path: str | Path) -> bool:
        """Whether a store (complete: see :meth:`__init__`) is at ``path``."""
        return (Path(path) / "zarr.json").exists()

    def done(self) -> np.ndarray:
        """Which runs are done: booleans of shape (*point shape, replicas)."""
        return np.asarray(self._arrays["done"][...]).astype(bool)

    def pending(self) -> list[Run]:
        """The sweep's runs not yet done, in the sweep's order."""
        done = self.done()
        return [run for run in self.sweep.runs if not done[(*run.index, run.replica)]]

    def start_session(self) -> int:
        """Record a new invocation (start time and skygas version) and return its session number."""
        sessions = json.loads(cast(str, self.group.attrs.get("sessions_json", "[]")))  # JSON text
        sessions.append({"started": time.time(), "skygas_version": __version__})
        self.group.attrs["sessions_json"] = json.dumps(sessions)
        return len(sessions) - 1

    def write(self, run: Run, result: dict, session: int) -> None:
        """Store one finished run: its values first, its ``done`` flag last.

        The values go to their four arrays concurrently (one chunk file each, on zarr's I/O
        loop): the client's CPU time per run competes with the workers when they share the
        client's cores. ``done`` is written only after every value has been written.
        """
        at = (*run.index, run.replica)
        # a number the run did not return (a store written before the kind returned it: NaN)
        summary = np.array([result.get(name, np.nan) for name in self.quantities], np.float64)
        values: list[tuple[str, Any]] = [("summary", summary)]
        if self.curves:
            running = np.full(self._arrays["running_curves"].shape[-2:], np.nan)
            for row, name in enumerate(self.curves):
                data = np.asarray(result[name], dtype=np.float64)[: running.shape[1]]
                running[row, : data.size] = data
            values.append(("running_curves", running))
        values += [("finished_at", np.float64(time.time())), ("session", np.int32(session))]
        _sync(_set_all([(self._async[name], at, value) for name, value in values]))
        _sync(self._async["done"].setitem(at, np.int8(1)))


def _async_of(array):
    # the public property exists in recent zarr 3 releases; the attribute in all of them
    return array.async_array if hasattr(type(array), "async_array") else array._async_array


async def _set_all(items) -> None:
    await asyncio.gather(*(array.setitem(at, value) for array, at, value in items))


def open_sweep(path: str | Path) -> xr.Dataset:
    """The sweep store as an :class:`xarray.Dataset`, one variable per quantity.

    Quantities ``correlation``, …, ``running_rho``, ``running_time``, with ``seed``, ``done``,
    ``session`` and ``finished_at`` (datetime64; NaT until done). Runs not yet done are NaN.
    """
    path = Path(path)
    if not (path / "zarr.json").exists() or path.name.endswith(CREATING):
        raise InputError(
            "STORE",
            str(path),
            "a sweep store written by `skygas sweep`",
            "a name ending in .creating is a store left unfinished: run the sweep again"
            if path.name.endswith(CREATING)
            else None,
        )
    try:
        with warnings.catch_warnings():  # zarr's and xarray's notes on the format, not the user's
            warnings.simplefilter("ignore")
            raw = xr.open_zarr(path, consolidated=False, decode_times=False).load()
            if "summary" in raw:  # layout 2: unpack the per-run arrays
                packed_names = [n for n in ("summary", "running_curves") if n in raw]
                ds = raw.drop_vars(packed_names)
                ds.attrs.setdefault("device", DEFAULT_DEVICE)  # stores from before other kinds
                for packed, dim, names in (
                    ("summary", "quantity", "quantities"),
                    ("running_curves", "curve", "curves"),
                ):
                    if packed not in raw:
                        continue
                    for k, name in enumerate(raw[packed].attrs[names]):
                        part = raw[packed].variable[{dim: k}]
                        ds[name] = (
                            part.dims,
                            part.values,
                            {"units": "s"} if name == "running_time" else {},
                        )
            else:  # layout 1 (one array per quantity), written by earlier versions
                ds = raw
            seconds = ds["finished_at"].values
            stamps = np.where(
                np.isnan(seconds),
                np.datetime64("NaT", "ns"),
                (np.nan_to_num(seconds) * 1e9).astype(np.int64).astype("datetime64[ns]"),
            )
            ds["finished_at"] = (ds["finished_at"].dims, stamps)
    except (
        OSError,
        ValueError,
        KeyError,
        IndexError,
        TypeError,
        AttributeError,
        RuntimeError,
    ) as err:
        why = str(err).splitlines()[0] if str(err) else type(err).__name__
        raise InputError(
            "STORE",
            str(path),
            f"a sweep store written by `skygas sweep` (this one is damaged or not a sweep "
            f"store: {why})",
            "give the folder that `skygas sweep --out` wrote, or run the sweep again",
        ) from None
    return ds


def open_sweeps(paths) -> xr.Dataset:
    """Several sweep stores over the same swept fields as one :class:`xarray.Dataset`.

    On the union of their grids (points no store holds are NaN, not done), for figures and fits that
    span them: say, a grid at one p-value and a second grid of other p-values at some of its
    currents. A point done in two stores is refused (the stores would disagree on its runs).

    One path: :func:`open_sweep`. The attributes keep each store's sweep file
    (``sweep_file``, one after the other, each under a ``# STORE`` line) and its root seed
    (``root_seed``, listed).
    """
    paths = [Path(p) for p in ([paths] if isinstance(paths, (str, Path)) else paths)]
    if len(paths) == 1:
        return open_sweep(paths[0])
    parts = [open_sweep(p) for p in paths]
    fields = [tuple(sorted(json.loads(ds.attrs.get("fields_json", "{}")))) for ds in parts]
    for path, own in zip(paths[1:], fields[1:], strict=True):
        if own != fields[0]:
            raise InputError(
                "STORE",
                str(path),
                f"a sweep over the same fields as {paths[0]} "
                f"({', '.join(fields[0])}; this one sweeps {', '.join(own)})",
            )
    points = [ds["done"].fillna(0).astype(bool).any("replica") for ds in parts]
    for a in range(len(parts)):
        for b in range(a + 1, len(parts)):
            both = points[a] & points[b]  # aligned on the points the two grids share
            if bool(both.any()):
                point = both.where(both, drop=True).isel({d: 0 for d in both.dims})
                where = ", ".join(f"{d} = {float(point[d]):g}" for d in both.dims)
                raise InputError(
                    "STORE",
                    str(paths[b]),
                    f"stores of different points ({where} is done in {paths[a]} too)",
                )
    masked = []
    for ds in parts:  # runs not done are NaN, so that the grids merge without conflicts
        done = ds["done"].fillna(0) == 1
        masked.append(
            ds.assign(
                {name: ds[name].where(done) for name in ds.data_vars if "replica" in ds[name].dims}
            )
        )
    merged = xr.merge(masked, join="outer", compat="no_conflicts", combine_attrs="drop_conflicts")
    merged["done"] = merged["done"].fillna(0)
    merged.attrs["fields_json"] = parts[0].attrs.get("fields_json", "{}")
    merged.attrs["sweep_file"] = "\n".join(
        f"# {path}\n{ds.attrs.get('sweep_file', '')}" for path, ds in zip(paths, parts, strict=True)
    )
    merged.attrs["root_seed"] = [ds.attrs.get("root_seed", ds.attrs.get("seed")) for ds in parts]
    merged.attrs["stores"] = [str(p) for p in paths]
    return merged
