"""One self-contained HTML report of a run or a sweep: open it anywhere, offline.

Everything is inside the file: figures as PNG data URIs, the movie as an MP4 (or GIF) data URI,
and the numbers as embedded JSON (with a download link). No script, style sheet, font or
image is fetched from the network.

A run's report holds its kind, provenance (skygas version, seed, the full configuration and
the engine's parameters when recorded), the summary numbers, the observables of
:func:`skygas.analysis.analyze` with their standard errors (MSD, D, velocity and Hall angle,
g(r), occupancy) and their figures, every PNG figure of the run directory, and its movie. A
sweep's report holds the sweep's provenance, its scaling fits and its figures.
"""

from __future__ import annotations

import base64
import html
import io
import json
import math
from pathlib import Path

import numpy as np

from skygas._version import __version__
from skygas.core.errors import InputError

MOVIE_NAMES = ("movie.mp4", "movie.gif")
_STYLE = """
body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;
color:#222}
h1{font-size:1.5em}h2{font-size:1.2em;border-bottom:1px solid #ccc;padding-bottom:.2em}
table{border-collapse:collapse;font-size:.9em}td,th{border:1px solid #ddd;padding:.2em .6em;
text-align:left}td.n{text-align:right;font-variant-numeric:tabular-nums}
figure{display:inline-block;margin:.5em;vertical-align:top}figure img{max-width:100%;
border:1px solid #eee}figcaption{font-size:.85em;color:#555}
video,.movie{max-width:100%;max-height:80vh;border:1px solid #ccc}
pre{background:#f6f6f6;padding:.6em;overflow:auto;max-height:30em;font-size:.8em}
"""


def _data_uri(mime: str, data: bytes) -> str:
    return f"data:{mime};base64,{base64.b64encode(data).decode('ascii')}"


def _figure_png(fig) -> bytes:
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    buf = io.BytesIO()
    FigureCanvasAgg(fig).print_png(buf)
    return buf.getvalue()


def _number(value, error=None, unit: str = "") -> str:
    """``value ± error unit`` with the value rounded to the error's precision."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "n/a"
    if not isinstance(value, (int, float)) or isinstance(value, bool):
        return html.escape(str(value))
    if error is None or not math.isfinite(error) or error <= 0:
        return f"{value:.4g} {unit}".strip()
    digits = max(0, 1 - math.floor(math.log10(error)))
    exponent = math.floor(math.log10(abs(value))) if value else 0
    if abs(exponent) >= 4:
        scale = 10.0**exponent
        d = max(0, digits + exponent)
        return f"({value / scale:.{d}f} ± {error / scale:.{d}f})×10^{exponent} {unit}".strip()
    return f"{value:.{digits}f} ± {error:.{digits}f} {unit}".strip()


class _Page:
    """The HTML document, built section by section."""

    def __init__(self, title: str):
        self.title = title
        self.parts: list[str] = []

    def heading(self, text: str) -> None:
        self.parts.append(f"<h2>{html.escape(text)}</h2>")

    def paragraph(self, text: str) -> None:
        self.parts.append(f"<p>{html.escape(text)}</p>")

    def table(self, rows) -> None:
        body = "".join(
            f"<tr><th>{html.escape(str(k))}</th><td class=n>{v}</td></tr>" for k, v in rows
        )
        self.parts.append(f"<table>{body}</table>")

    def image(self, png: bytes, caption: str) -> None:
        self.parts.append(
            f'<figure><img src="{_data_uri("image/png", png)}" '
            f'alt="{html.escape(caption)}"><figcaption>{html.escape(caption)}'
            "</figcaption></figure>"
        )

    def movie(self, path: Path) -> None:
        data = path.read_bytes()
        if path.suffix == ".mp4":
            self.parts.append(
                f'<video id="movie" controls muted loop preload="auto" '
                f'src="{_data_uri("video/mp4", data)}"></video>'
            )
        else:
            self.image_tag(_data_uri("image/gif", data), "movie of the gas")

    def image_tag(self, uri: str, alt: str) -> None:
        self.parts.append(f'<img class="movie" src="{uri}" alt="{html.escape(alt)}">')

    def json_block(self, name: str, data) -> None:
        text = json.dumps(data, indent=1, default=_jsonable)
        inline = text.replace("</", "<\\/")  # no "</script>" inside the block
        self.parts.append(
            f'<script type="application/json" id="{name}">{inline}'
            f'</script><p><a download="{name}.json" href="'
            f'{_data_uri("application/json", text.encode())}">download {name}.json</a></p>'
        )

    def pre(self, text: str) -> None:
        self.parts.append(f"<pre>{html.escape(text)}</pre>")

    def html(self) -> str:
        return (
            "<!DOCTYPE html>\n<html lang=en><head><meta charset=utf-8>"
            # no network: a policy that forbids every fetch but data: URIs and inline style
            "<meta http-equiv=Content-Security-Policy content=\"default-src 'none'; "
            "img-src data:; media-src data:; style-src 'unsafe-inline'\">"
            f"<meta name=viewport content='width=device-width'>"
            f"<title>{html.escape(self.title)}</title><style>{_STYLE}</style></head><body>"
            f"<h1>{html.escape(self.title)}</h1>" + "\n".join(self.parts) + "</body></html>"
        )


#: The page builder, for other reports (the calibration's).
Page = _Page
#: ``value ± error unit`` rounded to the error's precision, for other reports.
format_number = _number


def _jsonable(value):
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return str(value)


def _write(text: str, path: Path) -> Path:
    from skygas.runs.run_driver import write_atomic

    return write_atomic(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))


def check_report_path(path: str | Path) -> Path:
    """``path`` as a Path; refused (:class:`InputError`) unless .html in an existing folder."""
    path = Path(path)
    if path.suffix.lower() not in (".html", ".htm"):
        raise InputError("--out", str(path), "a file name ending in .html")
    if not path.parent.is_dir():
        raise InputError("--out", str(path), "a file in an existing directory")
    return path


def write_report(source: str | Path, out: str | Path, *, analysis: dict | None = None) -> Path:
    """Write the report of the run or sweep store at ``source`` to ``out`` (.html)."""
    out = check_report_path(out)
    if isinstance(source, (list, tuple)):  # sweep stores drawn together
        return _write(sweep_report([Path(s) for s in source]), out)
    source = Path(source)
    if (source / "zarr.json").exists():
        return _write(sweep_report(source), out)
    from skygas.outputs.records import RESULT_FILES, load_run

    if (
        source.is_dir()
        and not any((source / n).exists() for n in RESULT_FILES)
        and any((source / n).exists() for n in SUMMARY_FILES)
    ):
        return _write(directory_report(source), out)  # a run that kept no positions
    return _write(run_report(load_run(source), analysis=analysis), out)


def _movie(page: _Page, directory: Path) -> None:
    movie = next((directory / n for n in MOVIE_NAMES if (directory / n).exists()), None)
    if movie is not None:
        page.heading("Movie")
        page.movie(movie)


def _figures(page: _Page, directory: Path) -> None:
    figures = sorted(directory.glob("*.png"))
    if figures:
        page.heading("Figures")
        for path in figures:
            page.image(path.read_bytes(), path.name)


#: the summary files of runs that keep no positions, in the order a directory is searched
SUMMARY_FILES = ("summary.json", "reservoir.json", "saturation.json")


def directory_report(directory: Path) -> str:
    """The report of a run directory that holds a summary and figures but no positions.

    Such as a neuron run without ``--animate``, a reservoir study, a saturation curve.
    """
    name = next(n for n in SUMMARY_FILES if (directory / n).exists())
    summary = json.loads((directory / name).read_text())
    provenance = summary.get("device", summary)  # the reservoir keeps it with its device
    page = _Page(f"skygas run — {directory.name}")
    page.paragraph(f"Report written by skygas {__version__} from {directory / name}.")
    page.heading("Provenance")
    page.table(
        [
            ("skygas version of the run", provenance.get("skygas_version", "?")),
            ("seed", provenance.get("seed", "?")),
        ]
    )
    _movie(page, directory)
    page.heading("Summary")
    page.table(_summary_rows(summary))
    _figures(page, directory)
    page.heading("Configuration")
    page.pre(json.dumps(summary.get("config", {}), indent=2))
    page.heading("Data")
    page.json_block("summary", summary)
    return page.html()


# -- runs -----------------------------------------------------------------------------------
def run_report(record, *, analysis: dict | None = None) -> str:
    """The HTML text of a run's report.

    ``analysis``: a ready :func:`skygas.analysis.analyze` result, computed here without the maps
    when not given.
    """
    from skygas.analysis import analyze

    if analysis is None:
        analysis = analyze(record, maps=False)
    page = _Page(f"skygas {record.kind} run — {record.directory.name}")
    page.paragraph(f"Report written by skygas {__version__} from {record.path.name}.")
    page.heading("Provenance")
    page.table(
        [
            ("run kind", record.kind),
            ("skygas version of the run", record.version),
            ("seed", record.seed),
            ("result file", html.escape(str(record.path))),
            ("frames recorded", record.frames.n_frames),
            (
                "time span",
                _number(float(record.frames.time[-1]), unit="s")
                if record.frames.n_frames
                else "n/a",
            ),
        ]
    )
    _movie(page, record.directory)
    page.heading("Summary")
    if record.summary:
        page.table(_summary_rows(record.summary))
    page.heading("Observables")
    page.table(_observable_rows(analysis))
    for png, caption in _analysis_figures(analysis):
        page.image(png, caption)
    _figures(page, record.directory)
    page.heading("Configuration")
    page.pre(json.dumps(record.config, indent=2))
    page.heading("Data")
    page.json_block("summary", record.summary or {})
    page.json_block("observables", analysis)
    return page.html()


def _summary_rows(summary: dict):
    """Scalar summary entries; ``x`` with a sibling ``x_error`` shows as x ± error."""
    rows = []
    for key, value in summary.items():
        if key.endswith("_error") or key in ("config",) or isinstance(value, (dict, list)):
            continue
        error = summary.get(f"{key}_error")
        if error is None and key.endswith("_s"):
            error = summary.get(f"{key[:-2]}_error_s")
        rows.append((key, _number(value, error if isinstance(error, float) else None)))
    interval = summary.get("p_out_interval")
    if interval:
        rows.append(("p_out 95 % interval", f"{interval[0]:.4f} – {interval[1]:.4f}"))
    return rows


def _observable_rows(a: dict):
    rows = [("frames analysed", a.get("frames")), ("skyrmion entries", a.get("entries"))]
    diffusion = a.get("diffusion")
    if diffusion:
        removed = " (drift removed)" if diffusion.get("drift_subtracted") else ""
        for key, label in (("short_time", "short-time D₀"), ("long_time", "long-time D_eff")):
            value = diffusion.get(f"{key}_diffusion_m2_s")
            if value is not None:
                error = diffusion[f"{key}_diffusion_error_m2_s"]
                rows.append((f"{label}{removed}", _number(value, error, "m²/s")))
            elif diffusion.get(f"{key}_reason"):
                rows.append((f"{label}", f"none: {diffusion[f'{key}_reason']}"))
        if diffusion.get("reason"):
            rows.append(("diffusion constant", f"none: {diffusion['reason']}"))
        if a.get("free_diffusion_constant_m2_s"):
            rows.append(
                (
                    "free diffusion constant D₀ (material, T)",
                    _number(a["free_diffusion_constant_m2_s"], unit="m²/s"),
                )
            )
    v = a.get("velocity")
    if v:
        rows.append(
            (
                "mean velocity (vx, vy)",
                f"{_number(v['velocity_m_s'][0], v['velocity_error_m_s'][0])}, "
                f"{_number(v['velocity_m_s'][1], v['velocity_error_m_s'][1])} m/s",
            )
        )
        if v.get("hall_angle_reason"):
            rows.append(("Hall angle", f"none: {v['hall_angle_reason']}"))
        if "hall_angle_rad" in v:
            rows.append(
                (
                    f"Hall angle from the drive direction (skyrmions ≥ "
                    f"{v['hall_angle_wall_clearance_diameters']:g} d_sk from walls)",
                    _number(
                        math.degrees(v["hall_angle_rad"]),
                        math.degrees(v["hall_angle_error_rad"]),
                        "°",
                    ),
                )
            )
    occ = a.get("occupancy", {})
    if occ:
        rows.append(("mean skyrmions present", _number(occ.get("mean_total"))))
        for name in ("up", "down"):
            if f"mean_{name}" in occ:
                rows.append((f"mean skyrmions in {name.upper()}", _number(occ[f"mean_{name}"])))
    return rows


def _analysis_figures(a: dict):
    from matplotlib.figure import Figure

    diffusion = a.get("diffusion")
    if diffusion and diffusion.get("lag_time_s"):
        # MSD(τ)/4τ: flat where the motion is diffusive; the constants are read on its plateaus
        fig = Figure(figsize=(4.6, 3.4), dpi=100)
        ax = fig.add_subplot()
        t = np.array(diffusion["lag_time_s"]) * 1e9
        ratio = np.array(diffusion["msd_over_4tau_m2_s"]) * 1e9  # nm²/ns
        error = np.array(diffusion["msd_over_4tau_error_m2_s"]) * 1e9
        ax.errorbar(t, ratio, yerr=error, fmt="o", ms=3, color="tab:blue", label="MSD(τ)/4τ")
        for key, style, label in (
            ("short_time", "k--", "D₀ (short lags)"),
            ("long_time", "k-.", "D_eff (plateau)"),
        ):
            value = diffusion.get(f"{key}_diffusion_m2_s")
            lags = np.array(diffusion.get(f"{key}_lag_times_s") or []) * 1e9
            if value is not None and len(lags):
                ax.plot(lags, np.full(len(lags), value * 1e9), style, lw=1.5, label=label)
        if a.get("free_diffusion_constant_m2_s"):
            ax.axhline(
                a["free_diffusion_constant_m2_s"] * 1e9,
                ls=":",
                color="tab:red",
                label="free D₀ of the material",
            )
        if len(t) > 1:
            ax.set_xscale("log")
        ax.set_ylim(bottom=0)
        ax.set_xlabel("lag τ (ns)")
        ax.set_ylabel("MSD(τ)/4τ (nm²/ns)")
        ax.legend(fontsize=8)
        fig.tight_layout()
        yield (
            _figure_png(fig),
            "MSD(τ)/4τ against the lag (± jackknife error): flat where the motion is "
            "diffusive; the constants drawn are those it supports",
        )
    g = a.get("pair_correlation")
    if g:
        fig = Figure(figsize=(4.6, 3.4), dpi=100)
        ax = fig.add_subplot()
        r = np.array(g["r_m"]) * 1e9
        ax.errorbar(r, g["g"], yerr=np.nan_to_num(np.array(g["g_error"], float)), fmt="-", lw=1)
        ax.axhline(1.0, color="grey", lw=0.5)
        ax.set_xlabel("r (nm)")
        ax.set_ylabel("g(r)")
        fig.tight_layout()
        yield _figure_png(fig), "pair correlation g(r), normalised for the confinement"
    occ = a.get("occupancy")
    if occ and len(occ.get("time_s", [])) > 1:
        fig = Figure(figsize=(4.6, 3.4), dpi=100)
        ax = fig.add_subplot()
        t = np.array(occ["time_s"]) * 1e6
        ax.plot(t, occ["total"], lw=1, label="all")
        for name in ("up", "down"):
            if name in occ:
                ax.plot(t, occ[name], lw=1, label=name.upper())
        ax.set_xlabel("time (µs)")
        ax.set_ylabel("skyrmions present")
        ax.legend(fontsize=8)
        fig.tight_layout()
        yield _figure_png(fig), "occupancy"


# -- sweeps -----------------------------------------------------------------------------------
def sweep_report(store: Path | list[Path]) -> str:
    """The HTML text of a sweep store's report (or of several stores drawn together).

    Provenance, scaling fits and figures.
    """
    import tempfile

    from skygas.sweep import open_sweeps, plot_sweep

    stores = store if isinstance(store, list) else [store]
    ds = open_sweeps(stores)
    page = _Page(f"skygas sweep — {' + '.join(s.name for s in stores)}")
    page.paragraph(
        f"Report written by skygas {__version__} from {', '.join(str(s) for s in stores)}."
    )
    page.heading("Provenance")
    done = ds["done"].values
    page.table(
        [
            ("skygas version of the sweep", ds.attrs.get("skygas_version", "?")),
            ("root seed", ds.attrs.get("root_seed", ds.attrs.get("seed", "?"))),
            ("runs done", f"{int(np.sum(done))} of {done.size}"),
            ("swept dimensions", ", ".join(map(str, ds["done"].dims))),
        ]
    )
    with tempfile.TemporaryDirectory() as tmp:
        try:
            fits = plot_sweep(ds, tmp)
        except InputError as err:
            fits = {"figures": [], "note": str(err)}
        page.heading("Scaling fits")
        for key, name in (("current", "beta"), ("chamber", "gamma")):
            if key in fits:
                f = fits[key][name]
                page.table(
                    [
                        (
                            f"{name} (ρ/(1−ρ) power law)",
                            _number(f["exponent"], f.get("exponent_error")),
                        ),
                        ("points", f.get("n_points")),
                    ]
                )
        if "note" in fits:
            page.paragraph(fits["note"])
        page.heading("Figures")
        for path in fits["figures"]:
            page.image(Path(path).read_bytes(), Path(path).name)
    page.heading("Sweep file")
    page.pre(str(ds.attrs.get("sweep_text", ds.attrs.get("sweep_toml", ""))))
    page.heading("Data")
    page.json_block("fits", fits)
    return page.html()
