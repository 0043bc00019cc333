"""Time base of rig surface data: seconds from the first sample, order, duplicates, gaps, rate.

Rig recorders log absolute timestamps (ISO 8601) or elapsed seconds, with jittered spacing,
repeated rows and outages. Here time becomes ``time_s`` [s] from the first sample (the
absolute time of ``time_s = 0`` is kept as ``origin`` when known); a timestamp that goes
backwards is an error naming the row; gaps and the nominal rate come from the sample spacing.

Rows sharing a timestamp (:meth:`TimeTracker.settle`): identical ones are one sample
written twice — one is kept, the others counted in ``duplicates``; rows of one time with
*different* values contradict each other — which one is the sample cannot be told, so all of
them are dropped and counted in ``conflicts`` (keeping the first had put μ_k at 0.263 for
0.28 when 9 % of the times were written twice with other values: issue 30, ninth attack).
The rows of a chunk's last time are held back until the next chunk (or the end of the data,
:meth:`TimeTracker.flush`) shows whether that time repeats, so the rows kept are the same in
any chunking — a live follower's and a run's alike.

:class:`TimeTracker` carries the state across chunks so that a file read in several
chunks gives exactly the same ``time_s`` as the file read at once.

Clock times stay in integer nanoseconds: the rows keep the timestamps as parsed, and a clock
time drillfric derives from a ``time_s`` (an estimate on the model's grid, a segment's end)
is the origin plus a whole number of nanoseconds, rounded to the microsecond of the
outputs (:func:`clock_at`) — never a float turned back into a timestamp, which leaves stray
nanoseconds that a microsecond column cannot hold.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np
import pandas as pd

from drillfric.errors import InputError
from drillfric.io.grouping import text_numbers
from drillfric.io.source import NULL_VALUES
from drillfric.io.text import printable
from drillfric.segmentation import is_gap


@dataclass(frozen=True)
class TimeBase:
    """Summary of a well's time base.

    Attributes
    ----------
    rows : int
        Rows kept (after dropping repeated times and rows without a time).
    t_start_s, t_end_s : float
        First and last ``time_s`` [s].
    rate_hz : float
        Nominal sample rate [Hz]: 1 / median spacing (robust to jitter and gaps);
        0 for fewer than two rows.
    gaps : tuple of (float, float)
        ``(start_s, end_s)`` of every spacing longer than ``segmentation.max_gap_s``: where
        a run ends a segment (:func:`drillfric.segmentation.is_gap`).
    duplicates_dropped : int
        Rows dropped because they repeat the previous row's timestamp and values.
    origin : pandas.Timestamp or None
        Absolute time of ``time_s = 0`` when the file has absolute timestamps.
    untimed_dropped : int
        Rows dropped because their time was empty or a null marker.
    source_start_s : float or None
        The file's own numeric time of the first sample [s] (``time_s`` starts at 0).
    conflicts_dropped : int
        Rows dropped because other rows of their timestamp hold other values (every row
        of such a time is dropped: :meth:`TimeTracker.settle`).
    """

    rows: int
    t_start_s: float
    t_end_s: float
    rate_hz: float
    gaps: tuple[tuple[float, float], ...]
    duplicates_dropped: int
    origin: pd.Timestamp | None
    untimed_dropped: int = 0
    source_start_s: float | None = None
    conflicts_dropped: int = 0


def nominal_rate_hz(time_s: np.ndarray) -> float:
    """Nominal sample rate [Hz] = 1 / median positive spacing (0 below two samples).

    Examples
    --------
    >>> nominal_rate_hz(np.array([0.0, 0.9, 2.1, 3.0, 3.9]))
    1.1111111111111112
    """
    dt = np.diff(np.asarray(time_s, dtype=float))
    dt = dt[dt > 0]
    return float(1.0 / np.median(dt)) if dt.size else 0.0


def find_gaps(time_s: np.ndarray, max_gap_s: float,
              rate_hz: float) -> tuple[tuple[float, float], ...]:
    """Spacings longer than ``max(max_gap_s, 5 / rate_hz)`` as ``(start_s, end_s)`` pairs:
    the holes of a bit trace (the window check of :mod:`drillfric.estimation.chain` passes
    the string's wave travel time as ``max_gap_s``), not the gaps that end a segment
    (:attr:`TimeBase.gaps`).

    Five nominal periods keep jitter (spacings of 0–2 s at 1 Hz) from counting as gaps.

    Examples
    --------
    >>> find_gaps(np.array([0.0, 1.0, 2.0, 30.0, 31.0]), 10.0, 1.0)
    ((2.0, 30.0),)
    """
    limit = max(max_gap_s, 5.0 / rate_hz) if rate_hz > 0 else max_gap_s
    return _spans(np.asarray(time_s, dtype=float), limit)


def _spans(time_s: np.ndarray, max_gap_s: float) -> tuple[tuple[float, float], ...]:
    """``(start_s, end_s)`` of every gap of ``time_s`` [s] (:func:`~drillfric.segmentation.
    is_gap` with ``max_gap_s`` [s])."""
    idx = np.flatnonzero(is_gap(np.diff(time_s), max_gap_s))
    return tuple((float(time_s[i]), float(time_s[i + 1])) for i in idx)


#: Plausible sampling of rig surface data [Hz]: outside it the time column is almost surely
#: in another unit (Excel serial days, milliseconds read as seconds).
PLAUSIBLE_RATE_HZ = (1.0 / 120.0, 5000.0)


def check_plausible_rate(time_s: np.ndarray, *, file=None, column: str = "time") -> None:
    """Raise InputError when the median sample spacing is not that of a rig log."""
    rate = nominal_rate_hz(np.asarray(time_s, dtype=float))
    lo, hi = PLAUSIBLE_RATE_HZ
    if np.isfinite(rate) and rate > 0 and not lo <= rate <= hi:
        raise InputError(f"time column '{printable(column)}' gives {rate:.3g} samples per "
                         "second, not a rig log's (0.008–5000 Hz): probably another unit "
                         "(Excel days, ms)",
                         file=file, fix='state it in [channels], e.g. time = { unit = "ms" }, '
                                        "or export the time in seconds")


def summarize(time_s: np.ndarray, *, max_gap_s: float, duplicates_dropped: int = 0,
              untimed_dropped: int = 0, origin: pd.Timestamp | None = None,
              source_start_s: float | None = None, conflicts_dropped: int = 0) -> TimeBase:
    """:class:`TimeBase` of an already checked, increasing ``time_s`` [s]."""
    time_s = np.asarray(time_s, dtype=float)
    rate = nominal_rate_hz(time_s)
    return TimeBase(rows=int(time_s.size),
                    t_start_s=float(time_s[0]) if time_s.size else 0.0,
                    t_end_s=float(time_s[-1]) if time_s.size else 0.0,
                    rate_hz=rate, gaps=_spans(time_s, max_gap_s),
                    duplicates_dropped=duplicates_dropped, origin=origin,
                    untimed_dropped=untimed_dropped, source_start_s=source_start_s,
                    conflicts_dropped=conflicts_dropped)


OUTPUT_CLOCK_UNIT = "us"
"""Resolution of the clock times drillfric writes (estimates.parquet ``timestamp``)."""


def clock_at(origin: pd.Timestamp, seconds):
    """Clock time ``seconds`` [s] after ``origin``, in whole microseconds.

    ``seconds`` is a float or an array of floats (NaN gives NaT); the sum is rounded once,
    to the microsecond (the origin's nanoseconds below its microsecond added to the offset
    first: rounding to the nanosecond and then to the microsecond had put 41 499.7 ns at
    42 µs), so the result fits the outputs' ``timestamp[us]`` column exactly, whatever the
    origin's resolution.

    Examples
    --------
    >>> origin = pd.Timestamp("2026-03-01T06:00:00.000000001Z")
    >>> clock_at(origin, 2.3116699999)
    Timestamp('2026-03-01 06:00:02.311670+0000', tz='UTC')
    """
    below = origin.value % 1000  # [ns]
    base = origin - pd.Timedelta(below, unit="ns")
    micros = np.round((below + np.asarray(seconds, dtype=float) * 1e9) / 1000.0)
    if micros.ndim == 0:
        if not np.isfinite(micros):
            return pd.NaT
        return base + pd.Timedelta(int(micros), unit=OUTPUT_CLOCK_UNIT)
    return base + pd.to_timedelta(np.where(np.isfinite(micros), micros, np.nan),
                                  unit=OUTPUT_CLOCK_UNIT)


def origin_of(stamp: pd.Timestamp, seconds: float) -> pd.Timestamp:
    """Clock time of ``time_s = 0`` from one row's ``stamp`` and its ``seconds`` [s].

    The offset is rounded to the nanosecond, so the origin a reader computed is found again
    exactly (``seconds`` was an integer number of nanoseconds divided by 10⁹; a float holds
    it to the nanosecond for 52 days of log).

    Examples
    --------
    >>> origin_of(pd.Timestamp("2026-03-01T06:00:02.311670Z"), 2.31167)
    Timestamp('2026-03-01 06:00:00+0000', tz='UTC')
    """
    seconds = float(seconds)
    whole = math.floor(seconds)  # the fraction apart: seconds·10⁹ in one float product had
    # lost the last nanosecond beyond ~26 days (48.6 days of log: origin 1 ns off)
    nanoseconds = int(whole) * 1_000_000_000 + int(round((seconds - whole) * 1e9))
    return pd.Timestamp(stamp) - pd.Timedelta(nanoseconds, unit="ns")


#: Share of a log's timestamps that may be repeated with other values (all their rows
#: dropped) before the log is refused (:meth:`TimeTracker.check_conflicts`).
MAX_CONFLICT_SHARE = 0.25


class TimeTracker:
    """Turns the time column of successive chunks into checked ``time_s`` [s].

    Parameters
    ----------
    factor : float
        Seconds per unit of a numeric time column (1 for seconds).
    file, column : str
        For messages.
    date_column : str, optional
        A column of the file holding dates (for messages).
    """

    def __init__(self, factor: float, *, file: str | None = None, column: str = "time",
                 date_column: str | None = None):
        self.factor = factor
        self.file = file
        self.column = column
        self.date_column = date_column  # a column of dates beside the time (for messages)
        self.origin: pd.Timestamp | None = None
        self.source_start_s: float | None = None
        self.duplicates = 0  # rows dropped: a repeat of their time's values
        self.untimed = 0
        self.conflicts = 0  # rows dropped: other values at their time
        self.conflict_times = 0  # the times of those rows
        self.first_conflict_s: float | None = None  # time_s of the first such time
        self._rows_seen = 0
        self._last: float | None = None
        self._absolute: bool | None = None
        self._zoned: bool | None = None  # whether the text timestamps carry a UTC offset
        self._held: pd.DataFrame | None = None  # rows of the last time read (settle)
        # the part of a log in parts read last, and the rows read before it
        self._part: str | None = None
        self._part_row = 0
        # a numeric time that may be clock times written HHMMSS: its last value (None: no
        # longer possible — a value no HHMMSS is, or a unit other than the second)
        self._hhmmss: float | None = np.nan if factor == 1.0 else None
        self._hhmmss_jumps = 0  # minutes crossed so far by such a column
        self._hhmmss_first: list = []  # the first: value before, after, s, as s, data row

    def state(self) -> dict:
        """Where the time base stands (plain values; the origin as ISO 8601 text; the rows
        held back as a DataFrame)."""
        return {"origin": None if self.origin is None else self.origin.isoformat(),
                "source_start_s": self.source_start_s, "duplicates": self.duplicates,
                "untimed": self.untimed, "rows_seen": self._rows_seen, "last": self._last,
                "absolute": self._absolute, "conflicts": self.conflicts,
                "conflict_times": self.conflict_times,
                "first_conflict_s": self.first_conflict_s, "held": self._held,
                "part": self._part, "part_row": self._part_row, "hhmmss": self._hhmmss,
                "hhmmss_jumps": self._hhmmss_jumps, "hhmmss_first": self._hhmmss_first}

    def restore(self, state: dict) -> None:
        """Continue from a :meth:`state`."""
        self.origin = None if state["origin"] is None else pd.Timestamp(state["origin"])
        self.source_start_s = state["source_start_s"]
        self.duplicates, self.untimed = int(state["duplicates"]), int(state["untimed"])
        self._rows_seen, self._last = int(state["rows_seen"]), state["last"]
        self._absolute = state["absolute"]
        self.conflicts = int(state.get("conflicts", 0))
        self.conflict_times = int(state.get("conflict_times", 0))
        self.first_conflict_s = state.get("first_conflict_s")
        self._part, self._part_row = state.get("part"), int(state.get("part_row", 0))
        self._hhmmss = state.get("hhmmss")
        self._hhmmss_jumps = int(state.get("hhmmss_jumps", 0))
        self._hhmmss_first = list(state.get("hhmmss_first") or [])
        held = state.get("held")
        self._held = None if held is None else held.copy()

    @property
    def holding(self) -> bool:
        """Whether rows are held back (:meth:`settle`) for :meth:`flush` to hand out."""
        return self.held_rows > 0

    @property
    def held_rows(self) -> int:
        """Rows held back by :meth:`settle` (read, their time not yet settled)."""
        return 0 if self._held is None else len(self._held)

    def step(self, values: pd.Series, part: str | None = None
             ) -> tuple[np.ndarray, np.ndarray, pd.Series | None]:
        """Check one chunk's time column (``part``: the file of a log in parts it comes
        from, for messages).

        Rows repeating a time are all kept here: :meth:`settle` decides on them, with their
        values.

        Returns
        -------
        time_s : ndarray
            Seconds from the first sample for the rows kept.
        keep : ndarray of bool
            Which rows of the chunk are kept (time present).
        stamps : pandas.Series or None
            The kept rows' timestamps (UTC, nanoseconds, as parsed) when the column holds
            clock time; None for a numeric time.

        Raises
        ------
        InputError
            A time that goes backwards (naming its data row) or cannot be read.
        """
        seconds, stamps = self._seconds(values)
        valid = np.isfinite(seconds)
        self.untimed += int((~valid).sum())
        rows = np.flatnonzero(valid)
        t = seconds[valid]
        if stamps is None and self._hhmmss is not None and t.size:
            self._check_hhmmss(t + (self.source_start_s or 0.0), rows)
        previous = np.concatenate([[self._last if self._last is not None else -np.inf], t[:-1]])
        back = np.flatnonzero(t < previous)
        if back.size:
            self._backwards(int(rows[back[0]]), float(t[back[0]]), float(previous[back[0]]),
                            part, first=back[0] == 0 and part != self._part)
        if t.size:
            self._last = float(t[-1])
        if part != self._part:
            self._part, self._part_row = part, self._rows_seen
        self._rows_seen += len(seconds)
        kept = None if stamps is None else stamps[valid].reset_index(drop=True)
        return seconds[valid], valid, kept

    def _check_hhmmss(self, v: np.ndarray, rows: np.ndarray) -> None:
        """Raise when a numeric time column holds clock times written as HHMMSS (235859,
        235900: one second, read as seconds 41): every value a time of day so written, and
        a step across a minute 40 s or more longer as a number than as a time of day
        (read as seconds, every minute of the log would end in a 41-s gap) — twice, so that
        one gap of a log in seconds skipping 60–99 is not taken for it."""
        whole = np.floor(np.round(v, 6))
        fits = (v >= 0) & (v < 240000) & ((whole // 100) % 100 < 60) & (whole % 100 < 60)
        if not fits.all():
            self._hhmmss = None
            return
        sod = (whole // 10000) * 3600 + (whole // 100 % 100) * 60 + v - 100 * (whole // 100)
        prev = np.r_[self._hhmmss, v[:-1]]
        prev_whole = np.floor(np.round(prev, 6))
        prev_sod = (prev_whole // 10000) * 3600 + (prev_whole // 100 % 100) * 60 \
            + prev - 100 * (prev_whole // 100)
        step, as_time = v - prev, np.mod(sod - prev_sod, 86400.0)
        wraps = (step < 0) & (as_time < 40)  # 235959 then 000000: midnight
        jump = np.flatnonzero(((as_time < 40) & (step - as_time >= 40)) | wraps)
        self._hhmmss = float(v[-1])
        for k in jump[:2]:
            if not self._hhmmss_first:
                self._hhmmss_first = [float(prev[k]), float(v[k]), float(as_time[k]),
                                      float(step[k]), self._rows_seen + int(rows[k]) + 1]
        self._hhmmss_jumps += int(jump.size)
        if self._hhmmss_jumps < 2:
            return
        before, after, as_time_s, step_s, row = self._hhmmss_first
        date = f" beside the date column '{printable(self.date_column)}'" \
            if self.date_column else ""
        raise InputError(f"time column '{printable(self.column)}' holds times of day written "
                         f"as HHMMSS{date} ({before:g} then {after:g} at data row {row:.0f}: "
                         f"{as_time_s:g} s, read as seconds {step_s:g}): drillfric reads a "
                         "time column as seconds or as timestamps", file=self.file,
                         fix="give one time column of ISO 8601 timestamps, date and time "
                             "together (e.g. 2026-11-27T23:59:00), or a time_s column")

    def _backwards(self, i: int, t: float, before: float, part: str | None,
                   first: bool) -> None:
        """Raise the InputError of a time going back at the chunk's row ``i`` (``t`` after
        ``before`` [s]; ``first``: the first timed row of a new part), saying where and what
        it looks like: two overlapping parts of a log, a daylight-saving fall-back, a clock
        stepped back."""
        back = before - t
        at, prev = self._show(t), self._show(before)
        if first and part is not None and self._part is not None:
            raise InputError(f"part '{printable(part)}' starts at {at}, before part "
                             f"'{printable(self._part)}' ends ({prev}): the two parts of "
                             "the log overlap", file=self.file,
                             fix="the parts are read in name order (numbers by value), "
                                 "the files are never changed: if the names do not sort in "
                                 "time order, copy the parts into a new folder under names "
                                 f"that do; if '{printable(part)}' exports hours already "
                                 "logged again, move it into a sub-folder (not read)")
        if part is not None and part != self._part:
            self._part_row = self._rows_seen  # the row is in a part begun in this chunk
        row = self._rows_seen + i + 1
        where = f"at data row {row - self._part_row} of part '{printable(part)}'" \
            if part is not None else f"at data row {row}"
        problem = f"time goes backwards {where} ({at} after {prev})"
        if abs(back - 3600.0) <= 60.0 and self.origin is not None:
            raise InputError(f"{problem}: back {back / 60:.0f} min, a daylight-saving "
                             "fall-back of a local clock written without its UTC offset",
                             file=self.file,
                             fix="export the times in UTC or with their offset (e.g. "
                                 "2026-10-25T02:30:00+01:00), or give a time_s column")
        if back < 60.0:
            raise InputError(f"{problem}: back {back:.3g} s, a clock stepped back (set or "
                             "synchronised while logging)", file=self.file,
                             fix=f"remove the rows from that one on whose time is not after "
                                 f"{prev} (the {back:.3g} s the clock logged twice), or give "
                                 "a time_s column that never goes back")
        raise InputError(problem, file=self.file,
                         fix="sort the file by time or remove the out-of-order rows")

    def settle(self, rows: pd.DataFrame) -> pd.DataFrame:
        """The rows of ``rows`` (canonical: ``time_s`` from :meth:`step`, values) whose time
        is settled, with the rows held back from the chunk before.

        The rows of the last time are held back: the next chunk may repeat it. Of rows
        sharing a time, identical ones are kept once (the others counted in
        :attr:`duplicates`); rows of one time holding different values are all dropped
        (counted in :attr:`conflicts` and :attr:`conflict_times`) — the same rows in any
        chunking.
        """
        if self.holding and len(rows):
            rows = pd.concat([self._held, rows], ignore_index=True)
        elif self.holding:
            return rows
        if not len(rows):
            return rows
        t = rows["time_s"].to_numpy(float)
        last = t == t[-1]
        self._held = rows[last].reset_index(drop=True)
        return self._resolve(rows[~last].reset_index(drop=True))

    def flush(self) -> pd.DataFrame | None:
        """The rows held back by :meth:`settle` (settled: the data ended), or None."""
        held, self._held = self._held, None
        return None if held is None else self._resolve(held)

    def _resolve(self, rows: pd.DataFrame) -> pd.DataFrame:
        """``rows`` with each repeated time settled (:meth:`settle`)."""
        t = rows["time_s"].to_numpy(float)
        if t.size < 2 or not (t[1:] == t[:-1]).any():
            return rows
        starts = np.flatnonzero(np.r_[True, t[1:] != t[:-1]])
        sizes = np.diff(np.r_[starts, t.size])
        group = np.repeat(np.arange(starts.size), sizes)
        values = rows[[c for c in rows.columns if c not in ("time_s", "timestamp")]]
        v = values.to_numpy(dtype=float, na_value=np.nan)
        ref = v[starts][group]
        same = ((v == ref) | (np.isnan(v) & np.isnan(ref))).all(axis=1)
        agree = np.logical_and.reduceat(same, starts)
        self.duplicates += int((sizes[agree] - 1).sum())
        self.conflicts += int(sizes[~agree].sum())
        self.conflict_times += int((~agree).sum())
        if self.first_conflict_s is None and not agree.all():
            self.first_conflict_s = float(t[starts[~agree][0]])
        keep = np.zeros(t.size, dtype=bool)
        keep[starts[agree]] = True
        return rows[keep].reset_index(drop=True)

    def check_conflicts(self, kept: int) -> None:
        """Raise when more than :data:`MAX_CONFLICT_SHARE` of the log's times were repeated
        with other values (``kept``: the rows kept): the time column is not the samples'
        time (cut to whole seconds on a faster log, two recorders interleaved), and what is
        left of the log cannot be trusted."""
        times = kept + self.conflict_times
        if self.conflict_times <= MAX_CONFLICT_SHARE * times:
            return
        if kept == 0 and self.conflict_times == 1:
            raise InputError(f"time column '{printable(self.column)}' holds one value for all "
                             f"{self.conflicts} rows", file=self.file,
                             fix="map the column that holds the sample times in [channels] "
                                 'time = { column = "..." }')
        raise InputError(f"{self.conflict_times} of the log's {times} timestamps "
                         f"({100.0 * self.conflict_times / times:.0f} %) are repeated with "
                         f"other values ({self.conflicts} rows, the first at "
                         f"{self._show(self.first_conflict_s or 0.0)} in column "
                         f"'{printable(self.column)}'): which row is the sample cannot be told",
                         file=self.file,
                         fix="log the time at full resolution (not cut to whole seconds), or "
                             "give a time_s column; if two recorders write the file, keep one")

    def conflicts_note(self, kept: int) -> str | None:
        """A warning naming the file and the counts when rows were dropped for a timestamp
        repeated with other values (louder from 1 % of the log's times), or None."""
        if not self.conflicts:
            return None
        times = kept + self.conflict_times
        share = 100.0 * self.conflict_times / times
        where = f"{self.file}: " if self.file else ""
        text = (f"{where}{self.conflict_times} of the log's {times} timestamps ({share:.1f} %) "
                f"are repeated with other values ({self.conflicts} rows, the first at "
                f"{self._show(self.first_conflict_s or 0.0)}): which row is the sample cannot "
                "be told, so all of them were dropped")
        if share >= 1.0:
            text += (" — that many contradicting rows: check the recorder (timestamps cut "
                     "coarser than the logging, two sources writing one log)")
        return text

    def _show(self, t: float) -> str:
        if self.origin is not None:
            return str(clock_at(self.origin, t))
        return f"{t + (self.source_start_s or 0.0):g} s"

    def _seconds(self, values: pd.Series) -> tuple[np.ndarray, pd.Series | None]:
        """Seconds from the first sample (the origin is set by the first valid value), and
        the timestamps they come from (None for a numeric time)."""
        try:
            numeric = _as_number(values)
        except UnreadNumber as bad:
            raise InputError(f"time column '{printable(self.column)}': cannot read "
                             f"'{printable(bad.text, 30)}' at data row "
                             f"{self._rows_seen + bad.index + 1} as a number (the rows before "
                             "it hold numbers)", file=self.file,
                             fix="remove or comment out that line (# at its start), or write "
                                 "it as a number") from None
        absolute = numeric is None or (bool(self._absolute) and bool(np.isnan(numeric).all()))
        if self._absolute is not None and absolute != self._absolute:
            raise InputError(f"time column '{printable(self.column)}' mixes numbers and timestamps "
                             f"near data row {self._rows_seen + 1}", file=self.file,
                             fix="write every time as seconds or every time as a timestamp")
        self._absolute = absolute
        if absolute:
            stamps = self._timestamps(values)
            if self.origin is None and stamps.notna().any():
                self.origin = stamps[stamps.notna()].iloc[0]
            if self.origin is None:
                return np.full(len(values), np.nan), stamps
            return ((stamps - self.origin) / pd.Timedelta(seconds=1)).to_numpy(
                dtype=float, na_value=np.nan), stamps
        if not np.isfinite(self.factor):
            raise InputError(f"time column '{printable(self.column)}' holds numbers but its "
                             "unit is not a time unit", file=self.file,
                             fix='state it in the config: [channels] time = { unit = "s" }')
        seconds = numeric * self.factor
        if self.source_start_s is None and np.isfinite(seconds).any():
            self.source_start_s = float(seconds[np.isfinite(seconds)][0])
        return seconds - (self.source_start_s or 0.0), None

    def _timestamps(self, values: pd.Series) -> pd.Series:
        if pd.api.types.is_datetime64_any_dtype(values):
            return self._nanoseconds(values.reset_index(drop=True))
        text = values.astype("string").str.strip()
        if text.str.contains(",", regex=False).any():  # ISO 8601's decimal comma: 12:00:00,05
            text = text.str.replace(_COMMA_FRACTION, r"\1.\2", regex=True)
        self._same_zoning(text)
        for utc in (False, True):  # several UTC offsets (a daylight-saving change): to UTC
            try:
                stamps = pd.to_datetime(text, format="ISO8601", utc=utc)
            except (ValueError, TypeError):
                continue
            return self._nanoseconds(stamps.reset_index(drop=True))
        stamps = pd.to_datetime(text, format="ISO8601", errors="coerce", utc=True)
        bad = np.flatnonzero(stamps.isna().to_numpy() & _present(text))
        row = self._rows_seen + (bad[0] if bad.size else 0) + 1
        shown = printable(text.iloc[bad[0]], 30) if bad.size else ""
        if bad.size and _LEAP_SECOND.search(str(text.iloc[bad[0]])):
            raise InputError(f"time column '{printable(self.column)}': '{shown}' at data row "
                             f"{row} is a leap second (23:59:60): drillfric's time axis counts "
                             "UTC as POSIX does, without leap seconds, so its samples would "
                             "overlay the next second's", file=self.file,
                             fix="export the time as seconds (a time_s column) or with the "
                                 "leap second smeared (as NTP servers of Google and AWS do)")
        raise InputError(f"time column '{printable(self.column)}': cannot read '{shown}' at "
                         f"data row "
                         f"{row} as seconds or an ISO 8601 timestamp", file=self.file,
                         fix="write times as seconds or like 2024-05-01T12:00:00")

    def _same_zoning(self, text: pd.Series) -> None:
        """Refuse text timestamps some of which state a UTC offset and some not (the
        eleventh attack of issue 30: ``+02:00`` lost from row 2001 on read the rest as UTC,
        a silent 2-h jump and clock times 2 h off)."""
        present = _present(text)
        zoned = text.str.contains(_OFFSET, regex=True, na=False).to_numpy(dtype=bool)
        if not present.any():
            return
        first = bool(zoned[present][0]) if self._zoned is None else self._zoned
        odd = np.flatnonzero(present & (zoned != first))
        if odd.size:
            row = self._rows_seen + int(odd[0]) + 1
            raise InputError(f"time column '{printable(self.column)}': the timestamp at data "
                             f"row {row} ('{printable(text.iloc[odd[0]], 30)}') "
                             f"{'has no' if first else 'has a'} UTC offset, the earlier ones "
                             f"{'have one' if first else 'none'}: its clock time cannot be "
                             "placed", file=self.file,
                             fix="write every time with its UTC offset (or every time in UTC, "
                                 "ending in Z)")
        self._zoned = first

    def _nanoseconds(self, stamps: pd.Series) -> pd.Series:
        """``stamps`` at nanosecond resolution, the one times are computed in; a date
        outside 1677-09-21 … 2262-04-11 (``0001-01-01``, ``9999-12-31``: pandas parses
        them at a coarser resolution) is an InputError naming its row."""
        try:
            return stamps.dt.as_unit("ns")
        except (OverflowError, ValueError):  # OutOfBoundsDatetime is a ValueError
            pass
        low, high = pd.Timestamp.min, pd.Timestamp.max
        if stamps.dt.tz is not None:
            low, high = low.tz_localize("UTC"), high.tz_localize("UTC")
        bad = np.flatnonzero(((stamps < low) | (stamps > high)).to_numpy(dtype=bool))
        row = self._rows_seen + (int(bad[0]) if bad.size else 0) + 1
        raise InputError(f"time column '{printable(self.column)}': the timestamp at data row "
                         f"{row} lies outside the years 1677–2262 drillfric computes in",
                         file=self.file, fix="check the dates of the time column (a clock "
                                             "that was never set, a placeholder date)")


#: A UTC offset (or ``Z``) after a time of day, as ISO 8601 writes it.
_OFFSET = r"\d{2}:\d{2}(?::\d{2}(?:[.,]\d*)?)?\s*(?:[Zz]|UTC|[+-]\d{2}(?::?\d{2})?)$"
#: ISO 8601's decimal comma in the seconds (``12:00:00,05``), read as a point.
_COMMA_FRACTION = r"(\d{2}:\d{2}:\d{2}),(\d)"
#: A leap second's time of day (``23:59:60``, ``23:59:60.5``).
_LEAP_SECOND = re.compile(r"\d{2}:\d{2}:60(?:[.,]\d*)?(?:Z|[+-]\d{2}:?\d{2})?$")


def holds_timestamps(values: pd.Series) -> bool:
    """Whether a time column holds absolute timestamps (date-time values or text that is
    not a number), not numbers in a time unit.

    Examples
    --------
    >>> holds_timestamps(pd.Series(["2024-05-01T12:00:00Z"])), holds_timestamps(pd.Series([0.5]))
    (True, False)
    """
    try:
        return _as_number(values) is None
    except UnreadNumber:  # numbers with a text line among them: numbers
        return False


class UnreadNumber(ValueError):
    """A column of numbers holds text at ``index`` (its first unreadable entry)."""

    def __init__(self, index: int, text: str):
        super().__init__(text)
        self.index, self.text = index, text


def _as_number(values: pd.Series) -> np.ndarray | None:
    """Numeric time as float with nulls → NaN, or None when the column holds timestamps."""
    if pd.api.types.is_datetime64_any_dtype(values):
        return None
    if pd.api.types.is_numeric_dtype(values) and not pd.api.types.is_bool_dtype(values):
        out = values.to_numpy(dtype=float, na_value=np.nan)
    else:
        text = values.astype("string").str.strip()
        out = pd.to_numeric(text, errors="coerce").to_numpy(dtype=float, na_value=np.nan)
        unread = np.isnan(out) & _present(text)
        if unread.any() and not _CLOCKLIKE.search(str(text.iloc[np.argmax(unread)])):
            # a decimal comma, '1 234,50' s (issue 30, twelfth attack F2): as other channels
            out = text_numbers(text)
            unread = np.isnan(out) & _present(text)
        if unread.any():
            if (~unread & _present(text)).any() and not unread[np.argmax(_present(text))]:
                raise UnreadNumber(int(np.argmax(unread)), str(text.iloc[np.argmax(unread)]))
            return None  # text from the first value on: timestamps
    out = out.copy()
    out[np.isin(out, NULL_VALUES) | np.isinf(out)] = np.nan  # an infinite time is no value
    return out


#: Text that is a date or a clock time, not a number written with a decimal comma or groups.
_CLOCKLIKE = re.compile(r"[:T/]|^\d{4}-")


def _present(text: pd.Series) -> np.ndarray:
    """Which entries of a text column hold something (not missing, not blank)."""
    return (text.fillna("") != "").to_numpy(dtype=bool)


def spacing_summary(time_s: np.ndarray) -> dict[str, float]:
    """Sample spacing statistics [s] (min, 5th percentile, median, 95th percentile, max).

    Shows jitter at a glance: a 1 Hz recorder with 0–2 s spacing has median 1 and a wide
    5–95 % band. Empty for fewer than two samples.

    Examples
    --------
    >>> spacing_summary(np.array([0.0, 1.0, 2.0]))["median"]
    1.0
    """
    dt = np.diff(np.asarray(time_s, dtype=float))
    if not dt.size:
        return {}
    p05, median, p95 = np.percentile(dt, [5, 50, 95])
    return {"min": float(dt.min()), "p05": float(p05), "median": float(median),
            "p95": float(p95), "max": float(dt.max())}
