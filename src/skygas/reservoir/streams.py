"""The streams of a reservoir study, and the worker processes that run them.

:func:`stream_specs` cuts a study into its independent streams: ``study.workers`` Boolean
streams (fewer for a short study, and one on a landscape with random terms, see below), stream
k with its own input symbols (drawn from (seed, k)), its own seed (1000·seed + k) and
``study.warmup_inputs`` warm-up inputs, then as many temporal streams (seed 1000·seed + k + 500,
their inputs held ``study.temporal_hold_time``).

:class:`StreamPool` advances streams by some inputs each, as tasks of Dask workers (a local
cluster, or a running one given by its scheduler's address; with one worker: in this process).
A stream travels as its state
(:meth:`~skygas.reservoir.device.StreamRun.state_dict`): the worker builds the run again from
its spec (each process keeps the devices of the last few configurations), loads the state,
holds the next inputs and returns the new state. Any process can so continue any stream, and
the numbers do not depend on where a stream is cut.

Signals (:mod:`skygas.runs.cluster`): the local workers ignore SIGINT. A Ctrl-C at the terminal
goes to the whole process group; it stops only the parent, whose run driver
(:mod:`skygas.runs.run_driver`) lets the piece end, saves a checkpoint and stops the workers.
They exit by themselves once the parent is gone (a ``kill -9``).

:func:`run_streams` runs a study's streams to their end in memory (``skygas reservoir`` runs
them piece by piece through the run driver, :mod:`skygas.reservoir.files`).
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Iterable
from concurrent.futures import Future
from typing import Any

import numpy as np

from skygas.reservoir.config import ReservoirConfig
from skygas.reservoir.device import (
    ReservoirDevice,
    StreamResult,
    StreamRun,
    StreamSpec,
    stream_result,
)
from skygas.runs.cluster import PoolWords, TaskPool

#: Landscape kinds drawn at random from the run's seed (see :func:`stream_specs`).
RANDOM_LANDSCAPES = ("random_pinning", "disorder")
#: Devices kept built per process (one per configuration: a sweep has one per point).
CACHED_DEVICES = 4

_devices: OrderedDict[str, ReservoirDevice] = OrderedDict()


def stream_specs(
    config: ReservoirConfig,
    n_inputs: int | None = None,
    n_temporal: int | None = None,
    workers: int | None = None,
) -> tuple[list[StreamSpec], list[StreamSpec]]:
    """The Boolean and temporal streams of the study of ``config``.

    ``n_inputs`` held inputs in all (default ``study.n_inputs``) and ``n_temporal`` temporal
    ones (default ``study.temporal_inputs``; 0: none) are split into ``workers`` independent
    streams (default ``study.workers``, at most one per 4 inputs).

    A landscape with random terms (pinning wells, disorder) is drawn from the run's seed, and
    every stream has its own seed: streams would be different devices. Such a study runs as
    one stream, so that one read-out is trained and tested on one device.

    Parameters
    ----------
    config
        The validated configuration.
    n_inputs, n_temporal
        Held inputs of the Boolean and of the temporal streams, in all.
    workers
        Streams to split them into (before the limits above).

    Returns
    -------
    tuple of list of StreamSpec
        The Boolean streams, then the temporal ones (none for a stream given no input).
    """
    st = config.study
    n_inputs = st.n_inputs if n_inputs is None else n_inputs
    n_temporal = st.temporal_inputs if n_temporal is None else n_temporal
    streams = max(1, min(st.workers if workers is None else workers, n_inputs // 4))
    if any(p.kind in RANDOM_LANDSCAPES for p in config.potentials):
        streams = 1
    sizes = [len(a) for a in np.array_split(np.arange(n_inputs), streams)]
    temporal_sizes = [len(a) for a in np.array_split(np.arange(n_temporal), streams)]
    width = len(config.drive.input_contacts)
    boolean: list[StreamSpec] = []
    temporal: list[StreamSpec] = []
    for k, (m, t) in enumerate(zip(sizes, temporal_sizes, strict=True)):
        # one generator per stream: its Boolean inputs, then its temporal ones
        rng = np.random.default_rng(np.random.SeedSequence([config.seed, k, 0xB175]))
        seed = config.seed * 1000 + k
        boolean.append(
            StreamSpec(config, rng.integers(0, 2, size=(m, width)), seed, st.warmup_inputs)
        )
        if t:
            temporal.append(
                StreamSpec(
                    config,
                    rng.integers(0, 2, size=(t, width)),
                    seed + 500,
                    st.warmup_inputs,
                    hold_time=st.temporal_hold_time,
                    sample_interval=st.temporal_sample_interval,
                )
            )
    return boolean, temporal


def device_for(config: ReservoirConfig) -> ReservoirDevice:
    """The device of ``config``, built once per process.

    The devices of the last :data:`CACHED_DEVICES` configurations are kept.
    """
    key = config.model_dump_json()
    device = _devices.pop(key, None) or ReservoirDevice(config)
    _devices[key] = device
    while len(_devices) > CACHED_DEVICES:
        _devices.popitem(last=False)
    return device


def advance_stream(
    spec: StreamSpec, state: dict[str, np.ndarray] | None, n_inputs: int
) -> dict[str, np.ndarray]:
    """Hold the next inputs of a stream and return its new state (what a worker does).

    Parameters
    ----------
    spec
        The stream.
    state
        Its state (:meth:`~skygas.reservoir.device.StreamRun.state_dict`); None: its start.
    n_inputs
        Inputs to hold (fewer at the end of the stream).

    Returns
    -------
    dict of numpy.ndarray
        The stream's state after them.
    """
    run = StreamRun(device_for(spec.config), spec)
    if state is not None:
        run.load_state_dict(state)
    run.hold_inputs(n_inputs)
    return run.state_dict()


#: How the reservoir's one-line errors name its tasks and what to do about a lost worker.
WORDS = PoolWords(
    job="the reservoir study",
    task="stream's inputs",
    holders="reservoir streams",
    local_advice="use fewer --workers (study.workers); --resume continues from the last checkpoint",
    remote_advice="give the cluster's workers more memory; --resume continues from the last "
    "checkpoint",
)


class StreamPool:
    """Where streams are advanced (:func:`advance_stream`): Dask workers, or this process.

    ``workers`` streams at once on a local Dask cluster of as many single-threaded processes
    (:class:`~skygas.runs.cluster.TaskPool`, started on the first :meth:`submit`), or on the
    running cluster of ``scheduler`` (an address); with one worker and no scheduler, in this
    process at :meth:`submit`. Kept until :meth:`close` (or the end of a ``with`` block). See
    the module docstring for signals.
    """

    def __init__(self, workers: int, scheduler: str | None = None):
        self.workers = max(1, int(workers))
        self.scheduler = scheduler
        self._pool: TaskPool | None = None

    def __enter__(self) -> StreamPool:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    @property
    def inline(self) -> bool:
        """Whether streams run in this process (one worker, no scheduler)."""
        return self.workers == 1 and self.scheduler is None

    def _tasks(self) -> TaskPool:
        if self._pool is None:
            self._pool = (
                TaskPool.remote(self.scheduler, WORDS)
                if self.scheduler is not None
                else TaskPool.local(self.workers, WORDS)
            )
        return self._pool

    def submit(self, spec: StreamSpec, state: dict[str, np.ndarray] | None, n_inputs: int):
        """Start holding the next inputs of a stream (see :func:`advance_stream`).

        Parameters
        ----------
        spec, state, n_inputs
            As for :func:`advance_stream`.

        Returns
        -------
        concurrent.futures.Future or distributed.Future
            Its result (:meth:`result`) is the stream's new state (already there in this
            process).
        """
        if self.inline:
            done: Future = Future()
            done.set_result(advance_stream(spec, state, n_inputs))
            return done
        return self._tasks().submit(
            advance_stream, spec, state, n_inputs, name=f"reservoir-stream-{spec.seed}"
        )

    def first_done(self, futures: Iterable[Any]) -> set[Any]:
        """Wait until one of ``futures`` is done; those done."""
        futures = list(futures)
        if self.inline:
            return {f for f in futures if f.done()}
        return self._tasks().first_done(futures)

    def result(self, future: Any) -> dict[str, np.ndarray]:
        """A stream's new state; one line if its worker died or the scheduler went away."""
        return future.result() if self.inline else self._tasks().result(future)

    def close(self) -> None:
        """Stop the workers of a local cluster (streams still running are abandoned)."""
        pool, self._pool = self._pool, None
        if pool is not None:
            pool.close()


def run_streams(
    config: ReservoirConfig,
    n_inputs: int | None = None,
    n_temporal: int | None = None,
    workers: int | None = None,
) -> tuple[list[StreamResult], list[StreamResult]]:
    """The Boolean and temporal streams of :func:`stream_specs`, run to their end.

    They run on a local Dask cluster, one worker per Boolean stream (one stream: in this
    process).

    Parameters
    ----------
    config
        The validated configuration.
    n_inputs, n_temporal, workers
        As for :func:`stream_specs`.

    Returns
    -------
    tuple of list of StreamResult
        The Boolean streams' results, then the temporal streams'.
    """
    boolean, temporal = stream_specs(config, n_inputs, n_temporal, workers)
    specs = [*boolean, *temporal]
    with StreamPool(len(boolean)) as pool:
        futures = [pool.submit(spec, None, spec.n_total) for spec in specs]
        states = [pool.result(f) for f in futures]
    results = [stream_result(spec.bits, state) for spec, state in zip(specs, states, strict=True)]
    return results[: len(boolean)], results[len(boolean) :]
