"""The progress bar of a study: finished runs (or trials) out of all, on standard error.

A run's own bar, in its unit of work, is the run driver's (:mod:`skygas.runs.run_driver`);
studies of many runs (``skygas sweep``, ``skygas optimize``) count whole runs with this one.
"""

from __future__ import annotations

from typing import Any


def count_bar(enabled: bool, total: int, initial: int = 0, *, unit: str, desc: str) -> Any:
    """A tqdm bar of ``total`` items, ``initial`` of them done already; None when not ``enabled``.

    Parameters
    ----------
    enabled
        False for ``--quiet`` and ``--json``: no bar at all.
    total, initial
        Items in all, and those done before this session (clipped to ``total``).
    unit, desc
        What is counted ("run", "trial") and the bar's label ("sweep", "optimize").
    """
    if not enabled:
        return None
    from tqdm import tqdm

    return tqdm(total=total, initial=min(initial, total), unit=unit, desc=desc)
