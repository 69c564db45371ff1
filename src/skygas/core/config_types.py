"""Types shared by every configuration, and the paper's chamber dimensions, defined once.

Every configuration: simulation, reshuffler, neuron.

- :class:`StrictModel`: the pydantic base of every configuration section: unknown fields
  (spelling mistakes) and non-finite numbers (``inf``, ``nan``) are refused;
- :data:`PositiveFloat` and :data:`Length` (metres, from 1 pm to 1 m);
- :data:`CHAMBER_DIAMETER`, :data:`CONDUIT_WIDTH`, :data:`CONDUIT_LENGTH`,
  :data:`CHAMBER_GAP`: the paper's device (a 1024 nm chamber with 100 nm × 50 nm conduits;
  two such chambers 400 nm apart in the reshuffler), and :class:`ChamberSize`, the section that
  holds them;
- :func:`to_input_error` and :func:`read_toml`: validation failures and unreadable files as
  one :class:`~skygas.core.errors.InputError` naming the field (a tagged union's tags are
  left out of that name once registered: :func:`register_union_tags`).

Only pydantic is imported here: geometry, fields, engine and devices import this module, not
the other way round.
"""

from __future__ import annotations

import tomllib
import types
import typing
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Annotated, Any

from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    model_validator,
)
from pydantic_core import ErrorDetails

from skygas.core.errors import InputError, require

#: Diameter [m] of the paper's chamber.
CHAMBER_DIAMETER = 1024e-9
#: Width [m] of its input and output conduits.
CONDUIT_WIDTH = 100e-9
#: Length [m] of each conduit, from where its edges meet the disk to its end.
CONDUIT_LENGTH = 50e-9
#: Spacing [m] between the reshuffler's two chambers.
CHAMBER_GAP = 400e-9

#: The lengths a configuration accepts [m]: outside, the number was almost surely given in
#: another unit (``chamber_diameter = 1024`` for 1024 nm). A device larger than a metre could
#: not be held in memory anyway (its wall field is sampled on a nanometre grid), and nothing
#: in the model is smaller than a picometre.
MIN_LENGTH = 1e-12
MAX_LENGTH = 1.0


def length_problem(value: float) -> str | None:
    """What is wrong with ``value`` as a length in metres (None: nothing).

    Outside :data:`MIN_LENGTH` … :data:`MAX_LENGTH` the number was almost surely given in
    another unit; the text says what was probably meant.
    """
    if MIN_LENGTH <= value <= MAX_LENGTH:
        return None
    hint = (
        f"did you mean {value:g}e-9 (nanometres)?"
        if value > MAX_LENGTH
        else "did you mean nanometres (e.g. 2e-9)?"
    )
    return f"a length between {MIN_LENGTH:g} m and {MAX_LENGTH:g} m; lengths are in metres: {hint}"


def require_length(field: str, value: float) -> float:
    """``value`` [m] if it is a length a device can have, else an InputError naming ``field``.

    The check of every length given outside a configuration file (options, Python arguments),
    the same as :data:`Length`'s.
    """
    problem = length_problem(value)
    if problem is not None:
        raise InputError(field, value, problem)
    return value


def _metres(value: float) -> float:
    problem = length_problem(value)
    if problem is not None:
        raise ValueError(problem)
    return value


PositiveFloat = Annotated[float, Field(gt=0)]
#: A length in metres, between :data:`MIN_LENGTH` and :data:`MAX_LENGTH`.
Length = Annotated[float, Field(gt=0, description="metres"), AfterValidator(_metres)]


def _numeric(annotation: Any) -> bool:
    """True if ``annotation`` takes only numbers (``float``, ``int``, optional or annotated)."""
    if typing.get_origin(annotation) is Annotated:
        return _numeric(typing.get_args(annotation)[0])
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        members = [a for a in typing.get_args(annotation) if a is not type(None)]
        return bool(members) and all(_numeric(a) for a in members)
    return annotation in (float, int)


class _NotANumber:
    """What a number's place held when it was true/false or a string: refused with its reason.

    pydantic fails on it at the right place (a number is expected), and :func:`to_input_error`
    reports the value that was given and ``reason``.
    """

    def __init__(self, value: Any):
        self.value = value
        kind = "true or false" if isinstance(value, bool) else "a string: write it without quotes"
        self.reason = f"a number (this is {kind})"

    def __repr__(self) -> str:
        return repr(self.value)


def _refuse_non_numbers(value: Any, annotation: Any) -> Any:
    """``value``, with true/false or a string where ``annotation`` wants a number marked.

    pydantic would take ``true`` as 1 and ``"300"`` as 300; a configuration means neither. Such a
    value is replaced by a :class:`_NotANumber`, which pydantic then refuses at its place. Lists,
    tuples and tables of numbers are looked into.
    """
    if typing.get_origin(annotation) is Annotated:
        annotation = typing.get_args(annotation)[0]
    if isinstance(value, (bool, str)) and _numeric(annotation):
        return _NotANumber(value)
    origin, args = typing.get_origin(annotation), typing.get_args(annotation)
    if origin in (tuple, list) and isinstance(value, (list, tuple)) and args:
        if origin is list or (len(args) == 2 and args[1] is Ellipsis):
            items = [_refuse_non_numbers(item, args[0]) for item in value]
        else:
            items = [
                _refuse_non_numbers(item, args[i]) if i < len(args) else item
                for i, item in enumerate(value)
            ]
        return type(value)(items)
    if origin is dict and isinstance(value, dict) and len(args) == 2:
        return {key: _refuse_non_numbers(item, args[1]) for key, item in value.items()}
    return value


class StrictModel(BaseModel):
    """A configuration section: unknown fields, non-finite numbers and non-numbers are refused.

    A number's field refuses ``true``/``false`` and strings (pydantic alone would read
    ``temperature = true`` as 1 K), in every section, on plain and constrained numbers alike.
    """

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    @model_validator(mode="before")
    @classmethod
    def _numbers_are_numbers(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            return data
        fields = cls.model_fields
        return {
            key: _refuse_non_numbers(value, fields[key].annotation) if key in fields else value
            for key, value in data.items()
        }


class ChamberSize(StrictModel):
    """A chamber with its two conduits [m] (the paper's device by default)."""

    chamber_diameter: Length = CHAMBER_DIAMETER
    conduit_width: Length = CONDUIT_WIDTH
    conduit_length: Length = CONDUIT_LENGTH


#: pydantic's error types, in skygas's words (``{gt}`` etc. are the error's context)
_ALLOWED = {
    "missing": "a value (this field is required)",
    "extra_forbidden": "no such field (check the spelling)",
    "finite_number": "a finite number (not inf or nan)",
    "greater_than": "a number > {gt}",
    "greater_than_equal": "a number >= {ge}",
    "less_than": "a number < {lt}",
    "less_than_equal": "a number <= {le}",
    "float_parsing": "a number",
    "float_type": "a number",
    "int_parsing": "an integer",
    "int_type": "an integer",
    "int_from_float": "an integer",
    "bool_parsing": "true or false",
    "string_type": "a string",
    "too_short": "at least {min_length} entries",
    "too_long": "at most {max_length} entries",
    "bool_type": "true or false",
    "tuple_type": "a list",
    "list_type": "a list",
    "dict_type": "a table",
    "model_type": "a table",
    "model_attributes_type": "a table",
    "literal_error": "one of {expected}",
    "enum": "one of {expected}",
    "string_pattern_mismatch": "text matching {pattern}",
    "string_too_short": "text of at least {min_length} characters",
    "string_too_long": "text of at most {max_length} characters",
    "multiple_of": "a multiple of {multiple_of}",
}

#: how many entries a tuple holds, in words (``Point2``: "two numbers")
_COUNT = {1: "one", 2: "two", 3: "three", 4: "four"}

#: pydantic's error types for a tagged union whose tag is unknown or missing
_TAG_ERRORS = ("union_tag_invalid", "union_tag_not_found")


def _allowed(error: ErrorDetails) -> str:
    ctx = error.get("ctx", {})
    if error["type"] == "too_long" and ctx.get("field_type") == "Tuple":
        count = ctx.get("max_length")
        words = _COUNT.get(count, str(count)) if isinstance(count, int) else str(count)
        return f"{words} entries (this has {ctx.get('actual_length')})"
    template = _ALLOWED.get(error["type"])
    if template is not None:
        try:
            return template.format(**error.get("ctx", {}))
        except (KeyError, IndexError):
            pass
    msg = error["msg"]
    for prefix in ("Value error, ", "Assertion failed, ", "Input should be "):
        msg = msg.removeprefix(prefix)
    return msg


#: Tags of tagged unions: the member names pydantic puts into an error's location
#: (``potentials.0.gaussian.sigma``), which :func:`to_input_error` leaves out of the field's name.
#: The module that defines such a union registers its tags when it is imported
#: (:func:`register_union_tags`; the energy landscape's kinds,
#: :data:`skygas.fields.landscape.kinds.KINDS`), so that this module imports nothing above the
#: foundations. An error can hold a tag only once its union exists, and so once it is registered.
_UNION_TAGS: set[str] = set()


def register_union_tags(tags: Iterable[str]) -> None:
    """Name a tagged union's tags (its members' names) as such to :func:`to_input_error`.

    That function leaves them out of the field names it reports.
    """
    _UNION_TAGS.update(tags)


def _is_tag(loc: tuple, i: int) -> bool:
    """True if element ``i`` of a pydantic error location is a union's tag, not a field.

    The tag is the name of the member tried, as in ``potentials.0.gaussian.sigma``.
    """
    return i >= 1 and isinstance(loc[i - 1], int) and loc[i] in _UNION_TAGS


def to_input_error(err: ValidationError, source: str = "", prefix: str = "") -> InputError:
    """The first error of a pydantic validation as one :class:`InputError` line naming the field.

    The line names the field (``source``, e.g. the file name, then ``prefix`` and the dotted
    location), the value and what is allowed, in skygas's words rather than pydantic's. The field's
    dotted path without ``source`` is kept as the error's ``loc`` (a command names the option
    instead when it came from one).

    A tagged union's tag (``potentials.0.gaussian.sigma``) is left out of the name
    (``potentials.0.sigma``), and an unknown or missing tag is reported as the ``kind`` field
    with the allowed kinds.
    """
    first = err.errors()[0]
    parts = [p for i, p in enumerate(first["loc"]) if not _is_tag(first["loc"], i)]
    value = first.get("input") if first["type"] != "missing" else "(missing)"
    allowed = _allowed(first)
    if isinstance(value, _NotANumber):  # true/false or a string in a number's place
        value, allowed = value.value, value.reason
    if first["type"] == "missing" and parts and isinstance(parts[-1], int):
        # a tuple one entry short (``center = [1e-7]``): the tuple is the field
        allowed = f"more entries (entry {parts.pop()} is missing)"
        value = first.get("input")
    if first["type"] in _TAG_ERRORS:
        parts.append(first.get("ctx", {}).get("discriminator", "kind").strip("'"))
        value = first.get("ctx", {}).get("tag", "(missing)")
        allowed = f"one of {first.get('ctx', {}).get('expected_tags', '')}"
    loc = ".".join(str(p) for p in [*prefix.split("."), *parts] if p != "")
    error = InputError(f"{source}{loc}", value, allowed)
    error.loc = loc
    return error


def read_toml(path: str | Path, field: str = "config") -> dict:
    """Parse a TOML file.

    Raises :class:`InputError` naming ``field`` if it is missing or malformed.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(field, str(path), "an existing TOML file")
    try:
        text = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError as err:
        raise InputError(
            field,
            str(path),
            f"a TOML text file (this is binary or not UTF-8: byte {err.start} cannot be read)",
            "give the configuration file, saved as UTF-8 text",
        ) from None
    except OSError as err:
        raise InputError(
            field, str(path), f"a readable TOML file ({err.strerror})", "check the file"
        ) from None
    if "\x00" in text:
        raise InputError(
            field,
            str(path),
            "a TOML text file (this one holds NUL bytes: it is binary)",
            "give the configuration file",
        )
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise InputError(field, str(path), f"valid TOML ({err})") from None


def apply_overrides(data: dict, overrides: Mapping[str, Any]) -> dict:
    """A copy of ``data`` with dotted-key overrides applied; ``None`` values are skipped.

    A dotted key: ``{"signal.p": 0.3}``, an index into a list of tables:
    ``{"potentials.0.rms": 1e-9}``, a top-level key: ``{"seed": 3}``. The one way every
    configuration takes overrides (keyword arguments, sweep points, command-line options).
    """
    data = {k: (dict(v) if isinstance(v, dict) else v) for k, v in data.items()}
    for key, value in overrides.items():
        if value is None:
            continue
        node: dict | list = data
        parts = key.split(".")
        for depth, part in enumerate(parts):
            last = depth == len(parts) - 1
            if isinstance(node, list):  # an index into a list ("potentials.0.rms")
                require(
                    part.isdigit() and int(part) < len(node),
                    key,
                    value,
                    f"an index below {len(node)} into the list {'.'.join(parts[:depth])}",
                )
                if last:
                    node[int(part)] = value
                    break
                child = node[int(part)]
                index: int | str = int(part)
            else:
                if last:
                    node[part] = value
                    break
                child = node.get(part, {})
                index = part
            # copied on the way down: the caller's data is never changed
            if isinstance(child, dict):
                child = dict(child)
            elif isinstance(child, list):
                child = [dict(t) if isinstance(t, dict) else t for t in child]
            else:
                raise InputError(
                    key,
                    value,
                    f"a key into a table ({'.'.join(parts[: depth + 1])} is a value, not a "
                    "table or a list)",
                )
            node[index] = child  # type: ignore[index]
            node = child
    return data
