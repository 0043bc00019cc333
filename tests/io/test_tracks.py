"""tracks.parquet producer (drillfric.io.tracks): envelopes, chunking, bounded memory."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from drillfric.io.tracks import INITIAL_BIN_S, TrackAccumulator, write_tracks
from drillfric.segmentation import IDLE, RIG_STATES, ROTATING_OFF_BOTTOM, UNKNOWN


def _log(hours: float, rate_hz: float, seed: int = 7) -> tuple[pd.DataFrame, np.ndarray]:
    """A synthetic log: noisy torque and hook load, rotating in the first half, idle after."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, hours * 3600.0, 1.0 / rate_hz)
    frame = pd.DataFrame({"time_s": t,
                          "surface_torque_Nm": 10e3 + 500.0 * rng.standard_normal(t.size),
                          "hookload_N": 8e5 + 2e3 * rng.standard_normal(t.size),
                          "surface_rpm": np.where(t < t[-1] / 2, 60.0, 0.0)})
    states = np.where(t < t[-1] / 2, ROTATING_OFF_BOTTOM, IDLE).astype(np.int8)
    return frame, states


def _feed(frame, states, rows, **kw) -> TrackAccumulator:
    acc = TrackAccumulator(**kw)
    for lo in range(0, len(frame), rows):
        acc.feed(frame.iloc[lo:lo + rows], states[lo:lo + rows])
    return acc


def test_single_sample_spike_survives_as_the_bin_maximum():
    """A one-sample torque spike (break-over) and a one-sample dip are in the envelope even
    after 10 h at 10 Hz are reduced to ≤ 500 bins (≥ 720 samples each); the mean barely
    moves (it is an average of the bin's samples)."""
    frame, states = _log(10.0, 10.0)
    spike, dip = 123_457, 250_001
    frame.loc[spike, "surface_torque_Nm"] = 60e3
    frame.loc[dip, "hookload_N"] = 1e5
    out = _feed(frame, states, 50_000, max_bins=500).result()
    assert len(out) <= 500
    row = np.searchsorted(out["time_s"], frame["time_s"][spike])
    near = out.iloc[max(row - 1, 0):row + 2]
    assert near["surface_torque_Nm_max"].max() == 60e3
    assert out["surface_torque_Nm_max"].max() == 60e3
    assert out["hookload_N_min"].min() == 1e5
    # the mean of a bin holding the spike moves by (60e3 − 10e3)/n_bin at most
    n_bin = len(frame) / len(out)
    assert near["surface_torque_Nm_mean"].max() < 10e3 + 3 * 500 + 50e3 / n_bin * 1.5


def test_chunked_feeding_equals_feeding_at_once():
    """Same bins, bit for bit in min/max and to rounding in the means, whatever the chunk
    size (the merges are exact; sums are added in a different order → 1e-12 relative)."""
    frame, states = _log(3.0, 20.0)
    whole = _feed(frame, states, len(frame), max_bins=1000).result()
    for rows in (977, 10_000, 65_536):
        parts = _feed(frame, states, rows, max_bins=1000).result()
        assert list(parts.columns) == list(whole.columns)
        assert len(parts) == len(whole)
        for col in whole.columns:
            if col.endswith(("_min", "_max")) or col == "rig_state":
                np.testing.assert_array_equal(parts[col], whole[col], err_msg=col)
            else:
                np.testing.assert_allclose(parts[col], whole[col], rtol=1e-12, err_msg=col)


def test_memory_is_bounded_for_a_log_of_unknown_length():
    """Without an expected duration, 24 h at 10 Hz fed in 200 000-row chunks never holds
    more than max_bins bins, and ends with between max_bins/2 and max_bins."""
    acc = TrackAccumulator(max_bins=400)
    rate, chunk_s = 10.0, 20_000.0
    peak = 0
    for start in np.arange(0.0, 86_400.0, chunk_s):
        t = np.arange(start, min(start + chunk_s, 86_400.0), 1.0 / rate)
        acc.feed(pd.DataFrame({"time_s": t, "surface_rpm": np.full(t.size, 50.0)}))
        peak = max(peak, acc.bins, acc._time_sum.size)
    assert peak <= 400
    assert 200 <= acc.bins <= 400
    # the width doubled from its start value: 0.1 s · 2^m ≥ 86 400 s / 400
    assert acc.width_s >= 86_400.0 / 400 and np.log2(acc.width_s / INITIAL_BIN_S) % 1 == 0


def test_expected_duration_sets_the_target_width():
    """Known duration: ~max_bins bins of duration/max_bins, no merge needed."""
    frame, states = _log(1.0, 10.0)
    acc = _feed(frame, states, 7000, expected_duration_s=frame["time_s"].iloc[-1],
                max_bins=360)
    out = acc.result()
    assert len(out) == 360
    assert acc.width_s == pytest.approx(frame["time_s"].iloc[-1] / 360, rel=1e-6)


def test_rig_state_is_the_most_frequent_code_and_unknown_without_states():
    frame, states = _log(1.0, 10.0)
    out = _feed(frame, states, 5000, max_bins=100).result()
    assert out["rig_state"].dtype == np.int8
    first, last = out["rig_state"].iloc[0], out["rig_state"].iloc[-1]
    assert RIG_STATES[first] == "rotating_off_bottom" and RIG_STATES[last] == "idle"
    acc = TrackAccumulator(max_bins=100)
    acc.feed(frame)
    assert (acc.result()["rig_state"] == UNKNOWN).all()


def test_gaps_nulls_and_clock_time(tmp_path):
    """A logging gap leaves no bins (no line is drawn across it); a channel that is null in
    a bin has NaN there; a log with clock time gets a UTC timestamp column."""
    t = np.r_[np.arange(0.0, 100.0, 1.0), np.arange(1000.0, 1100.0, 1.0)]
    torque = np.where(t < 50, np.nan, 5e3)
    stamp = pd.Timestamp("2024-03-01T06:00:00Z") + pd.to_timedelta(t, unit="s")
    frame = pd.DataFrame({"time_s": t, "surface_torque_Nm": torque, "timestamp": stamp})
    acc = TrackAccumulator(expected_duration_s=1100.0, max_bins=110)
    acc.feed(frame)
    out = acc.result()
    assert len(out) == 20  # 10 s bins: 10 before the gap, 10 after
    assert out["surface_torque_Nm_mean"].isna().sum() == 5
    assert out["timestamp"].iloc[0] == pd.Timestamp("2024-03-01T06:00:04.5Z")
    write_tracks(tmp_path / "tracks.parquet", out)
    back = pd.read_parquet(tmp_path / "tracks.parquet")
    assert back["surface_torque_Nm_max"].dtype == np.float32
    assert str(back["timestamp"].dt.tz) == "UTC"
