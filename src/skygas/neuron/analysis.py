r"""Analyses of the neuron: leak time, inter-spike intervals, transfer curve and the fit of a
leaky integrate-and-fire (LIF) model.

**Leak time (maximum likelihood).** With the gate closed and no input the count N(t) only
decreases, by annihilation. If each skyrmion dies at rate 1/τ, the likelihood of the observed
deaths over the observed exposure gives τ̂ = ∫N dt / n_deaths with standard error τ̂/√n_deaths
(censored exponential lifetimes). In a driven run the same estimator over the annihilation log
gives the mean leak time at the run's occupancy.

**LIF model.** dV/dt = −V/τ + Σ_k δ(t − t_k) (one unit per injected skyrmion); when V reaches
the threshold θ it fires and V is set to V_r. Fitted to a device run: τ from the leak estimator,
θ the median count at the gate openings, V_r the median count at the closings. Goodness of
fit: the ratio of the LIF's spike count to the device's over the same injections, the fraction
of device spikes with an LIF spike within ``window``, and the normalised RMS difference between
V(t) and the count trace. The transfer curve of a deterministic LIF driven at a mean rate r,
f(r) = 1/(t_rel + τ ln((rτ − V_r)/(rτ − θ))) for rτ > θ, else 0, is compared with the measured
one (coefficient of determination R²).
"""

from __future__ import annotations

import math

import numpy as np


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
    """The leak experiment: gate closed, no input, ``initial_count`` skyrmions at random in the
    chamber; returns the trace and the fitted leak time with its error."""
    from skygas.geometry import random_positions

    run = device.build(inputs=[], duration=duration, seed=seed)
    run.controller.threshold = math.inf     # never open the gate
    d_nm = run.sim.thiele.skyrmion_diameter_internal
    rng = np.random.default_rng(np.random.SeedSequence((seed, 0x6C65616B)))
    pts = random_positions(run.sim.outline, initial_count, 2 * d_nm, 1.5 * d_nm, rng)
    # keep them in the chamber (not the conduits)
    run.sim._insert_nm(pts)
    run.controller.act(run.sim)              # first trace point at t = 0
    run.run()
    tr = run.trace()
    deaths = [a[0] for a in run.annihilator.annihilations]
    tau, err = leak_from_log(tr["time"], tr["count"], deaths)
    return {"time": tr["time"], "count": tr["count"], "leak_time_s": tau,
            "leak_time_error_s": err, "n_annihilated": len(deaths), "run": run}


def simulate_lif(injection_times, tau: float, threshold: float, reset: float,
                 duration: float, dt: float, dead_time: float = 0.0):
    """V(t) on a grid of step dt and the LIF spike times for unit jumps at ``injection_times``."""
    n = int(duration / dt) + 1
    jumps = np.bincount(np.clip((np.asarray(injection_times) / dt).astype(int), 0, n - 1),
                        minlength=n)
    decay = math.exp(-dt / tau) if math.isfinite(tau) else 1.0
    v = np.empty(n)
    value, spikes, blocked_until = 0.0, [], -1.0
    for k in range(n):
        value = value * decay + jumps[k]
        t = k * dt
        if value >= threshold and t >= blocked_until:
            spikes.append(t)
            value = reset
            blocked_until = t + dead_time
        v[k] = value
    return np.arange(n) * dt, v, np.array(spikes)


def fit_lif(run, window: float | None = None) -> dict:
    """Fit τ, θ, V_r of an LIF to a device run and say how well it reproduces it."""
    tr = run.trace()
    summary_tau, tau_err = leak_from_log(tr["time"], tr["count"],
                                         [a[0] for a in run.annihilator.annihilations])
    dt = run.sim.time_step
    t_open = np.array(run.controller.openings, dtype=int)
    t_close = np.array(run.controller.closings, dtype=int)
    step_of = {int(round(t / dt)): c for t, c in zip(tr["time"], tr["count"])}
    theta = float(np.median([step_of.get(s, np.nan) for s in t_open])) if len(t_open) else \
        float(run.controller.threshold)
    reset = float(np.median([step_of.get(s, np.nan) for s in t_close])) if len(t_close) else \
        float(run.controller.reset_level)
    release = float(np.mean((t_close - t_open[:len(t_close)]) * dt)) if len(t_close) else 0.0
    inj = run.injection_times()
    grid_dt = float(np.median(np.diff(tr["time"]))) if len(tr["time"]) > 1 else dt
    t, v, spikes = simulate_lif(inj, summary_tau, theta, reset, run.sim.time, grid_dt, release)
    device_spikes = run.spike_times()
    window = window if window is not None else max(10 * grid_dt, 0.1 * release)
    matched = 0
    for s in device_spikes:
        if len(spikes) and np.min(np.abs(spikes - s)) <= window:
            matched += 1
    counts = np.interp(t, tr["time"], tr["count"]) if len(tr["time"]) else np.zeros_like(t)
    scale = float(np.std(counts)) or 1.0
    return {
        "tau_s": summary_tau, "tau_error_s": tau_err, "threshold": theta, "reset": reset,
        "release_time_s": release,
        "lif_spikes": int(len(spikes)), "device_spikes": int(len(device_spikes)),
        "spike_count_ratio": len(spikes) / len(device_spikes) if len(device_spikes) else None,
        "spike_match_fraction": matched / len(device_spikes) if len(device_spikes) else None,
        "match_window_s": window,
        "trace_nrmse": float(np.sqrt(np.mean((v - counts) ** 2)) / scale),
    }


def lif_rate(rate, tau: float, threshold: float, reset: float, release: float = 0.0):
    """Deterministic LIF firing rate [Hz] at mean input ``rate`` [Hz] (array)."""
    rate = np.asarray(rate, float)
    drive = rate * tau
    out = np.zeros_like(drive)
    ok = drive > threshold
    out[ok] = 1.0 / (release + tau * np.log((drive[ok] - reset) / (drive[ok] - threshold)))
    return out


def transfer_curve(device, rates, duration: float, seed: int = 0, progress=None) -> dict:
    """Firing rate against input rate: one run per Poisson input rate [Hz] (same seed)."""
    from skygas.neuron.inputs import InputSpec

    rates = np.asarray(rates, float)
    if np.any(~np.isfinite(rates)) or np.any(rates < 0):
        from skygas.errors import InputError
        raise InputError("transfer.rates", rates.tolist(), "rates >= 0 in Hz")
    firing, injected, annihilated = [], [], []
    for r in rates:
        run = device.build(inputs=[InputSpec(kind="poisson", rate=float(r))],
                           duration=duration, seed=seed).run()
        firing.append(len(run.spike_times()) / run.sim.time)
        injected.append(run.injector.n_injected)
        annihilated.append(run.annihilator.n_annihilated)
        if progress is not None:
            progress(r, firing[-1])
    return {"input_rate_Hz": rates.tolist(), "firing_rate_Hz": firing,
            "n_injected": injected, "n_annihilated": annihilated, "duration_s": duration}


def r_squared(measured, predicted) -> float | None:
    measured, predicted = np.asarray(measured, float), np.asarray(predicted, float)
    ss = float(np.sum((measured - measured.mean()) ** 2))
    return None if ss == 0 else 1.0 - float(np.sum((measured - predicted) ** 2)) / ss
