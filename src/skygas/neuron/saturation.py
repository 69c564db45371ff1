"""The largest number of skyrmions a circular chamber holds.

The paper's "Skyrmion Neuron", maximum-density figure.

Protocol (the paper's, with the Thiele model and :mod:`skygas.neuron.annihilation` standing in
for micromagnetics): for each chamber diameter and each trial number N (growing), nucleate N
skyrmions at random positions (random sequential addition, at least half a diameter apart and
half a diameter from the wall, the engine's placement limit), relax ``relax_time`` (2 ns) at
``temperature`` (300 K) with annihilation active, count the survivors; repeat ``repetitions``
(10) times and average. The saturation count of a diameter is the largest mean survivor count
over N: beyond it, adding skyrmions adds no survivors.

The close-packing estimate beside it is the hexagonal area ratio
N_cp = π/(2√3) · (D/d_sk)², the most hard disks of diameter d_sk a large disk of diameter D can
hold (boundary losses ignored).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from skygas.core.errors import require
from skygas.engine import MIN_PLACEMENT_SEPARATION, Simulation
from skygas.neuron.annihilation import AnnihilationModel, Annihilator
from skygas.neuron.calibration import CALIBRATED
from skygas.physics.geometry import _random_positions_nm, disk
from skygas.physics.materials import derive_thiele, load_material

HEX_PACKING = math.pi / (2 * math.sqrt(3))


def close_packing_estimate(chamber_diameter: float, skyrmion_diameter: float) -> float:
    """N_cp = π/(2√3)·(D/d_sk)² (both diameters in metres)."""
    return HEX_PACKING * (chamber_diameter / skyrmion_diameter) ** 2


def saturation_estimate(
    chamber_diameter: float, skyrmion_diameter: float, model: AnnihilationModel = CALIBRATED
) -> float:
    """Quick estimate [skyrmions] of the saturation count without simulating.

    From a fit to the protocol's results (:data:`skygas.neuron.calibration.SATURATION_DENSITY_FIT`).
    """
    from skygas.neuron.calibration import SATURATION_DENSITY_FIT as fit

    r_c, _ = model._lengths_nm(skyrmion_diameter)
    # fitted: N_sat ≈ a · ((D − b·r_c)/r_c)², a, b from the calibration runs (docs/neuron.md)
    eff = max(chamber_diameter * 1e9 - fit["b"] * r_c, 0.0) / r_c
    return fit["a"] * eff**2


@dataclass
class SaturationResult:
    """The saturation curve: per chamber diameter [m], the trials and the saturation count.

    Per diameter: the numbers N tried, the mean and standard deviation of the survivors per N, the
    saturation count (``max_count``) with its standard error, and the close-packing estimate;
    ``parameters`` the protocol's settings.
    """

    diameters: np.ndarray  # [m]
    trial_counts: list  # per diameter: array of N tried
    survivors_mean: list  # per diameter: mean survivors per N
    survivors_std: list  # per diameter: standard deviation per N
    max_count: np.ndarray  # saturation count per diameter
    max_count_error: np.ndarray  # standard error of that mean
    close_packing: np.ndarray  # N_cp per diameter
    parameters: dict

    def summary(self) -> dict:
        """The result as a JSON-able dict (``diameters_m``, ``max_count``, …)."""
        return {
            "diameters_m": self.diameters.tolist(),
            "max_count": self.max_count.tolist(),
            "max_count_error": self.max_count_error.tolist(),
            "close_packing_estimate": self.close_packing.tolist(),
            "trial_counts": [np.asarray(c).tolist() for c in self.trial_counts],
            "survivors_mean": [np.asarray(c).tolist() for c in self.survivors_mean],
            "parameters": self.parameters,
        }


def relax_survivors(
    diameter: float,
    n: int,
    *,
    model: AnnihilationModel,
    seed: int,
    relax_time: float = 2e-9,
    temperature: float = 300.0,
    material="S2",
    time_step: float | None = None,
) -> int:
    """Survivors after nucleating ``n`` skyrmions at random in a disk and relaxing."""
    outline = disk(diameter=diameter)
    sim = Simulation(outline, material, temperature=temperature, time_step=time_step, seed=seed)
    d_nm = sim.thiele.skyrmion_diameter_internal
    rng = np.random.default_rng(np.random.SeedSequence((seed, 0x736174)))
    pts = _random_positions_nm(
        outline, n, MIN_PLACEMENT_SEPARATION * d_nm, MIN_PLACEMENT_SEPARATION * d_nm, rng
    )
    sim.state.insert_nm(pts)
    sim.operations.append(Annihilator.for_simulation(model, sim))
    sim.run(relax_time)
    return sim.count


class SaturationProtocol:
    """The saturation protocol as a list of independent trials (one relaxation each).

    So that a long protocol can run trial by trial (:class:`skygas.neuron.files.SaturationJob`
    checkpoints after each); arguments as :func:`saturation_curve`.
    """

    def __init__(
        self,
        diameters,
        *,
        trial_counts=None,
        repetitions: int = 10,
        relax_time: float = 2e-9,
        temperature: float = 300.0,
        model: AnnihilationModel = CALIBRATED,
        material="S2",
        seed: int = 0,
        time_step: float | None = None,
    ):
        diameters = np.atleast_1d(np.asarray(diameters, dtype=float))
        d_sk = derive_thiele(load_material(material), 2e-9).skyrmion_diameter
        for d in diameters:
            require(
                np.isfinite(d) and d > 2 * d_sk,
                "diameters",
                float(d),
                f"diameters > two skyrmion diameters ({2 * d_sk:.3g} m)",
            )
        require(
            isinstance(repetitions, int) and repetitions >= 1,
            "repetitions",
            repetitions,
            "an integer >= 1",
        )
        for name, value in (("relax_time", relax_time), ("temperature", temperature)):
            require(math.isfinite(value), name, value, "a finite number (not inf or nan)")
        require(relax_time > 0, "relax_time", relax_time, "a relaxation time > 0 in seconds")
        require(temperature >= 0, "temperature", temperature, "a temperature >= 0 in kelvin")
        self.diameters, self.d_sk, self.repetitions = diameters, d_sk, repetitions
        self.relax = {
            "model": model,
            "relax_time": relax_time,
            "temperature": temperature,
            "material": material,
            "time_step": time_step,
        }
        self.trial_counts, self.trial_seeds = [], []
        for d, ss in zip(
            diameters, np.random.SeedSequence(seed).spawn(len(diameters)), strict=True
        ):
            if trial_counts is None:
                top = max(12, int(5 * saturation_estimate(d, d_sk, model)))
                top = min(top, int(1.5 * close_packing_estimate(d, d_sk)))  # what placement fits
                ns = np.unique(np.linspace(max(1, top // 20), top, 16).astype(int))
            else:
                ns = np.asarray(trial_counts(d), dtype=int)
            self.trial_counts.append(ns)
            self.trial_seeds.append(
                ss.generate_state(len(ns) * repetitions, dtype=np.uint32).reshape(
                    len(ns), repetitions
                )
            )
        #: (diameter index, trial number N, seed) of every trial, in the order they run
        self.trials = [
            (i, int(n), int(s))
            for i, (ns, seeds) in enumerate(zip(self.trial_counts, self.trial_seeds, strict=True))
            for n, row in zip(ns, seeds, strict=True)
            for s in row
        ]
        self.parameters = {
            "repetitions": repetitions,
            "relax_time_s": relax_time,
            "temperature_K": temperature,
            "seed": seed,
            "material": str(material),
            "skyrmion_diameter_m": d_sk,
            "annihilation": model.record(),
        }

    def run_trial(self, k: int) -> int:
        """Survivors of trial ``k``."""
        i, n, s = self.trials[k]
        return relax_survivors(self.diameters[i], n, seed=s, **self.relax)

    def result(self, survivors) -> SaturationResult:
        """The curve from the survivors of every trial (in :attr:`trials` order)."""
        survivors = np.asarray(survivors, dtype=float)
        counts, means, stds, best, best_err = [], [], [], [], []
        first = 0
        r = self.repetitions
        for ns in self.trial_counts:
            surv = survivors[first : first + len(ns) * r].reshape(len(ns), r)
            first += len(ns) * r
            mean, std = surv.mean(axis=1), surv.std(axis=1, ddof=1) if r > 1 else np.zeros(len(ns))
            k = int(np.argmax(mean))
            counts.append(ns)
            means.append(mean)
            stds.append(std)
            best.append(mean[k])
            best_err.append(std[k] / math.sqrt(r))
        return SaturationResult(
            self.diameters,
            counts,
            means,
            stds,
            np.array(best),
            np.array(best_err),
            np.array([close_packing_estimate(d, self.d_sk) for d in self.diameters]),
            self.parameters,
        )


def saturation_curve(
    diameters,
    *,
    trial_counts=None,
    repetitions: int = 10,
    relax_time: float = 2e-9,
    temperature: float = 300.0,
    model: AnnihilationModel = CALIBRATED,
    material="S2",
    seed: int = 0,
    time_step: float | None = None,
    progress=None,
) -> SaturationResult:
    """Run the saturation protocol for each diameter [m].

    ``trial_counts``: a function diameter → the N to try, or ``None`` for 16 values from
    0.05 to 5 times the model's :func:`saturation_estimate` (at least 1 … 12).
    ``progress(k, n_trials)`` is called after each trial.
    """
    protocol = SaturationProtocol(
        diameters,
        trial_counts=trial_counts,
        repetitions=repetitions,
        relax_time=relax_time,
        temperature=temperature,
        model=model,
        material=material,
        seed=seed,
        time_step=time_step,
    )
    survivors = []
    for k in range(len(protocol.trials)):
        survivors.append(protocol.run_trial(k))
        if progress is not None:
            progress(k + 1, len(protocol.trials))
    return protocol.result(survivors)
