r"""Decorrelators: stream in, stream out, with latency and (where known) energy per bit.

A decorrelator re-times or re-generates a stream so that it keeps its p-value but loses its
correlation with the original (paper, "Motivation": a *stochastic reshuffler*). All of them
implement :class:`Decorrelator`:

``apply(stream, seed) -> DecorrelatorResult``
    Output of the same shape ``(..., N)`` as the input, on the same clock.
``latency_bits``
    Clock cycles between a bit entering and its information leaving (mean, for random designs).
``energy`` (:class:`EnergyFigure`)
    Energy per output bit in joules with its source, or ``None`` where no attributable figure
    exists.
``p_bias_bound(n_bits)``
    Bound on the p-value change the design may introduce, as stated in each class.

Register start-up convention
    Hardware registers start with whatever the circuit held before. To model a circuit in
    steady state without a transient, registers are pre-loaded with the *last* bits of the
    input, as if the stream had been running periodically. Output and input then have the
    same length and clock, so they can be fed to a gate together.

The skyrmion reshuffler plugs in through :class:`FunctionDecorrelator`, which wraps any
function mapping an input bit sequence to an output bit sequence and an energy per bit.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from skygas.core import validate as v
from skygas.core.errors import InputError

PAPER_CMOS_RESHUFFLER_SOURCE = (
    "order-of-magnitude estimate for CMOS reshufflers of clocked stochastic bitstreams "
    "(pseudo-random generator plus shift register or counter), paper section 'Skyrmion "
    "Reshuffler' (energy discussion), citing Tehrani et al. 2010 [tehrani2010relaxation]"
)
PAPER_SHIFT_REGISTER_SIZE_SOURCE = (
    "'a typical integrated shift-register has a linear size of ~10-100 um', paper section "
    "'Motivation: Stochastic Computing'"
)


@dataclass(frozen=True)
class EnergyFigure:
    """Energy per output bit (J) and where the number comes from; ``None`` when unknown."""

    joules_per_bit: float | None
    source: str

    @classmethod
    def unknown(cls) -> EnergyFigure:
        """No attributable figure (``joules_per_bit`` None)."""
        return cls(None, "unknown: no attributable figure")


@dataclass(frozen=True)
class FootprintFigure:
    """Linear size range of the circuit (m) and its source; ``None`` when unknown."""

    linear_size_m: tuple[float, float] | None
    source: str

    @classmethod
    def unknown(cls) -> FootprintFigure:
        """No attributable figure (``linear_size_m`` None)."""
        return cls(None, "unknown: no attributable figure")


@dataclass(frozen=True)
class DecorrelatorResult:
    """What :meth:`Decorrelator.apply` returns.

    Attributes
    ----------
    stream : numpy.ndarray
        Output bits, same shape as the input.
    latency_bits : float or None
        Latency in clock cycles (``None`` if unknown).
    energy_per_bit_J : float or None
        Energy per output bit (J), ``None`` if unknown.
    energy_source : str
        Where ``energy_per_bit_J`` comes from.
    """

    stream: np.ndarray
    latency_bits: float | None
    energy_per_bit_J: float | None
    energy_source: str


class Decorrelator(ABC):
    """Common interface of all decorrelators (see the module docstring)."""

    name: str = "decorrelator"
    energy: EnergyFigure = EnergyFigure.unknown()
    footprint: FootprintFigure = FootprintFigure.unknown()

    @property
    @abstractmethod
    def latency_bits(self) -> float | None:
        """Latency in clock cycles."""

    @abstractmethod
    def p_bias_bound(self, n_bits: int) -> float:
        """Bound on the p-value change for an N-bit stream (see each class for its kind)."""

    @abstractmethod
    def _apply(self, stream: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """Decorrelate a validated boolean stream of shape (..., N)."""

    def apply(self, stream: Any, seed: v.SeedLike = None) -> DecorrelatorResult:
        """Decorrelate ``stream`` (boolean, shape ``(..., N)``); ``seed`` drives any randomness."""
        stream = v.as_stream(stream, "stream")
        rng = v.make_rng(seed)
        out = self._apply(stream, rng)
        return DecorrelatorResult(
            out, self.latency_bits, self.energy.joules_per_bit, self.energy.source
        )

    def __call__(self, stream: Any, seed: v.SeedLike = None) -> np.ndarray:
        """Shortcut for ``apply(stream, seed).stream``."""
        return self.apply(stream, seed).stream

    def describe(self) -> dict[str, Any]:
        """Parameters and figures of merit as plain data (for result files)."""
        return {
            "name": self.name,
            "latency_bits": self.latency_bits,
            "energy_per_bit_J": self.energy.joules_per_bit,
            "energy_source": self.energy.source,
            "linear_size_m": self.footprint.linear_size_m,
            "footprint_source": self.footprint.source,
        }


class DelayIsolator(Decorrelator):
    r"""A chain of k D flip-flops: :math:`y_t = x_{t-k}` (registers pre-loaded, see module).

    The standard "isolator" of stochastic computing. It preserves the number of ones exactly
    (``p_bias_bound`` = 0) and decorrelates :math:`x_t` from :math:`y_t` only as far as
    :math:`x_t` and :math:`x_{t-k}` are independent: for telegraph noise with correlation time
    :math:`\tau` the Pearson correlation left is :math:`e^{-k/\tau}`, and the output keeps the
    input's autocorrelation. No attributable energy figure: ``energy`` is unknown.
    """

    def __init__(self, flip_flops: int = 1):
        self.flip_flops = v.positive_int(flip_flops, "flip_flops")
        self.name = f"delay isolator (k={self.flip_flops})"

    @property
    def latency_bits(self) -> float:
        """The latency: k clock cycles, one per flip-flop."""
        return float(self.flip_flops)

    def p_bias_bound(self, n_bits: int) -> float:
        """0: the delay preserves the number of ones exactly."""
        return 0.0

    def _apply(self, stream: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        if self.flip_flops >= stream.shape[-1]:
            raise InputError(
                "flip_flops",
                self.flip_flops,
                f"fewer flip-flops than stream bits ({stream.shape[-1]})",
            )
        return np.roll(stream, self.flip_flops, axis=-1)


class ShuffleBuffer(Decorrelator):
    r"""A buffer of D one-bit slots with random replacement.

    Each clock a slot :math:`s_t` is drawn uniformly from D; the bit held there is emitted and
    the incoming bit takes its place. A bit therefore stays a Geometric(1/D) number of clocks,
    mean D (``latency_bits``), and consecutive output bits come from unrelated input times,
    which also whitens an autocorrelated input. Ones are conserved except for the difference
    between the initial and final buffer contents, so :math:`|p_\text{out} - p_\text{in}| \le
    D/N` always (``p_bias_bound``). Energy: the paper's CMOS-reshuffler estimate,
    :math:`\sim 10` pJ/bit (PRNG plus register; source in ``energy.source``).
    """

    energy = EnergyFigure(10e-12, PAPER_CMOS_RESHUFFLER_SOURCE)
    footprint = FootprintFigure((10e-6, 100e-6), PAPER_SHIFT_REGISTER_SIZE_SOURCE)

    def __init__(self, depth: int = 16):
        self.depth = v.positive_int(depth, "depth")
        self.name = f"shuffle buffer (D={self.depth})"

    @property
    def latency_bits(self) -> float:
        """D clock cycles, the mean stay of a bit in the buffer."""
        return float(self.depth)

    def p_bias_bound(self, n_bits: int) -> float:
        """D/N: the initial and final buffer contents may differ."""
        return self.depth / n_bits

    def _apply(self, stream: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        n_bits = stream.shape[-1]
        if self.depth > n_bits:
            raise InputError("depth", self.depth, f"at most the stream length ({n_bits} bits)")
        lead = stream.shape[:-1]
        flat = stream.reshape(-1, n_bits)
        rows = flat.shape[0]
        slots = rng.integers(0, self.depth, size=(rows, n_bits))
        # Output at clock t is the input written at the previous clock t' < t that drew the same
        # slot; found for all t at once by a stable sort on (row, slot).
        key = (np.arange(rows)[:, None] * self.depth + slots).reshape(-1)
        order = np.argsort(key, kind="stable")
        sorted_key = key[order]
        previous = np.full(key.size, -1, dtype=np.int64)
        same = sorted_key[1:] == sorted_key[:-1]
        previous[order[1:][same]] = order[:-1][same]
        inputs = flat.reshape(-1)
        # Slots never written yet still hold the pre-loaded last D input bits.
        preload = flat[:, n_bits - self.depth :]
        initial = preload[np.repeat(np.arange(rows), n_bits), slots.reshape(-1)]
        out = np.where(previous >= 0, inputs[np.maximum(previous, 0)], initial)
        return out.reshape(lead + (n_bits,))


class Regenerator(Decorrelator):
    r"""Regeneration: count the ones of a window of W bits, then emit a fresh stream.

    Bits of window j are generated as Bernoulli(:math:`\hat p_{j-1}`) with an independent
    generator, where :math:`\hat p_{j-1}` is the fraction of ones in the previous W input bits
    (windows wrap around, see the module). Output and input are independent given the
    estimates, so for Bernoulli input the SCC goes to 0; the price is latency W (one window
    must be counted first) and extra sampling noise: the output p-value has variance about
    :math:`2p(1-p)/N` instead of :math:`p(1-p)/N`. ``p_bias_bound`` is a bound on
    :math:`|E[p_\text{out}] - p_\text{in}|`: 0 when W divides N, otherwise at most W/N.
    Energy: the paper's CMOS-reshuffler estimate, :math:`\sim 10` pJ/bit (PRNG plus counter).
    """

    energy = EnergyFigure(10e-12, PAPER_CMOS_RESHUFFLER_SOURCE)
    footprint = FootprintFigure((10e-6, 100e-6), PAPER_SHIFT_REGISTER_SIZE_SOURCE)

    def __init__(self, window: int = 64):
        self.window = v.positive_int(window, "window")
        self.name = f"regenerator (W={self.window})"

    @property
    def latency_bits(self) -> float:
        """W clock cycles: one window must be counted first."""
        return float(self.window)

    def p_bias_bound(self, n_bits: int) -> float:
        """Bound on |E[p_out] − p_in|: 0 when W divides N, else W/N."""
        return 0.0 if n_bits % self.window == 0 else self.window / n_bits

    def _apply(self, stream: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        n_bits = stream.shape[-1]
        w = self.window
        if w > n_bits:
            raise InputError("window", w, f"at most the stream length ({n_bits} bits)")
        # Cumulative counts over the stream preceded by its own tail (wrap-around pre-load).
        extended = np.concatenate([stream[..., n_bits - w :], stream], axis=-1)
        counts = np.concatenate(
            [np.zeros(stream.shape[:-1] + (1,), dtype=np.int64), np.cumsum(extended, axis=-1)],
            axis=-1,
        )
        block_start = (np.arange(n_bits) // w) * w  # input index where each bit's block starts
        # Window [block_start - w, block_start) of the input is [block_start, block_start + w)
        # of `extended`.
        estimate = (counts[..., block_start + w] - counts[..., block_start]) / w
        return rng.random(stream.shape) < estimate


class FunctionDecorrelator(Decorrelator):
    """Adapter turning a device model into a :class:`Decorrelator`.

    Parameters
    ----------
    name : str
        Label used in tables and figures.
    function : callable
        ``function(bits, rng) -> (out_bits, energy_per_bit_J)`` or
        ``-> (out_bits, energy_per_bit_J, latency_bits)``, where ``bits`` is a 1-D boolean
        array of N bits, ``out_bits`` has the same length and ``rng`` a NumPy generator. Use
        ``None`` for an unknown energy. Batched inputs are processed row by row.
    latency_bits : float, optional
        Latency (clock cycles) if known in advance; a latency returned by ``function`` (mean
        over rows) takes precedence in :meth:`apply`.
    energy_source : str
        Where the function's energy figure comes from (e.g. "current solve of the device").
    p_bias : callable, optional
        Bound on the p-value change, as a function of N (default: 0, exact conservation).
    """

    def __init__(
        self,
        name: str,
        function: Callable[..., tuple],
        *,
        latency_bits: float | None = None,
        energy_source: str = "returned by the device model",
        p_bias: Callable[[int], float] | None = None,
    ):
        if not callable(function):
            raise InputError("function", function, "a callable (bits, rng) -> (bits, energy)")
        self.name = str(name)
        self._function = function
        self._latency = latency_bits
        self._energy_source = energy_source
        self._p_bias = p_bias
        self.energy = EnergyFigure(None, energy_source)

    @property
    def latency_bits(self) -> float | None:
        """The latency given to the constructor (clock cycles; ``None`` if unknown)."""
        return self._latency

    def p_bias_bound(self, n_bits: int) -> float:
        """``p_bias(n_bits)`` if given, else 0 (exact conservation)."""
        return 0.0 if self._p_bias is None else float(self._p_bias(n_bits))

    def _run(self, stream: np.ndarray, rng: np.random.Generator):
        n_bits = stream.shape[-1]
        flat = stream.reshape(-1, n_bits)
        outputs, energies, latencies = [], [], []
        for row in flat:
            returned = self._function(row.copy(), rng)
            out_bits = np.asarray(returned[0])
            if out_bits.dtype != np.bool_ or out_bits.shape != (n_bits,):
                raise InputError(
                    f"{self.name} output",
                    f"array of dtype {out_bits.dtype} and shape {out_bits.shape}",
                    f"a boolean array of shape ({n_bits},)",
                )
            outputs.append(out_bits)
            energies.append(returned[1])
            if len(returned) > 2 and returned[2] is not None:
                latencies.append(float(returned[2]))
        known = [e for e in energies if e is not None]
        energy = float(np.mean(known)) if len(known) == len(energies) else None
        latency = float(np.mean(latencies)) if latencies else self._latency
        return np.stack(outputs).reshape(stream.shape), energy, latency

    def _apply(self, stream: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        return self._run(stream, rng)[0]

    def apply(self, stream: Any, seed: v.SeedLike = None) -> DecorrelatorResult:
        """Decorrelate ``stream`` row by row; energy and latency as the function returns them.

        The energy is the mean over rows (``None`` if any row's is unknown), the latency the mean of
        those returned, else the one given to the constructor.
        """
        stream = v.as_stream(stream, "stream")
        out, energy, latency = self._run(stream, v.make_rng(seed))
        return DecorrelatorResult(out, latency, energy, self._energy_source)
