"""Two skyrmions relaxing apart, simulated with magnum.np, written as mumax3-like OVF snapshots.

    python examples/micromagnetics/pair_relaxation.py --out runs/pair [--cell-size 2e-9] \
        [--duration 5e-9] [--snapshots 51]
    skygas micromag fit runs/pair --out runs/pair-fit

The run, in a 400 × 250 nm film of material S2 (α = 0.1, 2 nm thick, one cell layer):

1. two S2 skyrmions (360° wall ansatz, R = S2's radius) are placed ``--separation`` (72 nm)
   apart on the film's long axis, and the energy is minimised with the cells of each core within
   ``--pin-radius`` (16 nm) of its centre held fixed (``FilmSolver.relax`` with ``pinned``): the
   constrained minimum at that separation, with the walls and the tails' overlap relaxed;
2. the cores are released and the Landau–Lifshitz–Gilbert equation is integrated for
   ``--duration`` (5 ns) at T = 0; ``--snapshots`` (51) files ``m000000.ovf`` … are written at a
   fixed interval, the first one the released state at t = 0, each with its time in a
   ``# Desc: Total simulation time`` line as mumax3 writes it.

The repulsion pushes the pair apart (and the gyrotropic force turns it) over a narrow range
of distances: 1.75–2.41 skyrmion diameters at 2 nm cells, 1.82–2.11 in the first 2 ns, which
do not fix the far field of the pair law (docs/micromagnetics.md). ``OUT/run.json`` records
the parameters, the solver's versions and the timings. About 20 min of one CPU core at 2 nm
cells, under 2 min at 4 nm (``--cell-size 4e-9``, to try the pipeline). Needs the
``micromagnetics`` extra (torch, magnum.np).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from skygas._version import __version__
from skygas.calibration import solver
from skygas.calibration.material import load_micromagnetic_material
from skygas.core.errors import InputError
from skygas.micromag import field_from_array, write_ovf
from skygas.physics.materials import preset
from skygas.runs.run_driver import write_atomic, write_json

WIDTH, HEIGHT = 400e-9, 250e-9  # m, the film (rounded to whole cells)
# The pinned disk of each core [m]. The core of an S2 skyrmion (R ≈ 20 nm) is flat: with only
# the 2 × 2 cells at its centre pinned, the repulsion slid the pair from 72 to 83 nm during the
# pinned relaxation (2 nm cells); pinning the cells within 16 nm holds it at 72.4 nm.
PIN_RADIUS = 16e-9


def parse_args(argv=None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", required=True, help="folder for the OVF snapshots and run.json")
    parser.add_argument("--cell-size", type=float, default=2e-9, help="cell size [m] (2e-9)")
    parser.add_argument(
        "--duration", type=float, default=5e-9, help="LLG time after the release [s] (5e-9)"
    )
    parser.add_argument(
        "--snapshots", type=int, default=51, help="files written, the first at the release (51)"
    )
    parser.add_argument(
        "--separation", type=float, default=72e-9, help="distance of the pinned cores [m] (72e-9)"
    )
    parser.add_argument(
        "--pin-radius",
        type=float,
        default=PIN_RADIUS,
        help="pin the cells within this distance of each core's centre [m] (16e-9)",
    )
    parser.add_argument("--threads", type=int, default=1, help="torch threads (1)")
    return parser.parse_args(argv)


def check(args: argparse.Namespace, out: Path) -> None:
    """Refuse, before any solve, what the run cannot do (one line each)."""
    if not args.snapshots >= 3:
        raise InputError("--snapshots", args.snapshots, "at least 3 files")
    if not args.duration > 0:
        raise InputError("--duration", args.duration, "a time > 0 in seconds")
    if not 0 <= args.pin_radius < args.separation / 2:
        raise InputError("--pin-radius", args.pin_radius, "a radius in [0, separation/2) m")
    if not 0 < args.separation < WIDTH / 2:
        raise InputError("--separation", args.separation, f"a distance in (0, {WIDTH / 2:g}) m")
    if not 0 < args.cell_size <= 5e-9:
        raise InputError("--cell-size", args.cell_size, "a cell size in (0, 5e-9] m")
    if out.exists() and any(out.glob("*.ovf")):
        raise InputError(
            "--out",
            str(out),
            "a new or empty folder (it holds OVF files: `micromag fit` reads every snapshot in it)",
        )


def core_cells(film: solver.Film, centre, radius: float) -> list[tuple[int, int]]:
    """The cells whose centres lie within ``radius`` [m] (at least one cell) of ``centre`` [m]:
    a disk symmetric about the centre, so that pinning keeps the pair's mirror symmetry."""
    x, y = film.centres()
    reach = max(radius, film.cell_size)
    near = np.hypot(x - centre[0], y - centre[1]) < reach
    return [tuple(map(int, ij)) for ij in np.argwhere(near)]


def as_field(m: np.ndarray, film: solver.Film, thickness: float, t: float):
    """The solver's (nx, ny, 3) texture as an OVF field (ny, nx, 3) at time ``t`` [s]."""
    return field_from_array(
        np.transpose(m, (1, 0, 2)), (film.cell_size, film.cell_size, thickness), time=t
    )


def main(argv=None) -> int:
    args = parse_args(argv)
    out = Path(args.out)
    try:
        check(args, out)
        material = load_micromagnetic_material("S2", cell_size=args.cell_size)
    except InputError as err:
        print(f"pair_relaxation: error: {err}", file=sys.stderr)
        return 2
    out.mkdir(parents=True, exist_ok=True)
    solver.configure(threads=args.threads)
    # the film in whole cells, as close to 400 × 250 nm as the cell allows
    film = solver.Film(
        round(WIDTH / args.cell_size), round(HEIGHT / args.cell_size), args.cell_size
    )
    width, height = film.size
    centres = [
        (width / 2 - args.separation / 2, height / 2),
        (width / 2 + args.separation / 2, height / 2),
    ]
    radius = preset("S2").skyrmion_radius
    m0 = solver.skyrmion_texture(film, centres, radius, material.bare_wall_width)
    pinned = solver.core_mask(
        film, [c for centre in centres for c in core_cells(film, centre, args.pin_radius)]
    )
    print(
        f"{film.nx} × {film.ny} cells of {args.cell_size * 1e9:g} nm, material S2, "
        f"cores pinned {args.separation * 1e9:g} nm apart; solver on {solver.device_name()}",
        flush=True,
    )
    fs = solver.FilmSolver(material, film)
    relaxed = fs.relax(m0, pinned)
    print(
        f"relaxed with the cores pinned: {relaxed.iterations} iterations, torque "
        f"{relaxed.torque:.3g} A/m, {relaxed.seconds:.0f} s",
        flush=True,
    )
    if not relaxed.converged:
        print("pair_relaxation: error: the pinned relaxation did not converge", file=sys.stderr)
        return 1
    interval = args.duration / (args.snapshots - 1)
    note = (
        f"magnum.np LLG run by examples/micromagnetics/pair_relaxation.py (skygas "
        f"{__version__}): two S2 skyrmions released {args.separation:g} m apart, "
        f"alpha = {material.damping:g}"
    )

    def snapshot(i: int, m: np.ndarray, t: float) -> None:
        field = as_field(m, film, material.film_thickness, t)
        write_atomic(out / f"m{i:06d}.ovf", lambda tmp: write_ovf(tmp, field, notes=[note]))

    m, t, step = relaxed.m, 0.0, 1e-14
    snapshot(0, m, t)
    started, steps = time.perf_counter(), 0
    for i in range(1, args.snapshots):
        # Each piece starts from the previous piece's step: the run is the same as one
        # uncut integration (FilmSolver.evolve), whatever the number of snapshots.
        piece = fs.evolve(m, t, interval, first_step=step)
        m, step, steps = piece.m, piece.next_step, steps + piece.steps
        t = i * interval  # the nominal time: uniform spacing, as mumax3's autosave writes
        snapshot(i, m, t)
        print(
            f"  snapshot {i}/{args.snapshots - 1}: t = {piece.time * 1e9:.4f} ns, "
            f"{piece.steps} steps, {piece.seconds:.1f} s",
            flush=True,
        )
    write_json(
        out / "run.json",
        {
            "skygas_version": __version__,
            "solver": solver.versions(),
            "device": solver.device_name(),
            "material": material.as_record(),
            "film": {
                "nx": film.nx,
                "ny": film.ny,
                "cell_size_m": film.cell_size,
                "width_m": width,
                "height_m": height,
            },
            "parameters": {
                "separation_m": args.separation,
                "duration_s": args.duration,
                "snapshots": args.snapshots,
                "interval_s": interval,
                "initial_radius_m": radius,
                "initial_wall_width_m": material.bare_wall_width,
                "pin_radius_m": args.pin_radius,
                "pinned_cells": int(pinned.sum()),
                "threads": args.threads,
            },
            "relaxation": {
                "iterations": relaxed.iterations,
                "torque_A_per_m": relaxed.torque,
                "energy_J": relaxed.energy,
                "seconds": relaxed.seconds,
            },
            "llg": {"steps": steps, "seconds": time.perf_counter() - started},
        },
    )
    print(
        f"{args.snapshots} snapshots in {out}; next: skygas micromag fit {out} --out FIT",
        flush=True,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
