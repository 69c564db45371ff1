"""Standard errors by the delete-one-skyrmion jackknife.

Windowed averages over overlapping time origins reuse each skyrmion's path many times, so the
terms of a pooled average are correlated and the naive σ/√n is far too small. Different
skyrmions of a dilute gas are independent, though: leaving out one skyrmion at a time and
recomputing the statistic gives an honest standard error for any smooth statistic of
per-skyrmion sums (Efron & Stein): SE² = (P − 1)/P Σ_p (θ₋ₚ − θ̄₋)², P skyrmions.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np


def per_skyrmion_sums(ids: np.ndarray, values: np.ndarray, n_groups: int) -> np.ndarray:
    """Σ of ``values`` (n, m) over entries of each skyrmion group index ``ids`` (n,) → (P, m)."""
    out = np.zeros((n_groups, values.shape[1]))
    np.add.at(out, ids, values)
    return out


def jackknife_error(sums: np.ndarray, statistic: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    """Delete-one-skyrmion jackknife standard error of ``statistic(total)``.

    Here ``total`` = ``sums.sum(axis=0)`` and ``sums`` (P, ...) holds each skyrmion's share;
    ``statistic`` maps an array of totals (..., like one row of ``sums``) to the estimate,
    vectorized over leading axes. Skyrmions that contribute nothing are left out of P. NaN with
    fewer than two.
    """
    flat = sums.reshape(len(sums), -1)
    active = np.any(flat != 0, axis=1)
    sums = sums[active]
    p = len(sums)
    total = sums.sum(axis=0)
    if p < 2:
        return np.full(np.shape(statistic(total)), np.nan)
    left_out = statistic(total[None, ...] - sums)
    return np.sqrt((p - 1) / p * np.sum((left_out - left_out.mean(axis=0)) ** 2, axis=0))
