"""No code outside a device's own folder switches on a device's name (issue 40).

A device's name (``"reshuffle"``, ``"neuron"``, ...) written as a string literal outside its
own package is a switch on it: the report, the time-step check and the analysis ask the device
registry (:mod:`skygas.devices.registry`) instead. The scan reads the source's tokens: a string
token whose value is exactly a name counts, a docstring or a comment that mentions one (prose,
not a switch) does not.

The files not yet moved onto the registry are listed in :data:`NOT_YET_MIGRATED`, each with its
reason; the list only shrinks (a file that no longer has a literal must leave it).
"""

from __future__ import annotations

import ast
import io
import tokenize
from pathlib import Path

import skygas

PACKAGE = Path(skygas.__file__).parent

#: the names of the kinds of run and of the devices, as the command line and the code write them
NAMES = frozenset({"reshuffle", "reshuffler", "neuron", "reservoir", "simulate", "saturation"})

#: each name's own folders, relative to ``src/skygas`` (``simulate`` has none: a plain
#: simulation is the engine's and the runs' code, which must not know it by name)
OWN_FOLDERS: dict[str, tuple[str, ...]] = {
    "reshuffle": ("reshuffler",),
    "reshuffler": ("reshuffler",),
    "neuron": ("neuron",),
    "saturation": ("neuron",),  # skygas saturation measures the neuron's chambers
    "reservoir": ("reservoir",),
    "simulate": ("runs",),  # the plain simulation's own package
}
#: where every name may stand: the registry itself
REGISTRY = "devices"

#: files where the names are those of the device packages as modules, not kinds of run
PACKAGE_NAMES: dict[str, str] = {
    "__init__.pyi": "the public API's __all__ lists the device packages, by module name",
}

#: files, relative to ``src/skygas``, that still name devices: the next installments' work
NOT_YET_MIGRATED: dict[str, str] = {}


def device_literals(source: str) -> list[tuple[int, str]]:
    """``(line, name)`` of every string literal of ``source`` whose value is a device's name."""
    found = []
    for token in tokenize.generate_tokens(io.StringIO(source).readline):
        if token.type != tokenize.STRING:
            continue
        try:
            value = ast.literal_eval(token.string)
        except (ValueError, SyntaxError):  # an f-string: not a plain literal
            continue
        if isinstance(value, str) and value in NAMES:
            found.append((token.start[0], value))
    return found


def _allowed(path: str, name: str) -> bool:
    """Whether ``name`` may stand in the file ``path`` (relative to ``src/skygas``)."""
    top = path.split("/")[0]
    return top == REGISTRY or top in OWN_FOLDERS[name]


def offences() -> dict[str, list[str]]:
    """Device-name literals outside their places, by file (allowlisted files included)."""
    found: dict[str, list[str]] = {}
    for file in sorted([*PACKAGE.rglob("*.py"), *PACKAGE.rglob("*.pyi")]):
        if "__pycache__" in file.parts:
            continue
        path = file.relative_to(PACKAGE).as_posix()
        for line, name in device_literals(file.read_text()):
            if not _allowed(path, name):
                found.setdefault(path, []).append(f"{path}:{line}: {name!r}")
    return found


def test_no_device_name_outside_its_folder_and_the_registry():
    left = {
        path: lines
        for path, lines in offences().items()
        if path not in NOT_YET_MIGRATED and path not in PACKAGE_NAMES
    }
    assert not left, (
        "device names written outside their device's folder: ask skygas.devices.registry "
        "instead (or, for a file not yet migrated, list it in NOT_YET_MIGRATED with why):\n"
        + "\n".join(line for lines in left.values() for line in lines)
    )


def test_every_file_not_yet_migrated_still_names_a_device():
    stale = sorted({*NOT_YET_MIGRATED, *PACKAGE_NAMES} - set(offences()))
    assert not stale, f"the allowlists name files that name no device any more: {stale}"


def test_the_scan_finds_a_device_name():
    """The scan can fail: a literal in code is found, in either quotes; prose is not."""
    source = (
        '"""A module: ``"neuron"`` in its docstring is prose."""\n'
        "def f(kind):\n"
        '    if kind == "reshuffle":  # "simulate" in a comment\n'
        "        return 'reservoir'\n"
        '    return "reshuffle it"\n'
    )
    assert device_literals(source) == [(3, "reshuffle"), (4, "reservoir")]
    assert not _allowed("outputs/report.py", "neuron")
    assert _allowed("neuron/files.py", "neuron")
    assert _allowed("devices/registry.py", "simulate")
