"""WITS level 0 (issue 24, docs/live.md): the decoder (cut, blank, garbage and hostile
streams), the item units against hand-computed SI values, the frame clock, the recording,
and end to end over real TCP sockets on 127.0.0.1: `replay --to wits0://` with one dropped
connection and `live wits0://… --until-idle` give the results of `run` on the whole file,
and a live run killed with -9 and restarted loses and repeats no row."""

from __future__ import annotations

import json
import math
import signal
import socket
import threading
from datetime import UTC, datetime

import numpy as np
import pandas as pd
import pytest

from drillfric.errors import ConfigError, InputError
from drillfric.io.wits0 import MAX_LINE, Decoder, Row, encode, frame_clock, item_map
from drillfric.live.wits0_receiver import (
    HANDSHAKE,
    FrameClock,
    Receiver,
    Recording,
    parse_address,
    setup,
)
from tests.conftest import DEMO, SCENARIO
from tests.test_live import _drillfric, _finish, _same_segments, _wait_for

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow

FRAME = (b"&&\r\n0105261127\r\n0106143015\r\n01082450.5\r\n01102455.0\r\n"
         b"0114150.0\r\n011818.42\r\n012041.0\r\n!!\r\n")


# ---------------------------------------------------------------- decoder
def test_a_frame_cut_at_every_byte_decodes_whole_once():
    stream = FRAME * 2
    for cut in range(len(stream) + 1):
        decoder = Decoder()
        frames = decoder.feed(stream[:cut]) + decoder.feed(stream[cut:])
        assert len(frames) == 2, cut
        assert frames[0] == {"0105": "261127", "0106": "143015", "0108": "2450.5",
                             "0110": "2455.0", "0114": "150.0", "0118": "18.42", "0120": "41.0"}


def test_bare_carriage_returns_end_lines():
    """Ninth attack: a recorder ending its lines with a bare CR had no frame decoded ("no
    WITS0 frame arrived … check the address"), while the file readers take bare CR."""
    stream = FRAME.replace(b"\r\n", b"\r") * 2
    for cut in (0, 7, len(stream) // 2, len(stream)):
        decoder = Decoder()
        frames = decoder.feed(stream[:cut]) + decoder.feed(stream[cut:])
        assert len(frames) == 2 and frames[0]["0118"] == "18.42", cut


def test_blank_lines_bare_newlines_unknown_codes_and_garbage_are_tolerated():
    noisy = (b"\r\n\nhello\n&&\n\n0114150.0\n9999123\n  \r\nnot an item\n012041.0\r\n!!\n"
             b"0120 stray line outside a frame\n")
    decoder = Decoder()
    frames = decoder.feed(noisy)
    assert frames == [{"0114": "150.0", "9999": "123", "0120": "41.0"}]
    assert decoder.ignored == 3  # hello, 'not an item', the stray line
    rows = Row(item_map({}))
    values = rows.update(frames[0])
    assert values["hookload_N"] == 1.5e6 and values["surface_rpm"] == 41.0
    assert math.isnan(values["wob_N"])  # never sent


def test_a_frame_cut_by_a_dropped_connection_is_discarded_and_the_next_decodes():
    decoder = Decoder()
    assert decoder.feed(FRAME[:40]) == []
    decoder.reset()  # the connection dropped
    assert decoder.discarded == 1
    assert decoder.feed(FRAME) != [] and decoder.frames == 1


def test_hostile_ten_megabyte_line_stays_bounded_and_the_stream_recovers():
    decoder = Decoder()
    blob = b"&&\r\n0114" + b"9" * 10_000_000
    for i in range(0, len(blob), 65536):
        assert decoder.feed(blob[i:i + 65536]) == []
        assert len(decoder._pending) <= MAX_LINE
    assert decoder.feed(b"\r\n!!\r\n" + FRAME)[0]["0114"] == "150.0"
    assert decoder.discarded == 1  # the frame holding the monster line


def test_a_frame_of_too_many_items_is_dropped():
    decoder = Decoder()
    huge = b"&&\n" + b"".join(b"%04d1.0\n" % (i % 10000) for i in range(5000)) + b"!!\n"
    assert decoder.feed(huge) == [] and decoder.discarded == 1


def test_non_numeric_and_null_values_are_missing_not_numbers():
    values = Row(item_map({})).update({"0114": "abc", "0118": "-999.25", "0120": "nan",
                                       "0108": "1e999"})
    assert all(math.isnan(values[n]) for n in ("hookload_N", "surface_torque_Nm",
                                               "surface_rpm", "bit_depth_m"))


def test_an_omitted_item_keeps_its_last_value():
    row = Row(item_map({}))
    row.update({"0120": "41.0", "0118": "18.0"})
    assert row.update({"0118": "19.0"})["surface_rpm"] == 41.0


# ---------------------------------------------------------------- units
def test_metric_units_kdn_and_a_kn_override_against_hand_computed_si():
    row = Row(item_map({}))
    v = row.update({"0114": "150.0", "0116": "2.5", "0118": "18.42", "0121": "12000",
                    "0113": "36", "0108": "2450.5"})
    assert v["hookload_N"] == 1.5e6  # 150 KDN = 1500 kN
    assert v["wob_N"] == 25e3
    assert v["surface_torque_Nm"] == pytest.approx(18420.0)
    assert v["standpipe_pressure_Pa"] == 12e6
    assert v["rop_m_s"] == pytest.approx(0.01)  # 36 m/h
    assert v["bit_depth_m"] == 2450.5
    kn = Row(item_map({"hookload": {"unit": "kN"}})).update({"0114": "150.0"})
    assert kn["hookload_N"] == 150e3


def test_field_units_against_hand_computed_si():
    v = Row(item_map({}, "field")).update({"0114": "300", "0118": "10", "0108": "8000",
                                           "0121": "3000", "0113": "100", "0120": "60"})
    assert v["hookload_N"] == pytest.approx(300 * 4448.2216152605)  # klb
    assert v["surface_torque_Nm"] == pytest.approx(10 * 1355.8179483314)  # kft·lbf
    assert v["bit_depth_m"] == pytest.approx(8000 * 0.3048)
    assert v["standpipe_pressure_Pa"] == pytest.approx(3000 * 6894.757293168)
    assert v["rop_m_s"] == pytest.approx(100 * 0.3048 / 3600)
    assert v["surface_rpm"] == 60.0


def test_channels_override_an_items_code_and_map_another_record():
    slots = item_map({"surface_rpm": {"column": 199}, "bit_rpm": {"column": "0824",
                                                                  "unit": "rpm"}})
    assert slots["0199"].channel.name == "surface_rpm" and "0120" not in slots
    assert slots["0824"].channel.name == "bit_rpm"
    for bad in ({"hookload": {"column": "HKLA"}}, {"hookload": {"column": "0118"}},
                {"bit_rpm": {"unit": "rpm"}}, {"wob": {"column": "0105"}},
                {"hookload": {"unit": "kN.m"}}):
        with pytest.raises(ConfigError):
            item_map(bad)


def test_encode_then_decode_gives_the_si_values_back():
    values = {"hookload_N": 1234567.8, "surface_torque_Nm": 17654.3, "surface_rpm": 57.1,
              "bit_depth_m": 2233.4, "wob_N": float("nan")}
    clock = datetime(2026, 11, 27, 14, 30, 15)
    frame = Decoder().feed(encode(values, item_map({}), clock))[0]
    assert frame_clock(frame) == clock
    back = Row(item_map({})).update(frame)
    for name, value in values.items():
        assert back[name] == pytest.approx(value, rel=1e-12, nan_ok=True)


# ---------------------------------------------------------------- time and recording
def test_frames_sharing_a_second_are_spaced_by_arrival_and_time_only_increases():
    clock, stamp = FrameClock(None), datetime(2026, 11, 27, 14, 30, 15)
    times = [clock.time_s(stamp, 10.0 + k * 0.25, 0.0) for k in range(3)]
    assert np.diff(times) == pytest.approx([0.25, 0.25])
    nxt = clock.time_s(datetime(2026, 11, 27, 14, 30, 16), 11.0, 0.0)
    assert nxt - times[0] == pytest.approx(1.0)
    assert clock.time_s(stamp, 11.1, 0.0) is None and clock.out_of_order == 1  # went back
    # no date/time after stamped frames: the rig's clock carried by the arrival time — not
    # the computer's UTC clock (ninth attack: a rig clock hours behind UTC, one frame
    # without its stamp, and every later frame was dropped as "before" it)
    assert clock.time_s(None, 12.0, nxt + 6 * 3600.0) == pytest.approx(nxt + 1.0)
    later = clock.time_s(datetime(2026, 11, 27, 14, 30, 18), 13.0, nxt + 6 * 3600.0)
    assert later == pytest.approx(nxt + 2.0) and clock.out_of_order == 1
    unstamped = FrameClock(None)  # a stream that never stamps: the computer's UTC clock
    assert unstamped.time_s(None, 5.0, 1e9) == 1e9
    shifted = FrameClock(2.0).time_s(stamp, 0.0, 0.0)
    assert shifted == pytest.approx(times[0] - 7200.0)  # rig clock at UTC+2 → UTC


def test_a_recording_cut_by_a_kill_is_continued_after_its_last_whole_line(tmp_path):
    path = tmp_path / "w.wits0.csv"
    rec = Recording(path, ["surface_rpm"], utc=False)
    t = datetime(2026, 11, 27, 14, 30, 15, tzinfo=UTC).timestamp()
    rec.write(t, {"surface_rpm": 41.0})
    rec.close()
    with open(path, "ab") as fh:
        fh.write(b"2026-11-27T14:30:16.0000")  # the line a kill -9 cut
    again = Recording(path, ["surface_rpm"], utc=False)
    assert again.last_s == t  # the next frame's time must come after it
    assert path.read_text() == "time,surface_rpm\n2026-11-27T14:30:15.000000,41.0\n"
    with pytest.raises(InputError, match="other columns"):
        Recording(path, ["surface_rpm", "hookload_N"], utc=False)


def test_bad_addresses_are_one_clear_error():
    assert parse_address("wits0://[::1]:5000").host == "::1"
    for bad in ("wits0://host", "wits0://h:0", "wits0://h:70000", "wits0://a b:1",
                "wits0://h:5000/x"):
        with pytest.raises(InputError, match="no WITS0 address"):
            parse_address(bad)


def test_live_on_a_bad_address_exits_2_with_one_line(tmp_path):
    code, err = _finish(_drillfric("live", "wits0://127.0.0.1:99999", "--out", tmp_path,
                                   "--until-idle", 1), 30)
    assert code == 2 and "no WITS0 address" in err and "Traceback" not in err
    assert not list(tmp_path.iterdir())


# ---------------------------------------------------------------- receiver on real sockets
def test_receiver_sends_handshakes_reconnects_and_records_each_frame_once(tmp_path):
    listener = socket.create_server(("127.0.0.1", 0))
    address = parse_address(f"wits0://127.0.0.1:{listener.getsockname()[1]}")
    rows = [{"surface_rpm": float(k), "hookload_N": 1e6 + k} for k in range(3)]
    frames = [encode(r, item_map({}), datetime(2026, 11, 27, 14, 30, 15 + k))
              for k, r in enumerate(rows)]
    receiver = Receiver(address, setup(address, None, "t"),
                        Recording(tmp_path / "t.wits0.csv", Row(item_map({})).names, False))
    thread = threading.Thread(target=receiver.run, daemon=True)
    listener.settimeout(10)
    thread.start()
    heard = []
    try:
        conn, _ = listener.accept()
        conn.sendall(frames[0] + frames[1][:25])  # the drop cuts frame 2
        heard.append(conn.recv(100))
        conn.close()
        conn, _ = listener.accept()  # the receiver came back
        conn.sendall(frames[1] + frames[2])
        heard.append(conn.recv(100))
        _wait_for(lambda: receiver.frames == 3, 10)
        receiver.stop.set()  # before the close: a drop would be reconnected (a 3rd connection)
        conn.close()
    finally:
        receiver.stop.set()
        thread.join(5)
        listener.close()
    assert heard == [HANDSHAKE, HANDSHAKE] and receiver.connections == 2
    got = pd.read_csv(tmp_path / "t.wits0.csv")
    assert got["surface_rpm"].tolist() == [0.0, 1.0, 2.0]
    assert got["hookload_N"].tolist() == pytest.approx([1e6, 1e6 + 1, 1e6 + 2], rel=1e-15)
    assert got["time"].tolist() == [f"2026-11-27T14:30:{15 + k}.000000" for k in range(3)]


# ---------------------------------------------------------------- end to end
@pytest.fixture(scope="module")
def one_hz(tmp_path_factory):
    """The three-stand well of tests/conftest.py recorded at 1 Hz (a WITS0 recorder's rate),
    with its whole-file run."""
    from click.testing import CliRunner
    from drillfric.cli.main import cli

    from drillfric.io.well import open_well
    from drillfric.runner import run_well

    folder = tmp_path_factory.mktemp("one_hz")
    (folder / "three.scenario.toml").write_text(SCENARIO)
    done = CliRunner().invoke(cli, ["-q", "simulate", str(DEMO / "demo.toml"), "--scenario",
                                    str(folder / "three.scenario.toml"), "--out",
                                    str(folder / "three.csv"), "--cells", "100", "--rate",
                                    "1", "--seed", "5"])
    assert done.exit_code == 0, done.output
    whole = run_well(open_well(folder / "three.csv"))
    assert whole.counts["converged"] >= 2
    return folder / "three.csv", whole.segments


def _port() -> int:
    with socket.create_server(("127.0.0.1", 0)) as probe:
        return probe.getsockname()[1]


def test_replay_over_wits0_dropping_once_gives_live_the_run_of_the_whole_file(one_hz,
                                                                             tmp_path):
    path, whole = one_hz
    address, out = f"wits0://127.0.0.1:{_port()}", tmp_path / "out"
    replay = _drillfric("replay", path, "--to", address, "--speed", 60, "--drop-after", 200)
    live = _drillfric("live", address, "--out", out, "--config", path.with_suffix(".toml"),
                      "--until-idle", 3, "--no-report")
    code, err = _finish(replay)
    assert code == 0, err
    code, err = _finish(live)
    assert code == 0, err
    recorded = pd.read_csv(out / "three.wits0.csv")
    assert len(recorded) == len(pd.read_csv(path))  # every frame once, the cut one too
    assert pd.to_datetime(recorded["time"]).is_monotonic_increasing
    _same_segments(out / "three", whole)
    status = json.loads((out / "live.json").read_text())
    assert status["rows"] == len(recorded) and status["last_sample_time_s"] == 440.0


def test_kill_9_during_a_wits0_stream_and_restart_lose_and_repeat_no_row(one_hz, tmp_path):
    from drillfric.live.replay import recorded_frame
    from drillfric.live.wits0_server import frames_of

    path, whole = one_hz
    _, canonical, _ = recorded_frame(path)
    frames = frames_of(canonical, None, datetime(2026, 11, 27, 12, 0, 0))
    listener = socket.create_server(("127.0.0.1", 0))
    listener.settimeout(60)
    address, out = f"wits0://127.0.0.1:{listener.getsockname()[1]}", tmp_path / "out"
    args = ("live", address, "--out", out, "--config", path.with_suffix(".toml"), "--no-report")
    recording, half = out / "three.wits0.csv", 300
    first = _drillfric(*args)
    try:
        conn, _ = listener.accept()
        for frame in frames[:half]:
            conn.sendall(frame)
        _wait_for(lambda: recording.is_file() and
                  recording.read_bytes().count(b"\n") == half + 1 and
                  (out / "three" / "state" / "engine.json").is_file(), 40)
    finally:
        first.send_signal(signal.SIGKILL)
        first.wait()
    conn.close()
    again = _drillfric(*args, "--until-idle", 3)
    conn, _ = listener.accept()
    for frame in frames[half:]:
        conn.sendall(frame)
    conn.shutdown(socket.SHUT_WR)
    code, err = _finish(again)
    conn.close()
    listener.close()
    assert code == 0, err
    summary = json.loads((out / "three" / "summary.json").read_text())
    assert summary["resumed"]["reason"] == "" and summary["resumed"]["from_row"] > 0
    assert summary["inputs"]["rows"] == len(frames)
    _same_segments(out / "three", whole)
