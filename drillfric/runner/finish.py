"""What every run of a well ends with, time log or depth log: the summary, the result files
and the report.

A run hands its output rows to a sink as segments finish — kept in memory
(:class:`MemorySink`, the Python API without ``out``) or appended to the result files
(:class:`DirectorySink`, bounded memory) — and ends with :func:`finish`: the files of
docs/outputs.md and the :class:`~drillfric.result.WellResult`. :func:`deliver` opens the
result directory (written atomically, :class:`~drillfric.io.results.ResultDirectory`) around
a run and writes the report into it before it is committed.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq

from drillfric._version import __version__
from drillfric.config import torque_lag_s
from drillfric.errors import OutputError
from drillfric.estimation.consensus import consensus
from drillfric.estimation.headline import judge as judge_headline
from drillfric.friction import FrictionProfile
from drillfric.io.atomic import replacing
from drillfric.io.results import (
    EstimatesWriter,
    ResultDirectory,
    file_sha256,
    write_json,
    write_segments,
)
from drillfric.io.tracks import write_tracks
from drillfric.io.well import Well
from drillfric.result import SEEDED_START_ID, Flag, SegmentRecord, WellResult, segments_frame
from drillfric.vocabulary import Status

#: Flags of the well-wide checks that withhold a segment's friction factors after its rows
#: were written (the string weight, the torque zero: docs/theory.md §2.1): its μ_k(t) rows
#: (the seeded pass's ``mu_k``, ``mu_k_half_width``) are withheld with them.
WELL_WITHHELD = (Flag.HOOKLOAD_CONTRADICTS_STRING, Flag.STRING_WEIGHT_UNVERIFIED,
                 Flag.TORQUE_ZERO_OFFSET)


def withheld_ids(records: list[SegmentRecord]) -> set[int]:
    """Ids of the segments whose friction factors a well-wide check withheld
    (:data:`WELL_WITHHELD`)."""
    return {r.id for r in records if any(f in WELL_WITHHELD for f in r.quality_flags)}


def without_mu_k(frame: pd.DataFrame, ids: set[int]) -> pd.DataFrame:
    """``frame`` (estimates rows) with the seeded rows' μ_k(t) and half-width null in the
    segments ``ids`` (a copy; ``frame`` itself when none is there)."""
    gone = frame["segment_id"].isin(list(ids)).to_numpy() & \
        (frame["start_id"].to_numpy() == SEEDED_START_ID)
    if not gone.any():
        return frame
    out = frame.copy()
    out.loc[gone, ["mu_k", "mu_k_half_width"]] = float("nan")
    return out

#: Writes the report of a result directory into it (``drillfric.report.write_well_report``
#: with the options asked for); the run layer calls it and never imports the report.
ReportWriter = Callable[[Path], None]


def summarise(well: Well, records: list[SegmentRecord], pools: list[dict], *, rows: int,
              assumed: list[str], warnings: list[str], wall_s: float,
              profile: FrictionProfile,
              resampled_rate_hz: float | None = None,
              requested_rate_hz: float | None = None,
              duplicates_dropped: int = 0, conflicts_dropped: int = 0) -> dict:
    """summary.json (docs/outputs.md) from what a run found.

    Parameters
    ----------
    well : Well
        The well run (name, input files, configuration).
    records, pools : list
        The segments' records and the pools of short segments
        (:func:`drillfric.estimation.consensus.pool_short_segments`).
    rows : int
        Input rows read.
    assumed, warnings : list of str
        What was assumed (makes the numbers indicative) and what the user should know.
    wall_s : float
        Run time [s].
    profile : FrictionProfile
        The well's friction zones and law (the estimation's own, built once per well).
    resampled_rate_hz, requested_rate_hz : float, optional
        The rate the estimation resampled to and the rate asked for [Hz].
    duplicates_dropped, conflicts_dropped : int
        Rows dropped for repeating an earlier row's time and values, and for repeating a
        time with other values (the time base's counts, docs/ingestion.md "EDR defects").
    """
    inputs = {k: {"path": str(Path(p).resolve()), "sha256": file_sha256(p)}
              for k, p in well.files.inputs.items() if Path(p).is_file()}
    inputs.update(rows=rows, duplicates_dropped=duplicates_dropped,
                  conflicts_dropped=conflicts_dropped, resampled_rate_hz=resampled_rate_hz,
                  requested_rate_hz=requested_rate_hz,
                  channel_skew=channel_skew(torque_lag_s(well.config.channels), records))
    count = {s: sum(r.status is s for r in records) for s in Status}
    return {"well": well.name, "drillfric_version": __version__, **consensus(records, pools),
            "friction_zone": profile.zone, "friction_profile": profile.describe(),
            "pooled": pools, "segments": [r.to_json() for r in records], "inputs": inputs,
            "config": well.config.to_dict(), "assumed": list(assumed),
            "indicative": bool(assumed),
            "counts": {"segments": len(records), "estimated": count[Status.OK],
                       "converged": sum(r.status is Status.OK and r.converged
                                        for r in records),
                       "skipped": count[Status.SKIPPED], "failed": count[Status.FAILED]},
            "run_time_s": wall_s, "warnings": list(warnings)}


#: How a segment's message states an unidentified skew (drillfric.estimation.skew).
_UNIDENTIFIED = "channel skew not identified"


def channel_skew(configured_s: float | None, records: list[SegmentRecord]) -> dict:
    """summary.json ``inputs.channel_skew``: the torque's lag behind the speed [s] the well
    was estimated with (docs/bit_speed.md, Channel skew).

    The configured lag, else the inverse-variance mean of the segments' identified lags
    (its ± the larger of the mean's 95 % half-width and the lags' spread), else "not
    identified" with the segments' first reason.

    Examples
    --------
    >>> channel_skew(0.8, [])["source"], channel_skew(None, [])["source"]
    ('config', 'not identified')
    """
    if configured_s is not None:
        return {"lag_s": configured_s, "uncertainty_s": 0.0, "source": "config",
                "segments_identified": 0}
    found = [(r.torque_lag_s, r.torque_lag_uncertainty_s) for r in records
             if r.torque_lag_source == "identified"]
    if not found:
        why = next((part[part.index(_UNIDENTIFIED):] for r in records
                    for part in (r.message or "").split("; ") if _UNIDENTIFIED in part),
                   "channel skew not identified: no segment's set-point steps, "
                   "start-ups or stops time it")
        return {"lag_s": None, "uncertainty_s": None, "source": "not identified",
                "segments_identified": 0, "reason": why}
    lags, half = (np.array(v, dtype=float) for v in zip(*found, strict=True))
    weights = 1.0 / np.maximum(half, 1e-3) ** 2
    mean = float(np.sum(weights * lags) / weights.sum())
    spread = float(lags.max() - lags.min()) / 2.0
    return {"lag_s": mean, "uncertainty_s": max(float(1.0 / np.sqrt(weights.sum())), spread),
            "source": "identified", "segments_identified": len(found)}


class MemorySink:
    """Collects a run's output rows in memory (the Python API without ``out``)."""

    def __init__(self):
        self.frames: dict[str, list] = {"estimates": [], "profile": []}
        self.withheld: set[int] = set()  # segments whose μ_k(t) rows are withheld

    def add(self, frames: dict[str, pd.DataFrame], with_truth: bool) -> None:
        """Keep a segment's output rows (``estimates``, ``profile``; either may be absent)."""
        for key, frame in frames.items():
            self.frames[key].append(frame)

    def replace(self, seg_id: int, frames: dict[str, pd.DataFrame], with_truth: bool) -> None:
        """A revised segment's output rows instead of those it had."""
        for key, parts in self.frames.items():
            kept = [f for f in parts if not (len(f) and f["segment_id"].iloc[0] == seg_id)]
            self.frames[key] = sorted(kept + [frames[key]] * (key in frames),
                                      key=lambda f: int(f["segment_id"].iloc[0]) if len(f) else 0)

    def drop(self, ids: set[int]) -> None:
        """Forget the rows of segments ``ids``."""
        self.frames = {key: [f for f in parts if not (len(f) and
                                                      int(f["segment_id"].iloc[0]) in ids)]
                       for key, parts in self.frames.items()}

    def state(self) -> dict:
        """The rows held, one table each (an engine state's)."""
        return {key: pd.concat(parts, ignore_index=True) if parts else None
                for key, parts in self.frames.items()}

    def restore(self, state: dict) -> None:
        """Hold the rows of a :meth:`state`, one table per segment."""
        self.frames = {key: [] if frame is None else
                       [part for _, part in frame.groupby("segment_id", sort=True)]
                       for key, frame in state.items()}

    def finish(self, well: Well, summary: dict, records, tracks, tables) -> None:
        """Nothing to write; the rows of segments a well-wide check withheld are given
        without their μ_k(t) (:func:`withheld_ids`; the rows held keep it: a later
        publication may judge otherwise)."""
        self.withheld = withheld_ids(records)

    def estimates(self) -> pd.DataFrame | None:
        """The estimates rows of the run, None when there are none."""
        parts = self.frames["estimates"]
        return without_mu_k(pd.concat(parts, ignore_index=True), self.withheld) if parts \
            else None


class DirectorySink:
    """Appends a run's output rows to the result files of ``folder`` as segments finish
    (bounded memory)."""

    def __init__(self, folder: Path):
        self.folder = folder
        self.writer: EstimatesWriter | None = None
        self.profiles: list[pd.DataFrame] = []
        self.revised: dict[int, pd.DataFrame | None] = {}  # segment id → its new estimates

    def add(self, frames: dict[str, pd.DataFrame], with_truth: bool) -> None:
        """Append a segment's output rows (``estimates``, ``profile``; either may be absent)."""
        if "estimates" in frames:
            self._writer(with_truth, "timestamp" in frames["estimates"]).write(
                frames["estimates"])
        if "profile" in frames:
            self.profiles.append(frames["profile"])

    def replace(self, seg_id: int, frames: dict[str, pd.DataFrame], with_truth: bool) -> None:
        """A revised segment's output rows instead of those it had (estimates.parquet is
        rewritten when the run finishes)."""
        self.profiles = [p for p in self.profiles if p["segment_id"].iloc[0] != seg_id] + (
            [frames["profile"]] if "profile" in frames else [])
        self.profiles.sort(key=lambda p: int(p["segment_id"].iloc[0]))
        if "estimates" in frames:
            self._writer(with_truth, "timestamp" in frames["estimates"])
        self.revised[seg_id] = frames.get("estimates")

    def seed(self, previous: Path, ids: set[int]) -> None:
        """Start with the output rows of segments ``ids`` from an earlier result directory
        ``previous`` (a resumed run: docs/fleet.md "Only what is new")."""
        estimates = previous / "estimates.parquet"
        if estimates.is_file():
            source = pq.ParquetFile(estimates)
            names = source.schema_arrow.names
            for i in range(source.num_row_groups):
                table = source.read_row_group(i)
                if table.num_rows and int(table["segment_id"][0].as_py()) in ids:
                    self._writer("bit_rpm" in names, "timestamp" in names).write_table(table)
        profiles = previous / "profiles.parquet"
        if profiles.is_file():
            frame = pd.read_parquet(profiles)
            self.profiles += [p for i, p in frame.groupby("segment_id", sort=True) if i in ids]

    def _writer(self, with_truth: bool, with_clock: bool) -> EstimatesWriter:
        if self.writer is None:
            self.writer = EstimatesWriter(self.folder / "estimates.parquet", with_truth,
                                          with_clock)
        return self.writer

    def finish(self, well: Well, summary: dict, records, tracks: pd.DataFrame | None,
               tables: dict[str, pd.DataFrame]) -> None:
        """Write every result file but the report: ``tables`` are extra Parquet files by
        name (a depth log's friction_log.parquet)."""
        if self.writer is None:  # no time series: an estimates.parquet without rows
            self.writer = EstimatesWriter(self.folder / "estimates.parquet", False)
        self.writer.close()
        withheld = withheld_ids(records)
        if self.revised or withheld:
            self._rewrite(withheld)
        write_json(self.folder / "summary.json", summary)
        write_segments(self.folder / "segments.parquet", records)
        if tracks is not None:
            write_tracks(self.folder / "tracks.parquet", tracks)
        if self.profiles:
            pd.concat(self.profiles, ignore_index=True).to_parquet(
                self.folder / "profiles.parquet", index=False)
        if well.survey is not None:
            pd.DataFrame(well.survey.at(well.survey.md_m)).to_parquet(
                self.folder / "wellpath.parquet", index=False)
        for name, table in tables.items():
            table.to_parquet(self.folder / name, index=False)

    def estimates(self) -> None:
        """None: read back from the file when asked (:attr:`WellResult.estimates`)."""
        return None

    def _rewrite(self, withheld: set[int]) -> None:
        """estimates.parquet with each revised segment's rows in place of its old ones (one
        row group per segment, in segment order), and the μ_k(t) rows of the segments a
        well-wide check withheld (``withheld``) null (:func:`without_mu_k`)."""
        path = self.folder / "estimates.parquet"
        old = pq.ParquetFile(path)
        with replacing(path) as fresh:
            writer = EstimatesWriter(fresh, "bit_rpm" in old.schema_arrow.names,
                                     "timestamp" in old.schema_arrow.names)
            pending = sorted((i, f) for i, f in self.revised.items() if f is not None)
            for g in range(old.num_row_groups):
                table = old.read_row_group(g)
                seg_id = int(table["segment_id"][0].as_py()) if table.num_rows else 0
                while pending and pending[0][0] < seg_id:
                    writer.write(without_mu_k(pending.pop(0)[1], withheld))
                if seg_id in withheld and seg_id not in self.revised:
                    writer.write(without_mu_k(table.to_pandas(), withheld))
                elif seg_id not in self.revised:
                    writer.write_table(table)
            for _, frame in pending:
                writer.write(without_mu_k(frame, withheld))
            writer.close()


Sink = MemorySink | DirectorySink


def finish(sink: Sink, well: Well, summary: dict, records: list[SegmentRecord], *,
           tracks: pd.DataFrame | None = None,
           tables: dict[str, pd.DataFrame] | None = None) -> WellResult:
    """The end of every run: the result files (with a :class:`DirectorySink`) and the
    :class:`~drillfric.result.WellResult`."""
    summary.update(judge_headline(summary))
    sink.finish(well, summary, records, tracks, tables or {})
    return WellResult(well.name, summary, segments_frame(records),
                      failed=sum(r.status is Status.FAILED for r in records),
                      warnings=summary["warnings"], tracks=tracks, _estimates=sink.estimates())


def deliver(well: Well, out_root, run: Callable[[Sink], WellResult],
            report: ReportWriter | None = None) -> WellResult:
    """``run`` into memory (``out_root`` None: nothing written) or into ``out_root/NAME``,
    written atomically with the report (``report``) before it is committed."""
    if out_root is None:
        return run(MemorySink())
    final = Path(out_root) / well.dir_name
    with ResultDirectory(out_root, well.dir_name, well.name) as tmp:
        result = run(DirectorySink(tmp))
        if report is not None:
            try:
                write_report(tmp, report, result)
            except OutputError as exc:  # named by the final path, not the temporary's
                raise OutputError(exc.problem, file=final / Path(exc.file or "").name,
                                  fix=exc.fix) from None
    result.out_dir = Path(out_root) / well.dir_name
    return result


def write_report(result_dir: Path, report: ReportWriter, result: WellResult) -> None:
    """Write the report; a failure to render is a warning, not a lost run (the results
    stand), and leaves no partial report file; a failure to write (disk) fails the run."""
    try:
        report(result_dir)
    except (OSError, OutputError):  # the disk, not the drawing: the run fails (exit 2)
        raise
    except Exception as exc:  # noqa: BLE001 — the estimates are written; say what failed
        for partial in result_dir.glob("report.*"):
            partial.unlink(missing_ok=True)
        result.warnings.append(f"report not written: {type(exc).__name__}: {exc}")
        write_json(result_dir / "summary.json", result.summary)
