"""Time base: order, duplicates, gaps, nominal rate (drillfric.io.timebase)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from drillfric.errors import InputError
from drillfric.io.timebase import (
    TimeTracker,
    clock_at,
    find_gaps,
    nominal_rate_hz,
    origin_of,
    spacing_summary,
    summarize,
)


def test_nominal_rate_of_jittered_1hz_sampling():
    # DSATS-like: spacing uniform in [0, 2] s around 1 s; the median spacing is 1 s within
    # the sampling error of a median of 20 000 draws (≈ 1/sqrt(n) of the spread, ~0.01).
    rng = np.random.default_rng(1)
    t = np.cumsum(rng.uniform(0.0, 2.0, 20_000))
    assert nominal_rate_hz(t) == pytest.approx(1.0, abs=0.02)


def test_jitter_is_not_a_gap_but_an_outage_is():
    rng = np.random.default_rng(2)
    t = np.cumsum(rng.uniform(0.0, 2.0, 1000))
    t[500:] += 60.0
    gaps = find_gaps(t, max_gap_s=10.0, rate_hz=nominal_rate_hz(t))
    assert len(gaps) == 1 and gaps[0] == (t[499], t[500])


def test_gap_threshold_is_five_periods_for_slow_logs():
    # At 0.1 Hz a 20 s spacing is 2 periods: not a gap even though max_gap_s = 10 s.
    t = np.array([0.0, 10.0, 30.0, 40.0, 150.0])
    assert find_gaps(t, max_gap_s=10.0, rate_hz=0.1) == ((40.0, 150.0),)


def test_summarize():
    tb = summarize(np.arange(0.0, 10.0, 0.2), max_gap_s=10.0, duplicates_dropped=3)
    assert (tb.rows, tb.t_start_s, tb.gaps, tb.duplicates_dropped) == (50, 0.0, (), 3)
    assert tb.t_end_s == pytest.approx(9.8) and tb.rate_hz == pytest.approx(5.0)


def test_backwards_time_names_the_row():
    tracker = TimeTracker(1.0, file="log.csv")
    tracker.step(pd.Series([10.0, 11.0, 12.0]))
    with pytest.raises(InputError, match=r"log.csv: time goes backwards at data row 5 "
                                         r"\(12.5 s after 13 s\)"):
        tracker.step(pd.Series([13.0, 12.5]))


def _settled(tracker, times, values):
    """``tracker``'s settled rows of one chunk of times and values (step, then settle)."""
    t, keep, _ = tracker.step(pd.Series(times, dtype=float))
    rows = pd.DataFrame({"time_s": t, "x": np.asarray(values, dtype=float)[keep]})
    return tracker.settle(rows)


def test_repeated_timestamps_are_dropped_and_counted_across_chunks():
    """Identical repeats are kept once, across a chunk boundary too (the chunk's last time
    held back until the next chunk)."""
    tracker = TimeTracker(1.0)
    a = _settled(tracker, [5.0, 6.0, 6.0, 7.0], [1.0, 2.0, 2.0, 3.0])
    b = _settled(tracker, [7.0, 8.0], [3.0, 4.0])
    rest = tracker.flush()
    assert a["time_s"].tolist() == [0.0, 1.0] and b["time_s"].tolist() == [2.0]
    assert rest["time_s"].tolist() == [3.0] and tracker.duplicates == 2
    assert tracker.source_start_s == 5.0 and tracker.conflicts == 0


def test_duplicated_timestamps_with_different_values_are_all_dropped_in_any_chunking():
    """Regression (issue 30, ninth attack): the first row of a repeated time was kept,
    whichever value it held (μ_k 0.263 for 0.28 with 9 % of the times written twice). Rows
    of one time with different values are all dropped and counted — also when the repeat
    is the first row of the next chunk."""
    tracker = TimeTracker(1.0, file="log.csv")
    a = _settled(tracker, [0.0, 1.0, 2.0], [10.0, 11.0, 12.0])
    b = _settled(tracker, [2.0, 3.0, 3.0, 4.0], [99.0, 13.0, 13.0, 14.0])
    rest = tracker.flush()
    kept = pd.concat([a, b, rest], ignore_index=True)
    assert kept["time_s"].tolist() == [0.0, 1.0, 3.0, 4.0]
    assert kept["x"].tolist() == [10.0, 11.0, 13.0, 14.0]
    assert (tracker.conflicts, tracker.conflict_times, tracker.duplicates) == (2, 1, 1)
    note = tracker.conflicts_note(len(kept))
    assert note.startswith("log.csv: 1 of the log's 5 timestamps (20.0 %) are repeated with "
                           "other values (2 rows, the first at 2 s)")
    assert "check the recorder" in note
    tracker.check_conflicts(len(kept))  # 20 %: warned, not refused
    tracker.conflict_times += 1
    with pytest.raises(InputError, match=r"log.csv: 2 of the log's 6 timestamps \(33 %\) are "
                                         r"repeated with other values"):
        tracker.check_conflicts(len(kept))


def test_a_time_column_of_one_value_with_changing_values_is_named():
    tracker = TimeTracker(1.0, file="log.csv", column="TIME")
    kept = _settled(tracker, [7.0] * 5, [1.0, 2.0, 3.0, 4.0, 5.0])
    assert not len(kept) and not len(tracker.flush())
    with pytest.raises(InputError, match="time column 'TIME' holds one value for all 5 rows"):
        tracker.check_conflicts(0)


def test_iso_timestamps_give_seconds_from_origin():
    tracker = TimeTracker(1.0)
    t, _, _ = tracker.step(pd.Series(["2024-05-01T12:00:00", "2024-05-01T12:00:00.5",
                                   "2024-05-01 12:00:01.25"]))
    assert t.tolist() == [0.0, 0.5, 1.25]
    assert tracker.origin == pd.Timestamp("2024-05-01T12:00:00")


def test_unreadable_time_names_the_row():
    tracker = TimeTracker(1.0, file="f.csv", column="TIME")
    with pytest.raises(InputError, match="cannot read 'noon' at data row 2"):
        tracker.step(pd.Series(["2024-05-01T12:00:00", "noon"]))


def test_null_times_are_dropped():
    tracker = TimeTracker(1.0)
    t, keep, _ = tracker.step(pd.Series([0.0, -999.25, 2.0, np.nan]))
    assert t.tolist() == [0.0, 2.0] and tracker.untimed == 2 and keep.sum() == 2


def test_spacing_summary():
    s = spacing_summary(np.array([0.0, 1.0, 3.0, 4.0]))
    assert (s["min"], s["median"], s["max"]) == (1.0, 1.0, 2.0)


@settings(max_examples=50, deadline=None)
@given(st.lists(st.tuples(st.sampled_from([0.0, 0.0, 0.5, 1.0, 2.5]), st.integers(0, 2)),
                min_size=2, max_size=60), st.integers(1, 20))
def test_chunking_does_not_change_time(steps, chunk):
    # Property: any split of the time column into chunks gives the same rows kept, time_s
    # and counts — repeated times (with the same or other values) at the boundaries too.
    t = pd.Series(np.cumsum([s for s, _ in steps]) + 100.0)
    x = np.array([v for _, v in steps], dtype=float)
    whole = TimeTracker(1.0)
    expected = pd.concat([_settled(whole, t, x), whole.flush()], ignore_index=True)
    tracker = TimeTracker(1.0)
    parts = [_settled(tracker, t.iloc[i:i + chunk].reset_index(drop=True), x[i:i + chunk])
             for i in range(0, len(t), chunk)] + [tracker.flush()]
    pd.testing.assert_frame_equal(pd.concat([p for p in parts if p is not None],
                                            ignore_index=True), expected)
    assert (tracker.duplicates, tracker.conflicts, tracker.conflict_times) == \
        (whole.duplicates, whole.conflicts, whole.conflict_times)


# ------------------------------------------------------------ clock times in integer ns
_ORIGINS = st.integers(0, 2**62).map(lambda ns: pd.Timestamp(ns, unit="ns", tz="UTC"))


@settings(max_examples=200, deadline=None)
@given(origin=_ORIGINS, seconds=st.floats(0.0, 4.0e6, allow_nan=False))
def test_clock_at_fits_a_microsecond_column_whatever_the_origin(origin, seconds):
    """Issue 30 (1): origin + a float time turned into a timedelta left stray nanoseconds
    that estimates.parquet's timestamp[us] column refused ("would lose data"). clock_at is
    whole microseconds, and within half a microsecond (+ the float's own ulp) of the sum."""
    stamp = clock_at(origin, seconds)
    assert stamp.value % 1000 == 0
    exact = origin.value + seconds * 1e9
    assert abs(stamp.value - exact) <= 500 + abs(exact) * 2.0**-52


@settings(max_examples=200, deadline=None)
@given(origin=_ORIGINS, offset_ns=st.integers(0, 52 * 86_400 * 10**9))
def test_origin_of_finds_the_readers_origin_again_exactly(origin, offset_ns):
    """A row's stamp minus its time_s (the stamp's offset from the origin / 10⁹ as a
    float) gives the origin back to the nanosecond within 52 days of log."""
    stamp = origin + pd.Timedelta(offset_ns, unit="ns")
    seconds = (stamp - origin) / pd.Timedelta(seconds=1)
    assert origin_of(stamp, seconds) == origin


def test_clock_at_of_arrays_keeps_missing_times_missing():
    origin = pd.Timestamp("2026-03-01T06:00:00.123456789Z")
    out = clock_at(origin, np.array([0.0, np.nan, 1.5]))
    assert out[0] == pd.Timestamp("2026-03-01T06:00:00.123457Z") and pd.isna(out[1])
    assert out[2] == pd.Timestamp("2026-03-01T06:00:01.623457Z")


def test_tracker_hands_back_the_parsed_stamps_not_a_float_round_trip():
    """The rows keep the timestamps as parsed (nanoseconds), not origin + float seconds."""
    text = pd.Series(["2026-03-01T06:00:00.000000001Z", "2026-03-01T06:00:00.049788999Z",
                      "2026-03-01T06:00:00.049788999Z", "2026-03-01T06:00:00.100241003Z"])
    time_s, keep, stamps = TimeTracker(1.0).step(text)
    assert keep.tolist() == [True, True, True, True]  # the repeat is settle's to drop
    assert [s.value % 10**9 for s in stamps] == [1, 49_788_999, 49_788_999, 100_241_003]
    assert time_s[1] == pytest.approx(0.049788998)
