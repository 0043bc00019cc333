"""Channel skew (issue 34 item 1): the torque's lag behind the speed, identified only where
broadband events time it, corrected before estimation, configured by ``[channels] lag_s``
(docs/theory.md §5.3, docs/bit_speed.md "Channel skew").

The synthetic top drive below is the equation the profile rests on (τ_m = I_TD·dω₀/dt +
Z·ω₀ + a slow friction level): whatever the rate, a lag applied to its torque is the truth
the identification must find or refuse.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from drillfric.config import config_from_dict, torque_lag_s
from drillfric.errors import ConfigError
from drillfric.estimation import skew
from drillfric.estimation.segment_data import SegmentData
from drillfric.io.writers import dumps_toml
from drillfric.result import SegmentRecord
from drillfric.runner.finish import channel_skew
from drillfric.sim.recorder import lagged
from drillfric.units import RPM_TO_RAD_S

#: Top-drive inertia [kg·m²] and the string's torsional impedance at the top [N·m·s/rad]
#: (5 7/8in drill pipe: J·√(Gρ) ≈ 1.2e3).
INERTIA, IMPEDANCE = 2900.0, 1200.0
#: Set-point steps [s, RPM]: start-up, up, down, up — the broadband events of a stand.
STEPS = ((5.0, 60.0), (90.0, 90.0), (160.0, 50.0), (230.0, 70.0))


def top_drive(rate_hz: float, *, steps=STEPS, period_s: float | None = None,
              seed: int = 1, noise_rpm: float = 0.1
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Time [s], speed [RPM] and motor torque [N·m] of a top drive following set-point
    ``steps`` with a 1-s first-order response (or, with ``period_s``, a speed oscillating at
    one stick-slip frequency around 60 RPM), ``noise_rpm`` / 50 N·m of white noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 300.0, 1.0 / rate_hz)
    if period_s is None:
        setpoint = np.zeros_like(t)
        for start, rpm in steps:
            setpoint[t >= start] = rpm
        rpm = np.empty_like(t)
        rpm[0] = 0.0
        dt = 1.0 / rate_hz
        for i in range(1, t.size):
            rpm[i] = rpm[i - 1] + dt / 1.0 * (setpoint[i] - rpm[i - 1])
    else:
        rpm = 60.0 + 25.0 * np.sin(2.0 * np.pi * t / period_s)
    omega = rpm * RPM_TO_RAD_S
    torque = 12e3 + INERTIA * np.gradient(omega, t) + IMPEDANCE * omega
    return (t, rpm + rng.normal(0.0, noise_rpm, t.size),
            torque + rng.normal(0.0, 50.0, t.size))


@pytest.mark.parametrize("rate_hz", [100.0, 10.0, 5.0])
@pytest.mark.parametrize("lag_s", [-2.0, -0.5, 0.0, 0.8, 2.0])
def test_a_lag_timed_by_set_point_steps_is_identified_within_its_tolerance(rate_hz, lag_s):
    """±0.2 s is the issue's tolerance at 10–100 Hz; the stated ± (95 %) must hold the truth
    too (a ± that excludes the truth is a false number)."""
    t, rpm, torque = top_drive(rate_hz)
    found = skew.identify_lag(t, rpm, lagged(t, torque, lag_s))
    assert found.source == "identified", found.reason
    assert abs(found.lag_s - lag_s) <= skew.TOLERANCE_S
    assert abs(found.lag_s - lag_s) <= found.uncertainty_s + 1e-9
    assert found.uncertainty_s <= skew.TOLERANCE_S


@pytest.mark.parametrize("period_s", [3.0, 5.0])
@pytest.mark.parametrize("lag_s", [-1.5, 0.0, 1.0])
def test_stick_slip_at_one_frequency_is_not_identified(period_s, lag_s):
    """At one frequency a lag is a phase shift: the profile peaks again one period away,
    so no lag may be stated (issue 34: the answer for stick-slip-only stands)."""
    t, rpm, torque = top_drive(100.0, period_s=period_s)
    found = skew.identify_lag(t, rpm, lagged(t, torque, lag_s))
    assert found.source == "not identified" and found.lag_s is None


@pytest.mark.parametrize("noise_rpm", [0.5, 1.0, 2.0])
@pytest.mark.parametrize("lag_s", [-1.0, 0.0, 1.0])
def test_a_noisy_speed_never_gives_a_false_lag(noise_rpm, lag_s):
    """Regression: with 0.5 RPM of noise at 100 Hz the torque-on-speed regression alone
    stated −0.6 s for a lag of 0 (the noisy derivative's bias); the two regressions must
    agree, so the lag is right within ±0.2 s or not stated."""
    t, rpm, torque = top_drive(100.0, noise_rpm=noise_rpm)
    found = skew.identify_lag(t, rpm, lagged(t, torque, lag_s))
    assert found.lag_s is None or abs(found.lag_s - lag_s) <= skew.TOLERANCE_S


def _naive_r2(y: np.ndarray, *regressors: np.ndarray) -> float:
    """R² of one least-squares fit, no intercept: the oracle of the profile's correlations."""
    x = np.column_stack(regressors)
    fitted = x @ np.linalg.lstsq(x, y, rcond=None)[0]
    return float(fitted @ fitted) / float(y @ y)


@pytest.mark.parametrize("torque_on_speed", [False, True])
@pytest.mark.parametrize("period_s", [None, 4.0])
def test_the_profile_equals_one_regression_per_lag(torque_on_speed, period_s):
    """The profile's cross-correlations are the per-lag regressions of docs/theory.md eq.
    5.3a, lag by lag (float64 sums of ~6000 products: 1e-9 relative)."""
    t, rpm, torque = top_drive(10.0, period_s=period_s)
    torque = lagged(t, torque, 0.7)
    profile = skew.lag_profile(t, rpm, torque, torque_on_speed=torque_on_speed)
    dt = max(float(np.median(np.diff(t))), skew.PROFILE_STEP_S)  # the profile's own grid
    grid = np.arange(t[0], t[-1], dt)
    k, hp = round(skew.SMOOTH_S / dt), round(skew.HIGH_PASS_S / dt)
    omega = np.interp(grid, t, skew.moving_mean(rpm * RPM_TO_RAD_S, k))
    speed, accel = skew.high_pass(omega, hp), skew.high_pass(np.gradient(omega, dt), hp)
    tau = skew.high_pass(np.interp(grid, t, skew.moving_mean(torque, k)), hp)
    shifts = np.rint(profile.lags_s / dt).astype(int)
    rows = np.arange(hp + shifts[-1], grid.size - hp - shifts[-1])
    naive = [_naive_r2(tau[rows + s], speed[rows], accel[rows]) if torque_on_speed
             else _naive_r2(accel[rows], speed[rows], tau[rows + s]) for s in shifts]
    np.testing.assert_allclose(profile.r2, naive, rtol=1e-9, atol=1e-12)


def test_a_1_hz_log_cannot_time_a_lag():
    t, rpm, torque = top_drive(1.0)
    found = skew.identify_lag(t, rpm, torque)
    assert found.lag_s is None and "interval" in found.reason


def test_a_lag_beyond_the_search_is_not_stated_at_the_edge():
    """A 5-s lag lies outside the ±3 s searched: the best lag sits at the edge (or a rival
    wins) — never a number."""
    t, rpm, torque = top_drive(10.0)
    assert skew.identify_lag(t, rpm, lagged(t, torque, 5.0)).lag_s is None


def test_shifting_undoes_a_lag():
    """shift_torque(lagged(τ, L), L) = τ away from the ends: the correction's sign."""
    t, rpm, torque = top_drive(10.0)
    data = SegmentData(t, rpm, lagged(t, torque, 0.8), 2000.0)
    moved = skew.shift_torque(data, 0.8)
    inside = (moved.time_s > 5.0) & (moved.time_s < 290.0)
    expected = np.interp(moved.time_s[inside], t, torque)
    # linear interpolation of a 10-Hz record: exact on the grid (0.8 s = 8 samples)
    np.testing.assert_allclose(moved.surface_torque_Nm[inside], expected, atol=1e-6)
    assert moved.time_s[-1] <= t[-1] - 0.8 + 1e-9


def test_a_configured_lag_is_applied_and_not_identified():
    t, rpm, torque = top_drive(10.0, period_s=4.0)
    data, found = skew.correct(SegmentData(t, rpm, torque, 2000.0), 0.5)
    assert (found.lag_s, found.uncertainty_s, found.source) == (0.5, 0.0, "config")
    assert data.time_s.size < t.size


def test_lag_s_in_channels():
    """Text with a time unit is converted; positive = the torque lags; only the torque and
    speed channels take one, and not minutes."""
    cfg = config_from_dict({"channels": {"surface_torque": {"column": "STOR",
                                                            "lag_s": "800 ms"},
                                         "surface_rpm": {"lag_s": 0.3}}})
    assert torque_lag_s(cfg.channels) == pytest.approx(0.5)
    assert torque_lag_s(config_from_dict({}).channels) is None
    with pytest.raises(ConfigError, match="surface_torque and surface_rpm only"):
        config_from_dict({"channels": {"hookload": {"lag_s": 1.0}}})
    with pytest.raises(ConfigError, match="magnitude"):
        config_from_dict({"channels": {"surface_torque": {"lag_s": 60}}})
    with pytest.raises(ConfigError):
        config_from_dict({"channels": {"surface_torque": {"lag_s": "3 m"}}})


def test_the_well_lag_pools_identified_segments_and_says_why_not():
    rec = [SegmentRecord(id=1, torque_lag_s=0.9, torque_lag_uncertainty_s=0.05,
                         torque_lag_source="identified"),
           SegmentRecord(id=2, torque_lag_s=1.0, torque_lag_uncertainty_s=0.05,
                         torque_lag_source="identified"),
           SegmentRecord(id=3, torque_lag_source="not identified",
                         message="bit speed withheld: channel skew not identified: rivals")]
    pooled = channel_skew(None, rec)
    assert pooled["lag_s"] == pytest.approx(0.95) and pooled["segments_identified"] == 2
    assert pooled["uncertainty_s"] == pytest.approx(0.05)  # the spread, above the mean's ±
    alone = channel_skew(None, rec[2:])
    assert alone["lag_s"] is None and alone["reason"] == "channel skew not identified: rivals"
    assert channel_skew(0.8, rec)["source"] == "config"


# ------------------------------------------------------------------ the simulator and a run
REPO = Path(__file__).resolve().parents[1]
DEMO = REPO / "examples" / "demo"
#: Set-point steps from rest [s, RPM]: a stand whose start-up and steps time the lag.
STEP_SETPOINT = [[0, 0], [3, 0], [3, 60], [100, 60], [100, 90], [160, 90], [160, 50],
                 [230, 50], [230, 70], [300, 70]]


def _quiet(**extra) -> dict:
    """Overrides of the demo's [simulate] for a short, noise-free record."""
    return dict(bit_depth_m=2300.0, duration_s=40.0, rate_hz=10.0, cells=300,
                torque_noise_Nm=0.0, torque_resolution_Nm=0.0, rpm_noise=0.0,
                rpm_resolution=0.0, **extra)


def test_the_simulator_logs_the_torque_late_and_says_so(tmp_path):
    """``[simulate] torque_lag_s`` delays the recorded torque (value at t = the plant's at
    t − lag) and the configuration written beside the data states it, so ``run`` corrects
    it; the truth channels are not lagged."""
    import drillfric

    base = drillfric.simulate(DEMO / "demo.toml", **_quiet())
    late = drillfric.simulate(DEMO / "demo.toml", out=tmp_path / "late.parquet",
                              **_quiet(torque_lag_s=1.0))
    t = base.columns["time_s"]
    inside = t >= 1.0
    np.testing.assert_allclose(late.columns["surface_torque_Nm"][inside],
                               np.interp(t[inside] - 1.0, t, base.columns["surface_torque_Nm"]),
                               rtol=1e-12, atol=1e-6)  # the same plant, round-off apart
    np.testing.assert_array_equal(late.columns["bit_rpm"], base.columns["bit_rpm"])
    written = tomllib.loads((tmp_path / "late.toml").read_text(encoding="utf-8"))
    assert written["channels"]["surface_torque"]["lag_s"] == 1.0


def _stand_run(tmp_path: Path, lag_s: float, configured: float | None):
    """A 300-s stand of set-point steps at 2300 m (demo well), its torque logged
    ``lag_s`` late at 10 Hz, run with ``configured`` as [channels] lag_s (None: none)."""
    import drillfric

    tmp_path.mkdir()
    (tmp_path / "steps.toml").write_text(dumps_toml({"stand": [
        {"bit_depth_m": 2300.0, "duration_s": 300.0, "setpoint_rpm": STEP_SETPOINT}]}),
        encoding="utf-8")
    cfg = tomllib.loads((DEMO / "demo.toml").read_text(encoding="utf-8"))
    cfg["simulate"].update(scenario="steps.toml", rate_hz=10.0, cells=1000, mu_s=0.6,
                           mu_k=0.25, torque_lag_s=lag_s)
    cfg["survey"] = {"file": str(DEMO / "demo.survey.csv")}
    cfg.pop("channels")
    (tmp_path / "sim.toml").write_text(dumps_toml(cfg), encoding="utf-8")
    data = tmp_path / "well.parquet"
    drillfric.simulate(tmp_path / "sim.toml", out=data)
    run_cfg = tomllib.loads((tmp_path / "well.toml").read_text(encoding="utf-8"))
    run_cfg["channels"] = {} if configured is None else {
        "surface_torque": {"lag_s": configured}}
    (tmp_path / "well.toml").write_text(dumps_toml(run_cfg), encoding="utf-8")
    return drillfric.run(drillfric.open_well(data))


@pytest.mark.slow
def test_a_skewed_stand_is_corrected_and_mu_k_barely_moves(tmp_path):
    """End to end (issue 34 item 1): a torque logged 1 s late is identified within ±0.2 s
    from the stand's set-point steps, reported in summary.json inputs, and the trace no
    longer withheld for the skew (the top-drive inertia check, issue 34 item 2, withholds
    it here: the steps that time the lag make the inertia correction 29 % of the torque's
    variation, and the data do not confirm I_TD); μ_k, a mean-torque fit, moves by < 2 %
    whether the lag is corrected or not (the means of a shifted torque differ by its change
    over the lag at the ends only)."""
    found = _stand_run(tmp_path / "found", 1.0, None)
    skew_in = found.summary["inputs"]["channel_skew"]
    assert skew_in["source"] == "identified"
    assert abs(skew_in["lag_s"] - 1.0) <= skew.TOLERANCE_S
    seg = [g for g in found.summary["segments"] if g["status"] == "ok"][0]
    assert seg["torque_lag_source"] == "identified"
    assert seg["bit_speed_resolved"] or (
        "top-drive inertia" in seg["bit_speed_reason"]
        and "skew" not in seg["bit_speed_reason"])
    ignored = _stand_run(tmp_path / "ignored", 1.0, 0.0)
    assert ignored.summary["inputs"]["channel_skew"]["source"] == "config"
    assert ignored.summary["mu_k"] == pytest.approx(found.summary["mu_k"], rel=0.02)
    assert found.summary["mu_k"] == pytest.approx(0.25, rel=0.05)
