"""What a study (a sweep or a search) needs of a kind of run: :class:`StudyPoints`.

A kind that can be swept and searched names, in the registry, one module of its own package
(``skygas.neuron.study_points``, …) that defines:

``NAME``
    The kind's name in study files (``[sweep] device = "neuron"``).
``QUANTITIES``
    The summary numbers every run of it returns (tuple of str; units in
    :mod:`skygas.core.quantities`).
``DEFAULT_BASE``
    The base configuration a study file without ``[base]`` uses (dict).
``model()``
    Its configuration class (pydantic).
``point(base, overrides, what)``
    One point's validated configuration: ``base`` with the dotted ``overrides`` set (the one
    override signature, :func:`~skygas.core.config_types.apply_overrides`), checked as its
    command checks it before building; an error names ``what`` and the point.
``estimate(config)``
    The :class:`~skygas.core.estimates.Estimate` of one run, before anything is built.
``run(config_json)``
    Run one configuration (its JSON) and return ``{quantity: float}`` (and each curve as an
    array): the function a study's worker calls. It imports what it needs when called, so a
    worker imports only its kind.

and, where it has them:

``extra_quantities(config)``
    Numbers that depend on the configuration (a census operation's counts), after
    ``QUANTITIES``.
``curves(config)``
    ``{name: length}`` of the curves a run returns (the reshuffler's running correlation).
``relative_cost(config)``
    A rough relative cost, used only to start the longest runs first (default: the estimate's
    seconds).
``SEED_LIMIT``
    Seeds are taken modulo this (default 2⁶³).
``PLOTTED``
    The quantities a sweep's figure draws first (default: :data:`QUANTITIES`' order).
``EXAMPLE_FIELDS``
    Fields a study typically varies, for messages (default: the configuration's first fields).

Importing this module (and the registry) imports no device: the module is imported when a
study first asks.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import import_module
from types import ModuleType
from typing import Any


@dataclass(frozen=True)
class StudyPoints:
    """A kind's study hooks, read from its module (see the module docstring)."""

    #: the module that defines them (``"skygas.neuron.study_points"``)
    module: str

    def _module(self) -> ModuleType:
        return import_module(self.module)

    @property
    def name(self) -> str:
        """Its name in study files."""
        return str(self._module().NAME)

    @property
    def quantities(self) -> tuple[str, ...]:
        """The summary numbers every run returns."""
        return tuple(self._module().QUANTITIES)

    @property
    def default_base(self) -> dict:
        """The base configuration of a study file without one."""
        return dict(self._module().DEFAULT_BASE)

    @property
    def seed_limit(self) -> int:
        """Seeds are taken modulo this."""
        return int(getattr(self._module(), "SEED_LIMIT", 2**63))

    @property
    def plotted(self) -> tuple[str, ...]:
        """The quantities a sweep's figure draws first."""
        return tuple(getattr(self._module(), "PLOTTED", self.quantities))

    @property
    def example_fields(self) -> str:
        """Fields a study typically varies, comma-separated (for messages)."""
        found = getattr(self._module(), "EXAMPLE_FIELDS", None)
        return str(found) if found else ", ".join(list(self.model().model_fields)[:6])

    def model(self) -> type[Any]:
        """Its configuration class."""
        return self._module().model()

    def point(self, base: dict, overrides: dict[str, Any], what: str) -> Any:
        """One point's validated configuration (``what`` names it in an error)."""
        return self._module().point(base, overrides, what)

    def estimate(self, config: Any) -> Any:
        """One run's :class:`~skygas.core.estimates.Estimate`."""
        return self._module().estimate(config)

    def extra_quantities(self, config: Any) -> tuple[str, ...]:
        """Numbers that depend on ``config``, after :attr:`quantities` (none by default)."""
        extra = getattr(self._module(), "extra_quantities", None)
        return tuple(extra(config)) if extra is not None else ()

    def all_quantities(self, config: Any) -> tuple[str, ...]:
        """:attr:`quantities`, then :meth:`extra_quantities`."""
        return (*self.quantities, *self.extra_quantities(config))

    def curves(self, config: Any) -> dict[str, int]:
        """``{name: length}`` of the curves a run of ``config`` returns (none by default)."""
        curves = getattr(self._module(), "curves", None)
        return dict(curves(config)) if curves is not None else {}

    def relative_cost(self, config: Any) -> float:
        """A rough relative cost of a run: which runs start first (default: the estimate)."""
        cost = getattr(self._module(), "relative_cost", None)
        return float(cost(config)) if cost is not None else float(self.estimate(config).seconds)


def run_point(module: str, config_json: str) -> dict:
    """Run one configuration of the kind whose hooks are in ``module`` (a worker's task)."""
    return import_module(module).run(config_json)
