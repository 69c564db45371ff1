"""Energy landscapes: external potentials U(x, y) whose force −∇U enters the Thiele equation.

Kinds (:mod:`skygas.fields.landscape.kinds`): :class:`Gaussian`, :class:`Periodic`, :class:`Band`
(a gate), :class:`RandomPinning`, :class:`Disorder`, :class:`GridFile` (``kind = "grid"``) and
:class:`EdgeStrayField` (the film's edge stray field, :mod:`skygas.fields.landscape.stray_field`).
Pass them to :class:`~skygas.engine.Simulation` as ``landscape=[...]``, or list them in a TOML
configuration as ``[[potentials]]``. Several terms add. See ``docs/landscapes.md``.
"""

from skygas.fields.landscape.field import LandscapeField
from skygas.fields.landscape.kinds import (
    KINDS,
    Band,
    Disorder,
    EdgeStrayField,
    Gaussian,
    GridFile,
    Periodic,
    Potential,
    RandomPinning,
)

__all__ = [
    "KINDS",
    "Band",
    "Disorder",
    "EdgeStrayField",
    "Gaussian",
    "GridFile",
    "LandscapeField",
    "Periodic",
    "Potential",
    "RandomPinning",
    "parse_potentials",
]


def parse_potentials(potentials) -> list:
    """Potentials given as objects or as mappings with a ``kind`` (TOML tables), validated.

    A bad one raises :class:`~skygas.core.errors.InputError` naming its field.
    """
    from pydantic import TypeAdapter, ValidationError

    from skygas.core.config_types import to_input_error
    from skygas.core.errors import require

    potentials = [] if potentials is None else list(potentials)
    for k, p in enumerate(potentials):
        require(
            isinstance(p, (dict, *KINDS.values())),
            f"potentials.{k}",
            p,
            f"a table with kind = one of {sorted(KINDS)}",
        )
    try:
        return TypeAdapter(list[Potential]).validate_python(potentials)
    except ValidationError as err:
        raise to_input_error(err, "", prefix="potentials") from None
