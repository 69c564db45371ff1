"""The log of skyrmions that left a device through its ports.

The kernel reports exits in batches (one per call, often dozens in a reshuffler run); they are
kept as column blocks, so a run with 10⁵ exits builds no Python object per exit. Read them as
arrays (:meth:`ExitLog.arrays`) or, for small logs and interactive use, as a sequence of
``(id, time [s], port name, x [m], y [m])`` tuples.
"""

from __future__ import annotations

import numpy as np


class ExitLog:
    """Exits in the order they happened: skyrmion id, time [s], port, position [m]."""

    def __init__(self, port_names) -> None:
        self.port_names = list(port_names)
        self._blocks: list[tuple[np.ndarray, ...]] = []
        self._merged: dict[str, np.ndarray] | None = None

    def append(self, ids, times, ports, x, y) -> None:
        """Add a batch: ids, times [s], port indices into :attr:`port_names`, x and y [m].

        Arrays of equal length; they are copied.
        """
        if len(ids):
            self._blocks.append(
                (
                    np.array(ids, dtype=np.int64),
                    np.array(times, dtype=float),
                    np.array(ports, dtype=np.int64),
                    np.array(x, dtype=float),
                    np.array(y, dtype=float),
                )
            )
            self._merged = None

    def arrays(self) -> dict[str, np.ndarray]:
        """``skyrmion``, ``time`` [s], ``port`` (index into :attr:`port_names`), ``x``, ``y`` [m].

        As arrays: read-only views of one merged copy.
        """
        if self._merged is None:
            names = ("skyrmion", "time", "port", "x", "y")
            dtypes = (np.int64, float, np.int64, float, float)
            if self._blocks:
                columns = [np.concatenate(c) for c in zip(*self._blocks, strict=True)]
                self._blocks = [tuple(columns)]
            else:
                columns = [np.empty(0, d) for d in dtypes]
            self._merged = dict(zip(names, columns, strict=True))
            for column in self._merged.values():
                column.flags.writeable = False
        return self._merged

    def port_labels(self) -> np.ndarray:
        """The port name of each exit (strings)."""
        return np.array(self.port_names, dtype=str).reshape(-1)[self.arrays()["port"]]

    @classmethod
    def from_arrays(cls, port_names, ids, times, labels, x, y) -> ExitLog:
        """Rebuild a log from saved columns, ports given by name."""
        log = cls(port_names)
        index = {name: k for k, name in enumerate(log.port_names)}
        log.append(ids, times, [index[str(label)] for label in labels], x, y)
        return log

    def __len__(self) -> int:
        return sum(len(block[0]) for block in self._blocks)

    def __getitem__(self, k: int) -> tuple[int, float, str, float, float]:
        a = self.arrays()
        return (
            int(a["skyrmion"][k]),
            float(a["time"][k]),
            self.port_names[a["port"][k]],
            float(a["x"][k]),
            float(a["y"][k]),
        )

    def __iter__(self):
        return (self[k] for k in range(len(self)))
