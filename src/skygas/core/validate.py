"""Input checks for values handed to the API: seeds, integers, probabilities, bit arrays.

Any module may use them (the stochastic-computing package, the signals, the correlation
analyses); a public function validates its arguments with them before any work. Each raises
:class:`skygas.core.errors.InputError` naming the field, the value and what is allowed.
"""

from __future__ import annotations

import numbers
from typing import Any

import numpy as np

from skygas.core.errors import InputError

SeedLike = int | np.random.Generator | np.random.SeedSequence | None


def make_rng(seed: Any, field: str = "seed") -> np.random.Generator:
    """Return a NumPy generator from an int, a ``SeedSequence``, a ``Generator`` or ``None``."""
    if isinstance(seed, bool) or not (
        seed is None
        or isinstance(seed, (numbers.Integral, np.random.Generator, np.random.SeedSequence))
    ):
        raise InputError(field, seed, "an int >= 0, a numpy Generator, a SeedSequence or None")
    if isinstance(seed, numbers.Integral) and seed < 0:
        raise InputError(field, seed, "an int >= 0, a numpy Generator, a SeedSequence or None")
    # numpy's stubs list int and NumPy integers, not the numbers.Integral checked above
    return np.random.default_rng(seed)  # type: ignore[arg-type]


def as_stream(stream: Any, field: str) -> np.ndarray:
    """Return ``stream`` as a boolean array of shape ``(..., N)`` with ``N >= 1``.

    Integer 0/1 data is refused on purpose: silently casting would also accept 2 or -1.
    """
    array = np.asarray(stream)
    if array.dtype != np.bool_:
        raise InputError(
            field,
            f"array of dtype {array.dtype}",
            "a boolean array of shape (..., N) (convert 0/1 data with .astype(bool))",
        )
    if array.ndim < 1 or array.shape[-1] < 1:
        raise InputError(field, f"array of shape {array.shape}", "shape (..., N) with N >= 1 bits")
    return array


def same_length(**streams: np.ndarray) -> tuple[int, ...]:
    """Check that all streams have the same length N and broadcastable leading shapes.

    Returns the broadcast leading shape.
    """
    names = list(streams)
    first = names[0]
    n_bits = streams[first].shape[-1]
    for name in names[1:]:
        length = streams[name].shape[-1]
        if length != n_bits:
            raise InputError(
                name, f"a stream of {length} bits", f"{n_bits} bits, the length of {first}"
            )
    try:
        return np.broadcast_shapes(*(s.shape[:-1] for s in streams.values()))
    except ValueError:
        shapes = {name: s.shape for name, s in streams.items()}
        raise InputError(
            ",".join(names), shapes, "leading shapes (...) that broadcast together"
        ) from None


def probability(p: Any, field: str) -> np.ndarray:
    """Return ``p`` as a float array after checking every entry is finite and in [0, 1]."""
    try:
        array = np.asarray(p, dtype=float)
    except (TypeError, ValueError):
        raise InputError(field, p, "a number or array of numbers in [0, 1]") from None
    if not np.all(np.isfinite(array)) or np.any((array < 0.0) | (array > 1.0)):
        raise InputError(field, p, "a probability in [0, 1]")
    return array


def positive_int(value: Any, field: str, minimum: int = 1) -> int:
    """Return ``value`` as an int after checking it is an integer >= ``minimum``."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < minimum:
        raise InputError(field, value, f"an integer >= {minimum}")
    return int(value)


def positive_float(value: Any, field: str, unit: str) -> float:
    """Return ``value`` as a float after checking it is finite and > 0."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise InputError(field, value, f"a number > 0 ({unit})") from None
    if not np.isfinite(number) or number <= 0.0:
        raise InputError(field, value, f"a number > 0 ({unit})")
    return number


def leading_shape(shape: Any, field: str = "shape") -> tuple[int, ...]:
    """Return ``shape`` as a tuple of non-negative ints (the batch shape in front of N)."""
    if isinstance(shape, numbers.Integral) and not isinstance(shape, bool):
        shape = (shape,)
    try:
        dims = tuple(shape)
    except TypeError:
        raise InputError(field, shape, "a tuple of integers >= 1 (the batch shape)") from None
    for dim in dims:
        if isinstance(dim, bool) or not isinstance(dim, numbers.Integral) or dim < 1:
            raise InputError(field, shape, "a tuple of integers >= 1 (the batch shape)")
    return tuple(int(d) for d in dims)
