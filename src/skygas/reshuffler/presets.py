"""The reshuffler's named preset configurations: ``src/skygas/data/reshuffler-NAME.toml``.

Kept apart from :mod:`skygas.reshuffler.config` (which imports the simulation's numerics) so
that the command line can offer the names without importing them.
"""

from __future__ import annotations

import tomllib
from importlib import resources

from skygas.core.errors import InputError

PRESETS = ("default", "paper", "paper-figures")


def preset_data(name: str) -> dict:
    """The mapping of a named reshuffler preset (one of :data:`PRESETS`)."""
    if name not in PRESETS:
        raise InputError("preset", name, f"one of {', '.join(PRESETS)}")
    text = resources.files("skygas").joinpath(f"data/reshuffler-{name}.toml").read_text()
    return tomllib.loads(text)
