"""Running the Skyrmion Reshuffler: build, drive, detect, analyse (paper, "Skyrmion Reshuffler").

:class:`ReshufflerRun` wires the pieces together:

1. the device (:mod:`~skygas.reshuffler.device`) and its current (:mod:`skygas.fields.current`),
   giving the drift field v_s = ξ j in both chambers;
2. the engine (:class:`~skygas.engine.Simulation`) with the input bits driving an
   :class:`~skygas.reshuffler.injection.Injector`;
3. read-out: a skyrmion crossing an output line is detected (time, chamber) and removed;
4. the analyses of :mod:`skygas.reshuffler.correlation` on the input bits and the output bits
   rebuilt from the read-out order.

Counts are conserved by construction and checked at the end of every run:
injected = detected + present + annihilated (annihilation is not modelled here yet: 0).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from skygas.core.estimates import check
from skygas.core.resources import require_memory
from skygas.engine import FrameBlock, Simulation
from skygas.fields.current import solve_current
from skygas.reshuffler.config import ReshufflerConfig, check_time_step
from skygas.reshuffler.device import ReshufflerGeometry, drift_field_on_grid
from skygas.reshuffler.injection import Injector
from skygas.runs.device_run import DeviceRun
from skygas.runs.machine_speed import optimistic_estimate, run_estimate
from skygas.sc.signals import SignalSpec, as_bits, generate_bits

#: Pieces of a run (each returns to Python once: progress, checkpoints, interruption).
PIECES = 200
#: Shortest piece [steps] of a run between two returns to Python (progress, checkpoints): each
#: return costs ~0.5 ms, which 200 pieces of a 2 µs run (8 000 steps) would spend 200 times.
MIN_PIECE_STEPS = 5_000


def _largest_divisor_up_to(number: int, limit: int) -> int:
    """The largest divisor of ``number`` that is ≤ ``limit`` (both ≥ 1)."""
    return next(d for d in range(min(number, limit), 0, -1) if number % d == 0)


def _seeds(seed: int) -> dict[str, int]:
    """Independent child seeds for the signal and the thermal noise (SeedSequence)."""
    signal, noise = np.random.SeedSequence(seed).spawn(2)
    return {
        "signal": int(signal.generate_state(1, np.uint64)[0]),
        "noise": int(noise.generate_state(1, np.uint64)[0] >> np.uint64(1)),
    }


#: Bytes kept per injection event: the input bit (bool) and the injection log (bool, two
#: int64, two bool; :class:`~skygas.reshuffler.injection.InjectionLog`).
BYTES_PER_EVENT = 1 + 1 + 8 + 8 + 1 + 1
#: Bytes of a skyrmion in a snapshot: its id (int64) and position (two float64).
BYTES_PER_SNAPSHOT_SKYRMION = 8 + 16


#: Cost of a reshuffler step per skyrmion against the closed chamber's (drift field, injection,
#: read-out): the demonstration (the default preset, 100 µs, 9e5 steps, 45 skyrmions in a
#: chamber at most) took 6.8 µs per step where the chamber's 45-skyrmion gas took 7.4 µs on the
#: same machine at the same time (benchmarks/estimates.py; docs/performance.md).
STEP_COST_FACTOR = 1.0
#: Skyrmions in a half-full 1024 nm chamber (the demonstration's gas, at its fullest).
HALF_FULL_CHAMBER = 45.0


def expected_population(config: ReshufflerConfig) -> float:
    """Mean skyrmions in the device during a run (for its memory and expected time).

    One enters per injection interval and stays for the time it takes to cross a chamber and
    its conduits at the spin-drift speed ξJ, but the chambers hold a crowd: at least one
    half-full chamber's (:data:`HALF_FULL_CHAMBER` per 1024 nm; the demonstration's two
    chambers hold 45 at their fullest, about as many together on average), at most as many
    as fill both (one per skyrmion diameter squared). A step costs as much as a closed
    chamber's with :data:`STEP_COST_FACTOR` times as many. A gas that jams (a chamber that
    fills faster than it empties) costs more: the run says so as it goes
    (:mod:`skygas.runs.pace`).
    """
    device = config.device
    speed = config.drift_coefficient() * config.current_density  # v_s [m/s]
    present = (
        (device.chamber_diameter + 2 * device.conduit_length) / speed / config.injection.interval
    )
    d_sk = config.thiele_parameters().skyrmion_diameter
    crowd = HALF_FULL_CHAMBER * (device.chamber_diameter / 1024e-9) ** 2
    full = 2.0 * (device.chamber_diameter / d_sk) ** 2
    return min(max(present, crowd), max(full, crowd))


def reshuffler_memory(config: ReshufflerConfig, n_events: float, skyrmions: float) -> dict:
    """Bytes of a run's largest arrays, by the field that sets them.

    Returns
    -------
    dict
        ``"injection.interval"``: the input bits and the injection log of ``n_events`` events
        (:data:`BYTES_PER_EVENT` each); ``"output.snapshot_interval"``: the snapshots of
        ``skyrmions`` skyrmions (:data:`BYTES_PER_SNAPSHOT_SKYRMION` each), one per
        snapshot interval and one at the start.
    """
    snapshots = math.floor(config.duration / config.output.snapshot_interval) + 1
    return {
        "injection.interval": BYTES_PER_EVENT * n_events,
        "output.snapshot_interval": BYTES_PER_SNAPSHOT_SKYRMION * snapshots * skyrmions,
    }


def _check_memory(config: ReshufflerConfig, memory: dict, n_events: float) -> None:
    require_memory(
        "injection.interval",
        config.injection.interval,
        memory["injection.interval"],
        f"the input bits and log of {n_events:.3g} injection events",
        "use a longer injection interval or a shorter duration",
    )
    require_memory(
        "output.snapshot_interval",
        config.output.snapshot_interval,
        memory["output.snapshot_interval"],
        "the snapshots of all positions",
        "take snapshots less often or run for a shorter duration",
    )


class ReshufflerRun(DeviceRun):
    """A reshuffler simulation in progress. Build with :meth:`build`, then :meth:`advance`.

    A :class:`~skygas.runs.device_run.DeviceRun` whose pieces also keep sparse snapshots of
    all positions (:meth:`run_steps`); its injector is the named operation ``"injector"``.
    """

    pieces = PIECES
    min_piece_steps = MIN_PIECE_STEPS

    def __init__(
        self,
        config: ReshufflerConfig,
        geometry: ReshufflerGeometry,
        sim: Simulation,
        injector: Injector,
        current: object,
        electrical_outline: object,
        n_events: int,
    ):
        super().__init__(config, sim)
        self.geometry = geometry
        self.injector = injector
        self.current = current
        self.electrical_outline = electrical_outline
        self.n_events = n_events
        #: (time [s], ids, positions [m] (n, 2)) every ``output.snapshot_interval``
        self.snapshots: list[tuple[float, np.ndarray, np.ndarray]] = []

    @classmethod
    def build(
        cls, config: ReshufflerConfig, bits=None, brownian_substeps: int = 1
    ) -> ReshufflerRun:
        """Validate everything, solve the current and set up the engine (no stepping).

        ``bits`` (0/1 values) replaces the configured input signal; the run then lasts at least
        as long as it takes to inject them. ``brownian_substeps`` is the engine's
        (:class:`~skygas.engine.Simulation`): 2 draws each step's noise as two half steps, the
        time-step check's coarse run (:mod:`skygas.runs.timestep`).
        """
        thiele = config.thiele_parameters()
        d = config.device
        geometry = ReshufflerGeometry(
            d.chamber_diameter, d.conduit_width, d.conduit_length, d.chamber_gap
        )
        geometry.validate(thiele.skyrmion_diameter)
        spec = SignalSpec(
            kind=config.signal.kind,
            p=config.signal.p,
            correlation_time=config.signal.correlation_time,
            path=config.signal.path,
        )
        interval = config.injection.interval
        # estimates before anything is allocated (core.estimates): the steps are at least the
        # injection events (the step divides the interval), the exact count follows below
        lower_events = config.duration / interval
        if bits is not None:
            lower_events = max(lower_events, float(len(bits)))
        population = expected_population(config)
        memory = reshuffler_memory(config, lower_events, population)
        _check_memory(config, memory, lower_events)
        check(
            optimistic_estimate(lower_events, STEP_COST_FACTOR * population, sum(memory.values())),
            "duration",
            config.duration,
            "the run",
            "use a shorter duration",
            announce=False,
        )
        n_events = int(math.floor(config.duration / interval + 1e-9))
        seeds = _seeds(config.seed)
        if bits is not None:
            bits = as_bits(bits, "bits")
            n_events = len(bits)
            config = config.model_copy(
                update={"duration": max(config.duration, n_events * interval)}
            )
        else:
            bits = generate_bits(
                spec, n_events if config.signal.kind != "file" else None, interval, seeds["signal"]
            )
            if config.signal.kind == "file":
                bits = bits[:n_events]
                n_events = len(bits)
        chamber = geometry.chamber()
        current = solve_current(
            chamber,
            config.current_density,
            cell_size=config.current.cell_size,
            conductor_thickness=config.current.conductor_thickness,
            resistivity=config.current.resistivity,
        )
        time_step = config.time_step
        check_time_step(config)
        # time_step None: the suggested step, shortened to divide the injection interval
        sim = config.simulation(
            geometry.device_outline(),
            seed=seeds["noise"],
            temperature=config.noise_temperature(),
            time_step=time_step,
            brownian_substeps=brownian_substeps,
            step_interval=interval,
            capacity=64,
        )
        vx, vy = drift_field_on_grid(
            geometry, current, sim.wall_field.grid, config.drift_coefficient()
        )
        sim.set_drift_field(vx, vy)
        interval_steps = max(1, int(round(interval / sim.time_step)))
        retry = config.injection.retry_interval or interval / 10
        injector = Injector(
            bits=bits,
            interval_steps=interval_steps,
            retry_steps=max(1, int(round(retry / sim.time_step))),
            sites=geometry.nucleation_sites(),
            clearance_nm=config.injection.site_clearance * thiele.skyrmion_diameter_internal,
            rule=config.injection.occupied_rule,
            max_pending=config.injection.max_pending,
        )
        sim.operations.append(injector)
        run = cls(config, geometry, sim, injector, current, chamber, n_events)
        run.attach_operations(config.operations)
        check(
            run_estimate(run.total_steps, STEP_COST_FACTOR * population, sum(memory.values())),
            "duration",
            config.duration,
            "the run",
            "use a shorter duration",
        )
        return run

    # -- running ------------------------------------------------------------------------------
    @property
    def total_steps(self) -> int:
        """Steps of the configured duration."""
        from skygas.core.resources import step_count

        return step_count(self.config.duration, self.sim.time_step)

    def drain(self, max_duration: float = 1e-4) -> bool:
        """Keep running after the configured duration, without new input.

        Until every event has been nucleated and read out (or ``max_duration`` [s] has
        passed). Returns whether the device emptied. Used when the whole output stream is
        needed (decorrelator use).
        """
        piece = int(round(20 * self.config.injection.interval / self.sim.time_step))
        end = self.sim.step + int(round(max_duration / self.sim.time_step))
        while (self.sim.count or self.injector.n_pending) and self.sim.step < end:
            self.run_steps(piece)
        return not (self.sim.count or self.injector.n_pending)

    def run_steps(self, n: int) -> None:
        """Advance by ``n`` steps (fewer if the trajectory window ends first).

        Recording the snapshots and, inside the trajectory window, the dense frames of the
        figure.

        The kernel records frames itself (:class:`~skygas.engine.FrameBlock`), so it does not
        return to Python for every snapshot; the frames that are not needed for the figure are
        taken out of the simulation after each call and kept only as sparse snapshots.
        """
        dt = self.sim.time_step
        window = int(round(self.config.output.trajectory_window / dt))
        snapshot_every = self.snapshot_steps
        kept = len(self.sim.frame_blocks)
        new_frames: Sequence[FrameBlock]
        if self.sim.step < window:
            # frames ~1 ns apart that fall on every snapshot step as well
            dense_every = _largest_divisor_up_to(snapshot_every, max(1, int(round(1e-9 / dt))))
            self.sim.run(min(n, window - self.sim.step) * dt, record_interval=dense_every * dt)
            new_frames = self.sim.frame_blocks[kept:]  # the simulation keeps them
        else:
            self.sim.run(n * dt, record_interval=snapshot_every * dt)
            new_frames = self.sim.take_frames(kept)
        self._add_snapshots(new_frames)

    @property
    def snapshot_steps(self) -> int:
        """Steps between two snapshots of all positions (``output.snapshot_interval``)."""
        return max(1, int(round(self.config.output.snapshot_interval / self.sim.time_step)))

    def _add_snapshots(self, blocks) -> None:
        """Append the frames of ``blocks`` that fall on snapshot steps to :attr:`snapshots`.

        As (time [s], ids present in increasing order, positions [m] (n, 2)). A snapshot at
        step k holds the state reached at the end of step k − 1, before a nucleation due at
        step k.
        """
        every = self.snapshot_steps
        for block in blocks:
            for f in np.flatnonzero(block.step % every == 0):
                self.snapshots.append((float(block.time[f]), *block.positions(f)))

    # -- checkpoints ------------------------------------------------------------------------
    def extra_state(self) -> dict[str, np.ndarray]:
        """The snapshots, as flat arrays (the injector is saved with the simulation)."""
        if not self.snapshots:
            return {}
        return {
            "snap_time": np.array([s[0] for s in self.snapshots]),
            "snap_count": np.array([len(s[1]) for s in self.snapshots]),
            "snap_ids": np.concatenate([s[1] for s in self.snapshots]),
            "snap_pos": np.concatenate([s[2] for s in self.snapshots]),
        }

    def load_extra_state(self, state: dict[str, np.ndarray]) -> None:
        """Restore the snapshots saved by :meth:`extra_state`."""
        self.snapshots = []
        if "snap_time" in state:
            edges = np.concatenate([[0], np.cumsum(state["snap_count"])])
            for n, t in enumerate(state["snap_time"]):
                sl = slice(edges[n], edges[n + 1])
                self.snapshots.append((float(t), state["snap_ids"][sl], state["snap_pos"][sl]))

    # -- results ------------------------------------------------------------------------------
    def detections(self) -> dict[str, np.ndarray]:
        """Read-out events in time order: skyrmion id, time [s], chamber (1 = UP, 0 = DOWN)."""
        exits = self.sim.exits.arrays()
        labels = self.sim.exits.port_labels()
        read = np.char.endswith(labels, ".output")
        order = np.argsort(exits["time"][read], kind="stable")
        return {
            "skyrmion": exits["skyrmion"][read][order],
            "time": exits["time"][read][order],
            "up": (labels[read] == "up.output")[order],
        }

    def counts(self) -> dict[str, int]:
        """Injected, detected, present and annihilated skyrmions; raises if not conserved."""
        injected = self.injector.n_injected
        detected = len(self.detections()["skyrmion"])
        present = self.sim.count
        annihilated = 0
        if injected != detected + present + annihilated:
            raise RuntimeError(
                f"skyrmion count not conserved: injected {injected} != "
                f"detected {detected} + present {present} + "
                f"annihilated {annihilated}"
            )
        return {
            "injected": injected,
            "detected": detected,
            "present": present,
            "annihilated": annihilated,
        }
