"""Time base of rig surface data: seconds from the first sample, order, duplicates, gaps, rate.

Rig recorders log absolute timestamps (ISO 8601) or elapsed seconds, with jittered spacing,
repeated rows and outages. Here time becomes ``time_s`` [s] from the first sample (the
absolute time of ``time_s = 0`` is kept as ``origin`` when known); a timestamp that goes
backwards is an error naming the row; a row repeating the previous timestamp is dropped
(the first is kept) and counted; gaps and the nominal rate come from the sample spacing.

:class:`TimeTracker` carries the state across chunks so that a file read in several
chunks gives exactly the same ``time_s`` as the file read at once.

Clock times stay in integer nanoseconds: the rows keep the timestamps as parsed, and a clock
time drillfric derives from a ``time_s`` (an estimate on the model's grid, a segment's end)
is the origin plus a whole number of nanoseconds, rounded to the microsecond of the
outputs (:func:`clock_at`) — never a float turned back into a timestamp, which leaves stray
nanoseconds that a microsecond column cannot hold.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from drillfric.errors import InputError
from drillfric.io.source import NULL_VALUES
from drillfric.io.text import printable
from drillfric.segmentation import is_gap


@dataclass(frozen=True)
class TimeBase:
    """Summary of a well's time base.

    Attributes
    ----------
    rows : int
        Rows kept (after dropping duplicates and rows without a time).
    t_start_s, t_end_s : float
        First and last ``time_s`` [s].
    rate_hz : float
        Nominal sample rate [Hz]: 1 / median spacing (robust to jitter and gaps);
        0 for fewer than two rows.
    gaps : tuple of (float, float)
        ``(start_s, end_s)`` of every spacing longer than ``segmentation.max_gap_s``: where
        a run ends a segment (:func:`drillfric.segmentation.is_gap`).
    duplicates_dropped : int
        Rows dropped because they repeat the previous row's timestamp.
    origin : pandas.Timestamp or None
        Absolute time of ``time_s = 0`` when the file has absolute timestamps.
    untimed_dropped : int
        Rows dropped because their time was empty or a null marker.
    source_start_s : float or None
        The file's own numeric time of the first sample [s] (``time_s`` starts at 0).
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
              source_start_s: float | None = None) -> TimeBase:
    """:class:`TimeBase` of an already checked, increasing ``time_s`` [s]."""
    time_s = np.asarray(time_s, dtype=float)
    rate = nominal_rate_hz(time_s)
    return TimeBase(rows=int(time_s.size),
                    t_start_s=float(time_s[0]) if time_s.size else 0.0,
                    t_end_s=float(time_s[-1]) if time_s.size else 0.0,
                    rate_hz=rate, gaps=_spans(time_s, max_gap_s),
                    duplicates_dropped=duplicates_dropped, origin=origin,
                    untimed_dropped=untimed_dropped, source_start_s=source_start_s)


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
    return pd.Timestamp(stamp) - pd.Timedelta(int(np.round(float(seconds) * 1e9)), unit="ns")


class TimeTracker:
    """Turns the time column of successive chunks into checked ``time_s`` [s].

    Parameters
    ----------
    factor : float
        Seconds per unit of a numeric time column (1 for seconds).
    file, column : str
        For messages.
    """

    def __init__(self, factor: float, *, file: str | None = None, column: str = "time"):
        self.factor = factor
        self.file = file
        self.column = column
        self.origin: pd.Timestamp | None = None
        self.source_start_s: float | None = None
        self.duplicates = 0
        self.untimed = 0
        self._rows_seen = 0
        self._last: float | None = None
        self._absolute: bool | None = None

    def state(self) -> dict:
        """Where the time base stands (plain values; the origin as ISO 8601 text)."""
        return {"origin": None if self.origin is None else self.origin.isoformat(),
                "source_start_s": self.source_start_s, "duplicates": self.duplicates,
                "untimed": self.untimed, "rows_seen": self._rows_seen, "last": self._last,
                "absolute": self._absolute}

    def restore(self, state: dict) -> None:
        """Continue from a :meth:`state`."""
        self.origin = None if state["origin"] is None else pd.Timestamp(state["origin"])
        self.source_start_s = state["source_start_s"]
        self.duplicates, self.untimed = int(state["duplicates"]), int(state["untimed"])
        self._rows_seen, self._last = int(state["rows_seen"]), state["last"]
        self._absolute = state["absolute"]

    def step(self, values: pd.Series) -> tuple[np.ndarray, np.ndarray, pd.Series | None]:
        """Check one chunk's time column.

        Returns
        -------
        time_s : ndarray
            Seconds from the first sample for the rows kept.
        keep : ndarray of bool
            Which rows of the chunk are kept (time present, not a repeat).
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
        previous = np.concatenate([[self._last if self._last is not None else -np.inf], t[:-1]])
        back = np.flatnonzero(t < previous)
        if back.size:
            i = back[0]
            row = self._rows_seen + rows[i] + 1
            raise InputError(f"time goes backwards at data row {row} ({self._show(t[i])} "
                             f"after {self._show(previous[i])})", file=self.file,
                             fix="sort the file by time or remove the out-of-order rows")
        repeat = t == previous
        self.duplicates += int(repeat.sum())
        keep = np.zeros(len(seconds), dtype=bool)
        keep[rows[~repeat]] = True
        if t.size:
            self._last = float(t[-1])
        self._rows_seen += len(seconds)
        kept = None if stamps is None else stamps[keep].reset_index(drop=True)
        return seconds[keep], keep, kept

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
        raise InputError(f"time column '{printable(self.column)}': cannot read '{shown}' at "
                         f"data row "
                         f"{row} as seconds or an ISO 8601 timestamp", file=self.file,
                         fix="write times as seconds or like 2024-05-01T12:00:00")

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
        if unread.any():
            if (~unread & _present(text)).any() and not unread[np.argmax(_present(text))]:
                raise UnreadNumber(int(np.argmax(unread)), str(text.iloc[np.argmax(unread)]))
            return None  # text from the first value on: timestamps
    out = out.copy()
    out[np.isin(out, NULL_VALUES) | np.isinf(out)] = np.nan  # an infinite time is no value
    return out


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
