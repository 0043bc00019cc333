"""A declared mud motor (issue 34 item 5, docs/theory.md §2.4): the bit turns at the string's
bottom speed plus k·flow. Before it, with the pumps on, drillfric showed the string's bottom
speed (7–60 RPM) as the bit's (truth 126–180 RPM): a false number.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from drillfric.config import config_from_dict
from drillfric.estimation.bit_torque import bit_speed_rpm, teale_mse_Pa
from drillfric.estimation.motor import motor_speed, motor_speed_rad_s
from drillfric.runner.segment_output import with_motor
from drillfric.sim.run import pdm_speed_rad_s
from drillfric.units import RPM_TO_RAD_S

#: US gallon [L], exact by definition (231 in³).
GALLON_L = 3.785411784


def test_motor_constant_takes_revolutions_per_gallon():
    cfg = config_from_dict({"bha": {"motor_rev_per_litre": "0.15 rev/gal"}})
    # exact conversion: the float nearest 0.15/3.785411784
    assert cfg.bha.motor_rev_per_litre == pytest.approx(0.15 / GALLON_L, rel=1e-15)


def test_a_motor_constant_of_another_quantity_is_refused():
    from drillfric.errors import ConfigError

    with pytest.raises(ConfigError, match="motor_rev_per_litre"):
        config_from_dict({"bha": {"motor_rev_per_litre": "0.15 rev/min"}})


@pytest.mark.parametrize("k, litres_per_min", [(0.03, 3000.0), (0.1, 1800.0), (0.3, 600.0)])
def test_no_load_motor_speed_is_k_times_flow(k, litres_per_min):
    # eq. 2.4a: k rev/L × Q L/min = k·Q rev/min; the two paths differ only by round-off
    q = litres_per_min / 60_000.0
    rpm = motor_speed_rad_s(q, k) / RPM_TO_RAD_S
    assert rpm == pytest.approx(k * litres_per_min, rel=1e-12)
    # the simulator's own implementation, without load, agrees
    assert pdm_speed_rad_s(q, k, np.zeros(1), None)[0] / RPM_TO_RAD_S == pytest.approx(
        k * litres_per_min, rel=1e-12)


def test_simulated_motor_slows_linearly_with_bit_torque_to_stall():
    # eq. 2.4b: half the stall torque halves the speed; beyond the stall it stops, and a
    # negative (driving) bit torque does not speed it past its no-load speed
    w = pdm_speed_rad_s(0.03, 0.1, np.array([-100.0, 0.0, 1000.0, 2000.0, 3000.0]), 2000.0)
    no_load = 180.0 * RPM_TO_RAD_S
    assert w == pytest.approx([no_load, no_load, 0.5 * no_load, 0.0, 0.0], rel=1e-12)


def test_motor_band_on_bottom_spans_the_largest_drop_and_pumps_off_give_zero():
    m = motor_speed(np.array([0.03, 0.03, 0.001, np.nan, np.nan]),
                    np.array([1, 1, 0, 0, -1]), 0.1, 0.3, on_bottom=True)
    rpm = {n: getattr(m, n) / RPM_TO_RAD_S for n in ("low", "mid", "high")}
    assert rpm["high"][:2] == pytest.approx([180.0, 180.0])
    assert rpm["low"][:2] == pytest.approx([126.0, 126.0])  # 30 % slower
    assert rpm["mid"][:2] == pytest.approx([153.0, 153.0])
    # pumps off: 0, the band's top the (small) flow still logged; off with no flow: 0
    assert [rpm[n][2] for n in ("low", "mid")] == [0.0, 0.0]
    assert rpm["high"][2] == pytest.approx(6.0)
    assert [rpm[n][3] for n in ("low", "mid", "high")] == [0.0, 0.0, 0.0]
    # flow missing while the pumps may run: unknown, not 0
    assert all(np.isnan(rpm[n][4]) for n in rpm)


def test_off_bottom_motor_has_no_drop():
    m = motor_speed(np.array([0.03]), np.array([1]), 0.1, 0.3, on_bottom=False)
    assert m.low[0] == m.mid[0] == m.high[0]


def _frame(bha_rpm, stuck) -> pd.DataFrame:
    n = len(bha_rpm)
    bha = np.asarray(bha_rpm, float)
    return pd.DataFrame({
        "time_s": np.arange(n, dtype=float), "bit_rpm_est": bha, "bha_rpm_est": bha,
        "bit_rpm_est_min": (bha - 5).astype(np.float32), "bha_rpm_est_min":
            (bha - 5).astype(np.float32), "bit_rpm_est_max": (bha + 5).astype(np.float32),
        "bha_rpm_est_max": (bha + 5).astype(np.float32),
        "bit_stuck": pd.array(stuck, dtype="boolean")})


def test_bit_speed_with_pumps_on_is_the_bha_speed_plus_the_motor_speed():
    """Regression (issue 34 item 5): the bit's speed was the string's bottom speed."""
    frame = _frame([0.0, 20.0, 40.0, 0.0], [True, False, False, True])
    rows = pd.DataFrame({"time_s": np.arange(4.0)})
    motor = motor_speed(np.array([0.03, 0.03, 0.03, 0.0]), np.array([1, 1, 1, 0]), 0.1, 0.3,
                        on_bottom=False)
    out = with_motor(frame, rows, motor)
    assert out["bha_rpm_est"].tolist() == [0.0, 20.0, 40.0, 0.0]  # the string's, unchanged
    assert out["bit_rpm_est"].to_numpy() == pytest.approx([180.0, 200.0, 220.0, 0.0])
    # the band moves with the motor (float32 columns: 1e-4 relative)
    assert out["bit_rpm_est_min"].to_numpy() == pytest.approx([175, 195, 215, -5], rel=1e-4)
    assert out["bit_rpm_est_max"].to_numpy() == pytest.approx([185, 205, 225, 5], rel=1e-4)
    # a stuck BHA with the motor turning is not a stuck bit; with the pumps off it is
    assert out["bit_stuck"].tolist() == [False, False, False, True]


def test_bit_speed_is_withheld_where_the_flow_is_missing():
    frame = _frame([30.0, 30.0], [False, False])
    motor = motor_speed(np.array([0.03, np.nan]), np.array([1, -1]), 0.1, 0.3, False)
    out = with_motor(frame, pd.DataFrame({"time_s": [0.0, 1.0]}), motor)
    assert np.isnan(out["bit_rpm_est"].iloc[1]) and out["bit_stuck"].isna().iloc[1]
    assert out["bha_rpm_est"].iloc[1] == 30.0  # the string's speed stays known


def test_withheld_windows_stay_unknown_with_a_motor():
    frame = _frame([np.nan], [None])
    motor = motor_speed(np.array([0.03]), np.array([1]), 0.1, 0.3, False)
    out = with_motor(frame, pd.DataFrame({"time_s": [0.0]}), motor)
    assert np.isnan(out["bit_rpm_est"].iloc[0]) and out["bit_stuck"].isna().iloc[0]


def test_mse_takes_the_bit_speed_with_a_declared_motor():
    # eq. 2.2c with N = surface + motor; the motor's on-bottom speed 126–180 RPM is 153 ± 27
    rpm, u = bit_speed_rpm(60.0, 153.0, 0.3)
    assert (rpm, u) == pytest.approx((213.0, 27.0))
    # MSE's rotary term is linear in N: with the motor it is (60 + 153)/60 of the surface's
    rotary = lambda n: teale_mse_Pa(0.0, 3000.0, n, 20.0, 0.2159)  # noqa: E731
    assert rotary(rpm) / rotary(60.0) == pytest.approx(213.0 / 60.0, rel=1e-12)
    # without a motor: the surface speed, no speed uncertainty; a motor whose speed is not
    # known withholds it
    assert bit_speed_rpm(60.0, None, None) == (60.0, 0.0)
    assert bit_speed_rpm(60.0, None, 0.3) is None


@pytest.mark.slow
@pytest.mark.parametrize("declared", [True, False])
def test_simulated_motor_well_shows_the_bit_speed_or_says_it_is_the_bha(tmp_path, declared):
    """End to end: a single off-bottom stand with the pumps on and a 180-RPM motor (k =
    0.1 rev/L, 1800 L/min). Declared: bit − BHA = 180 RPM exactly where shown (off bottom
    the motor has no load); undeclared: the trace says it is the string's bottom speed."""
    from drillfric.io.well import open_well
    from drillfric.runner import run_well
    from drillfric.runner.segment_output import BHA_STATISTICS_NOTE, MOTOR_NOTE
    from drillfric.sim.run import simulate_config
    from tests.conftest import DEMO

    text = (DEMO / "demo.toml").read_text().replace('data = "demo.csv"\n', "")
    if declared:
        text += '\n[bha]\nmotor_rev_per_litre = "0.1 rev/L"\n'
    (tmp_path / "m.toml").write_text(text)
    (tmp_path / "demo.survey.csv").write_bytes((DEMO / "demo.survey.csv").read_bytes())
    simulate_config(tmp_path / "m.toml", out=tmp_path / "m.csv", overrides={
        "simulate.bit_depth_m": 2250.0, "simulate.duration_s": 100.0, "simulate.rpm": 60.0,
        "simulate.flow_m3_s": 0.03, "simulate.motor_rev_per_litre": 0.1,
        "simulate.cells": 1000, "simulate.rate_hz": 20.0})
    result = run_well(open_well(tmp_path / "m.csv"))
    seg = result.segments.iloc[0]
    shown = result.estimates[result.estimates["bit_rpm_est"].notna()]
    assert len(shown) > 0
    motor = (shown["bit_rpm_est"] - shown["bha_rpm_est"]).to_numpy()
    if declared:
        assert motor == pytest.approx(180.0, rel=1e-9)
        assert seg["motor_rpm_mean"] == pytest.approx(180.0)
        # the trace's error against the bit's truth is the BHA trace's, not ~180 RPM
        assert seg["bit_rms_error_rpm"] < 30.0
        if not np.isnan(seg["stuck_fraction"]):
            assert BHA_STATISTICS_NOTE in seg["message"]
    else:
        assert motor == pytest.approx(0.0, abs=1e-9)
        assert seg["bit_speed_reason"] == MOTOR_NOTE
        assert sum(MOTOR_NOTE in w for w in result.summary["warnings"]) == 1


def test_report_shows_the_bha_speed_beside_the_bit_speed_with_a_motor():
    from drillfric.report.evidence import panel_data
    from drillfric.report.render import _bit_speed_cell

    rows = pd.DataFrame({"time_s": [0.0, 1.0], "start_id": [-1, -1],
                         "surface_rpm": [60.0, 60.0], "surface_rpm_est": [60.0, 60.0],
                         "bit_rpm_est": [230.0, 200.0], "bha_rpm_est": [50.0, 20.0],
                         "bit_stuck": [False, False]})
    assert panel_data(rows)["bit"]["bha"].tolist() == [50.0, 20.0]
    # without a motor the two are the same numbers: one line
    assert "bha" not in panel_data(rows.assign(bha_rpm_est=rows["bit_rpm_est"]))["bit"]
    cell = _bit_speed_cell({"status": "ok", "bit_speed_resolved": True,
                            "motor_rpm_mean": 180.0, "sample_interval_s": 0.01})
    assert "BHA + motor ≈ 180 rpm" in cell


def test_live_open_segment_gives_the_bha_speed(tmp_path):
    import pyarrow as pa
    import pyarrow.parquet as pq

    from drillfric.live.alerts import bit_tail

    table = pa.table({"segment_id": pa.array([3, 3], pa.int32()), "time_s": [0.0, 1.0],
                      "surface_rpm": [60.0, 60.0], "bit_rpm_est": [230.0, 200.0],
                      "bha_rpm_est": [50.0, 20.0], "bit_stuck": [False, False]})
    pq.write_table(table, tmp_path / "estimates.parquet")
    assert bit_tail(tmp_path, 3) == (200.0, 20.0, 0.0)


def _rows(flow_m3_s) -> pd.DataFrame:
    n = len(flow_m3_s)
    return pd.DataFrame({"time_s": np.arange(float(n)), "surface_rpm": np.full(n, 60.0),
                         "flow_in_m3_s": np.asarray(flow_m3_s, float)})


@pytest.mark.parametrize("on_bottom, resolved, says", [
    (False, True, "bit speed shown is the string's bottom speed"),
    (True, False, "mse_Pa takes the string's speed"),
    (False, False, None)])  # no trace shown: nothing to qualify
def test_undeclared_motor_segments_say_what_their_speed_is(on_bottom, resolved, says):
    from drillfric.result import SegmentRecord
    from drillfric.runner.segment_output import motor_fields

    record = SegmentRecord(id=1, bit_speed_resolved=resolved)
    fields = motor_fields(_rows([0.03] * 10), config_from_dict({}), on_bottom, None, record)
    if says is None:
        assert fields == {}
    else:
        assert says in fields["message"]
        assert ("bit_speed_reason" in fields) is (not on_bottom)


def test_declared_motor_segment_gives_its_mean_speed_and_says_the_statistics_are_the_bhas():
    from drillfric.result import SegmentRecord
    from drillfric.runner.segment_output import (
        BHA_STATISTICS_NOTE,
        FLOW_MISSING_NOTE,
        motor_fields,
    )

    cfg = config_from_dict({"bha": {"motor_rev_per_litre": 0.1}})
    record = SegmentRecord(id=1, stuck_fraction=0.4)
    fields = motor_fields(_rows([0.03] * 10), cfg, False, None, record)
    assert fields["motor_rpm_mean"] == pytest.approx(180.0)
    assert BHA_STATISTICS_NOTE in fields["message"]
    assert FLOW_MISSING_NOTE not in fields["message"]
    # on bottom the mean is the middle of 180·[0.7, 1]; a missing flow is said
    fields = motor_fields(_rows([0.03] * 9 + [np.nan]), cfg, True, None, record)
    assert fields["motor_rpm_mean"] == pytest.approx(153.0)
    assert FLOW_MISSING_NOTE in fields["message"]


def test_a_declared_motor_without_its_flow_is_said_once_for_the_well():
    from drillfric.result import SegmentRecord
    from drillfric.runner.engine import _flow_missing_note
    from drillfric.runner.segment_output import FLOW_MISSING_NOTE

    records = [SegmentRecord(id=i, message=FLOW_MISSING_NOTE if i != 2 else "")
               for i in (1, 2, 3)]
    note = _flow_missing_note(records)
    assert note.startswith("2 segments (1, 3): ") and FLOW_MISSING_NOTE in note
    assert _flow_missing_note(records[1:2]) is None
