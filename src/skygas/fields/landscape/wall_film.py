"""The wall law as the field of the missing film: every edge in reach, not only the nearest.

The wall law F(w) is measured (or fitted) for one straight edge at distance w. Applied along
the normal of the *nearest* wall only, it ignores a second edge a skyrmion also feels: the
other side of a corner, the far wall of a conduit. Here the law acts instead as an integral
over the film that is not there. A kernel u(ρ) [pN/nm] is chosen so that the half-plane
beyond a straight edge gives the law exactly:

    U(r) = ∫_outside u(|r − r'|) dA',     −dU/dw = F(w) for a straight edge at distance w,

which makes F the Abel transform of u, F(w) = ∫ u(√(w² + y²)) dy, inverted as

    u(ρ) = −(1/π) ∫_0^∞ F'(√(ρ² + s²)) / √(ρ² + s²) ds.

Near one straight edge U is the law's energy ∫_w^∞ F; near a convex corner it is the two edges'
energies less the quadrant they share; in a conduit both walls push; a curved wall wraps
around the skyrmion. The outside is "where the wall distance is negative": beyond a port the
wall distance is positive (:mod:`skygas.fields.wall_field`), so a port is not an edge.

**A breathing skyrmion** meets the walls at the gap w − s_w(R − R₀) between its domain wall and
the edge (:class:`~skygas.physics.materials.BreathingSpec`): the film of a skyrmion of radius R
is the device eroded by δ = s_w(R − R₀). The energy E(r, R) = U_δ(r) is tabulated in layers of
δ, δ_k = δ₀ + k Δδ, each one a landscape of its own, and interpolated between them by the
cubic Catmull–Rom rule (exact for a quadratic in δ); the radius's force is −s_w ∂U_δ/∂δ.

Discretisation: the kernel is averaged over each grid cell (``SUBSAMPLES``² points), the
outside's share of each cell is the linear ramp 1/2 − (d − δ)/h of the wall distance d (exact
for edges along grid lines, and it smooths a curved outline's staircase), and the sum is one
FFT convolution per layer. The law is tapered to zero over the last tenth of its cutoff
(smoothstep), where it is below the table's cutoff fraction of its peak, so that the kernel
has no 1/√(w_c² − ρ²) singularity from the table's step at the cutoff. A straight edge
reproduces the law's energy to ~0.5 % at the default spacing d_sk/16
(tests/fields/landscape/test_wall_film.py).
"""

from __future__ import annotations

import math

import numba
import numpy as np
from scipy import signal

from skygas.fields.landscape.hermite import cell_coefficients

#: Points per cell and axis at which the kernel is averaged over a cell.
SUBSAMPLES = 4
#: Share of the cutoff over which the law is tapered to zero.
TAPER = 0.1
#: Points of the kernel's radial table (and of the Abel integral's s).
KERNEL_POINTS = 512


def tapered_law(table_values: np.ndarray, spacing: float, cutoff: float):
    """F(w) [pN] of a wall table (|F| at w = k·spacing [nm]), tapered to 0 at ``cutoff``."""
    values = np.asarray(table_values, float)

    def force(w):
        w = np.asarray(w, float)
        f = np.interp(w, np.arange(len(values)) * spacing, values, right=0.0)
        t = np.clip((cutoff - w) / (TAPER * cutoff), 0.0, 1.0)
        return f * t * t * (3.0 - 2.0 * t)

    return force


def area_kernel(force, cutoff: float) -> tuple[np.ndarray, np.ndarray]:
    """(ρ, u(ρ)) [nm, pN/nm]: the kernel whose half-plane gives the law ``force`` (F(w) [pN]).

    u(ρ) = −(1/π) ∫ F'(√(ρ² + s²))/√(ρ² + s²) ds over s ∈ [0, √(w_c² − ρ²)] (module docstring),
    F' by central differences, the integral by the trapezoid rule on ``KERNEL_POINTS`` points.
    """
    rho = np.linspace(0.0, cutoff, KERNEL_POINTS)
    step = 1e-3 * cutoff
    u = np.empty_like(rho)
    for k, r in enumerate(rho):
        top = math.sqrt(max(cutoff * cutoff - r * r, 0.0))
        if top == 0.0:
            u[k] = 0.0
            continue
        s = np.linspace(0.0, top, KERNEL_POINTS)
        w = np.sqrt(r * r + s * s)
        slope = (force(w + step) - force(w - step)) / (2 * step)
        u[k] = -np.trapezoid(slope / np.maximum(w, 1e-12), s) / math.pi
    return rho, u


def cell_kernel(rho: np.ndarray, u: np.ndarray, spacing: float) -> np.ndarray:
    """The kernel integrated over each cell around the nodes of offset (i, j)·h [pN·nm]."""
    reach = int(math.ceil(rho[-1] / spacing)) + 1
    offsets = (np.arange(SUBSAMPLES) + 0.5) / SUBSAMPLES - 0.5
    grid = np.arange(-reach, reach + 1) * spacing
    total = np.zeros((len(grid), len(grid)))
    for oy in offsets:
        for ox in offsets:
            x = grid[None, :] + ox * spacing
            y = grid[:, None] + oy * spacing
            total += np.interp(np.hypot(x, y), rho, u, right=0.0)
    return total * (spacing * spacing) / SUBSAMPLES**2


def outside_share(wall_distance: np.ndarray, spacing: float, delta: float = 0.0) -> np.ndarray:
    """The share of each node's cell beyond the walls of the film eroded by ``delta`` [nm]."""
    return np.clip(0.5 - (np.asarray(wall_distance, float) - delta) / spacing, 0.0, 1.0)


def energy(wall_distance: np.ndarray, spacing: float, kernel: np.ndarray, delta: float = 0.0):
    """U [pN·nm] at every node of the wall-distance grid (ny, nx) [nm], film eroded by ``delta``.

    The grid is padded by the kernel's reach with the outside share of its border nodes
    (a straight edge continues straight beyond the grid).
    """
    reach = kernel.shape[0] // 2
    share = np.pad(outside_share(wall_distance, spacing, delta), reach, mode="edge")
    return signal.fftconvolve(share, kernel, mode="valid")


def layer_coefficients(wall_distance, spacing: float, kernel: np.ndarray, delta: float):
    """U [pN·nm] at the nodes and its bicubic Hermite cells (ny − 1, nx − 1, 16) float32.

    The derivatives by fourth-order central differences (as the edge stray field's), on U
    computed two nodes beyond the grid.
    """
    from skygas.fields.landscape.kinds import fourth_order_derivative

    u = energy(np.pad(np.asarray(wall_distance, float), 2, mode="edge"), spacing, kernel, delta)
    ux = fourth_order_derivative(u, spacing, 1)
    uy = fourth_order_derivative(u, spacing, 0)
    uxy = fourth_order_derivative(ux, spacing, 0)
    inner = (slice(2, -2), slice(2, -2))
    nodes = np.stack(
        [u[inner], spacing * ux[2:-2, :], spacing * uy[:, 2:-2], spacing * spacing * uxy], axis=-1
    )
    return u[inner], cell_coefficients(nodes).astype(np.float32)


def layer_deltas(wall_shift: float, growth: float, shrink: float, step: float) -> np.ndarray:
    """δ_k [nm] of the layers: one beyond each end of s_w·[−shrink, growth] (Catmull–Rom)."""
    lo = -wall_shift * shrink
    hi = wall_shift * growth
    if hi - lo <= 0.0:
        return np.zeros(1)
    n = max(int(math.ceil((hi - lo) / step)), 1)
    spacing = (hi - lo) / n
    return lo + spacing * np.arange(-1, n + 2)


@numba.njit(inline="always")
def catmull_rom(t):
    """Weights of the four layers k−1…k+2 at fraction t ∈ [0, 1) past k: value, ∂/∂t, ∂²/∂t².

    Three 4-tuples; compiled, so that the engine's kernel and the tests use the same weights.
    """
    t2 = t * t
    t3 = t2 * t
    value = (
        0.5 * (-t3 + 2 * t2 - t),
        0.5 * (3 * t3 - 5 * t2 + 2),
        0.5 * (-3 * t3 + 4 * t2 + t),
        0.5 * (t3 - t2),
    )
    slope = (
        0.5 * (-3 * t2 + 4 * t - 1),
        0.5 * (9 * t2 - 10 * t),
        0.5 * (-9 * t2 + 8 * t + 1),
        0.5 * (3 * t2 - 2 * t),
    )
    curve = (-3 * t + 2, 9 * t - 5, -9 * t + 4, 3 * t - 1)
    return value, slope, curve


class WallFilm:
    """The wall law's energy as the missing film's field, in layers of erosion δ.

    Parameters
    ----------
    wall_distance : array (ny, nx)
        The wall distance [nm] at the grid's nodes (> 0 inside and beyond ports).
    spacing : float
        The grid's spacing [nm].
    table_values, table_spacing, cutoff
        The wall law's table: |F| [pN] at w = k·``table_spacing`` [nm], 0 beyond ``cutoff``.
    deltas : array
        The layers' erosions δ_k [nm], evenly spaced (one layer, δ = 0, for rigid skyrmions).
    """

    def __init__(self, wall_distance, spacing, table_values, table_spacing, cutoff, deltas):
        self.spacing = float(spacing)
        self.deltas = np.asarray(deltas, float)
        law = tapered_law(table_values, table_spacing, cutoff)
        rho, u = area_kernel(law, cutoff)
        self.kernel = cell_kernel(rho, u, self.spacing)
        ny, nx = np.shape(wall_distance)
        cells = np.empty((len(self.deltas), max(ny - 1, 1), max(nx - 1, 1), 16), np.float32)
        #: U [pN·nm] of each layer at the grid's nodes
        self.energies = []
        for k, d in enumerate(self.deltas):
            u, cells[k] = layer_coefficients(wall_distance, self.spacing, self.kernel, d)
            self.energies.append(u)
        #: every layer's Hermite cells, what the engine reads (C-contiguous, float32)
        self.coefficients = np.ascontiguousarray(cells)

    @property
    def delta0(self) -> float:
        """δ of the first layer [nm]."""
        return float(self.deltas[0])

    @property
    def delta_step(self) -> float:
        """The layers' spacing in δ [nm] (1 for a single layer)."""
        return float(self.deltas[1] - self.deltas[0]) if len(self.deltas) > 1 else 1.0

    @property
    def nbytes(self) -> int:
        """Memory [bytes] of the layers the engine reads."""
        return int(self.coefficients.nbytes)


__all__ = [
    "WallFilm",
    "area_kernel",
    "catmull_rom",
    "cell_kernel",
    "energy",
    "layer_coefficients",
    "layer_deltas",
    "outside_share",
    "tapered_law",
]
