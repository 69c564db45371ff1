"""Current flow through a device: the drift field v_s = ξ·j, resistance, Joule power.

The paper drives skyrmions with the current density j(x) obtained from a separate current-flow
simulation (COMSOL; paper, Methods) and quotes J as the density *in the conduits*
(docs/physics.md §3).
:func:`solve_current` redoes that calculation for any :class:`~skygas.physics.geometry.Outline`:

    ∇·(σ∇φ) = 0          in the device (uniform conductivity σ = 1/ρ),
    j·n̂ = 0              on the walls (insulating),
    φ = V  on the source port(s),  φ = 0  on the sink port(s)   (electrodes),

with V chosen so that the mean of j·n̂ across the source port(s) equals the user's J. Then
j = −σ∇φ, the total current is I = J·w·t (w the source port width, t the conductor thickness),
R = V/I, the Joule power P = I²R and the energy per reshuffled bit is P·Δt_inj (the reshuffler
handles one bit per injection; paper, "Skyrmion Reshuffler", last paragraph of the discussion).

Discretisation
--------------
Finite volumes on square cells of side h (``cell_size``). A cell whose centre lies inside the
outline is an unknown; a face between two such cells carries the current σ t (φ_a − φ_b) (the
two-point flux is exact for a linear φ). A face between an inside cell and an outside cell
carries no current (insulating wall), unless the segment joining the two centres crosses a
source or sink port: then it carries σ t h (φ_cell − φ_port)/d, with d the distance from the
centre to the port (exact for a linear φ, whatever d). The matrix is the symmetric positive
definite graph Laplacian; a sparse direct solve (SuperLU) gives φ to round-off, so the discrete
current is conserved cell by cell to ~1e-12 relative.

The grid is aligned with the first source port: when that port is axis-aligned, the cell size
is rounded to w/round(w/h) and the port's ends fall on cell corners, so the discrete conduit is
exactly w wide and the mean density across it is exactly J.

Accuracy (``docs/current-flow.md`` has the measurements): straight axis-aligned strips are
exact. Curved walls are a staircase, displaced by at most h/√2 from the true wall. The staircase
perturbs j within a few cells of a curved wall: the wall-normal component there is a few % of J
(it averages out along the wall), and the resistance of the paper's chamber moves irregularly by
≲ 0.2 % between h = 2.5 and 1.25 nm. Away from staircase walls the scheme is second order (an
annular sector with curved electrodes matches the exact R to 3e-4 at h = 10 nm).

The solve for 1 V does not depend on J, the thickness or the resistivity, so each process does
it once per (outline, source, sink, cell size) and scales it for each call (:mod:`skygas.core.memo`;
a sweep over J, p or temperature solves once). The results are bit-identical to a fresh solve.

Fields are stored at cell centres and sampled bilinearly; cells outside the outline take the
value of the nearest inside cell, so that bilinear interpolation (here and in the engine, which
reads j on the wall-field grid) stays accurate up to about one cell from the wall. Within that
cell the wall-normal component is not forced to zero (skyrmions are kept much farther from the
walls by the wall force).

Units at the interface are SI (metres, A/m², Ω·m, V, A, W, J); grids use nanometres like the
rest of skygas (:class:`~skygas.fields.wall_field.Grid`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np
from scipy import ndimage, sparse
from scipy.sparse import csgraph
from scipy.sparse.linalg import splu
from shapely.geometry import LineString

from skygas.core.errors import InputError, require
from skygas.core.memo import Memo, frozen, outline_key
from skygas.core.units import M_TO_NM
from skygas.fields.wall_field import Grid, bilinear_at_indices
from skygas.physics.geometry import Outline

#: Default cell size [m]: 40 cells across the paper's 100 nm conduit, ~1.3e5 unknowns for the
#: 1024 nm chamber (about 1.4 s to solve).
DEFAULT_CELL_SIZE = 2.5e-9
#: Default conductor thickness [m]. ASSUMPTION (the paper never states it): a 5 nm heavy-metal
#: (Pt) underlayer carries the current; the 2 nm magnetic film is neglected (or folded into an
#: effective resistivity). Set it for your stack.
DEFAULT_CONDUCTOR_THICKNESS = 5e-9
#: Default resistivity [Ω·m]. ASSUMPTION: a typical thin-film value for a few-nm Pt layer
#: (20 µΩ·cm, about twice bulk Pt). Set it for your stack.
DEFAULT_RESISTIVITY = 2e-7

# More cells than this is refused before anything is allocated (about 1 GB of work arrays).
_MAX_CELLS = 8_000_000
# A port counts as axis-aligned if its direction is within this fraction of an axis.
_AXIS_TOLERANCE = 1e-9


# -- input checks --------------------------------------------------------------------------------
def _positive_number(name: str, value, unit: str) -> float:
    ok = isinstance(value, (int, float, np.floating, np.integer)) and not isinstance(value, bool)
    require(ok and math.isfinite(value) and value > 0, name, value, f"a number > 0 ({unit})")
    return float(value)


def _port_names(name: str, value, outline: Outline) -> tuple[str, ...]:
    names = (
        (value,)
        if isinstance(value, str)
        else tuple(value)
        if isinstance(value, Sequence)
        else None
    )
    allowed = f"a port name or a list of port names of the outline: {outline.port_names()}"
    require(names is not None and len(names) > 0, name, value, allowed)
    assert names is not None  # required just above
    for n in names:
        require(isinstance(n, str) and n in outline.ports, name, value, allowed)
    require(len(set(names)) == len(names), name, value, "port names without repetition")
    return names


def _segments(line: LineString) -> np.ndarray:
    c = np.asarray(line.coords, float)
    return np.hstack([c[:-1], c[1:]])  # (n, 4) x1, y1, x2, y2


def _cross(ax, ay, bx, by):
    return ax * by - ay * bx


def _ray_hits(cx, cy, dx, dy, segs) -> np.ndarray:
    """Fraction s ∈ [0, 1] along c → c + d where the rays first cross ``segs`` (nan: never)."""
    best = np.full(cx.shape, np.nan)
    for x1, y1, x2, y2 in segs:
        ex, ey = x2 - x1, y2 - y1
        denom = _cross(dx, dy, ex, ey)
        with np.errstate(divide="ignore", invalid="ignore"):
            s = _cross(x1 - cx, y1 - cy, ex, ey) / denom
            u = _cross(x1 - cx, y1 - cy, dx, dy) / denom
        hit = (denom != 0) & (s >= 0) & (s <= 1) & (u >= 0) & (u <= 1)
        best = np.where(hit & ~(best <= s), s, best)
    return best


# -- the cell grid -------------------------------------------------------------------------------
@dataclass(frozen=True)
class _Cells:
    """Square cells: cell (i, j) spans [x0 + i·h, x0 + (i+1)·h] × [y0 + j·h, …] nm."""

    x0: float
    y0: float
    h: float
    nx: int
    ny: int

    def centres(self):
        x = self.x0 + self.h * (np.arange(self.nx) + 0.5)
        y = self.y0 + self.h * (np.arange(self.ny) + 0.5)
        return np.meshgrid(x, y)

    def bilinear(self, field: np.ndarray, x, y) -> np.ndarray:
        """Bilinear interpolation of a cell-centred ``field`` at (x, y) nm (clamped)."""
        return bilinear_at_indices(
            field,
            (np.asarray(x, float) - self.x0) / self.h - 0.5,
            (np.asarray(y, float) - self.y0) / self.h - 0.5,
        )


def _aligned_cells(outline: Outline, reference: LineString, cell_size_nm: float) -> _Cells:
    """Cells covering the outline with a margin, aligned with the ``reference`` port."""
    (ax, ay), (bx, by) = reference.coords[0], reference.coords[-1]
    width = math.hypot(bx - ax, by - ay)
    h = cell_size_nm
    axis_aligned = len(reference.coords) == 2 and (
        abs(bx - ax) <= _AXIS_TOLERANCE * width or abs(by - ay) <= _AXIS_TOLERANCE * width
    )
    minx, miny, maxx, maxy = outline._bounds_nm
    if axis_aligned:
        h = width / max(1, round(width / h))
    else:
        ax, ay = minx, miny
    x0 = ax - (math.floor((ax - minx) / h) + 2) * h
    y0 = ay - (math.floor((ay - miny) / h) + 2) * h
    nx = int(math.ceil((maxx - x0) / h)) + 2
    ny = int(math.ceil((maxy - y0) / h)) + 2
    return _Cells(x0, y0, h, nx, ny)


# (neighbour offset di, dj) for the four faces of a cell: east, west, north, south
_DIRECTIONS = ((1, 0), (-1, 0), (0, 1), (0, -1))


@dataclass
class _PortFaces:
    """Boundary faces that are electrodes: the inside cell, direction, conductance, potential."""

    cell_j: np.ndarray
    cell_i: np.ndarray
    direction: np.ndarray  # index into _DIRECTIONS
    conductance: np.ndarray  # h/d (dimensionless; in units of σ t)
    potential: np.ndarray  # 1 on source faces, 0 on sink faces (units of V)
    is_source: np.ndarray
    port: np.ndarray  # index into sources + sinks


def _port_faces(
    cells: _Cells,
    inside: np.ndarray,
    outline: Outline,
    electrodes: Sequence[tuple[str, float, bool]],
) -> _PortFaces:
    """The boundary faces of the electrodes ``(port name, potential [V], is_source)``."""
    cx, cy = cells.centres()
    parts: dict[str, list] = {
        k: []
        for k in ("cell_j", "cell_i", "direction", "conductance", "potential", "is_source", "port")
    }
    for d, (di, dj) in enumerate(_DIRECTIONS):
        neighbour_inside = np.roll(inside, (-dj, -di), axis=(0, 1))
        jj, ii = np.nonzero(inside & ~neighbour_inside)  # the margin keeps rolls from wrapping
        px, py = cx[jj, ii], cy[jj, ii]
        best_s = np.full(px.shape, np.inf)
        best_k = np.full(px.shape, -1)
        for k, (name, _, _) in enumerate(electrodes):
            s = _ray_hits(px, py, di * cells.h, dj * cells.h, _segments(outline.ports[name]))
            closer = np.isfinite(s) & (s < best_s)
            best_s[closer] = s[closer]
            best_k[closer] = k
        hit = best_k >= 0
        kk = best_k[hit]
        parts["cell_j"].append(jj[hit])
        parts["cell_i"].append(ii[hit])
        parts["direction"].append(np.full(hit.sum(), d))
        # A centre (almost) on the port would give an infinite conductance; φ there is φ_port.
        parts["conductance"].append(1.0 / np.maximum(best_s[hit], 1e-3))
        parts["potential"].append(np.array([electrodes[k][1] for k in kk], float))
        parts["is_source"].append(np.array([electrodes[k][2] for k in kk], bool))
        parts["port"].append(kk)
    return _PortFaces(**{k: np.concatenate(v) for k, v in parts.items()})


def _solve_potential(cells: _Cells, inside: np.ndarray, ports: _PortFaces, cell_size: float):
    """φ [V] for the electrodes' potentials, in cells that reach an electrode (nan elsewhere).

    The device must connect at least one source face to one sink face.
    """
    index = np.full(inside.shape, -1)
    n = int(inside.sum())
    index[inside] = np.arange(n)
    rows, cols = [], []
    for di, dj in ((1, 0), (0, 1)):  # each interior face once
        both = inside & np.roll(inside, (-dj, -di), axis=(0, 1))
        a = index[both]
        b = np.roll(index, (-dj, -di), axis=(0, 1))[both]
        rows.append(a)
        cols.append(b)
    a = np.concatenate(rows)
    b = np.concatenate(cols)
    adjacency = sparse.coo_matrix((np.ones(a.size), (a, b)), shape=(n, n)).tocsr()
    adjacency = adjacency + adjacency.T

    # Only cells connected to an electrode have a defined potential.
    _, label = csgraph.connected_components(adjacency, directed=False)
    port_cell = index[ports.cell_j, ports.cell_i]
    live_labels = np.unique(label[port_cell])
    live = np.isin(label, live_labels)
    if (
        np.intersect1d(label[port_cell[ports.is_source]], label[port_cell[~ports.is_source]]).size
        == 0
    ):
        raise InputError(
            "cell_size",
            cell_size,
            "a cell size small enough that the discretised device connects source and sink",
        )

    diagonal = np.asarray(adjacency.sum(axis=1)).ravel()
    np.add.at(diagonal, port_cell, ports.conductance)
    rhs = np.zeros(n)
    np.add.at(rhs, port_cell, ports.conductance * ports.potential)
    matrix = (sparse.diags(diagonal) - adjacency).tocsr()
    keep = np.nonzero(live)[0]
    sub = matrix[keep][:, keep].tocsc()
    # The matrix is symmetric positive definite (a graph Laplacian plus the electrodes'
    # conductances on the diagonal): SuperLU's symmetric mode with a minimum-degree ordering of
    # A + Aᵀ and no pivoting keeps the factor sparse (0.9 s for the 1024 nm chamber's 133 000
    # cells, against 1.3 s for the general solver with the same ordering).
    factor = splu(
        sub, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True}
    )
    phi_live = factor.solve(rhs[keep])

    phi = np.full(inside.shape, np.nan)
    flat = np.full(n, np.nan)
    flat[keep] = phi_live
    phi[inside] = flat
    return phi


# -- the unit-voltage flow (memoised) -------------------------------------------------------------
@dataclass(frozen=True)
class _UnitFlow:
    """The flow for 1 V between source and sink, before scaling to the user's J.

    Everything here depends only on the outline, the electrodes and the cell size, never on J,
    the thickness or the resistivity (the problem is linear), so it is computed once per process
    for each combination (:data:`_MEMO`) and scaled on every call with the arithmetic an
    unmemoised solve would use: results are bit-identical either way. Fields are already
    extended to the outside cells (nearest live cell), which commutes with the scaling.
    """

    cells: _Cells
    inside: np.ndarray
    jx_unit: np.ndarray  # in units of σ·(1 V)/h
    jy_unit: np.ndarray
    phi_unit: np.ndarray  # φ for 1 V (0 … 1)
    # (port, outward current in units of σ t (1 V)) pairs: a tuple, immutable like the arrays
    # and picklable for the disk cache (a MappingProxyType is not)
    port_current_unit: tuple[tuple[str, float], ...]
    source_unit: float
    cells_live: int
    conservation_error: float
    solve_seconds: float


# Unit flows solved in this process (see skygas.core.memo): a sweep over J, p or temperature on one
# device solves the current once.
_MEMO = Memo("current", maxsize=4, persist=True)


def _unit_flow(
    outline: Outline,
    sources: tuple[str, ...],
    sinks: tuple[str, ...],
    h_nm: float,
    cell_size: float,
) -> _UnitFlow:
    started = time.perf_counter()
    cells = _aligned_cells(outline, outline.ports[sources[0]], h_nm)
    cx, cy = cells.centres()
    inside = outline._contains_nm(cx, cy)
    ports = _port_faces(
        cells, inside, outline, [(n, 1.0, True) for n in sources] + [(n, 0.0, False) for n in sinks]
    )
    for side, names, mask in (
        ("source", sources, ports.is_source),
        ("sink", sinks, ~ports.is_source),
    ):
        require(
            bool(mask.any()),
            "cell_size",
            cell_size,
            f"a cell size small enough that the {side} port(s) {list(names)} touch "
            "at least one cell centre inside the outline",
        )
    phi = _solve_potential(cells, inside, ports, cell_size)
    jx_unit, jy_unit, phi_unit, outward, live = _flow_fields(cells, inside, ports, phi)

    # Port currents in units of σ t (1 V): sum of outward face fluxes (h cancels).
    port_current_unit = {}
    for p, name in enumerate(sources + sinks):
        port_current_unit[name] = float(np.sum(outward[ports.port == p]))
    source_unit = -sum(port_current_unit[n] for n in sources)  # into the device
    sink_unit = sum(port_current_unit[n] for n in sinks)  # out of it
    return _UnitFlow(
        cells=cells,
        inside=inside,
        jx_unit=jx_unit,
        jy_unit=jy_unit,
        phi_unit=phi_unit,
        port_current_unit=tuple(port_current_unit.items()),
        source_unit=source_unit,
        cells_live=int(live.sum()),
        conservation_error=abs(sink_unit - source_unit) / source_unit,
        solve_seconds=time.perf_counter() - started,
    )


def _flow_fields(cells: _Cells, inside: np.ndarray, ports: _PortFaces, phi: np.ndarray):
    """The flow from the solved φ: (jx, jy, φ extended to every cell, port face fluxes, live cells).

    Flux densities are in units of σ·V/h, the outward flux of each port face in units of σ t V (V
    the unit of φ).

    Cells outside the outline (and cells cut off from the electrodes) take the nearest live
    value, so that bilinear interpolation stays accurate up to the wall.
    """
    # Flux densities across every face.
    face = []
    for di, dj in _DIRECTIONS:
        other = np.roll(phi, (-dj, -di), axis=(0, 1))
        flow = np.where(inside & np.isfinite(other), phi - other, 0.0)  # walls: 0
        face.append(np.nan_to_num(flow))
    k = ports.cell_j, ports.cell_i
    for d in range(4):
        on = ports.direction == d
        face[d][k[0][on], k[1][on]] = ports.conductance[on] * (
            phi[k[0][on], k[1][on]] - ports.potential[on]
        )
    jx = 0.5 * (face[0] - face[1])
    jy = 0.5 * (face[2] - face[3])
    outward = ports.conductance * (phi[k] - ports.potential)
    live = inside & np.isfinite(phi)
    nearest = ndimage.distance_transform_edt(~live, return_distances=False, return_indices=True)
    jx = jx[nearest[0], nearest[1]]
    jy = jy[nearest[0], nearest[1]]
    phi = phi[nearest[0], nearest[1]]  # every nearest cell is live: no nan left
    frozen(inside, jx, jy, phi)
    return jx, jy, phi, outward, live


# -- the solution --------------------------------------------------------------------------------
@dataclass(frozen=True)
class _CellFlow:
    """Cell-centred fields of a solved flow: j [A/m²], φ [V], and how to sample them."""

    _cells: _Cells = field(repr=False)
    _jx: np.ndarray = field(repr=False)
    _jy: np.ndarray = field(repr=False)
    _phi: np.ndarray = field(repr=False)
    _inside: np.ndarray = field(repr=False)

    def sample(self, grid: Grid) -> tuple[np.ndarray, np.ndarray]:
        """(jx, jy) [A/m²] at the nodes of ``grid`` (nm), arrays of shape (ny, nx).

        Nodes outside the device get the nearest inside value, so the engine's bilinear
        interpolation is accurate up to the wall. Pass ``sim.wall_field.grid`` and hand
        ξ·jx, ξ·jy to ``Simulation.set_drift_field``.
        """
        gx, gy = grid.nodes()
        return self._cells.bilinear(self._jx, gx, gy), self._cells.bilinear(self._jy, gx, gy)

    def drift_velocity(self, grid: Grid, spin_drift_coefficient: float):
        """v_s = ξ·j [m/s] on ``grid``, ξ = ``spin_drift_coefficient`` [m³/C].

        See docs/physics.md §1.
        """
        xi = float(spin_drift_coefficient)
        require(
            math.isfinite(xi),
            "spin_drift_coefficient",
            spin_drift_coefficient,
            "a finite number (m³/C)",
        )
        jx, jy = self.sample(grid)
        return xi * jx, xi * jy

    def current_density_at(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        """(jx, jy) [A/m²] at points (x, y) [m] (outside points: the nearest inside value)."""
        x_nm = np.asarray(x, float) * M_TO_NM
        y_nm = np.asarray(y, float) * M_TO_NM
        return self._cells.bilinear(self._jx, x_nm, y_nm), self._cells.bilinear(
            self._jy, x_nm, y_nm
        )


@dataclass(frozen=True)
class CurrentSolution(_CellFlow):
    """The current flow through one device, scaled to the user's J (SI at the interface).

    Attributes
    ----------
    current_density : float
        J [A/m²], the mean of j·n̂ across the source port(s) (> 0: from source to sink).
    total_current : float
        I = J·w·t [A].
    resistance : float
        R [Ω].
    voltage : float
        V = I·R [V].
    power : float
        Joule power I²R [W].
    solve_seconds : float
        How long the unit-voltage solve took when it was computed (it is shared by every later
        solve of the same outline, ports and cell size in this process).
    """

    current_density: float
    sources: tuple[str, ...]
    sinks: tuple[str, ...]
    cell_size: float
    conductor_thickness: float
    resistivity: float
    source_width: float
    total_current: float
    resistance: float
    voltage: float
    power: float
    cells: int
    solve_seconds: float
    conservation_error: float
    _outline: Outline = field(repr=False)
    _port_flux: dict = field(repr=False)
    _settings: Mapping = field(repr=False)  # solve_current's keyword arguments, as given

    # -- fields --------------------------------------------------------------------------------
    @property
    def cell_grid(self) -> _Cells:
        """The cells the fields live on.

        Hashable; equal for every solve of one outline, set of ports and cell size.
        """
        return self._cells

    def at_current_density(self, current_density: float) -> CurrentSolution:
        """The same device, electrodes and layer driven at another J [A/m²].

        The flow is linear in J; the unit-voltage solve is shared (:data:`_MEMO`).
        """
        return solve_current(self._outline, current_density, **self._settings)

    def potential_at(self, x, y) -> np.ndarray:
        """Electric potential φ [V] at (x, y) [m] (the sink is at 0 V; nearest cell)."""
        i = np.clip(
            ((np.asarray(x, float) * M_TO_NM - self._cells.x0) / self._cells.h).astype(int),
            0,
            self._cells.nx - 1,
        )
        j = np.clip(
            ((np.asarray(y, float) * M_TO_NM - self._cells.y0) / self._cells.h).astype(int),
            0,
            self._cells.ny - 1,
        )
        return self._phi[j, i]

    # -- integrals -----------------------------------------------------------------------------
    def flux_through(self, segment_start, segment_end) -> float:
        """Net current [A] through the straight cut from ``segment_start`` to ``segment_end`` [m].

        Positive when current crosses from the cut's left to its right (walking from start to
        end); a cut upwards (+y) counts current flowing in +x. Integrates t·j·n̂ exactly for the
        bilinear interpolant over the part of the cut inside the outline.
        """
        start = np.asarray(segment_start, float) * M_TO_NM
        end = np.asarray(segment_end, float) * M_TO_NM
        require(
            bool(
                start.shape == (2,)
                and end.shape == (2,)
                and np.all(np.isfinite(start))
                and np.all(np.isfinite(end))
                and np.any(start != end)
            ),
            "segment",
            (segment_start, segment_end),
            "two distinct (x, y) points in metres",
        )
        length = float(np.hypot(*(end - start)))
        normal = np.array([end[1] - start[1], start[0] - end[0]]) / length
        inside = self._outline.region.intersection(LineString([start, end]))
        total = 0.0
        for piece in getattr(inside, "geoms", [inside]):
            if piece.is_empty or piece.geom_type != "LineString":
                continue
            total += self._integrate_normal(np.asarray(piece.coords, float), normal)
        return total * self.conductor_thickness / M_TO_NM  # (A/m²)·nm·m → A

    def _integrate_normal(self, coords: np.ndarray, normal: np.ndarray) -> float:
        """∫ j·n̂ dl [A/m² · nm] along a polyline.

        Gauss–Legendre (2 points) between the cell-centre lines the path crosses, where the bilinear
        interpolant is a quadratic.
        """
        c = self._cells
        total = 0.0
        gauss = 0.5 + np.array([-0.5, 0.5]) / math.sqrt(3.0)
        for p, q in zip(coords[:-1], coords[1:], strict=True):
            cuts = [0.0, 1.0]
            for axis, origin in ((0, c.x0), (1, c.y0)):
                a = (p[axis] - origin) / c.h - 0.5
                b = (q[axis] - origin) / c.h - 0.5
                if a != b:
                    k = np.arange(math.ceil(min(a, b)), math.floor(max(a, b)) + 1)
                    cuts.extend(((k - a) / (b - a)).tolist())
            t = np.unique(np.clip(cuts, 0.0, 1.0))
            t0, dt = t[:-1], np.diff(t)
            s = (t0[:, None] + dt[:, None] * gauss[None, :]).ravel()
            x = p[0] + s * (q[0] - p[0])
            y = p[1] + s * (q[1] - p[1])
            jn = c.bilinear(self._jx, x, y) * normal[0] + c.bilinear(self._jy, x, y) * normal[1]
            weights = np.repeat(dt / 2, 2) * float(np.hypot(*(q - p)))
            total += float(np.sum(weights * jn))
        return total

    def mean_current_density(self, port: str) -> float:
        """Mean of j·n̂ [A/m²] across ``port``, from the discrete port currents.

        n̂ points from source to sink: into the device at a source, out of it at a sink.
        """
        require(
            port in self._port_flux, "port", port, f"a source or sink port: {list(self._port_flux)}"
        )
        current, width = self._port_flux[port]
        return current / (width * self.conductor_thickness)

    def energy_per_bit(self, injection_interval: float) -> float:
        """Energy per reshuffled bit [J] = P·Δt, for one bit per injection.

        One injection every ``injection_interval`` [s] (paper: 0.2 injections/ns → 5 ns).
        """
        dt = _positive_number("injection_interval", injection_interval, "seconds")
        return self.power * dt

    def record(self) -> dict:
        """A JSON-able record of the parameters and results (SI)."""
        return {
            "current_density_A_per_m2": self.current_density,
            "sources": list(self.sources),
            "sinks": list(self.sinks),
            "cell_size_m": self.cell_size,
            "conductor_thickness_m": self.conductor_thickness,
            "resistivity_ohm_m": self.resistivity,
            "source_width_m": self.source_width,
            "total_current_A": self.total_current,
            "resistance_ohm": self.resistance,
            "voltage_V": self.voltage,
            "power_W": self.power,
            "cells": self.cells,
            "solve_seconds": self.solve_seconds,
            "conservation_error": self.conservation_error,
            "port_mean_current_density_A_per_m2": {
                k: self.mean_current_density(k) for k in self._port_flux
            },
            "method": "finite volumes on square cells, staircase insulating walls, "
            "Dirichlet electrodes on the ports, sparse direct solve",
        }

    @property
    def cell_current_density(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple]:
        """(jx, jy, inside, extent) at cell centres [A/m²]; extent (x0, x1, y0, y1) in nm."""
        c = self._cells
        extent = (c.x0, c.x0 + c.nx * c.h, c.y0, c.y0 + c.ny * c.h)
        return self._jx, self._jy, self._inside, extent


def solve_current(
    outline: Outline,
    current_density: float,
    *,
    source: str | Sequence[str] = "input",
    sink: str | Sequence[str] = "output",
    cell_size: float = DEFAULT_CELL_SIZE,
    conductor_thickness: float = DEFAULT_CONDUCTOR_THICKNESS,
    resistivity: float = DEFAULT_RESISTIVITY,
) -> CurrentSolution:
    """Solve ∇·(σ∇φ) = 0 on ``outline``, scaled to a mean current density across the source port(s).

    Parameters
    ----------
    outline : Outline
        The device; its ports named in ``source`` and ``sink`` are the electrodes, all other
        boundary (other ports included) is insulating.
    current_density : float
        J [A/m²], the mean of j·n̂ across the source port(s) (the paper's J "in the conduits");
        positive: current flows from source to sink. Any finite number.
    source, sink : str or sequence of str
        Port name(s); several ports on one side share one potential.
    cell_size : float
        Finite-volume cell side [m] (rounded so the first source port, if axis-aligned, spans a
        whole number of cells). Default 2.5 nm.
    conductor_thickness : float
        Thickness t [m] of the layer that carries the current. Default 5 nm — an ASSUMED Pt
        underlayer; the paper does not state it.
    resistivity : float
        ρ [Ω·m] of that layer. Default 2e-7 Ω·m — an ASSUMED typical thin-film Pt value; the paper
        does not state it.

    Returns
    -------
    CurrentSolution
        The flow, scaled to ``current_density``, with I, R, V and P.

    Raises
    ------
    InputError
        If a value is out of range, or a port is unknown or named as both source and sink.

    Notes
    -----
    The current field depends only on the shape; thickness and resistivity enter only R, V and P.
    """
    require(isinstance(outline, Outline), "outline", type(outline).__name__, "a skygas.Outline")
    ok = isinstance(current_density, (int, float, np.floating, np.integer)) and not isinstance(
        current_density, bool
    )
    require(
        ok and math.isfinite(current_density),
        "current_density",
        current_density,
        "a finite number (A/m²)",
    )
    thickness = _positive_number("conductor_thickness", conductor_thickness, "metres")
    rho = _positive_number("resistivity", resistivity, "Ω·m")
    h_nm = _positive_number("cell_size", cell_size, "metres") * M_TO_NM
    sources = _port_names("source", source, outline)
    sinks = _port_names("sink", sink, outline)
    require(
        not set(sources) & set(sinks),
        "sink",
        sink,
        f"ports different from the source ports {list(sources)}",
    )
    minx, miny, maxx, maxy = outline._bounds_nm
    estimate = ((maxx - minx) / h_nm + 5) * ((maxy - miny) / h_nm + 5)
    require(
        estimate <= _MAX_CELLS,
        "cell_size",
        cell_size,
        f"a cell size giving at most {_MAX_CELLS} cells (this one gives ~{estimate:.2g})",
    )

    flow = _MEMO.get(
        (outline_key(outline), sources, sinks, h_nm),
        lambda: _unit_flow(outline, sources, sinks, h_nm, cell_size),
    )
    port_current_unit = dict(flow.port_current_unit)
    h_m = flow.cells.h / M_TO_NM
    source_width = sum(outline.ports[n].length for n in sources) / M_TO_NM
    total_current = current_density * source_width * thickness
    resistance = rho / (thickness * flow.source_unit)
    voltage = total_current * resistance
    scale = voltage / (rho * h_m)  # σ·V/h: unit flux density → A/m²
    jx = flow.jx_unit * scale
    jy = flow.jy_unit * scale
    phi_volts = flow.phi_unit * voltage

    # Port currents [A] (positive from source to sink) and the physical port widths [m].
    port_flux = {}
    for name in sources:
        port_flux[name] = (
            -port_current_unit[name] * voltage * thickness / rho,
            outline.ports[name].length / M_TO_NM,
        )
    for name in sinks:
        port_flux[name] = (
            port_current_unit[name] * voltage * thickness / rho,
            outline.ports[name].length / M_TO_NM,
        )
    return CurrentSolution(
        current_density=float(current_density),
        sources=sources,
        sinks=sinks,
        cell_size=h_m,
        conductor_thickness=thickness,
        resistivity=rho,
        source_width=source_width,
        total_current=total_current,
        resistance=resistance,
        voltage=voltage,
        power=total_current**2 * resistance,
        cells=flow.cells_live,
        solve_seconds=flow.solve_seconds,
        conservation_error=flow.conservation_error,
        _cells=flow.cells,
        _jx=jx,
        _jy=jy,
        _phi=phi_volts,
        _inside=flow.inside,
        _outline=outline,
        _port_flux=port_flux,
        _settings=MappingProxyType(
            {
                "source": sources,
                "sink": sinks,
                "cell_size": cell_size,
                "conductor_thickness": conductor_thickness,
                "resistivity": resistivity,
            }
        ),
    )


# -- contacts at arbitrary potentials -------------------------------------------------------
@dataclass(frozen=True)
class ContactFlow(_CellFlow):
    """The current flow through a device whose contacts are held at given potentials.

    Every port named in ``potentials`` is an electrode at that potential [V]; the rest of the
    boundary (other ports included) is insulating. The problem is linear, so flows add:
    ``a * f + b * g`` is the flow for the potentials a·V_f + b·V_g (:class:`ContactBasis`).

    Attributes
    ----------
    potentials : Mapping[str, float]
        Contact → potential [V].
    contact_currents : Mapping[str, float]
        Contact → current [A] flowing *into* the device through it (they sum to zero up to
        round-off).
    power : float
        Joule power P = Σ_k V_k I_k = ∫ ρ j² dV [W].
    conductor_thickness, resistivity, cell_size : float
        [m], [Ω·m], [m]: as in :func:`solve_current`.
    """

    potentials: Mapping[str, float]
    contact_currents: Mapping[str, float]
    conductor_thickness: float
    resistivity: float
    cell_size: float

    @property
    def power(self) -> float:
        """Joule power P = Σ_k V_k I_k = ∫ ρ j² dV [W]."""
        return float(sum(self.potentials[k] * self.contact_currents[k] for k in self.potentials))

    def mean_current_density(self) -> float:
        """Area mean of |j| [A/m²] over the cells inside the device."""
        return float(np.mean(np.hypot(self._jx, self._jy)[self._inside]))

    @property
    def cell_fields(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(jx [A/m²], jy [A/m²], φ [V], inside) at the cell centres."""
        return self._jx, self._jy, self._phi, self._inside


def _superpose(flows: Sequence[ContactFlow], weights: Sequence[float]) -> ContactFlow:
    """Σ_i w_i·flow_i: potentials, currents and fields all add (the problem is linear)."""
    first = flows[0]

    def mix(get):
        return sum(w * get(f) for f, w in zip(flows, weights, strict=True))

    names = list(first.potentials)
    return ContactFlow(
        potentials={k: float(mix(lambda f, k=k: f.potentials[k])) for k in names},
        contact_currents={k: float(mix(lambda f, k=k: f.contact_currents[k])) for k in names},
        conductor_thickness=first.conductor_thickness,
        resistivity=first.resistivity,
        cell_size=first.cell_size,
        _cells=first._cells,
        _jx=mix(lambda f: f._jx),
        _jy=mix(lambda f: f._jy),
        _phi=mix(lambda f: f._phi),
        _inside=first._inside,
    )


def _contact_cells(outline: Outline, contacts: Sequence[str], h_nm: float):
    """Cells aligned with the first contact, and the inside mask.

    The cells are shared by every solve on these contacts, so that flows can be added cell by cell.
    """
    cells = _aligned_cells(outline, outline.ports[contacts[0]], h_nm)
    cx, cy = cells.centres()
    return cells, outline._contains_nm(cx, cy)


def _check_contacts(outline: Outline, potentials) -> dict[str, float]:
    allowed = (
        f"a mapping of at least two port names of the outline "
        f"({outline.port_names()}) to finite potentials in volts"
    )
    require(
        isinstance(potentials, Mapping) and len(potentials) >= 2, "potentials", potentials, allowed
    )
    out = {}
    for name, v in potentials.items():
        ok = isinstance(v, (int, float, np.floating, np.integer)) and not isinstance(v, bool)
        require(name in outline.ports and ok and math.isfinite(v), f"potentials.{name}", v, allowed)
        out[name] = float(v)
    return out


def solve_contacts(
    outline: Outline,
    potentials: Mapping[str, float],
    *,
    cell_size: float = DEFAULT_CELL_SIZE,
    conductor_thickness: float = DEFAULT_CONDUCTOR_THICKNESS,
    resistivity: float = DEFAULT_RESISTIVITY,
) -> ContactFlow:
    """Solve ∇·(σ∇φ) = 0 with every port in ``potentials`` held at its potential [V].

    The direct solve for one set of potentials; :class:`ContactBasis` gives the same flow as a
    superposition of unit solutions, which is cheaper when many sets are needed. Cells are
    aligned with the first contact named, as in :class:`ContactBasis`.
    """
    require(isinstance(outline, Outline), "outline", type(outline).__name__, "a skygas.Outline")
    volts = _check_contacts(outline, potentials)
    thickness = _positive_number("conductor_thickness", conductor_thickness, "metres")
    rho = _positive_number("resistivity", resistivity, "Ω·m")
    h_nm = _positive_number("cell_size", cell_size, "metres") * M_TO_NM
    names = list(volts)
    cells, inside = _contact_cells(outline, names, h_nm)
    low = min(volts.values())
    ports = _port_faces(cells, inside, outline, [(n, v, v > low) for n, v in volts.items()])
    for n in range(len(names)):
        require(
            bool(np.any(ports.port == n)),
            "cell_size",
            cell_size,
            f"a cell size small enough that contact {names[n]!r} touches at least one "
            "cell centre inside the outline",
        )
    h_m = cells.h / M_TO_NM
    if np.all(ports.potential == low):  # one potential everywhere: no current
        zero = np.zeros(inside.shape)
        return ContactFlow(
            potentials=volts,
            contact_currents={n: 0.0 for n in names},
            conductor_thickness=thickness,
            resistivity=rho,
            cell_size=h_m,
            _cells=cells,
            _jx=zero,
            _jy=zero,
            _phi=np.full(inside.shape, low),
            _inside=inside,
        )
    phi = _solve_potential(cells, inside, ports, cell_size)
    jx, jy, phi, outward, _ = _flow_fields(cells, inside, ports, phi)
    # flux densities in σ·V/h → A/m²; face fluxes in σ t V → A (inward = −outward)
    currents = {
        n: -float(np.sum(outward[ports.port == p])) * thickness / rho for p, n in enumerate(names)
    }
    scale = 1.0 / (rho * h_m)
    return ContactFlow(
        potentials=volts,
        contact_currents=currents,
        conductor_thickness=thickness,
        resistivity=rho,
        cell_size=h_m,
        _cells=cells,
        _jx=jx * scale,
        _jy=jy * scale,
        _phi=phi,
        _inside=inside,
    )


class ContactBasis:
    """Unit solutions of a set of contacts: contact k at 1 V, the others at 0 V.

    By linearity the flow for potentials V is Σ_k V_k·(unit flow k) (:meth:`flow`), the contact
    currents are I = G·V with the conductance matrix G_kl = current into contact k for 1 V on
    contact l (:attr:`conductance`, [S]), and the Joule power is P = Vᵀ G V.
    """

    def __init__(
        self,
        outline: Outline,
        contacts: Sequence[str],
        *,
        cell_size: float = DEFAULT_CELL_SIZE,
        conductor_thickness: float = DEFAULT_CONDUCTOR_THICKNESS,
        resistivity: float = DEFAULT_RESISTIVITY,
    ):
        names = list(contacts)
        require(
            len(set(names)) == len(names) and len(names) >= 2,
            "contacts",
            contacts,
            "at least two different port names",
        )
        self.contacts = tuple(names)
        self.units = [
            solve_contacts(
                outline,
                {n: float(n == k) for n in names},
                cell_size=cell_size,
                conductor_thickness=conductor_thickness,
                resistivity=resistivity,
            )
            for k in names
        ]
        self.conductance = np.array([[u.contact_currents[k] for u in self.units] for k in names])

    def flow(self, potentials: Mapping[str, float]) -> ContactFlow:
        """The flow for ``potentials`` (every contact named, volts) by superposition."""
        require(
            isinstance(potentials, Mapping) and set(potentials) == set(self.contacts),
            "potentials",
            potentials,
            f"a potential [V] for each of {list(self.contacts)}",
        )
        return _superpose(self.units, [float(potentials[n]) for n in self.contacts])

    def power(self, potentials: Mapping[str, float]) -> float:
        """Joule power P = Vᵀ G V [W] for ``potentials`` [V]."""
        v = np.array([float(potentials[n]) for n in self.contacts])
        return float(v @ self.conductance @ v)
