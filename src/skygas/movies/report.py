"""The figures and the HTML report of ``skygas track``.

``detections.png``: the first frame with every located skyrmion circled (trackpy's diameter);
``track_lengths.png``: the histogram of the tracks' lengths and the number located per frame.
Axis units in parentheses, as in every figure of skygas: "x (px)". ``report.html``
(self-contained, :class:`skygas.outputs.report.Page`): which command made it, when and with which
skygas, a headline table (:func:`headline_rows`, every number from track.json's counts, which
tracks.csv holds), the choices and where each came from, the figures and the overlay movie.
Numbers are written as :func:`skygas.core.quantities.format_value` writes them (SI prefixes or
×10ⁿ, never e-notation).
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np


def write_figures(out: Path, movie, tracks, choices, summary: dict) -> None:
    """Write ``detections.png`` and ``track_lengths.png`` into ``out``, with the provenance."""
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle
    from matplotlib.ticker import MaxNLocator

    from skygas.runs.run_driver import write_figure

    record = {k: str(v) for k, v in summary["provenance"].items()}

    def detections(path: Path) -> None:
        fig = Figure(figsize=(6.5, 5.5 * movie.shape[0] / movie.shape[1] + 0.6), dpi=110)
        ax = fig.add_subplot()
        image = ax.imshow(movie.frame(0), cmap="gray", origin="lower")
        # the movie's own grey levels (counts, or a float image's values), as read
        fig.colorbar(image, ax=ax, label="pixel value", shrink=0.8, fraction=0.05, pad=0.03)
        first = tracks.table[tracks.table["frame"] == 0]
        if tracks.drift is not None:  # where they are in the picture
            first = first.assign(
                x=first["x"] + tracks.drift[0, 0], y=first["y"] + tracks.drift[0, 1]
            )
        for x, y in first[["x", "y"]].to_numpy():
            ax.add_patch(Circle((x, y), choices.diameter / 2, fill=False, color="tab:orange"))
        ax.set_title(f"frame 0: {len(first)} skyrmions located ({choices.contrast} contrast)")
        ax.set_xlabel("x (px)")
        ax.set_ylabel("y (px)")
        fig.tight_layout()
        fig.savefig(path)

    def lengths(path: Path) -> None:
        fig = Figure(figsize=(9, 3.6), dpi=110)
        ax1, ax2 = fig.subplots(1, 2)
        ell = tracks.lengths
        if len(ell):
            ax1.hist(ell, bins=np.linspace(0.5, movie.n_frames + 0.5, min(40, movie.n_frames) + 1))
        ax1.set_xlabel("track length (frames)")
        ax1.set_ylabel("tracks")
        ax1.set_title(f"{len(ell)} tracks")
        ax2.plot(tracks.per_frame(movie.n_frames), lw=0.8)
        ax2.set_xlabel("frame")
        ax2.set_ylabel("skyrmions located")
        ax2.set_ylim(bottom=0)
        for ax in (ax1, ax2):  # counts: whole-number ticks
            ax.yaxis.set_major_locator(MaxNLocator(integer=True))
        fig.tight_layout()
        fig.savefig(path)

    write_figure(out / "detections.png", detections, record)
    write_figure(out / "track_lengths.png", lengths, record)


def _q(value: float, unit: str = "", digits: int = 3) -> str:
    """``value`` as the reports write numbers (an SI prefix, or ×10ⁿ; no e-notation)."""
    from skygas.core.quantities import format_value

    return format_value(value, unit=unit, digits=digits) or "none"


def headline_rows(summary: dict) -> list[tuple[str, str]]:
    """The headline block of a track report: (label, value) rows from track.json's numbers.

    Counts and track lengths are those of tracks.csv (a track's length is the frames from its
    first to its last, gaps included); "skyrmions per frame" is located features per frame.
    """
    n = summary["counts"]
    p, dt = summary["pixel_size_m"], summary["frame_interval_s"]
    sources = summary["scale_sources"]
    rows = [
        (
            "frames",
            f"{summary['frames']} of {summary['frame_shape_px'][1]} × "
            f"{summary['frame_shape_px'][0]} px ({summary['dtype']})",
        ),
        (
            "pixel size",
            f"{_q(p, 'm', 4)} ({sources['pixel_size']})" if p else "not known (in pixels)",
        ),
        (
            "frame interval",
            f"{_q(dt, 's', 4)} ({sources['frame_interval']})" if dt else "not known (in frames)",
        ),
        (
            "skyrmions per frame, mean (least – most)",
            f"{n['per_frame_mean']:.2f} ({n['per_frame_min']} – {n['per_frame_max']})",
        ),
        ("located skyrmions, all frames", str(n["features"])),
        ("tracks", str(n["tracks"])),
    ]
    if "track_length_mean_frames" in n:  # track.json of skygas 0.x before it recorded the mean
        rows.append(("track length, mean", f"{n['track_length_mean_frames']:.1f} frames"))
    rows += [
        (
            "track length, median / longest",
            f"{n['track_length_median_frames']:.0f} / {n['track_length_max_frames']} frames",
        ),
        ("tracks spanning the whole movie", str(n["tracks_spanning_whole_movie"])),
    ]
    return rows


def _made_by(page, summary: dict) -> None:
    """The line every report starts with: Made by COMMAND on DATE, with skygas VERSION.

    The command is track.json's (the running command line, or none from Python) and the date
    is now, as the report is written at the end of the tracking. Not from the folder's manifest
    (:func:`skygas.outputs.report._made_by`): ``skygas track`` writes that when it has finished,
    and until then, under ``--overwrite``, it describes the run being replaced.
    """
    import html

    from skygas._version import __version__

    argv = summary["provenance"].get("command_line")
    made = (
        f"Made by <code class=command>{html.escape(argv)}</code>"
        if argv
        else "Made from Python (no command line recorded)"
    )
    when = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    page.raw(f"<p class=made>{made} on {when}, with skygas {html.escape(__version__)}.</p>")


def track_report(out: Path, summary: dict) -> str:
    """The HTML text of the report of a ``skygas track`` folder ``out``."""
    from skygas.outputs import headlines as H
    from skygas.outputs.report import Page

    page = Page(f"skygas track — {Path(summary['movie']).name}")
    c = summary["choices"]
    _made_by(page, summary)
    page.paragraph(f"Movie: {summary['movie']}. The numbers below are those of track.json.")
    headline = H.Results()
    headline.rows += headline_rows(summary)
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
                f"{_q(c['feature_sigma_px'])} px), separation {c['separation']} px",
            ),
            (
                "mass threshold (minmass)",
                f"{_q(c['minmass'], digits=4)} ({src['minmass']}; noise σ "
                f"{_q(c['noise_sigma'])} counts; median mass "
                f"{_q(c['mass_margin'])}× the threshold)",
            ),
            (
                "search range",
                f"{_q(c['search_range'])} px ({src['search_range']}; step σ "
                f"{_q(c['step_sigma_px'])} px, neighbours "
                f"{_q(c['neighbour_distance_px'])} px apart)",
            ),
            ("memory", f"{c['memory']} frames ({src['memory']})"),
            ("drift subtraction", "yes" if c["drift_subtraction"] else "no"),
        ]
    )
    page.heading("Overlay movie")
    page.paragraph(
        "The movie with each located skyrmion circled in its track's colour and a tail through "
        "its last positions; row 0 of the frames at the top, as image viewers show them; below "
        "the picture, the frame's number and a scale bar."
    )
    page.movie(out / "overlay.mp4")
    page.heading("Figures")
    for name, caption in (
        (
            "detections.png",
            "The first frame (row 0 at the bottom) with each skyrmion located in it circled "
            "(trackpy's feature diameter).",
        ),
        (
            "track_lengths.png",
            "Left: histogram of the tracks' lengths (frames from first to last). Right: the "
            "skyrmions located in each frame.",
        ),
    ):
        page.image((out / name).read_bytes(), caption)
    page.heading("Data")
    page.pre(json.dumps(summary, indent=1, default=str))
    page.json_block("track", summary)
    return page.html()
