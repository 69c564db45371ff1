r"""Analyses of the neuron: leak time, inter-spike intervals and the transfer curve.

**Leak time (maximum likelihood).** With the gate closed and no input the count N(t) only
decreases, by annihilation. If each skyrmion dies at rate 1/τ, the likelihood of the observed
deaths over the observed exposure gives τ̂ = ∫N dt / n_deaths with standard error τ̂/√n_deaths
(censored exponential lifetimes). In a driven run the same estimator over the annihilation log
gives the mean leak time at the run's occupancy.

The leaky integrate-and-fire model and its fit live in :mod:`skygas.neuron.lif`.
"""

from __future__ import annotations

import math

import numpy as np

from skygas.core.errors import require

# the LIF names stay importable from here, where they used to live
from skygas.neuron.lif import (
    lif_rate,  # noqa: F401
)


def _require_duration(duration) -> None:
    try:
        ok = math.isfinite(float(duration)) and float(duration) > 0
    except (TypeError, ValueError):
        ok = False
    require(ok, "duration", duration, "a finite duration > 0 in seconds")


def leak_from_log(times, counts, death_times) -> tuple[float, float]:
    """(τ̂, its standard error) [s] from a count trace and annihilation times; inf if none."""
    times, counts = np.asarray(times, float), np.asarray(counts, float)
    if len(times) < 2:
        return math.inf, math.inf
    exposure = float(np.sum(counts[:-1] * np.diff(times)))
    n = len(death_times)
    if n == 0:
        return math.inf, math.inf
    tau = exposure / n
    return tau, tau / math.sqrt(n)


def isi_statistics(spike_times) -> dict:
    """Mean, standard deviation and coefficient of variation of the inter-spike intervals."""
    isi = np.diff(np.asarray(spike_times, float))
    if len(isi) == 0:
        return {"n": 0, "mean_s": None, "std_s": None, "cv": None}
    mean = float(isi.mean())
    std = float(isi.std(ddof=1)) if len(isi) > 1 else 0.0
    return {"n": int(len(isi)), "mean_s": mean, "std_s": std, "cv": std / mean if mean else None}


def measure_leak(device, initial_count: int, duration: float, seed: int = 0) -> dict:
    """The leak experiment: gate closed, no input, ``initial_count`` skyrmions at random.

    Placed at random in the chamber; returns the trace and the fitted leak time with its error.
    """
    from skygas.physics.geometry import _random_positions_nm

    require(
        isinstance(initial_count, (int, np.integer)) and initial_count >= 0,
        "initial_count",
        initial_count,
        "an integer >= 0",
    )
    _require_duration(duration)
    run = device.build(inputs=[], duration=duration, seed=seed)
    run.controller.threshold = math.inf  # never open the gate
    d_nm = run.sim.thiele.skyrmion_diameter_internal
    rng = np.random.default_rng(np.random.SeedSequence((seed, 0x6C65616B)))
    pts = _random_positions_nm(run.sim.outline, initial_count, 2 * d_nm, 1.5 * d_nm, rng)
    # keep them in the chamber (not the conduits)
    run.sim.state.insert_nm(pts)
    run.controller.act(run.sim)  # first trace point at t = 0
    run.run()
    tr = run.trace()
    deaths = run.annihilator.annihilation_times
    tau, err = leak_from_log(tr["time"], tr["count"], deaths)
    return {
        "time": tr["time"],
        "count": tr["count"],
        "leak_time_s": tau,
        "leak_time_error_s": err,
        "n_annihilated": len(deaths),
        "run": run,
    }


def transfer_curve(
    device, rates, duration: float, seed: int = 0, progress=None, priced: bool = True
) -> dict:
    """Firing rate against input rate: one run per Poisson input rate [Hz] (same seed).

    ``priced``: each run's estimate is checked as it is built (False: a job that priced them
    with its own run, :class:`~skygas.neuron.files.NeuronJob`).
    """
    from skygas.neuron.inputs import InputSpec

    rates = np.asarray(rates, float)
    require(
        bool(np.all(np.isfinite(rates)) and np.all(rates >= 0)),
        "transfer.rates",
        rates.tolist(),
        "finite rates >= 0 in Hz",
    )
    _require_duration(duration)
    firing, injected, annihilated = [], [], []
    for r in rates:
        run = device.build(
            inputs=[InputSpec(kind="poisson", rate=float(r))],
            duration=duration,
            seed=seed,
            priced_runs=None if priced else 0,
        ).run()
        firing.append(len(run.spike_times()) / run.sim.time)
        injected.append(run.injector.n_injected)
        annihilated.append(run.annihilator.n_annihilated)
        if progress is not None:
            progress(r, firing[-1])
    return {
        "input_rate_Hz": rates.tolist(),
        "firing_rate_Hz": firing,
        "n_injected": injected,
        "n_annihilated": annihilated,
        "duration_s": duration,
    }


def r_squared(measured, predicted) -> float | None:
    """Coefficient of determination R² of ``predicted`` against ``measured`` (None if constant)."""
    measured, predicted = np.asarray(measured, float), np.asarray(predicted, float)
    ss = float(np.sum((measured - measured.mean()) ** 2))
    return None if ss == 0 else 1.0 - float(np.sum((measured - predicted) ** 2)) / ss
