"""The headline of ``skygas sc demo`` against what the streams must give, analytically.

- a delay isolator copies a telegraph stream k bits later: the SCC of two streams of equal p
  is their Pearson correlation, e^{-k/τ} for telegraph noise of correlation time τ, within
  four of its Bartlett standard errors (an AR(1) sequence with φ = e^{-1/τ});
- on Bernoulli input every decorrelator's copy is independent of x: |SCC| below 4/√N;
- squaring p with identical inputs (x AND x = x) is off by p − p² whatever N; with independent
  inputs the error reaches the binomial limit √(p²(1 − p²)/N), which the headline states.
"""

from __future__ import annotations

import json
import math
import re

import pytest
from tests.outputs.test_headlines_recomputed import headline

from skygas.cli import main


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    out = tmp_path_factory.mktemp("sc") / "demo"
    assert main(["sc", "demo", "--out", str(out)]) == 0
    return out, json.loads((out / "summary.json").read_text())


def _numbers(text: str) -> list[float]:
    return [
        float(x) for x in re.findall(r"[-+−]?\d+(?:\.\d+)?(?:e[-+]?\d+)?", text.replace("−", "-"))
    ]


def _bartlett(phi: float, k: int, n: int) -> float:
    """Standard error of the lag-k autocorrelation of an AR(1) sequence (Bartlett's formula)."""
    var = ((1 + phi**2) * (1 - phi ** (2 * k)) / (1 - phi**2) - 2 * k * phi ** (2 * k)) / n
    return math.sqrt(var)


def test_the_decorrelators_scc_is_what_the_streams_must_give(demo):
    out, summary = demo
    rows, _ = headline(out / "report.html")
    n = summary["parameters"]["n_bits"]
    tau = summary["parameters"]["telegraph_correlation_bits"]
    assert _numbers(rows["stream length N (bits)"]) == [n]
    for entry in summary["comparison"]:
        telegraph, bernoulli = _numbers(rows[f"{entry['name']}: SCC of x and its copy"])
        # what the headline states is the run's measurement, to its printed digits
        assert telegraph == pytest.approx(entry["telegraph"]["scc"], abs=0.006)
        assert bernoulli == pytest.approx(entry["bernoulli"]["scc"], abs=6e-4)
        assert abs(bernoulli) < 4 / math.sqrt(n)
        k = re.fullmatch(r"delay isolator \(k=(\d+)\)", entry["name"])
        if k:
            lag = int(k.group(1))
            phi = math.exp(-1 / tau)
            expected = phi**lag
            assert abs(telegraph - expected) < 4 * _bartlett(phi, lag, n), (lag, telegraph)
        else:  # a reshuffling decorrelator: less correlated than the delay of its own latency
            assert telegraph < math.exp(-entry["latency_bits"] / tau) + 4 * _bartlett(
                math.exp(-1 / tau), int(entry["latency_bits"]), n
            )


def test_the_squaring_error_is_p_minus_p_squared_or_the_binomial_limit(demo):
    out, summary = demo
    rows, _ = headline(out / "report.html")
    p = summary["parameters"]["p"]
    lengths = summary["error_vs_length"]["n_bits"]
    limits = summary["error_vs_length"]["binomial_limit"]
    for n, limit in zip(lengths, limits, strict=True):
        assert limit == pytest.approx(math.sqrt(p**2 * (1 - p**2) / n), rel=1e-12)
    label = f"RMS error of p² at N = {lengths[-1]} bits"
    identical, independent, stated_limit = _numbers(rows[label])[:3]
    assert identical == pytest.approx(p - p**2, abs=0.005)  # x AND x = x: p, not p²
    assert stated_limit == pytest.approx(math.sqrt(p**2 * (1 - p**2) / lengths[-1]), abs=5e-5)
    assert independent == pytest.approx(
        summary["error_vs_length"]["independent_inputs"][-1], abs=5e-5
    )
    # an RMS over the demo's 64 draws: its relative standard error is 1/√(2·64) ≈ 0.09
    assert abs(independent / stated_limit - 1) < 4 / math.sqrt(2 * 64)
