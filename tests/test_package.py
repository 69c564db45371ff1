"""The package's public names resolve, and a sweep worker's imports stay light.

The packages export their names lazily (``__init__.pyi`` lists them); a typo there would only
show when someone touches the name, so every one is touched here. A fresh Dask worker imports
``skygas.sweep.worker`` and the reshuffler's run; that path must not pull in the client-side
libraries (each would add to every worker's start, docs/sweeps.md).
"""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest


@pytest.mark.parametrize("package", ["skygas", "skygas.reshuffler", "skygas.sweep"])
def test_every_exported_name_resolves(package):
    module = importlib.import_module(package)
    assert module.__all__
    for name in module.__all__:
        assert getattr(module, name) is not None, name
    with pytest.raises(AttributeError):
        module.no_such_name  # noqa: B018


def test_a_sweep_worker_does_not_import_the_client_side_libraries():
    script = (
        "import sys\n"
        "from skygas.sweep.worker import run_one\n"
        "import skygas.reshuffler.run, skygas.reshuffler.analysis, skygas.reshuffler.config\n"
        "heavy = ('xarray', 'pandas', 'zarr', 'dask', 'matplotlib', 'netCDF4', 'joblib')\n"
        "print(' '.join(m for m in heavy if m in sys.modules))\n"
    )
    out = subprocess.run([sys.executable, "-c", script], check=True, capture_output=True,
                         text=True).stdout.strip()
    assert out == ""
