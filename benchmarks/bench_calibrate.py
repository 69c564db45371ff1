"""Wall time of ``skygas calibrate``, stage by stage.

Runs a calibration (default: S2 on 2 nm cells, with the mesh check and the validation run) and
prints, for every stage, the solver time summed over its solves and when (in wall time from
the start) its first solve started and its last one ended (stages overlap: the workers run the
validation's LLG beside the relaxations, and a cheap solve may wait behind costly ones), then
the whole calibration's wall time. ``--from DIR`` prints
the same for a finished calibration.

Stages: ``isolated`` (the isolated skyrmion, grown films), ``laws`` (singles and pairs of the
calibration film), ``enlarged``, ``sensitivity``, ``stray`` and ``mesh`` (the checks),
``validation`` (the validation's starting relaxation) and ``llg`` (its dynamics).

Run: ``.venv/bin/python benchmarks/bench_calibrate.py [MATERIAL] [--cell-size 2e-9]
[--no-validate] [--no-mesh-check] [--workers 2] [--out DIR] [--from DIR]``.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path


def report(data: dict, total: float | None = None) -> None:
    prov = data["provenance"]
    spans, solver = prov["stage_spans_s"], prov["solver_seconds_by_stage"]
    material = data["material"]
    print(
        f"{material['name']} on {material['cell_size'] * 1e9:g} nm cells, "
        f"{prov['workers']} worker(s), {prov['device']}, magnum.np {prov['magnumnp_version']}, "
        f"torch {prov['torch_version']}"
    )
    print(f"{'stage':<12} {'solves [s]':>11} {'started [s]':>12} {'done [s]':>9}")
    for stage in sorted(spans, key=lambda k: spans[k][1]):
        cpu = solver.get("validation LLG" if stage == "llg" else stage, float("nan"))
        start, end = spans[stage]
        print(f"{stage:<12} {cpu:11.1f} {start:12.1f} {end:9.1f}")
    if total is not None:
        print(f"total wall time {total:.1f} s")
    validation = data.get("validation", {})
    if "rms_error_max_d_sk" in validation:
        print(
            f"validation: {validation['duration_s'] * 1e9:.2f} ns of LLG, RMS error max "
            f"{validation['rms_error_max_d_sk']:.3f} d_sk"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("material", nargs="?", default="S2")
    parser.add_argument("--cell-size", type=float, default=2e-9)
    parser.add_argument("--no-validate", action="store_true")
    parser.add_argument("--no-mesh-check", action="store_true")
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--out", default=None, help="keep the calibration here")
    parser.add_argument(
        "--from",
        dest="source",
        default=None,
        help="print the times of this finished calibration instead",
    )
    args = parser.parse_args()
    if args.source:
        report(json.loads((Path(args.source) / "summary.json").read_text()))
        return
    from skygas.calibration import calibrate
    from skygas.calibration.material import load_micromagnetic_material

    out = Path(args.out) if args.out else Path(tempfile.mkdtemp()) / "cal"
    started = time.perf_counter()
    data = calibrate(
        load_micromagnetic_material(args.material, cell_size=args.cell_size),
        out,
        workers=args.workers,
        validate_dynamics=not args.no_validate,
        mesh_check=not args.no_mesh_check,
    )
    report(data, time.perf_counter() - started)
    print(f"results in {out}")


if __name__ == "__main__":
    main()
