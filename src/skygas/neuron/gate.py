r"""The neuron's voltage gate and its read element.

The gate is a switchable potential barrier across the output conduit, the read element a sensor
region inside the chamber.

**Gate as a potential.** A closed gate is a :class:`~skygas.fields.landscape.Band` across the output
conduit: an energy barrier U(x, y) = H g(s) f(n) whose profile along the conduit,

.. math::

    g(s) = \tfrac12\big[\tanh\big((s + w/2)/e\big) - \tanh\big((s - w/2)/e\big)\big],

rises over the edge width e on either side of a band of width w (between its half-height
points), centred on the conduit's middle; across the conduit it is flat (the band's own side
edges lie 3e outside the conduit's walls). The prefactor H = h k_BT / tanh(w/2e) makes the
top of the barrier, g(0) H, exactly ``barrier_height`` h in units of k_BT at the run's
temperature (k_B · 300 K at T = 0, where k_BT vanishes). Its force −∇U enters the Thiele
equation like the pair and wall forces, so it has the gyrotropic (Hall) response and adds to
the pair forces of a crowd pressing on it. The steepest slope, the largest force the closed
gate can oppose, is about H/(2e); the largest curvature, 2H/(3√3 e²), is a stiffness that
bounds the time step (:func:`gate_relaxation_time`).

The controller switches the band off (open) and on (closed) with
:meth:`~skygas.engine.Simulation.set_landscape_enabled`: the engine sees it at its next step.

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

import math

import numpy as np

from skygas.core import units
from skygas.fields.landscape import Band
from skygas.neuron._compiled import count_in_disk, covered_fraction

#: k_BT of the gate's height at T = 0, where the run's own k_BT is zero [K].
REFERENCE_TEMPERATURE = 300.0
#: Largest |d²/ds² ½ tanh(s/e)| · e²: the steepest curvature of a tanh edge, 2/(3√3).
TANH_EDGE_CURVATURE = 2.0 / (3.0 * math.sqrt(3.0))
#: The band's side edges lie this many edge widths outside the conduit's walls, so that the
#: barrier is flat across the conduit (tanh(3) = 0.995).
SIDE_MARGIN_EDGES = 3.0


def thermal_energy(temperature: float) -> float:
    """k_BT [J] of the gate's height unit: at the run's temperature, k_B·300 K at T = 0."""
    t = temperature if temperature > 0 else REFERENCE_TEMPERATURE
    return units.BOLTZMANN * t


def gate_band(
    center_x: float,
    band_width: float,
    edge_width: float,
    conduit_width: float,
    barrier_height: float,
    temperature: float,
) -> Band:
    """The closed gate's :class:`~skygas.fields.landscape.Band` (all lengths in m).

    Centred at (``center_x``, 0) on a conduit along x of width ``conduit_width``, ``band_width`` w
    between its half-height points, tanh edges of ``edge_width`` e, its top ``barrier_height``
    [k_BT].
    """
    w, e = band_width, edge_width
    height = barrier_height * thermal_energy(temperature) / math.tanh(w / (2 * e))
    return Band(
        height=height,
        edge_width=e,
        start=(center_x - w / 2, 0.0),
        end=(center_x + w / 2, 0.0),
        width=conduit_width + 2 * SIDE_MARGIN_EDGES * e,
        name="gate",
    )


def gate_max_force(band: Band) -> float:
    """The band's steepest slope [N] along the conduit (at its centre line): max |∂U/∂s|."""
    assert band.start is not None and band.end is not None and band.height is not None  # gate_band
    w, e = float(np.hypot(*np.subtract(band.end, band.start))), band.edge_width
    s = np.linspace(-w / 2 - 4 * e, 0.0, 4001)
    slope = 0.5 * (1 / np.cosh((s + w / 2) / e) ** 2 - 1 / np.cosh((s - w / 2) / e) ** 2) / e
    return float(band.height * np.abs(slope).max())


def gate_relaxation_time(band: Band, thiele) -> float:
    """τ [s] of a skyrmion on the band's steepest curvature κ = 2H/(3√3 e²): 1/(κ |M|).

    As the engine's τ_min (:func:`~skygas.engine.relaxation_time`).
    """
    assert band.height is not None  # in J, as gate_band makes it
    kappa = (
        TANH_EDGE_CURVATURE
        * band.height
        * units.J_TO_PN_NM
        / (band.edge_width * units.M_TO_NM) ** 2
    )  # pN/nm
    rate = kappa / math.hypot(thiele.friction_internal, thiele.gyrocoupling_internal)  # 1/ns
    return 1.0 / rate / units.S_TO_NS


class PotentialGate:
    """Switches the gate's landscape term and the current together.

    Closed, the band ``term`` (its index in the simulation's landscape) is on and the holding drift
    field flows; open, the band is off and the release field flows.

    hold_vx, hold_vy: holding drift field [m/s] on the simulation grid; open_vx, open_vy: drift
    field [m/s] while open (default: the holding field); band: the gate's
    :class:`~skygas.fields.landscape.Band` (for the record).
    """

    def __init__(self, sim, term: int, band: Band, hold_vx, hold_vy, open_vx=None, open_vy=None):
        self.sim = sim
        self.term = int(term)
        self.band = band
        self.base = (np.asarray(hold_vx, float), np.asarray(hold_vy, float))
        self.open_field = (
            self.base
            if open_vx is None
            else (np.asarray(open_vx, float), np.asarray(open_vy, float))
        )
        self.is_open: bool | None = None

    def set(self, is_open: bool) -> None:
        """Open (``True``) or close the gate: its band and the drift field switch together."""
        if is_open == self.is_open:
            return
        self.sim.set_drift_field(*(self.open_field if is_open else self.base))
        self.sim.set_landscape_enabled(self.term, not is_open)
        self.is_open = bool(is_open)


class ReadElement:
    """A disk-shaped sensor with its own seeded generator.

    Centre (x, y) [nm], radius [nm], ``signal`` ``"count"`` or ``"area"``, Gaussian ``read_noise``
    (signal units).
    """

    def __init__(
        self,
        center_nm,
        radius_nm,
        signal="count",
        read_noise=0.0,
        seed=0,
        skyrmion_diameter_nm=38.2,
        area_samples=1200,
    ):
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
            return float(
                count_in_disk(x_nm, y_nm, alive, self.center[0], self.center[1], self.radius)
            )
        return covered_fraction(
            x_nm, y_nm, alive, self.center[0], self.center[1], self.radius, self.r_sk, self.samples
        )

    def read(self, sim) -> float:
        """The sensor's reading of ``sim`` now, with read noise if any."""
        store = sim.state.arrays_nm()
        value = self.exact(store.x, store.y, store.alive)
        if self.read_noise > 0:
            value += self.rng.normal(0.0, self.read_noise)
        return value
