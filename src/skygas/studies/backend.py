"""The one parallel backend of studies, sweeps and calibrations: Dask.

A local cluster of single-threaded worker processes (:func:`start_local_cluster`), or a running
scheduler named by its address (:func:`connect`, the commands' ``--scheduler``). Workers only
compute; the process that submitted the work writes every result, so writes never race.
"""

from __future__ import annotations

from skygas.core.errors import InputError, require

#: Dask settings of the local cluster that a sweep starts (:func:`start_local_cluster`). The
#: cluster's processes share the machine's cores with the runs, and Dask's defaults wake each
#: of them many times a second: an event-loop health tick every 20 ms in every process, each
#: worker's statistical profiler every 10 ms, memory monitors every 100 ms and a system monitor
#: (with disk I/O counters) every 0.5 s. With 2 idle workers that is ~0.17 of a core (psutil:
#: 0.06 s/s in the client's process, which holds the scheduler and the nannies, 0.05 s/s per
#: worker); with these values ~0.02, and a 16-point sweep of 10 µs runs on 2 workers of a
#: 2-core machine took 0.88× the time (medians of 12 sweeps each, alternating). They only make
#: the dashboard's profiles and system plots coarser and memory limits checked once a second.
LOCAL_CLUSTER_CONFIG = {
    "distributed.admin.tick.interval": "1s",
    "distributed.worker.profile.enabled": False,
    "distributed.worker.memory.monitor-interval": "1s",
    "distributed.admin.system-monitor.interval": "5s",
    "distributed.admin.system-monitor.disk": False,
}


def start_local_cluster(workers: int, settings: dict | None = None):
    """A local Dask cluster of ``workers`` single-threaded worker processes.

    With :data:`LOCAL_CLUSTER_CONFIG`, and ``settings`` (Dask settings by their dotted names) on
    top of it: a caller's own, such as the calibration's
    (:data:`skygas.calibration.cluster.CLUSTER_SETTINGS`).
    """
    import copy

    import dask
    from dask.distributed import LocalCluster

    require(workers >= 1, "--workers", workers, "at least 1 worker")
    # read by the scheduler and nannies as they start
    with dask.config.set({**LOCAL_CLUSTER_CONFIG, **(settings or {})}):
        # Each nanny hands its worker processes a configuration that shares nested dicts with
        # the global one, which the context above restores on exit: a worker the nanny
        # restarts later would get Dask's defaults back. A private copy keeps the settings.
        return LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0",
            config=copy.deepcopy(dask.config.config),
        )


#: How long [s] a scheduler named with ``--scheduler`` has to answer.
CONNECT_TIMEOUT = 10.0


def connect(address: str, timeout: float = CONNECT_TIMEOUT):
    """A Dask client of the scheduler at ``address``, refused in one line if it does not answer.

    Parameters
    ----------
    address : str
        The scheduler's address (``tcp://10.0.0.5:8786``).
    timeout : float
        Seconds to wait for its answer.

    Returns
    -------
    distributed.Client
        The connected client.

    Raises
    ------
    InputError
        Naming ``--scheduler``, when the scheduler does not answer within ``timeout``.
    """
    from dask.distributed import Client

    try:
        return Client(address, timeout=f"{timeout:g}s")
    except Exception as err:  # noqa: BLE001 - no answer, or not a Dask scheduler's
        raise InputError(
            "--scheduler",
            address,
            f"a Dask scheduler that answers (no answer from it within {timeout:g} s: "
            f"{type(err).__name__})",
            "start the scheduler at that address, or drop --scheduler to use a local cluster",
        ) from None
