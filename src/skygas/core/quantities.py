"""One table of the quantities skygas reports: a human label, a unit and how to write each.

Every report (HTML or Markdown) and every terminal summary names a number through this table,
so that a key such as ``energy_per_bit_J`` reads "energy per bit" with its value written
``9.62 fJ``. The rules of writing:

- counts are integers (``153``, never ``1.53e+02``);
- a value with an error is rounded to the error's first two significant digits:
  ``0.281 ± 0.046``;
- units with an SI prefix (s, m, J, W, Hz, V, A, N, K) take the prefix that puts the value
  between 1 and 1000 (``210 ns``, ``9.62 fJ``); other units (m²/s, A/m²) take a power of ten,
  typeset with superscript digits: ``4.38×10⁻⁹ m²/s``, never ``4.38e-09`` nor ``10^-9``;
- a missing value (None, NaN, ±inf) has no writing: :func:`format_value` returns None and the
  caller says why the number is absent.

A key not in :data:`QUANTITIES` still gets a label and a unit from its name: its SI suffix
(``_s``, ``_m2_s``, ``_A_m2``, ...) gives the unit and the rest, underscores as spaces, the
label (:func:`quantity`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

SUPERSCRIPT = str.maketrans("0123456789-+", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻⁺")
#: SI prefixes by power of ten
PREFIXES = {-18: "a", -15: "f", -12: "p", -9: "n", -6: "µ", -3: "m", 0: "", 3: "k", 6: "M", 9: "G"}
#: units that take an SI prefix rather than a power of ten
PREFIXED_UNITS = frozenset({"s", "m", "J", "W", "Hz", "V", "A", "N", "S", "Ω", "C"})


@dataclass(frozen=True)
class Quantity:
    """How one quantity is named and written.

    Parameters
    ----------
    label : str
        What a reader calls it ("energy per bit").
    unit : str
        Its SI unit as a reader writes it ("J", "m²/s"); "" for a pure number.
    kind : str
        ``"number"``, ``"count"`` (an integer), ``"percent"`` (a fraction written in %),
        ``"yes/no"`` or ``"text"``.
    """

    label: str
    unit: str = ""
    kind: str = "number"


def _q(label: str, unit: str = "", kind: str = "number") -> Quantity:
    return Quantity(label, unit, kind)


_COUNT = "count"

#: The quantities of the summaries and configurations, by key (the last part of a dotted key
#: is looked up when the whole key is not here).
QUANTITIES: dict[str, Quantity] = {
    # provenance and run bookkeeping
    "seed": _q("seed", kind=_COUNT),
    "skygas_version": _q("skygas version", kind="text"),
    "simulated_time_s": _q("simulated time", "s"),
    "time_step_s": _q("time step", "s"),
    "steps": _q("engine steps", kind=_COUNT),
    "wall_time_s": _q("wall-clock time", "s"),
    "wall_seconds": _q("wall-clock time", "s"),
    "cpu_seconds": _q("CPU time", "s"),
    "wall_escapes": _q("wall escapes (steps that would have crossed a wall)", kind=_COUNT),
    "pair_evaluations": _q("pair-force evaluations", kind=_COUNT),
    # the reshuffler
    "correlation": _q("input–output correlation ρ"),
    "correlation_max_lag": _q("largest |ρ| over the lags scanned"),
    "correlation_best_lag": _q("lag of the largest |ρ| (bits)", kind=_COUNT),
    "scc": _q("stochastic-computing correlation SCC"),
    "p_in": _q("input p-value p_in"),
    "p_in_injected": _q("p-value of the bits injected so far"),
    "p_out": _q("output p-value p_out"),
    "p_in_within_output_interval": _q("p_in inside the 95 % interval of p_out", kind="yes/no"),
    "n_events": _q("input bits", kind=_COUNT),
    "n_injected": _q("skyrmions injected", kind=_COUNT),
    "n_detected": _q("skyrmions read out", kind=_COUNT),
    "n_present": _q("skyrmions present at the end", kind=_COUNT),
    "n_annihilated": _q("skyrmions annihilated", kind=_COUNT),
    "n_skipped": _q("injections skipped (site occupied)", kind=_COUNT),
    "n_delayed": _q("injections delayed (site occupied)", kind=_COUNT),
    "n_pending": _q("injections still pending", kind=_COUNT),
    "counts_conserved": _q("every skyrmion accounted for", kind="yes/no"),
    "max_occupancy": _q("largest occupancy of a chamber", kind=_COUNT),
    "max_occupancy_up": _q("largest occupancy of the UP chamber", kind=_COUNT),
    "max_occupancy_down": _q("largest occupancy of the DOWN chamber", kind=_COUNT),
    "mean_transit_s": _q("mean transit time", "s"),
    "median_transit_s": _q("median transit time", "s"),
    "current_density_A_m2": _q("current density J in the conduits", "A/m²"),
    "spin_drift_coefficient_m3_C": _q("spin-drift coefficient", "m³/C"),
    "conduit_drift_velocity_m_s": _q("drift velocity in the conduits", "m/s"),
    "chamber_diameter_m": _q("chamber diameter", "m"),
    "temperature_K": _q("temperature", "K"),
    "dynamics_time_scale": _q("dynamics time scale"),
    "noise_scale": _q("noise scale"),
    "noise_temperature_K": _q("noise temperature", "K"),
    "free_diffusion_m2_s": _q("free diffusion constant D₀ (material, T)", "m²/s"),
    "total_current_A": _q("total current", "A"),
    "resistance_ohm": _q("resistance", "Ω"),
    "power_W": _q("electrical power", "W"),
    "energy_per_bit_J": _q("energy per bit", "J"),
    # the neuron
    "n_output_spikes": _q("output spikes", kind=_COUNT),
    "firing_rate_Hz": _q("output spike rate", "Hz"),
    "input_rate_Hz": _q("input rate", "Hz"),
    "injection_rate_Hz": _q("injection rate", "Hz"),
    "leak_time_s": _q("leak time", "s"),
    "threshold": _q("threshold"),
    "reset_level": _q("reset level"),
    "rule.threshold": _q("threshold θ (skyrmions)"),
    "rule.reset_level": _q("reset level V_r (skyrmions)"),
    "reset": _q("reset level V_r (skyrmions)"),
    "max_count": _q("largest count in the chamber", kind=_COUNT),
    "final_count": _q("count at the end", kind=_COUNT),
    "n_nucleated": _q("skyrmions nucleated", kind=_COUNT),
    "n_emitted": _q("skyrmions emitted", kind=_COUNT),
    "gate_max_force_N": _q("largest force of the gate", "N"),
    "tau_s": _q("membrane time τ", "s"),
    "release_time_s": _q("release time", "s"),
    "refractory_time_s": _q("refractory time", "s"),
    "lif_spikes": _q("spikes of the fitted LIF neuron", kind=_COUNT),
    "device_spikes": _q("spikes of the device", kind=_COUNT),
    "spike_count_ratio": _q("LIF spikes / device spikes"),
    "spike_match_fraction": _q("device spikes matched by the LIF", kind="percent"),
    "match_window_s": _q("spike match window", "s"),
    "trace_nrmse": _q("NRMSE of the count trace"),
    "subthreshold_nrmse": _q("NRMSE below threshold"),
    "subthreshold_nrmse_floor": _q("NRMSE floor below threshold"),
    "next_spike_error_median_s": _q("median error of the next spike time", "s"),
    "next_spike_match_fraction": _q("next spikes matched", kind="percent"),
    "transfer_r_squared": _q("transfer curve: R² of the LIF prediction"),
    # the reservoir
    "task": _q("task", kind="text"),
    "mean_accuracy": _q("mean accuracy of the 16 functions", kind="percent"),
    "accuracy": _q("test accuracy", kind="percent"),
    "chance": _q("chance level", kind="percent"),
    "hold_time_s": _q("hold time per input", "s"),
    "temporal_hold_time_s": _q("hold time per input (temporal tasks)", "s"),
    "n_skyrmions": _q("skyrmions", kind=_COUNT),
    "energy_per_operation_J": _q("energy per operation", "J"),
    "n_inputs": _q("inputs", kind=_COUNT),
    "streams": _q("input streams", kind=_COUNT),
    "n_train": _q("training inputs", kind=_COUNT),
    "n_test": _q("test inputs", kind=_COUNT),
    "margin_standard_errors": _q("margin over chance (standard errors)"),
    "diffusion_constant_m2_per_s": _q("free diffusion constant", "m²/s"),
    "chamber_area_m2": _q("chamber area", "m²"),
    "exploration_time_s": _q("time to explore the chamber", "s"),
    "unit_voltage_V": _q("drive voltage V₀", "V"),
    # saturation
    "diameters_m": _q("chamber diameters", "m"),
    "repetitions": _q("repetitions per point", kind=_COUNT),
    "relax_time_s": _q("relaxation time", "s"),
    "skyrmion_diameter_m": _q("skyrmion diameter", "m"),
    "base_rate_per_s": _q("annihilation base rate", "s⁻¹"),
    "check_interval_s": _q("annihilation check interval", "s"),
    "nucleation_rate_per_m2_s": _q("nucleation rate", "m⁻² s⁻¹"),
    "crowding_distance_m": _q("crowding distance", "m"),
    "collapse_distance_m": _q("collapse distance", "m"),
    # simulate
    "skyrmions_initial": _q("skyrmions at the start", kind=_COUNT),
    "skyrmions_present": _q("skyrmions at the end", kind=_COUNT),
    "exits": _q("skyrmions that left through a port", kind=_COUNT),
    # stochastic computing
    "n_bits": _q("stream length N (bits)", kind=_COUNT),
    "p": _q("p-value"),
    "telegraph_correlation_bits": _q("correlation time of the telegraph input (bits)"),
    "latency_bits": _q("latency (bits)"),
    "squaring_rms_error": _q("RMS error of p²"),
    "p_shift": _q("shift of the p-value"),
    # configuration fields (TOML keys, SI units)
    "material": _q("material", kind="text"),
    "film_thickness": _q("film thickness", "m"),
    "temperature": _q("temperature", "K"),
    "duration": _q("duration", "s"),
    "time_step": _q("time step", "s"),
    "record_interval": _q("record interval", "s"),
    "integrator": _q("integrator", kind="text"),
    "current_density": _q("current density", "A/m²"),
    "release_current_density": _q("release current density", "A/m²"),
    "spin_drift_coefficient": _q("spin-drift coefficient", "m³/C"),
    "chamber_diameter": _q("chamber diameter", "m"),
    "conduit_width": _q("conduit width", "m"),
    "conduit_length": _q("conduit length", "m"),
    "kind": _q("kind", kind="text"),
    "closed": _q("closed", kind="yes/no"),
    "random_count": _q("skyrmions placed at random", kind=_COUNT),
    "min_separation": _q("smallest separation (skyrmion diameters)"),
    "hold_time": _q("hold time per input", "s"),
    "shape": _q("shape", kind="text"),
    "size": _q("size", "m"),
    "contact_width": _q("contact width", "m"),
    "radius": _q("radius", "m"),
    "read_noise": _q("read noise"),
    "sample_interval": _q("sample interval", "s"),
    "read_interval": _q("read interval", "s"),
    "bins": _q("bins", kind=_COUNT),
    "levels": _q("input levels"),
    "conductor_thickness": _q("conductor thickness", "m"),
    "resistivity": _q("resistivity", "Ω·m"),
    "cell_size": _q("cell size", "m"),
    "model": _q("model", kind="text"),
    "regularization": _q("regularization"),
    "test_fraction": _q("test fraction", kind="percent"),
    "warmup_inputs": _q("warm-up inputs", kind=_COUNT),
    "temporal_inputs": _q("inputs of the temporal tasks", kind=_COUNT),
    "temporal_hold_time": _q("hold time per input (temporal tasks)", "s"),
    "temporal_sample_interval": _q("sample interval (temporal tasks)", "s"),
    "delays": _q("recall delays (inputs)"),
    "workers": _q("worker processes", kind=_COUNT),
    "parameter": _q("swept parameter", kind="text"),
    "values": _q("values"),
    "replicas": _q("replicas", kind=_COUNT),
    "barrier_height": _q("barrier height (k_BT)"),
    "band_width": _q("band width", "m"),
    "edge_width": _q("edge width", "m"),
    "initially_open": _q("open at the start", kind="yes/no"),
    "signal": _q("signal", kind="text"),
    "release_time": _q("release time", "s"),
    "refractory_time": _q("refractory time", "s"),
    "base_rate": _q("base rate", "s⁻¹"),
    "compression_sensitivity": _q("compression sensitivity"),
    "crowding_distance": _q("crowding distance", "m"),
    "collapse_distance": _q("collapse distance", "m"),
    "check_interval": _q("check interval", "s"),
    "nucleation_rate": _q("nucleation rate", "m⁻² s⁻¹"),
    "enabled": _q("enabled", kind="yes/no"),
    "rate": _q("rate", "Hz"),
    "interval": _q("interval", "s"),
    "correlation_time": _q("correlation time", "s"),
    "weight": _q("weight"),
    "bits": _q("bits"),
    "occupied_rule": _q("rule for an occupied site", kind="text"),
    "site_clearance": _q("site clearance (skyrmion diameters)"),
    "retry_interval": _q("retry interval", "s"),
    "snapshot_interval": _q("snapshot interval", "s"),
    "chamber_gap": _q("gap between the chambers", "m"),
    "trajectory_window": _q("time span of the trajectories drawn", "s"),
    "max_pending": _q("most injections pending", kind=_COUNT),
    "spin_polarization": _q("spin polarization"),
    "path": _q("input file", kind="text"),
    "isi.n": _q("inter-spike intervals", kind=_COUNT),
    "isi.mean_s": _q("mean inter-spike interval", "s"),
    "isi.std_s": _q("standard deviation of the inter-spike interval", "s"),
    "isi.cv": _q("coefficient of variation of the inter-spike interval"),
    "max_lag": _q("largest lag scanned (bits)", kind=_COUNT),
    "running_points": _q("points of the running correlation", kind=_COUNT),
    "dissipation": _q("dissipation tensor 𝒟"),
    "force_scale": _q("force scale F₀", "N"),
    "skyrmion_diameter": _q("skyrmion diameter", "m"),
    "eta": _q("η"),
    "mu": _q("μ"),
    "pair_law": _q("pair law", kind="text"),
    "wall_law": _q("wall law", kind="text"),
    "cutoff_fraction": _q("force cut-off (fraction of the largest)"),
    "external_force": _q("external force", "N"),
    "velocity": _q("velocity", "m/s"),
    "center": _q("centre", "m"),
    "centers": _q("centres", "m"),
}

#: SI suffixes of keys, longest first: suffix → unit (for keys not in :data:`QUANTITIES`)
SUFFIX_UNITS: tuple[tuple[str, str], ...] = (
    ("_per_m2_s", "m⁻² s⁻¹"),
    ("_m2_per_s", "m²/s"),
    ("_A_per_m2", "A/m²"),
    ("_m2_s", "m²/s"),
    ("_A_m2", "A/m²"),
    ("_m3_C", "m³/C"),
    ("_m_s", "m/s"),
    ("_per_s", "s⁻¹"),
    ("_m2", "m²"),
    ("_Hz", "Hz"),
    ("_rad", "rad"),
    ("_ohm", "Ω"),
    ("_s", "s"),
    ("_m", "m"),
    ("_J", "J"),
    ("_W", "W"),
    ("_K", "K"),
    ("_V", "V"),
    ("_A", "A"),
    ("_N", "N"),
    ("_S", "S"),
    ("_C", "C"),
)


def humanize(name: str) -> str:
    """A snake_case name as words: ``n_output_spikes`` → "number of output spikes"."""
    words = name.replace("_", " ").strip()
    if words.startswith("n "):
        words = "number of " + words[2:]
    return words


def quantity(key: str) -> Quantity:
    """The :class:`Quantity` of ``key`` (a summary key or a dotted configuration key).

    The whole key, then its last part, is looked up in :data:`QUANTITIES`; otherwise the label
    and unit come from the name (:data:`SUFFIX_UNITS`, :func:`humanize`).
    """
    last = key.rsplit(".", 1)[-1]
    found = QUANTITIES.get(key) or QUANTITIES.get(last)
    if found is not None:
        return found
    for suffix, unit in SUFFIX_UNITS:
        if last.endswith(suffix) and len(last) > len(suffix):
            return Quantity(humanize(last[: -len(suffix)]), unit)
    kind = _COUNT if last.startswith("n_") else "number"
    return Quantity(humanize(last), "", kind)


def label(key: str) -> str:
    """The label of ``key`` with its unit in brackets when it has one: "energy per bit"."""
    return quantity(key).label


def missing(value: Any) -> bool:
    """Whether ``value`` is no number to show: None, NaN or ±inf."""
    if value is None:
        return True
    if isinstance(value, float) and not math.isfinite(value):
        return True
    return False


def power_of_ten(exponent: int) -> str:
    """``×10`` with ``exponent`` in superscript digits: ``×10⁻⁸``."""
    return "×10" + str(exponent).translate(SUPERSCRIPT)


def _exponent(x: float) -> int:
    return math.floor(math.log10(abs(x))) if x else 0


def _strip(text: str) -> str:
    """Trailing zeros of a decimal fraction off: 3.500 → 3.5, 2.0 → 2."""
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return text


def _plain(x: float, digits: int) -> str:
    """``x`` to ``digits`` significant digits in positional notation (no exponent)."""
    decimals = max(0, digits - 1 - _exponent(x))
    return _strip(f"{x:.{decimals}f}")


def _with_unit(text: str, unit: str) -> str:
    return f"{text} {unit}" if unit else text


def format_value(
    value: Any,
    error: Any = None,
    unit: str = "",
    *,
    kind: str = "number",
    digits: int = 4,
) -> str | None:
    """``value`` (± ``error``) in ``unit`` as a reader writes it; None for a missing value.

    Parameters
    ----------
    value : number, bool or str
        In SI units (a fraction for ``kind="percent"``).
    error : float, optional
        Its standard error (ignored when missing or not positive).
    unit : str
        The SI unit; an SI prefix is chosen for the units of :data:`PREFIXED_UNITS`.
    kind : str
        As :attr:`Quantity.kind`.
    digits : int
        Significant digits of a value without an error.

    Returns
    -------
    str or None
        E.g. ``"0.281 ± 0.046"``, ``"210 ns"``, ``"(4.38 ± 0.12)×10⁻⁹ m²/s"``, ``"153"``.
    """
    if missing(value):
        return None
    if isinstance(value, bool) or kind == "yes/no":
        return "yes" if value else "no"
    if isinstance(value, str) or kind == "text":
        return str(value)
    if isinstance(value, (list, tuple)):
        parts = [format_value(v, unit=unit, kind=kind, digits=digits) for v in value]
        if not parts or any(p is None for p in parts):
            return None
        return ", ".join(p for p in parts if p is not None)
    value = float(value)
    if kind == "count" and error is None:
        return _with_unit(f"{int(round(value))}", unit)
    if kind == "percent":
        value, unit = 100.0 * value, "%"
        error = None if missing(error) else 100.0 * float(error)
    if missing(error) or float(error) <= 0:
        error = None
    else:
        error = float(error)
    scale_exponent = 0
    prefix = ""
    reference = value if value else (error or 0.0)
    exponent = _exponent(reference)
    if unit in PREFIXED_UNITS and reference:
        scale_exponent = max(-18, min(9, 3 * math.floor(exponent / 3)))
        prefix = PREFIXES[scale_exponent]
    elif not -3 <= exponent < 5:
        scale_exponent = exponent
    scale = 10.0**scale_exponent
    v = value / scale
    shown_unit = prefix + unit if prefix or unit in PREFIXED_UNITS else unit
    power = power_of_ten(scale_exponent) if scale_exponent and not prefix else ""
    if error is None:
        text = _plain(v, digits)
        return _with_unit(f"{text}{power}", shown_unit)
    e = error / scale
    decimals = max(0, 1 - _exponent(e))
    text = f"{v:.{decimals}f} ± {e:.{decimals}f}"
    if power:
        text = f"({text}){power}"
    return _with_unit(text, shown_unit)


def format_quantity(key: str, value: Any, error: Any = None, **options: Any) -> str | None:
    """``value`` of quantity ``key`` written with its unit and kind (:func:`format_value`)."""
    q = quantity(key)
    return format_value(value, error, q.unit, kind=q.kind, **options)
