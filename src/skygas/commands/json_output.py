"""The one style of every command's ``--json`` output: one JSON object on stdout.

Standard JSON (NaN and ±inf, which JSON has no words for, are written ``null``; NumPy numbers as
numbers), indented by two spaces. Nothing else goes to stdout, so ``skygas ... --json | jq`` works.
"""

from __future__ import annotations

import json
from typing import Any

from skygas.core.json_values import plain

__all__ = ["plain", "print_json"]


def print_json(data: Any) -> None:
    """Print ``data`` as one JSON object (see the module docstring)."""
    print(json.dumps(plain(data), indent=2, default=float, allow_nan=False))
