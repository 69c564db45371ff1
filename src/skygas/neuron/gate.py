r"""The neuron's voltage gate (a switchable barrier across the output conduit) and its read
element (a sensor region inside the chamber).

**Gate as a drift barrier.** The compiled kernels take no extra potential, but they do take a
spatial drift field v_s(x) (:meth:`~skygas.engine.Simulation.set_drift_field`). A closed gate
adds, in a band of width w across the output conduit, a drift pointing back into the chamber,

.. math::

    v_\mathrm{gate}(x, y) = -\Big(v_{s,x}^\mathrm{current}(x, y) + \frac{h\,D}{w}\Big)\,\hat x,

with D the free-diffusion constant (docs/physics.md §1). It cancels the current's push across the
band and adds a uniform backward drift whose Péclet integral ∫ v dx / D over the band is h: for
motion along the conduit this is exactly the stationary (Boltzmann) effect of a potential step
of height h k_B T (P ∝ exp(∫ v dx / D)), so ``barrier_height`` is in units of k_B T. The
equivalence is exact for η = α (paper: the drift is then μ v_s with no Hall deflection); for
η ≠ α the drift acquires a Hall component across the conduit, which the conduit walls absorb.
The open gate restores the current's field. Switching is instantaneous, between kernel calls.

**Release drive.** The current that flows while the gate is open may differ from the holding
current while it is closed (``release_current_density`` in the configuration): the same
controller that switches the gate switches the current source, so a firing neuron flushes its
chamber at a high current and integrates at a low one. Both fields come from one current
solution, since v_s = ξ j is linear in the conduit current density J.

**Read element.** A disk (centre, radius) inside the chamber. Its signal is either the number of
skyrmion centres inside (``"count"``) or the fraction of its area covered by skyrmion disks of
diameter d_sk (``"area"``, what a tunnel junction's magnetoresistance reads), plus optional
Gaussian read noise of standard deviation ``read_noise`` (in the signal's units).
"""

from __future__ import annotations

import numpy as np

from skygas import units
from skygas.neuron._compiled import count_in_disk, covered_fraction


class BarrierGate:
    """Switches the drift field between the release field (open) and the holding field with
    the barrier band (closed).

    base_vx, base_vy: holding drift field [m/s] on the simulation grid (the current while
    closed); band_x: (x0, x1) [nm] of the barrier band across the output conduit;
    band_half_width: half the conduit width [nm]; barrier_height: h [k_B T]; diffusion: D [m²/s];
    open_vx, open_vy: drift field [m/s] while open (default: the holding field).
    """

    def __init__(self, sim, base_vx, base_vy, band_x, band_half_width, barrier_height,
                 diffusion, open_vx=None, open_vy=None):
        self.sim = sim
        self.base = (np.asarray(base_vx, float), np.asarray(base_vy, float))
        self.open_field = self.base if open_vx is None else (np.asarray(open_vx, float),
                                                             np.asarray(open_vy, float))
        gx, gy = sim.wall_field.grid.nodes()
        x0, x1 = band_x
        band = (gx >= x0) & (gx <= x1) & (np.abs(gy) <= band_half_width + 1.0)
        width_m = (x1 - x0) / units.M_TO_NM
        push = barrier_height * diffusion / width_m  # m/s
        self.closed_vx = np.where(band, -push, self.base[0])
        self.closed_vy = self.base[1]
        self.band = band
        self.barrier_velocity = push
        self.is_open = None

    def set(self, is_open: bool) -> None:
        if is_open == self.is_open:
            return
        if is_open:
            self.sim.set_drift_field(*self.open_field)
        else:
            self.sim.set_drift_field(self.closed_vx, self.closed_vy)
        self.is_open = bool(is_open)


class ReadElement:
    """A disk-shaped sensor: centre (x, y) [nm], radius [nm], ``signal`` ``"count"`` or
    ``"area"``, Gaussian ``read_noise`` (signal units), its own seeded generator."""

    def __init__(self, center_nm, radius_nm, signal="count", read_noise=0.0, seed=0,
                 skyrmion_diameter_nm=38.2, area_samples=1200):
        self.center = np.asarray(center_nm, float)
        self.radius = float(radius_nm)
        self.signal = signal
        self.read_noise = float(read_noise)
        self.rng = np.random.default_rng(np.random.SeedSequence((seed, 0x726561)))
        self.r_sk = skyrmion_diameter_nm / 2
        if signal == "area":
            # fixed quasi-uniform sample points (sunflower spiral) inside the sensor disk
            k = np.arange(area_samples) + 0.5
            r = self.radius * np.sqrt(k / area_samples)
            phi = k * np.pi * (3 - np.sqrt(5))
            self.samples = self.center + np.column_stack([r * np.cos(phi), r * np.sin(phi)])

    def exact(self, x_nm: np.ndarray, y_nm: np.ndarray, alive: np.ndarray | None = None) -> float:
        """The noiseless reading for skyrmion centres (x, y) [nm] (only where ``alive``)."""
        x_nm = np.ascontiguousarray(x_nm, dtype=float)
        y_nm = np.ascontiguousarray(y_nm, dtype=float)
        alive = np.ones(len(x_nm), np.bool_) if alive is None else alive
        if self.signal == "count":
            return float(count_in_disk(x_nm, y_nm, alive, self.center[0], self.center[1],
                                       self.radius))
        return covered_fraction(x_nm, y_nm, alive, self.center[0], self.center[1], self.radius,
                                self.r_sk, self.samples)

    def read(self, sim) -> float:
        store = sim.state.arrays_nm()
        value = self.exact(store.x, store.y, store.alive)
        if self.read_noise > 0:
            value += self.rng.normal(0.0, self.read_noise)
        return value
