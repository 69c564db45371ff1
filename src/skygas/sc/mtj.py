r"""Superparamagnetic magnetic tunnel junction (MTJ) as a tunable random-bit source.

A superparamagnetic MTJ has a free layer whose energy barrier :math:`E_b = \Delta\,k_B T` is
low enough that thermal fluctuations switch it between its parallel and antiparallel states;
a bias current tilts the barrier (paper, "Motivation", refs. on current-biased superparamagnetic
MTJs). We use the usual Néel-Brown form with a linear barrier lowering by the spin-transfer
current :math:`I`:

.. math::

    r_{0\to1}(I) = f_0\, e^{-\Delta (1 - I/I_c)}, \qquad
    r_{1\to0}(I) = f_0\, e^{-\Delta (1 + I/I_c)},

where state 1 is the state favoured by positive current. The stationary probability of
state 1 is a sigmoid in the current,

.. math::

    p(I) = \frac{r_{0\to1}}{r_{0\to1} + r_{1\to0}} = \frac{1}{1 + e^{-2\Delta I/I_c}},

and the resistance read once per clock period :math:`T` is random telegraph noise with
correlation time :math:`\tau = 1/[(r_{0\to1} + r_{1\to0})\,T]` clock cycles
(see :func:`skygas.sc.bitstreams.telegraph_stream`). The linear barrier lowering is only
meaningful for :math:`|I| < I_c`, which is enforced.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from skygas.core import validate as v
from skygas.core.errors import InputError
from skygas.sc.bitstreams import _refreshed_chain


@dataclass(frozen=True)
class SuperparamagneticMTJ:
    r"""A current-biased superparamagnetic MTJ read once per clock.

    Parameters
    ----------
    attempt_frequency_Hz : float
        Attempt frequency :math:`f_0` (Hz).
    barrier_kT : float
        Thermal stability factor :math:`\Delta = E_b/(k_B T)` (dimensionless).
    critical_current_A : float
        Critical switching current :math:`I_c` (A), > 0.
    clock_period_s : float
        Read-out period :math:`T` (s).
    """

    attempt_frequency_Hz: float
    barrier_kT: float
    critical_current_A: float
    clock_period_s: float

    def __post_init__(self) -> None:
        v.positive_float(self.attempt_frequency_Hz, "attempt_frequency_Hz", "Hz")
        v.positive_float(self.barrier_kT, "barrier_kT", "units of k_B T")
        v.positive_float(self.critical_current_A, "critical_current_A", "A")
        v.positive_float(self.clock_period_s, "clock_period_s", "s")

    def _current(self, current_A: Any) -> np.ndarray:
        current = np.asarray(current_A, dtype=float)
        if not np.all(np.isfinite(current)) or np.any(np.abs(current) >= self.critical_current_A):
            raise InputError(
                "current_A", current_A, f"currents with |I| < I_c = {self.critical_current_A} A"
            )
        return current

    def switching_rates(self, current_A: Any) -> tuple[np.ndarray, np.ndarray]:
        """Rates ``(r_0to1, r_1to0)`` in 1/s at bias current ``current_A`` (A)."""
        reduced = self._current(current_A) / self.critical_current_A
        f0, delta = self.attempt_frequency_Hz, self.barrier_kT
        return f0 * np.exp(-delta * (1.0 - reduced)), f0 * np.exp(-delta * (1.0 + reduced))

    def p_value(self, current_A: Any) -> np.ndarray:
        r"""Stationary probability of reading 1: :math:`1/(1 + e^{-2\Delta I/I_c})`."""
        reduced = self._current(current_A) / self.critical_current_A
        return 1.0 / (1.0 + np.exp(-2.0 * self.barrier_kT * reduced))

    def current_for(self, p: Any) -> np.ndarray:
        """Bias current (A) that gives p-value ``p`` in (0, 1): the inverse sigmoid."""
        prob = v.probability(p, "p")
        if np.any((prob <= 0.0) | (prob >= 1.0)):
            raise InputError("p", p, "a probability strictly between 0 and 1")
        current = self.critical_current_A * np.log(prob / (1.0 - prob)) / (2.0 * self.barrier_kT)
        return self._current(current)

    def correlation_bits(self, current_A: Any) -> np.ndarray:
        """Correlation time of the sampled signal, in clock cycles: 1/((r01 + r10) T)."""
        up, down = self.switching_rates(current_A)
        return 1.0 / ((up + down) * self.clock_period_s)

    def stream(
        self, current_A: Any, n_bits: int, *, shape: Any = (), seed: v.SeedLike = None
    ) -> np.ndarray:
        r"""Sampled MTJ state, boolean array of shape ``broadcast(shape, I.shape) + (n_bits,)``.

        Between reads the junction relaxes to its stationary state with probability
        :math:`1 - e^{-(r_{0\to1} + r_{1\to0})T}`, so successive bits are independent only
        when the clock is slow compared with the switching (``correlation_bits << 1``).
        """
        current = self._current(current_A)
        n_bits = v.positive_int(n_bits, "n_bits")
        lead = np.broadcast_shapes(v.leading_shape(shape), current.shape)
        rng = v.make_rng(seed)
        up, down = self.switching_rates(current)
        refresh = -np.expm1(-(up + down) * self.clock_period_s)
        prob = np.broadcast_to(self.p_value(current), lead)
        return _refreshed_chain(prob, np.broadcast_to(refresh, lead), lead + (n_bits,), rng)
