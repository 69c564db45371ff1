"""Sample OVF files shipped with skygas, to try ``skygas micromag inspect`` and ``fit`` at once.

They are synthetic, drawn by :mod:`skygas.micromag.synthetic` (not by a micromagnetic solver),
and every file says so in its header:

- ``pair/m000000.ovf`` … : two skyrmions (R = 6 nm, Δ = 2 nm, 2 nm cells, material S2's M_s and
  A_ex) released 1.2 d_sk apart, relaxing by S2's pair law under the T = 0 Thiele equation;
  ``skygas micromag fit`` gives that law back over the distances the pair covers.
- ``disk-tilted-edges.ovf``: two skyrmions in a disk whose edges tilt by 30°
  (:func:`~skygas.micromag.synthetic.edge_tilt`); ``inspect`` reports the edge band it leaves out.

:func:`write_samples` made them; ``tests/micromag/test_samples.py`` checks that the shipped
files are what it makes.
"""

from __future__ import annotations

import math
from importlib import resources
from pathlib import Path

import numpy as np

from skygas.physics.materials import preset

RADIUS = 6e-9  # m
WALL_WIDTH = 2e-9  # m
CELL = 2e-9  # m
FILM = 2e-9  # m, t_F
PAIR_FRAMES = 16
PAIR_DURATION = 1.6e-9  # s: frames 0.107 ns apart, steps below one radius
PAIR_CELLS = 30  # square mesh, cells per side
DISK_CELLS = 44
_MIDDLE = DISK_CELLS * CELL / 2
#: Skyrmion centres [m] of ``disk-tilted-edges.ovf`` (sub-cell offsets on purpose).
DISK_CENTRES = [
    (_MIDDLE - 2.4 * RADIUS, _MIDDLE + 0.3e-9),
    (_MIDDLE + 2.2 * RADIUS, _MIDDLE - 0.7e-9),
]
_NOTE = (
    "synthetic sample made by skygas.micromag.samples (analytic 360° wall skyrmions), "
    "not a micromagnetic simulation"
)


def folder() -> Path:
    """The folder of the shipped samples (inside the installed package)."""
    return Path(str(resources.files("skygas").joinpath("data/ovf")))


def usage() -> str:
    """Where the samples are and the commands that try them (``skygas micromag samples``)."""
    where = folder()
    return "\n".join(
        [
            f"sample OVF files (synthetic, see their headers): {where}",
            f"  {where / 'pair'}: {PAIR_FRAMES} snapshots of two relaxing skyrmions",
            f"  {where / 'disk-tilted-edges.ovf'}: two skyrmions in a disk with tilted edges",
            "try:",
            f"  skygas micromag inspect {where / 'disk-tilted-edges.ovf'}",
            f"  skygas micromag fit {where / 'pair'} --out fit-sample",
        ]
    )


def write_samples(target: str | Path) -> list[Path]:
    """Write every sample into ``target`` (made if missing); returns the paths written."""
    from skygas.micromag import synthetic
    from skygas.micromag.ovf import write_ovf
    from skygas.micromag.workflow import thiele_coefficients

    target = Path(target)
    (target / "pair").mkdir(parents=True, exist_ok=True)
    material = preset("S2")
    diameter = 2 * RADIUS
    coeffs = thiele_coefficients(
        -1.0, synthetic.ansatz_dissipation(RADIUS, WALL_WIDTH), material, FILM
    )
    system = synthetic.ThieleSystem(
        coeffs["gyrocoupling"],
        coeffs["friction"],
        material.exchange_stiffness * FILM / diameter,
        diameter,
    )
    centre = PAIR_CELLS * CELL / 2
    start = [(centre - 0.6 * diameter, centre), (centre + 0.6 * diameter, centre)]
    times = np.linspace(0.0, PAIR_DURATION, PAIR_FRAMES)
    positions = synthetic.integrate_thiele(
        system, start, times, synthetic.pair_forces(system, material.pair_law)
    )
    written = []
    notes = [
        _NOTE,
        f"pair relaxing by material S2's pair law {list(material.pair_law)}, "
        f"R = {RADIUS:g} m, wall width {WALL_WIDTH:g} m, t_F = {FILM:g} m",
    ]
    for i, (t, p) in enumerate(zip(times, positions, strict=True)):
        field = synthetic.skyrmion_field(
            (PAIR_CELLS, PAIR_CELLS), CELL, p, RADIUS, WALL_WIDTH, time=t
        )
        written.append(write_ovf(target / "pair" / f"m{i:06d}.ovf", field, fmt="bin4", notes=notes))
    yy, xx = (np.mgrid[0:DISK_CELLS, 0:DISK_CELLS] + 0.5) * CELL
    disk = np.hypot(xx - _MIDDLE, yy - _MIDDLE) < _MIDDLE - CELL
    field = synthetic.skyrmion_field(
        (DISK_CELLS, DISK_CELLS), CELL, DISK_CENTRES, RADIUS, WALL_WIDTH, mask=disk
    )
    field = synthetic.edge_tilt(field, math.radians(30.0), WALL_WIDTH)
    written.append(
        write_ovf(
            target / "disk-tilted-edges.ovf",
            field,
            fmt="bin4",
            notes=[
                _NOTE,
                "two skyrmions at "
                + " and ".join(f"({x * 1e9:.2f}, {y * 1e9:.2f}) nm" for x, y in DISK_CENTRES)
                + f" in a disk whose edges tilt by 30° (decay length {WALL_WIDTH:g} m)",
            ],
        )
    )
    return written
