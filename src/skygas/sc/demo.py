r"""Demonstrations of what a decorrelator buys a stochastic circuit (``skygas sc demo``).

Three experiments, each a function returning plain data, and :func:`run_demo` which runs them,
draws the figures and writes ``sc_demo.json`` (parameters, seed, package version, the hash of
the parameters as ``config_hash``, the command line, results); each PNG carries the same record
in its text chunks (:func:`~skygas.runs.run_driver.write_figure`):

1. :func:`squaring_curve` -- the paper's AND-gate figure: :math:`x \wedge x` gives :math:`p`,
   :math:`x \wedge d(x)` after a decorrelator :math:`d` gives :math:`p^2`.
2. :func:`error_vs_length` -- RMS multiplication error against N, compared with the binomial
   limit :math:`\sqrt{q(1-q)/N}`, :math:`q = p_x p_y`, of independent bits.
3. :func:`compare_decorrelators` -- each decorrelator on Bernoulli and on telegraph-noise
   inputs: SCC between a stream and its decorrelated copy, squaring error, latency, energy.

Every experiment takes a list of :class:`~skygas.sc.decorrelators.Decorrelator`; a device-backed
reshuffler (:class:`~skygas.sc.decorrelators.FunctionDecorrelator`) is simply appended to it.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from skygas._version import __version__
from skygas.core import validate as v
from skygas.core.errors import InputError
from skygas.core.resources import require_memory
from skygas.runs.provenance import provenance
from skygas.runs.run_driver import write_figure, write_json
from skygas.sc.bitstreams import bernoulli_stream, telegraph_stream
from skygas.sc.decorrelators import Decorrelator, DelayIsolator, Regenerator, ShuffleBuffer
from skygas.sc.metrics import binomial_std, p_value, scc


def default_decorrelators() -> list[Decorrelator]:
    """The CMOS baselines compared by default: isolators, shuffle buffers, a regenerator."""
    return [
        DelayIsolator(1),
        DelayIsolator(16),
        ShuffleBuffer(16),
        ShuffleBuffer(128),
        Regenerator(64),
    ]


def _check_decorrelators(decorrelators: Sequence[Decorrelator]) -> list[Decorrelator]:
    items = list(decorrelators)
    if not items or not all(isinstance(d, Decorrelator) for d in items):
        raise InputError("decorrelators", decorrelators, "a non-empty list of Decorrelator objects")
    return items


def ideal_reshuffle_squaring_error(p: float, n_bits: Any) -> np.ndarray:
    r"""RMS error of :math:`p^2` from ``x AND y`` when y is a uniformly random permutation of x.

    A perfect reshuffler keeps the number of ones k of its input, so the copy inherits the
    input's p-value error. Conditioning on k, the overlap is hypergeometric with mean
    :math:`k^2/N` and variance :math:`\approx N p^2(1-p)^2`; with
    :math:`\operatorname{Var}(k/N) = p(1-p)/N` this gives, to leading order in 1/N,

    .. math::  \text{RMS} = \sqrt{p^2 (1-p)(1+3p)/N},

    above the binomial limit :math:`\sqrt{p^2(1-p^2)/N}` of two independent inputs
    (by :math:`\sqrt{(1+3p)/(1+p)}`): squaring a stream costs more bits than multiplying two.
    """
    prob = float(v.probability(p, "p"))
    n = np.asarray(n_bits, dtype=float)
    return np.sqrt(prob**2 * (1 - prob) * (1 + 3 * prob) / n)


def squaring_curve(
    decorrelator: Decorrelator,
    p_values: Sequence[float] | np.ndarray,
    n_bits: int,
    *,
    n_trials: int = 16,
    correlation_bits: float | None = None,
    seed: v.SeedLike = None,
) -> dict[str, list[float]]:
    """Mean AND output for ``x AND x`` and ``x AND d(x)`` at each p.

    Inputs are Bernoulli streams, or telegraph noise when ``correlation_bits`` (clock cycles)
    is given.
    """
    p = v.probability(p_values, "p_values").reshape(-1)
    n_bits = v.positive_int(n_bits, "n_bits")
    n_trials = v.positive_int(n_trials, "n_trials")
    rng = v.make_rng(seed)
    if correlation_bits is None:
        x = bernoulli_stream(p[:, None], n_bits, shape=(p.size, n_trials), seed=rng)
    else:
        x = telegraph_stream(
            p[:, None], correlation_bits, n_bits, shape=(p.size, n_trials), seed=rng
        )
    copy = decorrelator.apply(x, rng).stream
    return {
        "p": p.tolist(),
        "identical_inputs": p_value(x & x).mean(axis=-1).tolist(),
        "decorrelated_inputs": p_value(x & copy).mean(axis=-1).tolist(),
    }


def error_vs_length(
    lengths: Sequence[int],
    decorrelators: Sequence[Decorrelator],
    *,
    p: float = 0.6,
    n_trials: int = 64,
    seed: v.SeedLike = None,
) -> dict[str, Any]:
    r"""RMS error of :math:`p^2` estimated by AND gates, against the stream length N.

    Compares independent inputs (two Bernoulli streams), identical inputs, and a stream ANDed
    with each decorrelator's copy of itself; the references are the binomial limit
    :math:`\sqrt{p^2(1-p^2)/N}` and :func:`ideal_reshuffle_squaring_error`.
    """
    ns = [v.positive_int(n, "lengths") for n in lengths]
    items = _check_decorrelators(decorrelators)
    prob = float(v.probability(p, "p"))
    n_trials = v.positive_int(n_trials, "n_trials")
    rng = v.make_rng(seed)
    target = prob * prob
    result: dict[str, Any] = {
        "n_bits": ns,
        "binomial_limit": [float(binomial_std(target, n)) for n in ns],
        "ideal_reshuffle_limit": [float(ideal_reshuffle_squaring_error(prob, n)) for n in ns],
        "independent_inputs": [],
        "identical_inputs": [],
        "decorrelated": {d.name: [] for d in items},
    }
    for n in ns:
        x = bernoulli_stream(prob, n, shape=(n_trials,), seed=rng)
        y = bernoulli_stream(prob, n, shape=(n_trials,), seed=rng)
        rms = lambda out: float(np.sqrt(np.mean((p_value(out) - target) ** 2)))  # noqa: E731
        result["independent_inputs"].append(rms(x & y))
        result["identical_inputs"].append(rms(x & x))
        for d in items:
            try:
                copy = d.apply(x, rng).stream
            except InputError:
                # Streams shorter than the decorrelator's registers: no point at this N.
                result["decorrelated"][d.name].append(None)
            else:
                result["decorrelated"][d.name].append(rms(x & copy))
    return result


def compare_decorrelators(
    decorrelators: Sequence[Decorrelator],
    *,
    p: float = 0.6,
    n_bits: int = 4096,
    n_trials: int = 32,
    correlation_bits: float = 16.0,
    seed: v.SeedLike = None,
) -> list[dict[str, Any]]:
    r"""Each decorrelator on Bernoulli and on telegraph inputs (correlation time in clocks).

    For each input kind, reports the mean SCC between the stream and its decorrelated copy,
    the RMS error of the squaring ``x AND d(x)`` against :math:`p^2`, the mean p-value shift
    :math:`p_\text{out} - p_\text{in}`, and the decorrelator's latency and energy per bit.
    """
    items = _check_decorrelators(decorrelators)
    prob = float(v.probability(p, "p"))
    n_bits = v.positive_int(n_bits, "n_bits")
    n_trials = v.positive_int(n_trials, "n_trials")
    rng = v.make_rng(seed)
    inputs = {
        "bernoulli": bernoulli_stream(prob, n_bits, shape=(n_trials,), seed=rng),
        "telegraph": telegraph_stream(prob, correlation_bits, n_bits, shape=(n_trials,), seed=rng),
    }
    rows = []
    for d in items:
        row = d.describe()
        for kind, x in inputs.items():
            result = d.apply(x, rng)
            y = result.stream
            row[kind] = {
                "scc": float(np.mean(scc(x, y))),
                "squaring_rms_error": float(np.sqrt(np.mean((p_value(x & y) - prob**2) ** 2))),
                "p_shift": float(np.mean(p_value(y) - p_value(x))),
            }
            # A device model may measure its latency and energy per run.
            row["latency_bits"] = result.latency_bits
            row["energy_per_bit_J"] = result.energy_per_bit_J
        rows.append(row)
    return rows


# -- figures ---------------------------------------------------------------------------------


def _plot_squaring(panels: dict[str, dict[str, dict[str, list[float]]]], path: Path) -> None:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10, 4.2))
    axes = fig.subplots(1, len(panels), sharey=True)
    grid = np.linspace(0, 1, 101)
    for ax, (title, curves) in zip(np.atleast_1d(axes), panels.items(), strict=False):
        ax.plot(grid, grid, "k:", lw=1, label="$p$")
        ax.plot(grid, grid**2, "k--", lw=1, label="$p^2$")
        first = next(iter(curves.values()))
        ax.plot(first["p"], first["identical_inputs"], "o", color="tab:red", label="x AND x")
        for name, curve in curves.items():
            ax.plot(
                curve["p"], curve["decorrelated_inputs"], "s", mfc="none", label=f"x AND {name}(x)"
            )
        ax.set_xlabel("input p-value $p$")
        ax.set_title(f"Squaring with an AND gate: {title}", fontsize=9)
    np.atleast_1d(axes)[0].set_ylabel("output p-value")
    np.atleast_1d(axes)[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=150)


def _plot_error(errors: dict[str, Any], path: Path) -> None:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8, 4.2))
    ax = fig.add_subplot()
    n = np.asarray(errors["n_bits"])
    ax.loglog(n, errors["binomial_limit"], "k--", label="binomial limit (independent inputs)")
    ax.loglog(n, errors["ideal_reshuffle_limit"], "k:", label="ideal reshuffle of x")
    ax.loglog(n, errors["independent_inputs"], "o-", label="independent inputs")
    ax.loglog(n, errors["identical_inputs"], "x-", label="identical inputs")
    for name, values in errors["decorrelated"].items():
        pts = [(ni, e) for ni, e in zip(n, values, strict=True) if e is not None]
        if pts:
            ax.loglog(*zip(*pts, strict=False), "s-", mfc="none", ms=4, label=name)
    ax.set_xlabel("stream length $N$ (bits)")
    ax.set_ylabel("RMS error of $p^2$")
    # beside the axes: inside, the legend would cover the curves of the short streams
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    fig.tight_layout()
    fig.savefig(path, dpi=150)


def _plot_comparison(rows: list[dict[str, Any]], path: Path) -> None:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11, 3.6))
    axes = fig.subplots(1, 4)
    names = [row["name"] for row in rows]
    pos = np.arange(len(rows))
    for ax, key, label in (
        (axes[0], "scc", "SCC(x, d(x))"),
        (axes[1], "squaring_rms_error", "RMS error of x AND d(x)"),
    ):
        for shift, kind in ((-0.2, "bernoulli"), (0.2, "telegraph")):
            ax.bar(pos + shift, [row[kind][key] for row in rows], width=0.4, label=kind)
        ax.set_ylabel(label)
    axes[0].axhline(0, color="k", lw=0.5)
    axes[0].legend(fontsize=7)
    latency = [row["latency_bits"] if row["latency_bits"] is not None else np.nan for row in rows]
    axes[2].bar(pos, latency, color="tab:gray")
    axes[2].set_ylabel("latency (clock cycles)")
    energy = [row["energy_per_bit_J"] for row in rows]
    axes[3].bar(pos, [e if e is not None else np.nan for e in energy], color="tab:green")
    for i, e in enumerate(energy):
        if e is None:
            # inside the axes, above the bottom spine, clear of the tick labels
            # upright inside the axes, from just above the bottom spine: clear of the axis
            # and of the tick labels whatever the number of bars
            axes[3].text(
                i,
                0.03,
                "no figure",
                rotation=90,
                ha="center",
                va="bottom",
                color="0.35",
                transform=axes[3].get_xaxis_transform(),
                fontsize=7,
            )
    axes[3].set_yscale("log")
    axes[3].set_ylabel("energy per bit (J)")
    for ax in axes:
        ax.set_xticks(pos, names, rotation=60, ha="right", fontsize=7)
        # every slot shown, also those whose bar is missing (autoscaling skips NaN bars)
        ax.set_xlim(-0.6, len(rows) - 0.4)
    fig.tight_layout()
    fig.savefig(path, dpi=150)


def run_demo(
    out_dir: str | Path,
    *,
    seed: int = 2024,
    n_bits: int = 4096,
    p: float = 0.6,
    correlation_bits: float = 16.0,
    decorrelators: Sequence[Decorrelator] | None = None,
) -> dict[str, Any]:
    """Run all demonstrations, write three PNG figures and ``sc_demo.json`` into ``out_dir``.

    Parameters
    ----------
    out_dir : str or Path
        Output directory (created if needed).
    seed : int
        Master seed; each experiment gets its own child seed via ``SeedSequence.spawn``.
    n_bits : int
        Stream length N for the squaring curve and the comparison (bits).
    p : float
        p-value squared in the error and comparison experiments.
    correlation_bits : float
        Correlation time of the telegraph input (clock cycles).
    decorrelators : sequence of Decorrelator, optional
        Decorrelators to compare (default :func:`default_decorrelators`).

    Returns
    -------
    dict
        The dictionary written to ``sc_demo.json``.
    """
    if decorrelators is None:
        decorrelators = default_decorrelators()
    items = _check_decorrelators(decorrelators)
    seed = v.positive_int(seed, "seed", minimum=0)
    n_bits = v.positive_int(n_bits, "n_bits", minimum=256)
    # the largest batch: 11 p-values × 16 trials of 8-byte random numbers, with three boolean
    # streams of the same shape (input, copy, AND)
    require_memory(
        "n_bits", n_bits, 11 * 16 * (8 + 3) * n_bits, "the streams", "use fewer bits (--n-bits)"
    )
    prob = float(v.probability(p, "p"))
    tau = v.positive_float(correlation_bits, "correlation_bits", "clock cycles")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    squaring_seed, error_seed, compare_seed = np.random.SeedSequence(seed).spawn(3)

    p_grid = np.linspace(0.0, 1.0, 11)
    squaring: dict[str, dict[str, Any]] = {"bernoulli input": {}, "telegraph input": {}}
    for d, child in zip(items, squaring_seed.spawn(len(items)), strict=True):
        bern_seed, tele_seed = child.spawn(2)
        squaring["bernoulli input"][d.name] = squaring_curve(d, p_grid, n_bits, seed=bern_seed)
        squaring["telegraph input"][d.name] = squaring_curve(
            d, p_grid, n_bits, correlation_bits=tau, seed=tele_seed
        )
    lengths = [2**k for k in range(6, 15)]
    errors = error_vs_length(lengths, items, p=prob, seed=error_seed)
    rows = compare_decorrelators(
        items, p=prob, n_bits=n_bits, correlation_bits=tau, seed=compare_seed
    )

    figures = {
        "squaring": "sc_and_squaring.png",
        "error_vs_length": "sc_error_vs_length.png",
        "decorrelators": "sc_decorrelators.png",
    }
    parameters = {
        "n_bits": n_bits,
        "p": prob,
        "telegraph_correlation_bits": tau,
        "squaring_p_grid": p_grid.tolist(),
        "error_lengths": lengths,
        "decorrelators": [d.describe() for d in items],
    }
    record = provenance(seed=seed, config_json=json.dumps(parameters, sort_keys=True, default=str))
    write_figure(out / figures["squaring"], lambda tmp: _plot_squaring(squaring, tmp), record)
    write_figure(out / figures["error_vs_length"], lambda tmp: _plot_error(errors, tmp), record)
    write_figure(out / figures["decorrelators"], lambda tmp: _plot_comparison(rows, tmp), record)

    summary = {
        "skygas_version": __version__,
        "seed": seed,
        "config_hash": record["config_hash"],
        "command": record["command"],
        "command_line": record["command_line"],
        "parameters": parameters,
        "figures": figures,
        "squaring": squaring,
        "error_vs_length": errors,
        "comparison": rows,
    }
    write_json(out / "sc_demo.json", summary)
    return summary
