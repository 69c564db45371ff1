r"""Input signals of the skyrmion reshuffler, sampled at the injection clock.

The reshuffler nucleates one skyrmion every injection interval :math:`\Delta` (paper, section
"Skyrmion Reshuffler": :math:`r_\mathrm{inj} = 0.2` per ns, :math:`\Delta = 5` ns) into the UP
chamber if the input signal is 1 at that instant and into the DOWN chamber otherwise. The input
is therefore a bit sequence :math:`b_k`, one bit per injection event :math:`k = 0, 1, \dots`, at
times :math:`t_k = k\Delta` (:func:`injection_times`). Three sources are offered:

``"telegraph"``
    Random telegraph noise, the paper's input: a stationary continuous-time two-state Markov
    process with :math:`P(1) = p` and autocorrelation :math:`e^{-t/\tau_c}`. Its switching
    rates are :math:`r_{0\to1} = p/\tau_c` and :math:`r_{1\to0} = (1-p)/\tau_c`, so the dwell
    times are exponential with means :math:`\tau_c/(1-p)` in state 1 and :math:`\tau_c/p` in
    state 0. Sampled at the clock it is *exactly* the two-state Markov chain with

    .. math::

        P(1 \to 1) = p + (1-p)\,\lambda, \qquad P(0 \to 0) = (1-p) + p\,\lambda,
        \qquad \lambda = e^{-\Delta/\tau_c},

    started from the stationary distribution, so the lag-:math:`j` autocorrelation of
    :math:`b_k` is :math:`\lambda^j`. The sampling is delegated to
    :func:`skygas.sc.bitstreams.telegraph_stream` with ``correlation_bits`` =
    :math:`\tau_c/\Delta` (that function counts time in clock cycles).
``"bernoulli"``
    Independent Bernoulli(:math:`p`) bits at the clock, the :math:`\tau_c \to 0` limit
    (:func:`skygas.sc.bitstreams.bernoulli_stream`).
``"file"``
    Bits read from a user file: ``.npy`` (a 1-D array of 0/1 or booleans) or text (``.csv``,
    ``.txt``): 0/1 values separated by commas, whitespace or new lines. Lines starting with
    ``#`` are comments.

The paper does not give the telegraph signal's correlation time (docs/physics.md §4). The default,
:data:`DEFAULT_CORRELATION_TIME` = 5 ns, equals one injection interval, so consecutive injected
bits are correlated by :math:`e^{-1} \approx 0.37`; set ``correlation_time`` to study others.
Units at this public edge are SI (seconds); only the ratio :math:`\tau_c/\Delta` enters.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np

from skygas.core import validate as v
from skygas.core.errors import InputError
from skygas.sc.bitstreams import bernoulli_stream, telegraph_stream

#: Time between injections [s] (paper: 0.2 nucleations per ns).
DEFAULT_INJECTION_INTERVAL = 5e-9
#: Default correlation time of the telegraph input [s]; not given by the paper (see above).
DEFAULT_CORRELATION_TIME = 5e-9

SignalKind = Literal["telegraph", "bernoulli", "file"]
_KINDS = ("telegraph", "bernoulli", "file")
_TEXT_SUFFIXES = (".csv", ".txt")


@dataclass(frozen=True)
class SignalSpec:
    r"""What drives the reshuffler's injector; validated on construction.

    Parameters
    ----------
    kind : {"telegraph", "bernoulli", "file"}
        ``"telegraph"``, ``"bernoulli"`` or ``"file"`` (see the module docstring).
    p : float
        p-value, the stationary probability of a 1. ``"telegraph"``: strictly between 0 and 1
        (a constant signal has no dwell times); ``"bernoulli"``: in [0, 1]; unused for files.
    correlation_time : float
        Telegraph correlation time :math:`\tau_c` [s], > 0. Unused by the other kinds.
    path : str or Path, optional
        The bit file for ``"file"`` (``.npy``, ``.csv`` or ``.txt``).
    """

    kind: SignalKind = "telegraph"
    p: float = 0.5
    correlation_time: float = DEFAULT_CORRELATION_TIME
    path: str | Path | None = None

    def __post_init__(self) -> None:
        if self.kind not in _KINDS:
            raise InputError("kind", self.kind, f"one of {', '.join(map(repr, _KINDS))}")
        if self.kind == "file":
            if self.path is None or str(self.path) == "":
                raise InputError("path", self.path, "a .npy, .csv or .txt file of 0/1 bits")
            return
        p = _number(self.p, "p", "a number in [0, 1]")
        if self.kind == "telegraph" and not 0.0 < p < 1.0:
            raise InputError(
                "p",
                self.p,
                "a number strictly between 0 and 1 for a telegraph "
                "signal (use kind = 'bernoulli' for a constant one)",
            )
        if not 0.0 <= p <= 1.0:
            raise InputError("p", self.p, "a number in [0, 1]")
        if self.kind == "telegraph":
            v.positive_float(self.correlation_time, "correlation_time", "seconds")


def _number(value: Any, field: str, allowed: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise InputError(field, value, allowed)
    number = float(value)
    if not math.isfinite(number):
        raise InputError(field, value, allowed)
    return number


def injection_times(
    n_events: int, injection_interval: float = DEFAULT_INJECTION_INTERVAL, start: float = 0.0
) -> np.ndarray:
    r"""Times :math:`t_k = t_0 + k\Delta` [s] of the injection events ``k = 0 .. n_events-1``."""
    n_events = v.positive_int(n_events, "n_events")
    interval = v.positive_float(injection_interval, "injection_interval", "seconds")
    start = _number(start, "start", "a finite number (seconds)")
    return start + interval * np.arange(n_events)


def generate_bits(
    spec: SignalSpec,
    n_events: int | None,
    injection_interval: float = DEFAULT_INJECTION_INTERVAL,
    seed: v.SeedLike = None,
) -> np.ndarray:
    r"""The input bits :math:`b_k`, one per injection event, as a boolean array.

    Parameters
    ----------
    spec : SignalSpec
        The signal source.
    n_events : int or None
        Number of injection events. For ``"file"`` it may be ``None`` (all bits of the file);
        otherwise the first ``n_events`` bits are used and the file must hold at least that many.
    injection_interval : float
        :math:`\Delta` [s], > 0; only the telegraph signal depends on it (through
        :math:`\tau_c/\Delta`).
    seed : int, SeedSequence, Generator or None
        int, ``numpy.random.SeedSequence``, ``numpy.random.Generator`` or ``None``.
    """
    if not isinstance(spec, SignalSpec):
        raise InputError("spec", spec, "a skygas.sc.signals.SignalSpec")
    interval = v.positive_float(injection_interval, "injection_interval", "seconds")
    if spec.kind == "file":
        assert spec.path is not None  # SignalSpec requires a path for a file
        bits = read_bits(spec.path)
        if n_events is None:
            return bits
        n_events = v.positive_int(n_events, "n_events")
        if n_events > bits.size:
            raise InputError(
                "n_events", n_events, f"at most {bits.size}, the number of bits in {spec.path}"
            )
        return bits[:n_events]
    n_events = v.positive_int(n_events, "n_events")
    rng = v.make_rng(seed)
    if spec.kind == "bernoulli":
        return bernoulli_stream(spec.p, n_events, seed=rng)
    return telegraph_stream(spec.p, spec.correlation_time / interval, n_events, seed=rng)


def as_bits(values: Any, field: str = "bits") -> np.ndarray:
    """Return a 1-D sequence of 0/1 (or booleans) as a boolean array with at least one bit.

    Unlike a plain ``astype(bool)`` this refuses any value other than 0 and 1 (a 2 or a -1
    is a user error, not a 1).
    """
    try:
        array = np.asarray(values)
    except (TypeError, ValueError):
        raise InputError(field, values, "a 1-D sequence of 0/1 bits") from None
    if array.ndim != 1:
        raise InputError(field, f"array of shape {array.shape}", "a 1-D sequence of 0/1 bits")
    if array.size == 0:
        raise InputError(field, "an empty sequence", "at least one bit")
    if array.dtype == np.bool_:
        return array
    if not (np.issubdtype(array.dtype, np.integer) or np.issubdtype(array.dtype, np.floating)):
        raise InputError(field, f"array of dtype {array.dtype}", "0/1 bits (integers or booleans)")
    bad = np.flatnonzero((array != 0) & (array != 1))
    if bad.size:
        raise InputError(f"{field}[{bad[0]}]", array[bad[0]].item(), "0 or 1")
    return array == 1


def read_bits(path: str | Path) -> np.ndarray:
    """Read a bit file (``.npy``, ``.csv`` or ``.txt``) into a boolean array.

    Text files hold 0/1 values separated by commas, whitespace or new lines (``1.0``/``0.0``,
    as ``numpy.savetxt`` writes them, are accepted); ``#`` starts a comment line. Any other
    value raises :class:`InputError` naming ``path`` with the line and the value.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError("path", str(path), "an existing .npy, .csv or .txt file of 0/1 bits")
    suffix = path.suffix.lower()
    if suffix == ".npy":
        try:
            array = np.load(path, allow_pickle=False)
        except (ValueError, OSError, EOFError) as err:
            why = str(err) or "the file is empty"
            raise InputError(
                "path",
                str(path),
                f"a readable .npy file of 0/1 bits (this one is empty, truncated or damaged: "
                f"{why})",
                "write the bits again, e.g. with numpy.save",
            ) from None
        try:
            return as_bits(
                np.ravel(array) if array.ndim == 2 and 1 in array.shape else array, "path"
            )
        except InputError as err:
            raise InputError("path", f"{path}: {err.field} = {err.value!r}", err.allowed) from None
    if suffix not in _TEXT_SUFFIXES:
        raise InputError("path", str(path), "a file ending in .npy, .csv or .txt")
    bits: list[bool] = []
    try:
        text = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError as err:
        raise InputError(
            "path",
            str(path),
            f"a text file of 0/1 bits (this one is binary or not UTF-8: byte {err.start})",
            "give a .csv or .txt file of 0 and 1, or a .npy array",
        ) from None
    for line_number, line in enumerate(text.splitlines(), start=1):
        if line.lstrip().startswith("#"):
            continue
        for token in line.replace(",", " ").split():
            if token in ("0", "1"):
                bits.append(token == "1")
                continue
            try:
                number = float(token)
            except ValueError:
                number = math.nan
            if number not in (0.0, 1.0):
                raise InputError("path", f"{path} line {line_number}: {token!r}", "only 0 or 1")
            bits.append(number == 1.0)
    if not bits:
        raise InputError("path", str(path), "a file holding at least one bit")
    return np.array(bits, dtype=bool)


def write_bits(path: str | Path, bits: Any) -> Path:
    """Write bits to ``.npy`` (boolean array) or ``.csv``/``.txt`` (one 0/1 per line)."""
    path = Path(path)
    array = as_bits(bits)
    suffix = path.suffix.lower()
    if suffix == ".npy":
        np.save(path, array)
    elif suffix in _TEXT_SUFFIXES:
        path.write_text("\n".join("1" if b else "0" for b in array) + "\n")
    else:
        raise InputError("path", str(path), "a file ending in .npy, .csv or .txt")
    return path
