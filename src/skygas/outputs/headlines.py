"""What each command's report states first: the paper's quantities, with errors and units.

:func:`headline` gives, for a command and its summary, the rows of the report's headline block
(label, value as text) and any further tables of results (:class:`Results`). Every value is
written by :mod:`skygas.core.quantities`; a value that a run cannot give (None, NaN: too few
events, no transfer curve, a record too sparse for a diffusion constant) is written
``none (why)``, never as a number.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from skygas.core.quantities import format_quantity, format_value, label, missing

Row = tuple[str, str]
#: a table: its column names and its rows of text cells
Table = tuple[list[str], list[list[str]]]


@dataclass
class Results:
    """A report's results: the headline rows, notes under them, and titled tables."""

    rows: list[Row] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    tables: list[tuple[str, Table]] = field(default_factory=list)
    #: the summary keys the headline shows (left out of the report's table of every number)
    keys: set[str] = field(default_factory=set)

    def add(self, key: str, value: Any, error: Any = None, *, reason: str, name: str = "") -> None:
        """A row for quantity ``key``: its value, or ``none (reason)`` when it has none."""
        text = format_quantity(key, value, error)
        self.rows.append((name or label(key), none(reason) if text is None else text))
        self.keys.add(key)


def none(reason: str) -> str:
    """The text of an absent value: ``none (reason)``."""
    return f"none ({reason})"


def _get(summary: dict, key: str) -> Any:
    value = summary.get(key)
    return None if missing(value) else value


# -- the reshuffler ----------------------------------------------------------------------------
def signed(lag: float) -> str:
    """A lag as a reader writes it: ``−2``, ``3``, ``0`` (never ``−0`` nor ``+0``); ``−16.5``."""
    text = format_value(abs(lag), digits=3) or "?"
    return text if text == "0" or lag > 0 else f"−{text}"


def _pairs_at_lag(n_in: int, n_out: int, lag: int) -> int:
    """Pairs of input bit k and read-out k + ``lag`` (0 ≤ k < n_in, 0 ≤ k + lag < n_out)."""
    return max(0, min(n_in, n_out - lag) - max(0, -lag))


def _noise_of_largest(pairs: int, lags: int) -> float:
    """The |ρ| that independent streams exceed at one of ``lags`` lags in half of all runs.

    Each lag's ρ of ``pairs`` independent bit pairs is about normal with standard deviation
    1/√pairs, and the lags are nearly independent: the median of the largest of ``lags``
    such |ρ|.
    """
    from statistics import NormalDist

    return NormalDist().inv_cdf((1 + 0.5 ** (1 / lags)) / 2) / math.sqrt(pairs)


def _lag_rows(r: Results, s: dict, config: dict) -> None:
    """The lag scan's largest |ρ(ℓ)|, its pairs and the noise level, and what a lag means."""
    lag, rho = s.get("correlation_best_lag"), s.get("correlation_max_lag")
    n_in, n_out = s.get("n_injected"), s.get("n_detected")
    max_lag = (config.get("output") or {}).get("max_lag")
    if missing(rho) or lag is None or n_in is None or n_out is None or max_lag is None:
        return
    max_lag = min(int(max_lag), max(min(n_in, n_out) - 2, 0))
    pairs = _pairs_at_lag(n_in, n_out, int(lag))
    if max_lag < 1 or pairs < 2:
        return
    lags = 2 * max_lag + 1
    noise = format_value(_noise_of_largest(pairs, lags), digits=2)
    r.rows.append(
        (
            f"largest |ρ(ℓ)| over the lags ℓ = −{max_lag} … {max_lag}",
            f"ρ({signed(lag)}) = {format_value(rho, digits=3)} over {pairs} pairs; independent "
            f"streams reach {noise} at one of the {lags} lags in half of all runs",
        )
    )
    interval = format_value((config.get("injection") or {}).get("interval"), unit="s")
    r.notes.append(
        "ρ(ℓ) pairs the k-th bit injected with the (k+ℓ)-th bit read out: ℓ counts bits, one per "
        f"injection interval ({interval or 'not recorded'}), and ρ(0) is ρ above. A large "
        "|ρ(ℓ)| at ℓ ≠ 0 means the output still copies the input, shifted by |ℓ| bits: each "
        "skyrmion carries its bit across a chamber in its transit time, and skyrmions that "
        "overtake others shift the order of the read-outs. ℓ < 0: the m-th read-out carries "
        "the bit injected (m+|ℓ|)-th, |ℓ| skyrmions injected before it being still in a chamber; "
        "ℓ > 0: it carries the (m−ℓ)-th bit, ℓ skyrmions injected after it having overtaken it."
    )


def reshuffler(s: dict, config: dict | None = None) -> Results:
    """ρ (± jackknife error), p_in and p_out, energy per bit, transit time, the skyrmion count.

    With the run's ``config``, the lag scan too: the largest |ρ(ℓ)|, its pairs, the level noise
    alone reaches, and what a lag means.
    """
    r = Results()
    detected = s.get("n_detected", 0)
    too_few = f"{detected} skyrmion(s) read out: too few to pair with the input"
    r.add("correlation", s.get("correlation"), s.get("correlation_error"), reason=too_few)
    if not missing(s.get("correlation")) and missing(s.get("correlation_error")):
        label_, value = r.rows[-1]
        r.rows[-1] = (label_, f"{value} (too few read-outs for its error)")
    p_in = format_quantity("p_in", s.get("p_in"), digits=3)
    p_out = format_quantity("p_out", s.get("p_out"), digits=3)
    interval = s.get("p_out_interval")
    if p_out is not None and interval and not any(missing(x) for x in interval):
        p_out += f" (95 % interval {interval[0]:.3f} – {interval[1]:.3f})"
    r.rows.append(("input p-value p_in", p_in or none("no input bit yet")))
    r.rows.append(("output p-value p_out", p_out or none("no skyrmion read out yet")))
    r.keys |= {"p_in", "p_out", "p_out_interval"}
    r.add("energy_per_bit_J", s.get("energy_per_bit_J"), reason="no current recorded")
    r.add("power_W", s.get("power_W"), reason="no current recorded")
    r.add("mean_transit_s", s.get("mean_transit_s"), reason="no skyrmion has crossed yet")
    r.add("median_transit_s", s.get("median_transit_s"), reason="no skyrmion has crossed yet")
    counts = ("n_injected", "n_detected", "n_present", "n_annihilated")
    if all(k in s for k in counts):
        r.rows.append(
            (
                "skyrmions",
                f"{s['n_injected']} injected = {s['n_detected']} read out + {s['n_present']} "
                f"present + {s['n_annihilated']} annihilated",
            )
        )
        r.keys |= set(counts)
    r.add("max_occupancy", s.get("max_occupancy"), reason="not recorded")
    if "correlation_error" in s:
        r.notes.append(
            "ρ pairs the k-th bit injected with the k-th bit read out; its error is the "
            "delete-one-block jackknife over 20 blocks of those pairs."
        )
    if config is not None:
        _lag_rows(r, s, config)
        r.keys |= {"correlation_best_lag", "correlation_max_lag"}
    r.keys |= {"correlation_error"}
    return r


# -- the neuron --------------------------------------------------------------------------------
def neuron(s: dict) -> Results:
    """The output spike rate (± Poisson error), the input rate and the LIF fit."""
    r = Results()
    n = s.get("n_output_spikes")
    duration = _get(s, "simulated_time_s")
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


# -- the reservoir -----------------------------------------------------------------------------
def reservoir(s: dict) -> Results:
    """XOR, the mean of the 16 functions, the temporal tasks (68 % intervals), the energy.

    With the tables of ``report.md`` (:mod:`skygas.reservoir.report`).
    """
    from skygas.reservoir.report import accuracy_text, boolean_table, describe, temporal_table

    r = Results()
    xor = s.get("xor") or {}
    text = accuracy_text(xor) if xor.get("accuracy") is not None else None
    if text is not None:
        chance = format_value(xor["chance"], kind="percent")
        text += f" on {xor['n_test']} test inputs (chance {chance})"
    r.rows.append(("XOR test accuracy", text or none("no test input")))
    r.add("mean_accuracy", s.get("mean_accuracy"), reason="no test input")
    temporal = s.get("temporal") or {}
    for k, t in (temporal.get("recall") or {}).items():
        r.rows.append(
            (
                f"recall of input a, {k} input(s) back",
                accuracy_text(t) if t.get("accuracy") is not None else none("no test input"),
            )
        )
    if temporal.get("parity_last_two"):
        t = temporal["parity_last_two"]
        r.rows.append(
            (
                "parity of the last two inputs",
                accuracy_text(t) if t.get("accuracy") is not None else none("no test input"),
            )
        )
    r.add("energy_per_operation_J", s.get("energy_per_operation_J"), reason="no drive")
    r.keys |= {"xor", "accuracy", "temporal", "boolean"}
    if "device" in s and "boolean" in s:
        r.notes += describe(s)
        r.tables.append(("Boolean functions (test accuracy, 68 % interval)", boolean_table(s)))
        if temporal:
            r.tables.append(("Temporal tasks", temporal_table(s)))
    return r


def reservoir_sweep(sweep: dict) -> tuple[str, Table]:
    """The sweep's table (``sweep.json``), titled."""
    from skygas.reservoir.report import sweep_table

    return (
        f"Accuracy against {label(sweep['parameter'])} ({sweep['replicas']} replicas of "
        f"{sweep['n_inputs']} inputs)",
        sweep_table(sweep),
    )


# -- saturation --------------------------------------------------------------------------------
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


# -- simulate ----------------------------------------------------------------------------------
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


# -- a sweep -----------------------------------------------------------------------------------
def constrained(value: Any, error: Any) -> bool:
    """Whether a fitted ``value`` is fixed by the data: 0 < error < |value|, both finite.

    The sweep's figures draw a fit only where this holds for each of its coefficients.
    """
    if missing(value) or missing(error):
        return False
    return 0 < float(error) < abs(float(value))


def _paper_fit_text(fit: dict) -> str:
    """The paper's fit: c_A and c_B ± errors and its χ²/dof, or why it is not stated."""
    if not all(constrained(fit.get(c), fit.get(f"{c}_error")) for c in ("c_A", "c_B")):
        return none(
            "the points do not constrain it: a coefficient's error is zero (at its bound) or "
            "larger than the coefficient; not drawn"
        )
    a = format_value(fit.get("c_A"), fit.get("c_A_error"), digits=3)
    b = format_value(fit.get("c_B"), fit.get("c_B_error"), digits=3)
    text = f"c_A = {a}, c_B = {b}"
    chi2 = fit.get("chi2_dof")
    if chi2 is not None and not missing(chi2):
        from skygas.sweep.figures import MISSES

        judged = f"χ²/dof = {format_value(chi2, digits=3)}"
        text += f": misses the data ({judged})" if float(chi2) > MISSES else f" ({judged})"
    return text


def sweep(fits: dict) -> Results:
    """The scaling fits: the free exponent (β or γ) and the paper's fit, with errors.

    A fit is stated only where the points constrain it (:func:`constrained`), with its χ²/dof
    about the replica means (recorded by :func:`skygas.sweep.figures.plot_sweep`).
    """
    r = Results()
    for key, name, power, paper in (
        ("current", "beta", "Jᵝ", "paper_beta"),
        ("chamber", "gamma", "Lᵞ", "paper_gamma"),
    ):
        if key not in fits:
            continue
        f = fits[key]
        exponent = f.get(name) or {}
        n = exponent.get("n_points", 0)
        text = (
            format_value(exponent.get("exponent"), exponent.get("exponent_error"), digits=3)
            if constrained(exponent.get("exponent"), exponent.get("exponent_error"))
            else None
        )
        r.rows.append(
            (
                f"exponent of ρ/(1−ρ) ∝ {power}",
                none(f"{n} point(s) with 0 < ρ < 1: too few to fit")
                if text is None and n < 3
                else none("the points do not constrain it")
                if text is None
                else f"{text} over {n} points (paper: {f.get(paper):g})",
            )
        )
        model = "ρ = c_A/(c_B + (J/J₀)⁻¹·⁵)" if key == "current" else "ρ = c_A + c_B/√(L/1 µm)"
        r.rows.append((f"paper's fit {model}", _paper_fit_text(f.get("paper_fit") or {})))
    if "current" in fits:
        r.notes.append(
            "J₀ = 10¹¹ A/m²: the fits take the current density J in units of J₀, so that c_A "
            "and c_B are plain numbers."
        )
    if fits.keys() & {"current", "chamber"}:
        r.notes.append(
            "The paper argues β = 3/2 and γ = −1/2; docs/paper-reproduction.md compares them "
            "with what this model gives. A fit the points do not constrain is neither stated "
            "nor drawn."
        )
    if "note" in fits:
        r.notes.append(str(fits["note"]))
    return r


# -- the stochastic-computing demo -------------------------------------------------------------
def _scc(row: dict, signal: str) -> str:
    return format_value((row.get(signal) or {}).get("scc"), digits=2) or "none"


def _rms(row: dict, signal: str) -> str:
    return format_value((row.get(signal) or {}).get("squaring_rms_error"), digits=2) or "none"


def sc_demo(s: dict, reshuffler: dict | None = None) -> Results:
    """Each decorrelator's SCC and error of p² on Bernoulli and telegraph inputs."""
    r = Results()
    parameters = s.get("parameters") or {}
    r.add("n_bits", parameters.get("n_bits"), reason="not recorded")
    r.add("p", parameters.get("p"), reason="not recorded", name="p-value squared")
    rows = list(s.get("comparison") or [])
    if reshuffler:
        rows += [row for row in reshuffler.get("comparison") or [] if row not in rows]
    for row in rows:
        r.rows.append(
            (
                f"{row['name']}: SCC of x and its copy",
                f"{_scc(row, 'telegraph')} on a telegraph input, {_scc(row, 'bernoulli')} on a "
                "Bernoulli input",
            )
        )
    errors = s.get("error_vs_length") or {}
    if errors.get("n_bits"):
        n = errors["n_bits"][-1]
        r.rows.append(
            (
                f"RMS error of p² at N = {n} bits",
                f"{format_value(errors['identical_inputs'][-1], digits=2)} with identical inputs, "
                f"{format_value(errors['independent_inputs'][-1], digits=2)} with independent "
                f"ones (binomial limit {format_value(errors['binomial_limit'][-1], digits=2)})",
            )
        )
    header = [
        "decorrelator",
        "latency (bits)",
        "SCC, Bernoulli input",
        "SCC, telegraph input",
        "RMS error of p², Bernoulli",
        "RMS error of p², telegraph",
        "energy per bit",
    ]
    table = [
        [
            row["name"],
            format_value(row.get("latency_bits"), digits=3) or "none",
            _scc(row, "bernoulli"),
            _scc(row, "telegraph"),
            _rms(row, "bernoulli"),
            _rms(row, "telegraph"),
            format_value(row.get("energy_per_bit_J"), unit="J", digits=2)
            or none("no attributable figure"),
        ]
        for row in rows
    ]
    r.tables.append(("Decorrelators compared", (header, table)))
    sources: dict[str, list[str]] = {}
    for row in rows:
        if row.get("energy_per_bit_J") is not None and row.get("energy_source"):
            sources.setdefault(row["energy_source"], []).append(row["name"])
    r.notes += [f"Energy per bit of {', '.join(names)}: {src}." for src, names in sources.items()]
    r.keys |= {"parameters", "comparison", "error_vs_length", "squaring", "figures"}
    return r


# -- a micromagnetic fit -----------------------------------------------------------------------
def _law(fit: dict) -> str:
    """A fitted law's coefficients with their names (when recorded) and errors, and F₀."""
    names = fit.get("coefficient_names") or [
        f"coefficient {k + 1}" for k in range(len(fit["coefficients"]))
    ]
    values = ", ".join(
        f"{name} = {format_value(c, u, digits=4) or 'none'}"
        for name, c, u in zip(names, fit["coefficients"], fit["uncertainties"], strict=True)
    )
    lo, hi = fit["distance_range"]
    return (
        f"{values}; F₀ = {format_value(fit['force_scale_N'], unit='N')}; {fit['n_points']} "
        f"samples over d = {lo:.2f}–{hi:.2f} skyrmion diameters"
    )


def micromag_fit(s: dict) -> Results:
    """The fitted pair and wall laws, or why a law is not fixed; the measured skyrmion.

    Each law with its functional form and named coefficients ± errors (when recorded).
    """
    r = Results()
    unfixed = s.get("unfixed_laws") or {}
    for law in ("pair", "wall"):
        fit = s.get(f"{law}_law")
        if fit:
            form = fit.get("formula")
            name = f"{law} law" + (f" {form}" if form else " (coefficients, highest power first)")
            r.rows.append((name, _law(fit)))
        elif law in unfixed:
            r.rows.append((f"{law} law", none(unfixed[law]["reason"])))
    for law, table in (s.get("tables") or {}).items():
        lo, hi = table["distance_range"]
        r.rows.append(
            (
                f"{law} law tabulated",
                f"{table['n_samples']} samples in {len(table['rows'])} bins over d = "
                f"{lo:.2f}–{hi:.2f} skyrmion diameters",
            )
        )
        r.tables.append(
            (
                f"The {law} law tabulated over the measured distances",
                (
                    ["distance (skyrmion diameters)", "|F| (median)", "|F|/F₀", "samples"],
                    [
                        [
                            format_value(row["distance_diameters"], digits=3) or "none",
                            format_value(row["force_N"], unit="N", digits=3) or "none",
                            format_value(row["force_over_F0"], digits=3) or "none",
                            str(row["n_samples"]),
                        ]
                        for row in table["rows"]
                    ],
                ),
            )
        )
    thiele = s.get("thiele") or {}
    for key, name in (
        ("skyrmion_diameter_m", "skyrmion diameter d_sk"),
        ("measured_charge", "topological charge Q (measured)"),
        ("measured_dissipation", "dissipation 𝒟 (measured)"),
    ):
        text = format_quantity(key, thiele.get(key), digits=4)
        if text is not None:
            r.rows.append((name, text))
    if s.get("no_material_toml"):
        r.notes.append(f"No material.toml: {s['no_material_toml']}")
    r.notes += [f"Warning: {w}" for w in s.get("warnings") or []]
    r.keys |= {"pair_law", "wall_law", "unfixed_laws", "tables", "thiele", "tracks", "files"}
    r.keys |= {"material_toml", "no_material_toml", "warnings", "parameters"}
    return r
