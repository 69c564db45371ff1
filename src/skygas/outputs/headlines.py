"""What each command's report states first: the paper's quantities, with errors and units.

:func:`headline` gives, for a command and its summary, the rows of the report's headline block
(label, value as text) and any further tables of results (:class:`Results`). Every value is
written by :mod:`skygas.core.quantities`; a value that a run cannot give (None, NaN: too few
events, no transfer curve, a record too sparse for a diffusion constant) is written
``none (why)``, never as a number.
"""

from __future__ import annotations

from skygas.core.headline import Results as Results
from skygas.core.headline import Row as Row
from skygas.core.headline import Table as Table
from skygas.core.headline import constrained as constrained
from skygas.core.headline import none as none
from skygas.core.quantities import format_quantity, format_value, missing

# The devices' headlines live with their devices, and are named here too, beside the
# other commands' headlines, for the callers that read them from this module (explicit
# re-exports: ``import x as x``).
from skygas.neuron.headline import neuron as neuron
from skygas.neuron.headline import saturation as saturation
from skygas.reservoir.headline import reservoir as reservoir
from skygas.reshuffler.headline import reshuffler as reshuffler
from skygas.reshuffler.headline import signed as signed
from skygas.runs.headline import diffusion_rows as diffusion_rows
from skygas.runs.headline import simulation as simulation


# -- a sweep -----------------------------------------------------------------------------------
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
    if fits.get("points"):
        r.tables.append(point_table(fits["points"], fits.get("plotted", [])))
    if "note" in fits:
        r.notes.append(str(fits["note"]))
    return r


def point_table(points: list[dict], plotted: list[str]) -> tuple[str, Table]:
    """Each point of a sweep: its swept values, replicas, and the plotted quantities' means.

    ``points`` are :func:`skygas.sweep.generic.point_rows` (``name`` and ``name_sem`` per
    quantity); each mean is written with its standard error where there is one.
    """
    from skygas.core.quantities import label

    first = points[0]
    shown = set(plotted) | {f"{q}_sem" for q in plotted} | {"replicas"}
    swept = [k for k in first if k not in shown and k not in _quantity_columns(first)]
    header = [*swept, "replicas", *(label(q) for q in plotted)]
    rows = []
    for point in points:
        cells = [format_quantity(k, point[k]) or str(point[k]) for k in swept]
        cells.append(str(point["replicas"]))
        for q in plotted:
            text = format_quantity(q, point.get(q), point.get(f"{q}_sem"))
            cells.append(text if text is not None else "none")
        rows.append(cells)
    return "Replica means at each point (± standard error)", (header, rows)


def _quantity_columns(point: dict) -> set[str]:
    """The columns of a point row that are quantities (each has its ``_sem`` column)."""
    return {k for k in point if f"{k}_sem" in point} | {k for k in point if k.endswith("_sem")}


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
