"""A reshuffler run read back from its ``reshuffler.nc`` (``skygas reshuffle``).

:func:`record` is the reshuffler's reader of :class:`~skygas.devices.registry.RecordFile`: the
sparse snapshots, the device outline rebuilt from the recorded configuration, and each
skyrmion coloured by the input bit it carries.
"""

from __future__ import annotations

import numpy as np

from skygas.devices.records import RecordParts


def record(ds) -> RecordParts:
    """The reshuffler's parts of the run whose result file is ``ds``."""
    from skygas.reshuffler.config import ReshufflerConfig
    from skygas.reshuffler.device import CHAMBERS, ReshufflerGeometry

    config = ReshufflerConfig.model_validate_json(ds.attrs["config_json"])
    d = config.device
    geometry = ReshufflerGeometry(
        d.chamber_diameter, d.conduit_width, d.conduit_length, d.chamber_gap
    )
    snapshots = (
        ds.snapshot_time.values,
        ds.snapshot_count.values.astype(np.int64),
        ds.snapshot_skyrmion.values.astype(np.int64),
        ds.snapshot_x.values,
        ds.snapshot_y.values,
    )
    # the input bit each skyrmion carries: 1 is steered to UP, 0 to DOWN
    carried = ds.event_skyrmion.values
    nucleated = carried >= 0
    bit_ids = carried[nucleated]
    bits = ds.input_bit.values[nucleated]
    order = np.argsort(bit_ids)
    bit_ids, bits = bit_ids[order], bits[order]

    def group_of(ids, x, y):
        out = np.full(len(ids), 2)  # "unknown": not in the event log
        if len(bit_ids):
            where = np.clip(np.searchsorted(bit_ids, ids), 0, len(bit_ids) - 1)
            known = bit_ids[where] == ids
            out[known] = 1 - bits[where[known]]
        return out

    def background(x, y):
        from skygas.fields.current import solve_current

        c = config.current
        solution = solve_current(
            geometry.chamber(),
            config.current_density,
            cell_size=c.cell_size,
            conductor_thickness=c.conductor_thickness,
            resistivity=c.resistivity,
        )
        values = np.zeros_like(x)
        which = geometry.chamber_of(y * 1e9)
        for index, name in enumerate(CHAMBERS):
            cx, cy = geometry.centres()[name]
            mask = which == index
            jx, jy = solution.current_density_at(x[mask] - cx, y[mask] - cy)
            values[mask] = np.hypot(jx, jy)
        return values, "current density |j| (A/m²)"

    return RecordParts(
        geometry.device_outline(),
        config.thiele_parameters().skyrmion_diameter,
        ("input bit 1 (to UP)", "input bit 0 (to DOWN)", "unknown"),
        group_of,
        (1.0, 0.0),
        snapshots=snapshots,
        background_fn=background,
        landscape_fn=_landscape(config),
    )


def _landscape(config):
    """Builds the landscape of a reshuffler run (the engine's, same grid and seed), or None."""
    if not config.potentials:
        return None

    def build():
        from skygas.reshuffler.run import ReshufflerRun

        return ReshufflerRun.build(config).sim.landscape

    return build
