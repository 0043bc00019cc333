"""``drillfric run``: one well, stand by stand, as a short list of named steps.

:func:`run_well` takes a well opened once (:func:`drillfric.io.well.open_well`) and

1. **streams** its surface data in chunks, checking the log as it goes
   (:class:`~drillfric.io.logcheck.LogCheck`), and cuts it into rotating segments with their
   rows (:class:`~drillfric.segmentation.SegmentStream`);
2. **estimates** each segment with the chain of :mod:`drillfric.estimation.chain` (torque and
   drag at its depth, observer starts, batch fit, verdict, seeded ensemble), warm-starting
   from the previous segment;
3. **collects** each segment's :class:`~drillfric.result.SegmentRecord` and output rows into
   a sink — in memory, or appended to the result files as it goes (bounded memory);
4. **summarises** the well (consensus, counts, what was assumed) and writes the results of
   docs/outputs.md atomically into ``OUT/NAME`` (:class:`~drillfric.io.results.
   ResultDirectory`), then the report.

Library code: no printing; progress goes through a callback.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import pandas as pd

from drillfric import __version__
from drillfric.errors import DrillfricError, InputError
from drillfric.estimation.chain import (
    SegmentData,
    SegmentEstimate,
    SkipSegment,
    check_segment,
    estimate_segment,
)
from drillfric.estimation.observer import ObserverRecord
from drillfric.friction import FrictionProfile
from drillfric.hookload import PlateauFinder, calibrate, judge
from drillfric.io.logcheck import LogCheck
from drillfric.io.results import (
    EstimatesWriter,
    ResultDirectory,
    file_sha256,
    write_json,
    write_segments,
)
from drillfric.io.timebase import check_plausible_rate, nominal_rate_hz
from drillfric.io.tracks import TrackAccumulator, write_tracks
from drillfric.io.well import CHUNK_ROWS, Well
from drillfric.result import (
    ESTIMATE_NAMES,
    SEEDED_START_ID,
    Flag,
    Kind,
    SegmentRecord,
    Status,
    segment_columns,
)
from drillfric.segmentation import Segment, SegmentStream
from drillfric.units import RPM_TO_RAD_S

#: Bit depth assumed when neither the log, the config nor a survey gives one [m].
DEFAULT_BIT_DEPTH_M = 2500.0
#: Relative margin by which a requested rate may exceed the data's nominal rate (timing
#: jitter) before it counts as upsampling.
RATE_MARGIN = 0.01
#: Flags a short segment may carry and still be pooled (it is only too short).
_POOLABLE = frozenset({"too_short_to_converge", "observer_not_converged",
                       "estimators_disagree"})


@dataclass(frozen=True)
class RunProgress:
    """Where a run stands (for a progress bar with an ETA).

    Attributes
    ----------
    rows_done : int
        Input rows read and, up to the last finished segment, estimated.
    rows_total : int or None
        Rows of the input when known cheaply (Parquet metadata, a CSV line count).
    segments_done : int
    """

    rows_done: int
    rows_total: int | None
    segments_done: int

    @property
    def fraction(self) -> float | None:
        """Share of the input done [-], None when the size is not known."""
        if not self.rows_total:
            return None
        return min(self.rows_done / self.rows_total, 1.0)


@dataclass
class WellResult:
    """What a run of one well produced (the API's return value; the CLI prints from it).

    Attributes
    ----------
    well : str
        The well's name.
    summary : dict
        summary.json (docs/outputs.md).
    segments : pandas.DataFrame
        One row per segment (:class:`~drillfric.result.SegmentRecord` fields).
    out_dir : Path or None
        ``OUT/NAME`` when results were written, else None.
    failed : int
        Segments whose estimation failed.
    warnings : list of str
        What the user should know (also ``summary["warnings"]``).
    tracks : pandas.DataFrame or None
        The whole log decimated for plotting (tracks.parquet).
    """

    well: str
    summary: dict
    segments: pd.DataFrame
    out_dir: Path | None = None
    failed: int = 0
    warnings: list = field(default_factory=list)
    tracks: pd.DataFrame | None = field(default=None, repr=False)
    _estimates: pd.DataFrame | None = field(default=None, repr=False)

    @property
    def estimates(self) -> pd.DataFrame:
        """estimates.parquet's rows (read from ``out_dir`` when the run wrote them)."""
        if self._estimates is None and self.out_dir is not None:
            self._estimates = pd.read_parquet(self.out_dir / "estimates.parquet")
        return self._estimates if self._estimates is not None else pd.DataFrame(
            columns=list(ESTIMATE_NAMES))

    @property
    def report(self) -> Path | None:
        """report.html when it was written."""
        path = None if self.out_dir is None else self.out_dir / "report.html"
        return path if path is not None and path.is_file() else None


def run_well(well: Well, out_root=None, *, rate_hz: float | None = None, pdf: bool = False,
             report: bool = True, progress: Callable[[RunProgress], None] | None = None,
             chunk_rows: int = CHUNK_ROWS) -> WellResult:
    """Run the whole estimation on one well; write ``out_root/NAME`` when ``out_root`` is given.

    Parameters
    ----------
    well : Well
        An opened well (:func:`drillfric.io.well.open_well`).
    out_root : str or Path, optional
        Output directory; results go to ``out_root/NAME`` atomically. None: results in
        memory only (nothing written).
    rate_hz : float, optional
        Resample the input to this rate before estimation; a rate above the data's own is
        not used (:func:`effective_rate`: a warning in ``summary["warnings"]``).
    pdf, report : bool
        Also write report.pdf; write report.html at all (only with ``out_root``).
    progress : callable, optional
        Called with a :class:`RunProgress` as rows are read and segments finish.
    chunk_rows : int
        Rows read per chunk.

    Raises
    ------
    DrillfricError
        Unreadable or meaningless input, or results that cannot be written (nothing is
        written then).
    """
    if well.depth_indexed:  # no time series: a static friction log by depth
        from drillfric.friction_log import run_depth_log

        return run_depth_log(well, out_root, rate_hz=rate_hz, pdf=pdf, report=report,
                             progress=progress, chunk_rows=chunk_rows)
    t_wall = time.perf_counter()
    if out_root is None:
        return _run(well, _MemorySink(), rate_hz, progress, chunk_rows, t_wall)
    with ResultDirectory(out_root, well.dir_name, well.name) as tmp:
        result = _run(well, _DirectorySink(tmp), rate_hz, progress, chunk_rows, t_wall)
        if report:
            write_report(tmp, pdf, result)
    result.out_dir = Path(out_root) / well.dir_name
    return result


def _run(well: Well, sink, rate_hz, progress, chunk_rows, t_wall) -> WellResult:
    """Steps 1–4 into ``sink``."""
    well, calibration = calibrate(well, chunk_rows)  # hook-load evidence (docs/theory.md §2.1)
    hook = PlateauFinder(well.config)
    estimator = _SegmentEstimator(well)
    check = LogCheck(well)
    tracker = well.time_tracker()
    total = _count_rows(well.files.data)
    stream = SegmentStream(well.config)
    tracks = TrackAccumulator()
    records: list[SegmentRecord] = []
    warnings: list[str] = []

    def take(done: list[tuple[Segment, pd.DataFrame]]) -> None:
        for seg, rows in done:
            record, frames = estimator.segment(seg, rows)
            records.append(record)
            sink.add(record, frames, estimator.has_truth)
            if progress:
                progress(RunProgress(seg.i_end, total, len(records)))

    for chunk in well.chunks(chunk_rows, tracker):
        if check.rows == 0 and len(chunk):
            estimator.rate_hz = _first_chunk(well, chunk, rate_hz, warnings)
            estimator.has_truth = "bit_rpm" in chunk
        check.feed(chunk)
        hook.feed(chunk)
        take(stream.feed(chunk))
        tracks.feed(chunk, stream.last_states)
        if progress:
            progress(RunProgress(check.rows, total, len(records)))
    take(stream.close())
    if check.rows == 0:
        raise InputError("no data rows", file=well.files.data,
                         fix="check that the file holds samples below its header")
    check.finish(tracker.duplicates)
    warnings += [w for w in (check.nothing_found(len(records)),) if w]
    weighed = judge(records, hook.close(), well.config, calibration)
    warnings += weighed.warnings
    records, pools = pool_short_segments(weighed.records)
    summary = summarise(well, records, pools, estimator, check.rows, rate_hz, warnings,
                        time.perf_counter() - t_wall)
    summary.update(hookload=weighed.summary, mu_k_reason=weighed.mu_k_reason(summary["mu_k"]))
    summary["time_origin_utc"] = _iso(tracker.origin)
    track_frame = tracks.result()
    sink.finish(well, summary, records, track_frame)
    return WellResult(well.name, summary, pd.DataFrame(segment_columns(records)),
                      failed=estimator.failed, warnings=summary["warnings"],
                      tracks=track_frame, _estimates=sink.estimates())


def _iso(stamp) -> str | None:
    """ISO 8601 UTC text of a timestamp (None when the log has no clock time)."""
    if stamp is None or pd.isna(stamp):
        return None
    stamp = pd.Timestamp(stamp)
    stamp = stamp.tz_localize("UTC") if stamp.tzinfo is None else stamp.tz_convert("UTC")
    return stamp.isoformat()


def _first_chunk(well: Well, chunk: pd.DataFrame, rate_hz, warnings: list) -> float | None:
    """Checks of the first chunk; the rate the estimation resamples to."""
    check_plausible_rate(chunk["time_s"].to_numpy(), file=well.files.data)
    rate_used, note = effective_rate(rate_hz, chunk["time_s"].to_numpy())
    warnings += [note] * bool(note)
    return rate_used


# --------------------------------------------------------------------------- step 2
class _SegmentEstimator:
    """Step 2 for every segment of a well, carrying what passes from one to the next (the
    warm start, the fallback bit depth, the count of failures)."""

    def __init__(self, well: Well):
        self.well = well
        self.rate_hz: float | None = None
        self.has_truth = False
        self.warm: tuple | None = None
        self.failed = 0
        self.fallback_depth: float | None = None
        self.assumed: list[str] = []

    def segment(self, seg: Segment, rows: pd.DataFrame) -> tuple[SegmentRecord, dict | None]:
        """The record and output rows (estimates, profile) of one segment."""
        depth = self._depth(seg)
        if seg.status != "ok":
            return _record(seg, depth, Status.SKIPPED, seg.message, rows), None
        data = _segment_data(rows, seg, depth)
        cfg = self.well.config
        try:
            check_segment(data, cfg)
            est = estimate_segment(cfg, self.well.survey, data, warm=self.warm,
                                   rate_hz=self.rate_hz,
                                   torque_channel=self.well.channels["surface_torque_Nm"])
        except SkipSegment as exc:
            return _record(seg, depth, Status.SKIPPED, exc.problem, rows), None
        except DrillfricError as exc:
            self.failed += 1
            return _record(seg, depth, Status.FAILED, exc.message, rows), None
        if est.converged and seg.kind == Kind.OFF_BOTTOM:
            self.warm = (est.mu_s_seed, est.mu_k)
        frames = {"estimates": _with_clock(_estimate_frame(seg.id, est, data,
                                                           cfg.omega_c_rad_s), rows),
                  "profile": _profile_frame(seg.id, est)}
        return _record(seg, depth, Status.OK, seg.message, rows, est), frames

    def _depth(self, seg: Segment) -> float:
        if np.isfinite(seg.bit_depth_m):
            return seg.bit_depth_m
        if self.fallback_depth is None:
            self.fallback_depth = _bit_depth_default(self.well, self.assumed)
        return self.fallback_depth


def _bit_depth_default(well: Well, assumed: list) -> float:
    """Bit depth [m] of segments the log gives none for: ``[well] bit_depth_m``, else a
    simulated well's ``[simulate] bit_depth_m``, else (announced in ``assumed``) the
    survey's last station or :data:`DEFAULT_BIT_DEPTH_M`."""
    cfg, survey = well.config, well.survey
    for given in (cfg.well.bit_depth_m, cfg.simulate.bit_depth_m):
        if given is not None:
            return given
    if survey is not None:
        assumed.append(f"bit depth {survey.md_max_m:.0f} m (the survey's last station): the "
                       "log has no bit depth")
        return survey.md_max_m
    assumed.append(f"bit depth {DEFAULT_BIT_DEPTH_M:.0f} m: neither the log nor a survey "
                   "gives one")
    return DEFAULT_BIT_DEPTH_M


def effective_rate(rate_hz: float | None, time_s: np.ndarray) -> tuple[float | None, str | None]:
    """The rate to resample to [Hz] and, when it differs from ``rate_hz``, why.

    A requested rate above the data's nominal rate would only interpolate between logged
    samples (upsampling invents nothing the observer could use, and costs time): the data
    are then estimated at their own rate (None) and a warning says so.

    Parameters
    ----------
    rate_hz : float or None
        Requested rate (``run --rate``) [Hz].
    time_s : ndarray
        Sample times of (the start of) the log [s].

    Examples
    --------
    >>> effective_rate(5.0, np.arange(10.0))[0] is None
    True
    >>> effective_rate(0.5, np.arange(10.0))
    (0.5, None)
    """
    data_rate = nominal_rate_hz(time_s)
    if rate_hz is None or data_rate <= 0 or rate_hz <= data_rate * (1.0 + RATE_MARGIN):
        return rate_hz, None
    return None, (f"requested rate {rate_hz:g} Hz is above the data's logging rate "
                  f"({data_rate:.3g} Hz): estimated at the data's rate, not upsampled")


def _segment_data(rows: pd.DataFrame, seg: Segment, depth: float) -> SegmentData:
    """The estimator's samples: rows with both speed and torque (the few nulls a segment
    may hold are bridged when the measurements are put on a uniform grid)."""
    rows = rows[np.isfinite(rows["surface_rpm"].to_numpy(float))
                & np.isfinite(rows["surface_torque_Nm"].to_numpy(float))]
    wob = float(np.nanmedian(rows["wob_N"])) if "wob_N" in rows and \
        rows["wob_N"].notna().any() else 0.0
    def column(name):
        return rows[name].to_numpy(float) if name in rows else None

    return SegmentData(rows["time_s"].to_numpy(float), rows["surface_rpm"].to_numpy(float),
                       rows["surface_torque_Nm"].to_numpy(float), float(depth), kind=seg.kind,
                       wob_N=max(wob, 0.0), bit_rpm=column("bit_rpm"),
                       torque_min_Nm=column("surface_torque_min_Nm"),
                       torque_max_Nm=column("surface_torque_max_Nm"))


# --------------------------------------------------------------------------- step 3
def _record(seg: Segment, depth: float, status: Status, message: str, rows: pd.DataFrame,
            est: SegmentEstimate | None = None) -> SegmentRecord:
    """A segment's :class:`SegmentRecord` (the estimate's numbers when there is one)."""
    base = dict(id=seg.id, kind=Kind(seg.kind), t_start_s=seg.t_start_s, t_end_s=seg.t_end_s,
                bit_depth_m=depth, status=status, duration_s=seg.duration_s, message=message,
                hookload_N=_median(rows, "hookload_N"), **_clock(rows, seg))
    if est is None:
        return SegmentRecord(**base)
    return SegmentRecord(**base | dict(
        message="; ".join([message] * bool(message) + list(est.messages)),
        mu_s=est.mu_s, mu_k=est.mu_k, mu_s_identifiable=est.mu_s_identifiable,
        mu_s_lower_bound=est.mu_s_lower_bound, mu_s_spread=est.mu_s_spread,
        mu_k_spread=est.mu_k_spread, converged=est.converged, method=est.method,
        settling_time_s=est.settling_time_s, residual_rms_rpm=est.residual_rms_rpm,
        mu_k_observer=est.mu_k_observer, mu_s_observer=est.mu_s_observer, mu_td=est.mu_td,
        T_N_Nm=est.T_N_Nm, flags=est.flags, starts=tuple(map(tuple, est.starts.tolist())),
        friction_zone=est.friction_zone, hookload_model_N=est.td.hookload_N,
        **_evidence_fields(est), **_bit_fields(est)))


def _evidence_fields(est: SegmentEstimate) -> dict:
    ev = est.evidence
    return dict(torque_rms_misfit_Nm=ev.misfit_rms_Nm, torque_swing_Nm=ev.swing_Nm,
                fit_quality=ev.quality, surface_torque_mean_Nm=ev.mean_Nm)


def _bit_fields(est: SegmentEstimate) -> dict:
    """The bit-speed statistics, or null with the reason where the trace is withheld (the
    stuck fraction and severity stay where only the kinematic check withheld it)."""
    logged = dict(sample_interval_s=est.logged.interval_s,
                  interval_torque_swing=est.logged.torque_swing)
    if not est.bit_speed.resolved:
        kept = dict(stick_slip_severity=est.stick_slip_severity,
                    stuck_fraction=est.stuck_fraction) if est.bit_statistics else {}
        return logged | kept | dict(bit_speed_resolved=False,
                                    bit_speed_reason=est.bit_speed.reason)
    return logged | dict(bit_speed_resolved=True, stick_slip_severity=est.stick_slip_severity,
                         stuck_fraction=est.stuck_fraction,
                         bit_rms_error_rpm=est.bit_rms_error_rpm)


def _median(rows: pd.DataFrame, column: str) -> float | None:
    if column not in rows or not rows[column].notna().any():
        return None
    return float(np.nanmedian(rows[column].to_numpy(float)))


def _origin(rows: pd.DataFrame) -> pd.Timestamp | None:
    """Clock time (UTC) of ``time_s = 0`` from a segment's rows, None without absolute time."""
    if "timestamp" not in rows or rows.empty:
        return None
    first = pd.to_datetime(rows["timestamp"].iloc[:1], utc=True).iloc[0]
    return first - pd.to_timedelta(float(rows["time_s"].iloc[0]), unit="s")


def _clock(rows: pd.DataFrame, seg: Segment) -> dict:
    """Clock times of the segment's ends when the log has absolute time."""
    origin = _origin(rows)
    if origin is None:
        return {}
    return {"clock_start_utc": _iso(origin + pd.to_timedelta(seg.t_start_s, unit="s")),
            "clock_end_utc": _iso(origin + pd.to_timedelta(seg.t_end_s, unit="s"))}


def _with_clock(frame: pd.DataFrame, rows: pd.DataFrame) -> pd.DataFrame:
    """estimates rows with their clock time (``timestamp``, UTC) beside ``time_s`` when the
    log has absolute time."""
    origin = _origin(rows)
    if origin is not None:
        frame.insert(1, "timestamp", origin + pd.to_timedelta(frame["time_s"], unit="s"))
    return frame


def _estimate_frame(seg_id: int, est: SegmentEstimate, data: SegmentData,
                    omega_c: float) -> pd.DataFrame:
    """estimates.parquet rows of one segment: every start (``start_id`` 0…), then the pass
    seeded with the batch-refined factors (``start_id`` = :data:`SEEDED_START_ID`): its
    ensemble as one start (``est.bit``: weighted means, the bit stuck where stuck members
    carry most of the weight) with the members' min–max bit speed as
    ``bit_rpm_est_min/max`` (NaN on the starts' rows). Where the logging does not resolve
    the stick-slip cycle the bit columns are null: no trace is drawn from such data.
    """
    first = _record_frame(seg_id, est.first, 0, data,
                          np.abs(est.first.bha_rad_s_est) <= omega_c, est)
    seeded = _record_frame(seg_id, est.bit.record(est.final), SEEDED_START_ID, data,
                           est.bit.stuck(est.final, omega_c), est)
    seeded["bit_rpm_est_min"] = (est.bit.low_rad_s / RPM_TO_RAD_S).astype(np.float32)
    seeded["bit_rpm_est_max"] = (est.bit.high_rad_s / RPM_TO_RAD_S).astype(np.float32)
    frame = pd.concat([first, seeded], ignore_index=True)
    if not est.bit_speed.resolved:
        frame[["bit_rpm_est", "bit_rpm_est_min", "bit_rpm_est_max"]] = np.nan
        frame["bit_stuck"] = pd.array([None] * len(frame), dtype="boolean")
    return frame


def _record_frame(seg_id: int, rec: ObserverRecord, offset: int, data: SegmentData,
                  stuck: np.ndarray, est: SegmentEstimate) -> pd.DataFrame:
    """Rows of one observer record, one per time and start (``start_id`` from ``offset``);
    ``stuck`` is the bit-stuck flag per time and start (R, S) or per time (R,)."""
    n_t, n_s = rec.mu_k.shape
    ev = est.evidence
    at = lambda t, y: np.repeat(np.interp(rec.time_s, t, y), n_s)  # noqa: E731
    cols = {
        "time_s": np.repeat(rec.time_s, n_s),
        "segment_id": np.full(n_t * n_s, seg_id, dtype=np.int32),
        "start_id": np.tile(np.arange(n_s, dtype=np.int16) + offset, n_t),
        "mu_s": rec.mu_s.ravel(), "mu_k": rec.mu_k.ravel(),
        "surface_rpm": at(data.time_s, data.surface_rpm),
        "surface_rpm_est": rec.surface_rad_s_est.ravel() / RPM_TO_RAD_S,
        "bit_rpm_est": rec.bit_rad_s_est.ravel() / RPM_TO_RAD_S,
        "bit_stuck": np.asarray(stuck, dtype=bool).ravel(),
        "residual_rpm": rec.residual_rad_s.ravel() / RPM_TO_RAD_S,
        "surface_torque_Nm": at(ev.time_s, ev.measured_Nm),
        "surface_torque_est_Nm": rec.surface_torque_est_Nm.ravel(),
        "surface_torque_fit_Nm": at(ev.time_s, ev.model_Nm),
        "bit_rpm_est_min": np.full(n_t * n_s, np.nan, dtype=np.float32),
        "bit_rpm_est_max": np.full(n_t * n_s, np.nan, dtype=np.float32)}
    if data.bit_rpm is not None:
        cols["bit_rpm"] = at(data.time_s, data.bit_rpm)
    return pd.DataFrame(cols)


def _profile_frame(seg_id: int, est: SegmentEstimate, step_m: float = 10.0) -> pd.DataFrame:
    """Torque-and-drag profile of a segment every ~``step_m`` (profiles.parquet)."""
    td = est.td
    keep = np.unique(np.r_[np.arange(0, td.md_m.size - 1, max(1, int(step_m // max(
        np.diff(td.md_m).mean(), 1e-9)))), td.md_m.size - 2])
    return pd.DataFrame({"segment_id": np.int32(seg_id), "md_m": td.md_m[keep],
                         "inc_deg": np.degrees(td.inc_rad[keep]),
                         "tension_N": td.tension_N[keep], "torque_Nm": td.torque_Nm[keep],
                         "normal_force_N_m": td.normal_force_N_m[keep],
                         "fc_Nm_m": td.fc_Nm_m[keep]})


class _MemorySink:
    """Collects a run's output rows in memory (the Python API without ``out``)."""

    def __init__(self):
        self.frames: dict[str, list] = {"estimates": [], "profile": []}

    def add(self, record: SegmentRecord, frames: dict | None, with_truth: bool) -> None:
        for key, frame in (frames or {}).items():
            self.frames[key].append(frame)

    def finish(self, well: Well, summary: dict, records, tracks: pd.DataFrame) -> None:
        """Nothing to write."""

    def estimates(self) -> pd.DataFrame | None:
        parts = self.frames["estimates"]
        return pd.concat(parts, ignore_index=True) if parts else None


class _DirectorySink:
    """Appends a run's output rows to the result files as segments finish (bounded memory)."""

    def __init__(self, folder: Path):
        self.folder = folder
        self.writer: EstimatesWriter | None = None
        self.profiles: list[pd.DataFrame] = []

    def add(self, record: SegmentRecord, frames: dict | None, with_truth: bool) -> None:
        if frames is None:
            return
        if self.writer is None:
            self.writer = EstimatesWriter(self.folder / "estimates.parquet", with_truth,
                                          "timestamp" in frames["estimates"])
        self.writer.write(frames["estimates"])
        self.profiles.append(frames["profile"])

    def finish(self, well: Well, summary: dict, records, tracks: pd.DataFrame) -> None:
        """Write every result file but the report."""
        if self.writer is None:
            self.writer = EstimatesWriter(self.folder / "estimates.parquet", False)
        self.writer.close()
        write_json(self.folder / "summary.json", summary)
        write_segments(self.folder / "segments.parquet", records)
        write_tracks(self.folder / "tracks.parquet", tracks)
        if self.profiles:
            pd.concat(self.profiles, ignore_index=True).to_parquet(
                self.folder / "profiles.parquet", index=False)
        if well.survey is not None:
            pd.DataFrame(well.survey.at(well.survey.md_m)).to_parquet(
                self.folder / "wellpath.parquet", index=False)

    def estimates(self) -> None:
        return None  # read back from the file when asked (WellResult.estimates)


# --------------------------------------------------------------------------- step 4
#: Short segments pool when their bit depths are within this [m] (one stand's depth)...
POOL_DEPTH_M = 5.0
#: ...their μ_k agree within this (max/min − 1) [-]...
POOL_AGREEMENT = 0.05
#: ...and together they hold at least this much rotation [s] (the converged minimum).
POOL_MIN_ROTATION_S = 90.0


def pool_short_segments(records: list[SegmentRecord]) -> tuple[list, list[dict]]:
    """Pool short off-bottom segments at one bit depth whose μ_k agree into one estimate.

    Segments too short to converge alone (only ``too_short_to_converge`` keeps them from
    it) at one depth (within :data:`POOL_DEPTH_M`), whose batch μ_k agree within
    :data:`POOL_AGREEMENT` and which together rotate for :data:`POOL_MIN_ROTATION_S`, give a
    converged estimate: the rotation-weighted mean μ_k. Returns the records (members flagged
    ``pooled``) and the pools (summary.json ``pooled``).
    """

    short = [r for r in records if r.status is Status.OK and r.kind is Kind.OFF_BOTTOM
             and not r.converged and r.method.value == "batch" and r.mu_k is not None
             and set(r.flags) <= _POOLABLE]
    groups: list[list[SegmentRecord]] = []
    for r in sorted(short, key=lambda r: r.bit_depth_m):
        if groups and r.bit_depth_m - groups[-1][0].bit_depth_m <= POOL_DEPTH_M:
            groups[-1].append(r)
        else:
            groups.append([r])
    pools, members = [], {}
    for group in groups:
        mu = np.array([r.mu_k for r in group])
        weight = np.array([r.duration_s for r in group])
        if len(group) < 2 or weight.sum() < POOL_MIN_ROTATION_S or \
                mu.max() / mu.min() - 1.0 > POOL_AGREEMENT:
            continue
        pool = {"segment_ids": [r.id for r in group],
                "bit_depth_m": float(np.median([r.bit_depth_m for r in group])),
                "mu_k": float(np.sum(mu * weight) / weight.sum()),
                "mu_k_spread": float(mu.max() - mu.min()), "rotation_s": float(weight.sum())}
        pools.append(pool)
        members |= {r.id: pool for r in group}
    return [_pooled(r, members[r.id]) if r.id in members else r for r in records], pools


def _pooled(record: SegmentRecord, pool: dict) -> SegmentRecord:
    note = (f"pooled with segments {', '.join(map(str, pool['segment_ids']))} at "
            f"{pool['bit_depth_m']:.0f} m: μ_k = {pool['mu_k']:.3f} over "
            f"{pool['rotation_s']:.0f} s of rotation")
    return replace(record, flags=record.flags + (Flag.POOLED,),
                   message="; ".join(filter(None, [record.message, note])))


def consensus(records: list[SegmentRecord], pools: list[dict] = ()) -> dict:
    """Well-level friction factors from the segments (never a made-up value).

    Only converged, off-bottom segments with status ok count, and pools of short segments
    (:func:`pool_short_segments`) as one each. μ_k: their median; μ_s: the median over those
    that identify it; otherwise the median of their lower bounds (each is claimed valid, so
    the median is too, and one unreliable segment cannot set it).
    """
    ok = [r for r in records if r.status is Status.OK and r.kind is Kind.OFF_BOTTOM
          and r.converged]
    mu_k = [r.mu_k for r in ok if r.mu_k is not None] + [p["mu_k"] for p in pools]
    mu_s = [r.mu_s for r in ok if r.mu_s_identifiable and r.mu_s is not None]
    bounds = [r.mu_s_lower_bound for r in ok if r.mu_s_lower_bound is not None]
    return {"mu_k": float(np.median(mu_k)) if mu_k else None,
            "mu_s": float(np.median(mu_s)) if mu_s else None,
            "mu_s_lower_bound": None if mu_s or not bounds else float(np.median(bounds))}


def summarise(well: Well, records: list[SegmentRecord], pools: list[dict],
              estimator: _SegmentEstimator, n_rows: int, rate_hz, warnings: list,
              wall_s: float) -> dict:
    """summary.json (docs/outputs.md)."""
    inputs = {k: {"path": str(Path(p).resolve()), "sha256": file_sha256(p)}
              for k, p in well.files.inputs.items() if Path(p).is_file()}
    inputs.update(rows=n_rows, resampled_rate_hz=estimator.rate_hz, requested_rate_hz=rate_hz)
    assumed = well.assumed + estimator.assumed
    count = {s: sum(r.status is s for r in records) for s in Status}
    profile = FrictionProfile.from_config(well.config)
    return {"well": well.name, "drillfric_version": __version__, **consensus(records, pools),
            "friction_zone": profile.zone, "friction_profile": profile.describe(),
            "pooled": pools, "segments": [r.to_json() for r in records], "inputs": inputs,
            "config": well.config.to_dict(), "assumed": assumed, "indicative": bool(assumed),
            "counts": {"segments": len(records), "estimated": count[Status.OK],
                       "converged": sum(r.status is Status.OK and r.converged
                                        for r in records),
                       "skipped": count[Status.SKIPPED], "failed": count[Status.FAILED]},
            "run_time_s": wall_s, "warnings": list(warnings)}


def write_report(result_dir: Path, pdf: bool, result: WellResult) -> None:
    """Write the report; a failure to render is a warning, not a lost run (the results
    stand), and leaves no partial report file; a failure to write (disk) fails the run."""
    from drillfric.report import write_well_report

    try:
        write_well_report(result_dir, pdf=pdf)
    except OSError:
        raise
    except Exception as exc:  # noqa: BLE001 — the estimates are written; say what failed
        for partial in result_dir.glob("report.*"):
            partial.unlink(missing_ok=True)
        result.warnings.append(f"report not written: {type(exc).__name__}: {exc}")
        write_json(result_dir / "summary.json", result.summary)


def _count_rows(data_path: Path) -> int | None:
    """Row count for the progress bar: Parquet metadata, else a fast line count."""
    suffix = data_path.suffix.lower()
    try:
        if suffix in (".parquet", ".pq"):
            import pyarrow.parquet as pq

            return pq.ParquetFile(data_path).metadata.num_rows
        if suffix in (".csv", ".txt", ".tsv"):
            count = 0
            with open(data_path, "rb") as fh:
                while block := fh.read(1 << 22):
                    count += block.count(b"\n") or block.count(b"\r")
            return count
    except OSError:
        return None
    return None

