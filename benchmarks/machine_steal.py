"""CPU time the hypervisor took from this virtual machine ("steal", Linux ``/proc/stat``).

On a shared VM, steal makes timings slower and noisier without any change in the code. The
benchmarks print how much there was while they ran, so a reader can tell a disturbed
measurement from a regression.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

_STAT = Path("/proc/stat")


def steal_seconds() -> float | None:
    """Total steal time of all CPUs since boot [s], or None where the kernel does not report it."""
    try:
        fields = _STAT.read_text().splitlines()[0].split()
    except OSError:
        return None
    if fields[0] != "cpu" or len(fields) < 9:
        return None
    return int(fields[8]) / os.sysconf("SC_CLK_TCK")  # the 8th value after "cpu": steal


class StealMeter:
    """Steal from its creation to :meth:`report`."""

    def __init__(self) -> None:
        self.start_value = steal_seconds()
        self.started = time.perf_counter()

    def report(self) -> str:
        end = steal_seconds()
        wall_seconds = time.perf_counter() - self.started
        if self.start_value is None or end is None:
            return "steal time: not reported by this system"
        stolen = end - self.start_value
        cores = os.cpu_count() or 1
        return (
            f"steal time (CPU taken by the hypervisor) during the benchmark: {stolen:.1f} s "
            f"= {100 * stolen / (wall_seconds * cores):.1f} % of {cores} cores × "
            f"{wall_seconds:.0f} s"
        )
