"""report.html of a calibration study: each point's isolated skyrmion and laws, side by side.

One self-contained page (figures embedded, no network) built from ``study.json`` alone
(:func:`skygas.calibration.study.run_study`): a table with a row per point (its values of the
swept fields, the radius, the wall width, 𝒟, G, the laws' measured ranges and the validation's
largest RMS centre error), a figure of the radius and of 𝒟 against the first swept field when
it is numeric, the study file and the record itself. Each point's own report is
``point-K/report.html``.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

#: The table's columns after the swept values: (header, key of study.json's point, scale, digits).
COLUMNS = (
    ("radius R (nm)", "radius_m", 1e9, 2),
    ("wall width Δ (nm)", "wall_width_m", 1e9, 2),
    ("𝒟", "dissipation", 1.0, 3),
    ("G (kg/s)", "gyrocoupling_kg_per_s", 1.0, 3),
    ("pair law measured to (d_sk)", "pair_measured_range_d_sk", None, 2),
    ("edge law measured to (d_sk)", "wall_measured_range_d_sk", None, 2),
    ("validation: largest RMS centre error (d_sk)", "rms_error_max_d_sk", 1.0, 3),
)


def _cell(value: Any, scale: float | None, digits: int) -> str:
    """A number for the table; a measured range [lo, hi] as "lo–hi"; "–" when absent."""
    if value is None:
        return "–"
    if scale is None:  # a range
        lo, hi = value
        return f"{lo:.{digits}f}–{hi:.{digits}f}"
    if abs(value * scale) >= 1e-2 and abs(value * scale) < 1e4:
        return f"{value * scale:.{digits}f}"
    return f"{value * scale:.{digits}g}"


def point_table(record: dict) -> tuple[list[str], list[list[str]]]:
    """The header and the rows (one per point) of the report's table, as text."""
    fields = list(record["fields"])
    header = ["point", *fields, *(c[0] for c in COLUMNS)]
    rows = []
    for p in record["points"]:
        values = [str(p["values"].get(f, "")) for f in fields]
        cells = [_cell(p.get(key), scale, digits) for _, key, scale, digits in COLUMNS]
        rows.append([p["folder"], *values, *cells])
    return header, rows


def _figure(record: dict) -> bytes | None:
    """The radius and 𝒟 against the first swept field, when it is numeric and has two values."""
    fields = record["fields"]
    points = record["points"]
    if not fields or len(points) < 2:
        return None
    x = [p["values"].get(fields[0]) for p in points]
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in x):
        return None
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8, 3.2), dpi=110)
    left, right = fig.subplots(1, 2)
    left.plot(x, [p["radius_m"] * 1e9 for p in points], "o-")
    left.set_ylabel("radius R (nm)")
    right.plot(x, [p["dissipation"] for p in points], "s-")
    right.set_ylabel(r"dissipation $\mathcal{D}$")
    for ax in (left, right):
        ax.set_xlabel(fields[0])
    fig.tight_layout()
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png")
    return buffer.getvalue()


def write_study_report(record: dict, out: str | Path) -> Path:
    """Write ``out/report.html`` for the study whose ``study.json`` is ``record``; its path."""
    from skygas.outputs.report import Page, _made_by
    from skygas.runs.run_driver import write_atomic

    out = Path(out)
    points = record["points"]
    page = Page(f"skygas calibrate — a study of {len(points)} film(s)")
    _made_by(page, out, record.get("skygas_version"), None)
    fields = ", ".join(record["fields"]) or "whole films"
    page.paragraph(
        f"{len(points)} calibrations ({fields}); each point's folder holds its model.toml, "
        "summary.json and report.html."
    )
    page.heading("Isolated skyrmion and laws, point by point")
    page.grid(*point_table(record))
    png = _figure(record)
    if png is not None:
        first = record["fields"][0]
        others = (
            " (one line through every point, in the study's order)"
            if len(record["fields"]) > 1
            else ""
        )
        page.image(
            png,
            f"The isolated skyrmion's radius (left) and its dissipation 𝒟 (right) against "
            f"{first}{others}, from study.json.",
        )
    page.heading("Study file")
    page.pre(record.get("study_file", ""))
    page.heading("Data")
    page.json_block("study", record)
    text = page.html()
    return write_atomic(out / "report.html", lambda tmp: tmp.write_text(text, encoding="utf-8"))
