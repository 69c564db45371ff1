"""The Skyrmion Reshuffler as a stochastic-computing decorrelator (:mod:`skygas.sc`).

:func:`reshuffler_decorrelator` wraps the device simulation in the common decorrelator
interface: a bit stream goes in (one nucleation per bit, one bit per injection interval), the
device is run until every skyrmion has been read out, and the read-out order is the output
stream, of the same length and exactly the same number of ones (the ``delay`` rule loses no
bit). The energy per bit comes from the current solve (both chambers' Joule power × the
injection interval); the latency is the mean transit time in injection intervals.

A skyrmion can stay in a chamber for a long time: near a wall the gyrotropic response to the
wall force moves it along the wall (clockwise), which in the lower half of a chamber is away
from the exit and can outrun the weak drift at the chamber's edge. Skyrmions still present
after ``drain_limit`` of extra running are read out in nucleation order and counted in
:attr:`ReshufflerDecorrelator.forced_readouts`, so the output keeps its length and p-value.
"""

from __future__ import annotations

import numpy as np

from skygas.reshuffler.analysis import summarize
from skygas.reshuffler.config import ReshufflerConfig, load_reshuffler_config
from skygas.reshuffler.run import ReshufflerRun
from skygas.sc.decorrelators import FunctionDecorrelator


class ReshufflerDecorrelator(FunctionDecorrelator):
    """A :class:`~skygas.sc.decorrelators.FunctionDecorrelator` that counts forced read-outs.

    The skyrmions read out by force after the drain limit (``forced_readouts``, summed over calls).
    """

    forced_readouts: int = 0


def reshuffler_decorrelator(
    config: ReshufflerConfig | None = None,
    name: str = "skyrmion reshuffler",
    drain_limit: float = 100e-6,
) -> ReshufflerDecorrelator:
    """A decorrelator that runs ``config`` (default: the ``paper`` preset) on each stream."""
    if config is None:
        config = load_reshuffler_config(preset="paper")
    config = config.model_copy(
        update={
            "output": config.output.model_copy(
                update={"trajectory_window": 0.0, "snapshot_interval": 1.0}
            )
        }
    )

    def reshuffle(bits: np.ndarray, rng: np.random.Generator):
        seeded = config.model_copy(
            update={
                "seed": int(rng.integers(2**62)),
                "duration": len(bits) * config.injection.interval,
            }
        )
        run = ReshufflerRun.build(seeded, bits=bits)
        run.advance()
        run.drain(drain_limit)
        summary = summarize(run, dataset=False).summary
        out = run.detections()["up"]
        if len(out) < len(bits):  # still inside: read out in nucleation order, counted
            log = run.injector.log
            detected = set(run.detections()["skyrmion"].tolist())
            order = np.argsort(log.injection_step, kind="stable")
            rest = [
                log.bit[k]
                for k in order
                if log.skyrmion[k] >= 0 and log.skyrmion[k] not in detected
            ]
            decorrelator.forced_readouts += len(rest)
            out = np.concatenate([out, np.asarray(rest, dtype=bool)])
        latency = summary["mean_transit_s"] / config.injection.interval
        return out.astype(bool), summary["energy_per_bit_J"], latency

    decorrelator = ReshufflerDecorrelator(
        name,
        reshuffle,
        energy_source="Joule power of the device's current solve × injection interval "
        "(conductor thickness and resistivity as configured)",
    )
    return decorrelator


#: The key of the reshuffler's part in the ``skygas sc demo --reshuffler`` summary.
DEMO_SUMMARY_KEY = "reshuffler"


def reshuffler_demo(
    out_dir,
    *,
    seed: int = 2024,
    n_bits: int = 2048,
    p_values=(0.2, 0.4, 0.6, 0.8),
    correlation_bits: float = 16.0,
    trials: int = 2,
) -> dict:
    """The paper's AND-gate figure with the device, and the reshuffler beside two CMOS baselines.

    Squaring x·x with an AND gate (x AND x gives p; x AND reshuffled x should give p²), then SCC,
    squaring error, latency and energy per bit on Bernoulli and telegraph inputs. Writes
    ``sc_reshuffler.png`` and ``sc_reshuffler.json`` into ``out_dir``.
    """
    import json
    from pathlib import Path

    from matplotlib.figure import Figure

    from skygas._version import __version__
    from skygas.sc import DelayIsolator, ShuffleBuffer, bernoulli_stream
    from skygas.sc.demo import compare_decorrelators

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    device = reshuffler_decorrelator()
    square_seed, compare_seed = np.random.SeedSequence(seed).spawn(2)
    squaring = []
    for p, child in zip(p_values, square_seed.spawn(len(p_values)), strict=True):
        x = bernoulli_stream(p, n_bits, seed=child)
        y = device.apply(x, seed=np.random.default_rng(child)).stream
        squaring.append(
            {
                "p": p,
                "x_and_x": float((x & x).mean()),
                "x_and_reshuffled_x": float((x & y).mean()),
                "binomial_std": float(np.sqrt(p * p * (1 - p * p) / n_bits)),
            }
        )
    rows = compare_decorrelators(
        [DelayIsolator(1), ShuffleBuffer(128), device],
        p=0.6,
        n_bits=n_bits,
        n_trials=trials,
        correlation_bits=correlation_bits,
        seed=compare_seed,
    )
    fig = Figure(figsize=(10, 4), dpi=110)
    ax, bx = fig.subplots(1, 2)
    grid = np.linspace(0, 1, 101)
    ax.plot(grid, grid, "k:", label="p (identical inputs)")
    ax.plot(grid, grid**2, "k--", label="p² (independent inputs)")
    ps = [s["p"] for s in squaring]
    ax.plot(ps, [s["x_and_x"] for s in squaring], "o", label="x AND x")
    ax.errorbar(
        ps,
        [s["x_and_reshuffled_x"] for s in squaring],
        yerr=[2 * s["binomial_std"] for s in squaring],
        fmt="s",
        label="x AND reshuffled x (bars: ±2σ, binomial)",
    )
    ax.set_xlabel("p of x")
    ax.set_ylabel("p of the AND output")
    ax.legend(fontsize=8)
    ax.set_title(f"squaring with an AND gate, N = {n_bits}", fontsize=9)
    names = [r["name"] for r in rows]
    width = 0.38
    for k, kind in enumerate(("bernoulli", "telegraph")):
        values = [r[kind]["scc"] for r in rows]
        bx.bar(np.arange(len(names)) + (k - 0.5) * width, values, width, label=kind)
    bx.set_xticks(np.arange(len(names)), names, rotation=15, fontsize=8)
    bx.set_ylabel("SCC(x, decorrelated x)")
    bx.axhline(0, color="grey", lw=0.5)
    bx.legend(fontsize=8)
    fig.tight_layout()
    from skygas.runs.provenance import provenance
    from skygas.runs.run_driver import write_figure, write_json

    parameters = {
        "n_bits": n_bits,
        "trials": trials,
        "telegraph_correlation_bits": correlation_bits,
    }
    prov = provenance(seed=seed, config_json=json.dumps(parameters, sort_keys=True))
    write_figure(out / "sc_reshuffler.png", lambda tmp: fig.savefig(tmp), prov)
    record = {
        "skygas_version": __version__,
        "seed": seed,
        **parameters,
        "config_hash": prov["config_hash"],
        "command_line": prov["command_line"],
        "squaring": squaring,
        "comparison": rows,
    }
    write_json(out / "sc_reshuffler.json", record)
    return record
