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
    find_gaps,
    nominal_rate_hz,
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


def test_repeated_timestamps_are_dropped_and_counted_across_chunks():
    tracker = TimeTracker(1.0)
    t1, k1 = tracker.step(pd.Series([5.0, 6.0, 6.0, 7.0]))
    t2, k2 = tracker.step(pd.Series([7.0, 8.0]))
    assert t1.tolist() == [0.0, 1.0, 2.0] and k1.tolist() == [True, True, False, True]
    assert t2.tolist() == [3.0] and tracker.duplicates == 2
    assert tracker.source_start_s == 5.0


def test_iso_timestamps_give_seconds_from_origin():
    tracker = TimeTracker(1.0)
    t, _ = tracker.step(pd.Series(["2024-05-01T12:00:00", "2024-05-01T12:00:00.5",
                                   "2024-05-01 12:00:01.25"]))
    assert t.tolist() == [0.0, 0.5, 1.25]
    assert tracker.origin == pd.Timestamp("2024-05-01T12:00:00")


def test_unreadable_time_names_the_row():
    tracker = TimeTracker(1.0, file="f.csv", column="TIME")
    with pytest.raises(InputError, match="cannot read 'noon' at data row 2"):
        tracker.step(pd.Series(["2024-05-01T12:00:00", "noon"]))


def test_null_times_are_dropped():
    tracker = TimeTracker(1.0)
    t, keep = tracker.step(pd.Series([0.0, -999.25, 2.0, np.nan]))
    assert t.tolist() == [0.0, 2.0] and tracker.untimed == 2 and keep.sum() == 2


def test_spacing_summary():
    s = spacing_summary(np.array([0.0, 1.0, 3.0, 4.0]))
    assert (s["min"], s["median"], s["max"]) == (1.0, 1.0, 2.0)


@settings(max_examples=50, deadline=None)
@given(st.lists(st.floats(0.0, 5.0), min_size=2, max_size=60), st.integers(1, 20))
def test_chunking_does_not_change_time(steps, chunk):
    # Property: any split of the time column into chunks gives the same time_s and counts.
    t = pd.Series(np.round(np.cumsum(steps), 3) + 100.0)
    whole = TimeTracker(1.0)
    expected, _ = whole.step(t)
    tracker = TimeTracker(1.0)
    parts = [tracker.step(t.iloc[i:i + chunk].reset_index(drop=True))[0]
             for i in range(0, len(t), chunk)]
    np.testing.assert_array_equal(np.concatenate(parts), expected)
    assert tracker.duplicates == whole.duplicates
