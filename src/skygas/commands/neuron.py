"""``skygas neuron`` and ``skygas saturation``: the Skyrmion Neuron and the maximum density.

``skygas neuron [CONFIG.toml] --out DIR [--json]``: run the Skyrmion Neuron, its transfer curve and
LIF fit; ``skygas saturation --diameters ... --out DIR [--json]``: the maximum density of skyrmions
in circular chambers.
"""

from __future__ import annotations

from pathlib import Path

from skygas.commands.json_output import add_json_option, print_json
from skygas.commands.run_options import (
    add_run_options,
    limits_from_flags,
    named_by_flags,
    run_options,
)
from skygas.core.errors import InputError
from skygas.outputs.flags import add_output_flags


def _neuron(args) -> int:
    from skygas.neuron.config import load_neuron_config
    from skygas.neuron.files import run_neuron_to_files
    from skygas.outputs.finish import finish_outputs, movie_record_interval

    with named_by_flags(args, {"seed": "seed", "duration": "duration"}):
        config = load_neuron_config(args.config, seed=args.seed, duration=args.duration)
    out = Path(args.out)
    with limits_from_flags(args, announce=not args.json):
        summary = run_neuron_to_files(
            config,
            out,
            transfer=not args.no_transfer,
            record_interval=movie_record_interval(args.animate),
            **run_options(args, progress=not args.json),
            then=lambda out: finish_outputs(out, animate=args.animate, report=not args.no_report),
        )
    lif = summary["lif_fit"]
    if args.json:
        print_json(summary)
    else:
        s = summary
        print(
            f"Skyrmion Neuron: {s['n_output_spikes']} output spikes in "
            f"{s['simulated_time_s'] * 1e6:.3g} µs (firing rate {s['firing_rate_Hz']:.3g} Hz, "
            f"input rate {s['input_rate_Hz']:.3g} Hz)\n"
            f"  {s['n_injected']} injected, {s['n_annihilated']} annihilated, "
            f"{s['n_emitted']} emitted; largest count {s['max_count']}, threshold "
            f"{s['threshold']:g}; leak time {s['leak_time_s']:.3g} s\n"
            f"  LIF fit: τ = {lif['tau_s']:.3g} s, θ = {lif['threshold']:g}, "
            f"V_r = {lif['reset']:g}; {lif['lif_spikes']} LIF spikes, "
            f"{_percent(lif['spike_match_fraction'])} of the device's matched, subthreshold "
            f"NRMSE {_number(lif['subthreshold_nrmse'])}, transfer R² "
            f"{_number(lif.get('transfer_r_squared'))}\nresults in {out.resolve()}"
        )
    return 0


def _percent(value) -> str:
    return "n/a" if value is None else f"{100 * value:.0f} %"


def _number(value) -> str:
    return "n/a" if value is None else f"{value:.2f}"


def _saturation(args) -> int:
    from skygas.neuron.files import run_saturation_to_files

    diameters = []
    for k, d in enumerate(args.diameters):
        try:
            diameters.append(float(d))
        except ValueError:
            raise InputError(
                f"diameters[{k}]", d, "a chamber diameter in metres (e.g. 1024e-9)"
            ) from None
    if args.repetitions < 1:
        raise InputError("repetitions", args.repetitions, "an integer >= 1")
    out = Path(args.out)
    with (
        named_by_flags(
            args, {name: name for name in ("repetitions", "seed", "relax_time", "temperature")}
        ),
        limits_from_flags(args, announce=not args.json),
    ):
        result = run_saturation_to_files(
            diameters,
            out,
            repetitions=args.repetitions,
            seed=args.seed,
            relax_time=args.relax_time,
            temperature=args.temperature,
            **run_options(args, progress=not args.json),
        )
    summary = result.summary()
    if not args.no_report:
        from skygas.outputs.report import write_report

        write_report(out, out / "report.html")
    if args.json:
        print_json(summary)
    else:
        for d, n, e, cp in zip(
            result.diameters,
            result.max_count,
            result.max_count_error,
            result.close_packing,
            strict=True,
        ):
            print(f"{d * 1e9:7.0f} nm: {n:6.1f} ± {e:.1f} skyrmions (close packing {cp:.0f})")
        print(f"results in {out.resolve()}")
    return 0


def register_neuron(subparsers, kind) -> None:
    """Add ``skygas neuron`` (the registry's ``kind``) to ``subparsers``."""
    p = subparsers.add_parser(kind.name, help=kind.help)
    p.add_argument("config", nargs="?", default=None, help="TOML configuration")
    p.add_argument("--out", required=True, help="output directory")
    add_json_option(p)
    p.add_argument("--seed", type=int, help="random seed")
    p.add_argument("--duration", type=float, help="simulated time [s]")
    p.add_argument("--no-transfer", action="store_true", help="skip the transfer curve")
    add_run_options(p)
    add_output_flags(p)
    p.set_defaults(func=_neuron)


def register_saturation(subparsers, kind) -> None:
    """Add ``skygas saturation`` (the registry's ``kind``) to ``subparsers``."""
    s = subparsers.add_parser(kind.name, help=kind.help)
    s.add_argument("--diameters", nargs="+", required=True, help="chamber diameters [m]")
    s.add_argument("--out", required=True, help="output directory")
    add_json_option(s)
    s.add_argument(
        "--repetitions",
        type=int,
        default=10,
        help="random fillings averaged for each chamber and count",
    )
    s.add_argument(
        "--relax-time", type=float, default=2e-9, help="relaxation time of each filling [s]"
    )
    s.add_argument("--temperature", type=float, default=300.0, help="temperature [K]")
    s.add_argument("--seed", type=int, default=0, help="random seed")
    add_run_options(s)
    s.add_argument("--no-report", action="store_true", help="do not write OUT/report.html")
    s.set_defaults(func=_saturation)
