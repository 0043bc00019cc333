"""Rate-aware honesty (issue 14.4; drillfric.estimation.sampling, docs/bit_speed.md "Logging
rate"): a bit-speed trace only where the log resolves the stick-slip cycle, from the
spacing, the averaging interval or held values — whatever the configuration says.

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
