"""The live page of `drillfric live --serve` (issue 24, docs/live.md "Live page"): a real
server on a loopback port while a replayed well grows, its JSON and a headless Chromium
showing newer data on a second visit, with the CSP on and no error; hostile requests and a
port in use answered in one line. The module's live run lasts ~30 s of replay."""

from __future__ import annotations

import gzip
import http.client
import json
import socket
import time
import urllib.error
import urllib.request
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from drillfric.live.page import LivePage, LiveServer, parse_address, segment_view
from drillfric.live.run import LiveRun, RecentRows
from tests.test_live import LIVE_KEYS, _drillfric, _feed_folder, _finish, _wait_for
from tests.test_report_browser import Browser, PageVisit, _chromium, _record

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow

#: Replay speed: the three-stand well's 440 s pass in ~30 s, long enough for the checks.
SPEED = 15


# ---------------------------------------------------------------------- without a server
@pytest.mark.parametrize(("text", "address"), [
    ("8050", ("127.0.0.1", 8050)), ("0", ("127.0.0.1", 0)),
    ("localhost:8050", ("localhost", 8050)), ("0.0.0.0:80", ("0.0.0.0", 80)),
    ("[::1]:8050", ("::1", 8050))])
def test_serve_address_defaults_to_loopback(text, address):
    assert parse_address(text) == address


@pytest.mark.parametrize("text", ["", "host", "::1:8050", "[::1]", "1:65536", "h:-1",
                                  "h:８０", "[]:80", ":80"])
def test_malformed_serve_address_is_refused(text):
    with pytest.raises(ValueError, match="PORT"):
        parse_address(text)


def test_recent_rows_keep_only_the_last_span_of_log_time():
    recent = RecentRows(span_s=10.0)
    for start in range(0, 30, 5):
        t = np.arange(start, start + 5, 0.5)
        recent.add(pd.DataFrame({"time_s": t, "surface_rpm": t * 2}))
    rows = recent.rows()
    assert rows["time_s"].min() == pytest.approx(19.5) and rows["time_s"].max() == 29.5
    np.testing.assert_array_equal(rows["surface_rpm"], rows["time_s"] * 2)
    assert np.isnan(rows["hookload_N"]).all()  # not logged: NaN, never 0
    assert recent.rows(since_s=28.0)["time_s"].tolist() == [28.5, 29.0, 29.5]
    assert len(recent._parts) <= 3  # older chunks were dropped


def _record_row(**kw) -> dict:
    return {"id": 1, "kind": "off_bottom_rotating", "status": "ok", "t_start_s": 0.0,
            "t_end_s": 100.0, "bit_depth_m": 2000.0, "mu_k": 0.25, "mu_s": None,
            "mu_s_identifiable": False, "mu_s_lower_bound": 0.3, "converged": True,
            "stick_slip_severity": 0.4, "bit_speed_resolved": True, "bit_speed_reason": None,
            "message": ""} | kw


def test_withheld_numbers_are_withheld_in_the_segments_json():
    skipped = segment_view(_record_row(status="skipped", mu_k=0.2, message="too short"), False)
    assert skipped["mu_k_text"] == skipped["mu_s_text"] == "withheld"
    assert skipped["plot_mu_k"] is None and skipped["plot_severity"] is None
    bounded = segment_view(_record_row(), True)
    assert bounded["mu_s_text"] == "≥ 0.300" and bounded["plot_mu_s"] is None
    assert bounded["plot_mu_s_lb"] == 0.3 and bounded["open"]
    on_bottom = segment_view(_record_row(kind="on_bottom_rotating"), False)
    assert on_bottom["mu_k_text"] == "0.250 apparent"
    assert on_bottom["plot_mu_k"] is None and on_bottom["plot_mu_app"] == 0.25


def test_unresolved_bit_speed_is_withheld_not_drawn(tmp_path):
    """A segment whose bit speed is not resolved has estimated rows in estimates.parquet;
    the page lists it as withheld, with the reason, and draws none of them."""
    folder = tmp_path / "out" / "w"
    folder.mkdir(parents=True)
    reason = "bit speed not resolved: 1 Hz log"
    (folder / "summary.json").write_text(json.dumps({"segments": [
        _record_row(id=1), _record_row(id=2, bit_speed_resolved=False,
                                       bit_speed_reason=reason)]}))
    t = np.arange(0.0, 20.0, 0.1)
    pd.DataFrame({"time_s": t, "segment_id": np.where(t < 10, 1, 2).astype("int32"),
                  "start_id": np.int16(-1), "bit_rpm_est": 50.0 + t,
                  "bit_rpm_est_min": 45.0 + t, "bit_rpm_est_max": 55.0 + t}) \
        .to_parquet(folder / "estimates.parquet")
    live = LiveRun(tmp_path / "w.csv", tmp_path / "out")
    live.folder = folder
    live.recent.add(pd.DataFrame({"time_s": t, "surface_rpm": 60.0 + 0 * t}))
    bit = LivePage(live).tracks(None)["bit"]
    drawn = np.asarray(bit["time_s"])
    assert drawn.max() < 10.0 and len(drawn) > 50
    assert bit["withheld"] == [{"segment": 2, "reason": reason}]


# ---------------------------------------------------------------------- a live run served
@pytest.fixture(scope="module")
def served(stands, tmp_path_factory):
    """`drillfric live --serve 0` on a file `drillfric replay` appends to: (URL, processes)."""
    tmp = tmp_path_factory.mktemp("live_page")
    target, out = _feed_folder((stands[0], None), tmp), tmp / "out"
    live = _drillfric("live", target, "--out", out, "--serve", 0, "--until-idle", 2,
                      "--no-report")
    replay = _drillfric("replay", stands[0], "--to", target, "--speed", SPEED)
    try:
        line = live.stdout.readline()  # printed once the port is bound
        assert line.startswith("live page: http://127.0.0.1:"), line + live.stderr.read()
        yield line.split(": ", 1)[1].strip(), live, replay
    finally:
        for proc in (replay, live):
            if proc.poll() is None:
                proc.kill()
            proc.communicate()


def _get(url: str) -> tuple[int, dict, bytes]:
    try:
        with urllib.request.urlopen(url, timeout=10) as reply:
            return reply.status, dict(reply.headers), reply.read()
    except urllib.error.HTTPError as exc:
        return exc.code, dict(exc.headers), exc.read()


def _json(url: str) -> dict:
    status, headers, body = _get(url)
    assert status == 200 and headers["Content-Type"].startswith("application/json")
    return json.loads(body)


def test_page_has_the_strict_csp_and_json_grows_with_the_source(served):
    url = served[0]
    status, headers, body = _get(url)
    assert status == 200 and b"<title>drillfric live</title>" in body
    csp = headers["Content-Security-Policy"]
    assert "default-src 'none'" in csp and "connect-src 'self'" in csp
    assert "unsafe-eval" not in csp and "script-src 'sha256-" in csp
    assert "unsafe-inline" not in csp.split("script-src")[1].split(";")[0]
    assert headers["X-Content-Type-Options"] == "nosniff"
    request = urllib.request.Request(url, headers={"Accept-Encoding": "gzip"})
    with urllib.request.urlopen(request, timeout=10) as reply:
        assert reply.headers["Content-Encoding"] == "gzip"
        assert gzip.decompress(reply.read()) == body
    _wait_for(lambda: _json(url + "tracks.json")["rows"] > 0, 30)
    first, status = _json(url + "tracks.json"), _json(url + "live.json")
    assert LIVE_KEYS <= set(status)
    time.sleep(2.0)
    second = _json(url + "tracks.json")
    assert second["rows"] > first["rows"] and second["last_time_s"] > first["last_time_s"]
    assert len(second["time_s"]) <= 2000 and len(second["time_s"]) == \
        len(second["surface_rpm"]) == len(second["surface_torque_Nm"])
    assert _json(url + "live.json")["rows"] > status["rows"]
    since = _json(url + f"tracks.json?since={second['last_time_s']}")
    assert min(since["time_s"], default=np.inf) > second["last_time_s"]


def _visit(browser: Browser, url: str, expressions: dict[str, str]) -> PageVisit:
    """Open ``url``, wait for the page's first poll to be drawn, evaluate ``expressions``,
    and record requests, console errors (CSP violations among them) and exceptions."""
    target = browser.send("Target.createTarget", {"url": "about:blank"})["targetId"]
    session = browser.send("Target.attachToTarget",
                           {"targetId": target, "flatten": True})["sessionId"]
    for domain in ("Page", "Runtime", "Log", "Network"):
        browser.send(f"{domain}.enable", session=session)
    browser._events.clear()
    browser.send("Page.navigate", {"url": url}, session=session)
    visit = PageVisit()
    if not browser.wait_event("Page.loadEventFired"):
        visit.console_errors.append("page did not finish loading")
    polled = ("new Promise(done => { const t0 = Date.now(); const wait = () => "
              "Number(document.body.dataset.polls || 0) >= 2 || Date.now() - t0 > 15000 ? "
              "done(Number(document.body.dataset.polls || 0)) : setTimeout(wait, 100); "
              "wait(); })")
    expressions = {"polls": polled} | expressions
    for name, expression in expressions.items():
        reply = browser.send("Runtime.evaluate", {"expression": expression,
                                                  "returnByValue": True,
                                                  "awaitPromise": True}, session=session)
        visit.values[name] = reply.get("result", {}).get("value")
    browser.drain(0.3)
    for event in browser._events:
        _record(visit, event, session)
    browser.send("Target.closeTarget", {"targetId": target})
    return visit


#: JavaScript: what the page shows (its text and its figures' data).
_SHOWN = {
    "rows": "Number(document.getElementById('rows').textContent)",
    "last_sample": "document.getElementById('last-sample').textContent",
    "surface_points": "Bokeh.documents[0].get_model_by_name('surface').data.x.length",
    "bit_points": "Bokeh.documents[0].get_model_by_name('bit').data.x.length",
    "mu_s_drawn": "Array.from(Bokeh.documents[0].get_model_by_name('segments').data.mu_s)"
                  ".map(v => Number.isNaN(v) ? 'NaN' : v)",
    "table": "Array.from(document.querySelectorAll('#segments-table tbody tr'))"
             ".map(r => r.cells[5].textContent)",
    "height": "document.getElementById('bk-live').getBoundingClientRect().height",
}


def test_browser_shows_newer_data_while_the_source_grows(served, tmp_path):
    """Headless Chromium loads the page twice while the file grows: the second visit shows
    more rows and a later sample, the figures hold the tracks, the withheld μ_s is NaN in
    the figure (not drawn; never 0) and "≥ …"/"withheld" in the table, and nothing violates
    the CSP or throws."""
    url = served[0]
    exe = _chromium()
    browser = Browser(exe, tmp_path / "profile", tmp_path / "chromium.log")
    try:
        first = _visit(browser, url, _SHOWN)
        time.sleep(2.0)
        _wait_for(lambda: _json(url + "segments.json")["segments"], 30)
        second = _visit(browser, url, _SHOWN)
        control = _visit(browser, url, {"blocked": "fetch('http://127.0.0.1:9/x')"
                                                   ".then(() => 'fetched', () => 'refused')"})
    finally:
        browser.close()
    for visit in (first, second):
        assert visit.console_errors == [] and visit.dialogs == []
        assert [u for u in visit.requests if not u.startswith((url, "data:"))] == []
        assert visit.values["polls"] >= 2 and visit.values["height"] > 500
    assert second.values["rows"] > first.values["rows"] > 0
    assert float(second.values["last_sample"].split()[0]) > \
        float(first.values["last_sample"].split()[0])
    assert second.values["surface_points"] > 100
    shown = dict(zip(second.values["table"][::-1], second.values["mu_s_drawn"], strict=True))
    for text, drawn in shown.items():  # μ_s drawn only where identified
        assert drawn == "NaN" if not text[0].isdigit() else drawn == pytest.approx(
            float(text))
    assert control.values["blocked"] == "refused"  # the CSP's connect-src is in force …
    assert any("Content Security Policy" in e for e in control.console_errors)  # … and seen


def _raw(url: str, method: str, path: str, host: str | None = None) -> tuple[int, dict]:
    address = url.split("//")[1].strip("/")
    conn = http.client.HTTPConnection(address, timeout=10)
    conn.putrequest(method, path, skip_host=host is not None)
    if host is not None:
        conn.putheader("Host", host)
    conn.endheaders()
    reply = conn.getresponse()
    reply.read()
    conn.close()
    return reply.status, dict(reply.headers)


def test_hostile_requests_get_short_answers(served):
    url = served[0]
    for path in ("/../../etc/passwd", "/%2e%2e/summary.json", "/three/summary.json",
                 "/out/live.json", "/favicon.ico"):
        assert _raw(url, "GET", path)[0] == 404, path
    assert _get(url + "tracks.json?since=nan")[0] == 400
    assert _get(url + "tracks.json?since=x")[0] == 400
    assert _raw(url, "POST", "/live.json")[0] in (405, 501)
    status, headers = _raw(url, "GET", "/live.json", host="attacker.example:80")
    assert status == 421  # DNS rebinding: a foreign name resolved to 127.0.0.1
    assert headers["X-Content-Type-Options"] == "nosniff"
    assert _raw(url, "GET", "/live.json", host="localhost")[0] == 200


def test_the_server_stops_when_live_finishes(served):
    url, live, replay = served
    replay.kill()
    replay.wait()
    code, err = _finish(live)
    assert code == 0, err
    host, port = url.split("//")[1].strip("/").rsplit(":", 1)
    with pytest.raises(OSError):
        socket.create_connection((host, int(port)), 2)


def test_port_in_use_exits_2_with_one_line(tmp_path):
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        live = _drillfric("live", tmp_path / "w.csv", "--out", tmp_path / "out", "--serve",
                          port, "--until-idle", 1)
        code, err = _finish(live, 30)
    assert code == 2 and "Traceback" not in err
    assert f"127.0.0.1:{port}" in err and "in use" in err and len(err.strip().splitlines()) == 1
    assert not Path(tmp_path / "out").exists()


def test_open_segment_numbers_that_are_withheld_show_as_withheld_in_the_browser(tmp_path):
    """The open segment's bit speed is in live.json (45 rpm) but the segment says its bit
    speed is not resolved; its μ_s is not identified; a skipped open segment has a μ_k in
    live.json: the page shows each as "withheld: <reason>", never the number."""
    exe = _chromium()
    folder = tmp_path / "out" / "w"
    folder.mkdir(parents=True)
    reason = "bit speed not resolved: 1 Hz log"
    (folder / "summary.json").write_text(json.dumps({"segments": [_record_row(
        id=2, mu_s_lower_bound=None, bit_speed_resolved=False, bit_speed_reason=reason)]}))
    live = LiveRun(tmp_path / "w.csv", tmp_path / "out")
    live.folder = folder
    opened = {"segment": 2, "kind": "off_bottom_rotating", "status": "ok", "t_start_s": 0.0,
              "t_end_s": 100.0, "mu_k": 0.27, "mu_s": None, "mu_s_lower_bound": None,
              "bit_rpm": 45.0, "stick_slip_severity": 0.5}
    live.view["open_segment"] = opened
    server = LiveServer("127.0.0.1", 0)
    server.start(live)
    shown = {k: f"document.getElementById('{k}').textContent" for k in (
        "open-mu-k", "open-mu-s", "open-bit-rpm", "open-severity")}
    browser = Browser(exe, tmp_path / "profile", tmp_path / "chromium.log")
    try:
        first = _visit(browser, server.url, shown)
        live.view["open_segment"] = opened | {"status": "skipped"}
        skipped = _visit(browser, server.url, shown)
        live.view["open_segment"] = opened | {"mu_k_drift": True, "mu_k_last": 0.31,
                                              "mu_k_drift_per_h": 0.2}
        moving = _visit(browser, server.url, shown)
    finally:
        browser.close()
        server.stop()
    assert first.console_errors == []
    assert first.values["open-mu-k"] == "0.270"
    assert first.values["open-mu-s"] == "withheld: not identifiable from these data"
    assert first.values["open-bit-rpm"] == f"withheld: {reason}"
    assert first.values["open-severity"] == "0.50"
    assert all(v.startswith("withheld") for k, v in skipped.values.items() if k != "polls")
    # issue 34 item 6: friction moving within the open segment is shown beside its μ_k
    assert moving.values["open-mu-k"] == ("0.270 — friction moving: μ_k(t) 0.310 at the last "
                                          "window, +0.200/h")


def test_live_values_older_than_five_seconds_say_their_age(tmp_path):
    """Issue 35: open_segment, the latest segment and the alerts resting on rows that ended
    150 s before the newest sample read as current. live.json gives each its age behind the
    newest sample (age_s) and old (beyond OLD_S, the page's constant too)."""
    import re

    from drillfric.live.alerts import OLD_S

    live = LiveRun(tmp_path / "w.csv", tmp_path / "out", clock=lambda: 0.0)
    live.last_data = 0.0
    live.view.update(last_sample_time_s=821.8, latest={"segment": 3, "mu_k": 0.27,
                                                       "mu_s": None, "t_end_s": 819.0},
                     open_segment={"segment": 4, "stick_slip_severity": 1.3,
                                   "t_end_s": 672.0})
    status = live.status()
    assert status["open_segment"]["age_s"] == 149.8 and status["open_segment"]["old"]
    assert status["latest"]["age_s"] == 2.8 and not status["latest"]["old"]
    (severe,) = status["alerts"]
    assert severe["kind"] == "severe_stick_slip" and severe["age_s"] == 149.8 and severe["old"]
    assert live.view["open_segment"].keys() == {"segment", "stick_slip_severity", "t_end_s"}
    js = (Path(__file__).resolve().parents[1] / "templates" / "live.js").read_text()
    assert float(re.search(r"const OLD_S = ([0-9.]+);", js).group(1)) == OLD_S


def test_old_alerts_and_latest_are_greyed_with_their_age_in_the_browser(tmp_path):
    """The page greys an alert and the latest segment older than OLD_S behind the newest
    sample and says how old they are; a current alert stays as it is."""
    exe = _chromium()
    live = LiveRun(tmp_path / "w.csv", tmp_path / "out", clock=lambda: 0.0)
    live.last_data = 0.0
    live.view.update(last_sample_time_s=821.8,
                     latest={"segment": 3, "mu_k": 0.27, "mu_s": None, "t_end_s": 700.0},
                     open_segment={"segment": 4, "kind": "off_bottom_rotating",
                                   "status": "ok", "t_start_s": 600.0, "t_end_s": 672.0,
                                   "mu_k": 0.27, "stick_slip_severity": 1.3},
                     rising={"kind": "friction_rising", "message": "now", "time_s": 820.0})
    server = LiveServer("127.0.0.1", 0)
    server.start(live)
    shown = {"alerts": "Array.from(document.querySelectorAll('#alerts li'))"
                       ".map(li => li.className + '|' + li.textContent)",
             "latest": "document.getElementById('latest').className + '|' + "
                       "document.getElementById('latest').textContent"}
    browser = Browser(exe, tmp_path / "profile", tmp_path / "chromium.log")
    try:
        visit = _visit(browser, server.url, shown)
    finally:
        browser.close()
        server.stop()
    assert visit.console_errors == []
    severe, rising = visit.values["alerts"]
    assert severe.startswith("severe_stick_slip old|")
    assert "150 s before the newest sample, not current" in severe
    assert rising.startswith("friction_rising|") and "not current" not in rising
    assert visit.values["latest"].startswith("old|segment 3")
    assert "122 s before the newest sample" in visit.values["latest"]


def test_live_json_open_segment_is_the_newest_or_says_its_age(stands, tmp_path):
    """Over real TCP while `drillfric replay` grows the file (first of the served tests, while
    the replay runs): when live.json has an open segment, it is the newest segment of
    /segments.json, or live.json says it is older than the newest sample (old, its age).
    Its own live run and replay: the module's served run is kept for the others."""
    target = _feed_folder((stands[0], None), tmp_path)
    live = _drillfric("live", target, "--out", tmp_path / "out", "--serve", 0,
                      "--until-idle", 2, "--no-report")
    replay = _drillfric("replay", stands[0], "--to", target, "--speed", SPEED)
    try:
        line = live.stdout.readline()
        assert line.startswith("live page: http://127.0.0.1:"), line + live.stderr.read()
        _check_open_segment(line.split(": ", 1)[1].strip())
    finally:
        for proc in (replay, live):
            if proc.poll() is None:
                proc.kill()
            proc.communicate()


def _check_open_segment(url: str) -> None:
    seen = []

    def check() -> bool:
        status, segs = _json(url + "live.json"), _json(url + "segments.json")
        again = _json(url + "live.json")  # published between the two fetches: ask again (a
        if again["last_sample_time_s"] != status["last_sample_time_s"]:  # loaded machine
            return False  # had compared a live.json with newer segments)
        opened = status["open_segment"]
        if opened is None or not segs["segments"]:
            return False
        newest = max(r["id"] for r in segs["segments"])
        age = status["last_sample_time_s"] - opened["t_end_s"]
        assert opened["age_s"] == pytest.approx(age, abs=0.06)
        assert opened["segment"] >= newest - 1
        assert opened["segment"] == newest or opened["old"] or age <= 5.0, (opened, newest)
        seen.append(opened["segment"])
        return len(seen) >= 1

    _wait_for(check, 60)
