"""What a report reads from a result directory (docs/outputs.md).

Only files of the directory are read (``summary.json`` and the Parquet tables next to it),
so ``drillfric report RESULT_DIR`` can rebuild a report long after the run. Estimates are
read for the segments that are drawn only, and decimated for plotting.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from drillfric.errors import InputError
from drillfric.io.atomic import own_file
from drillfric.io.results import read_json
from drillfric.io.text import printable
from drillfric.io.timebase import origin_of
from drillfric.result import ESTIMATE_NAMES, SEGMENT_FIELDS, SEGMENT_NUMBER_FIELDS
from drillfric.segmentation import RIG_STATES

from .interactive import TimeAxis, time_axis

_NUMERIC = SEGMENT_NUMBER_FIELDS  # None in summary.json becomes NaN
#: Torque columns of estimates.parquet: measured string torque, the observer's and the
#: batch fit's modelled surface torque [N·m].
TORQUE_COLUMNS = ("surface_torque_Nm", "surface_torque_est_Nm", "surface_torque_fit_Nm")


@dataclass(frozen=True)
class ResultData:
    """The contents of a result directory a report needs.

    Attributes
    ----------
    result_dir : Path
    summary : dict
        summary.json as read.
    segments : DataFrame
        The segments of summary.json, one row each; missing numbers are NaN.
    profiles : DataFrame or None
        profiles.parquet (torque-and-drag profile per estimated segment).
    wellpath : DataFrame or None
        wellpath.parquet (only when the run had a survey).
    tracks : DataFrame or None
        tracks.parquet: the whole log decimated for plotting (absent in older results).
    friction_log : DataFrame or None
        friction_log.parquet: one row per depth window of a depth-indexed log (its measured
        torque, hook load, WOB per window); None for time logs.
    drag_log : DataFrame or None
        drag_log.parquet: the drag-based friction per connection (docs/theory.md §2.2);
        None for depth logs and older results.
    """

    result_dir: Path
    summary: dict
    segments: pd.DataFrame
    profiles: pd.DataFrame | None
    wellpath: pd.DataFrame | None
    tracks: pd.DataFrame | None = None
    friction_log: pd.DataFrame | None = None
    drag_log: pd.DataFrame | None = None

    @property
    def depth_indexed(self) -> bool:
        """Whether the log was depth-indexed (a static friction log: no time series)."""
        return self.summary.get("index") == "depth"

    @property
    def log_span_s(self) -> tuple[float, float] | None:
        """First and last log time [s]: of tracks.parquet's bins (the whole log, to within
        a bin: ≤ 1/2000 of its length), else of the segments; None when neither has one."""
        for frame, first, last in ((self.tracks, "time_s", "time_s"),
                                   (self.segments, "t_start_s", "t_end_s")):
            if frame is None or first not in frame or not len(frame):
                continue
            low, high = frame[first].min(), frame[last].max()
            if np.isfinite(low) and np.isfinite(high):
                return float(low), float(high)
        return None

    @property
    def span_from_tracks(self) -> bool:
        """Whether :attr:`log_span_s` is the whole log's (tracks.parquet), not only the
        segments'."""
        return self.tracks is not None and len(self.tracks) > 0

    @property
    def time_axis(self) -> TimeAxis:
        """How the report plots log time: clock time when known, log hours for a log longer
        than an hour, else log seconds (:class:`~drillfric.report.interactive.TimeAxis`)."""
        span = self.log_span_s
        return time_axis(self.time_origin, 0.0 if span is None else span[1] - span[0])

    @property
    def time_origin(self) -> pd.Timestamp | None:
        """Clock time (UTC) of ``time_s = 0``, or None when the log has no clock time.

        From summary.json ``time_origin_utc``, else from tracks.parquet's ``timestamp``.
        """
        stamp = self.summary.get("time_origin_utc")
        if isinstance(stamp, str):
            try:
                return pd.Timestamp(stamp).tz_convert("UTC") if pd.Timestamp(stamp).tzinfo \
                    else pd.Timestamp(stamp).tz_localize("UTC")
            except ValueError:
                return None
        tracks = self.tracks
        if tracks is not None and "timestamp" in tracks and len(tracks):
            first = pd.to_datetime(tracks["timestamp"].iloc[:1], utc=True).iloc[0]
            return origin_of(first, float(tracks["time_s"].iloc[0]))
        return None


def _as_list(value) -> list:
    """A list field's value as a list (older results: JSON text or missing)."""
    if isinstance(value, str):
        try:
            value = json.loads(value)
        except ValueError:
            return []
    return list(value) if isinstance(value, list | tuple | np.ndarray) else []


def segments_frame(rows: list[dict]) -> pd.DataFrame:
    """The ``segments`` list of a summary.json as a table with NaN for missing numbers."""
    frame = pd.DataFrame(rows)
    for col in SEGMENT_FIELDS:  # older results lack some fields
        if col not in frame and col not in _NUMERIC:
            frame[col] = pd.Series([None] * len(frame), dtype=object)
    for col in _NUMERIC:
        frame[col] = pd.to_numeric(frame[col], errors="coerce") if col in frame else np.nan
    frame["converged"] = frame["converged"].fillna(False).astype(bool)
    frame["mu_s_identifiable"] = frame["mu_s_identifiable"].fillna(False).astype(bool)
    frame["message"] = frame["message"].fillna("").astype(str)
    if "flags" in frame:  # results before the rename (issue 25 item 9)
        frame["quality_flags"] = frame.pop("flags")
    frame["quality_flags"] = [_as_list(f) for f in frame["quality_flags"]]
    frame["starts"] = [_as_list(s) for s in frame["starts"]]
    frame["bit_speed_reason"] = frame["bit_speed_reason"].fillna("").astype(str)
    return frame


def load_result(result_dir: Path) -> ResultData:
    """Read a result directory written by ``drillfric run``.

    Raises
    ------
    InputError
        The directory or its summary.json is missing or unreadable.
    """
    result_dir = Path(result_dir)
    path = result_dir / "summary.json"
    if not result_dir.is_dir():
        raise InputError("not a directory", file=result_dir,
                         fix="give the OUT/NAME directory written by 'drillfric run'")
    if not path.is_file():
        raise InputError("no summary.json: not a drillfric result directory", file=result_dir,
                         fix="give the OUT/NAME directory written by 'drillfric run'")
    summary = read_json(path)
    if not isinstance(summary.get("segments", []), list):
        raise InputError("summary.json is not a drillfric summary", file=path,
                         fix="rerun 'drillfric run' to rewrite the results")
    return ResultData(result_dir, summary, segments_frame(summary.get("segments", [])),
                      _optional_parquet(result_dir / "profiles.parquet"),
                      _optional_parquet(result_dir / "wellpath.parquet"),
                      _optional_parquet(result_dir / "tracks.parquet"),
                      _optional_parquet(result_dir / "friction_log.parquet"),
                      _optional_parquet(result_dir / "drag_log.parquet"))


#: Text columns of the result tables (every other column holds numbers or timestamps).
_TEXT_COLUMNS = frozenset({"kind", "status", "source", "reason"})


def _numbers_schema(path: Path) -> list[str]:
    """The column names of a result table whose every column but :data:`_TEXT_COLUMNS`
    holds numbers, booleans or timestamps; ValueError otherwise (or for a link, a FIFO:
    :func:`~drillfric.io.atomic.own_file`)."""
    import pyarrow.parquet as pq
    import pyarrow.types as pt

    schema = pq.read_schema(own_file(path))
    for fld in schema:
        if fld.name in _TEXT_COLUMNS and not pt.is_nested(fld.type):
            continue
        if not (pt.is_integer(fld.type) or pt.is_floating(fld.type) or
                pt.is_boolean(fld.type) or pt.is_timestamp(fld.type) or pt.is_null(fld.type)):
            raise ValueError(f"column '{printable(fld.name, 40)}' holds {fld.type}, not numbers")
    return schema.names


def _optional_parquet(path: Path) -> pd.DataFrame | None:
    """A result table drillfric wrote, read as untrusted (it lies in OUT): a regular file,
    flat columns, numbers where numbers go, and rig-state codes among the known states —
    else one InputError naming it (a crafted table was an internal error in the report)."""
    if not path.is_file():
        return None
    try:
        _numbers_schema(path)
        frame = pd.read_parquet(path)
    except (OSError, ValueError) as exc:
        raise InputError(f"unreadable Parquet file ({exc})", file=path,
                         fix="rerun 'drillfric run' to rewrite the results") from None
    if "rig_state" in frame:
        codes = frame["rig_state"].dropna()
        if len(codes) and not codes.isin(range(-1, len(RIG_STATES))).all():
            raise InputError("rig_state holds codes that are no rig state", file=path,
                             fix="rerun 'drillfric run' to rewrite the results")
    return frame


#: The final (seeded) observer pass in estimates.parquet (drillfric.result.SEEDED_START_ID).
FINAL_START_ID = -1
#: Points per observer start (their μ move slowly: a few hundred points draw them).
START_POINTS = 300
#: Signals whose extremes survive the decimation of the final pass (stick-slip peaks,
#: break-over torque).
_EXTREME_KEYS = ("surface_torque_Nm", "surface_rpm", "bit_rpm_est")


def extreme_rows(frame: pd.DataFrame, max_points: int,
                 keys: tuple[str, ...] = _EXTREME_KEYS) -> np.ndarray:
    """Row positions of ``frame`` (time-ordered) kept for plotting: ≤ ``max_points``.

    The rows are cut into equal buckets; in each, the rows holding the minimum and the
    maximum of every key signal are kept, with the first and the last row. Unlike keeping
    every k-th sample, a stick-slip cycle shorter than the stride keeps its peaks and
    troughs, and a one-sample break-over peak stays. Kept rows are rows of the file, so the
    figure's values are the file's values.
    """
    n = len(frame)
    if n <= max_points:
        return np.arange(n)
    keys = tuple(k for k in keys if k in frame and frame[k].notna().any())
    buckets = max(1, (max_points - 2) // max(2 * len(keys), 1))
    size = int(np.ceil(n / buckets))
    keep = [np.array([0, n - 1])]
    for key in keys:
        values = np.full(buckets * size, np.nan)
        values[:n] = frame[key].to_numpy(float)
        grid = values.reshape(buckets, size)
        base = np.arange(buckets) * size
        keep.append(base + np.where(np.isnan(grid), np.inf, grid).argmin(axis=1))
        keep.append(base + np.where(np.isnan(grid), -np.inf, grid).argmax(axis=1))
    if not keys:
        keep.append(np.linspace(0, n - 1, max_points - 2).round().astype(int))
    rows = np.unique(np.concatenate(keep))
    return rows[rows < n]


def segment_estimates(result_dir: Path, ids: list[int],
                      max_points: int = 1200) -> dict[int, pd.DataFrame]:
    """Estimates of the given segments, every start, decimated to ≤ ``max_points`` per start.

    The final pass (``start_id`` −1, the reported speeds and torques) keeps the extremes
    of its signals (:func:`extreme_rows`); the starts, whose μ move slowly, keep every k-th
    sample (≤ :data:`START_POINTS`). The figures are for reading; the Parquet file keeps
    every sample.
    """
    path = Path(result_dir) / "estimates.parquet"
    if not ids or not path.is_file():
        return {}
    frame = _read_estimates(path, lambda names: [c for c in ESTIMATE_NAMES if c in names],
                            [("segment_id", "in", [int(i) for i in ids])])  # older lack some
    out = {}
    for seg_id, rows in frame.groupby("segment_id", sort=True):
        parts = []
        for start_id, one in rows.groupby("start_id", sort=True):
            one = one.sort_values("time_s", kind="stable")
            if start_id == FINAL_START_ID:
                parts.append(one.iloc[extreme_rows(one, max_points)])
            else:
                keep = min(max_points, START_POINTS)
                parts.append(one.iloc[::max(1, int(np.ceil(len(one) / keep)))])
        out[int(seg_id)] = pd.concat(parts, ignore_index=True)
    return out


def _read_estimates(path: Path, pick, filters: list) -> pd.DataFrame | None:
    """Rows of estimates.parquet: the columns ``pick`` takes from the file's (None: read
    nothing, return None), pyarrow ``filters``. A file that is not a table of numbers, or
    that pyarrow cannot read — it raises OSError, ValueError, TypeError or
    NotImplementedError for a crafted one — is one line naming it."""
    import pyarrow.parquet as pq

    try:
        columns = pick(_numbers_schema(path))
        if columns is None:
            return None
        return pq.read_table(path, columns=columns, filters=filters).to_pandas()
    except (OSError, ValueError, TypeError, NotImplementedError) as exc:
        raise InputError(f"unreadable estimates ({exc})", file=path,
                         fix="rerun 'drillfric run' to rewrite the results") from None


#: Columns of the final pass that say what the fit reproduces (every sample is read).
_FIT_COLUMNS = ("segment_id", "start_id", "time_s", "surface_torque_Nm", "surface_torque_fit_Nm")


def final_torques(result_dir: Path, ids: list[int]) -> dict[int, pd.DataFrame]:
    """The measured and fitted-model surface torque of the final pass of the given
    segments, every sample (:mod:`drillfric.report.reproduction`); empty when the file or
    its fit column is missing (older results)."""
    path = Path(result_dir) / "estimates.parquet"
    if not ids or not path.is_file():
        return {}
    frame = _read_estimates(
        path, lambda names: list(_FIT_COLUMNS) if "surface_torque_fit_Nm" in names else None,
        [("segment_id", "in", [int(i) for i in ids]), ("start_id", "=", FINAL_START_ID)])
    if frame is None:
        return {}
    return {int(i): rows for i, rows in frame.groupby("segment_id", sort=True)}
