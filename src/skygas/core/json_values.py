"""Values as standard JSON has words for them: what every JSON file and ``--json`` output holds.

JSON has no NaN or infinity: a number that a run cannot give yet (a correlation before any
output, a mean of nothing) is written ``null``. NumPy scalars become Python numbers.
"""

from __future__ import annotations

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
