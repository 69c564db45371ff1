"""Sweep files: which configurations of a device to run, how often, and with which seeds.

A sweep file is TOML with three parts::

    [sweep]
    device = "reshuffler"  # the kind of run: reshuffler (default), neuron, reservoir, simulate
    seed = 2024          # root seed; every run's seed is derived from it
    replicas = 4         # independent runs (different seeds) per point

    [base]               # the device's configuration, as its command reads it
    preset = "paper"
    duration = 4e-5

    [grid]               # dotted config fields → values; the points are their Cartesian product
    current_density = { start = 1e11, stop = 3.8e11, num = 8, spacing = "log" }
    "signal.p" = [0.2, 0.35, 0.5, 0.62, 0.8]

Instead of ``[grid]`` an explicit list of points may be given as ``[[points]]`` tables, each
setting the same fields (``[[points]]`` with ``current_density = 1e11`` and ``"signal.p" = 0.3``,
and so on). ``[sweep] config = "file.toml"`` may name the base configuration (relative to
the sweep file; its seed is set aside), and ``[base]`` then changes it.

Seeds (counter-based noise, docs/engine.md):
``SeedSequence(seed).spawn(n_points)[i].spawn(replicas)[r]`` gives run (point ``i`` in C order of
the grid, replica ``r``); its 63-bit ``seed`` is the
first word of that sequence's state (modulo the kind's seed limit, :class:`~skygas.devices.
study.StudyPoints`). A run's result therefore depends only on the sweep file, never on which
worker ran it or when.

The device is any kind of the registry that a study can run (:func:`skygas.devices.registry.
study_kind`); its study hooks build, price and run each point. Everything is checked here,
before anything runs: each field must exist in the device's configuration, each list must be
non-empty, and every point's configuration is built and validated.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import tomllib
import typing
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import BaseModel

from skygas.core.errors import InputError, require
from skygas.core.resources import require_memory
from skygas.devices.registry import DEFAULT_STUDY_DEVICE, DeviceKind, study_kind
from skygas.devices.study_hooks import StudyPoints
from skygas.runs.config import read_toml, resolve_paths

_SWEEP_KEYS = {"seed", "replicas", "config", "name", "description", "device"}
#: The device of a sweep file that names none.
DEFAULT_DEVICE = DEFAULT_STUDY_DEVICE
_TOP_KEYS = {"sweep", "base", "grid", "points"}
# fields whose value is a whole table or a name, never descended into
_LEAF_FIELDS = {"material"}
# derived per run; sweeping it would defeat the seed derivation
_RESERVED = {"seed"}
#: Bytes a sweep holds per run before any runs: its validated configuration and record.
BYTES_PER_RUN = 16 * 2**10


@dataclass(frozen=True)
class Run:
    """One run of a sweep: point ``index`` (a tuple over the sweep dimensions), ``replica``."""

    index: tuple[int, ...]
    replica: int
    seed: int
    config: Any  # the device's validated configuration (a pydantic model)


@dataclass(frozen=True)
class Sweep:
    """A validated sweep.

    ``fields`` are the swept dotted config fields, ``dims`` their dimension names in the store
    (``"signal.p"`` → ``"signal_p"``); ``values[k]`` the values of ``fields[k]``. For a grid
    the shape is ``(len(values[0]), …)``; for an explicit list there is one dimension
    ``point`` and ``values[k]`` lists field ``k`` at each point. ``device`` is the kind's
    name in study files; ``quantities`` the numbers each run stores and ``curves`` the curves
    with their lengths (the kind's :class:`~skygas.devices.study_hooks.StudyPoints`).
    """

    fields: tuple[str, ...]
    dims: tuple[str, ...]
    values: tuple[tuple[Any, ...], ...]
    layout: str  # "grid" or "list"
    replicas: int
    root_seed: int
    base: dict
    source_text: str
    runs: tuple[Run, ...]
    device: str = DEFAULT_DEVICE
    quantities: tuple[str, ...] = ()
    curves: tuple[tuple[str, int], ...] = ()

    @property
    def kind(self) -> DeviceKind:
        """The kind of run it sweeps."""
        return study_kind(self.device)

    @property
    def points(self) -> StudyPoints:
        """Its kind's study hooks."""
        hooks = self.kind.study
        assert hooks is not None  # study_kind returns only kinds with hooks
        return hooks

    @property
    def shape(self) -> tuple[int, ...]:
        """The shape of the points: one dimension per field for a grid, ``(points,)`` for a list."""
        if self.layout == "list":
            return (len(self.values[0]),)
        return tuple(len(v) for v in self.values)

    @property
    def point_dims(self) -> tuple[str, ...]:
        """The store's dimensions of a point: ``("point",)`` for a list, else :attr:`dims`."""
        return ("point",) if self.layout == "list" else self.dims

    @property
    def n_points(self) -> int:
        """The number of swept points (replicas not counted)."""
        return math.prod(self.shape)

    def fingerprint(self) -> str:
        """Hash of every run's resolved configuration and seed (not of the file's text).

        So a store can tell whether it was written by the same sweep.
        """
        digest = hashlib.sha256()
        head: list[Any] = [self.fields, self.layout, self.replicas]
        if self.device != DEFAULT_DEVICE:  # the reshuffler's stores keep their fingerprints
            head.append(self.device)
        digest.update(json.dumps(head).encode())
        for run in self.runs:
            digest.update(run.config.model_dump_json().encode())
        return digest.hexdigest()[:20]


def dim_name(field: str) -> str:
    """The store's dimension name of a dotted config field (``"signal.p"`` → ``"signal_p"``)."""
    return field.replace(".", "_")


def _models_in(annotation: Any) -> list[type[BaseModel]]:
    """The pydantic models an annotation holds (``list[A | B]`` → ``[A, B]``)."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    return [m for arg in typing.get_args(annotation) for m in _models_in(arg)]


def field_exists(model: type[BaseModel], dotted: str) -> bool:
    """Whether the dotted field ``dotted`` (``"device.chamber_diameter"``) exists in ``model``.

    ``potentials.<index>.<field>`` names a field of any potential kind, and so for any list of
    tables (``inputs.0.rate``: a field of any kind of input); a table-valued field such as
    ``material`` is a leaf (set as a whole, never descended into).
    """
    head, _, rest = dotted.partition(".")
    info = model.model_fields.get(head)
    if info is None:
        return False
    if not rest:
        return True
    if head in _LEAF_FIELDS:
        return False
    if head == "potentials":  # "potentials.<index>.<field of a potential kind>"
        from skygas.fields.landscape import KINDS

        index, _, name = rest.partition(".")
        return index.isdigit() and any(name in kind.model_fields for kind in KINDS.values())
    sub = info.annotation
    if typing.get_origin(sub) in (list, tuple):  # "<list>.<index>.<field of any of its kinds>"
        index, _, name = rest.partition(".")
        return index.isdigit() and any(field_exists(m, name) for m in _models_in(sub))
    return isinstance(sub, type) and issubclass(sub, BaseModel) and field_exists(sub, rest)


_field_exists = field_exists


def _expand_range(key: str, spec: dict) -> list[float]:
    allowed = '{start, stop, num >= 1, spacing = "linear" | "log"}'
    unknown = set(spec) - {"start", "stop", "num", "spacing"}
    require(not unknown, f"grid.{key}", spec, allowed)
    num = spec.get("num")
    require(
        isinstance(num, int) and not isinstance(num, bool),
        f"grid.{key}.num",
        num,
        "a whole number of values",
    )
    assert isinstance(num, int)  # checked just above
    require(num >= 1, f"grid.{key}.num", num, "at least 1 value (the range is empty)")
    require_memory(
        f"grid.{key}.num",
        num,
        BYTES_PER_RUN * num,
        f"a sweep of at least {num:.3g} runs",
        "sweep fewer values",
    )
    start, stop = spec.get("start"), spec.get("stop")
    for name, v in (("start", start), ("stop", stop)):
        require(
            isinstance(v, (int, float)) and not isinstance(v, bool),
            f"grid.{key}.{name}",
            v,
            "a number",
        )
    assert isinstance(start, (int, float)) and isinstance(stop, (int, float))  # checked above
    spacing = spec.get("spacing", "linear")
    require(spacing in ("linear", "log"), f"grid.{key}.spacing", spacing, '"linear" or "log"')
    if spacing == "log":
        require(start > 0 and stop > 0, f"grid.{key}", spec, "start, stop > 0 for log spacing")
        return [float(v) for v in np.geomspace(start, stop, num)]
    return [float(v) for v in np.linspace(start, stop, num)]


def _check_field(key: str, where: str, hooks: StudyPoints) -> None:
    require(
        isinstance(key, str) and key not in _RESERVED,
        f"{where}.{key}",
        key,
        "a configuration field other than seed (seeds are derived from [sweep] seed)",
    )
    require(
        field_exists(hooks.model(), key),
        f"{where}.{key}",
        key,
        f"a field of the {hooks.name} configuration (e.g. {hooks.example_fields})",
    )


def _check_value(key: str, value: Any, where: str) -> None:
    require(
        isinstance(value, (int, float, str, bool, dict)),
        f"{where}.{key}",
        value,
        "a number, a string, a boolean or a table",
    )


#: ``check_field(key, where)``: refuses (InputError) a key that is not a field of the study's
#: configuration; ``where`` is the table it stands in (``"grid"``, ``"points[0]"``).
FieldCheck = Callable[[str, str], None]


def parse_grid(data: dict, check_field: FieldCheck) -> tuple[list[str], list[list[Any]]]:
    """A ``[grid]`` table's fields and each one's values, each field checked by ``check_field``.

    A field's values are a list or a ``{start, stop, num}`` range, of distinct numbers,
    strings, booleans or tables.
    """
    require(
        isinstance(data, dict) and bool(data),
        "grid",
        data,
        "a table of dotted config fields, each with a list or a {start, stop, num} range",
    )
    fields, values = [], []
    for key, spec in data.items():
        check_field(key, "grid")
        if isinstance(spec, dict) and key not in _LEAF_FIELDS:
            vals = _expand_range(key, spec)
        elif isinstance(spec, list):
            require(len(spec) > 0, f"grid.{key}", spec, "a non-empty list of values")
            vals = spec
        else:
            raise InputError(f"grid.{key}", spec, "a list of values or a {start, stop, num} range")
        for v in vals:
            _check_value(key, v, "grid")
        require(
            len({json.dumps(v, sort_keys=True) for v in vals}) == len(vals),
            f"grid.{key}",
            spec,
            "distinct values",
        )
        fields.append(key)
        values.append(list(vals))
    return fields, values


def parse_points(data: list, check_field: FieldCheck) -> tuple[list[str], list[list[Any]]]:
    """The fields of ``[[points]]`` tables and each one's value at every point.

    Every point sets the same fields, each checked by ``check_field``.
    """
    require(
        isinstance(data, list) and len(data) > 0 and all(isinstance(p, dict) for p in data),
        "points",
        data,
        "a non-empty array of tables ([[points]])",
    )
    fields = list(data[0])
    require(len(fields) > 0, "points[0]", data[0], "at least one field")
    for key in fields:
        check_field(key, "points[0]")
    values: list[list[Any]] = [[] for _ in fields]
    for i, point in enumerate(data):
        require(
            list(point) == fields and set(point) == set(fields),
            f"points[{i}]",
            point,
            f"the same fields as points[0] ({', '.join(fields)})",
        )
        for k, key in enumerate(fields):
            _check_value(key, point[key], f"points[{i}]")
            values[k].append(point[key])
    return fields, values


def base_config(
    data: dict, head: str, base_dir: Path | None, default: dict, device: str = "device"
) -> dict:
    """The base configuration of a sweep or study file: ``[HEAD] config = FILE`` and/or ``[base]``.

    ``[HEAD] config`` names a configuration file (relative to the file's folder ``base_dir``);
    its own ``seed`` is set aside, as each run's seed is derived from the file's root seed.
    ``[base]`` is the configuration itself, or, with a file, what changes in it (tables merged
    key by key, a list replaced whole). File names in either are made relative to their own
    file's folder; a seed in ``[base]`` is refused.
    """
    table = data.get(head, {})
    given = data.get("base", default if "config" not in table else {})
    require(isinstance(given, dict), "base", given, f"a {device} configuration table")
    require(
        "seed" not in given,
        "base.seed",
        given.get("seed"),
        f"no seed in [base]: runs get seeds derived from [{head}] seed",
    )
    if base_dir is not None:  # file names in [base] are relative to the sweep file
        given = resolve_paths(given, base_dir)
    if "config" not in table:
        return given
    path = Path(table["config"])
    if not path.is_absolute() and base_dir is not None:
        path = base_dir / path
    from_file = resolve_paths(read_toml(path, f"{head}.config"), path.parent)
    from_file.pop("seed", None)  # runs get seeds derived from the root seed
    return _merged(from_file, given)


def _merged(into: dict, changes: dict) -> dict:
    """``into`` with ``changes`` set: tables merged key by key, anything else replaced."""
    out = dict(into)
    for key, value in changes.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = _merged(out[key], value)
        else:
            out[key] = value
    return out


def point_config(base: dict, overrides: dict[str, Any], what: str = "sweep point") -> Any:
    """The validated configuration of one reshuffler point (the reshuffler's study hook).

    :func:`skygas.reshuffler.study_points.point`; a sweep of another device uses its own.
    """
    hooks = study_kind(DEFAULT_DEVICE).study
    assert hooks is not None  # the reshuffler has study hooks
    return hooks.point(base, overrides, what)


def derive_seeds(root_seed: int, n_points: int, replicas: int) -> np.ndarray:
    """``seeds[i, r]``: the 63-bit seed of replica ``r`` of point ``i`` (C order)."""
    seeds = np.empty((n_points, replicas), dtype=np.int64)
    for i, point in enumerate(np.random.SeedSequence(root_seed).spawn(n_points)):
        for r, child in enumerate(point.spawn(replicas)):
            seeds[i, r] = int(child.generate_state(1, dtype=np.uint64)[0] >> np.uint64(1))
    return seeds


def parse_sweep(data: dict, source_text: str = "", base_dir: Path | None = None) -> Sweep:
    """Validate a parsed sweep file and build (without running) every run's configuration."""
    unknown = set(data) - _TOP_KEYS
    require(
        not unknown,
        ", ".join(sorted(unknown)),
        sorted(data),
        "only the tables [sweep], [base], [grid] or [[points]]",
    )
    head = data.get("sweep", {})
    require(isinstance(head, dict), "sweep", head, "a table")
    extra = set(head) - _SWEEP_KEYS
    require(
        not extra,
        f"sweep.{next(iter(sorted(extra)))}" if extra else "sweep",
        head,
        f"only the keys {', '.join(sorted(_SWEEP_KEYS))}",
    )
    replicas = head.get("replicas", 1)
    require(
        isinstance(replicas, int) and not isinstance(replicas, bool),
        "sweep.replicas",
        replicas,
        "a whole number of replicas",
    )
    require(replicas >= 1, "sweep.replicas", replicas, "at least 1 replica per point")
    kind = study_kind(head.get("device", DEFAULT_DEVICE))
    hooks = kind.study
    assert hooks is not None  # study_kind returns only kinds with hooks
    root_seed = head.get("seed", 0)
    require(
        isinstance(root_seed, int) and not isinstance(root_seed, bool) and root_seed >= 0,
        "sweep.seed",
        root_seed,
        "a whole number >= 0",
    )

    base = base_config(data, "sweep", base_dir, hooks.default_base, hooks.name)

    has_grid, has_points = "grid" in data, "points" in data
    require(
        has_grid != has_points,
        "grid",
        "both or neither given",
        "exactly one of [grid] or [[points]]",
    )
    layout = "grid" if has_grid else "list"

    def check(key: str, where: str) -> None:
        _check_field(key, where, hooks)

    fields, values = (
        parse_grid(data["grid"], check) if has_grid else parse_points(data["points"], check)
    )
    n_runs = replicas * (math.prod(len(v) for v in values) if has_grid else len(values[0]))
    require_memory(  # before the points are expanded: the runs are counted from the grid
        "grid" if has_grid else "points",
        f"{n_runs:.3g} runs",
        BYTES_PER_RUN * n_runs,
        f"a sweep of {n_runs:.3g} runs ({replicas} replicas per point)",
        "sweep fewer values or fewer replicas, or split the sweep",
    )

    if layout == "grid":
        combos = list(itertools.product(*[list(enumerate(v)) for v in values]))
        indexed = [(tuple(i for i, _ in c), [v for _, v in c]) for c in combos]
    else:
        indexed = [
            ((i,), [values[k][i] for k in range(len(fields))]) for i in range(len(values[0]))
        ]
    seeds = derive_seeds(root_seed, len(indexed), replicas)
    if hooks.seed_limit < 2**63:  # the kind derives seeds of its own from a run's seed
        seeds %= hooks.seed_limit
    runs = []
    quantities: dict[str, None] = dict.fromkeys(hooks.quantities)
    curves: dict[str, int] = {}
    for flat, (index, point_values) in enumerate(indexed):
        config = hooks.point(base, dict(zip(fields, point_values, strict=True)), "sweep point")
        quantities.update(dict.fromkeys(hooks.extra_quantities(config)))
        for name, length in hooks.curves(config).items():
            curves[name] = max(curves.get(name, 0), length)
        for r in range(replicas):
            runs.append(
                Run(
                    index,
                    r,
                    int(seeds[flat, r]),
                    config.model_copy(update={"seed": int(seeds[flat, r])}),
                )
            )
    return Sweep(
        tuple(fields),
        tuple(dim_name(f) for f in fields),
        tuple(tuple(v) for v in values),
        layout,
        replicas,
        root_seed,
        base,
        source_text,
        tuple(runs),
        hooks.name,
        tuple(quantities),
        tuple(curves.items()),
    )


def load_sweep(path: str | Path, settings: list[str] | None = None) -> Sweep:
    """Read and validate a sweep file (see the module docstring).

    ``settings`` (``skygas sweep --set``) change the file before it is validated, each
    ``TABLE.KEY=VALUE`` with a TOML value: ``sweep.replicas=2``, ``base.duration=1e-5``,
    ``base.output.trajectory_window=0.0``, ``grid.signal.p=[0.2, 0.8]`` (after ``grid.``
    the rest is the swept field). They are appended to the recorded file text as comments, so
    a store records them and a store written without them is not resumed with them.
    """
    path = Path(path)
    data = read_toml(path, "sweep file")
    text = path.read_text()
    for setting in settings or []:
        _apply_setting(data, setting)
        text += f"\n# --set {setting}"
    return parse_sweep(data, text, path.parent)


def _apply_setting(data: dict, setting: str) -> None:
    key, sep, raw = setting.partition("=")
    key = key.strip()
    table, _, rest = key.partition(".")
    require(
        bool(sep and table in ("sweep", "base", "grid") and rest),
        "--set",
        setting,
        "TABLE.KEY=VALUE with TABLE one of sweep, base, grid (e.g. base.duration=1e-5)",
    )
    try:
        value = tomllib.loads(f"v = {raw.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        raise InputError(
            "--set",
            setting,
            "a TOML value after = (a number, a quoted string, "
            "a list [...] or an inline table {...})",
        ) from None
    node = data.setdefault(table, {})
    parts = [rest] if table == "grid" else rest.split(".")
    for part in parts[:-1]:
        node = node.setdefault(part, {})
        require(isinstance(node, dict), "--set", setting, f"{part} to be a table")
    node[parts[-1]] = value
