"""Neuron and saturation runs to files, through the run driver (:mod:`skygas.run_driver`).

:func:`run_neuron_to_files` (``skygas neuron``) writes into ``out_dir``: ``trace.npz`` (count
trace, spikes, emissions, injections; with the configuration, the seed and the version),
``count_trace.png``, ``summary.json`` (with the LIF fit) and, unless ``transfer=False``,
``transfer_curve.png`` and the transfer curve in the summary.

:func:`run_saturation_to_files` (``skygas saturation``) writes ``saturation.json`` and
``max_density.png``.

Both keep ``checkpoint.npz`` while running; see :func:`skygas.run_driver.drive`.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from skygas._version import __version__
from skygas.neuron.config import NeuronConfig
from skygas.neuron.device import NeuronDevice
from skygas.neuron.saturation import SaturationProtocol, SaturationResult
from skygas.run_driver import PiecewiseRunJob, drive, write_atomic, write_json


class NeuronJob(PiecewiseRunJob):
    """One neuron run as a job of the run driver (work in ns of simulated time). The transfer
    curve, when asked for, is computed when the results are written."""

    def __init__(self, config: NeuronConfig, transfer: bool = True):
        self.device = NeuronDevice(config)  # validates everything before any run
        super().__init__(config, self.device.build())
        self.transfer = transfer

    def finish(self, out: Path) -> dict:
        from skygas.neuron import analysis as A
        from skygas.neuron import lif as L
        from skygas.neuron.figures import plot_trace, plot_transfer

        run, config = self.run, self.config
        summary = run.summary()
        lif = L.fit_lif(run)
        summary["lif_fit"] = lif
        arrays = {**run.trace(), "spikes": run.spike_times(), "emissions": run.emission_times(),
                  "injections": run.injection_times(),
                  "config_json": np.array(self.config_json()), "seed": np.array(config.seed),
                  "skygas_version": np.array(__version__)}
        write_atomic(out / "trace.npz", lambda tmp: np.savez_compressed(tmp, **arrays))
        write_atomic(out / "count_trace.png", lambda tmp: plot_trace(run, tmp))
        if self.transfer:
            rates = config.transfer.rates
            if not rates:
                # around the LIF's rheobase θ/τ (τ of the integrating, closed-gate phase)
                tau = lif["tau_s"] if np.isfinite(lif["tau_s"]) else 1e-6
                rates = list(np.array([0.25, 0.5, 1, 1.5, 2, 3]) * config.rule.threshold / tau)
            curve = A.transfer_curve(self.device, rates,
                                     config.transfer.duration or config.duration,
                                     seed=config.seed)
            pred = L.lif_rate(curve["input_rate_Hz"], lif["tau_s"], lif["threshold"],
                              lif["reset"], lif["release_time_s"], lif["refractory_time_s"])
            lif["predicted_Hz"] = pred.tolist()
            lif["transfer_r_squared"] = A.r_squared(curve["firing_rate_Hz"], pred)
            summary["transfer_curve"] = curve
            write_atomic(out / "transfer_curve.png",
                         lambda tmp: plot_transfer(curve, tmp, lif))
        write_json(out / "summary.json", summary, indent=1)
        return summary


def run_neuron_to_files(config: NeuronConfig, out_dir: str | Path, *, transfer: bool = True,
                        **drive_options) -> dict:
    """Run the neuron of ``config`` and write its files; returns the summary.
    ``drive_options``: ``resume``, ``progress``, ``checkpoint_seconds`` of
    :func:`~skygas.run_driver.drive`."""
    return drive(NeuronJob(config, transfer), out_dir, **drive_options)


class SaturationJob:
    """The saturation protocol (:class:`~skygas.neuron.saturation.SaturationProtocol`) as a
    job of the run driver: one trial (one relaxation) per piece, work counted in trials."""

    work_unit = "runs"

    def __init__(self, diameters, *, repetitions: int, seed: int, relax_time: float,
                 temperature: float):
        self.arguments = {"diameters_m": [float(d) for d in diameters],
                          "repetitions": repetitions, "seed": seed, "relax_time_s": relax_time,
                          "temperature_K": temperature}
        self.protocol = SaturationProtocol(diameters, repetitions=repetitions, seed=seed,
                                           relax_time=relax_time, temperature=temperature)
        self.work_total = float(len(self.protocol.trials))
        self.survivors: list[int] = []

    def work_done(self) -> float:
        return float(len(self.survivors))

    def advance_piece(self) -> None:
        self.survivors.append(self.protocol.run_trial(len(self.survivors)))

    def state_dict(self) -> dict[str, np.ndarray]:
        return {"survivors": np.array(self.survivors, dtype=np.int64)}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        self.survivors = [int(n) for n in state["survivors"]]

    def config_json(self) -> str:
        return json.dumps(self.arguments, sort_keys=True)

    def seed(self) -> int:
        return self.arguments["seed"]

    def finish(self, out: Path) -> SaturationResult:
        from skygas.neuron.figures import plot_saturation

        result = self.protocol.result(self.survivors)
        write_json(out / "saturation.json", {"skygas_version": __version__,
                                             "seed": self.seed(), **result.summary()}, indent=1)
        write_atomic(out / "max_density.png", lambda tmp: plot_saturation(result, tmp))
        return result


def run_saturation_to_files(diameters, out_dir: str | Path, *, repetitions: int = 10,
                            seed: int = 0, relax_time: float = 2e-9, temperature: float = 300.0,
                            **drive_options) -> SaturationResult:
    """Run the saturation protocol and write its files; returns the result."""
    job = SaturationJob(diameters, repetitions=repetitions, seed=seed, relax_time=relax_time,
                        temperature=temperature)
    return drive(job, out_dir, **drive_options)
