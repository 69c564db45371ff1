"""Wire gates and decorrelators into a small feed-forward circuit evaluated on whole streams.

Example: squaring with and without a decorrelator (the paper's AND-gate figure)::

    circuit = Circuit(inputs=["x"])
    circuit.add("naive", and_, "x", "x")                  # p instead of p^2
    circuit.add_decorrelator("x_copy", ShuffleBuffer(64), "x")
    circuit.add("square", and_, "x", "x_copy")            # p^2
    streams = circuit.evaluate({"x": bernoulli_stream(0.6, 4096, seed=1)}, seed=2)

Nodes are evaluated in the order they were added, and may only read nodes added before them,
so the circuit is acyclic by construction. Sequential gates (JK flip-flop, C-element) are fine
as nodes: each one consumes whole streams.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from skygas.core import validate as v
from skygas.core.errors import InputError
from skygas.sc.decorrelators import Decorrelator


@dataclass(frozen=True)
class _Node:
    name: str
    operation: Callable[..., np.ndarray] | Decorrelator
    sources: tuple[str, ...]


class Circuit:
    """A named, ordered list of gates over named input streams.

    Parameters
    ----------
    inputs : sequence of str
        Names of the primary input streams.
    """

    def __init__(self, inputs: Sequence[str]):
        names = list(inputs)
        if not names or len(set(names)) != len(names):
            raise InputError("inputs", inputs, "a non-empty list of distinct names")
        self.inputs = tuple(str(n) for n in names)
        self._nodes: list[_Node] = []

    @property
    def names(self) -> tuple[str, ...]:
        """All stream names: inputs first, then nodes in evaluation order."""
        return self.inputs + tuple(node.name for node in self._nodes)

    def _check_new(self, name: str, sources: Sequence[str]) -> None:
        if name in self.names:
            raise InputError("name", name, f"a name not already used ({', '.join(self.names)})")
        for source in sources:
            if source not in self.names:
                raise InputError(
                    f"{name}.sources", source, f"one of the streams defined so far: {self.names}"
                )

    def add(self, name: str, gate: Callable[..., np.ndarray], *sources: str) -> Circuit:
        """Add node ``name = gate(*sources)``; ``gate`` maps streams to a stream (e.g. ``and_``)."""
        if not callable(gate):
            raise InputError(f"{name}.gate", gate, "a callable taking streams")
        self._check_new(name, sources)
        self._nodes.append(_Node(name, gate, tuple(sources)))
        return self

    def add_decorrelator(self, name: str, decorrelator: Decorrelator, source: str) -> Circuit:
        """Add node ``name`` = ``decorrelator`` applied to ``source`` (seeded at evaluation)."""
        if not isinstance(decorrelator, Decorrelator):
            raise InputError(f"{name}.decorrelator", decorrelator, "a Decorrelator instance")
        self._check_new(name, (source,))
        self._nodes.append(_Node(name, decorrelator, (source,)))
        return self

    def evaluate(self, inputs: Mapping[str, Any], seed: v.SeedLike = None) -> dict[str, np.ndarray]:
        """Evaluate every node; return all streams by name.

        Each decorrelator node gets its own child generator spawned from ``seed``, in the order
        the nodes were added, so results do not depend on which other nodes exist downstream.
        """
        missing = [n for n in self.inputs if n not in inputs]
        if missing:
            raise InputError("inputs", sorted(inputs), f"streams for all of {list(self.inputs)}")
        streams: dict[str, np.ndarray] = {}
        for name in self.inputs:
            streams[name] = v.as_stream(inputs[name], name)
        v.same_length(**{name: streams[name] for name in self.inputs})
        rng = v.make_rng(seed)
        children = rng.spawn(len(self._nodes))
        for node, child in zip(self._nodes, children, strict=True):
            args = [streams[s] for s in node.sources]
            if isinstance(node.operation, Decorrelator):
                streams[node.name] = node.operation.apply(args[0], child).stream
            else:
                streams[node.name] = np.asarray(node.operation(*args))
        return streams
