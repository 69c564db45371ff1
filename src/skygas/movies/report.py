"""The figures and the HTML report of ``skygas track``.

``detections.png``: the first frame with every located skyrmion circled (trackpy's diameter);
``track_lengths.png``: the histogram of the tracks' lengths and the number located per frame.
``report.html`` (self-contained, :class:`skygas.outputs.report.Page`): a headline table, the
choices and where each came from, the figures and the overlay movie.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np


def write_figures(out: Path, movie, tracks, choices, summary: dict) -> None:
    """Write ``detections.png`` and ``track_lengths.png`` into ``out``, with the provenance."""
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle

    from skygas.runs.run_driver import write_figure

    record = {k: str(v) for k, v in summary["provenance"].items()}

    def detections(path: Path) -> None:
        fig = Figure(figsize=(5.5, 5.5 * movie.shape[0] / movie.shape[1] + 0.6), dpi=110)
        ax = fig.add_subplot()
        ax.imshow(movie.frame(0), cmap="gray", origin="lower")
        first = tracks.table[tracks.table["frame"] == 0]
        if tracks.drift is not None:  # where they are in the picture
            first = first.assign(
                x=first["x"] + tracks.drift[0, 0], y=first["y"] + tracks.drift[0, 1]
            )
        for x, y in first[["x", "y"]].to_numpy():
            ax.add_patch(Circle((x, y), choices.diameter / 2, fill=False, color="tab:orange"))
        ax.set_title(f"frame 0: {len(first)} skyrmions located ({choices.contrast} contrast)")
        ax.set_xlabel("x [px]")
        ax.set_ylabel("y [px]")
        fig.tight_layout()
        fig.savefig(path)

    def lengths(path: Path) -> None:
        fig = Figure(figsize=(9, 3.6), dpi=110)
        ax1, ax2 = fig.subplots(1, 2)
        ell = tracks.lengths
        if len(ell):
            ax1.hist(ell, bins=np.linspace(0.5, movie.n_frames + 0.5, min(40, movie.n_frames) + 1))
        ax1.set_xlabel("track length [frames]")
        ax1.set_ylabel("tracks")
        ax1.set_title(f"{len(ell)} tracks")
        ax2.plot(tracks.per_frame(movie.n_frames), lw=0.8)
        ax2.set_xlabel("frame")
        ax2.set_ylabel("skyrmions located")
        ax2.set_ylim(bottom=0)
        fig.tight_layout()
        fig.savefig(path)

    write_figure(out / "detections.png", detections, record)
    write_figure(out / "track_lengths.png", lengths, record)


def track_report(out: Path, summary: dict) -> str:
    """The HTML text of the report of a ``skygas track`` folder ``out``."""
    from skygas.outputs.report import Page

    page = Page(f"skygas track — {Path(summary['movie']).name}")
    c, n = summary["choices"], summary["counts"]
    p, dt = summary["pixel_size_m"], summary["frame_interval_s"]
    page.paragraph(f"Report written by {summary['provenance']['written_by']} from track.json.")
    from skygas.core.quantities import format_value
    from skygas.outputs import headlines as H

    headline = H.Results()
    headline.rows += [
        (
            "frames",
            f"{summary['frames']} of {summary['frame_shape_px'][1]} × "
            f"{summary['frame_shape_px'][0]} px ({summary['dtype']})",
        ),
        ("pixel size", (format_value(p, unit="m") if p else None) or "not known (in pixels)"),
        ("frame interval", (format_value(dt, unit="s") if dt else None) or "not known (in frames)"),
        (
            "skyrmions per frame",
            f"{n['per_frame_mean']:.2f} (from {n['per_frame_min']} to {n['per_frame_max']})",
        ),
        ("located features", str(n["features"])),
        ("tracks", str(n["tracks"])),
        (
            "track length, median / longest",
            f"{n['track_length_median_frames']:.0f} / {n['track_length_max_frames']} frames",
        ),
        ("tracks spanning the whole movie", str(n["tracks_spanning_whole_movie"])),
    ]
    page.headline(headline)
    for warning in summary["warnings"]:
        page.paragraph(f"Warning: {warning}")
    page.heading("Choices")
    src = c["sources"]
    page.table(
        [
            (
                "contrast",
                f"{c['contrast']} ({src['contrast']}; skewness of the high-passed "
                f"pixels {c['skewness']:+.3f})",
            ),
            (
                "feature diameter",
                f"{c['diameter']} px ({src['diameter']}; spot σ "
                f"{c['feature_sigma_px']:.3g} px), separation {c['separation']} px",
            ),
            (
                "mass threshold (minmass)",
                f"{c['minmass']:.4g} ({src['minmass']}; noise σ "
                f"{c['noise_sigma']:.3g} counts; median mass "
                f"{c['mass_margin']:.3g}× the threshold)",
            ),
            (
                "search range",
                f"{c['search_range']:.3g} px ({src['search_range']}; step σ "
                f"{c['step_sigma_px']:.3g} px, neighbours "
                f"{c['neighbour_distance_px']:.3g} px apart)",
            ),
            ("memory", f"{c['memory']} frames ({src['memory']})"),
            ("drift subtraction", "on" if c["drift_subtraction"] else "off"),
        ]
    )
    page.heading("Overlay movie")
    page.movie(out / "overlay.mp4")
    page.heading("Figures")
    for name, caption in (
        ("detections.png", "the first frame and its detections"),
        ("track_lengths.png", "track lengths and skyrmions per frame"),
    ):
        page.image((out / name).read_bytes(), caption)
    page.heading("Data")
    page.pre(json.dumps(summary, indent=1, default=str))
    page.json_block("track", summary)
    return page.html()
