"""One self-contained HTML report of a run or a sweep: open it anywhere, offline, mail it.

Everything is inside the file: figures as PNG data URIs, the movie as an MP4 (or GIF) data URI,
and the numbers as embedded JSON (with a download link). No script, style sheet, font or
image is fetched from the network.

Every report reads from the top:

1. what made it: the command line, the date and the skygas version, from the folder's manifest
   (:mod:`skygas.runs.manifest`);
2. **the headline**: the command's results, the paper's quantities with their errors and units
   (:mod:`skygas.outputs.headlines`); a number a run cannot give reads ``none (why)``;
3. the figures, each with a caption saying what it shows, and the movie;
4. the result tables and every other number of the summary, labelled with units
   (:mod:`skygas.core.quantities`), each once;
5. the configuration as a table (setting, value with unit, and the configuration key);
6. the provenance and the data (the summary as embedded JSON).
"""

from __future__ import annotations

import base64
import html
import io
import json
import math
import re
import shlex
import time
from pathlib import Path
from typing import Any

import numpy as np

from skygas._version import __version__
from skygas.core.errors import InputError
from skygas.core.quantities import format_quantity, format_value, label, missing, quantity
from skygas.devices.registry import KINDS, kind_of_summary, recorded_kind
from skygas.outputs import headlines as H

MOVIE_NAMES = ("movie.mp4", "movie.gif")
#: the main result file of a command that keeps no positions, then the names older skygas
#: versions gave it (still read)
SUMMARY_FILES = (
    "summary.json",
    *(name for device in KINDS.values() for name in device.result_files),
    "sc_demo.json",
    "fit.json",
)
_STYLE = """
body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;
color:#222;line-height:1.4}
h1{font-size:1.5em}h2{font-size:1.2em;border-bottom:1px solid #ccc;padding-bottom:.2em}
h3{font-size:1em}
table{border-collapse:collapse;margin:.4em 0}td,th{border:1px solid #ddd;padding:.25em .6em;
text-align:left;vertical-align:top}th{font-weight:600;background:#fafafa}
td.n{font-variant-numeric:tabular-nums}
section.headline{background:#f3f7fb;border:1px solid #c9d9ea;border-radius:6px;
padding:.2em 1em 1em}section.headline table{font-size:1.05em}
section.headline td,section.headline th{border-color:#c9d9ea;background:none}
tr.section th{background:#eef2f5;font-size:.95em}code.key{color:#667;font-size:.85em}
figure{display:inline-block;margin:.5em;vertical-align:top;max-width:100%}figure img{
max-width:100%;border:1px solid #eee}figcaption{font-size:.9em;color:#444;max-width:36em}
video,.movie{max-width:100%;max-height:80vh;border:1px solid #ccc}
pre{background:#f6f6f6;padding:.6em;overflow:auto;max-height:30em;font-size:.9em}
p.made{color:#444}
"""

#: what each figure a command writes shows, by file name (then by command for shared names)
FIGURE_CAPTIONS: dict[str, str] = {
    "running_correlation.png": "Input–output correlation ρ of the bits read out so far, "
    "against time.",
    "occupancy.png": "Skyrmions present in each chamber against time, counted at every read-out "
    "and injection (the legend gives each chamber's largest), and the distribution of transit "
    "times.",
    "count_trace.png": "Skyrmions counted in the neuron's chamber against time, with the "
    "threshold, the gate's openings and the output spikes.",
    "transfer_curve.png": "Transfer curve: output spike rate against input rate, with the "
    "prediction of the fitted LIF neuron.",
    "max_density.png": "The most skyrmions that survive in a circular chamber, against its "
    "diameter, with the close-packing estimate.",
    "occupation.png": "Where the skyrmion's centre was while each input symbol was held.",
    "accuracy.png": "Test accuracy of the 16 Boolean functions and of the temporal tasks, "
    "chance marked.",
    "sweep.png": "XOR and mean Boolean accuracy against the swept parameter (mean ± standard "
    "deviation of the replicas).",
    "trajectories.png": "The device's outline and the skyrmions' trajectories.",
    "sc_and_squaring.png": "Squaring with an AND gate: the output p-value against p for "
    "identical and for decorrelated inputs, on Bernoulli and telegraph inputs.",
    "sc_error_vs_length.png": "RMS error of p² against the stream length N, with the binomial "
    "limit.",
    "sc_decorrelators.png": "The decorrelators compared: SCC, error of p², latency and energy "
    "per bit, on Bernoulli and telegraph inputs.",
    "fit.png": "The force samples of each law against distance, the law tabulated (medians with "
    "quartile bars) and the fitted curve.",
    "sc_reshuffler.png": "The skyrmion reshuffler as a decorrelator: AND-gate squaring, and "
    "beside two CMOS decorrelators.",
    "reshuffler.png": "ρ against the current density J, with the paper's fit (J₀ = 10¹¹ A/m²) "
    "and the free power law, and the running ρ.",
    "reshuffler_details.png": "p_out − p_in, the fullest chamber, the transit time and the lag "
    "scan, against the current density.",
    "chamber_size.png": "ρ against the chamber diameter L, with the paper's fit and the free "
    "power law.",
    "chamber_size_details.png": "p_out − p_in, the fullest chamber, the transit time and the "
    "lag scan, against the chamber diameter.",
}

#: the command that wrote a summary, for the commands that run no device (a device's kind is
#: told by the registry, :func:`skygas.devices.registry.kind_of_summary`): by its result file,
#: then by a key only its summary has (a folder without a manifest)
_OTHER_BY_FILE = {"sc_demo.json": "sc demo", "fit.json": "micromag fit"}
_OTHER_BY_KEY = (("comparison", "sc demo"), ("unfixed_laws", "micromag fit"))
#: the report titles of the commands that run no device (a device's is its kind's title)
_OTHER_TITLES = {
    "sc demo": "Stochastic computing demonstration",
    "demo": "Skyrmion gas simulation",
    "micromag fit": "Force laws fitted to micromagnetic snapshots",
}


def _title(kind: str) -> str:
    """The report's title for a run of ``kind``: its device's, another command's, or generic."""
    device = KINDS.get(kind)
    if device is not None:
        return device.title
    return _OTHER_TITLES.get(kind, "skygas " + kind)


def caption(name: str, kind: str | None = None, *, recorded: bool = False) -> str:
    """What the figure ``name`` of a ``kind`` run shows.

    The kind's own caption (its ``device.png``, :attr:`~skygas.devices.registry.DeviceKind.
    captions`), else the shared one of :data:`FIGURE_CAPTIONS`, else the file's name in words.
    ``recorded``: the run recorded positions (its device figure draws their trajectories).
    """
    device = KINDS.get(kind) if kind is not None else None
    own = device.caption(name, recorded=recorded) if device is not None else None
    if own is not None:
        return own
    if name in FIGURE_CAPTIONS:
        return FIGURE_CAPTIONS[name]
    return H_words(Path(name).stem).capitalize() + "."


def H_words(name: str) -> str:
    """A file stem or key as words (underscores and hyphens as spaces)."""
    return name.replace("_", " ").replace("-", " ")


def _data_uri(mime: str, data: bytes) -> str:
    return f"data:{mime};base64,{base64.b64encode(data).decode('ascii')}"


def _figure_png(fig) -> bytes:
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    buf = io.BytesIO()
    FigureCanvasAgg(fig).print_png(buf)
    return buf.getvalue()


def _number(value, error=None, unit: str = "") -> str:
    """``value ± error unit`` as :func:`skygas.core.quantities.format_value` writes it; "n/a"."""
    text = format_value(value, error, unit)
    return "n/a" if text is None else text


def _cell(text: Any) -> str:
    return html.escape(str(text))


class _Page:
    """The HTML document, built section by section.

    Table values are HTML (escape text with :func:`html.escape`); labels are text.
    """

    def __init__(self, title: str):
        self.title = title
        self.parts: list[str] = []
        #: the labels of the rows shown so far (:meth:`text_table` shows each label once)
        self.seen: set[str] = set()

    def heading(self, text: str) -> None:
        self.parts.append(f"<h2>{html.escape(text)}</h2>")

    def subheading(self, text: str) -> None:
        self.parts.append(f"<h3>{html.escape(text)}</h3>")

    def paragraph(self, text: str, cls: str = "") -> None:
        attr = f" class={cls}" if cls else ""
        self.parts.append(f"<p{attr}>{html.escape(text)}</p>")

    def raw(self, markup: str) -> None:
        self.parts.append(markup)

    def table(self, rows) -> None:
        body = "".join(
            f"<tr><th>{html.escape(str(k))}</th><td class=n>{v}</td></tr>" for k, v in rows
        )
        self.parts.append(f"<table>{body}</table>")

    def text_table(self, rows) -> None:
        """Rows of (label, value), both text; a label shown before (here or above) is left out."""
        rows = [(k, v) for k, v in rows if k not in self.seen]
        self.seen |= {k for k, _ in rows}
        if rows:
            self.table([(k, _cell(v)) for k, v in rows])

    def grid(self, header: list[str], rows: list[list[str]]) -> None:
        """A table of text cells with a header row."""
        head = "".join(f"<th>{_cell(h)}</th>" for h in header)
        body = "".join(
            "<tr>" + "".join(f"<td class=n>{_cell(c)}</td>" for c in row) + "</tr>" for row in rows
        )
        self.parts.append(f"<table><tr>{head}</tr>{body}</table>")

    def headline(self, results: H.Results) -> None:
        """The headline block: the command's results first, in a box."""
        self.seen |= {k for k, _ in results.rows}
        body = "".join(
            f"<tr><th>{_cell(k)}</th><td class=n>{_cell(v)}</td></tr>" for k, v in results.rows
        )
        table = f"<table>{body}</table>" if body else ""
        notes = "".join(f"<p>{_cell(n)}</p>" for n in results.notes)
        self.parts.append(
            f"<section class=headline id=headline><h2>Results</h2>{table}{notes}</section>"
        )

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
        from skygas.core.json_values import plain

        # standard JSON: NaN and infinities written null, as in every JSON file of skygas
        text = json.dumps(plain(data), indent=1, default=_jsonable)
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


def summary_file(directory: Path) -> Path | None:
    """The main result file (``summary.json``, or an older name) of a run folder, or None."""
    return next((directory / n for n in SUMMARY_FILES if (directory / n).is_file()), None)


def write_report(source: str | Path, out: str | Path, *, analysis: dict | None = None) -> Path:
    """Write the report of the run or sweep store at ``source`` to ``out`` (.html)."""
    out = check_report_path(out)
    if isinstance(source, (list, tuple)):  # sweep stores drawn together
        return _write(sweep_report([Path(s) for s in source]), out)
    source = Path(source)
    if (source / "zarr.json").exists():
        return _write(sweep_report(source), out)
    from skygas.outputs.records import RESULT_FILES, load_run

    found = summary_file(source) if source.is_dir() else None
    if found is not None and not any((source / n).exists() for n in RESULT_FILES):
        if _kind(source, found.name, {}) == "calibrate":
            raise InputError(
                "SOURCE",
                str(source),
                "a run folder or a sweep store (a calibration folder holds its own report.html, "
                "written by skygas calibrate)",
            )
        return _write(directory_report(source), out)  # a run that kept no positions
    return _write(run_report(load_run(source), analysis=analysis), out)


# -- the parts every report shares --------------------------------------------------------------
def _when(stamp: str | None) -> str | None:
    """``2026-11-26T08:59:28Z`` as ``2026-11-26 08:59 UTC``."""
    if not stamp:
        return None
    return stamp.replace("T", " ")[:16] + " UTC"


def _made_by(page: _Page, directory: Path, version: str | None, seed: Any) -> dict | None:
    """The paragraph saying which command made the results, when, with which version and seed.

    From the folder's manifest; while the command is still writing it (``sc demo``), from the
    running command line.
    """
    from skygas.runs import manifest

    found = manifest.read(directory)
    argv = None if found is None else found.get("command_line")
    if argv is None and found is None:
        argv = manifest.current_argv()
    if isinstance(argv, list):
        argv = "skygas " + shlex.join(argv)
    started = _when(found.get("started_at")) if found else None
    finished = _when(found.get("finished_at")) if found else None
    made = (
        f"Made by <code class=command>{html.escape(argv)}</code>"
        if argv
        else "Made from Python (no command line recorded)"
    )
    if started:
        made += f" on {started}" + (f" (finished {finished[11:]})" if finished else "")
    made += f", with skygas {html.escape(str(version or '(version not recorded)'))}"
    if seed is not None:
        made += f", seed {html.escape(str(seed))}"
    page.raw(f"<p class=made>{made}.</p>")
    return found


def _report_line(page: _Page, source: Path) -> None:
    page.paragraph(
        f"Report written by skygas {__version__} on "
        f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} from {source}."
    )


def _movie(page: _Page, directory: Path) -> None:
    movie = next((directory / n for n in MOVIE_NAMES if (directory / n).exists()), None)
    if movie is not None:
        page.heading("Movie")
        page.movie(movie)


def _figures(page: _Page, directory: Path, kind: str | None) -> None:
    figures = sorted(directory.glob("*.png"))
    if figures:
        page.heading("Figures")
        for path in figures:
            page.image(path.read_bytes(), caption(path.name, kind))


def _results(page: _Page, results: H.Results) -> None:
    page.headline(results)


def _tables(page: _Page, results: H.Results) -> None:
    for title, (header, rows) in results.tables:
        page.heading(title)
        page.grid(header, rows)


def _error_of(summary: dict, key: str) -> Any:
    """The standard error recorded beside ``key``: ``x_error``, or ``x_error_s`` for ``x_s``."""
    error = summary.get(f"{key}_error")
    if error is None and "_" in key:
        stem, unit = key.rsplit("_", 1)
        error = summary.get(f"{stem}_error_{unit}")
    return None if missing(error) or isinstance(error, bool) else error


#: nested parts of a summary shown as their own tables, by key
_NESTED = {"lif_fit": "LIF fit", "isi": "Inter-spike intervals", "operations": "Operations"}


def number_rows(
    summary: dict, skip: set[str] | frozenset[str] = frozenset(), prefix: str = ""
) -> list[tuple[str, str]]:
    """Every scalar of ``summary`` not in ``skip``, labelled, with its error, each label once.

    ``prefix``: the key of ``summary`` inside its parent (``"isi"``), for the labels of
    :data:`~skygas.core.quantities.QUANTITIES` given with it (``"isi.mean_s"``).
    """
    rows: list[tuple[str, str]] = []
    seen: set[str] = set()
    for key, value in summary.items():
        path = f"{prefix}.{key}" if prefix else key
        if key in skip or path in skip or "_error" in key or isinstance(value, (dict, list)):
            continue
        if key in ("config", "command", "command_line", "config_hash"):
            continue
        name = label(path)
        if name in seen:
            continue
        seen.add(name)
        text = format_quantity(path, value, _error_of(summary, key))
        rows.append((name, H.none("undefined for this run") if text is None else text))
    return rows


def _numbers(page: _Page, summary: dict, skip: set[str]) -> None:
    rows = number_rows(summary, skip)
    if rows:
        page.heading("Every number of the summary")
        page.text_table(rows)
    for key, title in _NESTED.items():
        part = summary.get(key)
        if isinstance(part, dict) and part and key not in skip:
            rows = [(k, v) for k, v in number_rows(part, skip, key) if k not in page.seen]
            if rows:
                page.subheading(title)
                page.text_table(rows)


#: a configuration key written as a value (``"hold_time"``, ``"drive.current_density"``)
_KEY = re.compile(r"[a-z][a-z0-9]*(?:[_.][a-z0-9]+)*_[a-z0-9]+")


def config_rows(config: dict) -> list[tuple[str, list[tuple[str, str, str]]]]:
    """The configuration as sections of (setting, value, key path) rows.

    Top-level values first (section "general"), then one section per table; nested tables
    and lists of tables flattened into their section with their key path.
    """
    sections: dict[str, list[tuple[str, str, str]]] = {"general": []}

    def add(section: str, path: str, value: Any, prefix: str = "") -> None:
        last = path.rsplit(".", 1)[-1].split("[")[0]
        if isinstance(value, dict):
            if not value:
                return
            for k, v in value.items():
                add(section, f"{path}.{k}", v, prefix)
            return
        if isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            for i, item in enumerate(value):
                for k, v in item.items():
                    add(section, f"{path}[{i}].{k}", v, f"{H_words(last)} {i + 1}: ")
            return
        if isinstance(value, list) and not value:
            text = "none"
        elif value is None:
            text = "automatic"
        elif isinstance(value, str) and _KEY.fullmatch(value):
            text = label(value)  # a value that names a setting (a sweep's parameter)
        else:
            q = quantity(path.rsplit(".", 1)[-1].split("[")[0])
            text = format_value(value, unit=q.unit, kind=q.kind) or "none"
        sections.setdefault(section, []).append((prefix + label(last), text, path))

    for key, value in config.items():
        if isinstance(value, dict) or (
            isinstance(value, list) and value and all(isinstance(v, dict) for v in value)
        ):
            add(key, key, value)
        else:
            add("general", key, value)
    return [(name, rows) for name, rows in sections.items() if rows]


def _configuration(page: _Page, config: dict | None, title: str = "Configuration") -> None:
    """The configuration as a readable table; a config without values says so."""
    page.heading(title)
    sections = config_rows(config or {})
    if not sections:
        page.paragraph("The run recorded no configuration.")
        return
    body = []
    for name, rows in sections:
        body.append(f"<tr class=section><th colspan=3>{_cell(H_words(name))}</th></tr>")
        body += [
            f"<tr><td>{_cell(k)}</td><td class=n>{_cell(v)}</td>"
            f"<td><code class=key>{_cell(path)}</code></td></tr>"
            for k, v, path in rows
        ]
    page.raw(
        "<table class=config><tr><th>setting</th><th>value</th><th>configuration key</th></tr>"
        + "".join(body)
        + "</table>"
    )


def _provenance(page: _Page, rows: list[tuple[str, Any]]) -> None:
    """Version, seed, hashes and files; a hash or file name as code (verbatim, not a number)."""
    page.heading("Provenance")
    verbatim = ("configuration hash", "result file", "stores")
    page.table(
        [
            (k, f"<code>{_cell(v)}</code>" if k in verbatim else _cell(v))
            for k, v in rows
            if v is not None
        ]
    )


# -- runs that keep no positions -----------------------------------------------------------------
def _kind(directory: Path, name: str, summary: dict) -> str:
    """The command that wrote the summary ``name`` in ``directory`` ("run" where none tells)."""
    found = kind_of_summary(summary, directory, name)
    if found is not None:
        return found
    if name in _OTHER_BY_FILE:
        return _OTHER_BY_FILE[name]
    return next((kind for key, kind in _OTHER_BY_KEY if key in summary), "run")


def _extra_json(directory: Path, name: str) -> dict | None:
    try:
        return json.loads((directory / name).read_text())
    except (OSError, ValueError):
        return None


def directory_report(directory: Path) -> str:
    """The report of a run folder that holds a summary and figures but no positions.

    A neuron run without ``--animate``, a reservoir study, a saturation curve, the
    stochastic-computing demo.
    """
    path = summary_file(directory)
    assert path is not None, "a folder without summary.json"
    summary = json.loads(path.read_text())
    kind = _kind(directory, path.name, summary)
    provenance = summary.get("device", summary)  # the reservoir keeps it with its device
    version, seed = provenance.get("skygas_version"), provenance.get("seed")
    seed_text = "none (a fit draws no random numbers)" if kind == "micromag fit" else None
    page = _Page(f"{_title(kind)} — {directory.name}")
    found = _made_by(page, directory, version, seed)
    device = KINDS.get(kind)
    if device is not None:
        results = (
            device.folder_headline(summary, directory) if device.folder_headline else H.Results()
        )
        config = device.config_in(summary)
    elif kind == "sc demo":
        results = H.sc_demo(summary, _extra_json(directory, "sc_reshuffler.json"))
        # the decorrelators are the rows of the results' table
        config = {
            k: v for k, v in (summary.get("parameters") or {}).items() if k != "decorrelators"
        }
    elif kind == "micromag fit":
        results = H.micromag_fit(summary)
        config = summary.get("parameters")
    else:
        results = H.Results()
        config = summary.get("config")
    _results(page, results)
    _movie(page, directory)
    _figures(page, directory, kind)
    _tables(page, results)
    skip = results.keys | {"device", "parameters", "skygas_version", "seed"}
    _numbers(page, summary, skip)
    _configuration(page, config)
    _provenance(
        page,
        [
            ("skygas version of the run", version or "not recorded"),
            ("seed", seed if seed is not None else seed_text or "not recorded"),
            ("configuration hash", (found or {}).get("config_hash")),
            ("result file", path.name),
        ],
    )
    _report_line(page, path)
    page.heading("Data")
    page.json_block("summary", summary)
    if config:
        page.json_block("configuration", config)
    return page.html()


# -- runs ---------------------------------------------------------------------------------------
def run_report(record, *, analysis: dict | None = None) -> str:
    """The HTML text of a run's report.

    ``analysis``: a ready :func:`skygas.analysis.analyze` result, computed here without the maps
    when not given.
    """
    from skygas.analysis import analyze

    if analysis is None:
        analysis = analyze(record, maps=False)
    summary = record.summary or {}
    kind = record.kind
    page = _Page(f"{_title(kind)} — {record.directory.name}")
    found = _made_by(page, record.directory, record.version, record.seed)
    headline = recorded_kind(kind).run_headline
    assert headline is not None  # recorded_kind gives a kind with one
    results = headline(summary, record.config, analysis)
    _results(page, results)
    _movie(page, record.directory)
    page.heading("Figures")
    _figures_inline(page, record.directory, kind)
    page.heading("Observables of the recorded positions")
    page.text_table(_observable_rows(analysis))
    for png, text in _analysis_figures(analysis):
        page.image(png, text)
    _tables(page, results)
    _numbers(page, summary, results.keys | {"skygas_version", "seed"})
    _configuration(page, record.config)
    frames = record.frames
    _provenance(
        page,
        [
            ("skygas version of the run", record.version),
            ("seed", record.seed),
            ("configuration hash", (found or {}).get("config_hash")),
            ("result file", record.path.name),
            ("frames recorded", frames.n_frames),
            (
                "time span of the frames",
                format_value(float(frames.time[-1]), unit="s") if frames.n_frames else None,
            ),
        ],
    )
    _report_line(page, record.path)
    page.heading("Data")
    page.json_block("summary", summary)
    page.json_block("configuration", record.config)
    page.json_block("observables", analysis)
    return page.html()


def _figures_inline(page: _Page, directory: Path, kind: str) -> None:
    """The figures of a run that recorded positions (its result file is read here)."""
    for path in sorted(directory.glob("*.png")):
        page.image(path.read_bytes(), caption(path.name, kind, recorded=True))


def _observable_rows(a: dict):
    rows = [
        ("frames analysed", format_value(a.get("frames"), kind="count") or "none"),
        ("skyrmion entries", format_value(a.get("entries"), kind="count") or "none"),
    ]
    diffusion = a.get("diffusion")
    if diffusion:
        removed = " (drift removed)" if diffusion.get("drift_subtracted") else ""
        for key, name in (("short_time", "short-time D₀"), ("long_time", "long-time D_eff")):
            value = diffusion.get(f"{key}_diffusion_m2_s")
            if value is not None:
                error = diffusion.get(f"{key}_diffusion_error_m2_s")
                rows.append((f"{name}{removed}", _number(value, error, "m²/s")))
            elif diffusion.get(f"{key}_reason"):
                rows.append((name, H.none(diffusion[f"{key}_reason"])))
        if diffusion.get("reason"):
            rows.append(("diffusion constant", H.none(diffusion["reason"])))
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
                f"{_number(v['velocity_m_s'][0], v['velocity_error_m_s'][0], 'm/s')}, "
                f"{_number(v['velocity_m_s'][1], v['velocity_error_m_s'][1], 'm/s')}",
            )
        )
        if v.get("hall_angle_reason"):
            rows.append(("Hall angle", H.none(v["hall_angle_reason"])))
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
            "diffusive; the constants drawn are those it supports.",
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
        yield _figure_png(fig), "Pair correlation g(r), normalised for the confinement."
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
        yield _figure_png(fig), _occupancy_caption(occ)


def _occupancy_caption(occ: dict) -> str:
    """What the occupancy figure of the recorded frames draws: the frames only, how often."""
    t = np.asarray(occ["time_s"], float)
    steps = np.diff(t)
    every = format_value(float(np.median(steps)), unit="s", digits=3)
    even = bool(np.allclose(steps, steps[0], rtol=1e-6))
    sampled = f"at each recorded frame ({'every' if even else 'median spacing'} {every})"
    groups = " (all, and per chamber)" if "up" in occ else ""
    return f"Skyrmions present{groups} {sampled}: a change between two frames is not drawn."


# -- sweeps -----------------------------------------------------------------------------------
def _sweep_made(page: _Page, ds) -> None:
    """What the sweep varies and when its runs were made (the store's sessions)."""
    try:
        fields = json.loads(ds.attrs.get("fields_json", "{}"))
    except (TypeError, ValueError):
        fields = {}
    swept = [label(str(fields.get(d, d))) for d in ds["done"].dims if d != "replica"]
    try:
        sessions = json.loads(ds.attrs.get("sessions_json", "[]"))
    except (TypeError, ValueError):
        sessions = []
    dates = [
        time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime(s["started"]))
        for s in sessions
        if isinstance(s, dict) and "started" in s
    ]
    when = ""
    if dates:
        when = f", run in {len(dates)} session(s) from {dates[0]}"
        when += f" to {dates[-1]}" if len(dates) > 1 else ""
    page.paragraph(
        f"A sweep of {', '.join(swept)}{when}, with skygas "
        f"{ds.attrs.get('skygas_version', '(version not recorded)')}.",
        cls="made",
    )


#: the sweep figures that draw a field's fits: (field, what is against what, the paper's law,
#: the free law, what else the figure shows)
_FIT_FIGURES = {
    "reshuffler.png": (
        "current",
        "ρ against the current density J",
        "the paper's fit ρ = c_A/(c_B + (J/J₀)⁻¹·⁵), J₀ = 10¹¹ A/m²",
        "the free power law ρ/(1−ρ) ∝ Jᵝ",
        ", and the running ρ",
    ),
    "chamber_size.png": (
        "chamber",
        "ρ against the chamber diameter L",
        "the paper's fit ρ = c_A + c_B/√(L/1 µm)",
        "the free power law ρ/(1−ρ) ∝ Lᵞ",
        "",
    ),
}


def _sweep_caption(name: str, fits: dict) -> str:
    """A sweep figure's caption: the fits it draws, and those the points do not constrain."""
    if name in fits.get("captions", {}):
        return str(fits["captions"][name])
    if name not in _FIT_FIGURES or _FIT_FIGURES[name][0] not in fits:
        return caption(name)
    key, what, paper_law, free_law, rest = _FIT_FIGURES[name]
    fit = fits[key]
    paper = fit.get("paper_fit") or {}
    exponent = fit.get("beta") or fit.get("gamma") or {}
    laws = {
        paper_law: all(
            H.constrained(paper.get(c), paper.get(f"{c}_error")) for c in ("c_A", "c_B")
        ),
        free_law: H.constrained(exponent.get("exponent"), exponent.get("exponent_error")),
    }
    drawn = [law for law, ok in laws.items() if ok]
    left_out = [law for law, ok in laws.items() if not ok]
    text = what + (f", with {' and '.join(drawn)}" if drawn else "") + rest + "."
    if left_out:
        text += f" Not drawn: {' and '.join(left_out)}, which the points do not constrain."
    return text


def sweep_report(store: Path | list[Path]) -> str:
    """The HTML text of a sweep store's report (or of several stores drawn together).

    The fits first, then the figures, the sweep file, the base configuration and provenance.
    """
    import tempfile

    from skygas.sweep import open_sweeps, plot_sweep

    stores = store if isinstance(store, list) else [store]
    ds = open_sweeps(stores)
    page = _Page(f"Parameter sweep — {' + '.join(s.name for s in stores)}")
    _sweep_made(page, ds)
    done = ds["done"].values
    with tempfile.TemporaryDirectory() as tmp:
        try:
            fits = plot_sweep(ds, tmp)
        except InputError as err:
            fits = {"figures": [], "note": str(err)}
        figures = [(Path(p).name, Path(p).read_bytes()) for p in fits["figures"]]
    fits["figures"] = [name for name, _ in figures]  # names: the temporary folder is gone
    results = H.sweep(fits)
    _results(page, results)
    page.heading("Figures")
    for name, png in figures:
        page.image(png, _sweep_caption(name, fits))
    _tables(page, results)
    page.heading("Sweep file")
    page.pre(str(ds.attrs.get("sweep_file", "")) or "(not recorded)")
    try:
        base = json.loads(ds.attrs.get("base_config_json", "{}"))
    except (TypeError, ValueError):
        base = {}
    _configuration(page, base, "Base configuration (before the swept values)")
    seeds = ds.attrs.get("root_seed", ds.attrs.get("seed"))
    _provenance(
        page,
        [
            ("skygas version of the sweep", ds.attrs.get("skygas_version", "not recorded")),
            ("root seed", ", ".join(map(str, seeds)) if isinstance(seeds, list) else seeds),
            ("runs done", f"{int(np.sum(done))} of {done.size}"),
            ("stores", ", ".join(str(s) for s in stores)),
        ],
    )
    _report_line(page, stores[0])
    page.heading("Data")
    page.json_block("fits", fits)
    return page.html()
