"""Sweep files: which reshuffler configurations to run, how often, and with which seeds.

A sweep file is TOML with three parts::

    [sweep]
    seed = 2024          # root seed; every run's seed is derived from it
    replicas = 4         # independent runs (different seeds) per point

    [base]               # a reshuffler configuration, as in ``skygas reshuffle CONFIG.toml``
    preset = "paper"
    duration = 4e-5

    [grid]               # dotted config fields → values; the points are their Cartesian product
    current_density = { start = 1e11, stop = 3.8e11, num = 8, spacing = "log" }
    "signal.p" = [0.2, 0.35, 0.5, 0.62, 0.8]

Instead of ``[grid]`` an explicit list of points may be given as ``[[points]]`` tables, each
setting the same fields (``[[points]]`` with ``current_density = 1e11`` and ``"signal.p" = 0.3``,
and so on). ``[sweep] config = "file.toml"`` may name the base configuration instead of
``[base]`` (relative to the sweep file).

Seeds (counter-based noise, docs/engine.md):
``SeedSequence(seed).spawn(n_points)[i].spawn(replicas)[r]`` gives run (point ``i`` in C order of
the grid, replica ``r``); its 63-bit ``seed`` is the
first word of that sequence's state. A run's result therefore depends only on the sweep file,
never on which worker ran it or when.

Everything is checked here, before anything runs: each field must exist in
:class:`~skygas.reshuffler.config.ReshufflerConfig`, each list must be non-empty, and every
point's configuration is built and validated.
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
from skygas.core.resources import require_memory
from skygas.reshuffler.config import (
    DEVICE_NAME,
    ReshufflerConfig,
    check_time_step,
    parse_reshuffler_config,
)
from skygas.reshuffler.device import ReshufflerGeometry
from skygas.runs.config import read_toml, resolve_paths

_SWEEP_KEYS = {"seed", "replicas", "config", "name", "description"}
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
    config: ReshufflerConfig


@dataclass(frozen=True)
class Sweep:
    """A validated sweep.

    ``fields`` are the swept dotted config fields, ``dims`` their dimension names in the store
    (``"signal.p"`` → ``"signal_p"``); ``values[k]`` the values of ``fields[k]``. For a grid
    the shape is ``(len(values[0]), …)``; for an explicit list there is one dimension
    ``point`` and ``values[k]`` lists field ``k`` at each point.
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
        digest.update(json.dumps([self.fields, self.layout, self.replicas]).encode())
        for run in self.runs:
            digest.update(run.config.model_dump_json().encode())
        return digest.hexdigest()[:20]


def dim_name(field: str) -> str:
    """The store's dimension name of a dotted config field (``"signal.p"`` → ``"signal_p"``)."""
    return field.replace(".", "_")


def field_exists(model: type[BaseModel], dotted: str) -> bool:
    """Whether the dotted field ``dotted`` (``"device.chamber_diameter"``) exists in ``model``.

    ``potentials.<index>.<field>`` names a field of any potential kind; a table-valued field
    such as ``material`` is a leaf (set as a whole, never descended into).
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


def _check_field(key: str, where: str) -> None:
    require(
        isinstance(key, str) and key not in _RESERVED,
        f"{where}.{key}",
        key,
        "a configuration field other than seed (seeds are derived from [sweep] seed)",
    )
    require(
        field_exists(ReshufflerConfig, key),
        f"{where}.{key}",
        key,
        "a field of the reshuffler configuration (e.g. current_density, signal.p, "
        "device.chamber_diameter, temperature, material, duration)",
    )


def _check_value(key: str, value: Any, where: str) -> None:
    require(
        isinstance(value, (int, float, str, bool, dict)),
        f"{where}.{key}",
        value,
        "a number, a string, a boolean or a table",
    )


def _grid(data: dict) -> tuple[list[str], list[list[Any]]]:
    require(
        isinstance(data, dict) and bool(data),
        "grid",
        data,
        "a table of dotted config fields, each with a list or a {start, stop, num} range",
    )
    fields, values = [], []
    for key, spec in data.items():
        _check_field(key, "grid")
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


def _points(data: list) -> tuple[list[str], list[list[Any]]]:
    require(
        isinstance(data, list) and len(data) > 0 and all(isinstance(p, dict) for p in data),
        "points",
        data,
        "a non-empty array of tables ([[points]])",
    )
    fields = list(data[0])
    require(len(fields) > 0, "points[0]", data[0], "at least one field")
    for key in fields:
        _check_field(key, "points[0]")
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
    data: dict, head: str, base_dir: Path | None, default: dict, device: str = DEVICE_NAME
) -> dict:
    """The base configuration of a sweep or study file: ``[HEAD] config = FILE`` or ``[base]``.

    File names in it are made relative to the file's folder ``base_dir``; a seed is refused
    (each run's seed is derived from the file's root seed).
    """
    table = data.get(head, {})
    if "config" in table:
        require(
            "base" not in data,
            f"{head}.config",
            table["config"],
            f"either [{head}] config or a [base] table, not both",
        )
        path = Path(table["config"])
        if not path.is_absolute() and base_dir is not None:
            path = base_dir / path
        base = resolve_paths(read_toml(path, f"{head}.config"), path.parent)
    else:
        base = data.get("base", default)
        require(isinstance(base, dict), "base", base, f"a {device} configuration table")
        if base_dir is not None:  # file names in [base] are relative to the sweep file
            base = resolve_paths(base, base_dir)
    require(
        "seed" not in base,
        "base.seed",
        base.get("seed"),
        f"no seed in [base]: runs get seeds derived from [{head}] seed",
    )
    return base


def point_config(
    base: dict, overrides: dict[str, Any], what: str = "sweep point"
) -> ReshufflerConfig:
    """The validated configuration of one point: ``base`` with the dotted ``overrides`` set.

    With the checks :meth:`~skygas.reshuffler.run.ReshufflerRun.build` makes first (the
    geometry against the skyrmion's size), without solving anything; an error names the point
    (``what (current_density = 1e11, …): field = value: …``), and the time step against the
    injection interval.
    """
    label = ", ".join(f"{f} = {v!r}" for f, v in overrides.items())
    config = parse_reshuffler_config(dict(base), f"{what} ({label}): ", overrides)
    try:
        check_time_step(config)
        thiele = config.thiele_parameters()
        d = config.device
        ReshufflerGeometry(
            d.chamber_diameter, d.conduit_width, d.conduit_length, d.chamber_gap
        ).validate(thiele.skyrmion_diameter)
    except InputError as err:
        raise InputError(f"{what} ({label}): {err.field}", err.value, err.allowed) from None
    return config


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
    root_seed = head.get("seed", 0)
    require(
        isinstance(root_seed, int) and not isinstance(root_seed, bool) and root_seed >= 0,
        "sweep.seed",
        root_seed,
        "a whole number >= 0",
    )

    base = base_config(data, "sweep", base_dir, {"preset": "default"})

    has_grid, has_points = "grid" in data, "points" in data
    require(
        has_grid != has_points,
        "grid",
        "both or neither given",
        "exactly one of [grid] or [[points]]",
    )
    layout = "grid" if has_grid else "list"
    fields, values = _grid(data["grid"]) if has_grid else _points(data["points"])
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
    runs = []
    for flat, (index, point_values) in enumerate(indexed):
        config = point_config(base, dict(zip(fields, point_values, strict=True)))
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
