"""``skygas reshuffle [CONFIG.toml] --out DIR [--json] [overrides]``: run the Skyrmion Reshuffler.

It prints a readable summary (or one JSON object). ``skygas demo [--out DIR]`` is the same
command with every default (what ``make demo`` runs): 100 µs of the paper's device, into
``demo-output`` unless ``--out`` says otherwise.
"""

from __future__ import annotations

import math
from pathlib import Path

from skygas.commands.json_output import add_json_option, print_json
from skygas.commands.run_options import (
    add_run_options,
    limits_from_flags,
    named_by_flags,
    run_options,
)
from skygas.outputs.flags import add_output_flags
from skygas.reshuffler.presets import PRESETS

# command-line option → configuration field it overrides
OVERRIDES = {
    "current_density": "current_density",
    "chamber_diameter": "device.chamber_diameter",
    "conduit_width": "device.conduit_width",
    "conduit_length": "device.conduit_length",
    "p": "signal.p",
    "correlation_time": "signal.correlation_time",
    "duration": "duration",
    "temperature": "temperature",
    "seed": "seed",
    "time_step": "time_step",
    "injection_interval": "injection.interval",
    "material": "material",
    "spin_drift_coefficient": "spin_drift_coefficient",
}


def _known(value) -> bool:
    """Whether a summary number is a number (not NaN, None or infinite)."""
    return isinstance(value, (int, float)) and math.isfinite(value)


def _format(summary: dict, out: Path) -> str:
    """The summary for a person: numbers the run cannot support yet are said to be absent."""
    s = summary
    correlation = (
        f"  correlation ρ = {s['correlation']:.4f} (largest |ρ| over lags: "
        f"{s['correlation_max_lag']:.4f} at lag {s['correlation_best_lag']}), "
        f"SCC = {s['scc']:.4f}"
        if _known(s["correlation"]) and _known(s["correlation_max_lag"]) and _known(s["scc"])
        else f"  correlation: none yet ({s['n_detected']} skyrmion(s) read out: too few to "
        "correlate the output with the input)"
    )
    transit = (
        f"mean transit {s['mean_transit_s'] * 1e9:.1f} ns"
        if _known(s["mean_transit_s"])
        else "no transit completed yet"
    )
    lines = [
        f"Skyrmion Reshuffler, J = {s['current_density_A_m2']:.3g} A/m², "
        f"chamber {s['chamber_diameter_m'] * 1e9:.0f} nm, T = {s['temperature_K']:g} K",
        f"  simulated {s['simulated_time_s'] * 1e6:.3g} µs in {s['wall_time_s']:.1f} s "
        f"(time step {s['time_step_s'] * 1e12:.3g} ps)",
        correlation,
        f"  p_in = {s['p_in']:.4f}, p_out = {s['p_out']:.4f} "
        f"(95 % interval {s['p_out_interval'][0]:.4f}–{s['p_out_interval'][1]:.4f})"
        if s["p_out_interval"]
        else f"  p_in = {s['p_in']:.4f}, no output yet",
        f"  skyrmions: {s['n_injected']} injected = {s['n_detected']} detected + "
        f"{s['n_present']} present + {s['n_annihilated']} annihilated; "
        f"{s['n_delayed']} delayed, {s['n_skipped']} skipped, {s['n_pending']} pending",
        f"  largest occupancy {s['max_occupancy']} per chamber, {transit}",
        f"  power {s['power_W'] * 1e6:.3g} µW, {s['energy_per_bit_J'] * 1e15:.3g} fJ per bit",
        f"results in {out.resolve()}",
    ]
    return "\n".join(lines)


def _reshuffle(args) -> int:
    # imported here: building the command line (every skygas call) imports no numerics
    from skygas.outputs.finish import finish_outputs, recording_overrides
    from skygas.reshuffler.config import load_reshuffler_config
    from skygas.reshuffler.files import run_reshuffler

    overrides = {field: getattr(args, opt) for opt, field in OVERRIDES.items()}
    overrides.update(recording_overrides(args.animate))
    # the sanity checks and the estimates name the option too
    with named_by_flags(args, OVERRIDES), limits_from_flags(args, announce=not args.json):
        config = load_reshuffler_config(args.config, preset=args.preset, overrides=overrides)
        result = run_reshuffler(
            config,
            args.out,
            **run_options(args, progress=not args.json),
            then=lambda out: finish_outputs(out, animate=args.animate, report=not args.no_report),
        )
    if args.json:
        print_json(result.summary)
    else:
        print(_format(result.summary, Path(args.out)))
    return 0


#: where ``skygas demo`` writes without ``--out`` (``make demo``'s folder too)
DEMO_OUT = "demo-output"


def register(subparsers) -> None:
    """Add ``skygas demo`` (the reshuffler with every default) to ``subparsers``."""
    d = subparsers.add_parser(
        "demo",
        help="run the Skyrmion Reshuffler with every default (what `make demo` runs)",
        description="The Skyrmion Reshuffler with its defaults, as `skygas reshuffle` without a\n"
        "configuration or overrides: 100 µs of the paper's device. The defaults pass --strict.",
    )
    d.add_argument("--out", default=DEMO_OUT, help="output directory")
    add_json_option(d)
    add_run_options(d)
    add_output_flags(d)
    d.set_defaults(func=_reshuffle, config=None, preset=None, **dict.fromkeys(OVERRIDES))


def register_kind(subparsers, kind) -> None:
    """Add ``skygas reshuffle`` (the registry's ``kind``) and its overrides to ``subparsers``."""
    p = subparsers.add_parser(kind.name, help=kind.help)
    p.add_argument(
        "config", nargs="?", default=None, help="TOML configuration (default: the chosen preset)"
    )
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument(
        "--preset",
        choices=PRESETS,
        default=None,
        help="start from a preset (the config file's values override it)",
    )
    add_json_option(p)
    add_run_options(p)
    add_output_flags(p)
    p.add_argument("--current-density", type=float, help="J in the conduits [A/m²]")
    p.add_argument("--chamber-diameter", type=float, help="chamber diameter [m]")
    p.add_argument("--conduit-width", type=float, help="conduit width [m]")
    p.add_argument("--conduit-length", type=float, help="conduit length [m]")
    p.add_argument("--p", type=float, help="p-value of the input signal")
    p.add_argument("--correlation-time", type=float, help="input correlation time [s]")
    p.add_argument("--duration", type=float, help="simulated time [s]")
    p.add_argument("--temperature", type=float, help="temperature [K]")
    p.add_argument("--seed", type=int, help="random seed")
    p.add_argument("--time-step", type=float, help="time step [s]")
    p.add_argument("--injection-interval", type=float, help="time between nucleations [s]")
    p.add_argument("--material", help="material preset name or TOML file")
    p.add_argument("--spin-drift-coefficient", type=float, help="ξ in v_s = ξ j [m³/C]")
    p.set_defaults(func=_reshuffle)
