r"""The leaky integrate-and-fire (LIF) model of the neuron and its fit to a device run.

**LIF model.** dV/dt = −V/τ + Σ_k δ(t − t_k) (one unit per injected skyrmion); when V reaches
the threshold θ it fires, V is held at V_r for the release time t_rel (the device's gate is open
and its chamber drains), then integrates again; it cannot fire again before a further refractory
time t_ref has passed. Fitted to a device run: τ from the leak estimator over the closed-gate
periods (the integrating phase; annihilations while the gate is open are part of the release),
θ the median count at the gate openings, V_r the median count at the closings, t_rel the mean
opening, t_ref the device's refractory time. Goodness of fit: the ratio of the LIF's spike
count to the device's over the same injections, the fraction of device spikes with an LIF spike
within ``window``, and the normalised RMS difference between V(t) and the count trace (RMS of
V − N over the standard deviation of N: 0 is perfect, 1 is no better than the mean count).
A free-running LIF drifts out of phase with the device after a few spikes (both are driven by
the same injections, but the device's leak is not exactly exponential), which makes that last
figure large even when each integrating phase is well described. :func:`restarted_lif`
therefore restarts the LIF from the device's count at the start of every closed-gate period:
the *subthreshold* NRMSE compares only the closed-gate samples (the standard deviation of N over
the same samples in the denominator), and the *next-spike* error is the time between the
restarted LIF's first crossing of θ and the device's next opening (median of its absolute
value, and the fraction within ``window``). :func:`subthreshold_floor` says what the subthreshold
NRMSE of an ideal stochastic LIF (independent deaths at 1/τ) would be, since annihilation is
random and no deterministic model follows individual deaths. The transfer curve of a
deterministic LIF driven at a mean rate r,

    f(r) = 1 / (t_rel + max(t_ref, τ ln((rτ − V_r)/(rτ − θ))))  for rτ > θ, else 0,

is compared with the measured one (coefficient of determination R²).
"""

from __future__ import annotations

import math

import numpy as np


def closed_gate_leak(trace: dict, death_times) -> tuple[float, float]:
    """(τ̂, its standard error) [s] of the leak while the gate is closed.

    The estimator of :func:`skygas.neuron.analysis.leak_from_log` with the exposure ∫N dt and the
    deaths restricted to the trace intervals that start with the gate closed.
    """
    t, n, closed = (
        np.asarray(trace["time"], float),
        np.asarray(trace["count"], float),
        ~np.asarray(trace["gate_open"], bool),
    )
    if len(t) < 2:
        return math.inf, math.inf
    exposure = float(np.sum((n[:-1] * np.diff(t))[closed[:-1]]))
    deaths = np.asarray(death_times, float)
    interval = np.clip(np.searchsorted(t, deaths, side="right") - 1, 0, len(t) - 1)
    n_dead = int(np.count_nonzero(closed[interval]))
    if n_dead == 0:
        return math.inf, math.inf
    tau = exposure / n_dead
    return tau, tau / math.sqrt(n_dead)


def restarted_lif(trace: dict, injection_times, tau: float, threshold: float) -> dict:
    """The LIF restarted from the device's count at the start of every closed-gate period.

    In each period V starts at the device's count and follows V ← V e^{−Δt/τ} + (injections in
    Δt) on the trace's samples. Returns ``subthreshold_nrmse`` (RMS of V − N over the
    closed-gate samples, divided by the standard deviation of N there) and, for every period
    that ended with a gate opening, the error [s] of the LIF's first crossing of ``threshold``
    against that opening (``next_spike_errors``, positive: the LIF fires late; a period in which
    V never crosses counts as if it crossed at the end of the run).
    """
    t, n, closed = (
        np.asarray(trace["time"], float),
        np.asarray(trace["count"], float),
        ~np.asarray(trace["gate_open"], bool),
    )
    if len(t) < 2 or not closed.any():
        return {"subthreshold_nrmse": None, "next_spike_errors": []}
    inj = np.searchsorted(np.sort(np.asarray(injection_times, float)), t, side="right")
    arrivals = np.diff(inj)  # injections in (t[k-1], t[k]]
    decay = np.exp(-np.diff(t) / tau) if math.isfinite(tau) else np.ones(len(t) - 1)
    v = np.empty(len(t))
    v[0] = n[0]
    errors, crossed = [], None
    for k in range(1, len(t)):
        if closed[k - 1]:
            v[k] = v[k - 1] * decay[k - 1] + arrivals[k - 1]
            if crossed is None and v[k] >= threshold:
                crossed = t[k]
        else:
            v[k] = n[k]
        if not closed[k] and closed[k - 1]:  # the device opened at t[k]
            errors.append((crossed if crossed is not None else t[-1]) - t[k])
        if not closed[k]:
            crossed = None
    scale = float(np.std(n[closed])) or 1.0
    return {
        "subthreshold_nrmse": float(np.sqrt(np.mean((v[closed] - n[closed]) ** 2)) / scale),
        "next_spike_errors": errors,
    }


def subthreshold_floor(
    trace: dict, injection_times, tau: float, replicas: int = 200, seed: int = 0
) -> float | None:
    """The subthreshold NRMSE that an ideal *stochastic* LIF would score.

    Its count starts from the device's count in every closed-gate period, gains the same injections
    and loses each skyrmion independently at rate 1/τ (binomial survival per sample). The median
    over ``replicas`` realisations (seeded) is the floor set by shot noise alone; a device above it
    has a leak that is not a constant per-skyrmion rate.
    """
    t, n, closed = (
        np.asarray(trace["time"], float),
        np.asarray(trace["count"], float),
        ~np.asarray(trace["gate_open"], bool),
    )
    if len(t) < 2 or not closed.any() or not math.isfinite(tau):
        return None
    inj = np.searchsorted(np.sort(np.asarray(injection_times, float)), t, side="right")
    arrivals = np.diff(inj)
    survive = np.exp(-np.diff(t) / tau)
    rng = np.random.default_rng(np.random.SeedSequence((seed, 0x666C72)))
    mean = np.empty(len(t))
    paths = np.empty((len(t), replicas))
    mean[0], paths[0] = n[0], n[0]
    for k in range(1, len(t)):
        if closed[k - 1]:
            mean[k] = mean[k - 1] * survive[k - 1] + arrivals[k - 1]
            paths[k] = rng.binomial(paths[k - 1].astype(np.int64), survive[k - 1]) + arrivals[k - 1]
        else:
            mean[k], paths[k] = n[k], n[k]
    sub = paths[closed]
    scale = np.std(sub, axis=0)
    scale[scale == 0] = 1.0
    nrmse = np.sqrt(np.mean((sub - mean[closed, None]) ** 2, axis=0)) / scale
    return float(np.median(nrmse))


def simulate_lif(
    injection_times,
    tau: float,
    threshold: float,
    reset: float,
    duration: float,
    dt: float,
    release: float = 0.0,
    refractory: float = 0.0,
):
    """V(t) on a grid of step dt and the LIF spike times for unit jumps at ``injection_times`` [s].

    After a spike V is held at ``reset`` for ``release`` [s], and no spike comes before
    ``release + refractory`` [s] have passed.
    """
    n = int(duration / dt) + 1
    jumps = np.bincount(
        np.clip((np.asarray(injection_times) / dt).astype(int), 0, n - 1), minlength=n
    )
    decay = math.exp(-dt / tau) if math.isfinite(tau) else 1.0
    v = np.empty(n)
    value, spikes, held_until, blocked_until = 0.0, [], -1.0, -1.0
    for k in range(n):
        t = k * dt
        value = reset if t < held_until else value * decay + jumps[k]
        if value >= threshold and t >= blocked_until:
            spikes.append(t)
            value = reset
            held_until = t + release
            blocked_until = t + release + refractory
        v[k] = value
    return np.arange(n) * dt, v, np.array(spikes)


def fit_lif(run, window: float | None = None) -> dict:
    """Fit τ, θ, V_r of an LIF to a device run and say how well it reproduces it."""
    tr = run.trace()
    deaths = run.annihilator.annihilation_times
    tau, tau_err = closed_gate_leak(tr, deaths)
    dt = run.sim.time_step
    t_open = np.array(run.controller.openings, dtype=int)
    t_close = np.array(run.controller.closings, dtype=int)
    step_of = {int(round(t / dt)): c for t, c in zip(tr["time"], tr["count"], strict=True)}
    theta = (
        float(np.median([step_of.get(s, np.nan) for s in t_open]))
        if len(t_open)
        else float(run.controller.threshold)
    )
    reset = (
        float(np.median([step_of.get(s, np.nan) for s in t_close]))
        if len(t_close)
        else float(run.controller.reset_level)
    )
    release = float(np.mean((t_close - t_open[: len(t_close)]) * dt)) if len(t_close) else 0.0
    refractory = run.controller.refractory_steps * dt
    inj = run.injection_times()
    grid_dt = float(np.median(np.diff(tr["time"]))) if len(tr["time"]) > 1 else dt
    t, v, spikes = simulate_lif(inj, tau, theta, reset, run.sim.time, grid_dt, release, refractory)
    device_spikes = run.spike_times()
    window = window if window is not None else max(10 * grid_dt, 0.1 * release)
    matched = 0
    for s in device_spikes:
        if len(spikes) and np.min(np.abs(spikes - s)) <= window:
            matched += 1
    restarted = restarted_lif(tr, inj, tau, theta)
    errors = np.asarray(restarted["next_spike_errors"], float)
    counts = np.interp(t, tr["time"], tr["count"]) if len(tr["time"]) else np.zeros_like(t)
    scale = float(np.std(counts)) or 1.0
    return {
        "tau_s": tau,
        "tau_error_s": tau_err,
        "threshold": theta,
        "reset": reset,
        "release_time_s": release,
        "refractory_time_s": refractory,
        "lif_spikes": int(len(spikes)),
        "device_spikes": int(len(device_spikes)),
        "spike_count_ratio": len(spikes) / len(device_spikes) if len(device_spikes) else None,
        "spike_match_fraction": matched / len(device_spikes) if len(device_spikes) else None,
        "match_window_s": window,
        "trace_nrmse": float(np.sqrt(np.mean((v - counts) ** 2)) / scale),
        "subthreshold_nrmse": restarted["subthreshold_nrmse"],
        "subthreshold_nrmse_floor": subthreshold_floor(tr, inj, tau),
        "next_spike_error_median_s": float(np.median(np.abs(errors))) if len(errors) else None,
        "next_spike_match_fraction": float(np.mean(np.abs(errors) <= window))
        if len(errors)
        else None,
    }


def lif_rate(
    rate, tau: float, threshold: float, reset: float, release: float = 0.0, refractory: float = 0.0
):
    """Deterministic LIF firing rate [Hz] at mean input ``rate`` [Hz] (array).

    One spike per release plus the climb from ``reset`` to ``threshold`` (at least ``refractory``).
    An infinite ``tau`` (no leak) climbs in ``(threshold - reset) / rate``.
    """
    rate = np.asarray(rate, float)
    drive = rate * tau
    out = np.zeros_like(drive)
    ok = drive > threshold
    if np.isinf(tau):  # no leak (a fit of a run too short to see one): the climb's limit
        climb = (threshold - reset) / rate[ok]
    else:
        climb = tau * np.log((drive[ok] - reset) / (drive[ok] - threshold))
    out[ok] = 1.0 / (release + np.maximum(refractory, climb))
    return out
