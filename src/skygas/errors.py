"""The one exception type that user-facing validation raises.

Every check on user input (a config file, a CLI option, an array handed to the API) raises
:class:`InputError` *before* any long computation starts. The message always names the field,
the offending value and what is allowed, so that a user can fix the input without reading code.
"""

from __future__ import annotations

from typing import Any


class InputError(ValueError):
    """Invalid user input.

    Parameters
    ----------
    field:
        Dotted name of the offending field (``"temperature"``, ``"skyrmions[3].x"``).
    value:
        The value that was given.
    allowed:
        A short phrase saying what would be accepted (``"a number >= 0 (kelvin)"``).
    """

    def __init__(self, field: str, value: Any, allowed: str):
        self.field = field
        self.value = value
        self.allowed = allowed
        super().__init__(f"{field} = {value!r} is not allowed: expected {allowed}")


def require(condition: bool, field: str, value: Any, allowed: str) -> None:
    """Raise :class:`InputError` unless ``condition`` holds."""
    if not condition:
        raise InputError(field, value, allowed)
