"""Results of a reshuffler run: events, correlation figures of merit, power, and the dataset.

Signals compared (docs/physics.md §3, :mod:`skygas.reshuffler.correlation`):

- input: the bits of the nucleated skyrmions in nucleation order. With the default ``delay``
  rule this is the input signal itself (delays only reorder events that waited at an occupied
  site); with ``skip`` it lacks the skipped bits;
- output: one bit per read-out in detection order (1 for UP, 0 for DOWN), i.e. the paper's
  output signal sampled at each switching event.

They are aligned by event index (k-th nucleated against k-th detected).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from skygas._version import __version__
from skygas.reshuffler import correlation as corr

if TYPE_CHECKING:
    import xarray as xr


@dataclass
class ReshufflerResult:
    """The analysis of a run: its summary, running correlation and dataset.

    The summary (JSON-able dict, SI units), the running correlation (None with fewer than 3 aligned
    events) and the full :class:`xarray.Dataset` (None if not asked for).
    """

    summary: dict
    running: corr.RunningCorrelation | None
    dataset: xr.Dataset | None


def _injections(run) -> dict[str, np.ndarray]:
    log = run.injector.log
    done = np.nonzero(log.skyrmion >= 0)[0]
    order = done[np.lexsort((done, log.injection_step[done]))]  # by step, then event index
    return {
        "event": order,
        "skyrmion": log.skyrmion[order],
        "time": log.injection_step[order] * run.sim.time_step,
        "up": log.bit[order],
    }


def summarize(run, *, dataset: bool = True) -> ReshufflerResult:
    """Analyse a finished (or interrupted) :class:`~skygas.reshuffler.run.ReshufflerRun`.

    ``dataset=False`` leaves out the dataset: a sweep's worker keeps only the summary and the
    running curve, and skips importing xarray (its first dataset alone imports dask.array,
    ~0.5 s per fresh worker process).
    """
    cfg = run.config
    counts = run.counts()
    inj = _injections(run)
    det = run.detections()
    b, c = inj["up"], det["up"]
    n_pairs = min(len(b), len(c))
    rho = corr.pearson_by_index(b, c) if n_pairs >= 2 else float("nan")
    scc = corr.scc_by_index(b, c) if n_pairs >= 2 else float("nan")
    # every lag keeps at least half the pairs of lag 0: a lag of a few pairs reaches |ρ| = 1
    # by chance (a 0.4 µs run gave ρ(35) = 1.0 from 4 pairs)
    max_lag = min(cfg.output.max_lag, n_pairs // 2)
    lag = corr.pearson_vs_lag(b, c, max_lag) if n_pairs >= 4 else None
    all_bits = run.injector.log.bit
    p_cmp = corr.p_out_vs_p_in(all_bits, c) if len(c) else None
    running = (
        corr.running_correlation(b, c, det["time"][:n_pairs], cfg.output.running_points)
        if n_pairs >= 3
        else None
    )
    occ = corr.occupancy(inj["time"], inj["up"], det["time"], det["up"])
    grid_t = np.linspace(0.0, run.sim.time, 500)
    occ_t = corr.occupancy(inj["time"], inj["up"], det["time"], det["up"], grid_t)
    transit = (
        corr.transit_times(inj["skyrmion"], inj["time"], det["skyrmion"], det["time"])
        if len(det["skyrmion"])
        else None
    )
    power = 2.0 * run.current.power  # two identical chambers, each carrying J in its conduits
    energy_per_bit = power * cfg.injection.interval

    summary = {
        "correlation": rho,
        "correlation_error": corr.pearson_error_by_index(b, c) if n_pairs >= 2 else float("nan"),
        "correlation_max_lag": lag.best_rho if lag else float("nan"),
        "correlation_best_lag": lag.best_lag if lag else 0,
        "scc": scc,
        "p_in": float(all_bits.mean()) if len(all_bits) else float("nan"),
        "p_in_injected": float(b.mean()) if len(b) else float("nan"),
        "p_out": float(c.mean()) if len(c) else float("nan"),
        "p_out_interval": [float(p_cmp.p_out.low), float(p_cmp.p_out.high)] if p_cmp else None,
        "p_in_within_output_interval": p_cmp.p_in_within_output_interval if p_cmp else None,
        "n_events": int(len(all_bits)),
        "n_injected": counts["injected"],
        "n_detected": counts["detected"],
        "n_present": counts["present"],
        "n_annihilated": counts["annihilated"],
        "n_skipped": run.injector.n_skipped,
        "n_delayed": run.injector.n_delayed,
        "n_pending": run.injector.n_pending,
        "counts_conserved": True,  # run.counts() raises otherwise
        "max_occupancy": int(max(occ.up.max(initial=0), occ.down.max(initial=0))),
        "max_occupancy_up": int(occ.up.max(initial=0)),
        "max_occupancy_down": int(occ.down.max(initial=0)),
        "mean_transit_s": transit.mean if transit else float("nan"),
        "median_transit_s": transit.median if transit else float("nan"),
        "current_density_A_m2": cfg.current_density,
        "spin_drift_coefficient_m3_C": cfg.drift_coefficient(),
        "conduit_drift_velocity_m_s": cfg.drift_coefficient() * cfg.current_density,
        "chamber_diameter_m": cfg.device.chamber_diameter,
        "temperature_K": cfg.temperature,
        **cfg.hypothesis.record(),
        "noise_temperature_K": cfg.noise_temperature(),
        "free_diffusion_m2_s": run.sim.thiele.diffusion_constant(cfg.noise_temperature()),
        "total_current_A": 2.0 * run.current.total_current,
        "resistance_ohm": run.current.resistance,
        "power_W": power,
        "energy_per_bit_J": energy_per_bit,
        "simulated_time_s": run.sim.time,
        "time_step_s": run.sim.time_step,
        "wall_time_s": run.wall_time,
        "wall_escapes": run.sim.wall_escapes,
        "seed": cfg.seed,
        "skygas_version": __version__,
    }
    operations = run.sim.operation_summaries()  # the user's named operations, if any
    if operations:
        summary["operations"] = operations
    if not dataset:
        return ReshufflerResult(summary, running, None)

    import xarray as xr  # here, not at the top: see the docstring

    ds = xr.Dataset(
        {
            "input_bit": ("event", all_bits.astype(np.int8)),
            "event_skyrmion": ("event", run.injector.log.skyrmion),
            "event_injection_time": (
                "event",
                np.where(
                    run.injector.log.injection_step >= 0,
                    run.injector.log.injection_step * run.sim.time_step,
                    np.nan,
                ),
                {"units": "s"},
            ),
            "event_delayed": ("event", run.injector.log.delayed.astype(np.int8)),
            "event_skipped": ("event", run.injector.log.skipped.astype(np.int8)),
            "detection_time": ("detection", det["time"], {"units": "s"}),
            "detection_up": ("detection", det["up"].astype(np.int8)),
            "detection_skyrmion": ("detection", det["skyrmion"]),
            "transit_time": (
                "detection",
                transit.transit if transit else np.empty(0),
                {"units": "s"},
            ),
            "occupancy_up": ("occupancy_time", occ_t.up),
            "occupancy_down": ("occupancy_time", occ_t.down),
            "lag_rho": ("lag", lag.rho if lag else np.empty(0)),
            "running_rho": ("running", running.rho if running else np.empty(0)),
            "running_time": ("running", running.times if running else np.empty(0), {"units": "s"}),
            "running_events": ("running", running.n_events if running else np.empty(0, int)),
        },
        coords={
            "event_time": (
                "event",
                np.arange(len(all_bits)) * cfg.injection.interval,
                {"units": "s"},
            ),
            "occupancy_time": ("occupancy_time", grid_t, {"units": "s"}),
            "lag": ("lag", lag.lags if lag else np.empty(0, int)),
        },
    )
    snaps = run.snapshots
    counts_per = np.array([len(s[1]) for s in snaps], dtype=np.int64)
    ds["snapshot_time"] = ("snapshot", np.array([s[0] for s in snaps]), {"units": "s"})
    ds["snapshot_count"] = ("snapshot", counts_per)
    ds["snapshot_skyrmion"] = (
        "entry",
        np.concatenate([s[1] for s in snaps]) if snaps else np.empty(0, np.int64),
    )
    pos = np.concatenate([s[2] for s in snaps]) if snaps else np.empty((0, 2))
    ds["snapshot_x"] = ("entry", pos[:, 0], {"units": "m"})
    ds["snapshot_y"] = ("entry", pos[:, 1], {"units": "m"})
    run.add_operation_data(ds)  # the named operations' readings, if any
    ds.attrs.update(
        {
            "title": "skygas Skyrmion Reshuffler run",
            "skygas_version": __version__,
            "seed": cfg.seed,
            "config_json": cfg.model_dump_json(),
            "summary_json": json.dumps(summary),
            "current_json": json.dumps(run.current.record()),
            "engine_parameters_json": json.dumps(run.sim.parameters()),
            "snapshot_layout": "entries of snapshot n are the snapshot_count[n] consecutive "
            "entries after those of snapshots 0..n-1",
        }
    )
    return ReshufflerResult(summary, running, ds)
