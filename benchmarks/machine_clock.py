"""The clock a core of this machine runs at now, measured from a chain of dependent multiplies.

On a shared virtual machine the host may run the same core at different clocks from one hour
to the next, and every timing follows (on the development VM, engine timings differ by about
1.5× between a fast and a slow state; this probe reads 2.0–2.2 GHz in the slow one). A chain
of floating-point multiplies, each waiting for the previous result, takes a fixed number of
cycles per multiply whatever else the machine does, so its speed gives the clock:

    f = 4 · n / t     (n multiplies in t seconds, 4 cycles each)

The 4-cycle latency of a double-precision multiply holds for Intel cores since Skylake (the
development machine's); AMD Zen cores take 3, where the figure reads 4/3 too high. Timings
multiplied by this clock give cycles, which compare across the machine's states.
"""

from __future__ import annotations

import statistics
import time

import numba

MULTIPLY_LATENCY_CYCLES = 4


@numba.njit(cache=True)  # no fastmath: the compiler must keep the chain of multiplies
def _multiply_chain(n: int, value: float) -> float:
    for _ in range(n):
        value = value * 0.9999999
    return value


def clock_ghz(multiplies: int = 20_000_000, samples: int = 5) -> float:
    """Median over ``samples`` chains of ``multiplies`` dependent multiplies of 4·n/t [GHz]
    (about 0.2 s in all at 2 GHz)."""
    _multiply_chain(10, 1.0)  # compile
    rates = []
    for _ in range(samples):
        start = time.perf_counter()
        _multiply_chain(multiplies, 1.0)
        rates.append(MULTIPLY_LATENCY_CYCLES * multiplies / (time.perf_counter() - start))
    return statistics.median(rates) / 1e9


if __name__ == "__main__":
    print(f"core clock (dependent multiplies, {MULTIPLY_LATENCY_CYCLES} cycles each): "
          f"{clock_ghz():.2f} GHz")
