"""A headless Chromium driven over the DevTools protocol (CDP), for loading a page and reading
what a user's browser would report: console errors, undecodable images, a video's duration."""

from __future__ import annotations

import base64
import json
import re
import shutil
import subprocess
import time
from pathlib import Path

CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome", "chrome")

# Run inside the page once it has loaded: decode every image, wait for the video's metadata, read
# the visible text and the headline block.
PAGE_CHECK = """
(async () => {
  const images = await Promise.all([...document.images].map(async (img) => {
    try { await img.decode(); return {ok: img.naturalWidth > 0, width: img.naturalWidth}; }
    catch (e) { return {ok: false, error: String(e)}; }
  }));
  const video = document.querySelector('video');
  let duration = null, videoError = null;
  if (video) {
    if (video.readyState < 1) {
      await new Promise((done) => {
        video.addEventListener('loadedmetadata', done, {once: true});
        video.addEventListener('error', done, {once: true});
        setTimeout(done, 15000);
      });
    }
    duration = video.duration;
    videoError = video.error ? video.error.code : null;
  }
  // the text a reader sees, but for verbatim code and files (configuration keys, the command
  // line, a sweep file), and the headline block
  const body = document.body.cloneNode(true);
  body.querySelectorAll('code, pre, script, style').forEach((e) => e.remove());
  const headline = document.querySelector('#headline');
  return {images, duration, videoError, title: document.title, text: body.textContent,
          headline: headline ? headline.innerText : null,
          headlineRows: headline ? headline.querySelectorAll('tr').length : 0};
})()
"""


def find_chromium() -> str | None:
    for name in CHROMIUM_NAMES:
        path = shutil.which(name)
        if path:
            return path
    return None


class Chromium:
    """One headless browser process and a CDP session to one page in it."""

    def __init__(self, executable: str, profile: Path, timeout: float = 60.0):
        self.timeout = timeout
        self.process = subprocess.Popen(
            [
                executable,
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--no-first-run",
                "--remote-debugging-port=0",
                "--remote-debugging-address=127.0.0.1",
                f"--user-data-dir={profile}",
                "about:blank",
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
        )
        url = self._devtools_url()
        from contextlib import ExitStack

        from websockets.sync.client import connect

        self._stack = ExitStack()
        self.ws = self._stack.enter_context(connect(url, max_size=None, open_timeout=timeout))
        self.next_id = 0
        self.events: list[dict] = []
        target = self.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        self.session = self.call("Target.attachToTarget", {"targetId": target, "flatten": True})[
            "sessionId"
        ]
        for domain in ("Page", "Runtime", "Log"):
            self.call(f"{domain}.enable", session=True)

    def _devtools_url(self) -> str:
        deadline = time.monotonic() + self.timeout
        while time.monotonic() < deadline:
            line = self.process.stderr.readline()
            if not line and self.process.poll() is not None:
                break
            found = re.search(r"DevTools listening on (ws://\S+)", line)
            if found:
                return found.group(1)
        raise RuntimeError("Chromium did not start its DevTools server")

    def call(self, method: str, params: dict | None = None, session: bool = False) -> dict:
        self.next_id += 1
        message = {"id": self.next_id, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = self.session
        self.ws.send(json.dumps(message))
        while True:
            reply = json.loads(self.ws.recv(timeout=self.timeout))
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})
            self.events.append(reply)

    def wait_for(self, method: str) -> dict:
        for event in self.events:
            if event.get("method") == method:
                return event
        deadline = time.monotonic() + self.timeout
        while time.monotonic() < deadline:
            event = json.loads(self.ws.recv(timeout=self.timeout))
            self.events.append(event)
            if event.get("method") == method:
                return event
        raise TimeoutError(method)

    def errors(self) -> list[str]:
        """Console errors, uncaught exceptions and browser log errors (failed loads, blocked
        requests) seen so far."""
        out = []
        for e in self.events:
            m, p = e.get("method"), e.get("params", {})
            if m == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
                out.append(
                    "console: "
                    + " ".join(str(a.get("value", a.get("description"))) for a in p.get("args", []))
                )
            elif m == "Runtime.exceptionThrown":
                out.append("exception: " + json.dumps(p.get("exceptionDetails", {}))[:500])
            elif m == "Log.entryAdded" and p.get("entry", {}).get("level") == "error":
                out.append("log: " + p["entry"].get("text", ""))
        return out

    def load(self, url: str) -> dict:
        """Open ``url``, wait for its load event, run :data:`PAGE_CHECK`; returns its result
        with the page's ``errors`` and a PNG ``screenshot`` (bytes)."""
        self.events = []  # this page's events only (an earlier page's load event is not its own)
        self.call("Page.navigate", {"url": url}, session=True)
        self.wait_for("Page.loadEventFired")
        result = self.call(
            "Runtime.evaluate",
            {"expression": PAGE_CHECK, "awaitPromise": True, "returnByValue": True},
            session=True,
        )
        value = result["result"].get("value", {})
        size = self.call("Page.getLayoutMetrics", session=True)["cssContentSize"]
        # the whole page, at half scale (a long report would make a huge image otherwise)
        clip = {
            "x": 0,
            "y": 0,
            "width": size["width"],
            "height": min(size["height"], 12000),
            "scale": 0.5,
        }
        shot = self.call(
            "Page.captureScreenshot",
            {"format": "png", "clip": clip, "captureBeyondViewport": True},
            session=True,
        )
        value["screenshot"] = base64.b64decode(shot["data"])
        value["errors"] = self.errors()
        return value

    def close(self) -> None:
        try:
            self._stack.close()
        finally:
            self.process.terminate()
            try:
                self.process.wait(10)
            except subprocess.TimeoutExpired:
                self.process.kill()
