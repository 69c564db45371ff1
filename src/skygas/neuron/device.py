"""The Skyrmion Neuron (paper, "Skyrmion Neuron"; docs/physics.md §3).

One chamber of the reshuffler whose output conduit is closed by a voltage gate, a read element
inside the chamber, and a threshold rule that opens the gate (the neuron fires) and closes it again.

Layout: :func:`~skygas.physics.geometry.chamber_with_conduits`; the input conduit's end is a wall
(nucleation site at its middle), the output conduit's end is the read-out line where emitted
skyrmions are detected and removed. The current (conduit density J, v_s = ξ j) drives skyrmions
from input to output; the gate (:class:`~skygas.neuron.gate.PotentialGate`, a potential band
across the output conduit) holds them back. The configuration's own ``potentials`` (a user
landscape) act everywhere in the device, under the gate's band. The current switches with the
gate: the holding density ``current_density`` while it is closed, the release density
``release_current_density`` while it is open (docs/neuron.md, "Choosing the defaults", says
why).

Threshold rule, evaluated every ``read_interval``: a closed gate opens when the reading reaches
``threshold`` (and no refractory time is running); an open gate closes when the reading has
fallen to ``reset_level`` or, if set, ``release_time`` after it opened, whichever comes first;
after closing, the gate stays closed at least ``refractory_time``.

**Output spike** = one release event (gate opening); its time is the opening time. The
skyrmions emitted during each release are also recorded (``exits``, and per release).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from skygas.core import units
from skygas.core.errors import InputError, require
from skygas.engine import Simulation
from skygas.fields.current import solve_current
from skygas.neuron.annihilation import Annihilator
from skygas.neuron.config import NeuronConfig
from skygas.neuron.gate import (
    PotentialGate,
    ReadElement,
    gate_band,
    gate_max_force,
    gate_relaxation_time,
)
from skygas.neuron.inputs import SiteInjector, injection_schedule
from skygas.neuron.saturation import HEX_PACKING, saturation_estimate
from skygas.physics.geometry import chamber_with_conduits
from skygas.runs.device_run import DeviceRun

#: Pieces of a run (each returns to Python once: progress, checkpoints, interruption).
PIECES = 100


@dataclass
class NeuronController:
    """The read-and-threshold rule as an :class:`~skygas.engine.Operation`.

    It also records the count trace (time, chamber count, sensor reading, gate open).
    """

    gate: PotentialGate
    sensor: ReadElement
    interval_steps: int
    threshold: float
    reset_level: float
    release_steps: int | None
    refractory_steps: int
    trace: list = field(default_factory=list)
    openings: list = field(default_factory=list)  # steps
    closings: list = field(default_factory=list)  # steps
    _next: int = 0
    _refractory_until: int = -1
    #: its name among the run's operations: the simulation checkpoints it under this name
    name: str = "controller"

    def next_step(self, step: int) -> int:
        """The step of the next reading."""
        return self._next

    def act(self, sim) -> None:
        """Read the sensor, open or close the gate by the threshold rule, record the trace."""
        self._next = sim.step + self.interval_steps
        reading = self.sensor.read(sim)
        if self.gate.is_open:
            # a gate that starts open has no recorded opening: its release time runs from 0
            opened = self.openings[-1] if self.openings else 0
            timed_out = self.release_steps is not None and sim.step - opened >= self.release_steps
            if reading <= self.reset_level or timed_out:
                self.gate.set(False)
                self.closings.append(sim.step)
                self._refractory_until = sim.step + self.refractory_steps
        elif reading >= self.threshold and sim.step >= self._refractory_until:
            self.gate.set(True)
            self.openings.append(sim.step)
        self.trace.append((sim.time, sim.count, reading, bool(self.gate.is_open)))

    def state_dict(self) -> dict:
        """Trace, openings, closings, schedule, the gate's state and the read element's generator.

        As JSON-able values.
        """
        return {
            "trace": [[float(t), int(n), float(r), bool(o)] for t, n, r, o in self.trace],
            "openings": [int(k) for k in self.openings],
            "closings": [int(k) for k in self.closings],
            "next": int(self._next),
            "refractory_until": int(self._refractory_until),
            "gate_open": bool(self.gate.is_open),
            "sensor_rng": self.sensor.rng.bit_generator.state,
        }

    def load_state_dict(self, state: dict) -> None:
        """Restore what :meth:`state_dict` saved (the gate is set open or closed again)."""
        self.trace = [tuple(e) for e in state["trace"]]
        self.openings = list(state["openings"])
        self.closings = list(state["closings"])
        self._next = int(state["next"])
        self._refractory_until = int(state["refractory_until"])
        self.gate.set(state["gate_open"])
        self.sensor.rng.bit_generator.state = state["sensor_rng"]


class NeuronDevice:
    """A configured neuron, built and validated before anything runs."""

    def __init__(self, config: NeuronConfig):
        self.config = c = config
        self.thiele = c.thiele_parameters()
        d_sk = self.thiele.skyrmion_diameter
        dev = c.device
        require(
            dev.chamber_diameter > 2 * d_sk,
            "device.chamber_diameter",
            dev.chamber_diameter,
            f"a diameter > two skyrmion diameters ({2 * d_sk:.3g} m)",
        )
        require(
            d_sk < dev.conduit_width < dev.chamber_diameter,
            "device.conduit_width",
            dev.conduit_width,
            "a width between one skyrmion diameter and the chamber's",
        )
        full = chamber_with_conduits(dev.chamber_diameter, dev.conduit_width, dev.conduit_length)
        self.outline = full.without_ports("input")
        r_nm = dev.chamber_diameter / 2 * units.M_TO_NM
        half_w = dev.conduit_width / 2 * units.M_TO_NM
        self.x_meet = math.sqrt(r_nm**2 - half_w**2)
        # the nucleation site sits at the input conduit's middle: a conduit shorter than a
        # skyrmion puts it within half a diameter of the end wall, where it collapses at once
        require(
            dev.conduit_length >= d_sk,
            "device.conduit_length",
            dev.conduit_length,
            f"a length >= one skyrmion diameter ({d_sk:.3g} m)",
        )
        length = dev.conduit_length * units.M_TO_NM
        self.site = np.array([-(self.x_meet + length / 2), 0.0])
        self.band = self._gate_band(d_sk)
        self._validate_sensor(r_nm)
        self._validate_threshold(d_sk)
        self.inputs = c.input_specs()  # refuses bad inputs now, not at the first event
        self.full_outline = full

    # -- validation ------------------------------------------------------------------------------
    def _gate_band(self, d_sk: float):
        """The closed gate's band, centred on the output conduit, checked against the conduit.

        The field grid and the time step before anything is built.
        """
        c, dev, g = self.config, self.config.device, self.config.gate
        require(
            g.band_width <= dev.conduit_length,
            "gate.band_width",
            g.band_width,
            f"a width <= the conduit length ({dev.conduit_length:.3g} m): the band between "
            "its half-height points lies inside the output conduit",
        )
        # the band is sampled on the field grid (spacing d_sk/16): a thinner edge is a step
        # that the interpolant does not resolve; an edge wider than half the band leaves no top
        spacing = d_sk / 16
        require(
            spacing <= g.edge_width <= g.band_width / 2,
            "gate.edge_width",
            g.edge_width,
            f"an edge width in [{spacing:.3g}, {g.band_width / 2:.3g}] m (at least one "
            "cell of the field grid, at most half the band's width)",
        )
        center = (self.x_meet + dev.conduit_length * units.M_TO_NM / 2) / units.M_TO_NM
        band = gate_band(
            center, g.band_width, g.edge_width, dev.conduit_width, g.barrier_height, c.temperature
        )
        tau = gate_relaxation_time(band, self.thiele)
        if c.time_step is not None and g.barrier_height > 0 and c.time_step > tau:
            raise InputError(
                "gate.barrier_height",
                g.barrier_height,
                f"a barrier whose steepest edge the time step resolves: with "
                f"edge_width = {g.edge_width:.3g} m it relaxes skyrmions in "
                f"{tau:.3g} s < time_step = {c.time_step:.3g} s; lower the height, "
                "widen gate.edge_width (the stiffness goes as height/edge_width²) "
                "or shorten time_step",
            )
        return band

    def _sensor_geometry_nm(self, r_nm: float) -> tuple[np.ndarray, float]:
        """The read element's centre [nm] and radius [nm] (default: ``r_nm``)."""
        s = self.config.sensor
        center = np.asarray(s.center, float) * units.M_TO_NM
        radius = (s.radius * units.M_TO_NM) if s.radius is not None else r_nm
        return center, radius

    def _validate_sensor(self, r_nm: float) -> None:
        center, radius = self._sensor_geometry_nm(r_nm)
        if np.hypot(*center) + radius > r_nm * (1 + 1e-9):
            raise InputError(
                "sensor",
                {"center_m": list(self.config.sensor.center), "radius_m": radius / units.M_TO_NM},
                f"a disk lying inside the chamber (radius {r_nm * 1e-9:.3g} m about the origin)",
            )

    def saturation_reading(self, d_sk: float) -> float:
        """Largest reading the sensor can see at the chamber's saturation (estimate)."""
        c = self.config
        r_nm = c.device.chamber_diameter / 2 * units.M_TO_NM
        _, radius = self._sensor_geometry_nm(r_nm)
        n_sat = saturation_estimate(c.device.chamber_diameter, d_sk, c.annihilation_model())
        fraction = min(1.0, (radius / r_nm) ** 2)
        if c.sensor.signal == "count":
            return n_sat * fraction
        cover = n_sat * (d_sk / c.device.chamber_diameter) ** 2
        return min(HEX_PACKING, cover)

    def _validate_threshold(self, d_sk: float) -> None:
        rule = self.config.rule
        limit = self.saturation_reading(d_sk)
        if rule.threshold > limit:
            raise InputError(
                "rule.threshold",
                rule.threshold,
                f"a threshold at most the sensor's reading at saturation "
                f"(≈ {limit:.3g} for this chamber, sensor and annihilation model): "
                "above it the gate would never open",
            )
        require(
            rule.reset_level < rule.threshold,
            "rule.reset_level",
            rule.reset_level,
            f"a level below the threshold ({rule.threshold})",
        )

    # -- building ------------------------------------------------------------------------------
    def build(
        self,
        inputs=None,
        duration=None,
        seed=None,
        record_interval=None,
        brownian_substeps=1,
        *,
        priced_runs=None,
    ) -> NeuronRun:
        """A ready :class:`NeuronRun`: simulation, gate, read element and operations.

        Parameters
        ----------
        inputs
            The input spike trains (default: the configuration's).
        duration
            Simulated time [s] (default: the configuration's).
        seed
            The run's seed (default: the configuration's; a transfer curve's runs have
            their own).
        record_interval
            Time [s] between recorded frames (``None``: none).
        brownian_substeps
            The engine's (:class:`~skygas.engine.Simulation`): 2 draws each step's noise as
            two half steps, the time-step check's coarse run (:mod:`skygas.runs.timestep`).
        priced_runs
            What the estimate checked at the build prices, in runs as long as this one
            (default 1: this run; a job that runs a transfer curve after it prices them all
            at its first build, and 0 builds its curve's runs unchecked).
        """
        c = self.config
        seed = c.seed if seed is None else seed
        duration = c.duration if duration is None else duration
        inputs = self.inputs if inputs is None else inputs
        # the gate's band is the last landscape term, after the user's own potentials
        sim = c.simulation(
            self.outline,
            seed=seed,
            temperature=c.temperature,
            time_step=c.time_step,
            brownian_substeps=brownian_substeps,
            extra_potentials=[self.band],
        )
        grid = sim.wall_field.grid
        holding, release = c.current_density, c.release_current()
        if max(holding, release) > 0:
            # one solution at unit conduit density: v_s = ξ j is linear in J
            current = solve_current(self.full_outline, 1.0)
            unit_vx, unit_vy = current.drift_velocity(grid, c.spin_drift_coefficient)
        else:
            unit_vx = unit_vy = np.zeros((grid.ny, grid.nx))
        gate = PotentialGate(
            sim,
            len(c.potentials),
            self.band,
            holding * unit_vx,
            holding * unit_vy,
            release * unit_vx,
            release * unit_vy,
        )
        gate.set(c.gate.initially_open)
        r_nm = c.device.chamber_diameter / 2 * units.M_TO_NM
        center, radius = self._sensor_geometry_nm(r_nm)
        sensor = ReadElement(
            center,
            radius,
            c.sensor.signal,
            c.sensor.read_noise,
            seed,
            self.thiele.skyrmion_diameter * units.M_TO_NM,
        )
        dt = sim.time_step
        steps = lambda t: max(1, int(round(t / dt)))  # noqa: E731
        controller = NeuronController(
            gate,
            sensor,
            steps(c.sensor.read_interval),
            c.rule.threshold,
            c.rule.reset_level,
            None if c.rule.release_time is None else steps(c.rule.release_time),
            int(round(c.rule.refractory_time / dt)),
        )
        annihilator = Annihilator.for_simulation(c.annihilation_model(), sim)
        d_nm = self.thiele.skyrmion_diameter * units.M_TO_NM
        injector = SiteInjector(
            injection_schedule(inputs, duration, dt, seed),
            self.site,
            c.injection.site_clearance * d_nm,
            steps(c.injection.retry_interval),
            c.injection.occupied_rule,
        )
        sim.operations += [injector, annihilator, controller]
        run = NeuronRun(
            self,
            sim,
            gate,
            controller,
            annihilator,
            injector,
            inputs,
            duration,
            record_interval=record_interval,
        )
        run.attach_operations(c.operations)
        runs = 1.0 if priced_runs is None else float(priced_runs)
        if runs > 0:
            self._check_estimate(run, runs)
        return run

    def _check_estimate(self, run: NeuronRun, runs: float) -> None:
        """Refuse a run expected to take too long; announce a long one (core.estimates).

        ``runs`` runs as long as ``run`` are priced: each its steps, its controller's and
        annihilator's turns (every sensor interval and every check interval: on the example,
        the turns cost 50 times the steps) and its build.
        """
        from skygas.core.estimates import check
        from skygas.runs.machine_speed import run_estimate

        frames = 0.0
        if run.record_interval:
            frames = run.duration / run.record_interval + 1
        memory = 24.0 * frames * max(1.0, self.config.rule.threshold)
        turns = sum(
            run.total_steps / op.interval_steps
            for op in (run.controller, run.annihilator)
            if op.next_step(0) < np.iinfo(np.int64).max  # a disabled rule never acts
        )
        check(
            run_estimate(
                runs * run.total_steps,
                max(1.0, self.config.rule.threshold),
                memory,
                turns=runs * turns,
                builds=runs,
            ),
            "duration",
            run.duration,
            "the run" if runs == 1 else f"the run and its transfer curve ({runs:.3g} runs)",
            "use a shorter duration" + ("" if runs == 1 else " or transfer.duration"),
        )


class NeuronRun(DeviceRun):
    """A neuron in progress (:class:`~skygas.runs.device_run.DeviceRun`).

    Its gate, and the operations that drive it, each named so that the simulation checkpoints it
    (``injector``, ``annihilator``, ``controller``).

    Parameters
    ----------
    device
        The configured :class:`NeuronDevice`.
    sim
        Its built simulation.
    gate, controller, annihilator, injector
        The gate and the operations :meth:`NeuronDevice.build` added.
    inputs
        The input spike trains.
    duration
        Simulated time [s] of the run.
    record_interval
        Time [s] between recorded frames (``None``: none; a movie asks for them).
    """

    pieces = PIECES

    def __init__(
        self,
        device: NeuronDevice,
        sim: Simulation,
        gate: PotentialGate,
        controller: NeuronController,
        annihilator: Annihilator,
        injector: SiteInjector,
        inputs: list,
        duration: float,
        record_interval: float | None = None,
    ):
        super().__init__(device.config, sim)
        self.device = device
        self.gate = gate
        self.controller = controller
        self.annihilator = annihilator
        self.injector = injector
        self.inputs = inputs
        self.duration = duration
        self.record_interval = record_interval

    @property
    def total_steps(self) -> int:
        """Steps of the run's duration."""
        from skygas.core.resources import step_count

        return step_count(self.duration, self.sim.time_step)

    def run(self, record_interval: float | None = None) -> NeuronRun:
        """Run to the end, piece by piece, recording positions every ``record_interval`` [s].

        These are the pieces the run driver runs, with progress, checkpoints and interruption
        (:mod:`skygas.neuron.files`).
        """
        if record_interval is not None:
            self.record_interval = record_interval
        self.advance()
        return self

    # -- results -------------------------------------------------------------------------------
    def trace(self) -> dict[str, np.ndarray]:
        """The controller's readings: time [s], count, reading and whether the gate was open."""
        tr = self.controller.trace
        return {
            "time": np.array([t[0] for t in tr]),
            "count": np.array([t[1] for t in tr]),
            "reading": np.array([t[2] for t in tr]),
            "gate_open": np.array([t[3] for t in tr], dtype=bool),
        }

    def spike_times(self) -> np.ndarray:
        """Output spikes: times [s] of the gate openings (release events)."""
        return np.array(self.controller.openings, dtype=float) * self.sim.time_step

    def emission_times(self) -> np.ndarray:
        """Times [s] of every skyrmion emitted through the output read-out line."""
        return self.sim.exits.arrays()["time"].copy()

    def injection_times(self) -> np.ndarray:
        """Times [s] of the injections made."""
        return np.array([s for s, _ in self.injector.injected], dtype=float) * self.sim.time_step

    def input_rate(self) -> float:
        """Expected injection attempts per second (Σ weight·rate over the inputs)."""
        return float(sum(s.weight * s.mean_rate() for s in self.inputs))

    def summary(self) -> dict:
        """Spikes, rates, counts, the leak time, the ISI statistics and the configuration."""
        from skygas.neuron.analysis import isi_statistics, leak_from_log

        tr = self.trace()
        spikes = self.spike_times()
        leak, leak_err = leak_from_log(tr["time"], tr["count"], self.annihilator.annihilation_times)
        rule = self.device.config.rule
        summary = self.base_summary()
        operations = summary.pop("operations", None)
        return {
            **summary,
            "seed": self.sim.seed,  # the build's seed (a transfer curve's runs have their own)
            "output_spikes": spikes.tolist(),
            "n_output_spikes": int(len(spikes)),
            "firing_rate_Hz": len(spikes) / self.sim.time if self.sim.time > 0 else 0.0,
            "input_rate_Hz": self.input_rate(),
            "injection_rate_Hz": self.injector.n_injected / self.sim.time if self.sim.time else 0,
            "leak_time_s": leak,
            "leak_time_error_s": leak_err,
            "threshold": rule.threshold,
            "reset_level": rule.reset_level,
            "max_count": int(tr["count"].max()) if len(tr["count"]) else self.sim.count,
            "final_count": self.sim.count,
            "n_injected": self.injector.n_injected,
            "n_annihilated": self.annihilator.n_annihilated,
            "n_nucleated": self.annihilator.n_nucleated,
            "n_emitted": len(self.sim.exits),
            "n_delayed": self.injector.delayed,
            "n_skipped": self.injector.skipped,
            "n_pending": len(self.injector.pending),
            "isi": isi_statistics(spikes),
            "gate_max_force_N": gate_max_force(self.gate.band),
            "config": self.device.config.model_dump(mode="json"),
            # the user's named operations, if any
            **({"operations": operations} if operations else {}),
        }


def run_neuron(config: NeuronConfig, **kwargs) -> NeuronRun:
    """Build, validate and run one neuron (one call of the CLI)."""
    return NeuronDevice(config).build(**kwargs).run()
