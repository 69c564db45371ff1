"""The clock a core of this machine runs at now, measured from a chain of dependent multiplies.

On a shared virtual machine the host may run the same core at different clocks from one hour
to the next, and every timing follows (on the development VM, engine timings differ by about
1.5× between a fast and a slow state; in the slow one this probe reads 1.6–2.3 GHz, moving
within seconds). A chain of floating-point multiplies, each waiting for the previous result,
takes a fixed number of cycles per multiply whatever else the machine does, so its speed gives
the clock:

    f = 4 · n / t     (n multiplies in t seconds, 4 cycles each)

The 4-cycle latency of a double-precision multiply holds for Intel cores since Skylake (the
development machine's); AMD Zen cores take 3, where the figure reads 4/3 too high. Timings
multiplied by this clock give cycles, which compare across the machine's states.
"""

from __future__ import annotations

import math
import time

import numba

MULTIPLY_LATENCY_CYCLES = 4


@numba.njit(cache=True)  # no fastmath: the compiler must keep the chain of multiplies
def _multiply_chain(n: int, value: float) -> float:
    for _ in range(n):
        value = value * 0.9999999
    return value


def clock_ghz(multiplies: int = 5_000_000, samples: int = 20) -> float:
    """4·n/t [GHz] for the fastest of ``samples`` chains of ``multiplies`` dependent multiplies
    (about 0.2 s in all at 2 GHz). The fastest, not the median: a chain the hypervisor or
    another process interrupted only reads too slow."""
    _multiply_chain(10, 1.0)  # compile
    best = math.inf
    for _ in range(samples):
        start = time.perf_counter()
        _multiply_chain(multiplies, 1.0)
        best = min(best, time.perf_counter() - start)
    return MULTIPLY_LATENCY_CYCLES * multiplies / best / 1e9


if __name__ == "__main__":
    print(
        f"core clock (dependent multiplies, {MULTIPLY_LATENCY_CYCLES} cycles each): "
        f"{clock_ghz():.2f} GHz"
    )
