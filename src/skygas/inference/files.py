"""The files of ``skygas infer``.

- ``inference.json``: every number, with its error and how it was measured;
- ``landscape.nc``: the landscape from the forces with its jackknife error, the areas it is
  sampled and well sampled on, and the Boltzmann inversion's map where it was made;
- ``landscape-map.npy``: the model's map (U [k_BT] where the film was sampled, NaN elsewhere),
  which model.toml's ``[[potentials]]`` table names;
- ``model.toml``: the model, every number of which is in inference.json;
- ``report.html`` (:mod:`skygas.inference.report`).

Everything is made before the first file is written, and each file is written atomically
(:func:`skygas.runs.run_driver.write_atomic`), so an interrupted inference leaves no partial
file; each carries the provenance record (version, command line, the input's hash).
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from skygas.inference.pipeline import MAP_FILE, Inference
from skygas.runs.provenance import provenance


def record(result: Inference) -> dict:
    """The provenance record of the inference's files."""
    return provenance(
        seed=result.summary["input"]["seed"],
        config_hash=result.summary["input"]["sha256"][:16],
        source=result.tracks.source,
    )


def landscape_dataset(result: Inference):
    """The maps [k_BT] on x, y [m]: from the forces, its error, the masks, the cross-check."""
    import xarray as xr

    fmap = result.map
    g = fmap.grid
    variables: dict[str, tuple] = {
        "U": (("y", "x"), fmap.u, {"units": "k_BT", "long_name": "landscape from the forces"}),
        "U_error": (
            ("y", "x"),
            fmap.error,
            {
                "units": "k_BT",
                "long_name": "jackknife error of U relative to its mean over the well-sampled area",
            },
        ),
        "sampled": (("y", "x"), fmap.sampled.astype(np.int8)),
        "well_sampled": (("y", "x"), fmap.well_sampled.astype(np.int8)),
    }
    if result.boltzmann is not None:
        variables["U_boltzmann"] = (
            ("y", "x"),
            result.boltzmann,
            {"units": "k_BT", "long_name": "-ln rho, the neighbours' mean push taken out"},
        )
        variables["U_boltzmann_error"] = (
            ("y", "x"),
            result.boltzmann_error,
            {"units": "k_BT", "long_name": "bootstrap error of -ln rho (time and tracks)"},
        )
    return xr.Dataset(
        variables,
        coords={"x": ("x", g.x, {"units": "m"}), "y": ("y", g.y, {"units": "m"})},
        attrs={**record(result), "temperature_K": result.summary["input"]["temperature_K"]},
    )


def model_sections(result: Inference) -> tuple[dict, list[str], dict[str, str]]:
    """The model file's tables besides ``[material]``, its header and its comments."""
    s = result.summary
    fitted_pair = s["pair"]["fitted"] or {}
    fitted_wall = s["wall"]["fitted"] or {}
    sections: dict = {
        "potentials": [dict(p) for p in result.potentials],
        "inference": {
            "diffusion_constant": s["diffusion_constant"],
            "diffusion_constant_error": s["diffusion_constant_error"],
            "hall_angle": s["hall_angle_in_model"],
            "hall_angle_error": s["hall_angle_error"],
            "hall_angle_fixed_by_data": s["hall_angle"] is not None,
            "temperature": s["input"]["temperature_K"],
            "terms": s["model_selection"]["terms"],
            "pair_fixed_range": fitted_pair.get("fixed_range_m") or [],
            "wall_fixed_range": fitted_wall.get("fixed_range_m") or [],
            "drive_force": s["model"]["drive_force_N"],
            "film": s["film"]["kind"],
            "consistency_check_passed": None
            if s["consistency_check"] is None
            else s["consistency_check"]["passed"],
        },
        "provenance": {k: v for k, v in record(result).items() if k != "config_json"},
    }
    header = [
        "A particle model inferred from tracked skyrmions by `skygas infer` (docs/inference.md).",
        'Use it as --material FILE or material = "FILE" in any device; every number in it is',
        "in inference.json beside it.",
    ]
    comments = {
        "potentials": "The landscape where the movie sampled the film (landscape-map.npy, in the\n"
        "movie's coordinates) and random of its statistics elsewhere. Copy this table, with the\n"
        "file, into a configuration as [[potentials]] for a device on the same film.",
        "inference": "What the data measured (SI; angles in rad; drive_force in N, applied as\n"
        "external_force in the self-check).",
    }
    return sections, header, comments


def write_outputs(result: Inference, out) -> list[Path]:
    """Write the files into ``out``; returns their paths."""
    from skygas.calibration.model_file import write_model
    from skygas.inference.report import report_html
    from skygas.runs.run_driver import write_atomic, write_json, write_netcdf

    out = Path(out)
    # everything is made before the first file is written: a failure leaves no file behind
    summary = {**result.summary, "provenance": record(result)}
    dataset = landscape_dataset(result)
    text = report_html(result)
    sections, header, comments = model_sections(result)
    buffer = io.BytesIO()
    np.save(buffer, result.map_values)
    out.mkdir(parents=True, exist_ok=True)
    paths = [write_atomic(out / MAP_FILE, lambda tmp: tmp.write_bytes(buffer.getvalue()))]
    paths.append(write_model(out / "model.toml", result.material, sections, header, comments))
    paths.append(write_json(out / "inference.json", summary))
    paths.append(write_netcdf(dataset, out / "landscape.nc"))
    paths.append(
        write_atomic(out / "report.html", lambda tmp: tmp.write_text(text, encoding="utf-8"))
    )
    return paths
