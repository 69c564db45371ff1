"""The zarr store of a sweep: one xarray Dataset, filled run by run as runs finish.

Layout: dimensions ``(*point_dims, replica)`` (one per swept field, or ``point`` for a list of
points) and ``running`` for the running-correlation curves. Each quantity of a run's summary
(:data:`QUANTITIES`) is one variable; ``running_rho`` / ``running_time`` hold the curve (NaN
after its end). Every array is chunked one run per chunk, so writing a run touches no other
run's data, and zarr's local store replaces each chunk file atomically.

A new store is written as metadata only: a chunk that was never written reads as its array's
fill value (NaN, ``done`` = 0, ``session`` = −1), so creating the store writes no per-run files
and each run later writes only its own chunks (stored uncompressed: one number or one curve per
chunk is not worth compressing, and the client spends less time per run).

``done`` (0/1) is the source of truth for resuming: a run's values are written first and its
``done`` element last, so a run interrupted while being written counts as not done and is
simply run again. ``finished_at`` (Unix time) and ``session`` (which invocation of the sweep
computed it) record when a run was computed; a resumed sweep never rewrites them for runs
already done. Only the client process writes (workers return results), so writes never race.

Attributes: the sweep file's text, the root seed, the swept fields, the package version and a
fingerprint of the resolved configurations; ``seed`` holds every run's derived seed.
"""

from __future__ import annotations

import asyncio
import json
import time
from pathlib import Path

import dask.array as da
import numpy as np
import xarray as xr
import zarr
from zarr.core.sync import sync as _sync

from skygas._version import __version__
from skygas.errors import InputError
from skygas.sweep.spec import Run, Sweep

# summary keys stored per run (float64; NaN until the run is done)
QUANTITIES = (
    "correlation", "correlation_max_lag", "scc", "p_in", "p_out",
    "n_injected", "n_detected", "n_skipped", "n_present", "max_occupancy",
    "mean_transit_s", "power_W", "energy_per_bit_J", "simulated_time_s", "time_step_s",
    "wall_time_s",
)
RUNNING = ("running_rho", "running_time")


def _coordinate(values) -> np.ndarray:
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        return np.asarray(values, dtype=np.float64)
    # names, tables, booleans: stored as their JSON text
    return np.asarray([v if isinstance(v, str) else json.dumps(v, sort_keys=True)
                       for v in values], dtype=str)


def _skeleton(sweep: Sweep) -> tuple[xr.Dataset, dict]:
    dims = (*sweep.point_dims, "replica")
    shape = (*sweep.shape, sweep.replicas)
    n_running = max(run.config.output.running_points for run in sweep.runs)
    coords = {"replica": np.arange(sweep.replicas)}
    if sweep.layout == "grid":
        for dim, values in zip(sweep.dims, sweep.values):
            coords[dim] = (dim, _coordinate(values))
    else:
        coords["point"] = np.arange(sweep.shape[0])
        for dim, values in zip(sweep.dims, sweep.values):
            coords[dim] = ("point", _coordinate(values))
    seeds = np.zeros(shape, dtype=np.int64)
    for run in sweep.runs:
        seeds[(*run.index, run.replica)] = run.seed

    def unwritten(fill, dtype=np.float64, extra=()):
        # lazy: only the metadata is written, chunks stay absent and read as the fill value
        return da.full((*shape, *extra), fill, dtype=dtype, chunks=(1,) * len(shape) + extra)

    data = {q: (dims, unwritten(np.nan)) for q in QUANTITIES}
    for name in RUNNING:
        data[name] = ((*dims, "running"), unwritten(np.nan, extra=(n_running,)),
                      {"units": "s"} if name == "running_time" else {})
    data["seed"] = (dims, seeds)
    data["done"] = (dims, unwritten(0, np.int8))
    data["finished_at"] = (dims, unwritten(np.nan), {"units": "s since 1970-01-01 UTC"})
    data["session"] = (dims, unwritten(-1, np.int32))
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update({
        "title": "skygas reshuffler sweep",
        "skygas_version": __version__,
        "root_seed": sweep.root_seed,
        "replicas": sweep.replicas,
        "layout": sweep.layout,
        "fields_json": json.dumps(dict(zip(sweep.dims, sweep.fields))),
        "sweep_file": sweep.source_text,
        "base_config_json": json.dumps(sweep.base),
        "fingerprint": sweep.fingerprint(),
        "seed_derivation": "SeedSequence(root_seed).spawn(n_points)[i].spawn(replicas)[r]"
                           ".generate_state(1, uint64)[0] >> 1, i in C order of the points",
        "sessions_json": "[]",
    })
    chunk = (1,) * len(dims)
    per_run = {"chunks": chunk, "compressors": None}
    encoding = {name: dict(per_run) for name in (*QUANTITIES, "done", "finished_at")}
    encoding["session"] = {**per_run, "fill_value": -1}  # an int: −1 without NaN masking
    encoding.update({name: {**per_run, "chunks": (*chunk, n_running)} for name in RUNNING})
    encoding["seed"] = {"chunks": shape}  # written once, never rewritten
    return ds, encoding


class SweepStore:
    """A sweep's zarr store, opened for writing by the (single) client process."""

    def __init__(self, path: str | Path, sweep: Sweep):
        self.path = Path(path)
        self.sweep = sweep
        if not self.exists(self.path):
            ds, encoding = _skeleton(sweep)
            # written under a temporary name and moved into place, so a store either exists
            # complete or not at all
            tmp = self.path.with_name(self.path.name + ".creating")
            if tmp.exists():
                import shutil

                shutil.rmtree(tmp)
            ds.to_zarr(tmp, mode="w", encoding=encoding, consolidated=False, zarr_format=3,
                       compute=False)
            tmp.rename(self.path)
        self.group = zarr.open_group(self.path, mode="r+")
        found = self.group.attrs.get("fingerprint")
        if found != sweep.fingerprint():
            raise InputError("--out", str(self.path),
                             "a new store, or one written by this same sweep file "
                             f"(the store's sweep differs: fingerprint {found})")
        self._arrays = {name: self.group[name] for name in
                        (*QUANTITIES, *RUNNING, "done", "finished_at", "session")}
        self._async = {name: _async_of(array) for name, array in self._arrays.items()}

    @staticmethod
    def exists(path: str | Path) -> bool:
        """Whether a store (complete: see :meth:`__init__`) is at ``path``."""
        return (Path(path) / "zarr.json").exists()

    def done(self) -> np.ndarray:
        return np.asarray(self._arrays["done"][...]).astype(bool)

    def pending(self) -> list[Run]:
        done = self.done()
        return [run for run in self.sweep.runs if not done[(*run.index, run.replica)]]

    def start_session(self) -> int:
        sessions = json.loads(self.group.attrs.get("sessions_json", "[]"))
        sessions.append({"started": time.time(), "skygas_version": __version__})
        self.group.attrs["sessions_json"] = json.dumps(sessions)
        return len(sessions) - 1

    def write(self, run: Run, result: dict, session: int) -> None:
        """Store one finished run: its values first, its ``done`` flag last.

        The values go to their ~20 arrays concurrently (one chunk file each, on zarr's I/O
        loop), which halves the client's CPU time per run against writing them one by one:
        that time competes with the workers when they share the client's cores. ``done`` is
        written only after every value has been written."""
        at = (*run.index, run.replica)
        values = [(name, np.float64(result[name])) for name in QUANTITIES]
        for name in RUNNING:
            curve = np.full(self._arrays[name].shape[-1], np.nan)
            data = np.asarray(result[name], dtype=np.float64)[:curve.size]
            curve[:data.size] = data
            values.append((name, curve))
        values.append(("finished_at", np.float64(time.time())))
        values.append(("session", np.int32(session)))
        _sync(_set_all([(self._async[name], at, value) for name, value in values]))
        _sync(self._async["done"].setitem(at, np.int8(1)))


def _async_of(array):
    # the public property exists in recent zarr 3 releases; the attribute in all of them
    return array.async_array if hasattr(type(array), "async_array") else array._async_array


async def _set_all(items) -> None:
    await asyncio.gather(*(array.setitem(at, value) for array, at, value in items))


def open_sweep(path: str | Path) -> xr.Dataset:
    """The sweep store as an :class:`xarray.Dataset` (runs not yet done are NaN)."""
    path = Path(path)
    if not (path / "zarr.json").exists():
        raise InputError("STORE", str(path), "a sweep store written by `skygas sweep`")
    return xr.open_zarr(path, consolidated=False, decode_timedelta=False).load()
