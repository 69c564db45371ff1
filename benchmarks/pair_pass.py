"""The pair-force pass alone, repeated (a benchmark kernel, not part of the package).

:func:`repeated_pair_pass` builds the engine's neighbour list once and evaluates the pair forces
``repeats`` times, without Python call overhead or the one-body forces: the loop a run repeats
twice per step. ``tests/engine/test_neighbor_list.py`` checks it against a direct sum.
"""

from __future__ import annotations

import numba
import numpy as np

from skygas.engine._jit import JIT
from skygas.engine.neighbors import build_neighbor_list
from skygas.engine.stages import pair_forces
from skygas.engine.terms import COUNTERS


@numba.njit(**JIT)
def _repeated_pair_pass(x, y, alive, cells, pair, repeats, fx, fy, counters_array):
    counters = counters_array[0]
    n = x.shape[0]
    cell_head = np.empty(cells.ncx * cells.ncy, dtype=np.int64)
    cell_next = np.empty(n, dtype=np.int64)
    owner = np.empty(n, dtype=np.int64)
    start = np.empty(n + 1, dtype=np.int64)
    capacity = 16 * n + 16
    margin = np.full(n, 0.5 * cells.skin)
    while True:
        pair_j = np.empty(capacity, dtype=np.int64)
        n_owners = build_neighbor_list(
            x, y, alive, margin, cells, pair.cutoff, cell_head, cell_next, owner, start, pair_j
        )
        if n_owners >= 0:
            break
        capacity *= 2
    for _ in range(repeats):
        pair_forces(x, y, pair, owner, start, pair_j, n_owners, fx, fy, counters)


def repeated_pair_pass(sim, repeats: int) -> tuple[np.ndarray, np.ndarray, int]:
    """Pair forces [pN] on every slot of ``sim``'s store after ``repeats`` passes, and the
    pair evaluations inside the cutoff summed over the passes."""
    store = sim.state.arrays_nm()
    n = len(store.x)
    fx, fy = np.empty(n), np.empty(n)
    counters = np.zeros(1, COUNTERS)
    _repeated_pair_pass(
        store.x,
        store.y,
        store.alive,
        sim.neighbor_cells,
        sim.force_terms.pair,
        repeats,
        fx,
        fy,
        counters,
    )
    return fx, fy, int(counters[0]["pair_evaluations"])
