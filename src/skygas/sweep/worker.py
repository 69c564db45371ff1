"""What a sweep's worker runs: one reshuffler configuration in, the numbers a sweep stores out.

Kept apart from the rest of :mod:`skygas.sweep` so that a fresh Dask worker imports only the
simulation (not zarr, xarray or pandas: ~0.7 s of imports per worker process, paid again by
every worker a sweep starts; :mod:`skygas.sweep` exports its names lazily for the same reason).
"""

from __future__ import annotations

import numpy as np

#: Summary numbers stored for each run (float64; NaN until the run is done), in this order.
QUANTITIES = (
    "correlation",
    "correlation_max_lag",
    "scc",
    "p_in",
    "p_out",
    "n_injected",
    "n_detected",
    "n_skipped",
    "n_present",
    "max_occupancy",
    "mean_transit_s",
    "power_W",
    "energy_per_bit_J",
    "simulated_time_s",
    "time_step_s",
    "wall_time_s",
    "correlation_best_lag",
    "median_transit_s",
    "p_out_low",
    "p_out_high",
    "wall_escapes",
)
#: Curves stored for each run: the running correlation ρ and its times [s].
RUNNING = ("running_rho", "running_time")


def run_one(config_json: str) -> dict:
    """Run one reshuffler configuration and return its quantities.

    ``config_json`` is the JSON of a :class:`~skygas.reshuffler.ReshufflerConfig`; the result holds
    :data:`QUANTITIES` as floats and :data:`RUNNING` as float64 arrays (empty with fewer than 3
    aligned events).
    """
    from skygas.core.estimates import run_limits
    from skygas.reshuffler.analysis import summarize
    from skygas.reshuffler.config import ReshufflerConfig
    from skygas.reshuffler.run import ReshufflerRun

    config = ReshufflerConfig.model_validate_json(config_json)
    # the sweep checked every run's estimate before submitting it (sweep.execute)
    with run_limits(force=True):
        run = ReshufflerRun.build(config)
    run.advance()
    result = summarize(run, dataset=False)
    summary = dict(result.summary)
    # the 95 % interval of p_out (Clopper-Pearson), NaN without read-outs
    summary["p_out_low"], summary["p_out_high"] = summary["p_out_interval"] or (np.nan, np.nan)
    out: dict[str, float | np.ndarray] = {name: float(summary[name]) for name in QUANTITIES}
    running = result.running
    out["running_rho"] = np.asarray(running.rho if running else [], dtype=np.float64)
    out["running_time"] = np.asarray(running.times if running else [], dtype=np.float64)
    return out
