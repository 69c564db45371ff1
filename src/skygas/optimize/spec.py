"""Study files: which device to improve, over which parameters, towards which objectives.

A study file is TOML::

    [study]
    device = "reshuffler"      # reshuffler | neuron | reservoir | simulate | analytic
    seed = 1                   # root seed: the sampler's and every run's seed derive from it
    replicas = 2               # runs (different seeds) per trial; objectives are their mean
    sampler = "tpe"            # tpe | nsga2 | gp | random (default: tpe, nsga2 for several
                               # objectives)
    startup_trials = 10        # random trials before the model is used (nsga2: population)
    constraints = ["throughput_Hz >= 1.9e8"]   # each EXPRESSION < NUMBER (or <=, >, >=)
    reevaluate = 3             # best candidates run again at the end ...
    reevaluate_replicas = 4    # ... with this many more replicas each

    [base]                     # the device's configuration, as in a sweep file
    preset = "paper"
    duration = 4e-6

    [space]                    # dotted config fields → their range or choices
    current_density = { low = 1e11, high = 4e11, log = true }
    "device.conduit_width" = { low = 6e-8, high = 1.6e-7 }
    "rule.threshold" = { low = 4, high = 20 }          # whole numbers: an int parameter
    "signal.kind" = { choices = ["telegraph", "bernoulli"] }

    [[objectives]]
    expression = "correlation"     # a summary quantity or an expression of several
    direction = "minimize"         # or "maximize"

``[study] config = "file.toml"`` may name the base configuration instead of ``[base]``, as in a
sweep file. Any field a sweep may vary may be searched (:func:`skygas.sweep.spec.field_exists`
on the device's configuration model); a range's ends that are both whole numbers make an int
parameter, ``log = true`` a log-uniform one, ``step`` a grid of steps.

Everything is checked here, before anything runs: the fields, the ranges (not empty, a log
range above 0), the objectives and constraints against the device's summary quantities
(:mod:`skygas.optimize.devices`), constraints that contradict each other, and the configuration
at every corner of the space (each parameter at its ends and each of its choices) is built and
validated as a run's would be.

Seeds: run ``r`` of trial ``k`` has seed ``SeedSequence([seed, k, 0]).spawn(replicas)[r]``
(re-evaluation runs ``SeedSequence([seed, k, 1])``), its 63-bit state word as in a sweep
(:func:`skygas.sweep.spec.derive_seeds`; for the reservoir, modulo its
:attr:`~skygas.optimize.devices.Device.seed_limit`): a trial's runs depend only on the study
and its number.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import BaseModel

from skygas.core.errors import InputError, require
from skygas.devices.study_hooks import StudyPoints
from skygas.optimize.devices import device, field_exists
from skygas.optimize.expressions import (
    Constraint,
    Expression,
    check_consistent,
    parse_constraint,
    parse_expression,
)
from skygas.runs.config import read_toml

_STUDY_KEYS = {
    "device",
    "seed",
    "replicas",
    "sampler",
    "startup_trials",
    "constraints",
    "reevaluate",
    "reevaluate_replicas",
    "config",
    "name",
    "description",
}
_TOP_KEYS = {"study", "base", "space", "objectives"}
SAMPLERS = ("tpe", "nsga2", "gp", "random")
_DIRECTIONS = {"minimize": "minimize", "minimise": "minimize", "maximize": "maximize"}
_DIRECTIONS["maximise"] = "maximize"
#: at most this many corners of the space are built and checked (else each parameter's ends)
MAX_CORNERS = 256
#: Most trials a study runs (``--trials``, ``startup_trials``): the sampler weighs every earlier
#: trial at each proposal, and the journal holds them all.
MAX_TRIALS = 100_000
#: Most runs per trial (``replicas``), candidates re-evaluated (``reevaluate``) and runs per
#: candidate (``reevaluate_replicas``): a mean's error shrinks only as 1/√runs.
MAX_REPLICAS = 1000


@dataclass(frozen=True)
class Parameter:
    """One searched field: a float or int range (``log``, ``step``) or a list of ``choices``."""

    field: str
    kind: str  # "float", "int" or "categorical"
    low: float | int | None = None
    high: float | int | None = None
    log: bool = False
    step: float | int | None = None
    choices: tuple[Any, ...] = ()

    def distribution(self):
        """The parameter's optuna distribution."""
        import optuna

        if self.kind == "categorical":
            return optuna.distributions.CategoricalDistribution(self.choices)
        if self.kind == "int":
            assert isinstance(self.low, int) and isinstance(self.high, int)
            return optuna.distributions.IntDistribution(
                self.low, self.high, log=self.log, step=int(self.step or 1)
            )
        assert self.low is not None and self.high is not None
        return optuna.distributions.FloatDistribution(
            float(self.low), float(self.high), log=self.log, step=self.step
        )

    def ends(self) -> list[Any]:
        """The values a corner of the space takes: the range's ends, or every choice."""
        return list(self.choices) if self.kind == "categorical" else [self.low, self.high]

    def describe(self) -> dict:
        """A JSON-able description (recorded in the study folder)."""
        if self.kind == "categorical":
            return {"field": self.field, "kind": self.kind, "choices": list(self.choices)}
        return {
            "field": self.field,
            "kind": self.kind,
            "low": self.low,
            "high": self.high,
            "log": self.log,
            "step": self.step,
        }


@dataclass(frozen=True)
class Objective:
    """An objective: a name, its expression and ``"minimize"`` or ``"maximize"``."""

    name: str
    expression: Expression
    direction: str


@dataclass(frozen=True)
class Study:
    """A validated study file (see the module docstring)."""

    device: StudyPoints
    seed: int
    replicas: int
    sampler: str
    startup_trials: int
    parameters: tuple[Parameter, ...]
    objectives: tuple[Objective, ...]
    constraints: tuple[Constraint, ...]
    reevaluate: int
    reevaluate_replicas: int
    base: dict
    source_text: str
    name: str = ""

    @property
    def multi_objective(self) -> bool:
        """Whether the study has several objectives (a Pareto front rather than one best)."""
        return len(self.objectives) > 1

    def config(self, params: dict[str, Any], seed: int = 0) -> BaseModel:
        """The validated configuration of one run: the base with ``params`` set, and ``seed``."""
        built = self.device.point(self.base, dict(params), "trial")
        return built.model_copy(update={"seed": int(seed)})

    def run_seeds(self, key: int, replicas: int, stage: int = 0) -> list[int]:
        """The seeds of the runs of trial ``key`` (``stage`` 1: its re-evaluation's)."""
        children = np.random.SeedSequence([self.seed, key, stage]).spawn(replicas)
        words = [int(c.generate_state(1, dtype=np.uint64)[0] >> np.uint64(1)) for c in children]
        return [w % self.device.seed_limit for w in words]

    def describe(self) -> dict:
        """What defines the trials (the fingerprint's content; re-evaluation is not in it)."""
        return {
            "device": self.device.name,
            "seed": self.seed,
            "replicas": self.replicas,
            "sampler": self.sampler,
            "startup_trials": self.startup_trials,
            "parameters": [p.describe() for p in self.parameters],
            "objectives": [
                {"name": o.name, "expression": o.expression.text, "direction": o.direction}
                for o in self.objectives
            ],
            "constraints": [c.text for c in self.constraints],
            "base": self.base,
        }

    def fingerprint(self) -> str:
        """A hash of :meth:`describe`: a study folder only resumes the study that made it."""
        text = json.dumps(self.describe(), sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:20]


def _whole(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _parameter(field: str, spec: Any) -> Parameter:
    where = f"space.{field}"
    allowed = "{low, high} (log = true, step = …) or {choices = [...]}"
    require(isinstance(spec, dict), where, spec, allowed)
    if "choices" in spec:
        require(set(spec) == {"choices"}, where, spec, "only choices = [...] with choices")
        choices = spec["choices"]
        require(
            isinstance(choices, list) and len(choices) > 0,
            f"{where}.choices",
            choices,
            "a non-empty list of values",
        )
        require(
            all(isinstance(c, (str, int, float, bool)) for c in choices),
            f"{where}.choices",
            choices,
            "numbers, strings or booleans",
        )
        require(
            len(set(map(repr, choices))) == len(choices),
            f"{where}.choices",
            choices,
            "distinct values",
        )
        return Parameter(field, "categorical", choices=tuple(choices))
    unknown = set(spec) - {"low", "high", "log", "step"}
    require(not unknown, f"{where}.{next(iter(sorted(unknown)), '')}", spec, allowed)
    low, high = spec.get("low"), spec.get("high")
    for name, v in (("low", low), ("high", high)):
        require(_number(v), f"{where}.{name}", v, "a finite number")
    assert isinstance(low, (int, float)) and isinstance(high, (int, float))  # checked above
    require(
        math.isfinite(float(high) - float(low)),
        where,
        spec,
        "a range whose width high − low is a finite number (this one's overflows)",
        "give the range the field can take",
    )
    require(
        low < high,
        where,
        spec,
        "low < high (the range is empty)",
        "widen it, or set the field in [base]",
    )
    log = spec.get("log", False)
    require(isinstance(log, bool), f"{where}.log", log, "true or false")
    if log:
        require(
            low > 0,
            where,
            spec,
            "low > 0 for a log range (a log range cannot reach or cross 0)",
            "raise low above 0, or drop log = true",
        )
    step = spec.get("step")
    kind = "int" if _whole(low) and _whole(high) and (step is None or _whole(step)) else "float"
    if step is not None:
        require(_number(step) and step > 0, f"{where}.step", step, "a number > 0")
        require(not log, where, spec, "either log = true or a step, not both")
        require(
            step <= high - low, f"{where}.step", step, f"a step at most high − low = {high - low:g}"
        )
    if kind == "float":
        low, high = float(low), float(high)
    return Parameter(field, kind, low, high, log, step)


def _middle(p: Parameter) -> Any:
    """A value inside ``p``'s range (its first choice): the other ends are tried from it."""
    if p.kind == "categorical":
        return p.choices[0]
    assert p.low is not None and p.high is not None  # a range has both
    if p.log:
        middle = math.sqrt(float(p.low)) * math.sqrt(float(p.high))
    else:
        middle = 0.5 * float(p.low) + 0.5 * float(p.high)
    return int(round(middle)) if p.kind == "int" else middle


def _reference(study: Study) -> dict[str, Any] | None:
    """The point the ends are tried from: the space's middle, else the base (None: neither)."""
    for point in ({p.field: _middle(p) for p in study.parameters}, {}):
        try:
            study.device.point(study.base, point, "[space]")
        except InputError:
            continue
        return point
    return None


def _check_ends(study: Study) -> None:
    """Refuse a range whose end the device's configuration refuses, naming that end.

    Each parameter goes to each of its ends (or choices) while the others sit in the middle of
    their ranges (or, if the configuration refuses that point, at the base's values); a point
    refused there is the end's fault. Where neither is accepted, the corners name the
    combination.
    """
    reference = _reference(study)
    if reference is None:
        return
    for p in study.parameters:
        names = ["choices"] * len(p.choices) if p.kind == "categorical" else ["low", "high"]
        for name, value in zip(names, p.ends(), strict=True):
            try:
                study.device.point(study.base, {**reference, p.field: value}, "end of [space]")
            except InputError as err:
                raise InputError(
                    f"space.{p.field}.{name}",
                    value,
                    err.allowed
                    if err.field.endswith(p.field.rsplit(".", 1)[-1])
                    else f"a value the {study.device.name} configuration accepts ({err})",
                    "keep the search inside the field's own allowed values",
                ) from None


def _check_corners(study: Study) -> None:
    """Build and validate the configuration at the corners of the space (before any run)."""
    ends = [p.ends() for p in study.parameters]
    if math.prod(len(e) for e in ends) <= MAX_CORNERS:
        corners = [
            dict(zip([p.field for p in study.parameters], c, strict=True))
            for c in itertools.product(*ends)
        ]
    else:  # too many: each parameter at each of its ends, the others at their first
        first = {p.field: e[0] for p, e in zip(study.parameters, ends, strict=True)}
        corners = [
            {**first, p.field: v} for p, e in zip(study.parameters, ends, strict=True) for v in e
        ]
    for corner in corners:
        study.device.point(study.base, corner, "corner of [space]")


def parse_study(
    data: dict, source_text: str = "", base_dir: Path | None = None, seed: int | None = None
) -> Study:
    """Validate a parsed study file (see the module docstring).

    ``seed`` (``--seed``) overrides ``[study] seed``.
    """
    from skygas.sweep.spec import base_config

    unknown = set(data) - _TOP_KEYS
    require(
        not unknown,
        ", ".join(sorted(unknown)),
        sorted(data),
        "only the tables [study], [base], [space] and [[objectives]]",
    )
    head = data.get("study")
    require(isinstance(head, dict), "study", head, "a [study] table naming the device")
    assert isinstance(head, dict)  # checked just above
    extra = set(head) - _STUDY_KEYS
    require(
        not extra,
        f"study.{next(iter(sorted(extra)), '')}",
        head,
        f"only the keys {', '.join(sorted(_STUDY_KEYS))}",
    )
    dev = device(head.get("device"))
    counts = {}
    for key, default, least, most in (
        ("replicas", 1, 1, MAX_REPLICAS),
        ("startup_trials", 10, 1, MAX_TRIALS),
        ("reevaluate", 0, 0, MAX_REPLICAS),
        ("reevaluate_replicas", 4, 1, MAX_REPLICAS),
    ):
        value = head.get(key, default)
        require(
            _whole(value) and least <= value <= most,
            f"study.{key}",
            value,
            f"a whole number from {least} to {most}",
        )
        counts[key] = value
    root = head.get("seed", 0) if seed is None else seed
    require(
        _whole(root) and root >= 0,
        "--seed" if seed is not None else "study.seed",
        root,
        "a whole number >= 0",
    )

    base = base_config(data, "study", base_dir, dict(dev.default_base), dev.name)
    space = data.get("space")
    require(
        isinstance(space, dict) and bool(space),
        "space",
        space,
        "a [space] table of dotted config fields, each with {low, high} or {choices}",
    )
    assert isinstance(space, dict)  # checked just above
    parameters = []
    for field, spec in space.items():
        require(
            field != "seed",
            f"space.{field}",
            field,
            "a configuration field other than seed (seeds derive from [study] seed)",
        )
        require(
            field_exists(dev, field),
            f"space.{field}",
            field,
            f"a field of the {dev.name} configuration (as in [base], dotted: e.g. "
            f"{dev.example_fields})",
        )
        parameters.append(_parameter(field, spec))

    raw_objectives = data.get("objectives")
    require(
        isinstance(raw_objectives, list) and len(raw_objectives) > 0,
        "objectives",
        raw_objectives,
        "at least one [[objectives]] table with expression = … and direction = …",
    )
    assert isinstance(raw_objectives, list)  # checked just above
    objectives = []
    for i, raw in enumerate(raw_objectives):
        where = f"objectives[{i}]"
        require(isinstance(raw, dict), where, raw, "a table")
        extra = set(raw) - {"expression", "direction", "name"}
        require(
            not extra,
            f"{where}.{next(iter(sorted(extra)), '')}",
            raw,
            "only expression, direction, name",
        )
        expression = parse_expression(raw.get("expression"), f"{where}.expression", dev.quantities)
        direction = raw.get("direction", "minimize")
        require(
            direction in _DIRECTIONS, f"{where}.direction", direction, '"minimize" or "maximize"'
        )
        name = raw.get("name", expression.text)
        require(isinstance(name, str) and bool(name), f"{where}.name", name, "a name")
        objectives.append(Objective(name, expression, _DIRECTIONS[direction]))
    require(
        len({o.name for o in objectives}) == len(objectives),
        "objectives",
        [o.name for o in objectives],
        "objectives of distinct names",
    )

    raw_constraints = head.get("constraints", [])
    require(
        isinstance(raw_constraints, list),
        "study.constraints",
        raw_constraints,
        "a list of 'EXPRESSION < NUMBER'",
    )
    constraints = [
        parse_constraint(c, f"study.constraints[{i}]", dev.quantities)
        for i, c in enumerate(raw_constraints)
    ]
    check_consistent(constraints)

    sampler = head.get("sampler", "nsga2" if len(objectives) > 1 else "tpe")
    require(sampler in SAMPLERS, "study.sampler", sampler, f"one of {', '.join(SAMPLERS)}")
    if sampler == "gp":
        try:
            import torch  # noqa: F401 - optuna's Gaussian-process sampler runs on it
        except ImportError:
            raise InputError(
                "study.sampler",
                sampler,
                "a sampler whose packages are installed (the Gaussian-process sampler needs "
                "PyTorch)",
                "install torch (pip install torch, or skygas's micromagnetics extra), or use "
                'sampler = "tpe"',
            ) from None
    name = head.get("name", "")
    require(isinstance(name, str), "study.name", name, "a string")
    study = Study(
        dev,
        root,
        counts["replicas"],
        sampler,
        counts["startup_trials"],
        tuple(parameters),
        tuple(objectives),
        tuple(constraints),
        counts["reevaluate"],
        counts["reevaluate_replicas"],
        base,
        source_text,
        name,
    )
    _check_ends(study)
    _check_corners(study)
    return study


def load_study(path: str | Path, seed: int | None = None) -> Study:
    """Read and validate a study file (see the module docstring)."""
    path = Path(path)
    data = read_toml(path, "study file")
    try:
        text = path.read_text()
    except UnicodeDecodeError:  # read_toml has refused it already; kept for type checkers
        text = ""
    return parse_study(data, text, path.parent, seed)


def parse_study_text(text: str, base_dir: Path | None = None) -> Study:
    """A study from its TOML text (as recorded in a study folder)."""
    return parse_study(tomllib.loads(text), text, base_dir)
