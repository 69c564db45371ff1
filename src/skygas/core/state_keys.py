"""Checkpoint keys of nested parts: one flat mapping of arrays (what ``numpy.savez`` writes)
holds each part's own ``state_dict`` under a prefix (``sim_``, ``store_``, ``op.<name>.``)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import TypeVar

V = TypeVar("V")


def nest(prefix: str, state: Mapping[str, V]) -> dict[str, V]:
    """``state`` with every key prefixed: the part's entries in its owner's state."""
    return {f"{prefix}{key}": value for key, value in state.items()}


def unnest(prefix: str, state: Mapping[str, V]) -> dict[str, V]:
    """The entries of ``state`` under ``prefix``, with the prefix taken off: a part's own
    state, as :func:`nest` stored it."""
    return {key[len(prefix) :]: value for key, value in state.items() if key.startswith(prefix)}
