"""Rig-state classification and segmentation (drillfric.segmentation, issue 6 part 1).

Synthetic frames are built so that every expected state and segment boundary follows from
the rules in docs/segmentation.md by hand (1 Hz samples, exact thresholds: no tolerance is
needed on indices). The DSATS test compares with published labels (source: SPE DSATS
Project Data Clarity, RigStatesForSampleData1.txt) and skips when the data are absent.
"""

from __future__ import annotations

import importlib.util

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from drillfric.config import config_from_dict
from drillfric.errors import InputError
from drillfric.segmentation import (
    BACK_REAMING,
    COMBINED_MOTION_KINDS,
    IDLE,
    IN_SLIPS,
    KINDS,
    REAMING,
    RIG_STATES,
    ROTATING_OFF_BOTTOM,
    ROTATING_ON_BOTTOM,
    SLIDING_ON_BOTTOM,
    TRIPPING,
    TURNING_STATES,
    UNKNOWN,
    Segmenter,
    _classify_kernel,
    _column,
    _compiled_kernel,
    _kind_runs,
    axial_motion,
    classify,
    pumps_on,
    segment,
)
from tests.conftest import REAL_DATA, REPO


def cfg(**seg):
    return config_from_dict({"segmentation": seg} if seg else {})


def frame(rpm, **cols) -> pd.DataFrame:
    """1 Hz frame with torque proportional to speed (never null unless given)."""
    rpm = np.asarray(rpm, dtype=float)
    out = {"time_s": np.arange(rpm.size, dtype=float), "surface_rpm": rpm,
           "surface_torque_Nm": 100.0 * np.nan_to_num(rpm)}
    out.update({k: np.asarray(v, dtype=float) for k, v in cols.items()})
    return pd.DataFrame(out)


def blocks(*parts):
    """Concatenate (value, count) pairs."""
    return np.concatenate([np.full(n, v, dtype=float) for v, n in parts])


# ----------------------------------------------------------------------------------------
# classification


def test_state_codes_are_positions():
    assert RIG_STATES[ROTATING_OFF_BOTTOM] == "rotating_off_bottom"
    assert RIG_STATES[ROTATING_ON_BOTTOM] == "rotating_on_bottom"
    assert RIG_STATES[UNKNOWN] == "unknown"
    assert len(set(RIG_STATES)) == len(RIG_STATES)


def test_rpm_and_torque_only_gives_rotating_or_not():
    # 0.5 RPM is below rotating_stop_rpm (1 RPM): rotation has ended
    rpm = blocks((0, 20), (60, 50), (0.5, 10), (np.nan, 5), (80, 15))
    states = classify(frame(rpm), cfg())
    expected = blocks((IDLE, 20), (ROTATING_OFF_BOTTOM, 50), (IDLE, 10), (UNKNOWN, 5),
                      (ROTATING_OFF_BOTTOM, 15))
    np.testing.assert_array_equal(states, expected)


def test_rotating_threshold_is_strict():
    states = classify(frame([5.0, 5.01]), cfg(rotating_rpm=5.0))
    np.testing.assert_array_equal(states, [IDLE, ROTATING_OFF_BOTTOM])


def test_bit_and_hole_depth_on_bottom():
    # within on_bottom_m (0.5 m) of the hole: on bottom; 2 m above: off bottom (the 1.6-m
    # step in one sample is a pull at 1.6 m/s: the reaming gate is opened here)
    bit = blocks((999.6, 10), (998.0, 10))
    states = classify(frame(np.full(20, 60.0), bit_depth_m=bit, hole_depth_m=np.full(20, 1000)),
                      cfg(ream_speed_m_s=10.0))
    np.testing.assert_array_equal(states, blocks((ROTATING_ON_BOTTOM, 10),
                                                 (ROTATING_OFF_BOTTOM, 10)))


def test_back_reaming_at_0_2_m_s_is_its_own_state_not_pure_rotation():
    """Issue 22: turning at 40 RPM while pulling out at 0.2 m/s was segmented as pure
    rotation (turning was tested before tripping); it is back-reaming, running in is reaming,
    from the bit depth or from the block position, and slow drilling stays on bottom."""
    t = np.arange(300.0)
    up = 2000.0 - 0.2 * np.clip(t - 100.0, 0.0, None)
    hole = np.full(300, 2500.0)
    states = classify(frame(np.full(300, 40.0), bit_depth_m=up, hole_depth_m=hole), cfg())
    assert np.all(states[:100] == ROTATING_OFF_BOTTOM)
    assert np.all(states[130:] == BACK_REAMING)
    block = classify(frame(np.full(300, 40.0), block_position_m=0.2 * np.clip(t - 100.0, 0, 30)),
                     cfg(start_bit_depth_m=2000.0))
    assert np.all(block[110:125] == BACK_REAMING) and np.all(block[170:] == ROTATING_OFF_BOTTOM)
    down = classify(frame(np.full(300, 40.0), bit_depth_m=1900.0 + 0.2 * t,
                          hole_depth_m=np.full(300, 2500.0)), cfg())
    assert np.all(down[30:] == REAMING)
    drilling = classify(frame(np.full(300, 40.0), bit_depth_m=2000.0 + 0.01 * t), cfg())
    assert np.all(drilling == ROTATING_ON_BOTTOM)
    slow = classify(frame(np.full(300, 40.0), bit_depth_m=up, hole_depth_m=hole),
                    cfg(ream_speed_m_s=0.5))
    assert np.all(slow == ROTATING_OFF_BOTTOM)


def test_trip_before_a_stand_does_not_label_its_first_seconds_reaming():
    """Issue 35: the demo's rig state read "reaming" for ~6 s at each stand start: the bit
    ran in at 0.5 m/s, stopped, and rotation started 6 s later while the 5-s smoothed bit
    speed still exceeded ream_speed_m_s. Reaming now needs the bit to have moved
    REAM_MIN_TRAVEL_M within that travel's time at the gate speed; a bit at rest (depth
    jitter of a few cm included) turning after a trip is rotating off bottom."""
    t = np.arange(0.0, 120.0, 0.1)
    bit = 2200.0 + 0.5 * np.clip(t, 0.0, 40.0)  # runs in 20 m, stops at 40 s
    jitter = 0.02 * np.sin(2 * np.pi * t / 0.7)
    rpm = np.where(t >= 46.0, 60.0, 0.0)
    for depth in (bit, bit + jitter):
        f = pd.DataFrame({"time_s": t, "surface_rpm": rpm, "surface_torque_Nm": 100.0 * rpm,
                          "bit_depth_m": depth, "hole_depth_m": np.full(t.size, 2300.0)})
        states = classify(f, cfg())
        assert np.all(states[(t > 5.0) & (t < 40.0)] == TRIPPING)
        assert np.all(states[t >= 46.0] == ROTATING_OFF_BOTTOM), RIG_STATES[states[460]]
    # turning while it still moves is reaming, from the first samples
    moving = 2200.0 + 0.2 * t
    states = classify(frame(np.full(t.size, 60.0)).assign(
        time_s=t, bit_depth_m=moving, hole_depth_m=np.full(t.size, 2300.0)), cfg())
    assert np.all(states[t >= 30.0] == REAMING)


def test_back_reaming_segment_carries_its_axial_speed():
    """Issue 22, issue 36 item 2: a back-reaming stretch is a segment of its own, cut from
    the rotation before it, and carries the pipe's steady speed (signed, − pulling out) and
    when it moves, for the estimators' moving load case (docs/theory.md §3.3)."""
    t = np.arange(400.0)
    bit = 2000.0 - 0.2 * np.clip(t - 150.0, 0.0, 100.0)
    segs = segment(frame(np.r_[np.zeros(10), np.full(390, 40.0)], bit_depth_m=bit,
                         hole_depth_m=np.full(400, 2500.0)), cfg())
    kinds = [(s.kind, s.status) for s in segs]
    assert kinds[:2] == [("off_bottom_rotating", "ok"), ("back_reaming", "ok")]
    ream = segs[1]
    assert ream.axial_speed_m_s == pytest.approx(-0.2, rel=1e-6)
    assert ream.axial_from_s == pytest.approx(150.0, abs=3.0)
    assert ream.axial_to_s == pytest.approx(250.0, abs=3.0)
    assert ream.bit_depth_max_m < 2000.0
    assert segs[0].axial_speed_m_s is None


@pytest.mark.parametrize(("depth", "words"), [
    (lambda t: 2000.0 - 0.2 * np.clip(t - 150.0, 0.0, None), "over 49 m"),  # 247 s at 0.2
    (lambda t: 2000.0 - 0.001 * np.clip(t - 150.0, 0.0, 100.0) ** 2, "unsteady speed"),
])
def test_reaming_that_one_speed_or_depth_cannot_stand_for_is_skipped_with_why(depth, words):
    """A travel longer than MAX_REAM_TRAVEL_M (the string's side forces change along it) or a
    speed that is not steady is not estimated: skipped, the reason in the message."""
    t = np.arange(400.0)
    segs = segment(frame(np.r_[np.zeros(10), np.full(390, 40.0)], bit_depth_m=depth(t),
                         hole_depth_m=np.full(400, 2500.0)), cfg())
    moving = [s for s in segs if s.kind == "back_reaming"]
    assert moving and all(s.status == "skipped" for s in moving)
    assert words in moving[0].message and "withheld" in moving[0].message


def test_axial_motion_reads_the_speed_through_depth_quantisation():
    """0.05 m/s logged at 1 Hz with a 0.01-m depth resolution: the median rate over 4 s is
    the speed, steady within AXIAL_STEADY."""
    t = np.arange(0.0, 300.0)
    depth = np.round(2000.0 + 0.05 * np.clip(t - 50.0, 0.0, 200.0), 2)
    motion = axial_motion("reaming", depth, t)
    assert motion.withheld == "" and motion.speed_m_s == pytest.approx(0.05, rel=0.01)
    assert abs(motion.from_s - 50.0) <= 3.0 and abs(motion.to_s - 250.0) <= 3.0


def test_hole_depth_is_running_max_of_bit_depth():
    # drill 0.5 m in 50 s (36 m/h), pull up 3 m, go back down to 0.2 m above the bottom
    # (in steps: the speed gates are switched off with huge max_rop_m_h, ream_speed_m_s)
    bit = np.concatenate((np.linspace(1000, 1000.5, 50), np.full(20, 997.5),
                          np.full(10, 1000.3)))
    states = classify(frame(np.full(bit.size, 60.0), bit_depth_m=bit),
                      cfg(max_rop_m_h=1e6, ream_speed_m_s=100.0))
    np.testing.assert_array_equal(states, blocks((ROTATING_ON_BOTTOM, 50),
                                                 (ROTATING_OFF_BOTTOM, 20),
                                                 (ROTATING_ON_BOTTOM, 10)))


def test_fast_advance_below_the_known_hole_is_not_drilling():
    """A record starting mid-trip: the bit runs in at 1 m/s (3600 m/h > max_rop_m_h), always
    at the running maximum, yet is off bottom — turning while running in: reaming; once
    stopped it is on bottom after the smoothed speed (time constant 5 s, factor 0.8 per 1 s
    sample) has decayed below max_rop_m_h = 0.083 m/s: 0.8^12 = 0.069 (0.8^11 = 0.086),
    i.e. from row 72. Reaming lasts while the bit moves (issue 35: REAM_MIN_TRAVEL_M within
    its time at ream_speed_m_s, 2 s after the last move at row 60); between, the bit at rest
    turns off bottom (the smoothed speed still above max_rop_m_h).
    """
    bit = np.concatenate((np.arange(500.0, 560.0), np.full(30, 560.0)))
    states = classify(frame(np.full(bit.size, 60.0), bit_depth_m=bit), cfg())
    assert np.all(states[2:63] == REAMING)
    assert np.all(states[63:72] == ROTATING_OFF_BOTTOM)
    assert np.all(states[72:] == ROTATING_ON_BOTTOM)
    faster = classify(frame(np.full(bit.size, 60.0), bit_depth_m=bit), cfg(max_rop_m_h=4000.0))
    assert np.all(faster[1:] == ROTATING_ON_BOTTOM)


def test_block_position_reckoning_ignores_block_travel_in_slips():
    """Drill 1 m (72 m/h), pull 10 m off bottom, set slips, raise the empty block 27 m (new
    stand), pull the slips and lower 10 m: the bit is back on bottom.

    The string hangs still in the slips, so the 27 m of block travel there do not move the
    bit; without in-slips detection the reckoning puts the bit 27 m higher (off bottom).
    After lowering at 1 m/s the smoothed speed needs 11 samples to fall below max_rop_m_h.
    """
    block = np.concatenate((np.linspace(32.0, 31.0, 51), np.linspace(32.0, 41.0, 10),
                            np.linspace(41.0, 68.0, 28), np.linspace(67.0, 58.0, 10),
                            np.full(30, 58.0)))
    hook = np.concatenate((np.full(61, 800e3), np.full(28, 150e3), np.full(40, 800e3)))
    rpm = np.concatenate((np.full(51, 60.0), np.zeros(48), np.full(30, 60.0)))
    data = frame(rpm, block_position_m=block, hookload_N=hook)
    states = classify(data, cfg(slips_hookload_N=300e3))
    assert np.all(states[1:51] == ROTATING_ON_BOTTOM)
    assert np.all(states[51:61] == TRIPPING)
    assert np.all(states[61:89] == IN_SLIPS)
    assert np.all(states[89:99] == TRIPPING)
    assert np.all(states[110:] == ROTATING_ON_BOTTOM)
    no_slips = classify(data, cfg())
    # 27 m too high, still running in: reaming while the bit moves (the lowering ends at row
    # 98; issue 35: 2 s after the last 0.1-m move), not until the smoothed speed (0.89 m/s
    # there) has decayed below ream_speed_m_s, which labelled 12 s at rest as reaming
    assert np.all(no_slips[99:101] == REAMING)
    assert np.all(no_slips[101:] == ROTATING_OFF_BOTTOM)


def test_block_reckoning_reports_depth_only_from_a_start_depth():
    block = np.linspace(30.0, 20.0, 40)
    data = frame(np.full(40, 60.0), block_position_m=block)
    relative = segment(data, cfg())
    assert np.isnan(relative[0].bit_depth_m)
    absolute = segment(data, cfg(start_bit_depth_m=1000.0))
    assert absolute[0].bit_depth_m == pytest.approx(1005.0)
    assert absolute[0].bit_depth_min_m == pytest.approx(1000.0)
    assert absolute[0].bit_depth_max_m == pytest.approx(1010.0)


def test_wob_decides_on_bottom_without_depths():
    states = classify(frame(np.full(4, 60.0), wob_N=[0.0, 5e3, 10e3, 50e3]), cfg())
    np.testing.assert_array_equal(states, [ROTATING_OFF_BOTTOM] * 3 + [ROTATING_ON_BOTTOM])


def test_non_rotating_states_sliding_idle_tripping():
    # on bottom with pumps on: sliding; pumps off: idle; moving up 1 m/s off bottom: tripping
    bit = np.concatenate((np.full(10, 1000.0), np.full(10, 1000.0), 1000.0 - np.arange(1, 11)))
    spp = blocks((5e6, 10), (0.0, 20))
    states = classify(frame(np.zeros(30), bit_depth_m=bit, standpipe_pressure_Pa=spp), cfg())
    np.testing.assert_array_equal(states, blocks((SLIDING_ON_BOTTOM, 10), (IDLE, 10),
                                                 (TRIPPING, 10)))


def test_pump_channel_preference_flow_then_rate_then_pressure():
    data = frame(np.zeros(3), bit_depth_m=np.full(3, 1000.0), flow_in_m3_s=[0.0, 0.03, 0.0],
                 standpipe_pressure_Pa=[9e6, 9e6, 9e6])
    np.testing.assert_array_equal(classify(data, cfg()), [IDLE, SLIDING_ON_BOTTOM, IDLE])


# ----------------------------------------------------------------------------------------
# segmentation


def test_rotation_start_stop_gives_one_segment_per_stretch():
    rpm = blocks((0, 20), (60, 100), (0, 30), (70, 60), (0, 5))
    segs = segment(frame(rpm), cfg())
    assert [(s.i_start, s.i_end) for s in segs] == [(20, 120), (150, 210)]
    assert [s.id for s in segs] == [1, 2]
    assert segs[0].kind == "off_bottom_rotating" and segs[0].status == "ok"
    assert segs[0].t_start_s == 20.0 and segs[0].t_end_s == 119.0
    assert segs[0].duration_s == 99.0
    assert np.isnan(segs[0].bit_depth_m)


def test_short_segment_kept_as_skipped_with_reason():
    segs = segment(frame(blocks((0, 5), (60, 12), (0, 5))), cfg())
    assert len(segs) == 1
    assert segs[0].status == "skipped"
    assert segs[0].message == "too short: 11 s < 30 s"


def test_long_time_gap_splits_a_segment():
    data = frame(np.full(100, 60.0))
    data.loc[50:, "time_s"] += 40.0  # 41 s between rows 49 and 50
    assert [(s.i_start, s.i_end) for s in segment(data, cfg())] == [(0, 50), (50, 100)]
    assert len(segment(data, cfg(max_gap_s=60.0))) == 1


def test_a_few_nulls_are_bridged_many_skip_the_segment():
    """Up to 5 % null torque samples are bridged (a dropped sample is normal in rig logs);
    more skip the segment with the reason."""
    data = frame(np.full(100, 60.0))
    data.loc[40:42, "surface_torque_Nm"] = np.nan
    (seg,) = segment(data, cfg())
    assert (seg.i_start, seg.i_end, seg.status) == (0, 100, "ok")
    assert seg.message == "nulls bridged by interpolation: surface_torque_Nm (3 samples)"
    data.loc[40:49, "surface_torque_Nm"] = np.nan
    (seg,) = segment(data, cfg())
    assert seg.status == "skipped" and "more than 5%" in seg.message


def test_short_null_run_in_speed_is_bridged_long_one_splits():
    short = frame(blocks((60, 50), (np.nan, 5), (60, 50)))
    (seg,) = segment(short, cfg())
    assert seg.status == "ok" and "bridged by interpolation: surface_rpm (5 samples)" \
        in seg.message
    long = frame(blocks((60, 50), (np.nan, 30), (60, 50)))
    segs = segment(long, cfg())
    assert [(s.i_start, s.i_end, s.status) for s in segs] == [(0, 50, "ok"), (80, 130, "ok")]


def test_on_off_bottom_change_splits_only_when_it_persists():
    hole = np.full(200, 1000.0)
    bit = blocks((1000.0, 100), (995.0, 100))
    bit[40:45] = 995.0  # 5 s off bottom: shorter than kind_dwell_s = 20 s, absorbed
    steps = cfg(max_rop_m_h=1e6, ream_speed_m_s=100.0)  # depth steps: no speed gate
    segs = segment(frame(np.full(200, 60.0), bit_depth_m=bit, hole_depth_m=hole), steps)
    assert [(s.kind, s.i_start, s.i_end) for s in segs] == [
        ("on_bottom_rotating", 0, 100), ("off_bottom_rotating", 100, 200)]
    assert segs[0].bit_depth_m == 1000.0
    assert segs[0].bit_depth_min_m == 995.0 and segs[0].bit_depth_max_m == 1000.0
    finer = segment(frame(np.full(200, 60.0), bit_depth_m=bit, hole_depth_m=hole),
                    cfg(kind_dwell_s=3.0, max_rop_m_h=1e6, ream_speed_m_s=100.0))
    assert [(s.i_start, s.i_end) for s in finer] == [(0, 40), (40, 45), (45, 100), (100, 200)]


def test_missing_speed_channel_is_an_input_error():
    with pytest.raises(InputError, match="surface_rpm"):
        segment(pd.DataFrame({"time_s": [0.0, 1.0], "surface_torque_Nm": [1.0, 1.0]}), cfg())


def test_empty_frame_has_no_segments():
    assert segment(frame(np.zeros(0)), cfg()) == []
    assert classify(frame(np.zeros(0)), cfg()).size == 0


def test_precomputed_states_are_used():
    data = frame(np.full(60, 60.0))
    states = np.full(60, ROTATING_ON_BOTTOM, np.int8)
    assert segment(data, cfg(), states=states)[0].kind == "on_bottom_rotating"
    with pytest.raises(ValueError, match="59 values for 60 rows"):
        segment(data, cfg(), states=states[1:])


def test_in_slips_rotation_is_not_a_segment():
    # the top drive spins a new stand while the string sits in the slips
    data = frame(np.full(60, 25.0), hookload_N=np.full(60, 100e3))
    assert segment(data, cfg(slips_hookload_N=300e3)) == []


# ----------------------------------------------------------------------------------------
# streaming


def _random_well(seed: int, n_regimes: int = 40, depth: str = "bit_depth_m") -> pd.DataFrame:
    """Rotation on/off, on/off bottom, slips, nulls and gaps in random regimes (1 Hz).

    ``depth`` is the depth channel written: ``bit_depth_m`` or ``block_position_m`` (the
    block then moves opposite to the bit, and travels empty while in the slips).
    """
    rng = np.random.default_rng(seed)
    rpm, bit, block, hook, gaps = [], [], [], [], []
    depth_m, block_m, bit_m = 1000.0, 30.0, 1000.0
    for _ in range(n_regimes):
        n = int(rng.integers(1, 80))
        kind = rng.integers(0, 6)
        rpm.append(np.full(n, 0.0 if kind in (0, 5) else 60.0))
        if kind == 4:
            rpm[-1][rng.integers(0, n)] = np.nan
        hook.append(np.full(n, 100e3 if kind == 5 else 800e3))
        if kind == 5:  # in slips: the block travels, the bit does not
            block_m += float(rng.uniform(-5.0, 5.0))
        if kind == 1:
            depth_m += 0.01 * n
        if kind != 5:  # the bit hangs still in the slips
            bit_m = depth_m - (0.0 if kind in (1, 2) else float(rng.uniform(1.0, 5.0)))
        bit.append(np.full(n, bit_m))
        block.append(np.full(n, block_m + 1000.0 - bit_m))
        gaps.append(np.where(rng.random(n) < 0.01, 30.0, 1.0))
    columns = {"bit_depth_m": np.concatenate(bit), "block_position_m": np.concatenate(block)}
    data = frame(np.concatenate(rpm), hookload_N=np.concatenate(hook),
                 **{depth: columns[depth]})
    data["time_s"] = np.cumsum(np.concatenate(gaps))
    return data


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10_000), cuts=st.lists(st.integers(1, 1999), max_size=12),
       depth=st.sampled_from(["bit_depth_m", "block_position_m"]))
def test_segmenter_matches_segment_for_any_chunking(seed, cuts, depth):
    data = _random_well(seed, depth=depth)
    config = cfg(min_segment_s=10.0, kind_dwell_s=5.0, slips_hookload_N=300e3,
                 start_bit_depth_m=1000.0)
    bounds = [0, *sorted(c for c in set(cuts) if c < len(data)), len(data)]
    streamer = Segmenter(config)
    streamed = []
    for a, b in zip(bounds[:-1], bounds[1:], strict=True):
        streamed += streamer.feed(data.iloc[a:b].reset_index(drop=True))
    streamed += streamer.close()
    whole = segment(data, config)
    assert len(whole) > 0
    assert streamed == whole


def test_block_reckoning_follows_the_bit_in_a_random_well():
    # the reckoned depth equals the true bit depth when the slips are detected
    data = _random_well(7, depth="block_position_m")
    truth = _random_well(7)["bit_depth_m"].to_numpy()
    config = cfg(slips_hookload_N=300e3, start_bit_depth_m=float(truth[0]))
    segs = segment(data, config)
    assert len(segs) > 5
    for seg in segs:
        np.testing.assert_allclose(seg.bit_depth_m,
                                   np.median(truth[seg.i_start:seg.i_end]), atol=1e-9)


def test_compiled_kernel_matches_its_python_source():
    """The numba kernel and its plain-Python source agree exactly (NaN comparisons, integer
    codes); the Python source is the readable oracle and runs small inputs."""
    data = _random_well(3, depth="block_position_m")
    data["wob_N"] = np.linspace(0.0, 20e3, len(data))
    data["surface_torque_Nm"] = np.where(data["surface_rpm"] > 1.0, 5e3, 100.0)
    args = [_column(data, c) for c in ("time_s", "surface_rpm", "surface_torque_Nm",
                                        "hookload_N", "bit_depth_m", "hole_depth_m",
                                        "block_position_m", "wob_N")]
    args += [pumps_on(data, cfg()), 1, 5.0, 2.5, 10.0, 0.5, 300e3, 0.5, 10e3, 0.1, 300.0 / 3600.0,
             0.05]
    carry = [np.nan, np.nan, 0.0, np.nan, 0.0, 0.0, 0.0, 0.0, np.nan, np.nan, np.nan]
    fast = _compiled_kernel()(*args, np.array(carry))
    slow = _classify_kernel(*args, np.array(carry))
    np.testing.assert_array_equal(fast[0], slow[0])
    np.testing.assert_array_equal(fast[1], slow[1])


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10_000))
def test_segments_are_ordered_disjoint_and_rotating(seed):
    data = _random_well(seed)
    config = cfg(kind_dwell_s=5.0, min_rotation_s=1e-6)  # drop only one-sample runs
    states = classify(data, config)
    segs = segment(data, config)
    rotating = np.isin(states, TURNING_STATES)
    for prev, seg in zip(segs, segs[1:], strict=False):
        assert prev.i_end <= seg.i_start and seg.id == prev.id + 1
    covered = np.zeros(len(data), bool)
    for seg in segs:
        inside = states[seg.i_start:seg.i_end]
        assert rotating[seg.i_start]
        assert np.all(np.isin(inside, (*TURNING_STATES, UNKNOWN)))
        covered[seg.i_start:seg.i_end] = True
        assert seg.duration_s == seg.t_end_s - seg.t_start_s >= 0.0
    # every rotating sample is in a segment, except one-sample runs (zero duration: noise)
    left_out = rotating & ~covered
    pairs = np.flatnonzero(left_out[:-1] & left_out[1:])
    assert np.all(np.diff(data["time_s"].to_numpy())[pairs] > config.segmentation.max_gap_s)


# ----------------------------------------------------------------------------------------
# real data: DSATS rig-state labels


def _validation_module():
    path = REPO / "benchmarks" / "validate_segmentation_dsats.py"
    spec = importlib.util.spec_from_file_location("validate_segmentation_dsats", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def dsats_result():

    data = REAL_DATA / "dsats_1hz"
    if not (data / "SampleData1.csv").is_file():
        pytest.skip(f"real field data not available at {data}")
    return _validation_module().evaluate(data)


def test_dsats_drilling_agreement(dsats_result):
    """Regression guard at the measured values (docs/validation.md).

    The thresholds were tuned on the first half (t < 25 000 s): 95.0 % agreement there.
    On all the data 88.8 %: the held-out half holds three stretches labelled 8 that show
    every sign of slide drilling (new depth, steady descent, WOB, motor pressure).
    """
    assert dsats_result["tuning half"]["accuracy"] >= 0.945
    assert dsats_result["all"]["accuracy"] >= 0.885
    assert dsats_result["all"]["recall"] >= 0.92
    segs = dsats_result["segments"]
    assert sum(s.status == "ok" for s in segs) >= 20
    kinds = {s.kind for s in segs}
    assert {"on_bottom_rotating", "off_bottom_rotating"} <= kinds <= set(KINDS.values())
    assert all(s.status == "skipped" or s.axial_speed_m_s is not None
               for s in segs if s.kind in COMBINED_MOTION_KINDS)


@pytest.mark.xfail(strict=True, reason="acceptance target (issue 6) not met on the whole "
                   "record: 88.8 %; see docs/validation.md")
def test_dsats_drilling_agreement_meets_acceptance(dsats_result):
    assert dsats_result["all"]["accuracy"] >= 0.90


def _soft_torque_log(dip_torque: float, dip_s: float = 1.5) -> pd.DataFrame:
    """A soft-torque drive: the top drive turns at 80 RPM for 4 s, then almost stops for
    ``dip_s`` while the string stays wound (``dip_torque``), 30 times; 10 Hz."""
    t = np.arange(0.0, 30 * (4.0 + dip_s) + 20.0, 0.1)
    phase = np.mod(t - 10.0, 4.0 + dip_s)
    turning = (t >= 10.0) & (t < t[-1] - 10.0)
    dip = turning & (phase >= 4.0)
    rpm = np.where(turning, np.where(dip, 0.3, 80.0), 0.0)
    torque = np.where(turning, np.where(dip, dip_torque, 12e3), 0.0)
    return pd.DataFrame({"time_s": t, "surface_rpm": rpm, "surface_torque_Nm": torque})


def test_soft_torque_dips_while_wound_stay_one_segment():
    """A regression: a soft-torque drive's dips to ~0 RPM while the string stays wound cut
    one operation into ~30 pieces, none long enough to converge."""
    segs = segment(_soft_torque_log(dip_torque=11e3), cfg())
    assert len(segs) == 1 and segs[0].duration_s > 150.0


def test_a_stop_with_the_torque_released_ends_the_rotation():
    """Released torque (below half the rotating level) is a real stop: one piece per turn."""
    segs = segment(_soft_torque_log(dip_torque=1e3), cfg(min_segment_s=1.0))
    assert len(segs) == 30


def test_a_loaded_stop_longer_than_the_dip_limit_ends_the_rotation():
    segs = segment(_soft_torque_log(dip_torque=11e3, dip_s=15.0), cfg(min_segment_s=1.0))
    assert len(segs) == 30


def test_block_reckoning_without_a_slips_threshold_is_refused_not_silently_wrong(tmp_path):
    """Issue 33 item 7: the DSATS log run with only a start depth put the bit at 896–926 m
    (it drilled 934–1120 m): every connection's block travel in the slips moved the bit too.
    Reckoning from the block without ``slips_hookload_N`` is now one line naming it; with it,
    the depths follow the string only off the slips."""
    from click.testing import CliRunner
    from drillfric.cli.main import cli

    t = np.arange(0.0, 400.0, 1.0)
    in_slips = (t >= 150.0) & (t < 250.0)  # a connection: the block goes up 28 m empty
    block = np.where(t < 150.0, 30.0 - 0.1 * t, np.where(in_slips, 15.0 + 0.28 * (t - 150.0),
                                                          43.0 - 0.1 * (t - 250.0)))
    frame = pd.DataFrame({"time_s": t, "surface_rpm": np.where(in_slips, 0.0, 60.0),
                          "surface_torque_Nm": np.where(in_slips, 0.0, 8e3),
                          "hookload_N": np.where(in_slips, 3e5, 1.2e6),
                          "block_position_m": block})
    frame.to_csv(tmp_path / "w.csv", index=False)
    base = "[segmentation]\nstart_bit_depth_m = 1000.0\nmin_segment_s = 600.0\n"
    (tmp_path / "w.toml").write_text(base)
    runner = CliRunner()
    refused = runner.invoke(cli, ["run", str(tmp_path / "w.csv"), "--out", str(tmp_path / "a"),
                                  "--no-report"])
    assert refused.exit_code == 2 and "slips_hookload_N" in refused.output, refused.output
    assert not (tmp_path / "a" / "w").exists()
    (tmp_path / "w.toml").write_text(base + "slips_hookload_N = 6e5\n")
    ran = runner.invoke(cli, ["run", str(tmp_path / "w.csv"), "--out", str(tmp_path / "b"),
                              "--no-report"])
    assert ran.exit_code == 0, ran.output
    segments = pd.read_parquet(tmp_path / "b" / "w" / "segments.parquet")
    # 15 m lowered before the connection and 15 m after it: the second stand's median bit
    # depth is 1022.5 m (the empty block's 28-m climb in the slips moved the bit to 994.5 m)
    assert segments["bit_depth_m"].max() == pytest.approx(1022.5, abs=0.5)


def test_weight_on_the_bit_puts_it_on_bottom_whatever_the_depths_say():
    """The seventh attack (issue 30): a hole-depth channel reading 3 m below the bit labelled
    drilling (WOB 30 kN) off bottom, and its bit torque went into μ_k (0.323 for 0.28)."""
    n = 120
    bit = np.linspace(2250.0, 2250.7, n)
    states = classify(frame(np.full(n, 80.0), bit_depth_m=bit, hole_depth_m=bit + 3.0,
                            wob_N=np.full(n, 30e3)), cfg())
    assert np.all(states == ROTATING_ON_BOTTOM)
    lifted = classify(frame(np.full(n, 80.0), bit_depth_m=bit, hole_depth_m=bit + 3.0,
                            wob_N=np.full(n, 2e3)), cfg())
    assert np.all(lifted == ROTATING_OFF_BOTTOM)


def test_short_blips_do_not_pass_one_runs_kind_down_a_chain():
    """1-s off-bottom blips every 15 s of drilling after a 30-s off-bottom start made the
    whole drilled stand one off-bottom segment (each short run took its predecessor's
    already reassigned kind): the blips now join the drilling around them."""
    kinds = [ROTATING_OFF_BOTTOM] * 30
    for _ in range(12):
        kinds += [ROTATING_ON_BOTTOM] * 14 + [ROTATING_OFF_BOTTOM]
    on = np.array(kinds, dtype=np.int8)
    runs = _kind_runs(np.arange(on.size, dtype=float), on, 20.0)
    assert [(a, b, k) for a, b, k in runs] == [(0, 30, ROTATING_OFF_BOTTOM),
                                               (30, on.size, ROTATING_ON_BOTTOM)]


def test_a_wob_read_from_slack_off_drag_does_not_put_a_tripping_bit_on_bottom():
    """Review of the WOB rule: a WOB computed from the hook load reads a slack-off's drag
    (25 kN); 220 m above the hole, not turning, the bit is tripping, not on bottom."""
    n = 120
    t = np.arange(n, dtype=float)
    states = classify(frame(np.zeros(n), bit_depth_m=1000.0 + 0.3 * t,
                            hole_depth_m=np.full(n, 1300.0),
                            wob_N=np.where(t >= 60.0, 25e3, 0.0)), cfg())
    assert not np.any(states == SLIDING_ON_BOTTOM)
    assert np.all(states[70:] == TRIPPING)


def test_depth_jitter_over_a_tiny_time_step_is_not_a_depth_reset():
    """Issue 35 (fourth newcomer): DSATS segment 70, back-reaming, was withheld as a "depth
    reset" because the bit depth changed 0.14 m in 0.02 s (timestamp jitter: 7 m/s). A reset
    is judged by its size in metres (DEPTH_JUMP_MIN_M and a trip's travel in the time step),
    not by a speed over a jittery dt; a real reset of 41 m is still one."""
    t = np.arange(0.0, 120.0)
    t[60] = t[59] + 0.02                          # jittered timestamp
    depth = 2000.0 - 0.2 * t
    depth[60] = depth[59] - 0.14
    motion = axial_motion("back_reaming", depth, t)
    assert "jumps" not in motion.withheld
    assert motion.speed_m_s == pytest.approx(-0.2, rel=0.05)
    reset = np.where(t < 60.0, depth, depth + 41.0)
    assert "jumps by 40.7 m" in axial_motion("back_reaming", reset, t).withheld
