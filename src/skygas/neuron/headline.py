"""What a neuron run's and a saturation curve's reports state first.

The neuron's output rate and LIF fit, and the saturation count of its chambers (``skygas
saturation``, :mod:`skygas.neuron.saturation`): their parts of the report
(:mod:`skygas.outputs.report`, through the device registry :mod:`skygas.devices.registry`).
"""

from __future__ import annotations

import math

from skygas.core.headline import Results, none, present
from skygas.core.quantities import format_quantity, format_value, label, missing


def neuron(s: dict) -> Results:
    """The output spike rate (± Poisson error), the input rate and the LIF fit."""
    r = Results()
    n = s.get("n_output_spikes")
    duration = present(s, "simulated_time_s")
    if n is not None and duration:
        if n > 0:
            rate = format_value(n / duration, math.sqrt(n) / duration, "Hz")
            text = f"{rate} ({n} output spikes in {format_value(duration, unit='s')})"
        else:
            text = f"0 Hz (no output spike in {format_value(duration, unit='s')})"
        r.rows.append((label("firing_rate_Hz"), text))
        r.keys |= {"firing_rate_Hz", "n_output_spikes"}
    r.add("input_rate_Hz", s.get("input_rate_Hz"), reason="no input")
    lif = s.get("lif_fit") or {}
    tau = format_quantity("tau_s", lif.get("tau_s"), lif.get("tau_error_s"))
    if tau is None:
        r.rows.append(("LIF fit", none("the trace has no leak to fit")))
    else:
        r.rows.append(
            (
                "LIF fit: membrane time τ, threshold θ, reset V_r",
                f"τ = {tau}, θ = {format_value(lif.get('threshold'))}, "
                f"V_r = {format_value(lif.get('reset'))}",
            )
        )
    curve = s.get("transfer_curve")
    r2 = lif.get("transfer_r_squared")
    if curve is None:
        r.rows.append(("transfer curve", none("not run: --no-transfer")))
    else:
        fit_text = format_value(r2, digits=3)
        points = len(curve.get("input_rate_Hz", []))
        if fit_text is None:
            fit_text = none("undefined: the device fired at the same rate at every input rate")
        else:
            fit_text += f" over {points} input rates"
            if r2 is not None and r2 < 0:
                fit_text += " (the LIF predicts it worse than its mean)"
        r.rows.append((label("transfer_r_squared"), fit_text))
    matched = format_quantity("spike_match_fraction", lif.get("spike_match_fraction"), digits=3)
    r.rows.append((label("spike_match_fraction"), matched or none("the device did not spike")))
    for key in ("n_injected", "n_annihilated", "n_emitted", "max_count"):
        if key in s:
            r.add(key, s[key], reason="not recorded")
    # shown above: the LIF's τ (the leak time), θ and V_r, the transfer R², the spikes matched
    r.keys |= {"leak_time_s", "threshold", "reset_level", "transfer_curve"}
    r.keys |= {f"lif_fit.{k}" for k in ("tau_s", "threshold", "reset", "transfer_r_squared")}
    r.keys |= {"lif_fit.spike_match_fraction", "lif_fit.predicted_Hz"}
    return r


def saturation(s: dict) -> Results:
    """N_sat (± standard error over the repetitions) per chamber diameter, and close packing."""
    r = Results()
    repetitions = (s.get("parameters") or {}).get("repetitions")
    rows = []
    for d, n, e, cp in zip(
        s.get("diameters_m", []),
        s.get("max_count", []),
        s.get("max_count_error", []),
        s.get("close_packing_estimate", []),
        strict=False,
    ):
        count = format_value(n, e, digits=3)
        if count is not None and (missing(e) or e == 0) and repetitions:
            count += f" (the same in all {repetitions} repetitions)"
        diameter = format_value(d, unit="m")
        packing = format_value(cp, digits=3)
        r.rows.append(
            (
                f"N_sat in a {diameter} chamber",
                none("no trial finished")
                if count is None
                else count + (f"; close packing {packing}" if packing else ""),
            )
        )
        rows.append([diameter or "?", count or "none", format_value(cp, digits=3) or "none"])
    r.keys |= {"diameters_m", "max_count", "max_count_error", "close_packing_estimate"}
    r.keys |= {"trial_counts", "survivors_mean"}
    r.notes.append(
        "N_sat: the most skyrmions that survive a relaxation in the chamber (mean ± standard "
        "error over the repetitions); close packing: the hexagonal packing estimate."
    )
    r.tables.append(
        ("Maximum number per diameter", (["chamber diameter", "N_sat", "close packing"], rows))
    )
    return r
