"""The one parallel backend of runs, studies, sweeps and calibrations: Dask.

A local cluster of single-threaded worker processes (:func:`start_local_cluster`), or a running
scheduler named by its address (:func:`connect`, the commands' ``--scheduler``). Workers only
compute; the process that submitted the work writes every result, so writes never race.

:class:`TaskPool` is such a client for a job that hands out tasks and decides itself when to
stop (the reservoir's streams, a calibration's solves):

- on a local cluster (:meth:`TaskPool.local`) its workers ignore Ctrl-C (the job saves its
  checkpoint first, then stops them), die with the job's process even when it is killed by
  SIGKILL (Dask's worker processes exit when their parent's end of a pipe closes), and are
  killed at once when the job stops (a task in flight is recomputed on resume);
- on a running cluster (:meth:`TaskPool.remote`), a task that a worker has started when the job
  stops finishes on that worker and is discarded: Dask cannot stop a running task.

A worker that dies with a task (the kernel kills the largest process when memory runs out) ends
the job with one line naming ``--workers`` (or ``--scheduler``) and what to do, and so does a
scheduler that goes away. While the pool is open, Dask's own log lines (a worker restarted, a
task marked as failed) are kept from the terminal: the job says what happened, in one line.
"""

from __future__ import annotations

import logging
import os
import re
import signal
import time
from collections.abc import Callable, Iterable
from concurrent.futures import CancelledError
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from skygas.core.errors import InputError, require

if TYPE_CHECKING:
    from distributed import Client, Future

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
    top of it: a caller's own, such as a :class:`TaskPool`'s (:data:`POOL_SETTINGS`).
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


#: Seconds that the local cluster's nanny has, once a worker is known dead, to say how it died.
DEATH_NOTE_SECONDS = 2.0

#: Dask settings of a :class:`TaskPool`'s local cluster (beside :data:`LOCAL_CLUSTER_CONFIG`).
POOL_SETTINGS = {
    # a worker that dies with a task ends the job with one line: most likely the kernel killed
    # it for lack of memory, and a retry would die the same way, a task later
    "distributed.scheduler.allowed-failures": 0,
    # a worker's memory is what its tasks keep on purpose (a calibration's solvers, a stream's
    # devices), checked against the machine before the job starts; Dask's limits, a share of
    # the machine per worker, would pause a worker for good or restart it in the middle of a
    # task
    "distributed.worker.memory.pause": False,
    "distributed.worker.memory.terminate": False,
}

#: The nanny's line on a dead worker process (distributed.nanny.WorkerProcess._death_message).
_DEATH = re.compile(
    r"Worker process (\d+) (?:was killed by signal (\d+)|exited with status (\d+)"
    r"|was killed by unknown signal)"
)


def _ignore_interrupts_plugin():
    """A worker plugin that sets SIGINT to be ignored in every worker, those that join later too.

    A terminal's Ctrl-C reaches every process of its foreground group, the local cluster's
    workers too; one that stopped on it would fail its task, and the job would report a dead
    worker instead of saving its checkpoint. A plugin, not the task: signal handlers can only
    be set in a process's main thread, where Dask sets up plugins and tasks do not run.
    """
    from distributed import WorkerPlugin

    class IgnoreInterrupts(WorkerPlugin):
        def setup(self, worker) -> None:  # noqa: D102 - WorkerPlugin's
            signal.signal(signal.SIGINT, signal.SIG_IGN)

    return IgnoreInterrupts()


class _DaskLogs(logging.Filter):
    """Keeps Dask's log lines from the terminal while a pool is open; notes how workers died.

    Installed on the handlers of the ``distributed`` logger (every line of its loggers passes
    one of them) and on the nanny's logger, which logs a dead worker's exit at the INFO level
    (below what reaches a handler) and is set to INFO meanwhile.
    """

    def __init__(self) -> None:
        super().__init__()
        #: exit code by worker pid: negative, the signal; None, an unknown signal
        self.exit_codes: dict[int, int | None] = {}
        self._handlers: list[logging.Handler] = []
        self._nanny = logging.getLogger("distributed.nanny")
        self._nanny_level = self._nanny.level

    def filter(self, record: logging.LogRecord) -> bool:  # noqa: D102 - logging.Filter's
        found = _DEATH.match(record.getMessage())
        if found:
            signum, status = found.group(2), found.group(3)
            code = -int(signum) if signum else int(status) if status else None
            self.exit_codes[int(found.group(1))] = code
        return False

    def install(self) -> _DaskLogs:
        self._handlers = list(logging.getLogger("distributed").handlers)
        for handler in self._handlers:
            handler.addFilter(self)
        self._nanny.addFilter(self)
        self._nanny.setLevel(logging.INFO)
        return self

    def remove(self) -> None:
        for handler in self._handlers:
            handler.removeFilter(self)
        self._nanny.removeFilter(self)
        self._nanny.setLevel(self._nanny_level)


@dataclass(frozen=True)
class PoolWords:
    """How a job's one-line errors name its tasks and what to do about a lost worker.

    Attributes
    ----------
    job : str
        The job, for a scheduler lost while it runs ("the calibration").
    task : str
        One task ("solve").
    holders : str
        What a worker must be able to hold ("solver processes").
    local_advice : str
        What to do when a local worker dies with a task.
    remote_advice : str
        The same on a running cluster.
    """

    job: str
    task: str
    holders: str
    local_advice: str
    remote_advice: str


class TaskPool:
    """The Dask client that a job hands its tasks to: a local cluster's or a scheduler's.

    Build it with :meth:`local` or :meth:`remote`; :meth:`close` it (or use ``with``). See the
    module docstring for signals, kills and lost workers.
    """

    def __init__(
        self,
        client: Client,
        logs: _DaskLogs,
        words: PoolWords,
        cluster=None,
        address: str | None = None,
    ):
        self.client = client
        self.cluster = cluster
        #: the scheduler's address, given with ``--scheduler`` (None: a local cluster)
        self.address = address
        self.words = words
        self._logs = logs
        self._workers = len(cluster.workers) if cluster is not None else 0

    def __enter__(self) -> TaskPool:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    @classmethod
    def local(cls, workers: int, words: PoolWords, settings: dict | None = None) -> TaskPool:
        """A local cluster of ``workers`` processes (:data:`POOL_SETTINGS`), Ctrl-C ignored."""
        from distributed import Client

        logs = _DaskLogs().install()
        cluster = client = None
        try:
            cluster = start_local_cluster(workers, {**POOL_SETTINGS, **(settings or {})})
            client = Client(cluster)
            # the workers that start later (a nanny's restart) are set up as they join
            client.register_plugin(_ignore_interrupts_plugin(), name="skygas-ignore-sigint")
            return cls(client, logs, words, cluster=cluster)
        except BaseException:
            if client is not None:
                client.close()
            if cluster is not None:
                cluster.close()
            logs.remove()
            raise

    @classmethod
    def remote(cls, address: str, words: PoolWords) -> TaskPool:
        """The scheduler at ``address``, refused in one line if it does not answer."""
        logs = _DaskLogs().install()
        try:
            return cls(connect(address), logs, words, address=address)
        except BaseException:
            logs.remove()
            raise

    def capacity(self) -> int:
        """Tasks to keep in flight: one per worker thread (at least one).

        On a running cluster, asked again every time: its workers may come and go.
        """
        if self.cluster is not None:
            return self._workers
        try:
            return max(1, sum(self.client.nthreads().values()))
        except OSError:  # no answer within Dask's connect timeout: the scheduler is gone
            raise self._scheduler_lost() from None

    def pids(self) -> list[int]:
        """The worker processes' ids (on a running cluster, on their machines)."""
        if self.cluster is not None:
            return [n.pid for n in self.cluster.workers.values() if n.pid]
        return list(self.client.run(os.getpid).values())

    def submit(
        self, function: Callable[..., Any], *args: Any, name: str, priority: int = 0
    ) -> Future:
        """Hand ``function(*args)`` to the workers as the task ``name``.

        The higher ``priority``, the sooner Dask starts it. Every call is a new task: the same
        task handed out again (after a resume, or by a second job on the same cluster) is run
        again, not shared.
        """
        return self.client.submit(
            function,
            *args,
            key=f"skygas-{name.replace('/', '-')}-{time.time_ns()}",
            pure=False,
            priority=priority,
        )

    def first_done(self, futures: Iterable[Future]) -> set[Future]:
        """Wait until one of ``futures`` is done (finished, failed or lost); those done."""
        from distributed import wait

        try:
            done, _ = wait(list(futures), return_when="FIRST_COMPLETED")
        except OSError:  # the scheduler is gone
            raise self._scheduler_lost() from None
        return set(done)

    def result(self, future: Future) -> Any:
        """A finished task's result; one line if its worker died or the scheduler went away."""
        from distributed import KilledWorker

        try:
            return future.result()
        except KilledWorker as err:
            raise self._worker_died(err) from None
        except CancelledError:  # the client lost its scheduler, and the task with it
            raise self._scheduler_lost() from None
        finally:
            future.release()

    def _worker_died(self, err) -> InputError:
        """The error of a worker that died with its task: how, and what to do."""
        w = self.words
        if self.cluster is None:
            return InputError(
                "--scheduler",
                self.address,
                f"workers that can hold the {w.holders} (one died while running a {w.task}, "
                f"and its {w.task} with it)",
                w.remote_advice,
            )
        pid = getattr(err.last_worker, "pid", None)
        deadline = time.monotonic() + DEATH_NOTE_SECONDS
        while pid not in self._logs.exit_codes and time.monotonic() < deadline:
            time.sleep(0.02)
        if pid in self._logs.exit_codes:
            code = self._logs.exit_codes[pid]
            if code is None:
                how = "was killed by an unknown signal"
            elif code < 0:
                how = f"was killed by {signal.Signals(-code).name}" + (
                    ", most likely by the kernel for lack of memory"
                    if -code == signal.SIGKILL
                    else ""
                )
            else:
                how = f"exited with status {code}"
        else:
            how = "stopped"
        return InputError(
            "--workers",
            self._workers,
            f"{w.holders} that this machine can hold (one {how}, and its {w.task} with it)",
            w.local_advice,
        )

    def _scheduler_lost(self) -> InputError:
        w = self.words
        if self.cluster is not None:  # the local cluster lives in this process: not expected
            return InputError(
                "--workers",
                self._workers,
                f"a local Dask cluster that stays up (it went away with a {w.task})",
                "--resume continues from the last checkpoint",
            )
        return InputError(
            "--scheduler",
            self.address,
            f"a Dask scheduler that answers until {w.job} ends (the connection was lost)",
            "start it again (or drop --scheduler for a local cluster), then run the same "
            "command with --resume: it continues from the last checkpoint",
        )

    def close(self) -> None:
        """Stop: the local cluster's workers at once (their tasks are recomputed on resume).

        On a running cluster, the tasks handed out are released: those not started are dropped,
        those started finish on their workers and are discarded.
        """
        try:
            if self.cluster is not None:
                self._kill_workers()
            self.client.close()
            if self.cluster is not None:
                self.cluster.close()
        finally:
            self._logs.remove()

    def _kill_workers(self) -> None:
        """Kill the local cluster's worker processes now; their nannies do not restart them.

        A cluster's own close asks each worker to finish its task and waits 4 s before killing
        it: a task can take longer, and Ctrl-C must not wait for it.
        """
        cluster = self.cluster

        async def kill() -> None:  # on the cluster's event loop, where its nannies live
            for nanny in cluster.workers.values():
                close_gracefully = getattr(nanny, "close_gracefully", None)
                if close_gracefully is None:  # not a nanny: the cluster's close stops it
                    continue
                close_gracefully(reason="skygas-pool-closed")  # no restart from now on
                pid = nanny.pid
                if pid:
                    try:
                        os.kill(pid, signal.SIGKILL)
                    except ProcessLookupError:  # already gone
                        pass

        cluster.sync(kill)
