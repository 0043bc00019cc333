"""Attacks on the live inputs of issue 24 (docs/live.md), each named after the attack that
broke them: a WITS0 frame dated in 2099 silencing the stream for good, a value that
overflows in SI (1e308 KDN) recorded as inf, a signed or exponent DATE taken for a date, a
sparse gigabyte "CSV" or a never-ending line read whole into memory, and a live-page request
naming a foreign host in an absolute URI or a second Host header."""

from __future__ import annotations

import math
import os
import socket
import threading
import tracemalloc
from datetime import UTC, datetime, timedelta

import pandas as pd
import pytest

from drillfric.errors import InputError
from drillfric.io.wits0 import Row, encode, frame_clock, item_map
from drillfric.live.page import LiveServer
from drillfric.live.source import MAX_LINE_BYTES, Tail
from drillfric.live.wits0_receiver import Receiver, Recording, parse_address, setup
from tests.test_live import _wait_for


def _frame(clock: datetime, rpm: float) -> bytes:
    return encode({"surface_rpm": rpm, "hookload_N": 1.5e6}, item_map({}), clock)


def test_wits0_frame_dated_2099_is_dropped_and_does_not_silence_the_stream(tmp_path):
    listener = socket.create_server(("127.0.0.1", 0))
    listener.settimeout(10)
    address = parse_address(f"wits0://127.0.0.1:{listener.getsockname()[1]}")
    warnings: list[str] = []
    receiver = Receiver(address, setup(address, None, "t"),
                        Recording(tmp_path / "t.wits0.csv", Row(item_map({})).names, False),
                        warn=warnings.append)
    thread = threading.Thread(target=receiver.run, daemon=True)
    thread.start()
    start = (datetime.now(UTC) - timedelta(hours=1)).replace(tzinfo=None, microsecond=0)
    try:
        conn, _ = listener.accept()
        conn.sendall(_frame(start, 1.0) + _frame(datetime(2099, 12, 31, 23, 59, 59), 99.0)
                     + b"".join(_frame(start + timedelta(seconds=k), k) for k in (2, 3, 4)))
        _wait_for(lambda: receiver.frames == 4, 10)
        conn.close()
    finally:
        receiver.stop.set()
        thread.join(5)
        listener.close()
    got = pd.read_csv(tmp_path / "t.wits0.csv")
    assert got["surface_rpm"].tolist() == [1.0, 2.0, 3.0, 4.0]  # the true frames after it too
    assert len(warnings) == 1 and "2099-12-31" in warnings[0] and "not recorded" in warnings[0]


def test_wits0_recording_edited_to_end_without_a_time_is_one_error(tmp_path):
    names = Row(item_map({})).names
    path = tmp_path / "t.wits0.csv"
    path.write_bytes(("time," + ",".join(names) + "\n").encode() + b"not-a-time\xff,1\n")
    with pytest.raises(InputError, match="without a time"):
        Recording(path, names, False)


def test_wits0_value_1e308_kdn_overflowing_si_is_missing_not_inf():
    row = Row(item_map({}))
    values = row.update({"0114": "1e308", "0120": "41.0"})  # 1e308 KDN = 1e312 N
    assert math.isnan(values["hookload_N"]) and values["surface_rpm"] == 41.0
    assert math.isnan(row.update({"0114": "-1e308"})["hookload_N"])


@pytest.mark.parametrize("date", ["-9899", "2.61127e5", "+261127", " 261127x", "1e400"])
def test_wits0_signed_or_exponent_date_is_no_date(date):
    assert frame_clock({"0105": date, "0106": "120000"}) is None


def test_wits0_date_with_a_decimal_zero_is_still_a_date():
    assert frame_clock({"0105": "261127.00", "0106": "120000.0"}) == \
        datetime(2026, 11, 27, 12, 0, 0)


def test_sparse_gigabyte_csv_is_one_error_in_bounded_memory(tmp_path):
    path = tmp_path / "log.csv"
    path.write_bytes(b"time,surface_rpm\n0,1\n")
    os.truncate(path, 2**30)  # a gigabyte of NUL bytes, no line end
    tail = Tail(path)
    tracemalloc.start()
    try:
        with pytest.raises(InputError, match="no text log"):
            tail.poll()
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert tail.end == len(b"time,surface_rpm\n0,1\n")
    assert peak < 200 * 2**20


def test_never_ending_line_is_one_error_not_waited_for(tmp_path):
    path = tmp_path / "log.csv"
    path.write_bytes(b"time,surface_rpm\n0,1\n" + b"9" * (MAX_LINE_BYTES // 2))
    tail = Tail(path)
    assert tail.poll() == 21  # a partial line may still end: waited for
    with open(path, "ab") as fh:
        fh.write(b"9" * MAX_LINE_BYTES)
    with pytest.raises(InputError, match="line of more than"):
        tail.poll()


def test_a_log_larger_than_one_block_is_read_whole_and_its_lines_counted_once(
        tmp_path, monkeypatch):
    import drillfric.live.source as live_source

    monkeypatch.setattr(live_source, "MAX_BLOCK", 19)  # > a line; the third block cuts a CR LF
    rows = b"time,surface_rpm\r\n" + b"".join(b"%d,%d\r\n" % (k, k) for k in range(10))
    path = tmp_path / "log.csv"
    path.write_bytes(rows)
    tail = Tail(path)
    assert tail.poll() == len(rows) and tail.lines() == 11
    assert rows[:57].endswith(b"\r") and rows[57:58] == b"\n"


def _status(port: int, request: bytes) -> bytes:
    with socket.create_connection(("127.0.0.1", port), timeout=5) as conn:
        conn.sendall(request)
        return conn.recv(200).split(b"\r\n")[0]


@pytest.mark.parametrize("request_head", [
    b"GET http://evil.example/live.json HTTP/1.1\r\nHost: 127.0.0.1\r\n",
    b"GET /live.json HTTP/1.1\r\nHost: 127.0.0.1\r\nHost: evil.example\r\n",
])
def test_live_page_absolute_uri_or_second_host_naming_another_host_is_refused(request_head):
    server = LiveServer("127.0.0.1", 0)
    thread = threading.Thread(target=server.serve_forever, kwargs={"poll_interval": 0.1},
                              daemon=True)
    thread.start()
    try:
        answer = _status(server.server_port, request_head + b"Connection: close\r\n\r\n")
    finally:
        server.shutdown()
        server.server_close()
    assert answer == b"HTTP/1.1 421 Misdirected Request"
