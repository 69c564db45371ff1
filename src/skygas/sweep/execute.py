"""Running a sweep: serially in this process, or on Dask (a local cluster or a scheduler).

Workers only compute (:func:`~skygas.devices.study_hooks.run_point` takes a configuration as JSON
and returns plain numbers); this process writes every result into the store as it arrives, so
whatever finished is kept when the sweep is interrupted, and running the same sweep again only
runs what is missing.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from skygas.core.errors import require
from skygas.core.estimates import Estimate, announce_pending, check
from skygas.runs.cluster import (  # noqa: F401 - re-exported: earlier imports
    CONNECT_TIMEOUT,
    LOCAL_CLUSTER_CONFIG,
    connect,
    start_local_cluster,
)
from skygas.runs.progress import count_bar
from skygas.sweep.spec import Run, Sweep
from skygas.sweep.store import SweepStore
from skygas.sweep.worker import run_point


def check_sweep(runs: list[Run], workers: int, sweep: Sweep | None = None) -> Estimate:
    """Refuse a sweep that cannot fit or finish; announce a long one (:mod:`skygas.core.estimates`).

    Each run is priced as its kind prices it before it builds anything (the kind's study hook
    ``estimate``: the reshuffler's steps are at least its injection events), and the runs are
    spread over ``workers`` processes.

    Parameters
    ----------
    runs : list of Run
        The runs still to compute.
    workers : int
        Processes running them at once.
    sweep : Sweep, optional
        The sweep they belong to (its kind; default: the reshuffler's).

    Returns
    -------
    Estimate
        The whole sweep's estimate.
    """
    hooks = sweep.points if sweep is not None else _reshuffler()
    steps = seconds = memory = 0.0
    for run in runs:
        one = hooks.estimate(run.config)
        steps = max(steps, one.steps)
        seconds += one.seconds
        memory = max(memory, one.memory)
    parallel = max(1, min(workers, len(runs)))
    estimate = Estimate(steps, memory * parallel, seconds / parallel, runs=len(runs))
    check(
        estimate,
        "sweep",
        f"{len(runs)} runs",
        f"{len(runs)} runs on {parallel} workers",
        "sweep fewer points, replicas or a shorter base.duration",
    )
    announce_pending()  # the sweep is accepted: its estimate, if it is long, now
    return estimate


def _reshuffler():
    from skygas.devices.registry import study_kind
    from skygas.sweep.spec import DEFAULT_DEVICE

    return study_kind(DEFAULT_DEVICE).study


def relative_cost(config, sweep: Sweep | None = None) -> float:
    """A rough relative cost of one run, used only to start the longest runs first.

    Its kind's study hook (the reshuffler's: steps × (1 + skyrmions in the device)); results
    never depend on the order.
    """
    hooks = sweep.points if sweep is not None else _reshuffler()
    return hooks.relative_cost(config)


@dataclass
class SweepReport:
    """What one invocation did.

    Runs computed now, runs found done, the store's path and the invocation's session number in it
    (−1 if it ended before opening the store).
    """

    store: Path
    session: int
    computed: list[tuple[tuple[int, ...], int]] = field(default_factory=list)
    skipped: int = 0
    failed: list[tuple[tuple[int, ...], int, str]] = field(default_factory=list)
    wall_time_s: float = 0.0


def _serial(pending: list[Run], store: SweepStore, report: SweepReport, bar, module: str):
    report.session = session = store.start_session()
    for run in pending:
        store.write(run, run_point(module, run.config.model_dump_json()), session)
        report.computed.append((run.index, run.replica))
        if bar is not None:
            bar.update(1)


def _dask(
    pending: list[Run],
    open_store: Callable[[], SweepStore],
    report: SweepReport,
    bar,
    client,
    workers: int | None,
    sweep: Sweep,
):
    from dask.distributed import Client, as_completed

    cluster = None
    if client is None:
        cluster = start_local_cluster(workers or os.cpu_count() or 1)
        client = Client(cluster)
    try:
        futures = {}
        # the costliest first: submitted first (an idle worker takes a task as soon as it
        # arrives) and with the highest priority (Dask starts higher priorities first)
        hooks = sweep.points  # the kind's hooks, looked up once
        by_cost = sorted(pending, key=lambda r: hooks.relative_cost(r.config), reverse=True)
        for rank, run in enumerate(by_cost):
            future = client.submit(
                run_point,
                hooks.module,
                run.config.model_dump_json(),
                pure=False,
                priority=len(by_cost) - rank,
                key=f"skygas-run-{'-'.join(map(str, run.index))}-r{run.replica}-{time.time_ns()}",
            )
            futures[future] = run
        # the store is created (a new sweep) or opened while the workers start on the runs
        store = open_store()
        report.session = session = store.start_session()
        # as_completed must wait on this client's event loop: by default it takes the default
        # client's, which differs when the process holds another client (a test or benchmark
        # that started the cluster), and a run whose result is lost with a killed worker after
        # it completed is then awaited on two loops at once (RuntimeError: "bound to a
        # different event loop") instead of being recomputed
        for future in as_completed(list(futures), loop=client.loop):
            run = futures.pop(future)
            try:
                result = future.result()
            except Exception as err:  # noqa: BLE001 - one failed run must not stop the others
                report.failed.append((run.index, run.replica, f"{type(err).__name__}: {err}"))
                continue
            store.write(run, result, session)
            report.computed.append((run.index, run.replica))
            future.release()
            if bar is not None:
                bar.update(1)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def run_sweep(
    sweep: Sweep,
    out: str | Path,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    serial: bool = False,
    progress: bool = True,
) -> SweepReport:
    """Run every run of ``sweep`` not yet done in the store ``out`` and store the results.

    ``serial=True`` runs them one after the other in this process; otherwise on Dask: a local
    cluster of ``workers`` single-threaded processes (default: one per core), or the existing
    scheduler at ``scheduler`` (e.g. ``tcp://10.0.0.5:8786``) when given.
    """
    require(workers is None or workers >= 1, "--workers", workers, "at least 1 worker")
    start = time.perf_counter()
    # An existing store is opened (and checked against the sweep) before anything runs. A new
    # one is created once the runs are on their way (creating it costs ~0.4 s).
    parallel = 1 if serial else workers or os.cpu_count() or 1
    exists = SweepStore.exists(out)
    if not exists:  # estimated before the store is created
        check_sweep(list(sweep.runs), parallel, sweep)
    store = SweepStore(out, sweep) if exists or serial else None
    pending = store.pending() if store is not None else list(sweep.runs)
    if exists:
        check_sweep(pending, parallel, sweep)
    report = SweepReport(Path(out), -1, skipped=len(sweep.runs) - len(pending))
    # a named scheduler answers before anything starts (or is refused in one line)
    client = connect(scheduler) if scheduler is not None and pending and not serial else None
    bar = count_bar(progress, len(sweep.runs), report.skipped, unit="run", desc="sweep")
    try:
        if not pending:
            assert store is not None  # nothing pending: the store exists
            report.session = store.start_session()
        elif serial:
            assert store is not None  # opened or created above
            _serial(pending, store, report, bar, sweep.points.module)
        else:
            opener = lambda: store or SweepStore(out, sweep)  # noqa: E731
            _dask(pending, opener, report, bar, client, workers, sweep)
    finally:
        if bar is not None:
            bar.close()
    report.wall_time_s = time.perf_counter() - start
    return report
