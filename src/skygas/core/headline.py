"""The results a report states first, as rows of text: shared by every command's headline.

A :class:`Results` is what a report's headline block shows (label, value as text), the notes
under it and further titled tables. It lives here, below the devices, so that each device's
package writes its own headline (:mod:`skygas.reshuffler.headline`,
:mod:`skygas.neuron.headline`, ...) without importing the report that draws it
(:mod:`skygas.outputs.report`, a higher layer). Every value is written by
:mod:`skygas.core.quantities`; a value a run cannot give is written ``none (why)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from skygas.core.quantities import format_quantity, label, missing

#: a headline row: its label and its value, both text
Row = tuple[str, str]
#: a table: its column names and its rows of text cells
Table = tuple[list[str], list[list[str]]]


@dataclass
class Results:
    """A report's results: the headline rows, notes under them, and titled tables."""

    rows: list[Row] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    tables: list[tuple[str, Table]] = field(default_factory=list)
    #: the summary keys the headline shows (left out of the report's table of every number)
    keys: set[str] = field(default_factory=set)

    def add(self, key: str, value: Any, error: Any = None, *, reason: str, name: str = "") -> None:
        """A row for quantity ``key``: its value, or ``none (reason)`` when it has none."""
        text = format_quantity(key, value, error)
        self.rows.append((name or label(key), none(reason) if text is None else text))
        self.keys.add(key)


def none(reason: str) -> str:
    """The text of an absent value: ``none (reason)``."""
    return f"none ({reason})"


def constrained(value: Any, error: Any) -> bool:
    """Whether a fitted ``value`` is fixed by the data: 0 < error < |value|, both finite.

    A fit is stated (and a sweep's figure draws it) only where this holds for each of its
    coefficients.
    """
    if missing(value) or missing(error):
        return False
    return 0 < float(error) < abs(float(value))


def present(summary: dict, key: str) -> Any:
    """``summary[key]``, or None when absent, None or NaN."""
    value = summary.get(key)
    return None if missing(value) else value
