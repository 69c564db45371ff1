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


def to_input_error(err: ValidationError, source: str = "") -> InputError:
    """The first error of a pydantic validation as an :class:`InputError` naming the field
    (prefixed by ``source``, e.g. the file name), the value and what is allowed."""
    first = err.errors()[0]
    loc = ".".join(str(p) for p in first["loc"])
    value = first.get("input") if first["type"] != "missing" else "(missing)"
    msg = first["msg"]
    if first["type"] == "missing":
        msg = "this required field to be given"
    elif first["type"] == "extra_forbidden":
        msg = "no such field (check the spelling)"
    return InputError(f"{source}{loc}", value, msg)


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
