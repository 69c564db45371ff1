"""What a reshuffler run's report states first: ρ, the p-values, the energy, the lag scan.

The reshuffler's part of the report (:mod:`skygas.outputs.report`, through the device registry
:mod:`skygas.devices.registry`), next to the device it describes.
"""

from __future__ import annotations

import math

from skygas.core.headline import Results, none
from skygas.core.quantities import format_quantity, format_value, missing


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
