"""Operations added to a run from its configuration: ``[[operations]]`` tables.

Every run configuration (``simulate``, ``reshuffle``, ``neuron``, ``reservoir``) takes a list of
operations, each a TOML table with a ``kind`` and a ``name`` (letters, digits, ``-``, ``_``;
unique in the run). Each is a *named* operation
(:class:`~skygas.engine.scheduler.NamedOperation`): its state is checkpointed and resumed
bit-identically, its ``summary()`` appears in the run's ``summary.json`` under
``"operations"`` and its ``data()`` in the run's netCDF file as variables
``<name>_<variable>``. No device knows about them.

Two kinds:

``census``
    counts the skyrmions present, in the whole device or within ``radius`` [m] of
    ``center`` [m], every ``interval`` [s] (:class:`Census`)::

        [[operations]]
        kind = "census"
        name = "chamber"
        interval = 1e-9
        center = [0.0, 0.0]
        radius = 200e-9

``python``
    the user's own operation: ``target`` names a callable as ``"package.module:name"`` or
    ``"file.py:name"`` (a file relative to the configuration's folder), called with the
    table's ``options`` as keyword arguments; it returns the operation (an object with
    ``next_step(step)`` and ``act(sim)``, docs/architecture.md), whose ``name`` is set to the
    table's ``name`` when it has none::

        [[operations]]
        kind = "python"
        name = "sensor"
        target = "my_sensors.py:Sensor"
        options = { every = 100 }

The target is imported when the configuration is validated, so a wrong name is one line
before any work.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal

import numpy as np
from pydantic import AfterValidator, Field, field_validator

from skygas.core.config_types import Length, PositiveFloat, StrictModel, register_union_tags
from skygas.core.errors import InputError
from skygas.engine.scheduler import OPERATION_NAME

if TYPE_CHECKING:
    from skygas.engine import Simulation


#: Names the devices' own operations use (the reshuffler's and the neuron's injector, the
#: neuron's annihilator and controller): a configuration's operation may not take them, in any
#: device, so that a configuration moves from one device to another unchanged.
RESERVED_NAMES = ("injector", "annihilator", "controller")


def _check_name(name: str) -> str:
    if not OPERATION_NAME.fullmatch(name):
        raise ValueError("letters, digits, '-' and '_'")
    if name.lower() in RESERVED_NAMES:
        raise ValueError(f"a name other than {', '.join(RESERVED_NAMES)} (the devices' own)")
    return name


#: An operation's name: it becomes part of checkpoint keys and of variable names.
OperationName = Annotated[str, AfterValidator(_check_name)]


class Census:
    """A sensor that counts the skyrmions present every ``every_steps`` steps.

    Parameters
    ----------
    name
        The operation's name (its key in checkpoints, summaries and result files).
    every_steps
        Steps between two counts (≥ 1).
    time_step
        The run's time step [s], to report the interval.
    center, radius
        Count only the skyrmions whose centre lies within ``radius`` [m] of ``center`` [m];
        ``None`` (both): the whole device.
    """

    def __init__(
        self,
        name: str,
        every_steps: int,
        time_step: float,
        center: tuple[float, float] | None = None,
        radius: float | None = None,
    ):
        self.name = name
        self.every_steps = max(1, int(every_steps))
        self.time_step = float(time_step)
        self.center = None if center is None else np.asarray(center, dtype=float)
        self.radius = radius
        self.times: list[float] = []
        self.counts: list[int] = []

    def next_step(self, step: int) -> int:
        """The next multiple of :attr:`every_steps` after ``step``."""
        return (step // self.every_steps + 1) * self.every_steps

    def act(self, sim: Simulation) -> None:
        """Count the skyrmions present (in the disk, if one was given)."""
        positions = sim.state.positions
        if self.center is not None and self.radius is not None:
            inside = np.hypot(*(positions - self.center).T) <= self.radius
            count = int(np.count_nonzero(inside))
        else:
            count = len(positions)
        self.times.append(sim.time)
        self.counts.append(count)

    def state_dict(self) -> dict[str, np.ndarray]:
        """The readings so far, as arrays."""
        return {
            "time": np.array(self.times, dtype=float),
            "count": np.array(self.counts, dtype=np.int64),
        }

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore the readings saved by :meth:`state_dict`."""
        self.times = [float(t) for t in state["time"]]
        self.counts = [int(n) for n in state["count"]]

    def summary(self) -> dict:
        """Number of readings, the interval [s] and the mean, least and largest count."""
        counts = np.array(self.counts)
        return {
            "kind": "census",
            "interval_s": self.every_steps * self.time_step,
            "readings": len(counts),
            **(
                {
                    "mean_count": float(counts.mean()),
                    "min_count": int(counts.min()),
                    "max_count": int(counts.max()),
                }
                if len(counts)
                else {}
            ),
        }

    def data(self) -> dict[str, tuple[tuple[str, ...], np.ndarray]]:
        """The readings for the result file: time [s] and count, along ``reading``."""
        return {
            "time": (("reading",), np.array(self.times, dtype=float)),
            "count": (("reading",), np.array(self.counts, dtype=np.int64)),
        }


class CensusSpec(StrictModel):
    """``kind = "census"``: count the skyrmions every ``interval`` [s] (:class:`Census`)."""

    kind: Literal["census"]
    name: OperationName
    interval: PositiveFloat
    center: tuple[float, float] | None = None
    radius: Length | None = None

    @field_validator("radius")
    @classmethod
    def _radius_needs_a_center(cls, radius, info):
        if radius is not None and info.data.get("center") is None:
            raise ValueError("a radius with a center = [x, y] [m]")
        return radius

    def build(self, sim: Simulation) -> Census:
        """The :class:`Census` of this table for ``sim`` (the interval rounded to steps)."""
        steps = max(1, int(round(self.interval / sim.time_step)))
        center = self.center if self.radius is not None else None
        return Census(self.name, steps, sim.time_step, center, self.radius)


def load_target(target: str) -> Callable[..., Any]:
    """The callable ``target`` names: ``"package.module:name"`` or ``"path/file.py:name"``.

    Raises
    ------
    ValueError
        If it is not of that form or cannot be imported (the message says why).
    """
    module_name, sep, attribute = target.rpartition(":")
    if not sep or not module_name or not attribute:
        raise ValueError("'package.module:name' or 'file.py:name'")
    try:
        if module_name.endswith(".py"):
            path = Path(module_name)
            if not path.is_file():
                raise ValueError(f"an existing file (there is no {path})")
            key = f"skygas_user_operation_{abs(hash(path.resolve()))}"
            module = sys.modules.get(key)
            if module is None:
                spec = importlib.util.spec_from_file_location(key, path)
                assert spec is not None and spec.loader is not None
                module = importlib.util.module_from_spec(spec)
                sys.modules[key] = module
                spec.loader.exec_module(module)
        else:
            module = importlib.import_module(module_name)
    except ValueError:
        raise
    except Exception as err:  # the user's module: any error in it is reported in one line
        raise ValueError(
            f"an importable module ({type(err).__name__}: {err})".replace("\n", " ")
        ) from None
    obj = getattr(module, attribute, None)
    if not callable(obj):
        raise ValueError(f"a callable named '{attribute}' in {module_name}")
    return obj


class PythonSpec(StrictModel):
    """``kind = "python"``: the user's operation, made by calling ``target(**options)``."""

    kind: Literal["python"]
    name: OperationName
    target: str
    options: dict[str, Any] = {}

    @field_validator("target")
    @classmethod
    def _importable(cls, target: str) -> str:
        load_target(target)
        return target

    def build(self, sim: Simulation) -> Any:
        """Call the target with the options; name the operation if it has no name."""
        try:
            op = load_target(self.target)(**self.options)
        except Exception as err:  # the user's code: one line naming the table
            raise InputError(
                f"operations.{self.name}.options",
                self.options,
                f"arguments that {self.target} accepts ({type(err).__name__}: {err})",
            ) from None
        for method in ("next_step", "act"):
            if not callable(getattr(op, method, None)):
                raise InputError(
                    f"operations.{self.name}.target",
                    self.target,
                    f"a callable that returns an operation (it has no {method}() method)",
                )
        if getattr(op, "name", None) is None:
            op.name = self.name
        return UserOperation(op, self.target)


class UserOperation:
    """The user's operation under the run loop's contract: its errors are one line.

    An exception in ``next_step``, ``act``, ``summary``, ``data``, ``state_dict`` or
    ``load_state_dict`` becomes an :class:`~skygas.core.errors.InputError` naming the
    operation, the method and the error (the CLI prints it as one line, exit status 2; under
    ``--debug`` the user's own traceback follows, chained); ``next_step`` must return a whole
    number. Optional methods stay optional: the wrapper has one only where the operation has.
    """

    _OPTIONAL = ("summary", "data", "state_dict", "load_state_dict")

    def __init__(self, op: Any, target: str):
        self.operation = op
        self.name = op.name
        self.target = target

    def _call(self, method: str, *args):
        try:
            return getattr(self.operation, method)(*args)
        except Exception as err:  # the user's code: one line naming the operation
            raise InputError(
                f"operations.{self.name}.{method}()",
                f"{type(err).__name__}: {err}",
                "to run without an error",
                f"the error is in {self.target}; rerun with --debug for its traceback",
            ) from err

    def next_step(self, step: int) -> int:
        """The operation's next step, checked to be a whole number."""
        when = self._call("next_step", step)
        if isinstance(when, bool) or not isinstance(when, (int, np.integer)):
            raise InputError(
                f"operations.{self.name}.next_step()",
                when,
                "a whole number of steps (the step at which it next acts)",
            )
        return int(when)

    def act(self, sim: Simulation) -> None:
        """The operation's action."""
        self._call("act", sim)

    def __getattr__(self, attr: str):
        if attr not in self._OPTIONAL:
            raise AttributeError(attr)
        getattr(self.operation, attr)  # AttributeError where the operation has none
        return lambda *args: self._call(attr, *args)


OperationSpec = Annotated[CensusSpec | PythonSpec, Field(discriminator="kind")]
register_union_tags(("census", "python"))


def build_operations(specs: Sequence[Any], sim: Simulation) -> list[Any]:
    """The operations of a configuration's ``[[operations]]`` tables, built for ``sim``."""
    return [spec.build(sim) for spec in specs]
