"""The HTML report: self-contained (no network resource), every image and the movie decode,
the provenance and the numbers are in it; and a real browser shows it without errors."""

from __future__ import annotations

import base64
import html
import io
import json
import os
from html.parser import HTMLParser
from pathlib import Path

import pytest

from skygas._version import __version__
from skygas.outputs.finish import finish_outputs

from .browser import Chromium, find_chromium

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
    assert kinds["application/json"] == 2
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
    assert '"current_density": 170000000000.0' in html.unescape(text)
    assert "±" in text  # numbers come with their uncertainties


def test_report_of_a_simulation_without_movie(simulation_run, tmp_path):
    from skygas.cli import main

    out = tmp_path / "r.html"
    assert main(["report", str(simulation_run), "--out", str(out)]) == 0
    parser = _Resources()
    parser.feed(out.read_text())
    assert all(url.startswith("data:") for _, url in parser.urls)
    assert not any(url.startswith("data:video") for _, url in parser.urls)


def test_report_loads_in_a_real_browser(reshuffler_report, tmp_path):
    executable = find_chromium()
    if executable is None:
        pytest.skip("no Chromium installed (.ci/run installs Debian's chromium package)")
    pytest.importorskip("websockets")
    browser = Chromium(executable, tmp_path / "profile")
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
    assert "beta (ρ/(1−ρ) power law)" in html.unescape(text)
