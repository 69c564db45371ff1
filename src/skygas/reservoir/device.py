"""The Brownian reservoir device: skyrmions in a chamber, driven by a stream of held inputs.

For each input symbol of the stream the contact voltages are set (:mod:`~skygas.reservoir.drive`:
the drift field v_s = ξ·j of that symbol's current pattern), the engine runs for ``hold_time``,
and the sensors (:mod:`~skygas.reservoir.sensors`) are read every ``sample_interval`` with read
noise. The reservoir state of that input is the feature vector of the sensor means over
``bins`` equal windows of the hold (sensors × bins numbers): the last window says where the
present input sends the skyrmion, the first still remembers where the previous one left it.

The skyrmion is never reset between inputs: the device carries its state from one input to the
next, which is its (fading) memory. A stream (:class:`StreamSpec`) is run by a
:class:`StreamRun`, which can stop after any input and continue from its
:meth:`~StreamRun.state_dict` in this or another process, with the same numbers as a stream
run in one go. Several independent streams of a study (each its own seed) run in parallel
processes and are concatenated (:mod:`skygas.reservoir.streams`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from skygas._version import __version__
from skygas.core.errors import require
from skygas.core.units import M_TO_NM
from skygas.physics import geometry as geo
from skygas.reservoir.chamber import build_chamber, contact_middles
from skygas.reservoir.config import ReservoirConfig
from skygas.reservoir.drive import Drive
from skygas.reservoir.sensors import coverage
from skygas.runs.device_run import DeviceRun
from skygas.runs.run_driver import from_json_array, json_array

#: Occupation maps are histograms on this many bins along the chamber's longer side.
MAP_BINS = 48


@dataclass
class StreamResult:
    """What one stream of held inputs produced."""

    bits: np.ndarray  # (n_inputs, n_input_contacts) the input symbols, in order
    features: np.ndarray  # (n_inputs, n_sensors · bins) sensor means per window
    occupation: np.ndarray  # (n_symbols, ny, nx) frames with a skyrmion centre in each bin
    map_extent: tuple  # (x0, x1, y0, y1) [nm] of the occupation maps
    sensor_means: np.ndarray  # (n_symbols, n_sensors) mean signal while each symbol is held
    steps: int
    cpu_seconds: float
    wall_seconds: float
    #: the summaries of the stream's ``[[operations]]`` (:mod:`skygas.runs.operations`)
    operations: dict | None = None


@dataclass(eq=False)
class StreamSpec:
    """One stream of held inputs, as a study draws it.

    The configuration whose device runs it, the input symbols, the seed, and how the inputs
    are held (``None``: the configuration's ``hold_time`` and ``sensors.sample_interval``).
    ``warmup`` random inputs (drawn from the seed) are held first and not recorded.
    """

    config: ReservoirConfig
    bits: np.ndarray  # (n_inputs, n_input_contacts) of 0/1
    seed: int
    warmup: int = 0
    hold_time: float | None = None  # s
    sample_interval: float | None = None  # s

    @property
    def hold(self) -> float:
        """The time each input is held [s]."""
        return self.config.hold_time if self.hold_time is None else self.hold_time

    @property
    def n_total(self) -> int:
        """Inputs held in all, the warm-up included."""
        return self.warmup + len(self.bits)


class ReservoirDevice:
    """A validated reservoir: chamber, contacts, drive, sensors.

    Everything is checked on construction, before any run.
    """

    def __init__(self, config: ReservoirConfig):
        self.config = config
        self.outline = build_chamber(config.chamber)
        self.walls = self.outline.without_ports(*self.outline.port_names())
        self.drive = Drive.build(self.outline, config.drive)
        middles = contact_middles(self.outline)
        s = config.sensors
        if s.centers:
            from shapely.geometry import Point

            for k, c in enumerate(s.centers):
                gap = self.walls.region.distance(Point(c[0] * M_TO_NM, c[1] * M_TO_NM))
                require(
                    gap < s.radius * M_TO_NM,
                    f"sensors.centers[{k}]",
                    list(c),
                    "a sensor centre whose disk overlaps the chamber",
                )
            self.sensor_names = [f"S{k}" for k in range(len(s.centers))]
            self.sensor_centers = np.asarray(s.centers, float)
        else:
            self.sensor_names = list(middles)
            self.sensor_centers = np.array([middles[n] for n in self.sensor_names])
        probe = self.simulation(seed=config.seed)  # checks the material, time step, landscape
        self.time_step = probe.time_step
        self.skyrmion_radius_nm = probe.thiele.skyrmion_diameter_internal / 2
        self.diffusion_constant = probe.thiele.diffusion_constant(max(config.temperature, 0.0))
        for field, hold in (
            ("hold_time", config.hold_time),
            ("study.temporal_hold_time", config.study.temporal_hold_time),
        ):
            require(
                hold >= self.time_step,
                field,
                hold,
                f"a hold time of at least one time step ({self.time_step:.3g} s)",
            )
        st = config.study
        for field, interval, hold in (
            ("sensors.sample_interval", s.sample_interval, config.hold_time),
            ("study.temporal_sample_interval", st.temporal_sample_interval, st.temporal_hold_time),
        ):
            require(
                interval >= self.time_step,
                field,
                interval,
                f"an interval of at least one time step ({self.time_step:.3g} s)",
            )
            require(
                hold >= s.bins * interval,
                field,
                interval,
                f"at most 1/{s.bins} of the "
                f"hold time {hold:.3g} s, so that each of the sensors.bins = {s.bins} "
                "windows gets a read",
            )
        self._fields = self.drive.drift_fields(probe.wall_field.grid)
        self._initial_positions(probe, np.random.default_rng(0))  # do they fit?

    # -- parts ---------------------------------------------------------------------------------
    def simulation(self, seed: int, brownian_substeps: int = 1):
        """A fresh engine run in the closed chamber (contacts are walls for skyrmions).

        ``brownian_substeps`` is the engine's (:class:`~skygas.engine.Simulation`): 2 draws each
        step's noise as two half steps, the time-step check's coarse run
        (:mod:`skygas.runs.timestep`).
        """
        c = self.config
        return c.simulation(
            self.walls,
            seed=seed,
            temperature=c.temperature,
            time_step=c.time_step,
            brownian_substeps=brownian_substeps,
        )

    def _initial_positions(self, sim, rng) -> np.ndarray:
        d = sim.thiele.skyrmion_diameter_internal
        return geo._random_positions_nm(self.walls, self.config.n_skyrmions, 1.2 * d, 1.0 * d, rng)

    def map_extent(self) -> tuple[float, float, float, float]:
        """The occupation maps' extent (x0, x1, y0, y1) [nm]: the chamber's bounds."""
        x0, y0, x1, y1 = self.outline._bounds_nm
        return (x0, x1, y0, y1)

    def map_shape(self) -> tuple[int, int]:
        """The occupation maps' shape (ny, nx): square bins, :data:`MAP_BINS` on the long side."""
        x0, x1, y0, y1 = self.map_extent()
        size = max(x1 - x0, y1 - y0) / MAP_BINS
        return (max(1, round((y1 - y0) / size)), max(1, round((x1 - x0) / size)))

    # -- running -------------------------------------------------------------------------------
    def run_stream(self, spec: StreamSpec) -> StreamResult:
        """Hold every input of the stream ``spec`` in turn and return what it produced.

        See :class:`StreamRun`.
        """
        run = StreamRun(self, spec)
        run.hold_inputs(spec.n_total)
        return run.result()

    def describe(self) -> dict:
        """A JSON-able record of the device (SI)."""
        c = self.config
        return {
            "skygas_version": __version__,
            "seed": c.seed,
            "config": c.model_dump(mode="json"),
            "time_step_s": self.time_step,
            "diffusion_constant_m2_per_s": self.diffusion_constant,
            "chamber_area_m2": self.outline.area(),
            # the time for the mean squared displacement 4Dt to reach the chamber's area
            "exploration_time_s": self.outline.area() / (4 * self.diffusion_constant)
            if self.diffusion_constant > 0
            else None,
            "sensors": {
                n: list(map(float, p))
                for n, p in zip(self.sensor_names, self.sensor_centers, strict=True)
            },
            "drive": self.drive.record(c.hold_time),
            "geometry": self.outline.describe(),
        }


class StreamRun(DeviceRun):
    """A stream of held inputs (:class:`StreamSpec`) on ``device``, held a few inputs at a time.

    A device run (:class:`~skygas.runs.device_run.DeviceRun`) whose pieces are whole inputs:
    each input sets its symbol's drift field and runs the engine for the hold time, reading
    the sensors every ``interval`` (the hold divided into a whole number of reads, at least
    ``sensors.bins``); its features are the sensor means over ``bins`` windows of the hold.
    The configuration's ``[[operations]]`` (:mod:`skygas.runs.operations`) are attached to the
    stream's simulation. :meth:`state_dict` holds everything that changes (the simulation and
    its operations, the stream's random generator for the read noise, the features and
    occupation so far) as NumPy arrays: a run built again from the same device and spec and
    given that state continues bit-identically, wherever the stream was cut (every input is
    one call of the engine either way).
    """

    def __init__(self, device: ReservoirDevice, spec: StreamSpec):
        super().__init__(device.config, device.simulation(spec.seed))
        self.device = device
        self.spec = spec
        c = device.config
        self.hold = spec.hold
        every = c.sensors.sample_interval if spec.sample_interval is None else spec.sample_interval
        # the stream's own generator: initial positions, warm-up symbols, read noise (in order)
        self.rng = np.random.default_rng(np.random.SeedSequence([spec.seed, 0x5E5]))
        self.sim.state.insert_nm(device._initial_positions(self.sim, self.rng))
        self.attach_operations(c.operations)
        self.bits = np.asarray(spec.bits, int)
        warm = self.rng.integers(0, 2, size=(spec.warmup, self.bits.shape[1]))
        self.inputs = np.vstack([warm, self.bits]).astype(int)
        self.warmup = spec.warmup
        self.n_bins = c.sensors.bins
        reads = max(self.n_bins, int(round(self.hold / every)))
        self.interval = self.hold / reads
        self.extent = device.map_extent()
        self.shape = device.map_shape()
        n_symbols, n_sensors = len(device.drive.symbols), len(device.sensor_centers)
        self.occupation = np.zeros((n_symbols, *self.shape))
        self.sums = np.zeros((n_symbols, n_sensors))
        self.counts = np.zeros(n_symbols)
        self.features = np.zeros((len(self.bits), n_sensors * self.n_bins))
        self.position = 0  # inputs held so far, the warm-up included
        self.cpu_seconds = 0.0

    @property
    def finished(self) -> bool:
        """Whether every input has been held."""
        return self.position >= len(self.inputs)

    # -- the device run's skeleton: a piece is whole inputs ------------------------------------
    @property
    def hold_steps(self) -> int:
        """Engine steps of one held input (the hold's nearest whole number)."""
        return round(self.hold / self.sim.time_step)

    @property
    def total_steps(self) -> int:
        """Steps of the whole stream (warm-up included)."""
        return len(self.inputs) * self.hold_steps

    @property
    def piece_steps(self) -> int:
        """A piece: the stream cut into :attr:`pieces`, rounded up to whole inputs."""
        inputs = max(1, -(-len(self.inputs) // self.pieces))
        return inputs * self.hold_steps

    def run_steps(self, n: int) -> None:
        """Hold the inputs of the next ``n`` steps (whole inputs, see :attr:`piece_steps`)."""
        self._hold(-(-n // self.hold_steps))

    def hold_inputs(self, n_inputs: int) -> None:
        """Hold the next ``n_inputs`` inputs (fewer at the end of the stream)."""
        started = time.perf_counter()
        self._hold(n_inputs)
        self.wall_time += time.perf_counter() - started

    def _hold(self, n_inputs: int) -> None:
        cpu = time.process_time()
        device, sim, c = self.device, self.sim, self.device.config
        symbols = device.drive.symbols
        centers_nm = device.sensor_centers * M_TO_NM
        end = min(self.position + n_inputs, len(self.inputs))
        for n in range(self.position, end):
            key = tuple(int(b) for b in self.inputs[n])
            sim.set_drift_field(*device._fields[key])
            start, dt = sim.step, sim.time_step
            # whole numbers of steps: the hold's and the reads' nearest
            sim.run(
                round(self.hold / dt) * dt,
                record_interval=max(1, round(self.interval / dt)) * dt,
            )
            # the frames within the hold, after its start (the first hold's frame at t = 0
            # belongs to no input)
            blocks = sim.take_frames()
            x = np.concatenate([b.x[b.step > start] for b in blocks])
            y = np.concatenate([b.y[b.step > start] for b in blocks])
            if n < self.warmup:
                continue
            signal = coverage(
                x, y, centers_nm, c.sensors.radius * M_TO_NM, device.skyrmion_radius_nm
            )
            if c.sensors.read_noise > 0:
                signal = signal + self.rng.normal(0.0, c.sensors.read_noise, signal.shape)
            windows = np.array_split(signal, self.n_bins)
            self.features[n - self.warmup] = np.concatenate([w.mean(axis=0) for w in windows])
            s = symbols.index(key)
            self.sums[s] += signal.sum(axis=0)
            self.counts[s] += len(signal)
            ok = np.isfinite(x)
            extent = self.extent
            hist, _, _ = np.histogram2d(
                y[ok], x[ok], bins=self.shape, range=[extent[2:], extent[:2]]
            )
            self.occupation[s] += hist
        self.position = end
        self.cpu_seconds += time.process_time() - cpu

    def extra_state(self) -> dict[str, np.ndarray]:
        """What the stream keeps beside its simulation, as NumPy arrays.

        Its generator, the inputs held, the features, occupation and sensor sums so far, the
        CPU time and its operations' summaries (``operations_json``: the process that scores
        the stream holds its state, not its simulation).
        """
        return dict(
            rng=json_array(self.rng.bit_generator.state),
            position=np.array(self.position),
            features=self.features.copy(),
            occupation=self.occupation.copy(),
            sums=self.sums.copy(),
            counts=self.counts.copy(),
            map_extent=np.array(self.extent, float),
            steps=np.array(self.sim.step),
            cpu_seconds=np.array(self.cpu_seconds),
            operations_json=json_array(self.sim.operation_summaries()),
        )

    def load_extra_state(self, state: dict[str, np.ndarray]) -> None:
        """Restore what :meth:`extra_state` saved (same device and spec)."""
        self.rng.bit_generator.state = from_json_array(state["rng"])
        self.position = int(state["position"])
        self.features = np.array(state["features"], float)
        self.occupation = np.array(state["occupation"], float)
        self.sums = np.array(state["sums"], float)
        self.counts = np.array(state["counts"], float)
        self.cpu_seconds = float(state["cpu_seconds"])

    def result(self) -> StreamResult:
        """What the stream produced (its inputs held so far)."""
        return stream_result(self.bits, self.state_dict())


def stream_result(bits: np.ndarray, state: dict[str, np.ndarray]) -> StreamResult:
    """What a stream of inputs ``bits`` produced, from its state alone.

    ``state`` is :meth:`StreamRun.state_dict` of the finished stream; its device is not built
    again.
    """
    counts = np.asarray(state["counts"], float)
    return StreamResult(
        bits=np.asarray(bits, int),
        features=np.asarray(state["features"], float),
        occupation=np.asarray(state["occupation"], float),
        map_extent=tuple(float(v) for v in state["map_extent"]),
        sensor_means=np.asarray(state["sums"], float) / np.maximum(counts, 1)[:, None],
        steps=int(state["steps"]),
        cpu_seconds=float(state["cpu_seconds"]),
        wall_seconds=float(state["wall_time"]),
        operations=from_json_array(state["operations_json"]) or None,
    )
