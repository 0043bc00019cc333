"""Issue 30 (1): ordinary logs with sub-millisecond clocks. ISO 8601 UTC times at
microsecond (or nanosecond) resolution — a recorder's clock jitter, every WITS0 recording of
frames faster than 1 Hz — ended `run`, `live` and `fleet` in "internal error: ArrowInvalid:
Casting from timestamp[ns] to timestamp[us, tz=UTC] would lose data": a clock time was
computed as a timestamp plus a float time turned into a timedelta, leaving stray
nanoseconds. Clock times are now kept in integer nanoseconds (drillfric.io.timebase)."""

from __future__ import annotations

import json
from datetime import UTC, datetime

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from drillfric.cli.main import cli

from drillfric.live.wits0_receiver import FrameClock, Recording
from tests.conftest import DEMO

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow

START = pd.Timestamp("2026-03-01T06:00:00Z")
CHANNELS = ["surface_rpm", "surface_torque_Nm", "hookload_N", "bit_depth_m", "hole_depth_m"]


def _two_stands() -> pd.DataFrame:
    """The demo's first two stands (0–470 s, 20 Hz), its logged channels only."""
    demo = pd.read_csv(DEMO / "demo.csv")
    return demo.loc[demo["time_s"] < 470.0, ["time_s", *CHANNELS]]


def _config(folder) -> str:
    text = (DEMO / "demo.toml").read_text().replace('"demo.survey.csv"',
                                                     repr(str(DEMO / "demo.survey.csv")))
    path = folder / "well.toml"
    path.write_text(text)
    return str(path)


def _run(path, config, out) -> dict:
    done = CliRunner().invoke(cli, ["-q", "run", str(path), "--config", config, "--out",
                                    str(out), "--no-report"])
    assert done.exit_code == 0, done.output
    return json.loads(next(out.glob("*/summary.json")).read_text())


def _jittered(seed: int, unit: str) -> pd.DataFrame:
    """The two stands stamped in ``unit`` ("us", "ns") with ±0.4 ms clock jitter."""
    data = _two_stands()
    rng = np.random.default_rng(seed)
    start = START + pd.Timedelta(int(rng.integers(0, 10**6)), unit="us")
    per = {"us": 1e6, "ns": 1e9}[unit]
    jitter = rng.uniform(-4e-4, 4e-4, len(data))
    stamps = start + pd.to_timedelta(np.round((data["time_s"].to_numpy() + jitter) * per)
                                     .astype(np.int64), unit=unit)
    text = stamps.strftime("%Y-%m-%dT%H:%M:%S.%fZ") if unit == "us" else \
        [s.isoformat() for s in stamps]
    return data.drop(columns="time_s").assign(time=text)[["time", *CHANNELS]]


@pytest.mark.parametrize("unit, seed", [("us", 3), ("ns", 11)])
def test_microsecond_and_nanosecond_jittered_clocks_run_and_keep_their_time(tmp_path, unit,
                                                                           seed):
    """Seed 3 is one of the six of 24 jittered two-stand demo logs that crashed; the
    estimates' clock column is whole microseconds within 1 µs of origin + time_s."""
    frame = _jittered(seed, unit)
    frame.to_csv(tmp_path / "well.csv", index=False)
    summary = _run(tmp_path / "well.csv", _config(tmp_path), tmp_path / "out")
    assert summary["counts"]["estimated"] == 2
    origin = pd.Timestamp(summary["time_origin_utc"])
    assert origin == pd.Timestamp(frame["time"].iloc[0])  # the first stamp, to the ns
    est = pd.read_parquet(next((tmp_path / "out").glob("*/estimates.parquet")))
    late = (est["timestamp"] - origin).dt.total_seconds() - est["time_s"]
    assert late.abs().max() <= 1e-6


def test_wits0_recording_of_10_hz_frames_runs(tmp_path):
    """WITS0 frames carry the time to the second; frames within a second are spaced by
    arrival, so a 10 Hz stream's recording holds microsecond times (the live WITS0 run that
    died after 90 s; seed 4 crashed so)."""
    data = _two_stands().iloc[::2]
    rng = np.random.default_rng(4)
    clock, recording = FrameClock(None), Recording(tmp_path / "well.wits0.csv", CHANNELS,
                                                   utc=True)
    base = START.timestamp()
    for t, *values in data.itertuples(index=False):
        arrival = t + rng.uniform(0.0, 3e-3)  # the network's delay, a few ms
        stamp = datetime.fromtimestamp(base + np.floor(t), UTC).replace(tzinfo=None)
        time_s = clock.time_s(stamp, base + arrival, base + arrival)
        if time_s is not None:
            recording.write(time_s, dict(zip(CHANNELS, values, strict=True)))
    recording.close()
    fractions = pd.to_datetime(pd.read_csv(recording.path)["time"]).dt.microsecond
    assert (fractions % 1000 != 0).mean() > 0.5  # sub-millisecond times, as live writes them
    summary = _run(recording.path, _config(tmp_path), tmp_path / "out")
    assert summary["counts"]["estimated"] == 2
