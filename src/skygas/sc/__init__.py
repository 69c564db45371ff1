"""Stochastic computing: bitstreams, correlation metrics, gates, circuits and decorrelators.

The skyrmion reshuffler exists to make stochastic-computing circuits work (paper, section
"Motivation: Stochastic Computing"). This subpackage provides the circuit side: stream
generators, the metrics that say how correlated two streams are, gates that compute on whole
streams, and the CMOS decorrelators the reshuffler is measured against. See
``docs/stochastic-computing.md``.
"""

from skygas.sc.bitstreams import (
    LFSR_TAPS,
    bernoulli_stream,
    correlated_pair,
    lfsr_states,
    lfsr_stream,
    sobol_stream,
    telegraph_dwell_times,
    telegraph_stream,
)
from skygas.sc.circuit import Circuit
from skygas.sc.decorrelators import (
    Decorrelator,
    DecorrelatorResult,
    DelayIsolator,
    EnergyFigure,
    FootprintFigure,
    FunctionDecorrelator,
    Regenerator,
    ShuffleBuffer,
)
from skygas.sc.demo import (
    compare_decorrelators,
    default_decorrelators,
    error_vs_length,
    ideal_reshuffle_squaring_error,
    run_demo,
    squaring_curve,
)
from skygas.sc.gates import (
    and_,
    and_probability,
    c_element,
    jk_flip_flop,
    mux,
    not_,
    or_,
    or_probability,
    xor,
    xor_probability,
)
from skygas.sc.metrics import (
    PValueEstimate,
    autocorrelation,
    binomial_std,
    cross_correlation,
    p_value,
    p_value_interval,
    pearson,
    scc,
    zce,
)
from skygas.sc.mtj import SuperparamagneticMTJ

__all__ = [
    "LFSR_TAPS",
    "Circuit",
    "Decorrelator",
    "DecorrelatorResult",
    "DelayIsolator",
    "EnergyFigure",
    "FootprintFigure",
    "FunctionDecorrelator",
    "PValueEstimate",
    "Regenerator",
    "ShuffleBuffer",
    "SuperparamagneticMTJ",
    "and_",
    "and_probability",
    "autocorrelation",
    "bernoulli_stream",
    "binomial_std",
    "c_element",
    "compare_decorrelators",
    "correlated_pair",
    "cross_correlation",
    "default_decorrelators",
    "error_vs_length",
    "ideal_reshuffle_squaring_error",
    "jk_flip_flop",
    "lfsr_states",
    "lfsr_stream",
    "mux",
    "not_",
    "or_",
    "or_probability",
    "p_value",
    "p_value_interval",
    "pearson",
    "run_demo",
    "scc",
    "sobol_stream",
    "squaring_curve",
    "telegraph_dwell_times",
    "telegraph_stream",
    "xor",
    "xor_probability",
    "zce",
]
