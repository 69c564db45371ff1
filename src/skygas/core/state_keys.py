"""Checkpoint keys of nested parts, each under its own prefix in one flat mapping.

One flat mapping of arrays (what ``numpy.savez`` writes) holds each part's own ``state_dict`` under
a prefix (``sim_``, ``store_``, ``op.<name>.``).
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import TypeVar

import numpy as np

V = TypeVar("V")


def nest(prefix: str, state: Mapping[str, V]) -> dict[str, V]:
    """``state`` with every key prefixed: the part's entries in its owner's state."""
    return {f"{prefix}{key}": value for key, value in state.items()}


def unnest(prefix: str, state: Mapping[str, V]) -> dict[str, V]:
    """The entries of ``state`` under ``prefix``, with the prefix taken off.

    A part's own state, as :func:`nest` stored it.
    """
    return {key[len(prefix) :]: value for key, value in state.items() if key.startswith(prefix)}


#: Suffix of a checkpoint key whose value is JSON text (see :func:`to_arrays`).
JSON_SUFFIX = ":json"


def to_arrays(state: Mapping[str, object]) -> dict[str, np.ndarray]:
    """A part's state as arrays only, what a checkpoint stores.

    NumPy arrays pass unchanged; any other value (numbers, lists, dicts: a generator's
    ``bit_generator.state``, a log kept as a list) must be JSON-able and is stored as JSON text
    under its key with :data:`JSON_SUFFIX` appended, which :func:`from_arrays` reads back.
    """
    arrays: dict[str, np.ndarray] = {}
    for key, value in state.items():
        if isinstance(value, np.ndarray):
            arrays[key] = value
        else:
            arrays[key + JSON_SUFFIX] = np.array(json.dumps(value))
    return arrays


def from_arrays(state: Mapping[str, np.ndarray]) -> dict[str, object]:
    """The inverse of :func:`to_arrays`: JSON text back to its values."""
    return {
        (key[: -len(JSON_SUFFIX)] if key.endswith(JSON_SUFFIX) else key): (
            json.loads(str(value)) if key.endswith(JSON_SUFFIX) else value
        )
        for key, value in state.items()
    }
