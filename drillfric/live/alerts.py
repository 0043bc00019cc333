"""What live.json says beside the numbers: the open segment's view and the alerts
(docs/live.md "live.json"), pure functions of the run's records and its published files.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq

from drillfric.errors import DrillfricError
from drillfric.io.timebase import clock_at
from drillfric.result import Flag, SegmentRecord
from drillfric.vocabulary import Status

#: Bit-speed swing (max − min)/(2·mean) from which stick-slip is called severe (docs/live.md).
SEVERE_STICK_SLIP = 1.0
#: Relative change of a converged μ_k against the median of the previous five that raises a
#: friction-trend alert.
TREND_CHANGE = 0.25
#: Surface speed above which the top drive counts as turning for a stall [RPM].
STALL_SURFACE_RPM = 5.0
#: Log seconds behind the newest sample beyond which a live value is not current: live.json
#: gives it ``old`` true beside its ``age_s`` and the page greys it, saying how old it is
#: (issue 35: an open segment, a stick-slip alert 150 s old read as current). The page's
#: OLD_S (templates/live.js) is the same.
OLD_S = 5.0


def aged(item: dict | None, time_s, newest_s) -> dict | None:
    """``item`` (a live.json value resting on the rows up to log time ``time_s``) with
    ``age_s`` — log seconds behind the newest sample ``newest_s`` — and ``old`` (beyond
    :data:`OLD_S`); a copy, null ages where either time is unknown.

    >>> aged({"kind": "severe_stick_slip", "time_s": 672.0}, 672.0, 821.8)
    {'kind': 'severe_stick_slip', 'time_s': 672.0, 'age_s': 149.8, 'old': True}
    """
    if item is None:
        return None
    try:
        age = round(max(float(newest_s) - float(time_s), 0.0), 1)
    except (TypeError, ValueError):
        return item | {"age_s": None, "old": False}
    if not math.isfinite(age):
        return item | {"age_s": None, "old": False}
    return item | {"age_s": age, "old": age > OLD_S}


def open_view(record: SegmentRecord, folder: Path) -> dict:
    """live.json ``open_segment``: the open segment's numbers as estimated so far; its bit
    speed null with ``bit_rpm_reason`` where the run withholds it (:func:`bit_speed_withheld`)."""
    why = bit_speed_withheld(record.to_json())
    bit_rpm, bha_rpm, stalled_s = (None, None, None) if why else bit_tail(folder, record.id)
    if bit_rpm is None and not why:
        why = ("the latest 30-s window's bit speed is withheld (window-by-window kinematic "
               "check: the segment's message says why)" if record.bit_speed_windows_withheld
               else "no estimated bit speed in this publication")
    return {"segment": record.id, "kind": record.kind.value, "status": record.status.value,
            "t_start_s": record.t_start_s, "t_end_s": record.t_end_s, "mu_k": record.mu_k,
            "mu_s": record.mu_s, "mu_s_lower_bound": record.mu_s_lower_bound,
            "bit_rpm": bit_rpm, "bha_rpm": bha_rpm if bit_rpm is not None else None,
            "bit_rpm_reason": why or None, "bit_stalled_s": stalled_s,
            "stick_slip_severity": record.stick_slip_severity,
            "stick_slip_beyond_validated":
                Flag.STICK_SLIP_BEYOND_VALIDATED in record.quality_flags,
            "mu_k_drift": Flag.MU_K_DRIFT in record.quality_flags,
            "mu_k_last": record.mu_k_last, "mu_k_drift_per_h": record.mu_k_drift_per_h}


def severe_stick_slip(open_segment: dict, where: str = "the open segment") -> str:
    """The ``severe_stick_slip`` alert's message ("" when none): the open segment's severity
    at least :data:`SEVERE_STICK_SLIP`, or withheld as beyond its validated range (an
    estimated severity ≥ 2.1, docs/bit_speed.md: severe by far); ``where`` names the
    segment (the newest closed one: ``"segment 3, closed"``)."""
    ssi = open_segment.get("stick_slip_severity")
    if ssi is not None and ssi >= SEVERE_STICK_SLIP:
        return f"stick-slip severity {ssi:.2f} in {where} (≥ {SEVERE_STICK_SLIP:g})"
    if open_segment.get("stick_slip_beyond_validated"):
        return (f"severe stick-slip in {where}: severity beyond its validated range "
                "(estimated ≥ 2.1; the number is withheld, docs/bit_speed.md)")
    return ""


def closed_view(record: SegmentRecord | None) -> dict | None:
    """What the live view keeps of the newest closed segment estimated (``ok``): its id,
    end and stick-slip severity — its ``severe_stick_slip`` alert when no open segment was
    published after it (a stand that stick-slipped and closed between two publications of
    an open segment had raised none: issue 35)."""
    if record is None or record.status is not Status.OK:
        return None
    return {"segment": record.id, "t_end_s": record.t_end_s,
            "stick_slip_severity": record.stick_slip_severity,
            "stick_slip_beyond_validated":
                Flag.STICK_SLIP_BEYOND_VALIDATED in record.quality_flags}


def behind(newest_s, through_s) -> float | None:
    """live.json ``behind_s``: log seconds between the newest sample read (``newest_s``) and
    the newest one the published estimates rest on (``through_s``: the rows handed to the
    last publication made); computed from data times only, never the wall clock.

    >>> behind(821.8, 672.0), behind(10.0, 10.0), behind(None, 3.0)
    (149.8, 0.0, None)
    """
    try:
        lag = round(max(float(newest_s) - float(through_s), 0.0), 1)
    except (TypeError, ValueError):
        return None
    return lag if math.isfinite(lag) else None


def behind_alert(behind_s: float | None, through_s) -> dict | None:
    """The ``estimates_behind`` alert (raised when the publications are overdue: the
    machine cannot keep up — loaded, or a fast replay): the published estimates rest on rows
    more than :data:`OLD_S` log seconds older than the newest sample, so the open segment
    and the alerts resting on it are not current, and an open segment not published yet
    reads as unknown, not as none."""
    if behind_s is None or behind_s <= OLD_S:
        return None
    return alert("estimates_behind", f"the estimates are {behind_s:.0f} s of log behind the "
                 "newest sample (they rest on the rows up to log time "
                 + ("—" if through_s is None else f"{float(through_s):.1f} s")
                 + "): the open segment and its alerts are not current — the machine cannot "
                 "keep up (loaded, or a fast replay)", through_s)


def bit_speed_withheld(record: dict) -> str:
    """Why a segment's estimated bit speed is not shown ("" when it is): the segment was not
    estimated (status not ``ok``), or its bit trace is not resolved (``bit_speed_resolved``
    false: docs/bit_speed.md) — the one rule of live.json and the live page. ``record``:
    the segment as in summary.json."""
    if record.get("status") != Status.OK:
        return f"segment {record.get('status', 'not published')}: {record.get('message', '')}"
    if record.get("bit_speed_resolved") is False:
        return record.get("bit_speed_reason") or "bit speed not resolved"
    return ""


def bit_tail(folder: Path, seg_id: int) -> tuple[float | None, float | None, float | None]:
    """The last estimated bit and BHA speeds [RPM] of segment ``seg_id`` (its last row
    group; they differ by a declared mud motor's speed) and how long [s] the estimated bit
    has been stuck (``bit_stuck``) at its end while the top drive turned (above
    :data:`STALL_SURFACE_RPM`); (None, None, None) without estimates."""
    path = folder / "estimates.parquet"
    if not path.is_file():
        return None, None, None
    source = pq.ParquetFile(path)
    names = ["segment_id", "time_s", "surface_rpm", "bit_rpm_est", "bit_stuck"] + \
        ["bha_rpm_est"] * ("bha_rpm_est" in source.schema_arrow.names)
    for i in reversed(range(source.num_row_groups)):
        table = source.read_row_group(i, columns=names)
        if table.num_rows and int(table["segment_id"][0].as_py()) == seg_id:
            return (_last(table, "bit_rpm_est"), _last(table, "bha_rpm_est"),
                    stalled_s(table.to_pandas()))
    return None, None, None


def _last(table, column: str) -> float | None:
    """The last value of ``column`` of an Arrow table, None where null, NaN or absent."""
    if column not in table.column_names:
        return None
    value = table[column][-1].as_py()
    return None if value is None or not math.isfinite(value) else float(value)


def stalled_s(rows: pd.DataFrame) -> float:
    """Log seconds of the trailing rows whose bit is stuck while the top drive turns."""
    stalled = rows["bit_stuck"].fillna(False).to_numpy(bool) & \
        (rows["surface_rpm"].to_numpy(float) > STALL_SURFACE_RPM)
    if not stalled.size or not stalled[-1]:
        return 0.0
    moving = np.flatnonzero(~stalled)
    first = moving[-1] + 1 if moving.size else 0
    t = rows["time_s"].to_numpy(float)
    return float(t[-1] - t[first])


def trend_alert(done: list[SegmentRecord]) -> dict | None:
    """A friction-trend alert when the newest converged μ_k moved by :data:`TREND_CHANGE`
    or more against the median of the five before it."""
    if len(done) < 3 or done[-1].mu_k is None:
        return None
    before = sorted(r.mu_k for r in done[-6:-1] if r.mu_k is not None)
    if not before:
        return None
    median = before[len(before) // 2]
    if median > 0 and abs(done[-1].mu_k / median - 1.0) >= TREND_CHANGE:
        return alert("friction_trend", f"μ_k {done[-1].mu_k:.3f} in segment {done[-1].id} "
                      f"against {median:.3f} before", done[-1].t_end_s)
    return None


def friction_rising(latest: list[SegmentRecord]) -> dict | None:
    """The ``friction_rising`` alert: of the open segment, else the last closed one
    (``latest``, in that order), the first whose friction moved within it (flag
    ``mu_k_drift``, docs/theory.md §6.6) upwards (``mu_k_drift_per_h`` > 0); None when
    neither rose (a drift down — a hole cleaned — is no alarm)."""
    for record in latest:
        rate = record.mu_k_drift_per_h
        if Flag.MU_K_DRIFT in record.quality_flags and rate is not None and rate > 0:
            span = ("" if record.mu_k_first is None or record.mu_k_last is None else
                    f" from {record.mu_k_first:.3f} to {record.mu_k_last:.3f}")
            return alert("friction_rising", f"friction rising within segment {record.id}: "
                                            f"μ_k(t){span}, {rate:+.3f}/h (cuttings bed, "
                                            "pack-off?)", record.t_end_s)
    return None


def ended(error: BaseException | None, done: bool, time_s: float | None) -> list[dict]:
    """The alert of a run that ended: ``run_failed`` with its one-line reason (the numbers
    shown are the last published, not current), or ``run_ended``; none while it runs."""
    if error is not None:
        reason = error.message if isinstance(error, DrillfricError) else type(error).__name__
        return [alert("run_failed", f"the live run stopped, the numbers shown are its last: "
                                     f"{reason}", time_s)]
    if done:
        return [alert("run_ended", "the live run ended; the numbers shown are final", time_s)]
    return []


def alert(kind: str, message: str, time_s: float | None) -> dict:
    return {"kind": kind, "message": message, "time_s": time_s}


def utc_at(origin, time_s: float) -> str | None:
    if origin is None:
        return None
    return clock_at(pd.Timestamp(origin), time_s).isoformat()
