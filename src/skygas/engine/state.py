"""The documented way for operations and devices to read and change a simulation's skyrmions.

``sim.state`` is a :class:`StateView`: read-only views of the store (positions in metres, the
alive mask, ids) plus the few changes an operation may make, each of which keeps the engine's
bookkeeping right:

- :meth:`StateView.insert`: new skyrmions at given positions (ids are issued by the engine);
- :meth:`StateView.annihilate`: remove skyrmions by id, recording the time, place and reason;
- :meth:`StateView.is_site_clear`: is no skyrmion closer than a clearance to a point?

Positions are in metres; :meth:`StateView.insert_nm` and :meth:`StateView.is_site_clear_nm`
take nanometres, for devices that keep their geometry in the engine's unit.

Compiled device code that needs the raw arrays (a sensor counting skyrmions in a disk, an
annihilation rate summed over pairs) reads :meth:`StateView.arrays_nm`: read-only views in the
engine's internal unit, nanometres, valid until the next change of the store.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from skygas.core import units

if TYPE_CHECKING:
    from skygas.engine.simulation import Simulation


class StoreArrays(NamedTuple):
    """Read-only views of the store's slots: x, y [nm], alive mask and ids (−1 = empty)."""

    x: np.ndarray
    y: np.ndarray
    alive: np.ndarray
    ids: np.ndarray


def _read_only(array: np.ndarray) -> np.ndarray:
    view = array.view()
    view.flags.writeable = False
    return view


class StateView:
    """The state of a :class:`~skygas.engine.Simulation`, for operations and devices."""

    def __init__(self, sim: Simulation):
        self._sim = sim

    # -- reading ----------------------------------------------------------------------------
    @property
    def ids(self) -> np.ndarray:
        """Ids of the skyrmions present, in increasing order."""
        return self._sim.positions()[0]

    @property
    def positions(self) -> np.ndarray:
        """Positions [m] (n, 2) of the skyrmions present, in the order of :attr:`ids`."""
        return self._sim.positions()[1]

    @property
    def radii(self) -> np.ndarray:
        """Radii [m] (n,) of the skyrmions present, in the order of :attr:`ids`.

        A breathing model's own; rigid skyrmions all have the material's radius.
        """
        return self._sim.radii()[1]

    def arrays_nm(self) -> StoreArrays:
        """Read-only views of the store's slots in nanometres (see the module docstring)."""
        store = self._sim.store
        return StoreArrays(
            _read_only(store.x), _read_only(store.y), _read_only(store.alive), _read_only(store.ids)
        )

    def is_site_clear(self, point, clearance: float) -> bool:
        """True if no skyrmion's centre lies closer than ``clearance`` [m] to ``point`` [m]."""
        x, y = np.asarray(point, dtype=float) * units.M_TO_NM
        return self._sim.store.is_site_clear(x, y, clearance * units.M_TO_NM)

    def is_site_clear_nm(self, x_nm: float, y_nm: float, clearance_nm: float) -> bool:
        """:meth:`is_site_clear` in nanometres.

        For devices that keep their geometry in the engine's internal unit (no round trip through
        metres).
        """
        return self._sim.store.is_site_clear(x_nm, y_nm, clearance_nm)

    # -- changing ---------------------------------------------------------------------------
    def insert(self, positions, *, validate: bool = False) -> np.ndarray:
        """Insert skyrmions at ``positions`` [m] (shape (n, 2)); returns their new ids.

        ``validate`` refuses points outside the device or on top of another skyrmion (see
        :meth:`Simulation.add_skyrmions`); an injector that checks its site itself skips it.
        """
        return self._sim.add_skyrmions(positions, validate=validate)

    def insert_nm(self, positions_nm) -> np.ndarray:
        """:meth:`insert` in nanometres (k, 2), unvalidated.

        For devices that keep their geometry in the engine's internal unit (the kernel's planned
        insertions take the same values, so both paths put a skyrmion on exactly the same point).
        """
        return self._sim.store.insert(np.asarray(positions_nm, dtype=float).reshape(-1, 2))

    def annihilate(self, ids, reason: str) -> None:
        """Remove the present skyrmions ``ids`` (an unknown id raises), recording why.

        The time, their positions and ``reason`` are recorded in ``sim.annihilations``.
        """
        store = self._sim.store
        store.annihilate_slots(store.slots_of(ids), self._sim.time, reason)
