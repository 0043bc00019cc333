"""A time log, stand by stand, as a short list of named steps.

:func:`run_time_log` takes a well opened once (:func:`drillfric.io.well.open_well`) and

1. **streams** its surface data in chunks, checking the log as it goes
   (:class:`~drillfric.io.logcheck.LogCheck`), and cuts it into rotating segments with their
   rows (:class:`~drillfric.segmentation.SegmentStream`);
2. **estimates** each segment with the chain of :mod:`drillfric.estimation.chain` (torque and
   drag at its depth, observer starts, batch fit, verdict, seeded ensemble), warm-starting
   from the previous segment (:class:`SegmentEstimator`);
3. **collects** each segment's record and output rows
   (:mod:`drillfric.runner.segment_output`) into a sink — in memory, or appended to the
   result files as it goes (bounded memory);
4. **pools** short segments and **finishes** as every run does
   (:mod:`drillfric.runner.finish`): the summary, the result files of docs/outputs.md
   written atomically into ``OUT/NAME``, then the report.

Library code: no printing; progress goes through a callback.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd

from drillfric.drag import MoveFinder, drag_log
from drillfric.errors import DrillfricError, InputError
from drillfric.estimation.bit_torque import assess as assess_bit_torque
from drillfric.estimation.chain import SegmentData, SkipSegment, check_segment, estimate_segment
from drillfric.estimation.consensus import pool_short_segments
from drillfric.hookload import PlateauFinder, calibrate, judge
from drillfric.io.logcheck import LogCheck
from drillfric.io.timebase import check_plausible_rate, nominal_rate_hz
from drillfric.io.tracks import TrackAccumulator
from drillfric.io.well import CHUNK_ROWS, Well
from drillfric.result import Kind, RunProgress, SegmentRecord, Status, WellResult
from drillfric.segmentation import Segment, SegmentStream

from .finish import ReportWriter, Sink, deliver, finish, summarise
from .segment_output import iso, output_frames, segment_record

#: Bit depth assumed when neither the log, the config nor a survey gives one [m].
DEFAULT_BIT_DEPTH_M = 2500.0
#: Relative margin by which a requested rate may exceed the data's nominal rate (timing
#: jitter) before it counts as upsampling.
RATE_MARGIN = 0.01


def run_time_log(well: Well, out_root=None, *, rate_hz: float | None = None,
                 report: ReportWriter | None = None,
                 progress: Callable[[RunProgress], None] | None = None,
                 chunk_rows: int = CHUNK_ROWS) -> WellResult:
    """:func:`drillfric.runner.run_well` for a time log: steps 1–4 of the module's list,
    into memory or ``out_root/NAME`` (parameters as there)."""
    t_wall = time.perf_counter()
    return deliver(well, out_root, lambda sink: _stream(well, sink, rate_hz, progress,
                                                        chunk_rows, t_wall), report)


def _stream(well: Well, sink: Sink, rate_hz, progress, chunk_rows, t_wall) -> WellResult:
    """Steps 1–4 into ``sink``."""
    well, calibration = calibrate(well, chunk_rows)  # hook-load evidence (docs/theory.md §2.1)
    hook = PlateauFinder(well.config)
    moves = MoveFinder(well.config)  # pick-ups and slack-offs (docs/theory.md §2.2)
    estimator = SegmentEstimator(well)
    check = LogCheck(well)
    tracker = well.time_tracker()
    total = well.source.rows if well.source.rows is not None else _count_rows(well.files.data)
    stream = SegmentStream(well.config)
    tracks = TrackAccumulator()
    records: list[SegmentRecord] = []
    warnings: list[str] = []

    def take(done: list[tuple[Segment, pd.DataFrame]]) -> None:
        for seg, rows in done:
            record, frames = estimator.segment(seg, rows)
            records.append(record)
            sink.add(frames, estimator.has_truth)
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
        moves.feed(chunk, stream.last_states, stream.last_bit_depth_m)
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
    records, friction_log = assess_bit_torque(records, pools, well.config.well.bit_diameter_m)
    summary = summarise(well, records, pools, rows=check.rows,
                        assumed=well.assumed + estimator.assumed, warnings=warnings,
                        wall_s=time.perf_counter() - t_wall,
                        resampled_rate_hz=estimator.rate_hz, requested_rate_hz=rate_hz)
    summary.update(hookload=weighed.summary, mu_k_reason=weighed.mu_k_reason(summary["mu_k"]),
                   off_bottom_friction_log=friction_log)
    summary["drag"], drag_table = drag_log(moves.close(), moves.too_short, well.config,
                                           well.survey, weighed.summary)
    summary["time_origin_utc"] = iso(tracker.origin)
    return finish(sink, well, summary, records, tracks=tracks.result(),
                  tables={"drag_log.parquet": drag_table})


def _first_chunk(well: Well, chunk: pd.DataFrame, rate_hz, warnings: list) -> float | None:
    """Checks of the first chunk; the rate the estimation resamples to."""
    check_plausible_rate(chunk["time_s"].to_numpy(), file=well.files.data)
    rate_used, note = effective_rate(rate_hz, chunk["time_s"].to_numpy())
    warnings += [note] * bool(note)
    return rate_used


# --------------------------------------------------------------------------- step 2
class SegmentEstimator:
    """Step 2 for every segment of a well, carrying what passes from one to the next (the
    warm start, the fallback bit depth and what was assumed for it)."""

    def __init__(self, well: Well):
        self.well = well
        self.rate_hz: float | None = None
        self.has_truth = False
        self.warm: tuple | None = None
        self.fallback_depth: float | None = None
        self.assumed: list[str] = []

    def segment(self, seg: Segment, rows: pd.DataFrame) -> tuple[SegmentRecord, dict]:
        """The record and output rows (estimates, profile; none when not estimated) of one
        segment."""
        depth = self._depth(seg)
        if seg.status != "ok":
            return segment_record(seg, depth, Status.SKIPPED, seg.message, rows), {}
        data = _segment_data(rows, seg, depth)
        cfg = self.well.config
        try:
            check_segment(data, cfg)
            est = estimate_segment(cfg, self.well.survey, data, warm=self.warm,
                                   rate_hz=self.rate_hz,
                                   torque_channel=self.well.channels["surface_torque_Nm"])
        except SkipSegment as exc:
            return segment_record(seg, depth, Status.SKIPPED, exc.problem, rows), {}
        except DrillfricError as exc:
            return segment_record(seg, depth, Status.FAILED, exc.message, rows), {}
        if est.converged and seg.kind == Kind.OFF_BOTTOM:
            self.warm = (est.mu_s_seed, est.mu_k)
        return (segment_record(seg, depth, Status.OK, seg.message, rows, est),
                output_frames(seg, est, data, rows, cfg.omega_c_rad_s))

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
