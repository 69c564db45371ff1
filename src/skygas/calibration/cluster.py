"""Where a calibration's solves run side by side: Dask, on a local cluster or a running one.

:class:`SolverPool` is the :class:`~skygas.runs.cluster.TaskPool` that
:class:`~skygas.calibration.pipeline.CalibrationJob` hands its solves to
(:func:`skygas.calibration.worker.solve`): a local cluster of ``--workers`` single-threaded
worker processes, or the scheduler at ``--scheduler ADDRESS`` and its workers (any number,
joining or leaving). Signals, kills and lost workers are the pool's (:mod:`skygas.runs.cluster`):
the local workers ignore Ctrl-C and are killed when the calibration stops (a solve in flight is
recomputed on resume); a worker that dies with a solve, or a scheduler that goes away, ends the
calibration with one line, and ``--resume`` continues from the last checkpoint.
"""

from __future__ import annotations

from distributed import Future

from skygas.calibration import worker
from skygas.runs.cluster import PoolWords, TaskPool

#: How the calibration's one-line errors name its solves and what to do about a lost worker.
WORDS = PoolWords(
    job="the calibration",
    task="solve",
    holders="solver processes",
    local_advice="use fewer --workers or a larger --cell-size; --resume continues from the last "
    "checkpoint",
    remote_advice="give the cluster's workers more memory or use a larger --cell-size; --resume "
    "continues from the last checkpoint",
)


class SolverPool(TaskPool):
    """The Dask client that a calibration's solves go to: a local cluster's or a scheduler's.

    Build it with :meth:`local` or :meth:`remote`; :meth:`close` it.
    """

    @classmethod
    def local(cls, workers: int, words: PoolWords = WORDS, settings: dict | None = None):
        """A local cluster of ``workers`` solver processes, Ctrl-C ignored."""
        return super().local(workers, words, settings)

    @classmethod
    def remote(cls, address: str, words: PoolWords = WORDS):
        """The scheduler at ``address``, refused in one line if it does not answer."""
        return super().remote(address, words)

    def submit_solve(
        self, name: str, kind: str, args: tuple, threads: int, compile: bool, priority: int
    ) -> Future:
        """Hand the solve ``name`` to the workers (:func:`skygas.calibration.worker.solve`).

        The higher ``priority``, the sooner Dask starts it.
        """
        return self.submit(
            worker.solve,
            kind,
            threads,
            compile,
            *args,
            name=f"calibrate-{name}",
            priority=priority,
        )
