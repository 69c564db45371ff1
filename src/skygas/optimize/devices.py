"""The devices a study can optimise: the registry's kinds with study hooks, and a test function.

Each is a :class:`~skygas.devices.study_hooks.StudyPoints`: its configuration model, the summary
quantities a run returns (what objectives and constraints may use, checked before anything
runs), how the base configuration and a trial's parameters make one run's validated
configuration, how a run is priced and run. Every kind of the registry that a sweep can run
(:func:`skygas.devices.registry.study_kinds`, by its name in study files) can be optimised, and:

- ``analytic``: :mod:`skygas.optimize.analytic`, a known function for checking a study.
"""

from __future__ import annotations

from skygas.core.errors import require
from skygas.devices.study_hooks import StudyPoints

#: The known test function (not a device of the registry: it runs nothing).
ANALYTIC = StudyPoints("skygas.optimize.analytic")


def devices() -> dict[str, StudyPoints]:
    """The devices a study can name, by name (each kind once, under its name in study files)."""
    from skygas.devices.registry import study_kinds

    found = {k.study.name: k.study for k in study_kinds().values() if k.study is not None}
    return {**found, ANALYTIC.name: ANALYTIC}


def device(name: object) -> StudyPoints:
    """The device called ``name`` (one of :func:`devices`), refused in one line otherwise."""
    known = devices()
    require(name in known, "study.device", name, f"one of {', '.join(known)}")
    assert isinstance(name, str)  # one of the names
    return known[name]


def field_exists(dev: StudyPoints, dotted: str) -> bool:
    """Whether ``dotted`` is a field of ``dev``'s configuration."""
    from skygas.sweep.spec import field_exists as exists

    return exists(dev.model(), dotted)
