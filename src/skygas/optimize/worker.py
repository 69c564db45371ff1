"""What a study's worker runs: one device configuration in, its summary quantities out.

Kept apart from the rest of :mod:`skygas.optimize` so that a Dask worker imports only the
device it runs (not optuna, pandas or matplotlib), as a sweep's worker does.
"""

from __future__ import annotations

import math


def run_trial(device: str, config_json: str) -> dict[str, float]:
    """Run one configuration of ``device`` and return its summary quantities (floats).

    The device's study hook (:func:`skygas.devices.study_hooks.run_point`); curves a run returns
    (the reshuffler's running correlation) are not a study's quantities and are dropped.
    """
    from skygas.devices.study_hooks import run_point
    from skygas.optimize.devices import device as named

    hooks = named(device)
    result = run_point(hooks.module, config_json)
    return {
        name: math.nan if result.get(name) is None else float(result[name])
        for name in hooks.quantities
    }
