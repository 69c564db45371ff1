"""The Brownian reservoir device: skyrmions in a chamber, driven by a stream of held inputs.

For each input symbol of the stream the contact voltages are set (:mod:`~skygas.reservoir.drive`:
the drift field v_s = ξ·j of that symbol's current pattern), the engine runs for ``hold_time``,
and the sensors (:mod:`~skygas.reservoir.sensors`) are read every ``sample_interval`` with read
noise. The reservoir state of that input is the feature vector of the sensor means over
``bins`` equal windows of the hold (sensors × bins numbers): the last window says where the
present input sends the skyrmion, the first still remembers where the previous one left it.

The skyrmion is never reset between inputs: the device carries its state from one input to the
next, which is its (fading) memory. Several independent streams (``study.workers``, each its own
device and seed) run in parallel processes and are concatenated.
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

#: Landscape kinds drawn at random from the run's seed (see :func:`run_streams`).
RANDOM_LANDSCAPES = ("random_pinning", "disorder")
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


class ReservoirDevice:
    """A validated reservoir: chamber, contacts, drive, sensors (everything checked on
    construction, before any run)."""

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
    def simulation(self, seed: int):
        """A fresh engine run in the closed chamber (contacts are walls for skyrmions)."""
        from skygas.engine import Simulation

        c = self.config
        return Simulation(
            self.walls,
            c.resolved_material(),
            temperature=c.temperature,
            time_step=c.time_step,
            seed=seed,
            film_thickness=c.film_thickness,
            thiele=c.thiele_parameters(),
            landscape=c.potentials,
            **c.forces.simulation_arguments(),
        )

    def _initial_positions(self, sim, rng) -> np.ndarray:
        d = sim.thiele.skyrmion_diameter_internal
        return geo.random_positions(self.walls, self.config.n_skyrmions, 1.2 * d, 1.0 * d, rng)

    def map_extent(self) -> tuple[float, float, float, float]:
        x0, y0, x1, y1 = self.outline.bounds_nm
        return (x0, x1, y0, y1)

    def map_shape(self) -> tuple[int, int]:
        x0, x1, y0, y1 = self.map_extent()
        size = max(x1 - x0, y1 - y0) / MAP_BINS
        return (max(1, round((y1 - y0) / size)), max(1, round((x1 - x0) / size)))

    # -- running -------------------------------------------------------------------------------
    def run_stream(
        self,
        bits: np.ndarray,
        seed: int,
        warmup: int = 0,
        hold_time: float | None = None,
        sample_interval: float | None = None,
        progress=None,
    ) -> StreamResult:
        """Hold each symbol of ``bits`` (n, n_input_contacts) for ``hold_time`` in turn,
        reading the sensors every ``sample_interval`` (defaults: the configuration's), after
        ``warmup`` random symbols that are not recorded; returns the features and maps."""
        c = self.config
        hold = c.hold_time if hold_time is None else hold_time
        every = c.sensors.sample_interval if sample_interval is None else sample_interval
        started, cpu = time.perf_counter(), time.process_time()
        rng = np.random.default_rng(np.random.SeedSequence([seed, 0x5E5]))
        sim = self.simulation(seed)
        sim.state.insert_nm(self._initial_positions(sim, rng))
        symbols = self.drive.symbols
        n_bins = c.sensors.bins
        reads = max(n_bins, int(round(hold / every)))
        interval = hold / reads
        extent = self.map_extent()
        shape = self.map_shape()
        occupation = np.zeros((len(symbols), *shape))
        sums = np.zeros((len(symbols), len(self.sensor_centers)))
        counts = np.zeros(len(symbols))
        features = np.empty((len(bits), len(self.sensor_centers) * n_bins))
        warm = rng.integers(0, 2, size=(warmup, bits.shape[1]))
        centers_nm = self.sensor_centers * M_TO_NM
        for n, symbol in enumerate(np.vstack([warm, bits]).astype(int)):
            key = tuple(int(b) for b in symbol)
            sim.set_drift_field(*self._fields[key])
            sim.run(hold, record_interval=interval)
            blocks = sim.take_frames()
            x = np.concatenate([b.x for b in blocks])
            y = np.concatenate([b.y for b in blocks])
            if n < warmup:
                continue
            signal = coverage(x, y, centers_nm, c.sensors.radius * M_TO_NM, self.skyrmion_radius_nm)
            if c.sensors.read_noise > 0:
                signal = signal + rng.normal(0.0, c.sensors.read_noise, signal.shape)
            windows = np.array_split(signal, n_bins)
            features[n - warmup] = np.concatenate([w.mean(axis=0) for w in windows])
            s = symbols.index(key)
            sums[s] += signal.sum(axis=0)
            counts[s] += len(signal)
            ok = np.isfinite(x)
            hist, _, _ = np.histogram2d(y[ok], x[ok], bins=shape, range=[extent[2:], extent[:2]])
            occupation[s] += hist
            if progress is not None:
                progress(n - warmup + 1)
        return StreamResult(
            bits=np.asarray(bits, int),
            features=features,
            occupation=occupation,
            map_extent=extent,
            sensor_means=sums / np.maximum(counts, 1)[:, None],
            steps=sim.step,
            cpu_seconds=time.process_time() - cpu,
            wall_seconds=time.perf_counter() - started,
        )

    def describe(self) -> dict:
        """A JSON-able record of the device (SI)."""
        c = self.config
        return {
            "skygas_version": __version__,
            "seed": c.seed,
            "config": c.model_dump(mode="json"),
            "time_step_s": self.time_step,
            "diffusion_constant_m2_per_s": self.diffusion_constant,
            "chamber_area_m2": self.outline.area_nm2() / M_TO_NM**2,
            # the time for the mean squared displacement 4Dt to reach the chamber's area
            "exploration_time_s": self.outline.area_nm2()
            / M_TO_NM**2
            / (4 * self.diffusion_constant)
            if self.diffusion_constant > 0
            else None,
            "sensors": {
                n: list(map(float, p))
                for n, p in zip(self.sensor_names, self.sensor_centers, strict=True)
            },
            "drive": self.drive.record(c.hold_time),
            "geometry": self.outline.describe(),
        }


def _run_one(
    config: ReservoirConfig, stream: int, n_boolean: int, n_temporal: int
) -> tuple[StreamResult, StreamResult | None]:
    """Stream ``stream`` of a study, for a worker process: its own device, seed and random
    inputs; ``n_boolean`` inputs held ``hold_time``, then (if ``n_temporal`` > 0) a fresh
    stream of ``n_temporal`` inputs held ``study.temporal_hold_time``."""
    device = ReservoirDevice(config)
    rng = np.random.default_rng(np.random.SeedSequence([config.seed, stream, 0xB175]))
    width = len(config.drive.input_contacts)
    seed = config.seed * 1000 + stream
    boolean = device.run_stream(
        rng.integers(0, 2, size=(n_boolean, width)), seed=seed, warmup=config.study.warmup_inputs
    )
    temporal = None
    if n_temporal:
        st = config.study
        temporal = device.run_stream(
            rng.integers(0, 2, size=(n_temporal, width)),
            seed=seed + 500,
            warmup=st.warmup_inputs,
            hold_time=st.temporal_hold_time,
            sample_interval=st.temporal_sample_interval,
        )
    return boolean, temporal


def run_streams(
    config: ReservoirConfig,
    n_inputs: int | None = None,
    n_temporal: int | None = None,
    workers: int | None = None,
) -> tuple[list[StreamResult], list[StreamResult]]:
    """The Boolean streams (``n_inputs`` held inputs in all) and the temporal streams
    (``n_temporal``), split into ``workers`` independent streams run in parallel processes
    (one: in this process).

    A landscape with random terms (pinning wells, disorder) is drawn from the run's seed, and
    every stream has its own seed: streams would be different devices. Such a study runs as
    one stream, so that one read-out is trained and tested on one device."""
    st = config.study
    n_inputs = st.n_inputs if n_inputs is None else n_inputs
    n_temporal = st.temporal_inputs if n_temporal is None else n_temporal
    workers = max(1, min(st.workers if workers is None else workers, n_inputs // 4))
    if any(p.kind in RANDOM_LANDSCAPES for p in config.potentials):
        workers = 1
    sizes = [len(a) for a in np.array_split(np.arange(n_inputs), workers)]
    temporal = [len(a) for a in np.array_split(np.arange(n_temporal), workers)]
    if workers == 1:
        results = [_run_one(config, 0, n_inputs, n_temporal)]
    else:
        from joblib import Parallel, delayed

        results = Parallel(n_jobs=workers)(
            delayed(_run_one)(config, k, m, t)
            for k, (m, t) in enumerate(zip(sizes, temporal, strict=True))
        )
    return [b for b, _ in results], [t for _, t in results if t is not None]
