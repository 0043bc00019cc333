"""The ninth hostile-input attack (issue 30): its remaining findings, each a regression test
named after the bug (lasio style), fixtures made here (tmp_path), no field data copied.

The end-to-end cases use the demo's first stand (`drillfric simulate`: creep start-up and
stick-slip at 2210 m, 20 Hz, μ_k = 0.28: examples/demo/demo.truth.json).
"""

from __future__ import annotations

import shutil

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from drillfric.cli.main import cli

from drillfric.errors import InputError
from drillfric.io.well import open_well
from drillfric.runner import run_well
from drillfric.runner.engine import Engine
from tests.conftest import DEMO
from tests.io.io_frames import surface_frame
from tests.test_live import _wait_for

TRUTH_MU_K = 0.28


def _stand() -> pd.DataFrame:
    """The demo's first stand (its first 230 s)."""
    frame = pd.read_csv(DEMO / "demo.csv")
    return frame[frame["time_s"] < 230.0].reset_index(drop=True)


def _well_folder(folder, frame: pd.DataFrame):
    """``folder/demo.csv`` holding ``frame``, with the demo's configuration and survey."""
    folder.mkdir()
    for name in ("demo.toml", "demo.survey.csv"):
        shutil.copy(DEMO / name, folder / name)
    frame.to_csv(folder / "demo.csv", index=False)
    return folder / "demo.csv"


# ------------------------------------------------ F2: a time written twice, other values
def _written_twice(frame: pd.DataFrame, share: float, seed: int) -> tuple[pd.DataFrame,
                                                                         np.ndarray]:
    """``frame`` with ``share`` of its times written twice: first a row with the torque
    halved and the speed 30 % up, then the true row (the first row is the wrong one); the
    positions of the doubled times in the result."""
    rng = np.random.default_rng(seed)
    picks = np.sort(rng.choice(len(frame), int(share * len(frame)), replace=False))
    bad = frame.iloc[picks].assign(surface_torque_Nm=lambda f: 0.5 * f["surface_torque_Nm"],
                                   surface_rpm=lambda f: 1.3 * f["surface_rpm"] + 1.0)
    both = pd.concat([bad.assign(_o=0), frame.assign(_o=1)])
    both = both.sort_values(["time_s", "_o"], kind="stable").drop(columns="_o")
    both = both.reset_index(drop=True)
    twice = np.flatnonzero(both["time_s"].duplicated(keep="last").to_numpy())
    return both, twice


def test_duplicated_timestamps_with_different_values_give_the_same_rows_in_any_chunking():
    """Regression (issue 30, ninth attack): a repeated time's rows were settled chunk by
    chunk (the first row kept); keeping the last or dropping both is chunk-dependent at a
    chunk boundary. The rows of a chunk's last time are held back until the next chunk:
    read in chunks of 1, 2, 3, 7 or 1000 rows, the log gives the rows of one read — the
    doubled times (other values) dropped, an identical repeat kept once."""
    frame, twice = _written_twice(surface_frame(rows=300), 0.1, seed=3)
    once = int(np.flatnonzero(~frame["time_s"].duplicated(keep=False).to_numpy())[5])
    frame = pd.concat([frame.iloc[:once + 1], frame.iloc[once:]],
                      ignore_index=True)  # one identical repeat
    twice[twice > once] += 1
    well = open_well(frame=frame)
    whole = well.load()
    assert (whole.timebase.conflicts_dropped, whole.timebase.duplicates_dropped) == (60, 1)
    assert len(whole.surface) == 300 - 30
    assert not np.isin(whole.surface["time_s"] + frame["time_s"].iloc[0],
                       frame["time_s"].iloc[twice]).any()
    for rows in (1, 2, 3, 7, 1000):
        parts = list(well.chunks(rows))
        pd.testing.assert_frame_equal(pd.concat(parts, ignore_index=True), whole.surface)


def test_duplicated_timestamps_with_different_values_in_most_of_the_log_are_refused(
        tmp_path, capsys):
    """Timestamps cut to whole seconds on a 5-Hz log: every second written five times with
    other values. Nothing of it can be trusted: one line naming the file, the counts and the
    fix, exit 2, nothing written."""
    frame = surface_frame(rows=400)
    frame["time_s"] = np.floor(frame["time_s"])
    path = tmp_path / "coarse.csv"
    frame.to_csv(path, index=False)
    out = tmp_path / "out"
    result = CliRunner().invoke(cli, ["-q", "run", str(path), "--out", str(out),
                                      "--no-report"])
    assert result.exit_code == 2
    line = result.output.strip()
    assert "\n" not in line and "Traceback" not in line
    assert f"{path}: 80 of the log's 80 timestamps (100 %) are repeated with other values " \
           "(400 rows, the first at 0 s in column 'time_s')" in line
    assert "log the time at full resolution" in line
    assert not out.exists() or not any(out.rglob("*.parquet"))


@pytest.mark.slow
def test_duplicated_timestamps_with_different_values_keep_mu_k_within_its_uncertainty(
        tmp_path):
    """Regression (issue 30, ninth attack): 9 % of a simulated stand's times written twice,
    the first row wrong (torque halved, speed 30 % up). The first row of each time was kept:
    μ_k 0.267 ± 0.013 for the truth 0.28 (clean stand: 0.279 ± 0.014), with a warning that
    the repeats were dropped. All rows of a contradicted time are dropped now: μ_k within
    its stated ± of the truth, a warning naming the file and the counts — and the stand fed
    to the engine in chunks cut inside the doubled times (as ``drillfric live`` reads a
    growing file) gives the run's numbers."""
    frame, twice = _written_twice(_stand(), 0.09, seed=30)
    path = _well_folder(tmp_path / "twice", frame)
    whole = run_well(open_well(path))
    mu_k, plus = whole.summary["mu_k"], whole.summary["mu_k_uncertainty"]
    assert abs(mu_k - TRUTH_MU_K) <= plus
    note = next(w for w in whole.summary["warnings"] if "repeated with other values" in w)
    assert note.startswith(f"{path}: {twice.size} of the log's {len(frame) - twice.size} "
                           f"timestamps (9.0 %) are repeated with other values "
                           f"({2 * twice.size} rows")
    cuts = np.unique(np.r_[0, twice[::40], twice[5::40] + 1, len(frame)])
    engine = Engine(open_well(frame=frame.iloc[:10], config=path.with_suffix(".toml"),
                              survey=path.with_suffix(".survey.csv"), name="demo"))
    for a, b in zip(cuts[:-1], cuts[1:], strict=True):
        engine.feed(frame.iloc[a:b])
    fed = engine.result()
    assert fed.summary["inputs"]["rows"] == whole.summary["inputs"]["rows"]
    assert fed.summary["mu_k"] == pytest.approx(mu_k, rel=0.005)
    assert fed.segments["t_end_s"].tolist() == whole.segments["t_end_s"].tolist()


# ------------------------------------------------ F7: an absurd observer noise setting
@pytest.mark.parametrize("value", [1000, 5.5])
def test_observer_speed_noise_rpm_of_1000_is_refused_naming_key_value_and_range(
        value, tmp_path, capsys):
    """Regression (issue 30, ninth attack): ``observer.speed_noise_rpm = 1000`` was taken:
    the observer then ignores the speed it is given, and its bit trace, shown as resolved,
    was 54 RPM RMS from the bit. A speed sensor's noise is at most a few RPM: one line
    naming the key, the value, the allowed range and the fix; exit 2, nothing written."""
    frame = surface_frame(rows=50)
    path = tmp_path / "w.csv"
    frame.to_csv(path, index=False)
    path.with_suffix(".toml").write_text(f"[observer]\nspeed_noise_rpm = {value}\n")
    out = tmp_path / "out"
    result = CliRunner().invoke(cli, ["-q", "run", str(path), "--out", str(out),
                                      "--no-report"])
    assert result.exit_code == 2
    line = result.output.strip()
    assert "\n" not in line and "Traceback" not in line
    assert f"key 'observer.speed_noise_rpm' = {value:g} is outside (0, 5]" in line
    assert "fix: give a value (0, 5] [RPM]" in line
    assert not out.exists()


# ------------------------------------------------ F5b: 10-Hz frames flushed once a second
def _unstamped_bursts(bursts: int, per_burst: int = 10) -> list[bytes]:
    """``bursts`` bursts of ``per_burst`` WITS0 frames without date and time (speed = the
    frame's number)."""
    from drillfric.io.wits0 import encode, item_map

    items = item_map({})
    return [b"".join(encode({"surface_rpm": float(b * per_burst + k)}, items)
                     for k in range(per_burst)) for b in range(bursts)]


def _seconds(times: pd.Series) -> np.ndarray:
    """Recorded ISO times as seconds from the first [s]."""
    stamps = pd.to_datetime(times)
    return (stamps - stamps.iloc[0]).dt.total_seconds().to_numpy()


def _receiver(tmp_path, warned: list):
    from drillfric.io.wits0 import Row, item_map
    from drillfric.live.wits0_receiver import Receiver, Recording, parse_address, setup

    address = parse_address("wits0://127.0.0.1:5000")
    return Receiver(address, setup(address, None, "t"),
                    Recording(tmp_path / "t.wits0.csv", Row(item_map({})).names, False),
                    warn=warned.append)


def test_wits0_frames_without_time_flushed_once_a_second_are_spread_not_1_ms_apart(tmp_path):
    """Regression (issue 30, ninth attack): a recorder flushing its 10-Hz frames once a
    second, without their date and time, had them recorded 1 ms apart (μ_k right, the bit
    trace withheld). A burst's frames are spread evenly over the time since the previous
    burst — 0.1 s apart — and the burst is said once."""
    warned: list[str] = []
    receiver = _receiver(tmp_path, warned)
    for k, burst in enumerate(_unstamped_bursts(4)):
        receiver._take(burst, 100.0 + k)
    receiver.recording.close()
    got = pd.read_csv(tmp_path / "t.wits0.csv")
    t = _seconds(got["time"])
    assert got["surface_rpm"].tolist() == [float(k) for k in range(40)]
    np.testing.assert_allclose(np.diff(t[9:]), 0.1, atol=2e-6)  # after the first burst
    assert len(warned) == 1
    assert "10 frames without a date and time arrived together" in warned[0]
    assert "spread evenly over the 1 s since the previous burst, 0.1 s apart" in warned[0]


def test_wits0_burst_cut_into_two_reads_is_one_burst(tmp_path):
    """A burst that TCP delivers in two reads a few ms apart is gathered as one (its frames
    spread alike), over a real socket."""
    import socket
    import threading
    import time

    listener = socket.create_server(("127.0.0.1", 0))
    warned: list[str] = []
    receiver = _receiver(tmp_path, warned)
    receiver.address = receiver.address.__class__("127.0.0.1", listener.getsockname()[1])
    thread = threading.Thread(target=receiver.run, daemon=True)
    listener.settimeout(10)
    thread.start()
    try:
        conn, _ = listener.accept()
        for burst in _unstamped_bursts(3):
            half = len(burst) // 2
            conn.sendall(burst[:half])
            time.sleep(0.005)
            conn.sendall(burst[half:])
            time.sleep(0.5)
        _wait_for(lambda: receiver.frames >= 30, 10)
        receiver.stop.set()
        conn.close()
    finally:
        receiver.stop.set()
        thread.join(5)
        listener.close()
    got = pd.read_csv(tmp_path / "t.wits0.csv")
    t = _seconds(got["time"])
    steps = np.diff(t[10:])  # the second and third bursts: ~0.5 s / 10 apart
    assert len(got) == 30 and (steps > 0.03).all() and (steps < 0.08).all()


# ------------------------------------------------ messages: a survey tie-in written twice
def test_a_survey_tie_in_station_written_twice_identically_is_dropped_with_a_warning(tmp_path):
    """Regression (issue 30, ninth attack): a tie-in station repeated exactly (same MD,
    inclination and azimuth) refused the whole survey ("depths not increasing"). It is one
    station written twice: dropped, with one warning naming the file and the MD."""
    from drillfric.io.survey import SurveyWarning, read_survey

    path = tmp_path / "s.csv"
    path.write_text("MD,INC,AZI,TVD\n500,2.5,45,499.9\n500,2.5,45,499.9\n800,10,50,\n"
                    "1100,20,55,\n")
    with pytest.warns(SurveyWarning) as caught:
        well_path = read_survey(path)
    assert [str(w.message) for w in caught] == [
        f"{path}: survey station 2 repeats station 1 exactly (MD 500 m): dropped (a tie-in "
        "station written twice)"]
    assert well_path.md_m.tolist() == [500.0, 800.0, 1100.0]


def test_a_survey_station_repeated_with_other_values_is_refused_naming_the_md(tmp_path,
                                                                             capsys):
    """Two stations at one MD with different angles: which is the station cannot be told —
    one line naming the file, the MD and both readings, exit 2."""
    frame = surface_frame(rows=50)
    path = tmp_path / "w.csv"
    frame.to_csv(path, index=False)
    path.with_suffix(".survey.csv").write_text("MD,INC,AZI\n0,0,0\n500,2.5,45\n500,3,45\n"
                                               "2600,20,55\n")
    result = CliRunner().invoke(cli, ["-q", "run", str(path), "--out", str(tmp_path / "o"),
                                      "--no-report"])
    assert result.exit_code == 2
    line = result.output.strip()
    assert "\n" not in line and "Traceback" not in line
    assert (f"{path.with_suffix('.survey.csv')}: survey stations 2 and 3 are both at MD 500 m "
            "with different values (inclination / azimuth 2.5° / 45° and 3° / 45°)") in line
    assert "fix: keep one station at MD 500 m" in line


# ------------------------------------------------ messages: a clock going back
def _clock_log(tmp_path, stamps: list[str]):
    frame = surface_frame(rows=len(stamps))
    frame["time_s"] = stamps
    path = tmp_path / "clock.csv"
    frame.rename(columns={"time_s": "time"}).to_csv(path, index=False)
    return path


def test_a_dst_fall_back_is_named_with_its_timestamp_and_the_fix(tmp_path):
    """Regression (issue 30, ninth attack): a local clock's daylight-saving fall-back
    (02:59:59 then 02:00:00, no UTC offset) refused the log as "time goes backwards" with
    "sort the file by time" — which would scramble it. The line says where, that it is a
    fall-back, and to export the times in UTC or with their offset."""
    stamps = ["2026-10-25T02:59:58", "2026-10-25T02:59:59", "2026-10-25T02:00:00",
              "2026-10-25T02:00:01"]
    path = _clock_log(tmp_path, stamps)
    with pytest.raises(InputError) as caught:
        open_well(path).load()
    assert caught.value.message == (
        f"{path}: time goes backwards at data row 3 (2026-10-25 02:00:00 after "
        "2026-10-25 02:59:59): back 60 min, a daylight-saving fall-back of a local clock "
        "written without its UTC offset — fix: export the times in UTC or with their offset "
        "(e.g. 2026-10-25T02:30:00+01:00), or give a time_s column")


def test_a_clock_stepped_back_035_s_is_named_with_its_timestamp_and_the_fix(tmp_path):
    """Regression (issue 30, ninth attack): a 0.35-s clock step back (a clock synchronised
    while logging) refused the log with "sort the file by time". The line names the row and
    the timestamps, the step, and which rows to remove."""
    stamps = ["2026-03-01T06:00:00.00", "2026-03-01T06:00:00.50", "2026-03-01T06:00:00.15",
              "2026-03-01T06:00:00.65"]
    path = _clock_log(tmp_path, stamps)
    with pytest.raises(InputError) as caught:
        open_well(path).load()
    assert caught.value.message == (
        f"{path}: time goes backwards at data row 3 (2026-03-01 06:00:00.150000 after "
        "2026-03-01 06:00:00.500000): back 0.35 s, a clock stepped back (set or synchronised "
        "while logging) — fix: remove the rows from that one on whose time is not after "
        "2026-03-01 06:00:00.500000 (the 0.35 s the clock logged twice), or give a time_s "
        "column that never goes back")


def test_overlapping_hourly_exports_name_the_two_parts_not_the_folder(tmp_path):
    """Regression (issue 30, ninth attack): two hourly exports of a folder overlapping (the
    second starting before the first ends) were refused naming the folder only. The line
    names both parts and where they overlap."""
    well = tmp_path / "A-12"
    (well / "hourly").mkdir(parents=True)
    (well / "well.toml").write_text('[well]\ndata = "hourly"\n')
    frame = surface_frame(rows=60)
    frame.iloc[:40].to_csv(well / "hourly" / "06.csv", index=False)
    frame.iloc[30:].to_csv(well / "hourly" / "07.csv", index=False)  # 10 rows again
    with pytest.raises(InputError) as caught:
        open_well(well).load()
    assert caught.value.message == (
        f"{well / 'hourly'}: part '07.csv' starts at 6 s, before part '06.csv' ends (7.8 s): "
        "the two parts of the log overlap — fix: the parts are read in name order (numbers by "
        "value), the files are never changed: if the names do not sort in time order, copy the "
        "parts into a new folder under names that do; if '07.csv' exports hours already logged "
        "again, move it into a sub-folder (not read)")  # no fix that edits a file: tenth attack
    (well / "hourly" / "07.csv").write_text(
        frame.iloc[40:].assign(time_s=lambda f: f["time_s"].where(f.index != 50, 1.0))
        .to_csv(index=False))
    with pytest.raises(InputError, match="time goes backwards at data row 11 of part "
                                         "'07.csv' \\(1 s after 9.8 s\\)"):
        open_well(well).load()


# ------------------------------------------------ messages: a time or speed in another unit
def test_date_and_hhmmss_columns_are_not_read_as_seconds(tmp_path):
    """Regression (issue 30, ninth attack): DATE and TIME (HHMMSS) columns had the TIME read
    as seconds — 235859 then 235900 a 41-s gap every minute, and the log refused only where
    it crossed midnight, as "time goes backwards". One line names the columns, the rows and
    the fix; exit 2."""
    frame = surface_frame(rows=400, rate_hz=1.0)
    stamps = pd.Timestamp("2026-11-27 23:58:00") + pd.to_timedelta(frame["time_s"], unit="s")
    frame.insert(0, "DATE", stamps.dt.strftime("%Y%m%d").astype(int))
    frame.insert(1, "TIME", stamps.dt.strftime("%H%M%S").astype(int))
    frame = frame.drop(columns="time_s").rename(columns={"surface_rpm": "RPM"})
    path = tmp_path / "w.csv"
    frame.to_csv(path, index=False)
    for rows in (1, 7, 1000):  # the same line in any chunking
        with pytest.raises(InputError) as caught:
            list(open_well(path).chunks(rows))
        assert caught.value.message == (
            f"{path}: time column 'TIME' holds times of day written as HHMMSS beside the date "
            "column 'DATE' (235859 then 235900 at data row 61: 1 s, read as seconds 41): "
            "drillfric reads a time column as seconds or as timestamps — fix: give one time "
            "column of ISO 8601 timestamps, date and time together (e.g. 2026-11-27T23:59:00), "
            "or a time_s column")


def test_a_log_in_seconds_with_one_gap_over_60_to_99_is_not_taken_for_hhmmss():
    """One 41-s gap skipping 60–99 s of a log in seconds looks like a minute of HHMMSS: it
    takes two such steps to be called that."""
    t = np.r_[np.arange(0.0, 60.0), np.arange(100.0, 160.0)]
    frame = surface_frame(rows=t.size, rate_hz=1.0).assign(time_s=t)
    assert len(open_well(frame=frame).load().surface) == t.size


def _run_line(tmp_path, frame, config: str = ""):
    path = tmp_path / "w.csv"
    frame.to_csv(path, index=False)
    if config:
        path.with_suffix(".toml").write_text(config)
    result = CliRunner().invoke(cli, ["-q", "run", str(path), "--out", str(tmp_path / "o"),
                                      "--no-report"])
    return path, result


_NEUTRAL = {"surface_rpm": "RPM", "surface_torque_Nm": "TORQUE", "hookload_N": "HKLD",
            "bit_depth_m": "BITDEPTH", "time_s": "TIME"}
_SI = ('[channels]\nsurface_torque = { column = "TORQUE", unit = "N.m" }\n'
       'hookload = { column = "HKLD", unit = "N" }\n')


def test_time_in_minutes_says_every_rotation_is_short_and_how_to_say_minutes(tmp_path):
    """Regression (issue 30, ninth attack): a 1-Hz log's time written in minutes ran to
    "too short: 6.65 s < 30 s" for every rotation, nothing more. A warning says the samples
    are 1/60 s apart, that in minutes the rotation would be 399 s, and the config line."""
    frame = surface_frame(rows=400, rate_hz=1.0)
    frame["time_s"] /= 60.0
    path, result = _run_line(tmp_path, frame.rename(columns=_NEUTRAL), _SI)
    assert result.exit_code == 0, result.output
    assert (f"{path}: every rotation is too short (the longest 6.65 s < "
            "segmentation.min_segment_s = 30 s), its samples 0.0167 s apart: if the time "
            "column 'TIME' is in minutes (the longest 399 s, samples 1 s apart), say so: "
            '[channels] time = { column = "TIME", unit = "min" }') in result.output


def test_speed_in_rad_s_says_the_top_speed_and_how_to_say_rad_s(tmp_path):
    """Regression (issue 30, ninth attack): a speed column in rad/s ran to "the top drive
    never turns faster than ω_c". The segment's message gives ω_c and the top speed in RPM,
    and a warning names the column, its top, the RPM it would be and the config line."""
    frame = surface_frame(rows=400, rate_hz=1.0)
    frame["surface_rpm"] *= 2.0 * np.pi / 60.0
    path, result = _run_line(tmp_path, frame.rename(columns=_NEUTRAL), _SI)
    assert result.exit_code == 0, result.output
    top = frame["surface_rpm"].max()
    assert (f"{path}: the surface speed column 'RPM' reads at most {top:.3g} RPM, where a top "
            f"drive turns at 30–250: if it is in rad/s ({top:.3g} rad/s = "
            f"{top * 60 / (2 * np.pi):.3g} RPM), say so: [channels] surface_rpm = "
            '{ column = "RPM", unit = "rad/s" }') in result.output
    assert f"never turns faster than ω_c (9.55 RPM): at most {top:.3g} RPM" in result.output


# ------------------------------------------------ messages: WOB and hook load swapped
def test_wob_and_hook_load_swapped_are_refused_naming_both_columns(tmp_path):
    """Regression (issue 30, ninth attack): a log with its WOB and hook-load columns swapped
    passed every plausibility check (every rotation then on bottom). A WOB above the hook
    load in most rows cannot be: one line naming both columns, the share, the loads and the
    mapping that swaps them back; exit 2."""
    frame = surface_frame(rows=400, rate_hz=1.0)
    rng = np.random.default_rng(4)
    frame["wob_N"] = 80e3 + rng.normal(0.0, 5e3, len(frame))
    frame = frame.rename(columns={"wob_N": "HKLD", "hookload_N": "WOB"})
    frame = frame.rename(columns={"HKLD": "HKLD [N]", "WOB": "WOB [N]"})
    path, result = _run_line(tmp_path, frame)
    assert result.exit_code == 2, result.output
    line = result.output.strip()
    assert "\n" not in line and "Traceback" not in line
    assert (f"{path}: the weight-on-bit column 'WOB [N]' reads more than the hook-load column "
            "'HKLD [N]' in 100 % of the rows (mean 1200 kN against 8") in line
    assert ('the two columns look swapped — fix: map them the other way round: [channels] '
            'wob = { column = "HKLD [N]" }, hookload = { column = "WOB [N]" }') in line
    assert not any((tmp_path / "o").rglob("*.parquet"))
