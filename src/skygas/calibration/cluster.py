"""Where a calibration's solves run side by side: Dask, on a local cluster or a running one.

:class:`SolverPool` is the Dask client that :class:`~skygas.calibration.pipeline.CalibrationJob`
hands its solves to (:func:`skygas.calibration.worker.solve`), the one parallel backend of
studies, sweeps and calibrations (:mod:`skygas.studies.backend`):

- a local cluster of ``--workers`` single-threaded worker processes, with
  :data:`CLUSTER_SETTINGS`; its workers ignore Ctrl-C (the calibration decides when to stop,
  and saves its checkpoint first), die with the calibration's process, even when it is
  killed by SIGKILL (Dask's worker processes exit when their parent's end of a pipe closes),
  and are killed at once when the calibration stops (a solve in flight is recomputed on
  resume);
- the scheduler at ``--scheduler ADDRESS`` and its workers (any number, joining or leaving).
  There, a solve that a worker has started when the calibration stops finishes on that worker
  and is discarded: Dask cannot stop a running task.

A worker that dies with a solve (the kernel kills the largest process when memory runs out)
ends the calibration with one line naming ``--workers`` (or ``--scheduler``) and what to do,
and so does a scheduler that goes away: ``--resume`` continues from the last checkpoint.

While the pool is open, Dask's own log lines (a worker restarted, a task marked as failed) are
kept from the terminal: the calibration says what happened, in one line.
"""

from __future__ import annotations

import logging
import os
import re
import signal
import time
from concurrent.futures import CancelledError
from typing import Any

from distributed import Client, Future, KilledWorker, WorkerPlugin

from skygas.calibration import worker
from skygas.core.errors import InputError
from skygas.studies.backend import connect, start_local_cluster

#: Dask settings of the calibration's local cluster (beside
#: :data:`skygas.studies.backend.LOCAL_CLUSTER_CONFIG`).
CLUSTER_SETTINGS = {
    # a worker that dies with a solve ends the calibration with one line: most likely the
    # kernel killed it for lack of memory, and a retry would die the same way, a solve later
    "distributed.scheduler.allowed-failures": 0,
    # a solver process's memory is its films' solvers, kept on purpose and checked against the
    # machine before the calibration starts (skygas.calibration.estimate); Dask's limits, a
    # share of the machine per worker, would pause a worker for good (its memory never drops:
    # the calibration would wait for ever) or restart it in the middle of a solve
    "distributed.worker.memory.pause": False,
    "distributed.worker.memory.terminate": False,
}

#: Seconds that the local cluster's nanny has, once a worker is known dead, to say how it died.
DEATH_NOTE_SECONDS = 2.0

#: The nanny's line on a dead worker process (distributed.nanny.WorkerProcess._death_message).
_DEATH = re.compile(
    r"Worker process (\d+) (?:was killed by signal (\d+)|exited with status (\d+)"
    r"|was killed by unknown signal)"
)


class IgnoreInterrupts(WorkerPlugin):
    """Worker set-up on the local cluster: Ctrl-C is the calibration's business.

    A terminal's Ctrl-C reaches every process of its foreground group, the local cluster's
    workers too; one that stopped on it would fail its solve, and the calibration would report
    a dead worker instead of saving its checkpoint. A plugin, not the task: signal handlers can
    only be set in a process's main thread, where Dask sets up plugins and tasks do not run.
    """

    def setup(self, worker) -> None:  # noqa: D102 - WorkerPlugin's
        signal.signal(signal.SIGINT, signal.SIG_IGN)


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


class SolverPool:
    """The Dask client that a calibration's solves go to: a local cluster's or a scheduler's.

    Build it with :meth:`local` or :meth:`remote`; :meth:`close` it.
    """

    def __init__(self, client: Client, logs: _DaskLogs, cluster=None, address: str | None = None):
        self.client = client
        self.cluster = cluster
        #: the scheduler's address, given with ``--scheduler`` (None: a local cluster)
        self.address = address
        self._logs = logs
        self._workers = len(cluster.workers) if cluster is not None else 0

    @classmethod
    def local(cls, workers: int) -> SolverPool:
        """A local cluster of ``workers`` processes (:data:`CLUSTER_SETTINGS`), Ctrl-C ignored."""
        logs = _DaskLogs().install()
        cluster = client = None
        try:
            cluster = start_local_cluster(workers, CLUSTER_SETTINGS)
            client = Client(cluster)
            # the workers that start later (a nanny's restart) are set up as they join
            client.register_plugin(IgnoreInterrupts(), name="skygas-calibrate-ignore-sigint")
            return cls(client, logs, cluster=cluster)
        except BaseException:
            if client is not None:
                client.close()
            if cluster is not None:
                cluster.close()
            logs.remove()
            raise

    @classmethod
    def remote(cls, address: str) -> SolverPool:
        """The scheduler at ``address``, refused in one line if it does not answer."""
        logs = _DaskLogs().install()
        try:
            return cls(connect(address), logs, address=address)
        except BaseException:
            logs.remove()
            raise

    def capacity(self) -> int:
        """Solves to keep in flight: one per worker thread (at least one).

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
        self, name: str, kind: str, args: tuple, threads: int, compile: bool, priority: int
    ) -> Future:
        """Hand the solve ``name`` to the workers (:func:`skygas.calibration.worker.solve`).

        The higher ``priority``, the sooner Dask starts it.
        """
        return self.client.submit(
            worker.solve,
            kind,
            threads,
            compile,
            *args,
            # a new key every time: the same solve handed out again (after a resume, or by a
            # second calibration on the same cluster) is run again, not shared
            key=f"skygas-calibrate-{name.replace('/', '-')}-{time.time_ns()}",
            pure=False,
            priority=priority,
        )

    def result(self, future: Future) -> dict[str, Any]:
        """A finished solve's result; one line if its worker died or the scheduler went away."""
        try:
            return future.result()
        except KilledWorker as err:
            raise self._worker_died(err) from None
        except CancelledError:  # the client lost its scheduler, and the solve with it
            raise self._scheduler_lost() from None
        finally:
            future.release()

    def _worker_died(self, err: KilledWorker) -> InputError:
        """The error of a worker that died with its solve: how, and what to do."""
        if self.cluster is None:
            return InputError(
                "--scheduler",
                self.address,
                "workers that can hold the calibration's solver processes (one died while "
                "solving, and its solve with it)",
                "give the cluster's workers more memory or use a larger --cell-size; --resume "
                "continues from the last checkpoint",
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
            f"solver processes that this machine can hold (one {how}, and its solve with it)",
            "use fewer --workers or a larger --cell-size; --resume continues from the last "
            "checkpoint",
        )

    def _scheduler_lost(self) -> InputError:
        if self.cluster is not None:  # the local cluster lives in this process: not expected
            return InputError(
                "--workers",
                self._workers,
                "a local Dask cluster that stays up (it went away with a solve)",
                "--resume continues from the last checkpoint",
            )
        return InputError(
            "--scheduler",
            self.address,
            "a Dask scheduler that answers until the calibration ends (the connection was lost)",
            "start it again (or drop --scheduler for a local cluster), then run the same "
            "command with --resume: it continues from the last checkpoint",
        )

    def close(self) -> None:
        """Stop: the local cluster's workers at once (their solves are recomputed on resume).

        On a running cluster, the solves handed out are released: those not started are dropped,
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
        it: a relaxation takes longer, and Ctrl-C must not wait for it.
        """
        cluster = self.cluster

        async def kill() -> None:  # on the cluster's event loop, where its nannies live
            for nanny in cluster.workers.values():
                close_gracefully = getattr(nanny, "close_gracefully", None)
                if close_gracefully is None:  # not a nanny: the cluster's close stops it
                    continue
                close_gracefully(reason="skygas-calibrate-closed")  # no restart from now on
                pid = nanny.pid
                if pid:
                    try:
                        os.kill(pid, signal.SIGKILL)
                    except ProcessLookupError:  # already gone
                        pass

        cluster.sync(kill)
