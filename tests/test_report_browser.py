"""The reports open in a real browser: headless Chromium driven over the DevTools protocol.

Chromium is started with ``--remote-debugging-pipe`` (JSON messages separated by NUL on file
descriptors 3 and 4, no socket, no port) and background networking disabled. For each page
we record every network request, console error, uncaught exception and JavaScript dialog,
then take a screenshot. The tests skip, with a message, where no Chromium is installed
(Debian: ``apt-get install chromium``; .ci/run installs it).
"""

from __future__ import annotations

import base64
import io
import json
import os
import select
import shutil
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from drillfric.report import write_fleet_report, write_well_report
from tests.synthetic_results import older_result
from tests.test_report import (
    XSS_NAME,
    demo_result_dir,
    evidence_dir,
    fleet_wells,
    renamed_result,
)

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow

_FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
          "--disable-component-update", "--disable-sync", "--no-first-run",
          "--disable-default-apps", "--disable-extensions", "--mute-audio",
          "--window-size=1280,1600")
#: Schemes a self-contained page may load from (itself and its embedded images).
_LOCAL_SCHEMES = ("file:", "data:", "about:")
_TIMEOUT_S = 60.0


def _chromium() -> str:
    for name in ("chromium", "chromium-browser", "google-chrome", "chrome"):
        if path := shutil.which(name):
            return path
    pytest.skip("no Chromium browser found (Debian: apt-get install chromium): "
                "the browser checks of the reports were not run")


@dataclass
class PageVisit:
    """What happened while a page was loaded."""

    requests: list = field(default_factory=list)
    console_errors: list = field(default_factory=list)
    dialogs: list = field(default_factory=list)
    screenshot: bytes = b""
    values: dict = field(default_factory=dict)

    @property
    def remote_requests(self) -> list[str]:
        """URLs of requests that leave the file (anything but file:, data:, about:)."""
        return [u for u in self.requests if not u.startswith(_LOCAL_SCHEMES)]


class Browser:
    """A headless Chromium spoken to over ``--remote-debugging-pipe``."""

    def __init__(self, exe: str, profile: Path, log: Path):
        # fd 3 (commands) and fd 4 (replies) of Chromium are our stdin/stdout pipes.
        wrapper = ['sh', '-c', 'exec "$@" 3<&0 4>&1 0</dev/null 1>/dev/null', 'sh', exe,
                   *_FLAGS, f"--user-data-dir={profile}", "--remote-debugging-pipe",
                   "about:blank"]
        self._log = open(log, "wb")  # noqa: SIM115 — closed in close()
        self.proc = subprocess.Popen(wrapper, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=self._log)
        self._buffer = b""
        self._next_id = 0
        self._events: list[dict] = []

    def send(self, method: str, params: dict | None = None, session: str | None = None,
             timeout_s: float = _TIMEOUT_S) -> dict:
        """Send a command and wait for its reply (events received meanwhile are kept)."""
        self._next_id += 1
        message = {"id": self._next_id, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = session
        self.proc.stdin.write(json.dumps(message).encode() + b"\0")
        self.proc.stdin.flush()
        deadline = time.monotonic() + timeout_s
        while True:
            msg = self._receive(deadline)
            if msg is None:
                raise TimeoutError(f"no reply to {method} within {timeout_s} s")
            if msg.get("id") == self._next_id:
                if "error" in msg:
                    raise RuntimeError(f"{method}: {msg['error']}")
                return msg.get("result", {})
            self._events.append(msg)

    def wait_event(self, method: str, timeout_s: float = _TIMEOUT_S) -> bool:
        """Wait until an event named ``method`` arrived (True) or time ran out (False)."""
        deadline = time.monotonic() + timeout_s
        while not any(e.get("method") == method for e in self._events):
            msg = self._receive(deadline)
            if msg is None:
                return False
            self._events.append(msg)
        return True

    def drain(self, seconds: float) -> None:
        """Collect events for ``seconds`` more."""
        deadline = time.monotonic() + seconds
        while (msg := self._receive(deadline)) is not None:
            self._events.append(msg)

    def _receive(self, deadline: float) -> dict | None:
        fd = self.proc.stdout.fileno()
        while b"\0" not in self._buffer:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([fd], [], [], left)[0]:
                return None
            chunk = os.read(fd, 1 << 20)
            if not chunk:
                raise RuntimeError("Chromium closed the DevTools pipe")
            self._buffer += chunk
        raw, self._buffer = self._buffer.split(b"\0", 1)
        return json.loads(raw)

    def visit(self, url: str, expressions: dict[str, str] | None = None,
              width: int | None = None, full_page: bool = False) -> PageVisit:
        """Open ``url`` in a new tab, wait for its load event, record what happened.

        ``width``: viewport width [px] (default: the window's); ``full_page``: the
        screenshot covers the whole page, not only the viewport.
        """
        target = self.send("Target.createTarget", {"url": "about:blank"})["targetId"]
        session = self.send("Target.attachToTarget",
                            {"targetId": target, "flatten": True})["sessionId"]
        for domain in ("Page", "Runtime", "Log", "Network"):
            self.send(f"{domain}.enable", session=session)
        if width is not None:
            self.send("Emulation.setDeviceMetricsOverride", {
                "width": width, "height": 1600, "deviceScaleFactor": 1, "mobile": False},
                session=session)
        self._events.clear()
        self.send("Page.navigate", {"url": url}, session=session)
        loaded = self.wait_event("Page.loadEventFired")
        self.drain(0.5)
        visit = PageVisit()
        for event in self._events:
            _record(visit, event, session)
        if not loaded:
            visit.console_errors.append("page did not finish loading")
        for name, expression in (expressions or {}).items():
            reply = self.send("Runtime.evaluate", {"expression": expression,
                                                   "returnByValue": True}, session=session)
            visit.values[name] = reply.get("result", {}).get("value")
        shot = self.send("Page.captureScreenshot", {"format": "png",
                                                    "captureBeyondViewport": full_page},
                         session=session)
        visit.screenshot = base64.b64decode(shot["data"])
        self.send("Target.closeTarget", {"targetId": target})
        return visit

    def close(self) -> None:
        try:
            self.send("Browser.close", timeout_s=10)
        except (OSError, RuntimeError, TimeoutError):
            pass
        try:
            self.proc.wait(timeout=15)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        self._log.close()


def _record(visit: PageVisit, event: dict, session: str) -> None:
    if event.get("sessionId") != session:
        return
    method, params = event.get("method"), event.get("params", {})
    if method == "Network.requestWillBeSent":
        visit.requests.append(params["request"]["url"])
    elif method == "Runtime.exceptionThrown":
        visit.console_errors.append(json.dumps(params.get("exceptionDetails", {}))[:300])
    elif method == "Runtime.consoleAPICalled" and params.get("type") in ("error", "assert"):
        visit.console_errors.append(json.dumps(params.get("args", []))[:300])
    elif method == "Log.entryAdded" and params.get("entry", {}).get("level") == "error":
        visit.console_errors.append(params["entry"].get("text", "")[:300])
    elif method == "Page.javascriptDialogOpening":
        visit.dialogs.append(params.get("message"))


def _non_blank(png: bytes) -> bool:
    """More than a handful of colours and not one flat colour (a rendered page)."""
    from PIL import Image

    pixels = np.asarray(Image.open(io.BytesIO(png)).convert("L"), dtype=float)
    return pixels.size > 0 and pixels.std() > 5.0 and np.unique(pixels).size > 16


@pytest.fixture(scope="module")
def browser(tmp_path_factory):
    exe = _chromium()
    tmp = tmp_path_factory.mktemp("chromium")
    instance = Browser(exe, tmp / "profile", tmp / "chromium.log")
    try:
        instance.send("Browser.getVersion", timeout_s=_TIMEOUT_S)
    except (OSError, RuntimeError, TimeoutError) as exc:
        instance.close()
        tail = (tmp / "chromium.log").read_text(errors="replace")[-400:]
        pytest.skip(f"Chromium could not be started ({exc}): {tail}")
    yield instance
    instance.close()


def test_browser_check_catches_remote_requests_and_errors(browser, tmp_path):
    """Positive control: the harness does see a network request, a console error, an alert.

    Without it the checks below could pass because nothing is ever recorded.
    """
    page = tmp_path / "leaky.html"
    page.write_text('<!DOCTYPE html><html><body><p>leaky</p>'
                    '<img src="http://127.0.0.1:9/x.png"><script>console.error("boom")'
                    '</script></body></html>', encoding="utf-8")
    visit = browser.visit(page.as_uri())
    assert any(u.startswith("http://127.0.0.1:9/") for u in visit.remote_requests)
    assert any("boom" in e for e in visit.console_errors)


#: JavaScript: every figure container holds a drawn Bokeh figure (non-zero height).
_DRAWN = ("Array.from(document.querySelectorAll('.bk-root-box'))"
          ".map(e => Math.round(e.getBoundingClientRect().height))")
#: JavaScript: the toolbars' tools of every embedded Bokeh document (zoom, hover, ...).
_TOOLS = ("Bokeh.documents.map(d => { const r = d.roots()[0];"
          " const tb = r.toolbar || (r.children && r.children[0] && r.children[0].toolbar);"
          " return tb ? tb.tools.map(t => t.type === 'ToolProxy' ? t.tools[0].type : t.type)"
          " : []; })")


def test_well_report_loads_offline_without_errors(browser, tmp_path_factory):
    """Issues 7 and 16: report.html loads with no console error (none from the CSP
    either), no network request; every interactive figure is drawn and has its zoom and
    hover tools; the static images decode; the screenshot is not blank."""
    result = evidence_dir(tmp_path_factory)
    html = write_well_report(result)
    visit = browser.visit(html.as_uri(), {
        "images": "Array.from(document.images).filter(i => i.complete && i.naturalWidth > 0)"
                  ".length",
        "all_images": "document.images.length",
        "title": "document.title",
        "documents": "Bokeh.documents.length",
        "drawn": _DRAWN,
        "tools": _TOOLS}, full_page=True)
    assert visit.remote_requests == []
    assert visit.console_errors == []
    assert visit.dialogs == []
    n_segments = len(json.loads((result / "summary.json").read_text())["segments"])
    assert visit.values["documents"] == 2 + n_segments  # tracks, friction log, segments
    assert len(visit.values["drawn"]) == visit.values["documents"]
    assert min(visit.values["drawn"]) > 200
    for tools in visit.values["tools"]:
        assert {"WheelZoomTool", "BoxZoomTool", "HoverTool", "ResetTool"} <= set(
            t.split(".")[-1] for t in tools), tools
    assert visit.values["all_images"] >= 3  # broomstick, well path, profiles
    assert visit.values["images"] == visit.values["all_images"]  # every image decoded
    assert visit.values["title"] == "drillfric — demo"
    assert _non_blank(visit.screenshot)


def test_older_results_load_without_errors(browser, tmp_path_factory, tmp_path):
    """Results without the issue-16 files still give a working page (notes, no errors)."""
    html = write_well_report(older_result(demo_result_dir(tmp_path_factory), tmp_path / "o"))
    visit = browser.visit(html.as_uri(), {"documents": "Bokeh.documents.length"})
    assert visit.remote_requests == [] and visit.console_errors == []
    assert visit.values["documents"] == 1 + 4  # friction log and the 4 segments


def test_diagnostics_rows_fit_at_1400_px(browser, tmp_path_factory):
    """Issue 16, item 7: at 1400 px the diagnostics table fits its width (no horizontal
    overflow) and no row is taller than 60 px (the old table had 100 px rows and a cut
    message column)."""
    html = write_well_report(evidence_dir(tmp_path_factory))
    visit = browser.visit(html.as_uri(), {
        "heights": "Array.from(document.querySelectorAll('#diagnostics-table tr'))"
                   ".map(r => r.getBoundingClientRect().height)",
        "table": "document.getElementById('diagnostics-table').getBoundingClientRect().right",
        "page": "document.documentElement.clientWidth"}, width=1400)
    assert visit.console_errors == []
    assert max(visit.values["heights"]) <= 60.0, visit.values["heights"]
    assert visit.values["table"] <= visit.values["page"]


def test_fleet_report_loads_offline_without_errors(browser, tmp_path_factory, tmp_path):
    """Issue 7: fleet.html of 3 wells (+1 failed) loads offline, links resolve to files."""
    wells = fleet_wells(tmp_path, demo_result_dir(tmp_path_factory))
    html = write_fleet_report(tmp_path, wells)
    visit = browser.visit(html.as_uri(), {
        "documents": "Bokeh.documents.length", "drawn": _DRAWN,
        "rows": "document.querySelectorAll('#wells-table tr').length - 1",
        "links": "Array.from(document.querySelectorAll('#wells-table a')).map(a => a.href)",
        "failed": "document.getElementById('failed-wells').textContent"})
    assert visit.remote_requests == []
    assert visit.console_errors == []
    assert visit.values["rows"] == len(wells)
    assert visit.values["documents"] == 1 and min(visit.values["drawn"]) > 200
    assert "disk full" in visit.values["failed"]
    assert len(visit.values["links"]) == 3
    for href in visit.values["links"]:
        assert href.startswith("file://")
        from urllib.parse import unquote, urlparse

        assert Path(unquote(urlparse(href).path)).is_file()
    assert _non_blank(visit.screenshot)


def test_script_in_well_name_is_text_in_browser(browser, tmp_path_factory, tmp_path):
    """A well named <script>alert(1)</script> shows as text and runs nothing: the page's
    only scripts are its own three (Bokeh, the figures' JSON, the loader)."""
    result = renamed_result(tmp_path, XSS_NAME, demo_result_dir(tmp_path_factory))
    html = write_well_report(result)
    fleet = write_fleet_report(tmp_path, [{"well": XSS_NAME, "status": "ok", "message": "",
                                           "result_dir": result.name,
                                           "summary": json.loads(
                                               (result / "summary.json").read_text())}])
    for path, selector in ((html, "#well-name"), (fleet, "#wells-table b")):
        visit = browser.visit(path.as_uri(), {
            "text": f"document.querySelector('{selector}').textContent",
            "scripts": "document.scripts.length"})
        assert visit.values["text"] == XSS_NAME
        assert visit.values["scripts"] == 3
        assert visit.dialogs == []
        assert visit.console_errors == []
