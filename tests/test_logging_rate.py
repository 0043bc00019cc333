"""Rate-aware honesty (issue 14.4; drillfric.estimation.sampling, docs/bit_speed.md "Logging
rate"): a bit-speed trace only where the log resolves the stick-slip cycle, from the
spacing, the averaging interval, held values or a moving average written at the full rate
— whatever the configuration says.

The end-to-end cases use the demo's first stand (creep start-up and severe stick-slip at
2210 m, 20 Hz, examples/demo) as an EDR would have written it. The shortest stick-slip
cycle there is the string's first torsional period, 4 × the wave travel time ≈ 3.3 s
(docs/theory.md §3): 1-s and 5-s intervals give 3.3 and 0.7 samples per cycle, below the 6
needed.
"""

from __future__ import annotations

import json
import shutil

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from drillfric.cli.main import cli

from drillfric.estimation import sampling
from drillfric.sim import recorder
from tests.conftest import REPO

DEMO = REPO / "examples" / "demo"


# --- the effective interval -----------------------------------------------------------------

def test_held_values_give_the_update_interval():
    """A 1-Hz log forward-filled from 5-s values changes every 5 samples: 5 s."""
    t = np.arange(600.0)
    rng = np.random.default_rng(0)
    held = np.repeat(rng.normal(60.0, 5.0, 120), 5)
    assert sampling.held_interval_s(t, held, held * 100) == pytest.approx(5.0)


def test_quantised_spot_values_are_not_held():
    """Quantised noisy spot values repeat too, but at irregular steps: not held values."""
    rng = np.random.default_rng(1)
    t = np.arange(0.0, 60.0, 0.01)
    rpm = np.round(60.0 + rng.normal(0.0, 0.4, t.size))  # 1-RPM resolution
    torque = np.round((12e3 + rng.normal(0.0, 80.0, t.size)) / 100.0) * 100.0
    assert sampling.held_interval_s(t, rpm, torque) is None


def test_one_channel_held_sets_the_interval():
    """Ninth attack: a torque sampled and held every 1 s beside a 10-Hz speed. The changes
    of the two together come every sample, yet the estimate rests on 1-s torques: the
    slowest channel sets the interval (its trace had been shown resolved, 48 RPM RMS off).
    Quantised spot values of either channel alone still are no hold."""
    rng = np.random.default_rng(2)
    t = np.arange(0.0, 120.0, 0.1)
    rpm = 60.0 + rng.normal(0.0, 3.0, t.size)
    torque = np.repeat(12e3 + rng.normal(0.0, 500.0, t.size // 10), 10)
    logged = sampling.logging_interval(t, rpm, torque)
    assert logged.interval_s == pytest.approx(1.0) and logged.kind == "held values"
    quantised = np.round(60.0 + rng.normal(0.0, 0.4, t.size))
    assert sampling.held_interval_s(t, quantised) is None


def test_min_max_channels_make_the_rows_interval_means():
    """With the torque's interval min/max the rows are aggregates over their spacing; the
    swing inside each interval is reported."""
    t = np.arange(0.0, 100.0, 5.0)
    mean = np.full(t.size, 10e3)
    logged = sampling.logging_interval(t, 60 + 0 * t, mean, torque_min_Nm=mean - 4e3,
                                       torque_max_Nm=mean + 4e3)
    assert logged == sampling.LoggingInterval(5.0, "means", 0.8)
    spot = sampling.logging_interval(t, 60 + 0 * t, mean)
    assert spot.kind == "samples" and spot.torque_swing is None


def test_resolution_says_why_and_what_the_swing_shows():
    slow = sampling.LoggingInterval(5.0, "means", 0.8)
    res = sampling.resolution(slow, 3.3)
    assert not res.resolved and res.samples_per_cycle == pytest.approx(0.66)
    assert "5-s means" in res.reason and "probably stick-slipping" in res.reason
    steady = sampling.resolution(sampling.LoggingInterval(5.0, "means", 0.1), 3.3)
    assert "no sign of stick-slip" in steady.reason
    assert sampling.resolution(sampling.LoggingInterval(0.05, "samples"), 3.3).resolved


@pytest.mark.parametrize("rate_hz", [20.0, 100.0])
@pytest.mark.parametrize("width_s", [0.5, 2.0, 5.0])
def test_a_moving_average_at_the_full_rate_gives_its_width(rate_hz, width_s):
    """A w-sample moving average puts a null at every multiple of 1/(wΔt) in the spectrum
    of the differences: found to the sample, on a random walk with white noise (a signal
    whose raw spectrum has no nulls of its own)."""
    rng = np.random.default_rng(int(rate_hz + 10 * width_s))
    t = np.arange(0.0, 600.0, 1.0 / rate_hz)
    raw = np.cumsum(rng.normal(size=t.size)) + 3.0 * rng.normal(size=t.size)
    w = int(round(width_s * rate_hz))
    smoothed = np.convolve(raw, np.ones(w) / w, mode="valid")
    assert sampling.moving_average_s(t, raw) is None
    assert sampling.moving_average_s(t[:smoothed.size], smoothed) == pytest.approx(width_s)
    logged = sampling.logging_interval(t[:smoothed.size], smoothed, raw[:smoothed.size])
    assert logged.kind == "moving averages" and logged.interval_s == pytest.approx(width_s)


def test_the_demo_as_logged_is_not_taken_for_moving_averages(first_stand):
    """The demo's stand (20 Hz spot values with sensor noise, stick-slip): no moving
    average found in either channel."""
    assert sampling.moving_average_s(first_stand["time_s"], first_stand["surface_rpm"],
                                     first_stand["surface_torque_Nm"]) is None


# --- end to end ------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def first_stand():
    """The demo's first stand at 20 Hz (0–230 s) as columns."""
    frame = pd.read_csv(DEMO / "demo.csv")
    frame = frame[frame["time_s"] < 230.0]
    return {c: frame[c].to_numpy(float) for c in frame.columns}


def _run(folder, columns, tmp_path):
    """Write ``columns`` as the demo well in ``folder`` and run it; the first segment."""
    folder.mkdir()
    for name in ("demo.toml", "demo.survey.csv"):
        shutil.copy(DEMO / name, folder / name)
    pd.DataFrame(columns).to_csv(folder / "demo.csv", index=False)
    result = CliRunner().invoke(cli, ["run", str(folder / "demo.csv"), "--out",
                                      str(tmp_path / "out"), "--no-report"])
    assert result.exit_code == 0, result.output
    out = tmp_path / "out" / "demo"
    summary = json.loads((out / "summary.json").read_text())
    estimates = pd.read_parquet(out / "estimates.parquet")
    return summary["segments"][0], estimates


def test_5_s_means_with_min_max_report_no_bit_trace(first_stand, tmp_path):
    """5-s EDR means (with min/max) of a stand in severe stick-slip: μ_k still (the mean of
    means is the mean), but no bit speed, no stuck fraction, no trace — null with the
    reason, which the min/max channels let say that the string does stick-slip."""
    seg, estimates = _run(tmp_path / "w", recorder.block_means(first_stand, 5.0), tmp_path)
    assert seg["status"] == "ok" and seg["mu_k"] is not None
    assert seg["sample_interval_s"] == pytest.approx(5.0)
    assert seg["interval_torque_swing"] > sampling.STICK_SLIP_SWING
    assert seg["bit_speed_resolved"] is False
    assert seg["stuck_fraction"] is None and seg["stick_slip_severity"] is None
    assert "5-s means" in seg["bit_speed_reason"]
    assert "probably stick-slipping" in seg["bit_speed_reason"]
    rows = estimates[estimates["segment_id"] == seg["id"]]
    assert rows["bit_rpm_est"].isna().all()


def test_held_values_are_seen_without_configuration(first_stand, tmp_path):
    """1-s means written at 20 Hz (each value held for 20 rows, no [rig] key): the log is
    taken at its update interval — no bit speed, and the creep start is not fitted as if
    it were logged at 20 Hz."""
    means = recorder.block_means(first_stand, 1.0, minmax=False)
    held = {k: np.repeat(v, 20) for k, v in means.items()}
    held["time_s"] = means["time_s"][0] + 0.05 * np.arange(held["time_s"].size)
    seg, _ = _run(tmp_path / "w", held, tmp_path)
    assert seg["sample_interval_s"] == pytest.approx(1.0, rel=0.05)
    assert seg["bit_speed_resolved"] is False and "held values" in seg["bit_speed_reason"]
    assert "creep_rate_too_low" in seg["quality_flags"]
    assert not seg["mu_s_identifiable"]


def test_a_5_s_moving_average_at_20_hz_is_not_a_20_hz_log(first_stand, tmp_path):
    """Regression (issue 30, sixth attack): speed and torque smoothed by a 5-s moving
    average and written at the demo's 20 Hz reported the bit trace as resolved, with a
    stuck fraction of 0.23 for 0.55–0.68 and a severity of 1.35 for 2.5–4.6. The log holds
    one value per 5 s: no bit speed, no statistics, and the reason names the smoothing."""
    smooth = dict(first_stand)
    for name in ("surface_rpm", "surface_torque_Nm"):
        smooth[name] = pd.Series(first_stand[name]).rolling(100, min_periods=1).mean().to_numpy()
    seg, estimates = _run(tmp_path / "w", smooth, tmp_path)
    assert seg["sample_interval_s"] == pytest.approx(5.0)
    assert seg["bit_speed_resolved"] is False
    assert "5-s moving averages" in seg["bit_speed_reason"]
    assert "smoothing off" in seg["bit_speed_reason"]
    assert seg["stuck_fraction"] is None and seg["stick_slip_severity"] is None
    rows = estimates[estimates["segment_id"] == seg["id"]]
    assert rows["bit_rpm_est"].isna().all()
