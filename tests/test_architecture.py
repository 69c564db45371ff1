"""The package's architecture, checked on its source (AST, not text; docs/architecture.md).

**Layers.** Every module of ``skygas`` belongs to one layer, by the folder it lives in
(:data:`LAYERS`, lowest first), and imports only from its own layer and the layers below. Every
import counts, wherever it stands: at the top of a module, under ``if TYPE_CHECKING:`` or
inside a function. A lazy import inside a function that goes *down* (a command importing a
device when it runs, a configuration building the engine) is fine; one that goes *up* is an
upward dependency all the same, only hidden until the function runs, and is refused like a
top-level one. Any that had to be accepted would be listed, each with its reason, in
:data:`ALLOWED_UPWARD` (none is).

**The engine's boundary.** Code outside ``skygas.engine`` uses only its public API: devices and
tools read and change skyrmions through ``sim.state`` and the documented methods of
:class:`~skygas.engine.Simulation`; they never reach into the engine's private members or import
its compiled internals.
"""

from __future__ import annotations

import ast
from pathlib import Path

import skygas

PACKAGE = Path(skygas.__file__).parent
ENGINE = PACKAGE / "engine"

#: The layers, lowest first: each is a name and the folders (or top-level modules) of
#: ``src/skygas`` that hold it. ``""`` is the package itself: its ``__init__`` is the public
#: API, which names things from every layer (imported on first use).
LAYERS: tuple[tuple[str, frozenset[str]], ...] = (
    ("foundations", frozenset({"core", "_version"})),
    ("laws and shapes", frozenset({"physics"})),
    ("fields on a grid", frozenset({"fields"})),
    ("figures", frozenset({"figures"})),
    ("the engine", frozenset({"engine"})),
    ("runs", frozenset({"runs"})),
    ("stochastic computing", frozenset({"sc"})),
    ("devices", frozenset({"devices", "reshuffler", "neuron", "reservoir"})),
    # the studies and tools, in their order (each may use those before it)
    ("analysis", frozenset({"analysis"})),
    ("studies", frozenset({"sweep"})),
    ("micromagnetics", frozenset({"micromag"})),
    ("outputs", frozenset({"outputs"})),
    ("calibration", frozenset({"calibration"})),
    ("optimisation", frozenset({"optimize"})),
    ("movies", frozenset({"movies"})),
    ("inference", frozenset({"inference"})),
    ("the command line", frozenset({"commands", "cli"})),
    ("the public API", frozenset({""})),
)

#: Upward imports accepted, as (importing module, imported module): why each is there. None:
#: the last two went when Simulation.plot's figure functions moved below the engine
#: (skygas.figures) and the neuron's frames.nc writer moved beside its reader.
ALLOWED_UPWARD: dict[tuple[str, str], str] = {}

#: The engine's compiled internals: only the engine itself imports them.
INTERNAL_MODULES = {
    "skygas.engine.kernel",
    "skygas.engine.stages",
    "skygas.engine.neighbors",
    "skygas.engine._jit",
    "skygas.engine._rng",
}


# --- layers --------------------------------------------------------------------------------


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _sources() -> dict[str, tuple[str, bool]]:
    """Every module and stub of the package: name → (source, is a package's ``__init__``)."""
    sources = {}
    for path in sorted([*PACKAGE.rglob("*.py"), *PACKAGE.rglob("*.pyi")]):
        if "__pycache__" not in path.parts:
            name = _module_name(path)
            text = path.read_text()
            if name in sources:  # a package's __init__.py and its __init__.pyi: scan both
                text = sources[name][0] + "\n" + text
            sources[name] = (text, path.stem == "__init__")
    return sources


def layer_of(module: str) -> int:
    """The index in :data:`LAYERS` of ``module`` (``skygas`` or ``skygas.<folder>...``)."""
    parts = module.split(".")
    top = parts[1] if len(parts) > 1 else ""
    for index, (_, places) in enumerate(LAYERS):
        if top in places:
            return index
    raise AssertionError(f"{module}: in no layer; add skygas.{top} to LAYERS")


def imports_of(module: str, source: str, is_package: bool, known: set[str]):
    """``(line, imported module)`` for every import of a ``skygas`` module in ``source``,
    wherever it stands. ``from skygas.x import y`` is an import of ``skygas.x.y`` when that is
    a module (in ``known``), else of ``skygas.x``."""
    package = module if is_package else module.rpartition(".")[0]
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == "skygas":
                    yield node.lineno, alias.name
        elif isinstance(node, ast.ImportFrom):
            if node.level:  # relative (the stubs): from the package, level - 1 folders up
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                target = ".".join([*base, *([node.module] if node.module else [])])
            else:
                target = node.module or ""
            if target.split(".")[0] != "skygas":
                continue
            for alias in node.names:
                sub = f"{target}.{alias.name}"
                yield node.lineno, sub if sub in known else target


def upward_imports(sources: dict[str, tuple[str, bool]]) -> list[str]:
    """Every import of a module from a higher layer than the importer's, but those allowed:
    ``module:line: imported (importer's layer < imported's layer)``."""
    known = set(sources)
    offences = []
    for module, (source, is_package) in sources.items():
        own = layer_of(module)
        for line, target in imports_of(module, source, is_package, known):
            theirs = layer_of(target)
            if theirs > own and (module, target) not in ALLOWED_UPWARD:
                offences.append(
                    f"{module}:{line}: imports {target} ({LAYERS[own][0]} < {LAYERS[theirs][0]})"
                )
    return offences


def _upward_pairs(sources: dict[str, tuple[str, bool]]) -> set[tuple[str, str]]:
    known = set(sources)
    return {
        (module, target)
        for module, (source, is_package) in sources.items()
        for _, target in imports_of(module, source, is_package, known)
        if layer_of(target) > layer_of(module)
    }


def test_every_module_is_in_a_layer():
    for module in _sources():
        layer_of(module)


def test_no_module_imports_from_a_higher_layer():
    offences = upward_imports(_sources())
    assert not offences, (
        "upward imports (docs/architecture.md, Layers; move the code down, or the import up):\n"
        + "\n".join(offences)
    )


def test_every_allowed_upward_import_is_still_made():
    stale = set(ALLOWED_UPWARD) - _upward_pairs(_sources())
    assert not stale, f"ALLOWED_UPWARD lists imports the source no longer makes: {sorted(stale)}"


def test_the_layer_scan_finds_an_upward_import():
    """The scan can fail: modules importing from a higher layer, at the top or inside a
    function, are found; a command importing a device inside a function is no offence."""
    upward = {
        "skygas.core.units": ("from skygas.engine import Simulation\n", False),
        "skygas.physics.forces": ("def f():\n    from skygas.runs import runner\n", False),
        "skygas.fields.current": ("import skygas.reshuffler.run\n", False),
        # among the studies and tools too: analysis comes before the outputs
        "skygas.analysis.maps": ("from skygas.outputs import report\n", False),
        "skygas.sweep.store": ("def f():\n    from skygas.calibration import plan\n", False),
    }
    offences = upward_imports(upward)
    assert sorted(o.split(":")[0] for o in offences) == sorted(upward), offences
    downward = {"skygas.commands.x": ("def f():\n    from skygas.neuron import device\n", False)}
    assert not upward_imports(downward)


# --- the engine's boundary -----------------------------------------------------------------


def _private_engine_names() -> set[str]:
    """Names of the private members the engine's classes and modules define."""
    names = set()
    for path in ENGINE.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if (
                isinstance(node, ast.Attribute)
                and isinstance(node.value, ast.Name)
                and node.value.id == "self"
                and node.attr.startswith("_")
            ):
                names.add(node.attr)
            elif (
                isinstance(node, (ast.FunctionDef, ast.ClassDef))
                and node.name.startswith("_")
                and not node.name.startswith("__")
            ):
                names.add(node.name)
    return names


def _outside_modules():
    for path in sorted(PACKAGE.rglob("*.py")):
        if ENGINE not in path.parents:
            yield path, ast.parse(path.read_text())


def test_the_scan_finds_the_engines_private_members():
    names = _private_engine_names()
    assert {"_terms", "_advance", "_counters", "_sim"} <= names


def test_no_module_outside_the_engine_touches_its_private_members():
    private = _private_engine_names()
    offences = []
    for path, tree in _outside_modules():
        for node in ast.walk(tree):
            if (
                isinstance(node, ast.Attribute)
                and node.attr in private
                and not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"))
            ):
                offences.append(f"{path.relative_to(PACKAGE)}:{node.lineno}: .{node.attr}")
    assert not offences, "private engine members used outside the engine:\n" + "\n".join(offences)


def test_no_module_outside_the_engine_imports_its_internals():
    offences = []
    for path, tree in _outside_modules():
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.module:
                module = node.module
                names = [alias.name for alias in node.names]
                if (
                    module in INTERNAL_MODULES
                    or (
                        module.startswith("skygas.engine") and any(n.startswith("_") for n in names)
                    )
                    or (
                        module == "skygas.engine"
                        and any(f"skygas.engine.{n}" in INTERNAL_MODULES for n in names)
                    )
                ):
                    offences.append(f"{path.relative_to(PACKAGE)}:{node.lineno}: {module}")
            elif isinstance(node, ast.Import):
                offences += [
                    f"{path.relative_to(PACKAGE)}:{node.lineno}: {alias.name}"
                    for alias in node.names
                    if alias.name in INTERNAL_MODULES
                ]
    assert not offences, "engine internals imported outside the engine:\n" + "\n".join(offences)
