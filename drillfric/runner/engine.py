"""The incremental engine of a time log: rows in, segments estimated as they close, a state
that can be saved and continued (docs/api.md "Feeding a well in chunks", issue 23).

:class:`Engine` is the one code path of every time-log run: ``drillfric run`` feeds it the
whole file, a fleet re-run feeds it only the rows appended since the state it saved, and a
notebook feeds it chunks of a DataFrame. Per chunk (:meth:`Engine.feed`):

1. the log check takes the rows (it raises for a log that cannot be meant as read);
2. the segment stream classifies them into rig states and cuts rotating segments;
3. the per-chunk accumulators — the hook-load plateaus, the time tracks, the pick-ups and
   slack-offs — take the rows and their rig states (and bit depths) (:attr:`Engine.
   accumulators`: each has ``feed``, ``state()`` and ``restore()``);
4. each segment that closed is estimated (:class:`~drillfric.runner.estimator.
   SegmentEstimator`, warm-started) into a record and output rows handed to the sink.

:meth:`Engine.close` ends the data: the open segment is estimated, closed segments are
**revised** where later rows moved the evidence they rest on (the string-weight calibration:
re-estimated; the hook-load check and the pooling along depth: applied again to every
record), the revisions are listed in summary.json ``revisions``, and the run finishes as
every run does (:func:`~drillfric.runner.finish.finish`). The state that :meth:`state`
returns is the one *before* the end of the data (the open segment's rows kept), so a run can
continue after its results were written.
"""

from __future__ import annotations

import copy
import hashlib
import json
import time
from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path

import numpy as np
import pandas as pd

from drillfric._version import __version__
from drillfric.config import STRING_ASSUMED
from drillfric.drag import MoveFinder, drag_log
from drillfric.errors import InputError
from drillfric.estimation.bit_torque import assess as assess_bit_torque
from drillfric.estimation.consensus import pool_short_segments
from drillfric.hookload import PlateauFinder, StringWeightCalibration, judge
from drillfric.io.logcheck import LogCheck
from drillfric.io.text import plural
from drillfric.io.tracks import TrackAccumulator
from drillfric.io.well import Well, frame_source
from drillfric.result import RunProgress, SegmentRecord, WellResult
from drillfric.segmentation import Segment, SegmentStream
from drillfric.torque_drag import TDSettings
from drillfric.torque_zero import TorqueAtRest, withhold_offset, zero_check
from drillfric.vocabulary import Kind, Status

from .estimator import SegmentEstimator, first_chunk
from .finish import MemorySink, Sink, finish, summarise
from .segment_output import FLOW_MISSING_NOTE, MOTOR_NOTE, iso
from .state import read_state, write_state

#: Relative change of the string-weight scale beyond which a segment estimated with the
#: earlier scale is re-estimated (μ scales about as 1/W: 0.1 % in μ at most otherwise).
REVISE_SCALE = 1e-3


#: The channels that tell on bottom from off bottom (docs/segmentation.md).
BOTTOM_CHANNELS = frozenset({"bit_depth_m", "block_position_m", "wob_N"})
BOTTOM_UNKNOWN = ("on or off bottom: the log has no bit-depth, block-position or WOB "
                  "channel, so every rotation counts as off bottom — drilling would put its "
                  "bit torque into μ_k")


class Engine:
    """A time-log run that takes its rows in chunks and can be saved and continued.

    Parameters
    ----------
    well : Well
        The opened well (:func:`drillfric.io.well.open_well`, from a file or ``frame=``).
    rate_hz : float, optional
        Resample each segment to this rate (not above the data's own).
    sink : MemorySink or DirectorySink, optional
        Where output rows go (default: kept in memory).
    progress : callable, optional
        Called with a :class:`~drillfric.result.RunProgress` per chunk and segment.
    total_rows : int, optional
        Rows expected (for progress only).

    Examples
    --------
    >>> engine = Engine(well)                                   # doctest: +SKIP
    >>> for part in chunks: engine.feed(part)                   # doctest: +SKIP
    >>> engine.result().summary["mu_k"]                         # doctest: +SKIP
    """

    def __init__(self, well: Well, *, rate_hz: float | None = None, sink: Sink | None = None,
                 progress: Callable[[RunProgress], None] | None = None,
                 total_rows: int | None = None):
        if well.depth_indexed:
            raise InputError("a depth-indexed log is no time series to feed in chunks",
                             file=well.files.data, fix="run it with drillfric run")
        cfg = well.config
        self.well, self.rate_hz, self.sink = well, rate_hz, sink or MemorySink()
        self.progress, self.total_rows = progress, total_rows
        self.t_wall = time.perf_counter()
        self.tracker = well.time_tracker()
        self.check, self.hook = LogCheck(well), PlateauFinder(cfg)
        self.tracks = TrackAccumulator()
        self.moves = MoveFinder(cfg)  # pick-ups and slack-offs (docs/theory.md §2.2)
        #: Per-chunk accumulators, fed after the log check and the segment stream with the
        #: rows' rig states (and bit depths) in :meth:`feed_raw`; ``state()``/``restore(state)``.
        self.rest = TorqueAtRest(cfg)  # the torque channel's zero (drillfric.torque_zero)
        self.accumulators = {"hook": self.hook, "tracks": self.tracks, "moves": self.moves,
                             "rest": self.rest}
        self.stream = SegmentStream(cfg)
        self.estimator = SegmentEstimator(well)
        self.calibration = StringWeightCalibration(well) \
            if cfg.hookload.calibrate_string_weight else None
        self.raw_rows = 0  # source rows fed (before the time check drops any)
        self.records: list[SegmentRecord] = []  # as estimated: before the hook-load check
        self.warnings: list[str] = []
        self.published: dict = {}  # id → what the last results said (revisions are against it)
        self.revisions: list[dict] = []
        self._kept: dict[int, tuple] = {}  # id → (segment, rows, scale, warm set), calibrated
        self._open_ids: set[int] = set()  # segments the end of the data closed
        #: What was read of the data file (:func:`drillfric.runner.resume.csv_mark`).
        self.source: dict | None = None
        #: summary.json ``resumed``: where this run continued from, or why it did not.
        self.resumed: dict | None = None
        self._before_close: dict | None = None
        #: The canonical rows of the last raw chunk fed (SI; ``drillfric live``'s page).
        self.last_chunk: pd.DataFrame | None = None

    # ------------------------------------------------------------------ rows in
    def feed(self, frame: pd.DataFrame) -> list[SegmentRecord]:
        """Take the next rows of the well (columns as the well's data: the file's or the
        DataFrame's it was opened with); return the records of the segments they closed.

        Raises
        ------
        InputError
            Rows that cannot be meant as read (time going backwards, a log read in the
            wrong unit, …: docs/ingestion.md).
        """
        expected = list(self.well.source.columns) if self.well.source is not None else []
        if missing := [c for c in expected if c not in frame.columns]:
            raise InputError(  # a raw KeyError had named only the canonical channel
                f"the rows fed lack {plural(len(missing), 'column')} of the well's data: "
                + ", ".join(repr(c) for c in missing[:5]), fix="feed rows with the columns "
                "the well was opened with (Engine.feed, docs/api.md)")
        out = []
        for raw in frame_source(frame).chunks(max(len(frame), 1)):
            out += self.feed_raw(raw)
        return out

    def feed_raw(self, raw: pd.DataFrame) -> list[SegmentRecord]:
        """:meth:`feed` for a raw chunk of the well's own source (labels already text)."""
        return self.estimate(self.segment_raw(raw))

    def segment_raw(self, raw: pd.DataFrame) -> list[tuple[Segment, pd.DataFrame]]:
        """The cheap half of :meth:`feed_raw` (steps 1–3): the rows checked, classified and
        accumulated; returns the segments they closed, with their rows, to be handed to
        :meth:`estimate` in order (``drillfric live`` estimates them in another thread:
        this half touches only :meth:`feed_state`, that one only :meth:`fit_state`)."""
        self.raw_rows += len(raw)
        return self._segment(self.well.canonical(raw, self.tracker))

    def _segment(self, chunk: pd.DataFrame) -> list[tuple[Segment, pd.DataFrame]]:
        """Steps 1–3 of :meth:`feed_raw` for canonical rows (time settled)."""
        self.last_chunk = chunk
        if self.check.rows == 0 and len(chunk):
            self.estimator.rate_hz = first_chunk(self.well, chunk, self.rate_hz, self.warnings)
            self.estimator.has_truth = "bit_rpm" in chunk
            if not BOTTOM_CHANNELS & set(chunk.columns):
                self.estimator.assumed.append(BOTTOM_UNKNOWN)
        self.check.feed(chunk)
        done = self.stream.feed(chunk)
        states = self.stream.last_states
        self.hook.feed(chunk, states)
        self.rest.feed(chunk, states)
        self.tracks.feed(chunk, states)
        self.moves.feed(chunk, states, self.stream.last_bit_depth_m)
        return done

    def estimate(self, done: list[tuple[Segment, pd.DataFrame]],
                 plateaus: list | None = None) -> list[SegmentRecord]:
        """Step 4 of :meth:`feed_raw`: estimate the segments :meth:`segment_raw` closed;
        ``plateaus`` are the hook-load plateaus found up to their close (default: now)."""
        records = self._take(done, plateaus)
        self._report()
        return records

    def _take(self, done: list[tuple[Segment, pd.DataFrame]],
              plateaus: list | None = None) -> list[SegmentRecord]:
        """Estimate closed segments (with the calibration the rows so far support)."""
        scale = None
        if self.calibration is not None and done:
            self.calibration.add(done)
            self.estimator.well, calib = self.calibration.current(
                self.hook.plateaus if plateaus is None else plateaus)
            scale = calib.scale
        out = []
        for seg, rows in done:
            record, frames = self.estimator.segment(seg, rows)
            self.records.append(record)
            out.append(record)
            self.sink.add(frames, self.estimator.has_truth)
            if self.calibration is not None and seg.status == Status.OK:
                self._kept[seg.id] = (seg, rows, scale, self._warm_set(record))
            self._report(seg.i_end)
        return out

    def _warm_set(self, record: SegmentRecord):
        """The warm start a segment passed on (None: it passed on the one it got)."""
        return self.estimator.warm if record.status is Status.OK and record.converged \
            and record.kind == Kind.OFF_BOTTOM else None

    def _report(self, row: int | None = None) -> None:
        if self.progress:
            self.progress(RunProgress(self.check.rows if row is None else row,
                                      self.total_rows, len(self.records)))

    # ------------------------------------------------------------------ results out
    def result(self) -> WellResult:
        """The results of the rows fed so far, in memory; the engine keeps its state and
        can be fed further (closed segments as revised)."""
        try:
            result = self.close()
        finally:
            if self._before_close is not None:
                self.restore(self.saved_state() | {"sink": None})
                self.sink.drop(self._open_ids)
                self._before_close = None  # fed further, the engine's state is its own
        return result

    def close(self, tail=()) -> WellResult:
        """End of the data: the open segment, revisions, the summary and the result files
        (with a directory sink). :meth:`state` afterwards is the state before the end (to be
        saved and continued).

        ``tail``: raw chunks that end the data but not the state — a last line of a CSV
        still being written (docs/fleet.md "Only what is new"): its rows count in these
        results and are read again, complete, by the run that continues."""
        tail = list(tail)
        # the tail and the rows the time base held back move the accumulators on: the state
        # before them, copied (not views of them)
        self._before_close = copy.deepcopy(self.state()) if tail else \
            copy.deepcopy(self.feed_state()) | self.fit_state() if self.tracker.holding \
            else self.state()
        ended = {r.id for raw in tail for r in self.feed_raw(raw)}
        held = self.tracker.flush()
        if held is not None and len(held):
            ended |= {r.id for r in self.estimate(self._segment(held))}
        done = self.stream.close()
        open_ids = {seg.id for seg, _ in done} | ended
        self._take(done)
        self.tracker.check_conflicts(self.check.rows)
        if self.check.rows == 0:
            raise InputError("no data rows", file=self.well.files.data,
                             fix="check that the file holds samples below its header")
        self.check.finish(self.tracker.duplicates)
        self.check.time_unit_check(self.records)
        warnings = self.warnings + [w for w in (
            self.tracker.conflicts_note(self.check.rows),
            self.check.duplicates_note(self.tracker.duplicates),
            self.check.nothing_found(len(self.records)), self.check.hole_above_note(),
            _cut_line_note(self.well, tail),
            _motor_note(self.records), _flow_missing_note(self.records)) if w] \
            + self.check.unit_hints(self.records)
        plateaus = self.hook.close()
        calibration = None
        if self.calibration is not None:
            well, calibration = self.calibration.current(plateaus)
            self._revise(well, calibration.scale)
        weighed = judge(self.records, plateaus, self.well.config, calibration)
        zero = zero_check(self.rest, weighed.summary["block_weight_N"], weighed.records)
        records, pools = pool_short_segments(withhold_offset(weighed.records, zero))
        cfg = self.well.config
        records, friction_log = assess_bit_torque(
            records, pools, cfg.well.bit_diameter_m,
            None if cfg.bha.motor_rev_per_litre is None else cfg.bha.motor_speed_drop)
        self._note_revisions(records)
        summary = summarise(self.well, records, pools, rows=self.check.rows,
                            assumed=self.well.assumed + self.estimator.assumed,
                            warnings=warnings + weighed.warnings + zero.warnings(),
                            wall_s=time.perf_counter() - self.t_wall,
                            profile=self.estimator.settings.friction,
                            resampled_rate_hz=self.estimator.rate_hz,
                            requested_rate_hz=self.rate_hz,
                            duplicates_dropped=self.tracker.duplicates,
                            conflicts_dropped=self.tracker.conflicts)
        summary.update(hookload=weighed.summary, torque_zero=zero.summary(),
                       mu_k_reason=weighed.mu_k_reason(summary["mu_k"])
                       or zero.mu_k_reason(summary["mu_k"]),
                       off_bottom_friction_log=friction_log,
                       time_origin_utc=iso(self.tracker.origin), revisions=self.revisions,
                       resumed=self.resumed)
        summary["drag"], drag_table = drag_log(
            self.moves.close(), self.moves.too_short, TDSettings.from_config(self.well.config),
            self.well.survey, weighed.summary,
            string_assumed=any(n.startswith(STRING_ASSUMED) for n in self.well.assumed))
        self.published = {r.id: _published(r) for r in records}
        self._open_ids = open_ids
        return finish(self.sink, self.well, summary, records, tracks=self.tracks.result(),
                      tables={"drag_log.parquet": drag_table})

    def _revise(self, well: Well, scale: float | None) -> None:
        """Re-estimate, in order, the segments estimated with a string-weight scale other
        than ``scale`` (warm starts chained as in a run over the whole file)."""
        warm = None
        for i, record in enumerate(self.records):
            kept = self._kept.get(record.id)
            if kept is not None and _moved(kept[2], scale):
                seg, rows, used, _ = kept
                self.estimator.well, self.estimator.warm = well, warm
                new, frames = self.estimator.segment(seg, rows)
                self.sink.replace(record.id, frames, self.estimator.has_truth)
                self.records[i] = new
                self._kept[record.id] = (seg, rows, scale, self._warm_set(new))
                self.revisions.append(_revision(record, new, "string-weight calibration "
                                                f"moved: scale {_show(used)} → {_show(scale)}"))
            if kept is not None and self._kept[record.id][3] is not None:
                warm = self._kept[record.id][3]
        self.estimator.well = well
        self.estimator.warm = warm if self._kept else self.estimator.warm

    def _note_revisions(self, records: list[SegmentRecord]) -> None:
        """Record the segments whose published numbers changed since the last results
        (segments the end of the earlier rows closed: :attr:`_open_ids` of that close)."""
        calibrated = {r["segment"] for r in self.revisions}
        was_open = self._open_ids
        for r in records:
            old = self.published.get(r.id)
            if old is None or old == _published(r) or r.id in calibrated:
                continue
            why = ("the segment was still open at the end of the earlier rows" if r.id in
                   was_open else "later segments changed the hook-load check or the pooling "
                                 "along depth it rests on")
            self.revisions.append({"segment": r.id, "reason": why, "before": old,
                                   "after": _published(r)})

    # ------------------------------------------------------------------ state
    def state(self) -> dict:
        """Everything that continues the run (plain values, arrays, DataFrames: the format of
        :func:`~drillfric.runner.state.write_state`)."""
        return self.feed_state() | self.fit_state()

    def feed_state(self) -> dict:
        """The part of :meth:`state` that :meth:`segment_raw` changes."""
        return {"drillfric_version": __version__, "config": self.well.config.to_dict(),
                "survey": survey_key(self.well),
                "rate_hz": self.rate_hz, "raw_rows": self.raw_rows, "source": self.source,
                "tracker": self.tracker.state(), "stream": self.stream.state(),
                "check": self.check.state(),
                "accumulators": {k: a.state() for k, a in self.accumulators.items()},
                "warnings": list(self.warnings)}

    def fit_state(self) -> dict:
        """The part of :meth:`state` that :meth:`estimate` changes."""
        return {"estimator": self.estimator.state(),
                "calibration": None if self.calibration is None else self.calibration.state(),
                "sink": self.sink.state() if isinstance(self.sink, MemorySink) else None,
                **self._records_state()}

    def _records_state(self, leave: frozenset = frozenset()) -> dict:
        """The records and the rows kept for revisions, but those of segments ``leave``."""
        kept = [(i, seg, rows, scale, warm) for i, (seg, rows, scale, warm)
                in self._kept.items() if i not in leave]
        return {"records": [r.to_json() for r in self.records if r.id not in leave],
                "published": {str(k): v for k, v in self.published.items()},
                "open_ids": sorted(self._open_ids),
                "kept": [{"segment": asdict(seg), "scale": scale,
                          "warm": None if warm is None else list(warm)}
                         for _, seg, _, scale, warm in kept],
                "kept_rows": pd.concat([rows.assign(segment_id=i) for i, _, rows, _, _ in kept],
                                       ignore_index=True) if kept else None}

    def restore(self, state: dict) -> None:
        """Continue from a :meth:`state` (of this well, this configuration)."""
        self.raw_rows, self.source = int(state["raw_rows"]), state.get("source")
        self.tracker.restore(state["tracker"])
        self.stream.restore(state["stream"])
        self.check.restore(state["check"])
        for key, acc in self.accumulators.items():
            acc.restore(state["accumulators"][key])
        self.estimator.restore(state["estimator"])
        self.warnings = list(state["warnings"])
        if self.calibration is not None:
            self.calibration.restore(state["calibration"])
        if isinstance(self.sink, MemorySink) and state.get("sink") is not None:
            self.sink.restore(state["sink"])
        self.records = [SegmentRecord.from_json(r) for r in state["records"]]
        self.published = {int(k): v for k, v in state["published"].items()}
        self._open_ids = set(state["open_ids"])
        self.revisions = []
        rows = state["kept_rows"]
        self._kept = {}
        for entry in state["kept"]:
            seg = Segment(**entry["segment"])
            mine = rows[rows["segment_id"] == seg.id].drop(columns="segment_id")
            self._kept[seg.id] = (seg, mine.reset_index(drop=True), entry["scale"],
                                  None if entry["warm"] is None else tuple(entry["warm"]))
        if self.calibration is not None and self.records:
            self.estimator.well, _ = self.calibration.current(self.hook.plateaus)

    def saved_state(self) -> dict:
        """The state to save after :meth:`close`: the rows before the end of the data, the
        closed segments as revised (and the warm start their revision passes on)."""
        state = self._before_close | self._records_state(frozenset(self._open_ids))
        chain = [kept[3] for i, kept in sorted(self._kept.items())
                 if i not in self._open_ids and kept[3] is not None]
        if chain:
            state["estimator"] = state["estimator"] | {"warm": [float(v) for v in chain[-1]]}
        return state

    def save(self, folder: Path) -> None:
        """Write :meth:`saved_state` (after :meth:`close`) or :meth:`state` into ``folder``."""
        write_state(Path(folder), self.state() if self._before_close is None
                    else self.saved_state())

    @classmethod
    def load(cls, folder: Path, well: Well, **kw) -> Engine:
        """An engine continuing from the state saved in ``folder`` (see :meth:`save`).

        Raises
        ------
        InputError
            No readable state there, or one of another drillfric version or configuration.
        """
        state = read_state(Path(folder))
        why = mismatch(state, well, kw.get("rate_hz"))
        if why:
            raise InputError(f"engine state does not continue this well: {why}",
                             file=Path(folder), fix="run the well from its start")
        engine = cls(well, **kw)
        try:
            engine.restore(state)
        except (KeyError, TypeError, ValueError, IndexError, AttributeError) as exc:
            raise InputError(f"engine state not readable ({type(exc).__name__}: {exc})",
                             file=Path(folder), fix="run the well from its start") from exc
        return engine


def mismatch(state: dict, well: Well, rate_hz: float | None) -> str:
    """Why ``state`` cannot continue ``well`` ("" when it can): another drillfric version,
    configuration, well path or rate."""
    if state.get("drillfric_version") != __version__:
        return f"saved by drillfric {state.get('drillfric_version')}, this is {__version__}"
    if _plain(state.get("config")) != _plain(well.config.to_dict()):
        return "the effective configuration changed"
    if state.get("survey") != survey_key(well):
        return "the survey changed"
    if state.get("rate_hz") != rate_hz:
        return f"the rate changed ({state.get('rate_hz')} → {rate_hz} Hz)"
    return ""


def survey_key(well: Well) -> str | None:
    """A digest of the well path's stations (None without a survey): the configuration
    names the survey file, not what it holds, and a survey edited, extended or first given
    between two runs had left every saved segment's numbers from the old path (μ_k 0.2785
    where the new survey gives 0.2031; issue 30, twelfth attack)."""
    path = well.survey
    if path is None:
        return None
    stations = np.concatenate([np.asarray(a, dtype=np.float64) for a in
                               (path.md_m, path.inc_rad, path.azi_rad)])
    return hashlib.sha256(stations.tobytes()).hexdigest()


def _plain(value):
    """A configuration as JSON would give it back (tuples as lists)."""
    return json.loads(json.dumps(value, default=str))


def _moved(used: float | None, scale: float | None) -> bool:
    if used is None or scale is None:
        return (used is None) != (scale is None)
    return abs(used / scale - 1.0) > REVISE_SCALE


def _show(scale: float | None) -> str:
    return "none" if scale is None else f"{scale:.4f}"


def _published(record: SegmentRecord) -> dict:
    """The numbers of a segment a revision is judged on."""
    return {"status": record.status.value, "mu_k": record.mu_k, "mu_s": record.mu_s,
            "mu_s_lower_bound": record.mu_s_lower_bound, "converged": record.converged,
            "t_end_s": record.t_end_s}


def _revision(old: SegmentRecord, new: SegmentRecord, why: str) -> dict:
    return {"segment": new.id, "reason": why, "before": _published(old),
            "after": _published(new)}


def _motor_note(records: list[SegmentRecord]) -> str | None:
    """The well's warning, once, where bit speeds were shown with the pumps on (issue 34
    item 5: a mud motor's speed is not in them), or None."""
    return _segments_note([r.id for r in records if r.bit_speed_reason == MOTOR_NOTE],
                          MOTOR_NOTE)


def _flow_missing_note(records: list[SegmentRecord]) -> str | None:
    """The well's warning, once, where a declared motor's flow is missing (its bit speed is
    withheld there), or None."""
    return _segments_note([r.id for r in records if FLOW_MISSING_NOTE in (r.message or "")],
                          f"{FLOW_MISSING_NOTE} (a mud motor is declared, [bha] "
                          "motor_rev_per_litre: map the flow-in channel)")


def _segments_note(ids: list[int], text: str) -> str | None:
    """``text`` once for the segments ``ids`` (the first ten named), or None without any."""
    if not ids:
        return None
    return (f"{plural(len(ids), 'segment')} ({', '.join(map(str, ids[:10]))}"
            f"{', …' if len(ids) > 10 else ''}): {text}")


def _cut_line_note(well: Well, tail: list) -> str:
    """The warning of a text log whose last line has no line end (cut, or still being
    written): its row is read as it stands (issue 35 item 16: a truncated CSV in a fleet
    was "ok" without a word)."""
    if not any(len(chunk) for chunk in tail):
        return ""
    return (f"{well.files.data.name}: its last line has no line end (the file was cut, or is "
            "still being written): that row is read as it stands, and read again by a later "
            "run when complete")
