"""``model.toml``: a calibrated particle model, readable by every command that takes a material.

Its ``[material]`` table is a :class:`skygas.physics.materials.Material` (what
:func:`skygas.physics.materials.load_material` reads from a TOML file): the Thiele parameters
(radius, wall width, measured 𝒟, charge sign, damping, γ, the film thickness), the tabulated pair
and short-range wall laws (``[material.pair_table]``, ``[material.wall_table]``, SI), the skyrmion's
profile for the edge stray field (``[material.stray_field]``) and the paper's forms fitted to
the same laws (``pair_law``, ``wall_law``: used when a configuration asks for
``forces.pair_law = "paper"`` or ``forces.wall_law = "paper"``). The other tables say what the
model is and how it was made: ``[micromagnetics]`` (the input, enough to calibrate again),
``[thiele]`` (G, k, 𝒟 and its tensor, Q), ``[fits]`` (the paper-form fits with their range and
residuals), ``[laws]`` (the measured ranges), ``[provenance]`` (solver, versions, device, mesh,
convergence, wall times).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from skygas.core.errors import InputError


def _value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return repr(int(value))
    if isinstance(value, float):  # NumPy's float64 too, whose repr is not TOML
        if not math.isfinite(value):
            raise InputError("model value", value, "a finite number")
        return repr(float(value))
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)  # a JSON string is a TOML basic string
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    if hasattr(value, "item"):  # NumPy scalars
        return _value(value.item())
    raise InputError("model value", value, "a number, string, bool or list")


def dumps(data: dict[str, Any], comments: dict[str, str] | None = None, prefix: str = "") -> str:
    """``data`` (nested dicts of numbers, strings, bools and lists) as TOML.

    A list of dicts is an array of tables (``[[name]]``).

    ``comments`` maps a table's dotted name to a comment line written above it. ``None`` values are
    left out.
    """
    comments = comments or {}
    lines = []
    tables = []
    for key, value in data.items():
        if value is None:
            continue
        if isinstance(value, dict) or (
            isinstance(value, list) and value and all(isinstance(v, dict) for v in value)
        ):
            tables.append((key, value))
        else:
            lines.append(f"{key} = {_value(value)}")
    out = "\n".join(lines)
    for key, value in tables:
        name = f"{prefix}{key}"
        head = (
            ""
            if not comments.get(name)
            else "".join(f"# {line}\n" for line in comments[name].splitlines())
        )
        if isinstance(value, list):  # an array of tables, [[name]]
            for k, item in enumerate(value):
                out += f"\n\n{head if k == 0 else ''}[[{name}]]\n" + dumps(
                    item, comments, f"{name}."
                )
        else:
            out += f"\n\n{head}[{name}]\n" + dumps(value, comments, f"{name}.")
    return out.strip("\n") + "\n"


def write_model(
    path: Path,
    material: dict[str, Any],
    sections: dict[str, dict],
    header: list[str],
    comments: dict[str, str],
) -> Path:
    """Write ``model.toml`` atomically: the ``[material]`` table, then ``sections``.

    The table is validated first as a :class:`skygas.physics.materials.Material`, so the file always
    loads.
    """
    from skygas.physics.materials import material_from_mapping
    from skygas.runs.run_driver import write_atomic

    material_from_mapping(material, field="calibrated material")
    text = "".join(f"# {line}\n" for line in header) + "\n"
    text += dumps({"material": material, **sections}, comments)
    return write_atomic(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))
