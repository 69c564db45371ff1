"""What a ``skygas simulate`` run's report states first: the counts, D₀ and D_eff.

The diffusion rows are shared by every run that recorded positions (a neuron run recorded with
``--animate`` shows them too).
"""

from __future__ import annotations

from skygas.core.headline import Results, none
from skygas.core.quantities import format_value


def simulation(s: dict, analysis: dict | None) -> Results:
    """The skyrmion counts and, where the record supports them, D₀ and D_eff."""
    r = Results()
    for key in ("skyrmions_initial", "skyrmions_present", "exits", "wall_escapes"):
        if key in s:
            r.add(key, s[key], reason="not recorded")
    if analysis is not None:
        diffusion_rows(r, analysis)
    return r


def diffusion_rows(r: Results, analysis: dict) -> None:
    """D₀ and D_eff from :func:`skygas.analysis.analyze`, each with its reason when absent."""
    diffusion = analysis.get("diffusion")
    if not diffusion:
        r.rows.append(("diffusion constant", none("no positions recorded at even intervals")))
        return
    for key, name in (("short_time", "short-time D₀"), ("long_time", "long-time D_eff")):
        value = diffusion.get(f"{key}_diffusion_m2_s")
        reason = diffusion.get(f"{key}_reason") or diffusion.get("reason") or "not estimated"
        text = format_value(value, diffusion.get(f"{key}_diffusion_error_m2_s"), "m²/s")
        if text is not None and diffusion.get("drift_subtracted"):
            text += " (drift removed)"
        r.rows.append((name, text or none(reason)))
