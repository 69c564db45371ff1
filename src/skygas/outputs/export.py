"""Trajectories for particle viewers: GSD and extended XYZ.

GSD is HOOMD-blue's format, read by OVITO, HOOMD's tools and freud; extended XYZ is read by OVITO,
ASE, and VMD with its plugin.

Both hold one frame per recorded frame of the run, in the run's order, with every skyrmion
present at that time (frames with no skyrmion included, so the frame count is the record's).
Positions are in nanometres, z = 0, unchanged from the record (× 10⁹). The box is the
rectangle centred on the origin that holds the device outline; it is not periodic.

GSD: ``configuration.box`` = [Lx, Ly, 0, 0, 0, 0] nm, ``dimensions`` 2, ``step`` the frame
index; ``particles.diameter`` the skyrmion diameter [nm]; ``particles.typeid`` the colour group
of the movie (input bit, ...), named in ``particles.types``. Per-frame log entries:
``skygas/time_s`` (time [s]), ``skygas/length_unit_m`` (1e-9: one length unit is one
nanometre), ``particles/skygas_id`` (the skyrmion id of each particle). The first frame's log
holds the provenance, ``skygas/provenance_json``: the record of
:meth:`~skygas.outputs.records.RunRecord.provenance` (the run's skygas version, seed,
configuration and its hash, the command line) as UTF-8 JSON bytes (``uint8``; read it with
``json.loads(bytes(frame.log["skygas/provenance_json"]))``; later frames return the first
frame's value, as GSD does for any entry a frame leaves out).

Extended XYZ: the comment line of each frame states ``Lattice``, ``Origin``,
``Properties=species:S:1:pos:R:3:id:I:1``, ``Time`` (s), ``time_unit=s``,
``length_unit=nm``, ``pbc="F F F"`` and the provenance: ``skygas_version``, ``seed``,
``config_hash`` (the run manifest's) and ``skygas_command`` (the command line, quoted).

Both files are written through a temporary file (:func:`~skygas.runs.run_driver.write_atomic`):
a failed export leaves nothing behind.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from skygas.core.errors import InputError
from skygas.runs.run_driver import write_atomic

FORMATS = ("gsd", "extxyz")


def _box_nm(record) -> tuple[float, float]:
    """Lx, Ly [nm] of the origin-centred box that holds the outline (1 % margin)."""
    x0, y0, x1, y1 = record.outline._bounds_nm
    return 2.02 * max(abs(x0), abs(x1)), 2.02 * max(abs(y0), abs(y1))


def _species(record) -> list[str]:
    return [
        "".join(c if c.isalnum() else "_" for c in name.split(" (")[0])
        for name in record.group_names
    ]


def export_gsd(record, path: str | Path) -> Path:
    """Write ``record``'s frames to a GSD file at ``path`` (see the module docstring)."""
    lx, ly = _box_nm(record)
    d_nm = record.skyrmion_diameter * 1e9
    frames = record.frames
    types = _species(record)
    provenance = json.dumps(record.provenance(), sort_keys=True).encode("utf-8")
    return write_atomic(
        path, lambda tmp: _write_gsd(tmp, record, frames, types, lx, ly, d_nm, provenance)
    )


def _write_gsd(tmp: Path, record, frames, types, lx, ly, d_nm, provenance: bytes) -> None:
    import gsd.hoomd

    with gsd.hoomd.open(tmp, "w") as traj:
        for f in range(frames.n_frames):
            ids, xy = frames.frame(f)
            frame = gsd.hoomd.Frame()
            frame.configuration.step = f
            frame.configuration.dimensions = 2
            frame.configuration.box = [lx, ly, 0.0, 0.0, 0.0, 0.0]
            n = len(ids)
            frame.particles.N = n
            frame.particles.types = types
            pos = np.zeros((n, 3), dtype=np.float32)
            pos[:, :2] = xy * 1e9
            frame.particles.position = pos
            frame.particles.typeid = record.group_of(ids, xy[:, 0], xy[:, 1]).astype(np.uint32)
            frame.particles.diameter = np.full(n, d_nm, dtype=np.float32)
            frame.log["skygas/time_s"] = np.array([frames.time[f]])
            frame.log["skygas/length_unit_m"] = np.array([1e-9])
            frame.log["particles/skygas_id"] = ids.astype(np.int64)
            if f == 0:
                frame.log["skygas/provenance_json"] = np.frombuffer(provenance, dtype=np.uint8)
            traj.append(frame)


def export_extxyz(record, path: str | Path) -> Path:
    """Write ``record``'s frames to an extended-XYZ file at ``path``."""
    lx, ly = _box_nm(record)
    frames = record.frames
    species = np.array(_species(record))
    prov = record.provenance()
    command = prov["command_line"].replace('"', "'").replace("\\", "/")
    header = (
        f'Lattice="{lx:.6g} 0 0 0 {ly:.6g} 0 0 0 1" Origin="{-lx / 2:.6g} {-ly / 2:.6g} '
        f'-0.5" Properties=species:S:1:pos:R:3:id:I:1 time_unit=s length_unit=nm '
        f'pbc="F F F" skygas_version={prov["skygas_version"]} seed={prov["seed"]} '
        f'config_hash={prov["config_hash"]} skygas_command="{command}"'
    )

    def write(tmp: Path) -> None:
        with open(tmp, "w") as out:
            for f in range(frames.n_frames):
                ids, xy = frames.frame(f)
                names = species[record.group_of(ids, xy[:, 0], xy[:, 1])]
                out.write(f"{len(ids)}\n{header} Time={frames.time[f]:.9e} Frame={f}\n")
                for name, (x, y), i in zip(names, xy * 1e9, ids, strict=True):
                    out.write(f"{name} {x:.6f} {y:.6f} 0 {i}\n")

    return write_atomic(path, write)


def export_run(record, fmt: str, path: str | Path) -> Path:
    """Export ``record`` in ``fmt`` (one of :data:`FORMATS`) to ``path``."""
    if fmt not in FORMATS:
        raise InputError("--format", fmt, f"one of {', '.join(FORMATS)}")
    return (export_gsd if fmt == "gsd" else export_extxyz)(record, path)
