"""Energy landscapes: external potentials U(x, y) whose force −∇U enters the Thiele equation.

Kinds (:mod:`skygas.landscape.kinds`): :class:`Gaussian`, :class:`Periodic`, :class:`Band`
(a gate), :class:`RandomPinning`, :class:`Disorder` and :class:`GridFile` (``kind = "grid"``).
Pass them to :class:`~skygas.engine.Simulation` as ``landscape=[...]``, or list them in a TOML
configuration as ``[[potentials]]``. Several terms add. See ``docs/landscapes.md``.
"""

from skygas.landscape.field import LandscapeField
from skygas.landscape.kinds import (
    KINDS,
    Band,
    Disorder,
    Gaussian,
    GridFile,
    Periodic,
    Potential,
    RandomPinning,
)

__all__ = ["KINDS", "Band", "Disorder", "Gaussian", "GridFile", "LandscapeField", "Periodic",
           "Potential", "RandomPinning", "parse_potentials"]


def parse_potentials(potentials) -> list:
    """Potentials given as objects or as mappings with a ``kind`` (TOML tables), validated;
    a bad one raises :class:`~skygas.errors.InputError` naming its field."""
    from pydantic import TypeAdapter, ValidationError

    from skygas.errors import InputError, require

    potentials = [] if potentials is None else list(potentials)
    adapter = TypeAdapter(Potential)
    out = []
    for k, p in enumerate(potentials):
        if isinstance(p, tuple(KINDS.values())):
            out.append(p)
            continue
        require(isinstance(p, dict), f"potentials[{k}]", p,
                f"a table with kind = one of {sorted(KINDS)}")
        try:
            out.append(adapter.validate_python(p))
        except ValidationError as err:
            first = err.errors()[0]
            loc = ".".join(str(x) for x in first["loc"][1:] if x not in KINDS) or "kind"
            raise InputError(f"potentials[{k}].{loc}", first.get("input"), first["msg"]) \
                from None
    return out
