"""The live page of ``drillfric live SOURCE --serve HOST:PORT`` (docs/live.md "Live page").

A small HTTP server in the live process (the standard library's, one daemon thread per
connection) serves five fixed paths:

- ``/`` — the page: Bokeh figures (BokehJS inlined as in the reports,
  :mod:`drillfric.report.interactive`) and a script that polls the JSON below every
  :data:`POLL_MS` and redraws;
- ``/live.json`` — :meth:`drillfric.live.run.LiveRun.status`, the object of OUT/live.json;
- ``/tracks.json`` — the last minutes of surface rows (:class:`drillfric.live.run.RecentRows`,
  ≤ :data:`TRACK_POINTS`, extremes kept) and the estimated bit speed with its band from
  OUT/NAME/estimates.parquet (``?since=T``: rows after log time T [s] only);
- ``/segments.json`` — the segments of the last publication (OUT/NAME/summary.json) with the
  texts the report shows for them (withheld numbers say so and why).

No request names a file: the server reads only the well's own result files, by name. It
answers GET and HEAD; a Host header that is not a loopback name is refused while bound to a
loopback address (DNS rebinding). The page's Content-Security-Policy is the report's
(scripts by hash, no eval, no network source) plus ``connect-src 'self'``.
"""

from __future__ import annotations

import gzip
import ipaddress
import json
import math
import re
import socket
import threading
from dataclasses import dataclass
from functools import cache, partial
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from importlib.resources import files
from pathlib import Path
from socketserver import TCPServer
from urllib.parse import parse_qs, urlsplit

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
from markupsafe import Markup

from drillfric.errors import DrillfricError
from drillfric.io.results import jsonable, read_json
from drillfric.live.alerts import SEVERE_STICK_SLIP, bit_speed_withheld
from drillfric.live.run import LiveRun
from drillfric.report.data import FINAL_START_ID, extreme_rows
from drillfric.report.interactive import bokeh_js, json_in_script, script_hash, time_figure
from drillfric.report.render import (
    environment,
    is_apparent,
    mu_k_cell,
    mu_s_text,
    severity_text,
    status_word,
)
from drillfric.vocabulary import Status

#: Host the page binds when ``--serve`` names only a port (never all interfaces unasked).
DEFAULT_HOST = "127.0.0.1"
#: Milliseconds between the page's polls.
POLL_MS = 1000
#: Most surface rows per /tracks.json (the extremes of every bucket are kept).
TRACK_POINTS = 2000
#: Most bit-speed rows per /tracks.json, shared by the segments in the window.
BIT_POINTS = 1000
#: Seconds a connection may stay silent before the server closes it.
REQUEST_TIMEOUT_S = 10.0
#: The bit-speed columns read from estimates.parquet (the band only where written).
_BIT_COLUMNS = ("time_s", "segment_id", "start_id", "bit_rpm_est", "bit_rpm_est_min",
                "bit_rpm_est_max", "bha_rpm_est")
_JSON = "application/json; charset=utf-8"
_HTML = "text/html; charset=utf-8"
#: CSP of the JSON answers and errors: nothing at all.
_NOTHING = "default-src 'none'; frame-ancestors 'none'"


def parse_address(text: str) -> tuple[str, int]:
    """``--serve``'s ``PORT``, ``HOST:PORT`` or ``[IPv6]:PORT`` as ``(host, port)``; the host
    defaults to :data:`DEFAULT_HOST` and port 0 picks a free port.

    Raises
    ------
    ValueError
        Not one of these forms (the message says which are).
    """
    text = text.strip()
    host, port = DEFAULT_HOST, text
    if text.startswith("["):
        host, sep, port = text[1:].partition("]:")
        if not sep or not host:
            raise ValueError(f"{text!r}: an IPv6 address is written [ADDRESS]:PORT")
    elif ":" in text:
        host, port = text.rsplit(":", 1)
        if ":" in host:
            raise ValueError(f"{text!r}: an IPv6 address is written [ADDRESS]:PORT")
    if not host or not re.fullmatch(r"[0-9]{1,5}", port) or int(port) > 65535:
        raise ValueError(f"{text!r} is not PORT, HOST:PORT or [ADDRESS]:PORT with a port "
                         "from 0 to 65535")
    return host, int(port)


@dataclass(frozen=True)
class Answer:
    """One HTTP answer: status, content type, body, Content-Security-Policy and the body's
    Content-Encoding (None: as is)."""

    status: int
    content_type: str
    body: bytes
    csp: str = _NOTHING
    encoding: str | None = None


def _json_answer(payload) -> Answer:
    return Answer(200, _JSON, json.dumps(jsonable(payload), separators=(",", ":"),
                                         ensure_ascii=False, allow_nan=False).encode("utf-8"))


def _error(status: int, message: str) -> Answer:
    return Answer(status, "text/plain; charset=utf-8", (message + "\n").encode("utf-8"))


class LivePage:
    """The answers of the live page's server for one :class:`~drillfric.live.run.LiveRun`.

    Reading the well's result files and decimating the rows is done once per change (a
    publication, new rows), whatever the number of pages polling.
    """

    def __init__(self, live: LiveRun):
        self.live = live
        self._lock = threading.Lock()
        self._cache: dict[str, tuple] = {}

    def answer(self, path: str, query: str, gzip_ok: bool = False) -> Answer:
        """The answer to a GET of ``path`` with ``query`` (404 for any other path); the page
        gzip-compressed when the browser takes it (``gzip_ok``)."""
        if path == "/":
            html, csp = page()
            return Answer(200, _HTML, page_gzip(), csp, "gzip") if gzip_ok else \
                Answer(200, _HTML, html, csp)
        if path == "/live.json":
            return _json_answer(self.live.status())
        if path == "/segments.json":
            return _json_answer(self.segments())
        if path == "/tracks.json":
            since = parse_qs(query, max_num_fields=4).get("since", [None])[-1]
            try:
                since_s = None if since is None else float(since)
            except ValueError:
                since_s = math.nan
            if since_s is not None and not math.isfinite(since_s):
                return _error(400, "since must be a log time in seconds")
            return _json_answer(self.tracks(since_s))
        return _error(404, "not found: the live page serves /, /live.json, /tracks.json "
                           "and /segments.json")

    # ------------------------------------------------------------------ result files
    def _folder(self) -> Path | None:
        return getattr(self.live, "folder", None)

    def _published(self, name: str, read, extra: tuple = ()):
        """``read(path)`` of OUT/NAME/``name``, cached by the file's identity and ``extra``
        (what ``read`` depends on besides the file); the last good value while a publication
        replaces the folder (None before any)."""
        folder = self._folder()
        if folder is None:
            return None
        path = folder / name
        try:
            stat = path.stat()
            key = (stat.st_ino, stat.st_mtime_ns, stat.st_size, extra)
        except OSError:
            key = None
        with self._lock:
            held = self._cache.get(name)
        if key is None or (held is not None and held[0] == key):
            return None if held is None else held[1]
        try:
            value = read(path)
        except (OSError, ValueError, DrillfricError):  # replaced while read: next poll
            return None if held is None else held[1]
        with self._lock:
            self._cache[name] = (key, value)
        return value

    def records(self) -> list[dict]:
        """The segments of the last publication (summary.json), as written."""
        summary = self._published("summary.json", read_json)
        return [] if summary is None else list(summary.get("segments", []))

    def segments(self) -> dict:
        """/segments.json: every segment with the report's texts and the plotted values."""
        status = self.live.status()
        open_id = (status["open_segment"] or {}).get("segment")
        return {"well": status["well"], "open_segment": open_id,
                "severe_stick_slip": SEVERE_STICK_SLIP,
                "segments": [segment_view(r, r.get("id") == open_id) for r in self.records()]}

    # ------------------------------------------------------------------ tracks
    def tracks(self, since_s: float | None) -> dict:
        """/tracks.json: surface rows of the last minutes and the estimated bit speed."""
        rows = self.live.recent.rows(since_s)
        t = rows["time_s"]
        keep = extreme_rows(pd.DataFrame(rows), TRACK_POINTS) if len(t) else np.arange(0)
        start = float(t.min()) if len(t) else None
        return {"rows": int(len(t)), "first_time_s": start,
                "last_time_s": float(t.max()) if len(t) else None,
                **{name: values[keep] for name, values in rows.items()},
                "bit": self.bit(start)}

    def bit(self, start_s: float | None) -> dict:
        """The estimated bit speed of the segments after log time ``start_s`` [s], with its
        band; segments whose bit speed is not resolved are listed as withheld instead."""
        empty = {c: [] for c in ("time_s", "bit_rpm_est", "bit_rpm_est_min",
                                 "bit_rpm_est_max", "bha_rpm_est")}
        if start_s is None:
            return empty | {"withheld": []}
        records = {r.get("id"): r for r in self.records()
                   if (r.get("t_end_s") or -math.inf) >= start_s}
        ids = tuple(sorted(records))  # only these segments are read (memory: the window's)
        if not ids:
            return empty | {"withheld": []}
        estimates = self._published("estimates.parquet", partial(_final_bit_rows, ids=ids),
                                    ids)
        if estimates is None:
            return empty | {"withheld": []}
        window = estimates[estimates["time_s"] >= start_s]
        parts, withheld = [], []
        groups = list(window.groupby("segment_id", sort=True))
        for seg_id, rows in groups:
            why = bit_speed_withheld(records.get(int(seg_id), {}))
            if why:
                withheld.append({"segment": int(seg_id), "reason": why})
                continue
            parts.append(band_breaks(rows.iloc[extreme_rows(rows, BIT_POINTS // len(groups),
                                                            ("bit_rpm_est",))]))
        if not parts:
            return empty | {"withheld": withheld}
        frame = pd.concat(parts, ignore_index=True)
        return {c: frame[c].to_numpy(float) for c in empty} | {"withheld": withheld}


def band_breaks(rows: pd.DataFrame) -> pd.DataFrame:
    """One segment's bit rows for the page's band and lines: the area glyph skips null
    values and so joins the band across them — over a withheld window, and from one segment
    to the next across a connection where nothing turned (a newcomer saw a 110-RPM band
    over 90 s in the slips) — so each stretch of the band is closed by a row of no width
    at its first and last time (its low = high, the lines null there), and the null rows
    leave the band: between stretches it has no area.

    Examples
    --------
    >>> rows = pd.DataFrame({"time_s": [0.0, 1.0, 2.0, 3.0], "bit_rpm_est": [5.0, 5, np.nan, 7],
    ...                      "bit_rpm_est_min": [4.0, 4, np.nan, 6],
    ...                      "bit_rpm_est_max": [6.0, 6, np.nan, 8], "bha_rpm_est": np.nan})
    >>> out = band_breaks(rows)
    >>> out["time_s"].tolist(), out["bit_rpm_est_min"].tolist()
    ([0.0, 0.0, 1.0, 1.0, 3.0, 3.0, 3.0], [5.0, 4.0, 4.0, 5.0, 7.0, 6.0, 7.0])
    """
    low, high = rows["bit_rpm_est_min"].to_numpy(float), rows["bit_rpm_est_max"].to_numpy(float)
    valid = np.isfinite(low) & np.isfinite(high)
    if not valid.any():
        return rows
    mid = (low + high) / 2.0
    edges = np.diff(np.r_[0, valid.astype(int), 0])
    pieces = []
    for a, b in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1), strict=True):
        run = rows.iloc[a:b]
        pieces += [_closed(run.iloc[:1], mid[a]), run, _closed(run.iloc[-1:], mid[b - 1])]
    return pd.concat(pieces, ignore_index=True)


def _closed(row: pd.DataFrame, level: float) -> pd.DataFrame:
    """``row`` as the band's end: no width at ``level`` [RPM], its lines null."""
    return row.assign(bit_rpm_est=np.nan, bha_rpm_est=np.nan, bit_rpm_est_min=level,
                      bit_rpm_est_max=level)


def _final_bit_rows(path: Path, ids: tuple[int, ...]) -> pd.DataFrame:
    """The final pass's bit speed, its band and the BHA's speed of segments ``ids`` in
    estimates.parquet (NaN where the file has no such column)."""
    names = pq.read_schema(path).names
    table = pq.read_table(path, columns=[c for c in _BIT_COLUMNS if c in names],
                          filters=[("start_id", "=", FINAL_START_ID),
                                   ("segment_id", "in", list(ids))])
    frame = table.to_pandas()
    for column in ("bit_rpm_est_min", "bit_rpm_est_max", "bha_rpm_est"):
        if column not in frame:
            frame[column] = np.nan
    return frame.sort_values(["segment_id", "time_s"], kind="stable")


def segment_view(record: dict, is_open: bool) -> dict:
    """One segment of /segments.json: its numbers, the report's texts, and the values the
    friction figure plots (null where withheld; μ_k and the apparent μ on bottom apart)."""
    ok = record.get("status") == Status.OK
    apparent = is_apparent(record)
    mu_k = record.get("mu_k") if ok else None
    return {key: record.get(key) for key in (
        "id", "kind", "status", "t_start_s", "t_end_s", "bit_depth_m", "mu_k", "mu_s",
        "mu_s_identifiable", "mu_s_lower_bound", "converged", "stick_slip_severity",
        "bit_speed_resolved", "bit_speed_reason", "message")} | {
        "open": is_open, "status_text": status_word(record),
        "mu_k_text": mu_k_cell(record) if ok and mu_k is not None else "withheld",
        "mu_s_text": mu_s_text(record.get("mu_s"), bool(record.get("mu_s_identifiable")),
                               record.get("mu_s_lower_bound")) if ok else "withheld",
        "severity_text": severity_text(record) if ok else "—",
        "plot_mu_k": None if apparent else mu_k, "plot_mu_app": mu_k if apparent else None,
        "plot_mu_s": record.get("mu_s") if ok and record.get("mu_s_identifiable") else None,
        "plot_mu_s_lb": record.get("mu_s_lower_bound") if ok else None,
        "plot_severity": record.get("stick_slip_severity") if ok else None,
        "plot_fill": 1.0 if record.get("converged") else 0.0}


# ---------------------------------------------------------------------------- the page
@cache
def page() -> tuple[bytes, str]:
    """The page's HTML and its Content-Security-Policy (built once per process)."""
    from bokeh.embed import json_item

    app = files("drillfric.templates").joinpath("live.js").read_text(encoding="utf-8") \
        .replace("POLL_MS", str(POLL_MS))
    js = bokeh_js()
    html = environment().get_template("live.html.j2").render(
        bokeh_js=Markup(js), app_js=Markup(app),
        items=json_in_script([json_item(_layout(), "bk-live")]))
    csp = ("default-src 'none'; img-src data:; style-src 'unsafe-inline'; "
           f"script-src {script_hash(js)} {script_hash(app)}; connect-src 'self'; "
           "base-uri 'none'; form-action 'none'; frame-ancestors 'none'")
    return html.encode("utf-8"), csp


@cache
def page_gzip() -> bytes:
    """The page's HTML, gzip-compressed (a third of the bytes; built once per process)."""
    return gzip.compress(page()[0], compresslevel=6, mtime=0)


def _layout():
    """The figures, their ColumnDataSources named for the page's script: ``surface``
    (x, rpm, torque_kNm, hookload_kN), ``bit`` (x, rpm, low, high, bha) and ``segments``."""
    from bokeh.layouts import column, row
    from bokeh.models import ColumnDataSource, DataRange1d, HoverTool, Span
    from bokeh.plotting import figure

    surface = ColumnDataSource({k: [] for k in ("x", "rpm", "torque_kNm", "hookload_kN")},
                               name="surface")
    bit = ColumnDataSource({k: [] for k in ("x", "rpm", "low", "high", "bha")}, name="bit")
    segs = ColumnDataSource({k: [] for k in ("id", "depth", "mu_k", "mu_app", "mu_s", "mu_s_lb",
                                             "severity", "fill")}, name="segments")
    speed = time_figure(220, "speed [rpm]")
    speed.varea("x", "low", "high", source=bit, fill_alpha=0.25, color="#ff7f0e",
                legend_label="bit band")
    speed.line("x", "rpm", source=surface, color="#1f77b4", legend_label="surface")
    speed.line("x", "rpm", source=bit, color="#d62728", legend_label="bit (estimated)")
    speed.line("x", "bha", source=bit, color="#d62728", line_dash="dashed",
               legend_label="BHA (string's bottom; the bit's less a mud motor's)")
    speed.legend.location = "top_left"
    torque = time_figure(170, "torque [kN·m]", x_range=speed.x_range)
    torque.line("x", "torque_kNm", source=surface, color="#2ca02c")
    hook = time_figure(170, "hook load [kN]", x_range=speed.x_range, x_label="log time [s]")
    hook.line("x", "hookload_kN", source=surface, color="#9467bd")
    depth = DataRange1d(flipped=True, range_padding=0.2, min_interval=10.0)
    mu = figure(height=300, width=460, tools="pan,wheel_zoom,box_zoom,reset,save",
                x_range=DataRange1d(start=0.0, range_padding=0.15), y_range=depth,
                x_axis_label="μ [-]", y_axis_label="bit depth [m]")
    mu.scatter("mu_k", "depth", source=segs, size=9, color="#1f77b4", fill_alpha="fill",
               legend_label="μ_k")
    mu.scatter("mu_app", "depth", source=segs, size=9, marker="triangle", color="#8c564b",
               fill_alpha="fill", legend_label="apparent μ (on bottom)")
    mu.scatter("mu_s", "depth", source=segs, size=9, marker="square", color="#d62728",
               fill_alpha="fill", legend_label="μ_s")
    mu.scatter("mu_s_lb", "depth", source=segs, size=9, marker="triangle", angle=-math.pi / 2,
               color="#d62728", fill_alpha=0.0, legend_label="μ_s lower bound")
    mu.legend.location = "bottom_left"
    mu.legend.label_text_font_size = "9px"
    mu.legend.background_fill_alpha = 0.6
    mu.add_tools(HoverTool(tooltips=[("segment", "@id"), ("depth", "@depth{0.0} m")]))
    severity = figure(height=300, width=300, y_range=depth,
                      x_range=DataRange1d(start=0.0, range_padding=0.15),
                      tools="pan,wheel_zoom,box_zoom,reset,save",
                      x_axis_label="stick-slip severity [-]")
    severity.scatter("severity", "depth", source=segs, size=9, color="#7f7f7f")
    severity.add_layout(Span(location=SEVERE_STICK_SLIP, dimension="height",
                             line_dash="dashed", line_color="#d62728"))
    return column(speed, torque, hook, row(mu, severity), sizing_mode="stretch_width")


# ---------------------------------------------------------------------------- the server
class _Handler(BaseHTTPRequestHandler):
    server_version = "drillfric-live"
    sys_version = ""
    protocol_version = "HTTP/1.1"
    timeout = REQUEST_TIMEOUT_S

    def do_GET(self):  # noqa: N802 — the standard library's name
        self._respond(body=True)

    def do_HEAD(self):  # noqa: N802
        self._respond(body=False)

    def _respond(self, body: bool) -> None:
        url = urlsplit(self.path)
        hosts = self.headers.get_all("Host") or []  # one, and an absolute URI's host too
        if len(hosts) != 1 or not self.server.host_allowed(hosts[0]) or \
                (url.netloc and not self.server.host_allowed(url.netloc)):
            answer = _error(421, "this page answers only to a loopback host name")
        else:
            try:
                answer = self.server.page.answer(
                    url.path, url.query, "gzip" in self.headers.get("Accept-Encoding", ""))
            except Exception as exc:  # noqa: BLE001 — one line to the page, the run goes on
                answer = _error(500, f"the live page failed: {type(exc).__name__}: {exc}")
        self.send_response(answer.status)
        self.send_header("Content-Type", answer.content_type)
        self.send_header("Content-Length", str(len(answer.body)))
        self.send_header("Content-Security-Policy", answer.csp)
        self.send_header("Cache-Control", "no-store")
        self.send_header("Vary", "Accept-Encoding")
        if answer.encoding:
            self.send_header("Content-Encoding", answer.encoding)
        self.end_headers()
        if body:
            self.wfile.write(answer.body)

    def end_headers(self):
        self.send_header("X-Content-Type-Options", "nosniff")
        self.send_header("Referrer-Policy", "no-referrer")
        super().end_headers()

    def log_message(self, format, *args):  # noqa: A002 — quiet: the CLI prints its own lines
        pass


class LiveServer(ThreadingHTTPServer):
    """The live page's server, bound on creation (a failure raises :class:`OSError`)."""

    daemon_threads = True

    def __init__(self, host: str, port: int):
        self.address_family = socket.AF_INET6 if ":" in host else socket.AF_INET
        self.page: LivePage | None = None
        self._thread: threading.Thread | None = None
        super().__init__((host, port), _Handler)
        self.loopback = _is_loopback(host)

    def handle_error(self, request, client_address) -> None:
        """A connection that broke off (a closed tab) is no error of the run: quiet."""

    def server_bind(self) -> None:
        TCPServer.server_bind(self)  # no reverse DNS look-up of the host (HTTPServer's)
        self.server_name, self.server_port = self.server_address[:2]

    @property
    def url(self) -> str:
        """The page's address (the port the system chose for port 0)."""
        host = self.server_address[0]
        return f"http://[{host}]:{self.server_port}/" if ":" in host else \
            f"http://{host}:{self.server_port}/"

    def host_allowed(self, header: str) -> bool:
        """Whether a request's Host header may be answered: any while bound to a public
        address; a loopback name or address while bound to loopback (DNS rebinding)."""
        if not self.loopback:
            return True
        name = header.rsplit(":", 1)[0] if not header.endswith("]") else header
        name = name.strip("[]").lower()
        return name == "localhost" or _is_loopback(name)

    def start(self, live: LiveRun) -> None:
        """Serve ``live`` from a daemon thread."""
        self.page = LivePage(live)
        self._thread = threading.Thread(target=self.serve_forever, kwargs={"poll_interval": 0.2},
                                        name="drillfric-live-page", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stop serving and close the socket."""
        if self._thread is not None:
            self.shutdown()
            self._thread.join()
        self.server_close()


def _is_loopback(host: str) -> bool:
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return host.lower() == "localhost"


def serve(address: str) -> LiveServer:
    """A :class:`LiveServer` bound at ``--serve``'s ``address`` (not serving yet).

    Raises
    ------
    ValueError
        ``address`` is malformed or cannot be bound (the message says why).
    """
    host, port = parse_address(address)
    try:
        return LiveServer(host, port)
    except OSError as exc:
        why = exc.strerror or str(exc)
        raise ValueError(f"cannot serve the live page at {host}:{port}: {why}") from None
