"""The HTML report: self-contained (no network resource), every image and the movie decode,
the provenance and the numbers are in it; and a real browser shows it without errors."""

from __future__ import annotations

import base64
import html
import io
import json
import os
import re
from html.parser import HTMLParser
from pathlib import Path

import pytest

from reservoir.test_cli import FAST as RESERVOIR
from skygas._version import __version__
from skygas.outputs.finish import finish_outputs

from .browser import Chromium, find_chromium
from .test_run_commands import CONFIG as SIMULATE

ARTIFACTS = Path(
    os.environ.get("SKYGAS_TEST_ARTIFACTS", Path(__file__).resolve().parents[2] / "test-artifacts")
)


class _Resources(HTMLParser):
    """Every URL the page would load, and the embedded JSON blocks."""

    def __init__(self):
        super().__init__()
        self.urls: list[tuple[str, str]] = []
        self.json_blocks: dict[str, str] = {}
        self._json_id = None

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        for key in ("src", "href", "poster", "data"):
            if attrs.get(key):
                self.urls.append((tag, attrs[key]))
        if tag == "script" and attrs.get("type") == "application/json":
            self._json_id = attrs.get("id")
            self.json_blocks[self._json_id] = ""

    def handle_data(self, data):
        if self._json_id is not None:
            self.json_blocks[self._json_id] += data

    def handle_endtag(self, tag):
        if tag == "script":
            self._json_id = None


def _payload(url: str) -> tuple[str, bytes]:
    head, data = url.split(",", 1)
    return head[5:].split(";")[0], base64.b64decode(data)


@pytest.fixture(scope="module")
def reshuffler_report(reshuffler_run):
    """The report a run command writes with --animate (movie included)."""
    done = finish_outputs(reshuffler_run, animate=True, report=True)
    assert done["movie"]["frames"] == 101  # t = 0 and every 4 ns to 0.4 µs, each one shown
    return Path(done["report"]["path"])


def test_report_is_self_contained_and_every_resource_decodes(reshuffler_report):
    import imageio_ffmpeg
    from PIL import Image

    text = reshuffler_report.read_text()
    parser = _Resources()
    parser.feed(text)
    kinds = {}
    for tag, url in parser.urls:
        assert url.startswith("data:"), f"{tag} loads {url[:80]}: not embedded"
        mime, data = _payload(url)
        kinds[mime] = kinds.get(mime, 0) + 1
        if mime == "image/png":
            with Image.open(io.BytesIO(data)) as image:
                image.load()
                assert image.size[0] > 100
        elif mime == "video/mp4":
            movie = reshuffler_report.with_name("embedded.mp4")
            movie.write_bytes(data)
            meta = next(imageio_ffmpeg.read_frames(str(movie)))
            assert meta["duration"] > 0
        elif mime == "application/json":
            json.loads(data)
    # the run's three figures, the MSD, g(r) and occupancy figures, the movie, the data
    assert kinds["image/png"] >= 6 and kinds["video/mp4"] == 1
    assert kinds["application/json"] == 3
    summary = json.loads(parser.json_blocks["summary"])
    observables = json.loads(parser.json_blocks["observables"].replace("<\\/", "</"))
    assert summary["seed"] == 0
    # snapshots 100 ns apart of skyrmions that cross a chamber in a few hundred ns: no diffusion
    # constant, and the report says why instead of fitting one
    diffusion = observables["diffusion"]
    assert diffusion["short_time_diffusion_m2_s"] is None and diffusion["short_time_reason"]
    assert "hall_angle_rad" not in observables["velocity"]
    # provenance: version, seed and the full configuration
    assert f"skygas {__version__}" in text
    configuration = json.loads(parser.json_blocks["configuration"])
    assert configuration["current_density"] == 1.7e11 and configuration["seed"] == 0
    assert "<td>current density</td><td class=n>1.7×10¹¹ A/m²</td>" in text
    assert "±" in text  # numbers come with their uncertainties


def test_report_of_a_simulation_without_movie(simulation_run, tmp_path):
    from skygas.cli import main

    out = tmp_path / "r.html"
    assert main(["report", str(simulation_run), "--out", str(out)]) == 0
    parser = _Resources()
    parser.feed(out.read_text())
    assert all(url.startswith("data:") for _, url in parser.urls)
    assert not any(url.startswith("data:video") for _, url in parser.urls)


def _browser(profile: Path) -> Chromium:
    """A headless Chromium; the test is skipped without one (or without websockets)."""
    executable = find_chromium()
    if executable is None:
        pytest.skip("no Chromium installed (.ci/run installs Debian's chromium package)")
    pytest.importorskip("websockets")
    return Chromium(executable, profile)


def test_report_loads_in_a_real_browser(reshuffler_report, tmp_path):
    browser = _browser(tmp_path / "profile")
    try:
        page = browser.load(reshuffler_report.resolve().as_uri())
    finally:
        browser.close()
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    (ARTIFACTS / "report-screenshot.png").write_bytes(page["screenshot"])
    assert page["errors"] == []
    assert page["images"] and all(image["ok"] for image in page["images"]), page["images"]
    assert page["videoError"] is None
    assert page["duration"] and page["duration"] > 0


def test_report_of_a_sweep_store_holds_the_fits(tmp_path):
    from skygas.cli import main
    from sweep.test_analysis import fake_store

    grid = {"current_density": [1e11, 1.5e11, 2e11, 2.7e11, 3.8e11]}
    store = fake_store(
        tmp_path / "j.zarr", grid, lambda c: 1 / (1 + (c.current_density / 1e11) ** -1.5)
    )
    out = tmp_path / "sweep.html"
    assert main(["report", str(store), "--out", str(out)]) == 0
    text = out.read_text()
    parser = _Resources()
    parser.feed(text)
    assert all(url.startswith("data:") for _, url in parser.urls)
    # the paper's figure and its details figure (p_out, occupancy, transit, lag scan)
    assert sum(url.startswith("data:image/png") for _, url in parser.urls) == 2
    fits = json.loads(parser.json_blocks["fits"].replace("<\\/", "</"))
    assert fits["current"]["beta"]["exponent"] == pytest.approx(1.5, abs=1e-6)
    # the headline: the free exponent and the paper's fit, with their errors
    assert "exponent of ρ/(1−ρ) ∝ Jᵝ</th><td class=n>1.500 ± 0.058 over 5 points" in text
    assert "c_A = 1.000 ± 0.041, c_B = 1.000 ± 0.053" in text
    assert fits["figures"] == ["reshuffler.png", "reshuffler_details.png"]  # no temporary path


# -- every command's report reads as a summary -----------------------------------------------
#: symbols written with an underscore, as physicists write them (no key names)
SYMBOLS = ("p_in", "p_out", "V_r", "k_BT", "D_eff", "c_A", "c_B", "d_sk")
SNAKE_CASE = re.compile(r"\b[a-z][a-z0-9]*(?:_[a-z0-9]+)+\b")
#: numbers as a program prints them: 4.4e-08, 1e+11, nan, inf, a caret power
RAW_NUMBER = re.compile(r"\d[eE][+-]?\d|\bnan\b|\binf\b|\^", re.IGNORECASE)

MOVIE = Path(__file__).resolve().parents[2] / "examples" / "tracking" / "chamber-movie.tif"
STUDY = """
[study]
device = "analytic"
seed = 1
[space]
x = { low = -1.0, high = 1.0 }
[[objectives]]
expression = "f"
"""
#: the main result of the commands whose result file has a name of its own
MAIN_RESULT = {"track": "track.json", "infer": "inference.json", "optimize": "best.json"}
#: commands whose report has no configuration (they read files, not a configuration)
NO_CONFIGURATION = ("sweep", "track", "infer", "optimize")

SWEEP = """
[sweep]
seed = 1
replicas = 2
[base]
preset = "paper"
duration = 1e-6
[grid]
current_density = [1e11, 1.5e11, 2e11, 2.7e11, 3.8e11]
"""


class _Text(HTMLParser):
    """The page's text as a reader sees it, but for verbatim code and files (``code``,
    ``pre``: configuration keys, the command line, a sweep file); and each h2's section text."""

    SKIP = ("code", "pre", "script", "style", "title")

    def __init__(self):
        super().__init__()
        self.text: list[str] = []
        self.sections: list[list[str]] = []
        self.headline_rows = 0
        self._skip = 0
        self._in_headline = False

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag in self.SKIP:
            self._skip += 1
        if tag == "h2":
            self.sections.append([])
        if tag == "section" and attrs.get("id") == "headline":
            self._in_headline = True
        if tag == "tr" and self._in_headline:
            self.headline_rows += 1
        if tag in ("img", "video") and self.sections:
            self.sections[-1].append(f"<{tag}>")

    def handle_endtag(self, tag):
        if tag in self.SKIP:
            self._skip -= 1
        if tag == "section":
            self._in_headline = False

    def handle_data(self, data):
        if self.sections:
            self.sections[-1].append(data)  # verbatim blocks count as content too
        if not self._skip:
            self.text.append(data)


def _check_reads_as_a_summary(text: str) -> None:
    """No key names, no raw numbers, no empty braces in the text a reader sees."""
    for symbol in SYMBOLS:
        text = text.replace(symbol, "")
    assert not SNAKE_CASE.findall(text), SNAKE_CASE.findall(text)
    assert not RAW_NUMBER.findall(text), [
        text[max(0, m.start() - 40) : m.end() + 40] for m in RAW_NUMBER.finditer(text)
    ]
    assert "{}" not in text and "[]" not in text


@pytest.fixture(scope="module")
def command_reports(tmp_path_factory, reshuffler_report):
    """The report of every command that writes a folder, each from its shortest run."""
    import skygas
    from skygas.cli import main

    root = tmp_path_factory.mktemp("commands")
    (root / "run.toml").write_text(SIMULATE)  # 12 ns, 10 skyrmions
    (root / "reservoir.toml").write_text(RESERVOIR)  # 24 inputs
    runs = {
        "simulate": ["simulate", root / "run.toml", "--quiet"],
        "neuron": ["neuron", "--duration", "5e-8", "--no-transfer", "--quiet"],
        "saturation": ["saturation", "--diameters", "150e-9", "--repetitions", "2", "--quiet"],
        "reservoir": ["reservoir", root / "reservoir.toml", "--quiet"],
        "sc demo": ["sc", "demo", "--n-bits", "256"],
        "micromag fit": ["micromag", "fit", Path(skygas.__file__).parent / "data" / "ovf" / "pair"],
        "track": ["track", MOVIE, "--quiet"],
        "infer": [
            "infer",
            root / "track" / "tracks.csv",
            *("--pixel-size", "14e-9", "--frame-interval", "2e-9", "--temperature", "300"),
            *("--outline", MOVIE.parent / "chamber-movie-outline.csv"),
            *("--check-frames", "200"),
        ],
        "optimize": ["optimize", root / "study.toml", "--trials", "6", "--serial", "--quiet"],
    }
    (root / "study.toml").write_text(STUDY)
    reports = {"reshuffle": reshuffler_report}
    for name, argv in runs.items():
        out = root / name.replace(" ", "-")
        assert main([*map(str, argv), "--out", str(out)]) == 0, name
        # the main result of every command (those the issues named otherwise: their own)
        assert (out / MAIN_RESULT.get(name, "summary.json")).is_file(), name
        reports[name] = out / "report.html"
    store = _sweep_store(root / "sweep.zarr")
    assert main(["plot", str(store), "--out", str(root / "figures")]) == 0
    reports["sweep"] = root / "figures" / "report.html"
    return reports


def _sweep_store(path: Path) -> Path:
    """A store of the sweep :data:`SWEEP` holding ρ = 1/(1 + (J/J₀)^(−3/2)) ± 0.01."""
    import tomllib

    import numpy as np

    from skygas.sweep.spec import parse_sweep
    from skygas.sweep.store import SweepStore
    from skygas.sweep.worker import QUANTITIES

    sweep = parse_sweep(tomllib.loads(SWEEP), SWEEP)
    store = SweepStore(path, sweep)
    session = store.start_session()
    for run in sweep.runs:
        result = {q: 0.3 for q in QUANTITIES}
        rho = 1 / (1 + (run.config.current_density / 1e11) ** -1.5)
        result["correlation"] = rho + (0.01 if run.replica == 0 else -0.01)
        result["running_time"] = np.linspace(1e-7, 1e-6, 30)
        result["running_rho"] = result["correlation"] + np.exp(-result["running_time"] / 2e-7)
        store.write(run, result, session=session)
    return path


COMMANDS = (
    "reshuffle",
    "neuron",
    "saturation",
    "reservoir",
    "simulate",
    "sc demo",
    "micromag fit",
    "sweep",
    "track",
    "infer",
    "optimize",
)


@pytest.mark.parametrize("command", COMMANDS)
def test_every_report_opens_with_its_results_and_reads_as_a_summary(command, command_reports):
    text = command_reports[command].read_text()
    page = _Text()
    page.feed(text)
    assert page.headline_rows >= 1, command  # the headline block, with the results first
    assert text.index("id=headline") < text.index("<h2>Figures</h2>")
    _check_reads_as_a_summary("".join(page.text))
    for section in page.sections:
        assert "".join(section).strip(), f"{command}: an empty section"
    if command not in NO_CONFIGURATION:
        assert "<th>configuration key</th>" in text  # the configuration as a table
    if command not in ("reshuffle", "sweep", "track", "optimize"):  # made from the command line
        assert "Made by <code class=command>skygas " in text
    # each quantity once: the labelled rows of the headline and the tables of numbers
    labels = re.findall(r"<tr><th>([^<]*)</th><td class=n>", text)
    assert len(labels) == len(set(labels)), [k for k in labels if labels.count(k) > 1]
    # captions say what a figure shows, never its file name
    assert not re.search(r"<figcaption>[^<]*\.png", text)


def test_headlines_state_the_papers_quantities(command_reports):
    def headline(command):
        page = command_reports[command].read_text()
        return html.unescape(page[page.index("id=headline") : page.index("</section>")])

    assert "input–output correlation ρ" in headline("reshuffle")
    assert "energy per bit" in headline("reshuffle") and "fJ" in headline("reshuffle")
    assert "output spike rate" in headline("neuron")
    assert "N_sat in a 150 nm chamber" in headline("saturation")
    # an accuracy with its own 68 % interval, not the chance level's standard error
    assert "XOR test accuracy" in headline("reservoir") and " ± " not in headline("reservoir")
    assert re.search(r"\d % \(\d+\.\d–\d+\.\d %\)", headline("reservoir"))
    assert "short-time D₀" in headline("simulate")
    assert "SCC of x and its copy" in headline("sc demo")
    assert "pair law" in headline("micromag fit") and "F₀ = " in headline("micromag fit")
    assert "exponent of ρ/(1−ρ) ∝ Jᵝ" in headline("sweep")
    # the sweep file, as the store keeps it
    sweep = command_reports["sweep"].read_text()
    assert "current_density = [1e11, 1.5e11, 2e11, 2.7e11, 3.8e11]" in sweep


def test_every_report_reads_well_in_a_real_browser(command_reports, tmp_path):
    browser = _browser(tmp_path / "profile")
    try:
        for command in COMMANDS:
            page = browser.load(command_reports[command].resolve().as_uri())
            assert page["errors"] == [], command
            assert all(image["ok"] for image in page["images"]), command
            assert page["headline"] and page["headlineRows"] >= 1, command
            _check_reads_as_a_summary(page["text"])
    finally:
        browser.close()
