"""A well estimated while it is drilled: ``drillfric live`` on a CSV file being appended to,
or on a well directory into which its files arrive (docs/live.md, issue 24).

Three pieces:

- the source's tail (:mod:`drillfric.live.source`: :class:`~drillfric.live.source.Tail`,
  :class:`~drillfric.live.source.PartsTail`) — how far the data arrived complete (a write
  may stop mid-line: a partial last line waits for its line end), with the mark
  :mod:`drillfric.runner.resume` checks a continued run against;
- :class:`LiveRun` — a *feed thread* reads the new complete lines into the cheap half of an
  :class:`~drillfric.runner.engine.Engine` (kept in memory: log check, rig states, segment
  cuts; :meth:`~drillfric.runner.engine.Engine.segment_raw`) and hands the segments that
  closed to a *fit thread*, which estimates them in order and *publishes*: a copy of the
  engine is closed into ``OUT/NAME`` exactly as ``drillfric run`` writes it (atomically, with
  the state to continue from), which also estimates the open segment. A publication follows
  each segment's close, and one of an open segment with new rows comes every
  :attr:`LiveRun.publish_every_s` (or later: :meth:`LiveRun.open_every_s`);
- :func:`status` — live.json, rewritten atomically by the calling thread as soon as rows were
  fed and at least every :data:`POLL_S` (neither a fit nor a publication holds it back).

A restarted live run continues from ``OUT/NAME/state`` (the last publication) when the data
still start with what it had read, so no row is lost or read twice.
"""

from __future__ import annotations

import copy
import queue
import threading
import time
from collections import deque
from collections.abc import Callable
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq

from drillfric.errors import DrillfricError, InputError
from drillfric.io.atomic import replacing
from drillfric.io.results import write_json
from drillfric.io.well import CHUNK_ROWS, Well
from drillfric.live.alerts import (
    aged,
    alert,
    behind,
    behind_alert,
    closed_view,
    ended,
    friction_rising,
    open_view,
    severe_stick_slip,
    trend_alert,
    utc_at,
)
from drillfric.live.source import PartsTail, Tail, follow
from drillfric.result import SegmentRecord
from drillfric.runner import warmup
from drillfric.runner.engine import Engine
from drillfric.runner.finish import DirectorySink, MemorySink, ReportWriter, deliver
from drillfric.runner.resume import restored, unread
from drillfric.runner.time_log import STATE_DIR, finish_engine
from drillfric.segmentation import RIG_STATES
from drillfric.vocabulary import Status

#: Longest wait between two rewrites of live.json [s] (INTERFACE: at least every 0.5 s).
POLL_S = 0.2
#: Seconds between polls of the file when it did not grow.
FEED_POLL_S = 0.1
#: Shortest wait between two rewrites of live.json [s] (it is rewritten as soon as rows were
#: fed, but not more often).
MIN_WRITE_S = 0.05
#: Longest wait for the worker to end after live.json could not be written [s].
STOP_WAIT_S = 30.0
#: Share of a core that publications of an open segment may take on average (they come
#: less often than every ``publish_every_s`` when one costs more).
OPEN_SHARE = 0.1
#: The longest wait between two publications of an open segment, in ``publish_every_s``: a
#: costly one (a long open segment, a loaded machine) may take more than OPEN_SHARE of a core
#: rather than leave the open segment unpublished for minutes (issue 35).
MAX_OPEN_WAIT_FACTOR = 3.0
#: Log seconds the estimated bit must have stayed stuck, at the end of the open segment while
#: the top drive turns, for a ``bit_stalled`` alert: longer than the stick phase of ordinary
#: stick-slip (1–3 s at 60–120 RPM: docs/live.md).
BIT_STALL_S = 5.0
#: Log seconds of surface rows kept for the live page's time tracks (:class:`RecentRows`).
RECENT_S = 600.0
#: The channels of :class:`RecentRows` (SI; NaN where the log lacks one).
RECENT_CHANNELS = ("time_s", "surface_rpm", "surface_torque_Nm", "hookload_N")


class RecentRows:
    """The surface rows of the last ``span_s`` log seconds (a bounded ring of chunks), read
    by the live page's threads while the worker adds to it."""

    def __init__(self, span_s: float = RECENT_S):
        self.span_s = span_s
        self.version = 0  # counts the chunks added (a reader's cache key)
        self._parts: deque[dict[str, np.ndarray]] = deque()
        self._lock = threading.Lock()

    def add(self, chunk: pd.DataFrame | None) -> None:
        """Keep the rows of a canonical chunk; forget chunks older than the span."""
        if chunk is None or not len(chunk) or "time_s" not in chunk:
            return
        part = {c: chunk[c].to_numpy(float, copy=True) if c in chunk
                else np.full(len(chunk), np.nan) for c in RECENT_CHANNELS}
        with self._lock:
            self._parts.append(part)
            newest = _newest(self._parts)
            while len(self._parts) > 1 and not \
                    np.nanmax(self._parts[0]["time_s"], initial=-np.inf) >= newest - self.span_s:
                self._parts.popleft()
            self.version += 1

    def rows(self, since_s: float | None = None) -> dict[str, np.ndarray]:
        """The rows of the last ``span_s`` log seconds, after ``since_s`` [s] if given."""
        with self._lock:
            parts = list(self._parts)
        if not parts:
            return {c: np.zeros(0) for c in RECENT_CHANNELS}
        out = {c: np.concatenate([p[c] for p in parts]) for c in RECENT_CHANNELS}
        t = out["time_s"]
        keep = t >= _newest(parts) - self.span_s
        if since_s is not None:
            keep &= t > since_s
        return {c: v[keep] for c, v in out.items()}


def _newest(parts) -> float:
    return max(np.nanmax(p["time_s"], initial=-np.inf) for p in parts)


class LiveRun:
    """A live run of one CSV file being appended to (or of a well directory into which its
    files arrive), into ``out_root/NAME``.

    Parameters
    ----------
    path : Path
        The growing CSV file, or the well directory (:func:`drillfric.live.source.follow`).
    out_root : Path
        Output root (``--out``).
    open_kw : dict
        :func:`~drillfric.io.well.open_well` keywords (``config``, ``name``).
    report : callable, optional
        Writes the report of the final results (none for the intermediate ones).
    publish_every_s : float
        Wall seconds between publications of an open segment with new data (at least:
        :meth:`open_every_s`).
    stale_s, stopped_s : float
        Wall seconds without new data before a ``data_stale`` / ``data_stopped`` alert.
    clock : callable
        Wall clock [s] (tests).
    """

    def __init__(self, path: Path, out_root: Path, *, open_kw: dict | None = None,
                 report: ReportWriter | None = None, publish_every_s: float = 10.0,
                 stale_s: float = 10.0, stopped_s: float = 60.0,
                 clock: Callable[[], float] = time.monotonic):
        self.path, self.out_root, self.open_kw = Path(path), Path(out_root), open_kw or {}
        self.target = self.out_root / "live.json"
        self.report, self.publish_every_s = report, publish_every_s
        self.stale_s, self.stopped_s, self.clock = stale_s, stopped_s, clock
        self.tail: Tail | PartsTail = follow(self.path)
        self.well: Well | None = None
        self.engine: Engine | None = None
        self.stop = threading.Event()
        self.done = threading.Event()  # the worker ended (final results written or error)
        self.fed = threading.Event()  # rows fed since live.json was last written
        self.error: BaseException | None = None
        self.result = None
        self.last_data = clock()  # when the file last grew (wall clock)
        self.tail_fed, self.published_at, self.dirty = 0, clock(), False
        #: Work for the fit thread, in order: ("fit", segments, plateaus), ("publish" or
        #: "final", the engine's feed state, the well read); None ends it.
        self.jobs: queue.Queue = queue.Queue()
        self.pending = threading.Event()  # a publication handed and not yet begun
        self.fitted = threading.Event()  # the fit thread ended
        self.publish_cpu_s = 0.0  # CPU seconds of the last publication
        self.max_gap_s = 0.0  # the longest wait between two live.json writes
        self._size, self._written = -1, None
        self.lock = threading.Lock()
        self.recent = RecentRows()  # the last minutes of surface rows (the live page)
        self.view: dict = {"last_sample_time_s": None, "last_sample_utc": None,
                           "rig_state": None, "open_segment": None, "latest": None,
                           "trend_alert": None, "rising": None, "rows": 0,
                           "segments_closed": 0, "resumed": None, "closed": None,
                           "first_sample_time_s": None, "estimated_through_s": None,
                           "estimated_at": None}

    # ------------------------------------------------------------------ feed thread
    def work(self) -> None:
        """The feed thread: rows into the engine's cheap half, segments and publications
        handed to the fit thread (:meth:`_fit_loop`), and the final results when
        :attr:`stop` is set (after data came); :attr:`done` once both threads ended."""
        fitter = threading.Thread(target=self._fit_loop, name="drillfric-live-fit",
                                  daemon=True)
        fitter.start()
        try:
            while not self.stop.is_set():
                if not self._step():
                    self.stop.wait(FEED_POLL_S)
            if self.error is None:
                self.tail.poll(final=True)
                if self.engine is None and self.tail.ready(final=True):
                    self._start()  # a header and a few rows: enough to finish with
                if self.engine is not None:
                    self._feed(self.tail.poll(final=True))
                    self._hand_publication(final=True)
        except BaseException as exc:  # noqa: BLE001 — handed to the caller's thread
            self._fail(exc)
        finally:
            self.jobs.put(None)  # the fit thread ends after what it was handed
            self.fitted.wait()
            self.done.set()

    def _fail(self, exc: BaseException) -> None:
        if self.error is None:
            self.error = exc
        self.stop.set()

    def _step(self) -> bool:
        """One poll; True when rows were fed."""
        end = self.tail.poll()
        if self.engine is None:
            if not self.tail.ready():
                return False
            self._start()
            end = self.tail.poll()
        fed = end > self.tail_fed
        if fed and self._feed(end):
            self._hand_publication()
        elif self.dirty and not self.pending.is_set() and \
                self.clock() - self.published_at > self.open_every_s():
            self._hand_publication()
        return fed

    def open_every_s(self) -> float:
        """Wall seconds between publications of an open segment: :attr:`publish_every_s`,
        longer when one costs more than :data:`OPEN_SHARE` of a core over that time (its
        cost grows with the open segment's rows: each re-estimates it from its first row), but
        at most :data:`MAX_OPEN_WAIT_FACTOR` times :attr:`publish_every_s`."""
        every = self.publish_every_s
        return max(every, min(self.publish_cpu_s / OPEN_SHARE, MAX_OPEN_WAIT_FACTOR * every))

    def _start(self) -> None:
        """Open the well and its engine: continued from OUT/NAME/state when it fits."""
        self.well = self.tail.open(self.path, self.open_kw)
        self.folder = self.out_root / self.well.dir_name
        self.engine, why = _continued(self.well, self.folder)
        if self.engine is None:
            self.engine = Engine(self.well, sink=MemorySink())
            self.engine.resumed = {"from_row": 0, "reason": why}
        self.tail.restart(self.engine.source)
        self.tail_fed, self.published_at, self.dirty = self.tail.end, self.clock(), False
        with self.lock:
            self.view["resumed"] = self.engine.resumed
            self.view["estimated_at"] = self.published_at  # nothing estimated yet

    def _feed(self, end: int) -> bool:
        """Feed the rows read since the engine's source mark up to the tail's (``end``: how
        far it read) to the engine's cheap half; the segments they closed are handed to the
        fit thread (with the hook-load plateaus found up to their close, as a run over the
        whole file estimates them). True when segments closed."""
        closed = False
        if self.engine is None or end <= self.tail_fed:
            return False
        self.well, now = self.tail.well_for(self.well), self.tail.mark()
        for raw in unread(self.well, self.engine.source, now, CHUNK_ROWS):
            done = self.engine.segment_raw(raw)
            self.recent.add(self.engine.last_chunk)
            if done:
                self.jobs.put(("fit", done, list(self.engine.hook.plateaus)))
                closed = True
        self.tail_fed, self.engine.source, self.dirty = end, now, True
        self._note_rows()
        self.fed.set()
        return closed

    def _note_rows(self) -> None:
        engine = self.engine
        last = engine.tracker.state()["last"] if engine.tracker is not None else None
        states = engine.stream.last_states
        with self.lock:
            if self.view["first_sample_time_s"] is None and last is not None:
                # nothing published yet: the estimates are behind from the first sample
                self.view["first_sample_time_s"] = last
            self.view.update(
                last_sample_time_s=last,
                rows=engine.check.rows + (engine.tracker.held_rows if engine.tracker else 0),
                last_sample_utc=utc_at(engine.tracker.origin, last) if last is not None
                else None,
                rig_state=RIG_STATES[int(states[-1])] if states is not None and len(states)
                else self.view["rig_state"])

    def _hand_publication(self, final: bool = False) -> None:
        """Hand the fit thread a publication of the rows fed so far (a copy of the engine's
        cheap half: the fit thread adds its own, consistent once it estimated the segments
        handed before)."""
        snapshot = copy.deepcopy(self.engine.feed_state())
        with self.lock:  # the data time the publication will rest on, and when handed
            through = (self.view["last_sample_time_s"], self.clock())
        self.pending.set()
        self.jobs.put(("final" if final else "publish", snapshot, self.well, through))
        self.published_at, self.dirty = self.clock(), False

    # ------------------------------------------------------------------ fit thread
    def _fit_loop(self) -> None:
        """The fit thread: estimate the segments handed, in order, and publish; of several
        publications waiting, only the newest is made (none is restarted)."""
        try:
            while True:
                jobs = [self.jobs.get()]
                while True:
                    try:
                        jobs.append(self.jobs.get_nowait())
                    except queue.Empty:
                        break
                newest = max((i for i, job in enumerate(jobs) if job and job[0] != "fit"),
                             default=-1)
                for i, job in enumerate(jobs):
                    if job is None:
                        return
                    if self.error is not None:
                        continue
                    if job[0] == "fit":
                        self.engine.estimate(job[1], job[2])
                    elif i == newest:
                        self.pending.clear()
                        self._publish(job[1], job[2], final=job[0] == "final",
                                      through=job[3])
        except BaseException as exc:  # noqa: BLE001 — handed to the caller's thread
            self._fail(exc)
        finally:
            self.fitted.set()

    def _publish(self, feed_state: dict, well: Well, final: bool = False,
                 through: tuple = (None, None)) -> None:
        """Close a copy of the engine (``feed_state`` and the fit thread's half; ``well`` as
        the feed thread read it then; ``through``: its newest sample's log time and the wall
        time it was handed) into OUT/NAME as ``drillfric run`` would (the final results with
        the report)."""
        cpu = time.thread_time()
        state = feed_state | copy.deepcopy(self.engine.fit_state())
        memory = self.engine.sink

        def run(sink: DirectorySink):
            twin = Engine(well, sink=sink, rate_hz=self.engine.rate_hz)
            twin.restore(state)
            twin.resumed = self.engine.resumed
            for key, parts in memory.frames.items():
                for frame in parts:
                    sink.add({key: frame}, twin.estimator.has_truth)
            result = finish_engine(twin, sink)
            self._note_result(result, twin._open_ids, sink.folder)
            return result

        result = deliver(well, self.out_root, run, self.report if final else None)
        self.publish_cpu_s = time.thread_time() - cpu
        with self.lock:  # what live.json's behind_s is reckoned from (data times)
            self.view["estimated_through_s"], self.view["estimated_at"] = through
        if final:
            self.result = result
            with self.lock:  # the end of the data closed every segment
                self.view["open_segment"] = None

    def _note_result(self, result, open_ids: set[int], folder: Path) -> None:
        records = [SegmentRecord.from_json(r) for r in result.summary["segments"]]
        closed = [r for r in records if r.id not in open_ids]
        opened = [r for r in records if r.id in open_ids]
        done = [r for r in closed if r.status is Status.OK and r.converged]
        with self.lock:
            self.view.update(segments_closed=len(closed),
                             open_segment=open_view(opened[-1], folder) if opened else None,
                             latest=None if not done else
                             {"segment": done[-1].id, "mu_k": done[-1].mu_k,
                              "mu_s": done[-1].mu_s, "t_end_s": done[-1].t_end_s},
                             trend_alert=trend_alert(done),
                             closed=None if opened else closed_view(closed[-1] if closed
                                                                    else None),
                             rising=friction_rising(opened[-1:] + [
                                 r for r in closed if r.status is Status.OK][-1:]))

    # ------------------------------------------------------------------ live.json
    def status(self) -> dict:
        """live.json now (docs/live.md)."""
        with self.lock:
            view = dict(self.view)
        idle = self.clock() - self.last_data
        alerts = ended(self.error, self.done.is_set(), view["last_sample_time_s"])
        if self.engine is not None and idle >= self.stopped_s:
            alerts.append(alert("data_stopped", f"no new data for {idle:.0f} s",
                                 view["last_sample_time_s"]))
        elif idle >= self.stale_s:
            alerts.append(alert("data_stale", f"no new data for {idle:.0f} s",
                                 view["last_sample_time_s"]))
        severe = severe_stick_slip(view["open_segment"] or {})
        if severe:
            # the time of the data it rests on, not the newest sample's (a newcomer read a
            # 150-s-old segment's stick-slip as current)
            alerts.append(alert("severe_stick_slip", severe,
                                (view["open_segment"] or {}).get("t_end_s")))
        elif view["closed"] is not None and (severe := severe_stick_slip(
                view["closed"], f"segment {view['closed']['segment']}, closed")):
            # a stand that stick-slipped and closed before any publication of it open
            # (issue 35: on a loaded machine the alert had come after the data ended)
            alerts.append(alert("severe_stick_slip", severe, view["closed"]["t_end_s"]))
        stalled = (view["open_segment"] or {}).get("bit_stalled_s")
        if stalled is not None and stalled >= BIT_STALL_S:
            alerts.append(alert("bit_stalled", f"estimated bit speed at rest for the last "
                                 f"{stalled:.0f} s of the open segment while the top drive "
                                 "turns", (view["open_segment"] or {}).get("t_end_s")))
        if view["trend_alert"] is not None:
            alerts.append(view["trend_alert"])
        if view["rising"] is not None:
            alerts.append(view["rising"])
        newest = view["last_sample_time_s"]
        through = view["estimated_through_s"] if view["estimated_through_s"] is not None \
            else view["first_sample_time_s"]
        lag = behind(newest, through)
        # the alert when publications do not keep their schedule (a loaded machine): the
        # estimates older than two intervals of an open segment's publications
        overdue = view["estimated_at"] is not None and \
            self.clock() - view["estimated_at"] > 2.0 * self.open_every_s()
        if overdue and (late := behind_alert(lag, through)) is not None \
                and not self.done.is_set():
            first = int(bool(alerts) and alerts[0]["kind"] in ("run_failed", "run_ended"))
            alerts.insert(first, late)  # after the run's end, before the rest
        # every value resting on older rows says how old (issue 35: open_segment and the
        # alerts of a segment that had ended read as current)
        alerts = [aged(a, a.get("time_s"), newest) for a in alerts]
        opened = aged(view["open_segment"], (view["open_segment"] or {}).get("t_end_s"),
                      newest)
        latest = aged(view["latest"], (view["latest"] or {}).get("t_end_s"), newest)
        return {"source": str(self.path), "well": None if self.well is None else self.well.name,
                "last_sample_time_s": newest,
                "last_sample_utc": view["last_sample_utc"],
                "estimated_through_s": view["estimated_through_s"], "behind_s": lag,
                "updated_utc": datetime.now(UTC).isoformat(timespec="milliseconds"),
                "rig_state": view["rig_state"], "open_segment": opened,
                "latest": latest, "alerts": alerts, "rows": view["rows"],
                "running": not self.done.is_set(),
                "segments_closed": view["segments_closed"], "resumed": view["resumed"],
                "idle_s": round(idle, 3), "max_update_gap_s": round(self.max_gap_s, 3)}

    def watch(self) -> None:
        """Note whether the source grew (the caller's thread: a busy worker does not make
        the data look idle)."""
        size = self.tail.growth()
        if size != self._size:
            self._size, self.last_data = size, self.clock()

    def write_status(self, target: Path) -> None:
        """live.json written atomically (a temporary file renamed over it)."""
        now = self.clock()
        if self._written is not None:
            self.max_gap_s = max(self.max_gap_s, now - self._written)
        self._written = now
        target.parent.mkdir(parents=True, exist_ok=True)
        with replacing(target) as tmp:
            write_json(tmp, self.status())


def _continued(well: Well, folder: Path) -> tuple[Engine | None, str]:
    """An in-memory engine continuing the state published in ``folder``, or None and why."""
    kind = "parts" if well.source.parts else "csv"

    def same_kind(state: dict) -> str:
        source = state.get("source") or {}
        return "" if source.get("format") == kind else \
            "the earlier run read another kind of file"

    sink = MemorySink()
    engine, why = restored(well, folder / STATE_DIR, lambda: Engine(well, sink=sink),
                           also=same_kind)
    if engine is None:
        return None, why
    _seed(sink, folder, {r.id for r in engine.records})
    engine.resumed = {"from_row": engine.raw_rows, "reason": ""}
    return engine, ""


def _seed(sink: MemorySink, folder: Path, ids: set[int]) -> None:
    """The published output rows of segments ``ids`` into ``sink``, one frame each."""
    estimates = folder / "estimates.parquet"
    if estimates.is_file():
        source = pq.ParquetFile(estimates)
        for i in range(source.num_row_groups):
            frame = source.read_row_group(i).to_pandas()
            if len(frame) and int(frame["segment_id"].iloc[0]) in ids:
                sink.frames["estimates"].append(frame)
    profiles = folder / "profiles.parquet"
    if profiles.is_file():
        frame = pd.read_parquet(profiles)
        sink.frames["profile"] += [p.reset_index(drop=True) for i, p in
                                   frame.groupby("segment_id", sort=True) if i in ids]


def run_live(path: Path, out_root: Path, *, until_idle_s: float | None = None,
             started: Callable[[LiveRun], None] | None = None,
             upstream: Callable[[], BaseException | None] | None = None, **kw) -> LiveRun:
    """Run :class:`LiveRun` (``kw``) until ``until_idle_s`` wall seconds without new data
    (None: until interrupted), writing ``out_root/live.json`` every :data:`POLL_S` from this
    thread while the worker feeds and estimates; ``started`` is given the run before its
    worker starts (the live page serves it); ``upstream`` returns the error that ended
    whatever writes ``path`` (the WITS0 receiver: a full disk), which ends the run.

    Raises
    ------
    InputError
        No data ever arrived, or the file cannot be read as it grows.
    DrillfricError
        ``upstream``'s error, or live.json cannot be written (after the final results were
        attempted).
    KeyboardInterrupt
        Interrupted (Ctrl-C, SIGTERM): the final results were written first.
    """
    warmup.load()  # the kernels loaded now: loading them mid-stream held live.json ~0.5 s
    live = LiveRun(path, out_root, **kw)
    if started is not None:
        started(live)
    worker = threading.Thread(target=live.work, name="drillfric-live", daemon=True)
    worker.start()
    try:
        _tend(live, worker, until_idle_s, upstream or (lambda: None))
    except KeyboardInterrupt:
        live.stop.set()
        _tend(live, worker, None, lambda: None)
        raise
    except DrillfricError:  # live.json cannot be written: the worker ends, then the line
        live.stop.set()
        live.done.wait(STOP_WAIT_S)
        raise
    if live.error is not None:
        raise live.error
    if live.engine is None:
        raise InputError(f"no data arrived in {until_idle_s:g} s", file=live.path,
                         fix="check that the rig logger writes to this file (a header "
                             "line and data rows)")
    return live


def _tend(live: LiveRun, worker: threading.Thread, until_idle_s: float | None,
          upstream: Callable[[], BaseException | None]) -> None:
    """live.json as soon as rows were fed (at most every :data:`MIN_WRITE_S`, at least
    every :data:`POLL_S`) while the worker runs; stop it when idle or when ``upstream``
    failed (its error becomes the run's). (The
    worker's ``done`` event is waited on, not ``Thread.join``: a join interrupted by a signal
    can leave ``is_alive()`` False while the thread still runs, CPython gh-90882.)"""
    while not live.done.is_set():
        live.watch()
        live.fed.clear()
        live.write_status(live.target)
        if until_idle_s is not None and live.clock() - live.last_data >= until_idle_s:
            live.stop.set()
        if (failed := upstream()) is not None:
            live._fail(failed)
        time.sleep(MIN_WRITE_S)  # then at once when rows are fed, at the latest after POLL_S
        live.fed.wait(POLL_S - MIN_WRITE_S)
    worker.join()
    live.write_status(live.target)
