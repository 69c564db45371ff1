"""The one style of every command's ``--json`` output: one JSON object on stdout.

Standard JSON (NaN and ±inf, which JSON has no words for, are written ``null``; NumPy numbers as
numbers), indented by two spaces. Nothing else goes to stdout (progress bars and estimates are
off, warnings go to stderr), so ``skygas ... --json | jq`` works. Every command adds the option
with :func:`add_json_option` and prints with :func:`print_json`.
"""

from __future__ import annotations

import json
from typing import Any

from skygas.core.json_values import plain

__all__ = ["add_json_option", "json_text", "plain", "print_json"]

#: the indentation of every ``--json`` object
INDENT = 2


def add_json_option(parser, what: str = "the summary") -> None:
    """Add ``--json`` to a sub-command's parser: print ``what`` as one JSON object instead."""
    parser.add_argument(
        "--json",
        action="store_true",
        help=f"print {what} as one JSON object on stdout (indented by {INDENT} spaces, NaN as "
        "null), with no progress bar, instead of the lines for a person",
    )


def json_text(data: Any) -> str:
    """``data`` as the text :func:`print_json` prints (see the module docstring)."""
    return json.dumps(plain(data), indent=INDENT, default=float, allow_nan=False)


def print_json(data: Any) -> None:
    """Print ``data`` as one JSON object (see the module docstring)."""
    print(json_text(data))
