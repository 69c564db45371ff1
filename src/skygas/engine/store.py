"""The skyrmion store: where the skyrmions of a run live (internal units, nm).

A fixed-capacity structure of arrays (``x``, ``y`` [nm], an ``alive`` mask, a persistent integer
id per skyrmion) that grows on demand, so skyrmions can be inserted and removed during a run.
Ids are issued 0, 1, 2, … in order of creation and never reused; slots carry no meaning (the
noise is keyed on ids), so the store may reorder them (:meth:`sort_into_cells`). Every
annihilation is recorded with its reason (:class:`AnnihilationLog`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numba
import numpy as np

from skygas.core import units
from skygas.core.errors import require
from skygas.core.state_keys import nest, unnest
from skygas.engine.stages import free_slot_if_clear


@numba.njit(cache=True)
def _site_occupied(x, y, alive, sx, sy, clearance2):
    """True if an alive skyrmion lies closer than √clearance2 [nm] to (sx, sy).

    The test the kernel applies to the insertions planned into it.
    """
    return free_slot_if_clear(x, y, alive, sx, sy, clearance2) == -1


def by_id(ids: np.ndarray, x_nm: np.ndarray, y_nm: np.ndarray):
    """(ids in increasing order, positions [m] of shape (n, 2)) of the given skyrmions."""
    order = np.argsort(ids)
    return ids[order].copy(), np.column_stack([x_nm[order], y_nm[order]]) / units.M_TO_NM


class AnnihilationLog:
    """Skyrmions removed by an operation (not through a port), in the order they happened.

    Each row: id, time [s], position [m], reason.
    """

    def __init__(self) -> None:
        self.rows: list[tuple[int, float, float, float, str]] = []

    def append(self, ids, time: float, x_nm, y_nm, reason: str) -> None:
        """Log the skyrmions ``ids`` removed at ``time`` [s] from (``x_nm``, ``y_nm``) [nm].

        ``reason`` says why.
        """
        for ident, xi, yi in zip(ids, x_nm, y_nm, strict=True):
            self.rows.append(
                (
                    int(ident),
                    float(time),
                    float(xi) / units.M_TO_NM,
                    float(yi) / units.M_TO_NM,
                    str(reason),
                )
            )

    def __len__(self) -> int:
        return len(self.rows)

    def count(self, reason: str | None = None) -> int:
        """Removals for ``reason`` (all when None)."""
        return sum(1 for row in self.rows if reason is None or row[4] == reason)

    def times(self, reason: str | None = None) -> np.ndarray:
        """Times [s] of the removals for ``reason`` (all when None), in order."""
        return np.array(
            [row[1] for row in self.rows if reason is None or row[4] == reason], dtype=float
        )

    def arrays(self) -> dict[str, np.ndarray]:
        """``skyrmion``, ``time`` [s], ``x``, ``y`` [m] and ``reason`` as arrays."""
        columns: list[Sequence[Any]] = (
            list(zip(*self.rows, strict=True)) if self.rows else [[], [], [], [], []]
        )
        return {
            "skyrmion": np.array(columns[0], dtype=np.int64),
            "time": np.array(columns[1], dtype=float),
            "x": np.array(columns[2], dtype=float),
            "y": np.array(columns[3], dtype=float),
            "reason": np.array(columns[4], dtype=str),
        }

    @classmethod
    def from_arrays(cls, arrays: dict[str, np.ndarray]) -> AnnihilationLog:
        """The log back from :meth:`arrays`."""
        log = cls()
        log.rows = [
            (int(i), float(t), float(x), float(y), str(r))
            for i, t, x, y, r in zip(
                arrays["skyrmion"],
                arrays["time"],
                arrays["x"],
                arrays["y"],
                arrays["reason"],
                strict=True,
            )
        ]
        return log


class SkyrmionStore:
    """Positions [nm], alive mask and ids of a run's skyrmions, with room to grow.

    ``radius`` [nm] is each skyrmion's radius: ``radius0`` for rigid skyrmions, its own for a
    breathing model (``breathing``), whose checkpoints then carry it.
    """

    def __init__(self, capacity: int = 64, radius0: float = 0.0, breathing: bool = False):
        self.radius0 = float(radius0)
        self.breathing = bool(breathing)
        self.x = np.zeros(capacity)
        self.y = np.zeros(capacity)
        self.radius = np.full(capacity, self.radius0)
        self.alive = np.zeros(capacity, dtype=np.bool_)
        self.ids = np.full(capacity, -1, dtype=np.int64)
        self.next_id = 0
        self.annihilations = AnnihilationLog()

    # -- queries -----------------------------------------------------------------------------
    @property
    def capacity(self) -> int:
        """The number of slots."""
        return len(self.x)

    @property
    def count(self) -> int:
        """The number of skyrmions present."""
        return int(self.alive.sum())

    def used_slots(self) -> int:
        """One past the last occupied slot (0 if the store is empty)."""
        occupied = np.flatnonzero(self.alive)
        return int(occupied[-1]) + 1 if len(occupied) else 0

    def positions(self) -> tuple[np.ndarray, np.ndarray]:
        """(ids, positions [m] of shape (n, 2)) of the skyrmions present, ordered by id."""
        alive = self.alive
        return by_id(self.ids[alive], self.x[alive], self.y[alive])

    def radii(self) -> tuple[np.ndarray, np.ndarray]:
        """(ids, radii [m]) of the skyrmions present, ordered by id."""
        alive = self.alive
        ids = self.ids[alive]
        order = np.argsort(ids)
        return ids[order].copy(), self.radius[alive][order] / units.M_TO_NM

    def present_nm(self) -> np.ndarray:
        """Positions [nm] (n, 2) of the skyrmions present, in slot order."""
        return np.column_stack([self.x[self.alive], self.y[self.alive]])

    def is_site_clear(self, x_nm: float, y_nm: float, clearance_nm: float) -> bool:
        """True if no skyrmion's centre lies closer than ``clearance_nm`` to (x, y) [nm]."""
        return not _site_occupied(
            self.x, self.y, self.alive, float(x_nm), float(y_nm), float(clearance_nm) ** 2
        )

    def slots_of(self, ids) -> np.ndarray:
        """The slots of the present skyrmions with ``ids`` (an unknown id raises)."""
        ids = np.atleast_1d(np.asarray(ids, dtype=np.int64))
        slots = np.empty(len(ids), dtype=np.int64)
        for k, ident in enumerate(ids):
            match = np.flatnonzero(self.alive & (self.ids == ident))
            require(len(match) == 1, "skyrmion id", int(ident), "the id of a present skyrmion")
            slots[k] = match[0]
        return slots

    # -- changes -----------------------------------------------------------------------------
    def grow(self, needed: int) -> None:
        """Make room for at least ``needed`` slots (doubling)."""
        cap = len(self.x)
        if needed <= cap:
            return
        new = max(needed, 2 * cap)
        for name, fill in (
            ("x", 0.0),
            ("y", 0.0),
            ("radius", self.radius0),
            ("alive", False),
            ("ids", -1),
        ):
            old = getattr(self, name)
            arr = np.full(new, fill, dtype=old.dtype)
            arr[:cap] = old
            setattr(self, name, arr)

    def insert(self, p_nm: np.ndarray) -> np.ndarray:
        """Put skyrmions at positions ``p_nm`` (k, 2) [nm] into the lowest free slots.

        Returns their new ids.
        """
        if len(p_nm) == 1:  # the common case of an injector: one skyrmion, first free slot
            slot = int(np.argmin(self.alive))
            if not self.alive[slot]:
                ident = self.next_id
                self.next_id += 1
                self.x[slot], self.y[slot] = p_nm[0]
                self.radius[slot] = self.radius0
                self.alive[slot] = True
                self.ids[slot] = ident
                return np.array([ident], dtype=np.int64)
        free = np.nonzero(~self.alive)[0]
        if len(free) < len(p_nm):
            self.grow(len(self.x) + len(p_nm) - len(free))
            free = np.nonzero(~self.alive)[0]
        slots = free[: len(p_nm)]
        new_ids = np.arange(self.next_id, self.next_id + len(p_nm), dtype=np.int64)
        self.next_id += len(p_nm)
        self.x[slots], self.y[slots] = p_nm[:, 0], p_nm[:, 1]
        self.radius[slots] = self.radius0
        self.alive[slots] = True
        self.ids[slots] = new_ids
        return new_ids

    def annihilate_slots(self, slots: np.ndarray, time: float, reason: str) -> None:
        """Remove the skyrmions in ``slots`` and record why."""
        slots = np.asarray(slots, dtype=np.int64)
        self.annihilations.append(self.ids[slots], time, self.x[slots], self.y[slots], reason)
        self.alive[slots] = False

    def sort_into_cells(self, x0: float, y0: float, size: float) -> None:
        """Store skyrmions in row-major order of the square cells they sit in, packed at the front.

        The cells have side ``size`` [nm] from (x0, y0). Neighbours then sit close in memory and
        consecutive skyrmions read nearby rows of the field grid, which keeps large systems in
        cache. Only the order in which pair forces are summed changes, which moves results by
        floating-point rounding; runs stay bit-reproducible.
        """
        slots = np.flatnonzero(self.alive)
        cx = ((self.x[slots] - x0) // size).astype(np.int64)
        cy = ((self.y[slots] - y0) // size).astype(np.int64)
        order = slots[np.lexsort((cx, cy))]
        n = len(order)
        for name in ("x", "y", "radius", "ids"):
            arr = getattr(self, name)
            arr[:n] = arr[order]
        self.alive[:] = False
        self.alive[:n] = True
        self.ids[n:] = -1

    # -- checkpoints -------------------------------------------------------------------------
    def state_dict(self) -> dict[str, np.ndarray]:
        """Positions, alive mask, ids, the next id and the annihilation log, as raw arrays."""
        log = self.annihilations.arrays()
        radius = {"radius": self.radius.copy()} if self.breathing else {}
        return {
            "x": self.x.copy(),
            "y": self.y.copy(),
            **radius,
            "alive": self.alive.copy(),
            "ids": self.ids.copy(),
            "next_id": np.array(self.next_id),
            **nest("annihilation_", log),
        }

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        """Restore the store from :meth:`state_dict`.

        A checkpoint without an annihilation log gets an empty one.
        """
        self.x, self.y = state["x"].copy(), state["y"].copy()
        if "radius" in state:
            self.radius = state["radius"].copy()
        else:  # rigid skyrmions, or a checkpoint of a run before radii were kept
            self.radius = np.full(len(self.x), self.radius0)
        self.alive, self.ids = state["alive"].copy(), state["ids"].copy()
        self.next_id = int(state["next_id"])
        if "annihilation_skyrmion" in state:
            self.annihilations = AnnihilationLog.from_arrays(unnest("annihilation_", state))
        else:
            self.annihilations = AnnihilationLog()
