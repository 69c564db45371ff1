"""The engine's boundary: code outside ``skygas.engine`` uses only its public API.

Devices and tools read and change skyrmions through ``sim.state`` and the documented methods
of :class:`~skygas.engine.Simulation`; they never reach into the engine's private members or
import its compiled internals. This scan of the source (AST, not text) keeps it that way.
"""

from __future__ import annotations

import ast
from pathlib import Path

import skygas

PACKAGE = Path(skygas.__file__).parent
ENGINE = PACKAGE / "engine"
#: The engine's compiled internals: only the engine itself imports them.
INTERNAL_MODULES = {
    "skygas.engine.kernel",
    "skygas.engine.stages",
    "skygas.engine.neighbors",
    "skygas.engine._jit",
}


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
