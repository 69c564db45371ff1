"""The package's public names resolve, and what must start fast imports little.

The packages export their names lazily (``__init__.pyi`` lists them); a typo there would only
show when someone touches the name, so every one is touched here. A fresh Dask worker imports
``skygas.sweep.worker`` and the reshuffler's run; that path must not pull in the client-side
libraries (each would add to every worker's start, docs/sweeps.md). Every ``skygas`` command
builds the whole command line first, which must import no numerics.
"""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest


@pytest.mark.parametrize(
    "package",
    [
        "skygas",
        "skygas.reshuffler",
        "skygas.sweep",
        "skygas.neuron",
        "skygas.sc",
        "skygas.micromag",
        "skygas.reservoir",
    ],
)
def test_every_exported_name_resolves(package):
    module = importlib.import_module(package)
    assert module.__all__
    for name in module.__all__:
        assert getattr(module, name) is not None, name
    with pytest.raises(AttributeError):
        module.no_such_name  # noqa: B018


def imported(script: str) -> str:
    """Run ``script`` in a fresh interpreter and return what it prints."""
    return subprocess.run(
        [sys.executable, "-c", script], check=True, capture_output=True, text=True
    ).stdout.strip()


def test_a_sweep_worker_does_not_import_the_client_side_libraries():
    assert (
        imported(
            "import sys\n"
            "from skygas.sweep.worker import run_one\n"
            "import skygas.reshuffler.run, skygas.reshuffler.analysis, skygas.reshuffler.config\n"
            "heavy = ('xarray', 'pandas', 'zarr', 'dask', 'matplotlib', 'netCDF4', 'joblib')\n"
            "print(' '.join(m for m in heavy if m in sys.modules))\n"
        )
        == ""
    )


def test_the_command_line_is_built_without_numerics():
    assert (
        imported(
            "import sys\n"
            "from skygas.cli import build_parser\n"
            "build_parser()\n"
            "heavy = ('scipy', 'numba', 'xarray', 'pydantic', 'shapely', 'zarr', 'dask')\n"
            "print(' '.join(m for m in heavy if m in sys.modules))\n"
        )
        == ""
    )


def test_the_public_names_and_modules_have_docstrings():
    import types
    from pathlib import Path

    import skygas

    modules = {n for n in skygas.__all__ if isinstance(getattr(skygas, n), types.ModuleType)}
    # the public modules are those of the API reference (docs/api/<module>.md, one per module)
    api = Path(__file__).resolve().parents[1] / "docs" / "api"
    assert modules == {p.stem for p in api.glob("*.md")} - {"skygas"}
    for name in skygas.__all__:
        if name != "__version__":
            assert (getattr(skygas, name).__doc__ or "").strip(), name
    # the top-level docstring names every public module, and calls none of them internal
    for name in modules:
        assert f"skygas.{name}`" in skygas.__doc__, name
    assert "skygas.fields.landscape" in skygas.__doc__
