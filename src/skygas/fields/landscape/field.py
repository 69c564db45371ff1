"""An energy landscape on the engine's grid: the sum of its potentials, ready to interpolate.

:class:`LandscapeField` samples every potential (:mod:`skygas.fields.landscape.kinds`) at the nodes
of the wall-field grid, adds them, and keeps the sum as ``nodes[j, i] = (U, h ∂U/∂x, h ∂U/∂y,
h² ∂²U/∂x∂y)`` for the bicubic Hermite interpolant (:mod:`skygas.fields.landscape.hermite`), whose
exact gradient the engine applies as the force −∇U. Terms can be switched off and on during a
run (a gate): the sum is rebuilt in place, so the engine sees the change at its next step
without recompiling anything.
"""

from __future__ import annotations

from typing import cast

import numpy as np

from skygas.core import units
from skygas.core.errors import InputError
from skygas.fields.landscape.hermite import cell_coefficients, energy_and_gradient
from skygas.fields.landscape.kinds import SampleContext, Samples

#: Sub-stream of the run's seed for the random kinds (one child per term).
LANDSCAPE_STREAM = 0x4C414E44
#: The most memory [bytes] the landscape's kept sets of enabled terms may hold (see
#: ``LandscapeField._sum``): a gate's two sets on a device of a few µm.
KEPT_SETS_BYTES = 256 * 2**20


def _aligned_cells(ny: int, nx: int) -> np.ndarray:
    """Zeroed float32 (ny, nx, 16) whose cells start on 64-byte boundaries (one cache line each)."""
    raw = np.zeros(ny * nx * 16 + 16, dtype=np.float32)
    skip = (-raw.ctypes.data % 64) // 4
    return raw[skip : skip + ny * nx * 16].reshape(ny, nx, 16)


def _max_curvature(gx: np.ndarray, gy: np.ndarray, h: float, where=None) -> float:
    """Largest difference quotient [pN/nm] of the gradient (gx, gy) [pN] between neighbouring nodes.

    With ``where`` (a node mask), only between two nodes it holds.
    """
    out = 0.0
    for g in (gx, gy):
        for axis in (0, 1):
            slope = np.abs(np.diff(g, axis=axis)) / h
            if where is not None:
                both = np.logical_and(
                    np.take(where, np.arange(where.shape[axis] - 1), axis),
                    np.take(where, np.arange(1, where.shape[axis]), axis),
                )
                slope = slope[both]
            if slope.size:
                out = max(out, float(slope.max()))
    return out


class LandscapeField:
    """The potentials ``terms`` sampled on ``grid`` at temperature ``temperature`` [K].

    ``grid`` is a :class:`~skygas.fields.wall_field.Grid`; random kinds are drawn from ``seed``.

    Terms made by the device's shape (``needs_film``, the edge stray field) read ``inside``,
    the film's share of each node's cell (:class:`~skygas.fields.landscape.kinds.SampleContext`),
    and their curvature counts for the time step only at the nodes ``reachable`` (where skyrmion
    centres can be; every node if ``None``).
    """

    def __init__(self, terms, grid, temperature: float, seed: int, *, inside=None, reachable=None):
        self.terms = list(terms)
        self.grid = grid
        self.temperature = float(temperature)
        self.seed = int(seed)
        self.reachable = reachable
        gx, gy = grid.nodes()
        kt = units.thermal_energy_internal(temperature)
        self._samples: list[Samples] = []
        for index, term in enumerate(self.terms):
            seq = np.random.SeedSequence([self.seed, LANDSCAPE_STREAM, index])
            try:
                self._samples.append(term.sample(SampleContext(gx, gy, kt, seq, inside)))
            except InputError as err:  # a term's field, named as in the configuration
                raise InputError(
                    f"potentials.{index}.{err.field.removeprefix(term.kind + '.')}",
                    err.value,
                    err.allowed,
                    err.hint,
                ) from None
        self.enabled = [True] * len(self.terms)
        self.nodes = np.zeros((grid.ny, grid.nx, 4))
        #: the interpolant's polynomial per cell (see skygas.fields.landscape.hermite), what the
        #: engine reads; rebuilt in place with the nodes. float32: one cell is one 64-byte
        #: cache line, and a large grid half the memory pages (each skyrmion reads its own
        #: cell somewhere in a grid of up to hundreds of MB: the page-table misses, not the
        #: arithmetic, set the cost)
        self.coefficients = _aligned_cells(max(grid.ny - 1, 1), max(grid.nx - 1, 1))
        #: nodes and coefficients of the sets of enabled terms seen so far (see _sum)
        self._kept: dict[tuple[bool, ...], tuple[np.ndarray, np.ndarray]] = {}
        self._sum()

    def _sum(self) -> None:
        """Rebuild the nodes and the interpolant from the enabled terms.

        A gate switches between a few sets of enabled terms many times a run (the neuron's:
        about 40 times per µs), and each rebuild costs a pass of the interpolant over the whole
        grid (0.4 s at 1 µm); so the sets seen are kept (up to :data:`KEPT_SETS_BYTES`) and a
        switch back copies its arrays: the same values, bit for bit.
        """
        key = tuple(self.enabled)
        kept = self._kept.get(key)
        if kept is not None:
            np.copyto(self.nodes, kept[0])
            np.copyto(self.coefficients, kept[1])
            return
        self._fill()
        size = self.nodes.nbytes + self.coefficients.nbytes
        if size * (len(self._kept) + 1) <= KEPT_SETS_BYTES:
            self._kept[key] = (self.nodes.copy(), self.coefficients.copy())

    def _term_nodes(self, index: int) -> np.ndarray:
        """Term ``index``'s nodes (ny, nx, 4): U, h ∂U/∂x, h ∂U/∂y, h² ∂²U/∂x∂y."""
        h = self.grid.spacing
        s = self._samples[index]
        return np.stack([s.u, h * s.ux, h * s.uy, h * h * s.uxy], axis=-1)

    def _fill(self) -> None:
        self.nodes[...] = 0.0
        for k, on in enumerate(self.enabled):
            if on:
                self.nodes += self._term_nodes(k)
        cell_coefficients(self.nodes, out=self.coefficients)

    def term_coefficients(self, index: int) -> np.ndarray:
        """The interpolant's cells (as :attr:`coefficients`) of term ``index`` alone."""
        out = _aligned_cells(max(self.grid.ny - 1, 1), max(self.grid.nx - 1, 1))
        cell_coefficients(self._term_nodes(index), out=out)
        return out

    def index(self, name_or_index) -> int:
        """The index of a term given by index or by its ``name`` (bands have one)."""
        if isinstance(name_or_index, (int, np.integer)):
            return int(name_or_index)
        names = [getattr(t, "name", None) for t in self.terms]
        from skygas.core.errors import require

        require(
            name_or_index in names,
            "landscape term",
            name_or_index,
            f"one of the named terms {[n for n in names if n]}",
        )
        return names.index(name_or_index)

    def set_enabled(self, term, on: bool) -> None:
        """Switch a term (index or name) on or off; the engine sees it from its next step."""
        k = self.index(term)
        if self.enabled[k] != bool(on):
            self.enabled[k] = bool(on)
            self._sum()

    # -- evaluation (metres and joules at the edge) ------------------------------------------
    def energy_and_force(self, points) -> tuple[np.ndarray, np.ndarray]:
        """U [J] and the force −∇U [N] (n, 2) of the interpolant at ``points`` [m] (n, 2)."""
        p = np.asarray(points, dtype=float).reshape(-1, 2) * units.M_TO_NM
        u, gx, gy = (np.empty(len(p)) for _ in range(3))
        energy_and_gradient(
            self.coefficients,
            self.grid.x0,
            self.grid.y0,
            self.grid.spacing,
            np.ascontiguousarray(p[:, 0]),
            np.ascontiguousarray(p[:, 1]),
            u,
            gx,
            gy,
        )
        force = -np.column_stack([gx, gy]) / units.N_TO_PN
        return u / units.J_TO_PN_NM, force

    def max_curvature(self) -> float:
        """Largest |∂²U| [pN/nm] on the grid: the stiffness that limits the time step.

        It is taken from finite differences of the sampled gradient, and limits the time step like
        the force laws' slopes.

        Terms made by the device's shape (the edge stray field) are counted apart, at the
        ``reachable`` nodes only, as the wall law's slope is counted only where skyrmions can
        be (closer to a wall the step is undone); the bound is the sum, |∂²(U₁ + U₂)| ≤
        |∂²U₁| + |∂²U₂|. Without such terms this is the maximum over all nodes, as always.
        """
        if not self.terms:
            return 0.0
        h = self.grid.spacing
        film = [
            k
            for k, t in enumerate(self.terms)
            if getattr(t, "needs_film", False) and self.enabled[k]
        ]
        if not film:
            return _max_curvature(self.nodes[..., 1] / h, self.nodes[..., 2] / h, h)
        others = [
            k
            for k, t in enumerate(self.terms)
            if not getattr(t, "needs_film", False) and self.enabled[k]
        ]
        total = 0.0
        if others:
            # sums of arrays (typeshed allows sum's start value 0 for an empty iterable)
            gx = cast(np.ndarray, sum(self._samples[k].ux for k in others))
            gy = cast(np.ndarray, sum(self._samples[k].uy for k in others))
            total += _max_curvature(gx, gy, h)
        for k in film:
            total += _max_curvature(self._samples[k].ux, self._samples[k].uy, h, self.reachable)
        return total

    def describe(self) -> list[dict]:
        """The terms as JSON-able records (SI units, as configured)."""
        return [t.model_dump(mode="json") for t in self.terms]
