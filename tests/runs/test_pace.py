"""A run slower than its estimate says so, once per doubling, and not before it has measured."""

from __future__ import annotations

import io

from skygas.core.estimates import Estimate
from skygas.runs.pace import MIN_SECONDS, Pace


def _pace(estimated: float) -> tuple[Pace, io.StringIO]:
    stream = io.StringIO()
    return Pace(Estimate(1e6, 0.0, estimated), work_total=100.0, stream=stream), stream


def test_a_run_at_its_estimate_says_nothing():
    pace, stream = _pace(estimated=1000.0)
    pace.after_piece(0.0, now=0.0)  # the first piece starts the clock (it may compile)
    for k in range(1, 100):
        assert pace.after_piece(float(k), now=10.0 * k) is None  # 1000 s in all: as estimated
    assert stream.getvalue() == ""


def test_a_run_three_times_slower_says_so_once_then_again_when_it_doubles():
    pace, stream = _pace(estimated=100.0)
    pace.after_piece(0.0, now=0.0)
    said = []
    # 3 s per unit of work: 300 s in all, then slower still after half the work (12 s per unit)
    t = 0.0
    for k in range(1, 100):
        t += 3.0 if k <= 50 else 12.0
        line = pace.after_piece(float(k), now=t)
        if line is not None:
            said.append((k, line))
    assert [k for k, _ in said][0] == MIN_SECONDS // 3 + 1  # once 20 s are measured
    assert "about 5 min in all" in said[0][1] and "estimated 1.7 min" in said[0][1]
    # the projection reaches 600 s (twice the first one said) only as the run slows
    assert len(said) == 2 and said[1][0] > 50
    assert stream.getvalue().count("slower than estimated") == 2


def test_no_estimate_no_word():
    stream = io.StringIO()
    pace = Pace(None, work_total=10.0, stream=stream)
    for k in range(10):
        assert pace.after_piece(float(k), now=100.0 * k) is None
    assert stream.getvalue() == ""
