"""A run's pace against the estimate it was started with.

An estimate (:mod:`skygas.core.estimates`) prices a run before it starts, from what the
configuration says: its steps, its skyrmions, its operations. What it cannot see is a gas that
jams: a calibrated model whose chambers fill faster than they empty (800 injected in 4 µs,
609 still inside) costs more per step as it goes. So the run watches itself: once a share of
the work is done at a measured rate, the projected time of the whole job is compared with the
estimate, and a projection more than :data:`SLOWER_FACTOR` times it is said in one line, again
each time the projection doubles, so that a user who left a long run learns it early.
"""

from __future__ import annotations

import sys
import time

from skygas.core.estimates import Estimate, format_duration

#: The projection, over the estimate, that is said.
SLOWER_FACTOR = 2.0
#: What the projection must rest on: wall time [s] measured and share of the job done.
MIN_SECONDS = 20.0
MIN_SHARE = 0.02


class Pace:
    """Watches ``work_done()`` against ``estimate`` (its ``seconds`` for the whole job).

    Call :meth:`after_piece` after each piece; the first piece (which may compile the kernels)
    starts the clock instead of counting.
    """

    def __init__(self, estimate: Estimate | None, work_total: float, stream=None):
        self.estimate = estimate
        self.work_total = work_total
        self.stream = stream
        self._start: tuple[float, float] | None = None  # (wall clock, work done) at the start
        self._said = 0.0  # the last projection said [s]

    def projection(self, work_done: float, now: float | None = None) -> float | None:
        """Projected wall time [s] of the whole job at the rate so far (None: too early)."""
        if self._start is None:
            return None
        t0, w0 = self._start
        elapsed = (time.perf_counter() if now is None else now) - t0
        done = work_done - w0
        if elapsed < MIN_SECONDS or done < MIN_SHARE * self.work_total or done <= 0:
            return None
        return self.work_total * elapsed / done

    def after_piece(self, work_done: float, now: float | None = None) -> str | None:
        """The line to say after a piece, if the run is slower than estimated (it is printed)."""
        if self.estimate is None or not self.estimate.seconds > 0:
            return None
        if self._start is None:
            self._start = (time.perf_counter() if now is None else now, work_done)
            return None
        projected = self.projection(work_done, now)
        threshold = max(SLOWER_FACTOR * self.estimate.seconds, SLOWER_FACTOR * self._said)
        if projected is None or projected <= threshold:
            return None
        self._said = projected
        line = (
            f"skygas: note: slower than estimated: about {format_duration(projected)} in all at "
            f"the rate so far (estimated {format_duration(self.estimate.seconds)}; a gas that "
            "crowds costs more per step); Ctrl-C keeps the run, --resume continues it"
        )
        print(line, file=self.stream or sys.stderr, flush=True)
        return line
