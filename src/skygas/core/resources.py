"""Size checks made before anything is allocated: memory and step counts.

A job whose arrays cannot fit (a stream of 10¹⁰ bits, 10¹⁴ input spikes, a record of 10¹²
frames, a wall grid of 10²⁴ cells) or whose step count is not a number a computer can count
(``duration = 1e300``) is refused with one :class:`~skygas.core.errors.InputError` naming the
field, before any work, instead of failing later with ``MemoryError`` or ``OverflowError``.

- :func:`memory_limit`: the memory one job may ask for: :data:`MEMORY_FRACTION` of the
  machine's physical memory (``os.sysconf``), or ``SKYGAS_MEMORY_LIMIT`` bytes when that
  environment variable is set;
- :func:`require_memory`: refuse an estimate above it;
- :func:`step_count`: the number of time steps of a duration, refused above :data:`MAX_STEPS`.
"""

from __future__ import annotations

import math
import os

from skygas.core.errors import InputError

#: Fraction of the machine's physical memory one job may ask for.
MEMORY_FRACTION = 0.5
#: Used when the physical memory cannot be read (``os.sysconf`` unavailable) [bytes].
FALLBACK_MEMORY = 8 * 2**30
#: Most time steps a run may have: 2⁵³, beyond which the step counter, held as a float time,
#: can no longer tell two steps apart (and no run could ever finish: 10¹⁵ steps at 10⁸ steps/s
#: take a year).
MAX_STEPS = 2**53


def physical_memory() -> int:
    """The machine's physical memory [bytes] (:data:`FALLBACK_MEMORY` if it cannot be read)."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, ValueError, OSError):
        return FALLBACK_MEMORY


def memory_limit() -> int:
    """The most memory [bytes] one job may ask for (see the module docstring)."""
    text = os.environ.get("SKYGAS_MEMORY_LIMIT")
    if text:
        try:
            return int(float(text))
        except ValueError:
            raise InputError("SKYGAS_MEMORY_LIMIT", text, "a number of bytes") from None
    return int(MEMORY_FRACTION * physical_memory())


def format_bytes(n: float) -> str:
    """``n`` bytes in binary units (``"2.1 PiB"``)."""
    if not math.isfinite(n):
        return "an unbounded amount"
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if abs(n) < 1024 or unit == "PiB":
            return f"{n:.3g} {unit}"
        n /= 1024
    return f"{n:.3g} PiB"  # pragma: no cover


def require_memory(
    field: str, value, n_bytes: float, what: str, hint: str = "use a smaller value"
) -> None:
    """Refuse ``field = value`` when ``what`` would need more than :func:`memory_limit`.

    ``n_bytes`` [bytes] is an estimate of the largest arrays. Raises :class:`InputError` with
    ``hint``.
    """
    limit = memory_limit()
    if not (n_bytes <= limit):  # also catches inf and nan
        raise InputError(
            field,
            value,
            f"a job that fits in memory ({what} would need about "
            f"{format_bytes(n_bytes)}, more than the {format_bytes(limit)} a job "
            "may use)",
            hint,
        )


def step_count(duration: float, time_step: float, field: str = "duration") -> int:
    """``round(duration / time_step)``, the number of time steps of a run.

    Refused (:class:`InputError` naming ``field``) when it is not finite or above :data:`MAX_STEPS`.
    """
    steps = duration / time_step
    if not (math.isfinite(steps) and steps <= MAX_STEPS):
        raise InputError(
            field,
            duration,
            f"a duration of at most {MAX_STEPS:.3g} time steps "
            f"of {time_step:.3g} s ({MAX_STEPS * time_step:.3g} s)",
            "use a shorter duration",
        )
    return int(round(steps))
