"""Types shared by every configuration (simulation, reshuffler, neuron), and the paper's
chamber dimensions, defined once.

- :class:`StrictModel`: the pydantic base of every configuration section: unknown fields
  (spelling mistakes) and non-finite numbers (``inf``, ``nan``) are refused;
- :data:`PositiveFloat` and :data:`Length` (metres, > 0);
- :data:`CHAMBER_DIAMETER`, :data:`CONDUIT_WIDTH`, :data:`CONDUIT_LENGTH`,
  :data:`CHAMBER_GAP`: the paper's device (a 1024 nm chamber with 100 nm × 50 nm conduits;
  two such chambers 400 nm apart in the reshuffler), and :class:`ChamberSize`, the section that
  holds them;
- :func:`to_input_error` and :func:`read_toml`: validation failures and unreadable files as
  one :class:`~skygas.errors.InputError` naming the field.

Only pydantic is imported here: geometry, engine and devices import this module, not the
other way round.
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Annotated

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from skygas.errors import InputError

#: Diameter [m] of the paper's chamber.
CHAMBER_DIAMETER = 1024e-9
#: Width [m] of its input and output conduits.
CONDUIT_WIDTH = 100e-9
#: Length [m] of each conduit, from where its edges meet the disk to its end.
CONDUIT_LENGTH = 50e-9
#: Spacing [m] between the reshuffler's two chambers.
CHAMBER_GAP = 400e-9

PositiveFloat = Annotated[float, Field(gt=0)]
#: A length in metres, > 0.
Length = Annotated[float, Field(gt=0, description="metres")]


class StrictModel(BaseModel):
    """A configuration section: unknown fields and non-finite numbers are refused."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class ChamberSize(StrictModel):
    """A chamber with its two conduits [m] (the paper's device by default)."""

    chamber_diameter: Length = CHAMBER_DIAMETER
    conduit_width: Length = CONDUIT_WIDTH
    conduit_length: Length = CONDUIT_LENGTH


def to_input_error(err: ValidationError, source: str = "", prefix: str = "") -> InputError:
    """The first error of a pydantic validation as one :class:`InputError` line: the dotted
    field (``source`` + ``prefix`` + location), the value and what is allowed.

    A tagged union's tag (``potentials.0.gaussian.sigma``) is left out of the name
    (``potentials.0.sigma``), and an unknown or missing tag is reported as the ``kind`` field
    with the allowed kinds."""
    first = err.errors()[0]
    loc = [p for i, p in enumerate(first["loc"]) if not _is_tag(first["loc"], i)]
    value = first.get("input") if first["type"] != "missing" else "(missing)"
    msg = first["msg"].removeprefix("Value error, ")
    if msg.startswith("Input should be "):  # "… is not allowed: expected a finite number"
        msg = msg.removeprefix("Input should be ")
        msg = f"a value {msg}" if msg.startswith(("greater", "less")) else msg
    if first["type"] == "missing":
        msg = "this required field to be given"
    elif first["type"] == "extra_forbidden":
        msg = "no such field (check the spelling)"
    elif first["type"] in _TAG_ERRORS:
        tags = first.get("ctx", {}).get("expected_tags", "")
        loc.append(first.get("ctx", {}).get("discriminator", "kind").strip("'"))
        value = first.get("ctx", {}).get("tag", "(missing)")
        msg = f"one of {tags}"
    field = ".".join(str(p) for p in [*prefix.split("."), *loc] if p != "")
    return InputError(f"{source}{field}", value, msg)


#: pydantic's error types for a tagged union whose tag is unknown or missing
_TAG_ERRORS = ("union_tag_invalid", "union_tag_not_found")


def _is_tag(loc: tuple, i: int) -> bool:
    """True if element ``i`` of a pydantic error location is a union's tag (the name of the
    member tried, as in ``potentials.0.gaussian.sigma``), not a field."""
    from skygas.landscape.kinds import KINDS  # imported here: the kinds import this module

    return i >= 1 and isinstance(loc[i - 1], int) and loc[i] in KINDS


def read_toml(path: str | Path, field: str = "config") -> dict:
    """Parse a TOML file, or raise :class:`InputError` naming ``field`` if it is missing or
    malformed."""
    path = Path(path)
    if not path.is_file():
        raise InputError(field, str(path), "an existing TOML file")
    try:
        return tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as err:
        raise InputError(field, str(path), f"valid TOML ({err})") from None
