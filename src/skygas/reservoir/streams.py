"""The streams of a reservoir study, and the worker processes that run them.

:func:`stream_specs` cuts a study into its independent streams: ``study.workers`` Boolean
streams (fewer for a short study, and one on a landscape with random terms, see below), stream
k with its own input symbols (drawn from (seed, k)), its own seed (1000·seed + k) and
``study.warmup_inputs`` warm-up inputs, then as many temporal streams (seed 1000·seed + k + 500,
their inputs held ``study.temporal_hold_time``).

:class:`StreamPool` advances streams by some inputs each, in parallel worker processes (with
one worker: in this process). A stream travels as its state
(:meth:`~skygas.reservoir.device.StreamRun.state_dict`): the worker builds the run again from
its spec (each process keeps the devices of the last few configurations), loads the state,
holds the next inputs and returns the new state. Any process can so continue any stream, and
the numbers do not depend on where a stream is cut.

Signals: the workers ignore SIGINT and SIGTERM. A Ctrl-C at the terminal goes to the whole
process group; it stops only the parent, whose run driver (:mod:`skygas.runs.run_driver`) lets
the piece end, saves a checkpoint and stops. The workers start with both signals blocked (they
inherit the mask), so that none arrives before they ignore it, and each exits by itself once
its parent is gone (a ``kill -9``).

:func:`run_streams` runs a study's streams to their end in memory (``skygas reservoir`` runs
them piece by piece through the run driver, :mod:`skygas.reservoir.files`).
"""

from __future__ import annotations

import os
import signal
import threading
import time
from collections import OrderedDict
from concurrent.futures import Future, ProcessPoolExecutor

import numpy as np

from skygas.reservoir.config import ReservoirConfig
from skygas.reservoir.device import (
    ReservoirDevice,
    StreamResult,
    StreamRun,
    StreamSpec,
    stream_result,
)

#: Landscape kinds drawn at random from the run's seed (see :func:`stream_specs`).
RANDOM_LANDSCAPES = ("random_pinning", "disorder")
#: Devices kept built per process (one per configuration: a sweep has one per point).
CACHED_DEVICES = 4
#: The signals the workers leave to their parent.
_SIGNALS = (signal.SIGINT, signal.SIGTERM)

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
    run.advance(n_inputs)
    return run.state_dict()


def _start_worker(parent: int) -> None:
    """A worker's initializer: leave SIGINT and SIGTERM to the parent, and exit once it is gone."""
    for s in _SIGNALS:
        signal.signal(s, signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, _SIGNALS)  # a pending one is dropped
    threading.Thread(target=_watch_parent, args=(parent,), daemon=True).start()


def _watch_parent(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(1.0)
    os._exit(1)  # the parent died without closing the pool: nobody wants the result


class StreamPool:
    """Worker processes that advance streams (:func:`advance_stream`) in parallel.

    ``workers`` processes (1: everything runs in this process, at :meth:`submit`), started on
    first use with the ``spawn`` method and kept until :meth:`close` (or the end of a ``with``
    block). See the module docstring for signals.
    """

    def __init__(self, workers: int):
        self.workers = max(1, int(workers))
        self._executor: ProcessPoolExecutor | None = None
        self._submitted: list[Future] = []

    def __enter__(self) -> StreamPool:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def submit(
        self, spec: StreamSpec, state: dict[str, np.ndarray] | None, n_inputs: int
    ) -> Future:
        """Start holding the next inputs of a stream (see :func:`advance_stream`).

        Parameters
        ----------
        spec, state, n_inputs
            As for :func:`advance_stream`.

        Returns
        -------
        concurrent.futures.Future
            Its result is the stream's new state (already there with one worker).
        """
        if self.workers == 1:
            done: Future = Future()
            done.set_result(advance_stream(spec, state, n_inputs))
            return done
        if self._executor is None:
            import multiprocessing

            self._executor = ProcessPoolExecutor(
                self.workers,
                mp_context=multiprocessing.get_context("spawn"),
                initializer=_start_worker,
                initargs=(os.getpid(),),
            )
        # a worker starts on submit: with the signals blocked, it inherits the mask (a signal
        # that arrives meanwhile reaches this process once they are unblocked again)
        block = hasattr(signal, "pthread_sigmask")
        if block:
            mask = signal.pthread_sigmask(signal.SIG_BLOCK, _SIGNALS)
        try:
            future = self._executor.submit(advance_stream, spec, state, n_inputs)
        finally:
            if block:
                signal.pthread_sigmask(signal.SIG_SETMASK, mask)
        self._submitted = [f for f in self._submitted if not f.done()] + [future]
        return future

    def close(self, wait: bool = True) -> None:
        """Stop the workers.

        ``wait=False`` returns before they have exited (a worker takes a moment to end, which
        this process can spend on other work). Streams still running (after an interruption,
        a second Ctrl-C, an error in another stream) are abandoned: their workers are killed.
        """
        executor, self._executor = self._executor, None
        if executor is None:
            return
        if any(not f.done() for f in self._submitted):
            # the executor has no public way to stop a running call
            for process in list((getattr(executor, "_processes", None) or {}).values()):
                process.kill()
        self._submitted = []
        executor.shutdown(wait=wait, cancel_futures=True)


def run_streams(
    config: ReservoirConfig,
    n_inputs: int | None = None,
    n_temporal: int | None = None,
    workers: int | None = None,
) -> tuple[list[StreamResult], list[StreamResult]]:
    """The Boolean and temporal streams of :func:`stream_specs`, run to their end.

    They run in parallel processes, one per Boolean stream (one stream: in this process).

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
        states = [f.result() for f in futures]
    results = [stream_result(spec.bits, state) for spec, state in zip(specs, states, strict=True)]
    return results[: len(boolean)], results[len(boolean) :]
