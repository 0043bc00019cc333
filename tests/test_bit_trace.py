"""The kinematic check of a bit-speed trace, the on-bottom rule, stuck fraction and severity
(drillfric.estimation.bit_trace; docs/bit_speed.md "Kinematic check")."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from drillfric.drillstring import build_string
from drillfric.estimation.bit_trace import (
    SEVERITY_VALIDATED_BELOW,
    bit_speed_claim,
    check_trace,
    compliance_rad_Nm,
    drift_note,
    mixture_severity,
    statistics_note,
    stuck_share,
    twist_bound_rad,
)
from drillfric.estimation.chain import SegmentData, estimate_segment, statistics_from
from drillfric.estimation.diagnostics import stick_slip_severity
from drillfric.estimation.sampling import Resolution
from drillfric.estimation.settings import ChainSettings
from drillfric.result import Flag
from tests.synthetic import RPM, build_and_hold, config, noisy, simulate

NOISE = 0.5 * RPM


def _string(depth_m=2300.0):
    return build_string(config().sections, depth_m)


def test_compliance_adds_the_sections_in_series():
    """C = Σ L_i/(G_i J_i): the pipe alone, then pipe + the BHA's two sections."""
    string = _string()
    parts = [s.length_m / (s.shear_modulus_Pa * s.polar_moment_m4) for s in string.sections]
    assert len(parts) == 3
    assert compliance_rad_Nm(string) == pytest.approx(sum(parts))


def test_twist_bound_spans_zero_to_the_highest_torque():
    """The twist lies between that of min(τ_lo, 0) and of τ_hi over the whole string; a
    single glitch (outside the 0.1–99.9 percentiles) does not widen it."""
    torque = np.r_[np.linspace(5e3, 20e3, 5000), 1e7]
    assert twist_bound_rad(torque, 1e-3) == pytest.approx(20.0, rel=1e-2)
    assert twist_bound_rad(np.full(100, -3e3), 1e-3) == pytest.approx(3.0)


def test_rigid_string_trace_equal_to_the_surface_passes():
    """A rigid string: mean bit = mean surface over every window, no drift at all."""
    t = np.arange(0.0, 300.0, 0.01)
    surface = 40 * RPM + 2 * RPM * np.sin(t)
    check = check_trace(t[::10], surface[::10], t, surface, twist_bound=0.0, noise_rad_s=0.0)
    assert check.passed
    assert check.drift_rad < 0.05


def test_twist_change_within_the_torque_bound_passes():
    """bit = ω₀ − dΘ/dt with Θ = C·τ/2 swinging with a stick-slip-like torque: the drift is
    the twist change, inside the bound from the same torque."""
    t = np.arange(0.0, 300.0, 0.01)
    c = compliance_rad_Nm(_string())
    torque = 15e3 + 8e3 * np.sign(np.sin(2 * np.pi * t / 6.0))
    twist = np.convolve(c * torque / 2, np.ones(50) / 50, mode="same")
    surface = np.full_like(t, 40 * RPM)
    bit = surface - np.gradient(twist, t)
    check = check_trace(t[::10], bit[::10], t, surface, twist_bound_rad(torque, c), NOISE)
    assert check.passed, check


def test_trace_6_rpm_behind_its_top_drive_for_2_minutes_is_withheld():
    """Issue 22: back-reaming at 0.2 m/s, every member drew the bit at 33–34 RPM for 2 minutes
    while the top drive and the bit turned at 40 RPM. At 2300 m with a torque swinging
    10–20 kN·m the string holds at most C·20 kN·m ≈ 31 rad of twist; 6 RPM for 120 s is
    75 rad: withheld, with the window and the lag in the reason."""
    t = np.arange(0.0, 150.0, 0.01)
    surface = np.full_like(t, 40 * RPM)
    bit = np.where((t > 20) & (t < 140), 34 * RPM, 40 * RPM)
    torque = 15e3 + 5e3 * np.sin(t)
    bound = twist_bound_rad(torque, compliance_rad_Nm(_string()))
    check = check_trace(t[::10], bit[::10], t, surface, bound, NOISE)
    assert not check.passed
    assert check.drift_rad == pytest.approx(6 * RPM * 120, rel=0.01)
    assert check.lag_rpm == pytest.approx(-6.0, abs=0.1)
    assert 19 < check.t_from_s < 21 and 139 < check.t_to_s < 141
    claim = bit_speed_claim(Resolution(True, 20.0), check, on_bottom=False)
    assert not claim.resolved
    assert "6.0 RPM behind the top drive" in claim.reason and "20–140 s" in claim.reason


def test_simulated_stick_slip_truth_passes_the_check():
    """The true bit speed of a simulated severe stick-slip record (a plant keeps its own
    kinematics) passes against the record's noisy surface data: the bound is not too tight."""
    path = build_and_hold(800.0, 45.0, 2000.0)
    case = simulate(path, 2000.0, 0.8, 0.3, 40.0, 120.0, cells=600, rate_hz=100.0)
    rec = case.record
    rng = np.random.default_rng(1)
    surface = rec.surface_rad_s + rng.normal(0.0, NOISE, rec.time_s.size)
    assert stick_slip_severity(rec.bit_rad_s[rec.time_s > 30]) > 1.5
    bound = twist_bound_rad(rec.motor_torque_Nm, compliance_rad_Nm(case.string))
    truth = check_trace(rec.time_s[::10], rec.bit_rad_s[::10], rec.time_s, surface, bound,
                        NOISE)
    assert truth.passed, truth
    assert truth.drift_rad > 0.5 * bound  # the check is not vacuous: the twist swings a lot
    lagging = check_trace(rec.time_s[::10], rec.bit_rad_s[::10] - 5 * RPM, rec.time_s,
                          surface, bound, NOISE)
    assert not lagging.passed


def test_on_bottom_trace_is_withheld_and_unresolved_keeps_its_reason():
    passed = check_trace(np.arange(3.0), np.ones(3), np.arange(3.0), np.ones(3), 1.0, 0.0)
    on_bottom = bit_speed_claim(Resolution(True, 20.0), passed, on_bottom=True)
    assert not on_bottom.resolved and "on bottom" in on_bottom.reason
    slow = Resolution(False, 2.0, "bit speed not resolved: 5-s means")
    assert bit_speed_claim(slow, passed, on_bottom=True) is slow
    assert bit_speed_claim(Resolution(True, 20.0), passed, on_bottom=False).resolved


def test_non_finite_trace_never_passes():
    t = np.arange(10.0)
    check = check_trace(t, np.r_[np.ones(9), np.nan], t, np.ones(10), 100.0, 0.0)
    assert not check.passed


def test_stuck_fraction_and_severity_of_members_out_of_phase():
    """Two members, each stuck 60 % of a 10-s cycle and slipping at 100 RPM, half a cycle
    apart: their weighted mean is rarely below ω_c and swings half as far (stuck fraction
    0.2, severity halved), the pooled members keep each member's 0.6 and severity."""
    t = np.arange(0.0, 100.0, 0.1)
    one = np.where((t % 10.0) < 6.0, 0.0, 100 * RPM)
    other = np.where(((t + 5.0) % 10.0) < 6.0, 0.0, 100 * RPM)
    bit = np.column_stack([one, other])
    w = np.full(bit.shape, 0.5)
    assert stuck_share(bit, w, 1.0) == pytest.approx(0.6)
    assert mixture_severity(bit, w) == pytest.approx(stick_slip_severity(one))
    mean = bit.mean(axis=1)
    assert np.mean(np.abs(mean) <= 1.0) == pytest.approx(0.2)
    assert stick_slip_severity(mean) < 0.6 * stick_slip_severity(one)


def test_creeping_bit_counts_as_stuck():
    """A stuck bit may creep a few RPM under a held torque: below ω_c it is stuck."""
    bit = np.full((10, 1), 3 * RPM)
    assert stuck_share(bit, np.ones((10, 1)), 1.0) == 1.0
    assert stuck_share(bit + 10 * RPM, np.ones((10, 1)), 1.0) == 0.0


def test_stick_slip_trace_drifting_under_a_third_of_its_swing_is_shown_flagged():
    """A trace that fails the check by a mean lag far below its stick-slip swing stays
    within its stated accuracy (a mean offset ε adds at most ε to the RMS error): shown, with
    the flag's message; the same lag under a steady top drive (swing ≈ lag) is withheld."""
    t = np.arange(0.0, 300.0, 0.01)
    surface = np.full_like(t, 60 * RPM)
    stick_slip = 60 * RPM * (1.0 + np.sign(np.sin(2 * np.pi * t / 6.0)))  # 0 / 120 RPM
    bound = twist_bound_rad(15e3 + 5e3 * np.sin(t), compliance_rad_Nm(_string()))
    drifting = check_trace(t[::10], stick_slip[::10] + 6 * RPM, t, surface, bound, NOISE)
    assert not drifting.passed and drifting.approximate
    assert drifting.swing_rpm == pytest.approx(60.3, abs=1.0) and 5.5 < drifting.lag_rpm < 7.0
    claim = bit_speed_claim(Resolution(True, 20.0), drifting, on_bottom=False)
    assert claim.resolved
    assert f"{drifting.lag_rpm:.1f} RPM ahead of the top drive" in drift_note(drifting)
    steady = check_trace(t[::10], surface[::10] + 6 * RPM, t, surface, bound, NOISE)
    assert not steady.passed and not steady.approximate
    assert not bit_speed_claim(Resolution(True, 20.0), steady, on_bottom=False).resolved


def _synchronised(cfg):
    """The chain's settings for a simulated record, whose torque and speed are logged in
    step (``[channels] lag_s = 0``): stick-slip alone cannot time a lag, and an unknown lag
    would withhold the statistics these tests read (docs/bit_speed.md, Channel skew)."""
    return replace(ChainSettings.from_config(cfg), torque_lag_s=0.0)


def test_severe_stick_slip_statistics_withheld_not_printed_low():
    """Issue 22 (benchmarks/validate_severity.py): in severe off-bottom stick-slip (sticky
    0.8/0.25 at 2000 m, 30 RPM: the truth's severity 3.9, stuck 0.73) the ensemble read the
    severity up to 26 % and the stuck fraction up to 0.13 low — beyond the stated ±12 % /
    ±0.05. Such a segment's estimated severity is ≥ 2.1: both statistics are withheld, with
    the flag and the reason, not printed."""
    path = build_and_hold(800.0, 45.0, 2000.0)
    cfg = config(cells=200)
    case = simulate(path, 2000.0, 0.8, 0.25, 30.0, 150.0, cells=400, rate_hz=10.0, cfg=cfg)
    rec = case.record
    late = rec.time_s > 30.0
    assert stick_slip_severity(rec.bit_rad_s[late]) > 2.9  # beyond the validated 1.9–2.9
    w, q = noisy(rec)
    est = estimate_segment(_synchronised(cfg), path, SegmentData(rec.time_s, w / RPM, q, 2000.0))
    assert est.stick_slip_severity >= SEVERITY_VALIDATED_BELOW
    assert not est.bit_statistics
    assert Flag.STICK_SLIP_BEYOND_VALIDATED in est.flags
    assert any(m.startswith("severe stick-slip: stuck fraction and severity withheld")
               for m in est.messages)


def test_stick_slip_statistics_rest_on_mu_s_and_are_withheld_without_it():
    """Moderate off-bottom stick-slip from a ramp start (0.5/0.25 at 2000 m, 50 RPM; truth
    severity 1.53, stuck 0.51 with |ω_bit| ≤ ω_c = 1 rad/s): the ensemble's statistics are
    within the stated ±12 % and ±0.05 of the truth on this plant (measured +4 % and 0.00),
    but a ramp start does not identify μ_s, and how long the bit sticks each cycle turns on
    it: on the lumped plant such statistics were off by up to ±0.15 stuck and +24 %
    (issue 33 item 4, docs/bit_speed.md). They are withheld, flagged, with the reason."""
    path = build_and_hold(800.0, 45.0, 2000.0)
    cfg = config(cells=200)
    case = simulate(path, 2000.0, 0.5, 0.25, 50.0, 150.0, cells=400, rate_hz=10.0, cfg=cfg)
    rec = case.record
    late = rec.time_s > 30.0
    truth = stick_slip_severity(rec.bit_rad_s[late])
    stuck = float(np.mean(np.abs(rec.bit_rad_s[late]) <= 1.0))
    assert 1.0 < truth < 2.0  # the bit stops, below the validated-range limit
    w, q = noisy(rec)
    est = estimate_segment(_synchronised(cfg), path, SegmentData(rec.time_s, w / RPM, q, 2000.0))
    assert est.mu_s is None  # a ramp start: μ_s not identified
    assert est.stick_slip_severity == pytest.approx(truth, rel=0.12)
    assert est.stuck_fraction == pytest.approx(stuck, abs=0.05)
    assert not est.bit_statistics and Flag.STICK_SLIP_UNDETERMINED in est.flags
    assert any("how long it sticks turns on μ_s" in m for m in est.messages)


def test_statistics_note_only_beyond_the_validated_severity():
    assert statistics_note(SEVERITY_VALIDATED_BELOW - 0.01) == ""
    assert statistics_note(float("nan")) == ""
    note = statistics_note(3.2)
    # the withheld estimate itself is not printed (it reads up to 26 % low there)
    assert "3.2" not in note and "2.1 or more" in note and "docs/bit_speed.md" in note


def test_a_30_s_runaway_inside_a_long_trace_is_withheld_window_by_window():
    """Issue 33: on an independent plant a trace shown as resolved averaged 213 RPM over a
    window in which the bit averaged 33 — the whole-segment check allowed it the segment's
    twist range. Window by window, the runaway's window goes (its rows null); the stick-slip
    windows around it, whose mean equals the top drive's, stay."""
    from drillfric.estimation import bit_trace

    rpm = 2 * np.pi / 60
    t = np.arange(0.0, 300.0, 0.1)
    top = np.full(t.size, 60.0 * rpm)
    bit = 60.0 * rpm * (1.0 + np.sin(2 * np.pi * t / 5.0))  # stick-slip about the top drive
    runaway = (t >= 120.0) & (t < 150.0)
    bit[runaway] = 213.0 * rpm
    torque = 20e3 + 5e3 * np.sin(2 * np.pi * t / 5.0)
    compliance = 55.0 / 25e3  # ~55 rad of twist at 25 kN·m
    verdict = bit_trace.window_check(t, bit, t, top, torque, compliance, 1.0, 0.5 * rpm)
    assert verdict.windows == 10 and verdict.withheld == ((120.0, 150.0),)
    assert "ahead of the top drive" in verdict.reason and not verdict.too_many
    unknown = bit_trace.window_check(t, bit, t, top, torque, compliance, 1.0, 0.5 * rpm,
                                     unknown_spans=((0.0, 40.0),))
    assert unknown.withheld[:2] == ((0.0, 30.0), (30.0, 60.0))


def test_window_grid_joins_a_short_last_window():
    from drillfric.estimation.bit_trace import window_grid

    assert window_grid(10.0, 100.0) == [(10.0, 40.0), (40.0, 70.0), (70.0, 100.0)]
    assert window_grid(0.0, 65.0) == [(0.0, 30.0), (30.0, 65.0)]


def test_a_seeded_trace_running_away_for_most_of_the_rotation_says_the_factors_are_wrong():
    """The lumped plant's false μ_k (0.125 for 0.157, 10 Hz): the observer seeded with it ran
    the bit 38.7 RPM ahead for 242 s of 300, 981 rad against the 119 the string can hold; a
    right μ_k's trace drifted as far only through a break-free (62 s)."""
    from drillfric.estimation.bit_trace import KinematicCheck, runs_away

    wrong = KinematicCheck(False, 981.0, 119.0, 154.0, 396.0, 38.7)
    assert runs_away(wrong, settled_s=300.0)
    break_free = KinematicCheck(False, 1135.0, 119.0, 40.0, 102.0, 82.1)
    assert not runs_away(break_free, settled_s=300.0)
    assert not runs_away(KinematicCheck(False, 300.0, 119.0, 0.0, 280.0, 5.0), 300.0)


def test_stick_slip_statistics_the_data_do_not_fix_are_withheld():
    """Issue 33 item 4: on the lumped plant stuck fractions of 0.06 were printed for 0.23
    (estimated severity 0.94, the bit grazing rest) and 0.56 for 0.65 (members carrying
    μ_s ±15 % gave 0.40–0.59). Members that agree, away from the edge of rest, keep them."""
    from drillfric.estimation.bit_trace import members_disagree

    t = np.arange(0.0, 60.0, 0.1)
    stick = np.clip(np.sin(2 * np.pi * t / 5.0), -0.3, None) + 0.3  # stops each cycle
    same = np.column_stack([6.0 * stick] * 3)
    assert members_disagree(same, 2.0, 0.1) == ""
    spread = np.column_stack([6.0 * stick, 6.0 * (stick + 0.25), 6.0 * (stick + 0.6)])
    assert "members" in members_disagree(spread, 2.0, 0.1)
    assert "edge of rest" in members_disagree(same, 0.9, 0.1)


def test_steady_members_agree_on_their_statistics():
    """Review: five steady members at 60 RPM (severities 0.01–0.02) were called undetermined
    — 12 % of a near-zero severity is no spread at all (a floor of 0.05 now)."""
    from drillfric.estimation.bit_trace import members_disagree

    rng = np.random.default_rng(1)
    steady = 2 * np.pi + rng.normal(0.0, 0.03, (600, 5))
    assert members_disagree(steady, 0.015, 0.1) == ""


def test_windows_over_a_gap_of_the_log_are_withheld():
    """A window holding a stretch the log has no sample in is withheld, whatever the trace
    there (the observer's guess), with the reason; the others are judged as before."""
    from drillfric.estimation.bit_trace import window_check
    from drillfric.io.timebase import find_gaps

    t = np.arange(0.0, 90.0, 0.05)
    w = np.full(t.size, 6.0)
    tau = np.full(t.size, 10e3)
    logged = t[(t < 40.0) | (t > 48.0)]
    gaps = find_gaps(logged, 0.8, 20.0)
    assert gaps == ((pytest.approx(39.95), pytest.approx(48.05)),)
    verdict = window_check(t, w, t, w, tau, 1e-5, 0.8, 0.01, gap_spans=gaps)
    assert verdict.withheld == ((30.0, 60.0),)
    assert "gap longer than the string's wave travel time" in verdict.reason


def test_statistics_are_taken_after_the_transients_an_unidentified_mu_s_decides():
    """Issue 33 item 4: on the lumped plant every stuck fraction and severity was withheld,
    the right ones too, because the creep start-up's break-free — whose bit speed depends on
    the unidentified μ_s — lay inside their span. They are now taken after the start-up
    (30 s, or 30 % of a short segment) and after every such span: the rotation at its
    set-point."""
    t = np.arange(0.0, 300.0, 0.1)
    assert statistics_from(t, ()) == pytest.approx(30.0, abs=0.1)
    assert statistics_from(t, ((0.0, 30.0), (40.0, 121.5))) == 121.5
    # to the end of the 30-s window withheld over the creep, not into it
    assert statistics_from(t, ((0.0, 30.0), (40.0, 121.5)), ((120.0, 150.0),)) == 150.0
    assert statistics_from(t, ((0.0, 30.0),), ((120.0, 150.0),)) == pytest.approx(30.0, abs=.1)
    short = np.arange(0.0, 50.0, 0.1)
    assert statistics_from(short, ()) == pytest.approx(15.0, abs=0.1)


STEADY_SCENARIO = """connection_s = 20.0
[defaults]
duration_s = 150.0
rpm = 120.0
ramp_s = 10.0
[[stand]]
bit_depth_m = 2210.0
"""


@pytest.mark.slow
def test_a_steady_stands_stop_is_not_stick_slip(tmp_path):
    """Regression (issue 34, validate_edr): a steady 120-RPM stand (μ_s = μ_k) had its
    stick-slip statistics taken to the segment's end, through the ramp to rest: a severity
    of 0.62 on this stand (validate_trust's steady plant 0.55), its truth graded over the
    same span agreeing. They end where the set-point does (`stick_slip_to_s`, before the
    stop): here the bit's own torsional swing is 0.14, below the 0.2 from which a severity
    is stated, so the segment says "no stick-slip" and gives the stuck fraction (0)."""
    from drillfric.io.well import open_well
    from drillfric.runner import run_well
    from tests.conftest import DEMO, _simulated

    (tmp_path / "demo.survey.csv").write_bytes((DEMO / "demo.survey.csv").read_bytes())
    config = tmp_path / "steady.toml"
    config.write_text((DEMO / "demo.toml").read_text().replace("mu_s = 0.6", "mu_s = 0.28"))
    path = _simulated(tmp_path, "steady", config, STEADY_SCENARIO, seed=3)
    result = run_well(open_well(path))
    seg = result.summary["segments"][0]
    assert seg["stick_slip_to_s"] < seg["t_end_s"] - 5.0  # before the 10-s stop
    rows = result.estimates[(result.estimates["segment_id"] == 1)
                            & (result.estimates["start_id"] == -1)]
    bit = rows.loc[rows["time_s"].between(seg["stick_slip_from_s"], seg["stick_slip_to_s"]),
                   "bit_rpm"].to_numpy(float)
    assert seg["stuck_fraction"] == pytest.approx(np.mean(np.abs(bit) <= 30.0 / np.pi),
                                                  abs=0.05)
    assert stick_slip_severity(bit) < 0.2 and seg["stick_slip_severity"] is None
    assert "no stick-slip: the severity is below 0.2" in seg["message"]
