"""The one style of every command's ``--json`` output: one JSON object on stdout.

Standard JSON (NaN and ±inf, which JSON has no words for, are written ``null``; NumPy numbers as
numbers), indented by two spaces. Nothing else goes to stdout, so ``skygas ... --json | jq`` works.
"""

from __future__ import annotations

import json
import math
from typing import Any


def plain(value: Any) -> Any:
    """``value`` with NaN and ±inf replaced by None and NumPy scalars by Python numbers."""
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if hasattr(value, "item") and callable(value.item) and getattr(value, "ndim", 1) == 0:
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def print_json(data: Any) -> None:
    """Print ``data`` as one JSON object (see the module docstring)."""
    print(json.dumps(plain(data), indent=2, default=float, allow_nan=False))
