"""Neuron and saturation runs to files, through the run driver (:mod:`skygas.runs.run_driver`).

:func:`run_neuron_to_files` (``skygas neuron``) writes into ``out_dir``: ``trace.npz`` (count
trace, spikes, emissions, injections, annihilations; with the configuration, the seed and the
version), ``count_trace.png``, ``device.png`` (the device over its energy landscape),
``summary.json`` (with the LIF fit), ``frames.nc`` when positions were recorded and, unless
``transfer=False``, ``transfer_curve.png`` and the transfer curve in the summary (its runs are
pieces of the job too: they show progress and resume).

:func:`run_saturation_to_files` (``skygas saturation``) writes ``summary.json`` and
``max_density.png``.

Both keep ``checkpoint.npz`` while running; see :func:`skygas.runs.run_driver.drive`.
"""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Any

import numpy as np

from skygas._version import __version__
from skygas.neuron.config import NeuronConfig
from skygas.neuron.device import NeuronDevice
from skygas.neuron.saturation import SaturationProtocol, SaturationResult
from skygas.runs.run_driver import (
    PiecewiseRunJob,
    drive,
    from_json_array,
    json_array,
    run_record,
    write_atomic,
    write_figure,
    write_json,
)

#: Default transfer-curve input rates, in units of the fitted LIF's rheobase θ/τ.
RHEOBASE_MULTIPLES = (0.25, 0.5, 1, 1.5, 2, 3)


class NeuronJob(PiecewiseRunJob):
    """One neuron run as a job of the run driver, work in ns of simulated time.

    The main run piece by piece, then (``transfer=True``) one piece per point of the transfer
    curve.
    """

    result_files: tuple[str, ...] = ("trace.npz", "summary.json", "frames.nc")

    def __init__(
        self, config: NeuronConfig, transfer: bool = True, record_interval: float | None = None
    ):
        self.device = NeuronDevice(config)  # validates everything before any run
        self.transfer_duration = config.transfer.duration or config.duration
        self.n_rates = (len(config.transfer.rates) or len(RHEOBASE_MULTIPLES)) if transfer else 0
        # the estimate prices the transfer curve's runs too: with six points, 7/8 of the job
        priced = 1.0 + self.n_rates * self.transfer_duration / config.duration
        super().__init__(
            config, self.device.build(record_interval=record_interval, priced_runs=priced)
        )
        self.work_total += self._transfer_work(self.n_rates)
        #: transfer-curve points done: (firing rate [Hz], injected, annihilated) per rate
        self.points: list[list] = []
        #: wall seconds the transfer curve's runs took (build and stepping), as the main run's
        #: ``wall_time_s``: the estimate prices both
        self.transfer_wall_time = 0.0
        self._lif: dict | None = None

    def _transfer_work(self, n_points: int) -> float:
        return n_points * self.transfer_duration * self.time_scale

    def work_done(self) -> float:
        """Simulated time of the main run, then of the transfer curve's runs [ns]."""
        return super().work_done() + self._transfer_work(len(self.points))

    def lif_fit(self) -> dict:
        """The LIF fit of the finished main run (computed once)."""
        from skygas.neuron.lif import fit_lif

        if self._lif is None:
            self._lif = fit_lif(self.run)
        return self._lif

    def transfer_rates(self) -> list[float]:
        """Input rates [Hz] of the transfer curve.

        The configured ones, or multiples of the LIF's rheobase θ/τ (τ of the integrating,
        closed-gate phase).
        """
        if self.config.transfer.rates:
            return list(self.config.transfer.rates)
        tau = self.lif_fit()["tau_s"]
        tau = tau if np.isfinite(tau) else 1e-6
        return list(np.array(RHEOBASE_MULTIPLES) * self.config.rule.threshold / tau)

    def advance_piece(self) -> None:
        """A piece of the main run, then one point of the transfer curve."""
        if self.run.sim.step < self.run.total_steps:
            self.run.advance_piece()
            return
        from skygas.neuron.analysis import transfer_curve

        rate = self.transfer_rates()[len(self.points)]
        started = time.perf_counter()
        point = transfer_curve(
            self.device, [rate], self.transfer_duration, seed=self.config.seed, priced=False
        )
        self.transfer_wall_time += time.perf_counter() - started
        self.points.append(
            [point["firing_rate_Hz"][0], point["n_injected"][0], point["n_annihilated"][0]]
        )

    def state_dict(self) -> dict[str, np.ndarray]:
        """The main run's state and the transfer curve's finished points."""
        return {
            **super().state_dict(),
            "transfer_points_json": json_array(self.points),
            "transfer_wall_time": np.array(self.transfer_wall_time),
        }

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        """Restore what :meth:`state_dict` saved."""
        super().load_state_dict(state)
        self.points = from_json_array(state["transfer_points_json"])
        self.transfer_wall_time = float(state.get("transfer_wall_time", 0.0))

    def transfer_curve(self) -> dict:
        """The finished transfer curve.

        As :func:`~skygas.neuron.analysis.transfer_curve` returns it.
        """
        firing, injected, annihilated = (list(c) for c in zip(*self.points, strict=True))
        return {
            "input_rate_Hz": [float(r) for r in self.transfer_rates()],
            "firing_rate_Hz": firing,
            "n_injected": injected,
            "n_annihilated": annihilated,
            "duration_s": self.transfer_duration,
        }

    def finish(self, out: Path) -> dict:
        """Write ``trace.npz``, the figures, ``frames.nc`` if recorded and ``summary.json``."""
        from skygas.neuron import analysis as A
        from skygas.neuron import lif as L
        from skygas.neuron.figures import plot_device, plot_trace, plot_transfer

        run, config = self.run, self.config
        summary = run.summary()
        lif = dict(self.lif_fit())
        summary["lif_fit"] = lif
        arrays = {
            **run.trace(),
            "spikes": run.spike_times(),
            "emissions": run.emission_times(),
            "injections": run.injection_times(),
            # the leak time τ of the summary is counted from these (with the count trace)
            "annihilations": np.asarray(run.annihilator.annihilation_times, dtype=float),
            "config_json": np.array(self.config_json()),
            "seed": np.array(config.seed),
            "skygas_version": np.array(__version__),
            # the named operations' readings, if any (``<name>_<variable>``)
            **{name: array for name, (_, array) in run.sim.operation_data().items()},
        }
        write_atomic(out / "trace.npz", lambda tmp: np.savez_compressed(tmp, **arrays))
        record = run_record(self)
        write_figure(out / "count_trace.png", lambda tmp: plot_trace(run, tmp), record)
        write_figure(out / "device.png", lambda tmp: plot_device(run, tmp), record)
        if run.record_interval is not None:  # positions recorded for a movie
            from skygas.neuron.records import write_frames

            write_frames(run.sim, config, out / "frames.nc")
        if self.n_rates:
            curve = self.transfer_curve()
            pred = L.lif_rate(
                curve["input_rate_Hz"],
                lif["tau_s"],
                lif["threshold"],
                lif["reset"],
                lif["release_time_s"],
                lif["refractory_time_s"],
            )
            lif["predicted_Hz"] = pred.tolist()
            lif["transfer_r_squared"] = A.r_squared(curve["firing_rate_Hz"], pred)
            summary["transfer_curve"] = curve
            summary["transfer_wall_time_s"] = self.transfer_wall_time
            write_figure(
                out / "transfer_curve.png", lambda tmp: plot_transfer(curve, tmp, lif), record
            )
        write_json(out / "summary.json", summary, indent=1)
        return summary


def run_neuron_to_files(
    config: NeuronConfig,
    out_dir: str | Path,
    *,
    transfer: bool = True,
    record_interval: float | None = None,
    **drive_options,
) -> dict:
    """Run the neuron of ``config`` and write its files; returns the summary.

    With ``record_interval`` [s] it records positions and writes them as ``frames.nc`` (a
    movie's input). ``drive_options``: those of :func:`~skygas.runs.run_driver.drive`.
    """
    return drive(NeuronJob(config, transfer, record_interval), out_dir, **drive_options)


class SaturationJob:
    """The saturation protocol as a job of the run driver, one trial per piece.

    Each piece is one relaxation of :class:`~skygas.neuron.saturation.SaturationProtocol`;
    the work is counted in trials.
    """

    work_unit = "runs"
    result_files: tuple[str, ...] = ("summary.json",)

    def __init__(
        self, diameters, *, repetitions: int, seed: int, relax_time: float, temperature: float
    ):
        self.arguments: dict[str, Any] = {
            "diameters_m": [float(d) for d in diameters],
            "repetitions": repetitions,
            "seed": seed,
            "relax_time_s": relax_time,
            "temperature_K": temperature,
        }
        self.protocol = SaturationProtocol(
            diameters,
            repetitions=repetitions,
            seed=seed,
            relax_time=relax_time,
            temperature=temperature,
        )
        self.work_total = float(len(self.protocol.trials))
        self.survivors: list[int] = []

    def work_done(self) -> float:
        """Trials done."""
        return float(len(self.survivors))

    def advance_piece(self) -> None:
        """Run the next trial."""
        self.survivors.append(self.protocol.run_trial(len(self.survivors)))

    def state_dict(self) -> dict[str, np.ndarray]:
        """The survivors of the trials done."""
        return {"survivors": np.array(self.survivors, dtype=np.int64)}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        """Restore the survivors of the trials done."""
        self.survivors = [int(n) for n in state["survivors"]]

    def config_json(self) -> str:
        """The protocol's arguments, as JSON."""
        return json.dumps(self.arguments, sort_keys=True)

    def seed(self) -> int:
        """The protocol's seed."""
        return self.arguments["seed"]

    def finish(self, out: Path) -> SaturationResult:
        """Write ``summary.json`` and its figure."""
        from skygas.neuron.figures import plot_saturation

        result = self.protocol.result(self.survivors)
        write_json(
            out / "summary.json",
            {"skygas_version": __version__, "seed": self.seed(), **result.summary()},
            indent=1,
        )
        write_figure(
            out / "max_density.png", lambda tmp: plot_saturation(result, tmp), run_record(self)
        )
        return result


def run_saturation_to_files(
    diameters,
    out_dir: str | Path,
    *,
    repetitions: int = 10,
    seed: int = 0,
    relax_time: float = 2e-9,
    temperature: float = 300.0,
    **drive_options,
) -> SaturationResult:
    """Run the saturation protocol and write its files; returns the result."""
    job = SaturationJob(
        diameters,
        repetitions=repetitions,
        seed=seed,
        relax_time=relax_time,
        temperature=temperature,
    )
    return drive(job, out_dir, **drive_options)
