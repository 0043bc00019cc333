"""`drillfric live` on a well directory into which the well's files arrive (issue 24,
docs/live.md "Sources"): CSV parts arriving one by one, the newest growing in cut writes, and
Parquet parts written slowly (a footer not yet there) give the results of `drillfric run` on
the complete folder; a live run killed with -9 continues; a file out of order or changed is
one line. And a bare CR ends a line for live as it does for `run`."""

from __future__ import annotations

import json
import random
import shutil
import signal
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from drillfric.errors import InputError
from drillfric.live.source import PartsTail, Tail, follow
from drillfric.runner.resume import changed, csv_mark
from tests.test_live import (
    _drillfric,
    _finish,
    _resumed_as_the_whole_run,
    _same_segments,
    _wait_for,
)

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow

#: Rows of the three-stand well at which its parts are cut (44001 rows: four parts).
CUTS = (0, 9000, 21000, 33000, 44001)


def _well_dir(recorded, tmp_path: Path) -> Path:
    """An empty well directory: well.toml ([well] data = ".") and the survey; no data yet."""
    path = recorded[0]
    well = tmp_path / "three"
    well.mkdir()
    shutil.copy(path.with_suffix(".survey.csv"), well / "three.survey.csv")
    (well / "well.toml").write_text(path.with_suffix(".toml").read_text().replace(
        'data = "three.csv"', 'data = "."'))
    return well


def _parts(recorded) -> list[pd.DataFrame]:
    frame = pd.read_csv(recorded[0])
    return [frame.iloc[a:b] for a, b in zip(CUTS[:-1], CUTS[1:], strict=True)]


def _cut_writes(path: Path, data: bytes, seed: int, pause_s: float = 0.02) -> None:
    """``data`` appended to ``path`` in writes cut at random bytes (lines split)."""
    rng = random.Random(seed)
    at = 0
    while at < len(data):
        step = rng.randint(1, 60_000)
        with open(path, "ab") as fh:
            fh.write(data[at:at + step])
        at += step
        time.sleep(pause_s)


@pytest.fixture
def recorded(stands):
    path, whole = stands
    return path, whole.segments


def test_csv_parts_arriving_one_by_one_the_newest_cut_give_the_run_of_the_folder(recorded,
                                                                                tmp_path):
    well, out = _well_dir(recorded, tmp_path), tmp_path / "out"
    parts = [p.to_csv(index=False).encode() for p in _parts(recorded)]
    live = _drillfric("live", well, "--out", out, "--until-idle", 3, "--no-report")
    try:
        for i, data in enumerate(parts):  # each file grows in cut writes, then the next
            _cut_writes(well / f"h{i:02d}.csv", data, seed=i)
            if i == 0:  # live reads the first file before the others come
                _wait_for(lambda: _rows(out) > 0, 40)
        seen = _rows(out)
    finally:
        code, err = _finish(live)
    assert code == 0, err
    _same_segments(out / "three", recorded[1])
    summary = json.loads((out / "three" / "summary.json").read_text())
    assert summary["inputs"]["rows"] == 44001
    assert sorted(k for k in summary["inputs"] if k.startswith("data ")) == \
        [f"data h{i:02d}.csv" for i in range(4)]
    assert seen < 44001, "every file was there before live read one: the test shows nothing"
    status = json.loads((out / "live.json").read_text())
    assert status["rows"] == 44001 and status["open_segment"] is None


def _rows(out: Path) -> int:
    try:
        return json.loads((out / "live.json").read_text())["rows"]
    except (OSError, ValueError):
        return 0


def test_parquet_parts_written_slowly_and_a_kill_9_continue_to_the_run_of_the_folder(
        recorded, tmp_path):
    """A Parquet part is written in two halves 0.6 s apart (no footer in between: retried,
    not an error); live is killed with -9 after a publication and restarted."""
    well, out = _well_dir(recorded, tmp_path), tmp_path / "out"
    blobs = []
    for part in _parts(recorded):
        scratch = tmp_path / "scratch.parquet"
        part.to_parquet(scratch, index=False, row_group_size=4000)
        blobs.append(scratch.read_bytes())

    def write(i: int) -> None:
        path = well / f"p{i:02d}.parquet"
        half = len(blobs[i]) // 2
        path.write_bytes(blobs[i][:half])
        time.sleep(0.6)
        with open(path, "ab") as fh:
            fh.write(blobs[i][half:])

    write(0)
    first = _drillfric("live", well, "--out", out, "--no-report")
    try:
        write(1)
        _wait_for(lambda: (out / "three" / "state" / "engine.json").is_file(), 40)
    finally:
        first.send_signal(signal.SIGKILL)
        first.wait()
    again = _drillfric("live", well, "--out", out, "--until-idle", 3, "--no-report")
    try:
        for i in (2, 3):
            time.sleep(0.5)
            write(i)
    finally:
        code, err = _finish(again)
    assert code == 0, err
    _resumed_as_the_whole_run(out / "three", recorded[1])


def _csv(path: Path, rows: range) -> None:
    path.write_text("time_s,surface_rpm,surface_torque_Nm\n"
                    + "".join(f"{t},60,9000\n" for t in rows))


def test_a_file_sorting_before_one_already_read_is_one_error_naming_it(tmp_path):
    """Regression (issue 24, folder source): the log's order cannot be kept when a file
    arrives with a name sorting before the newest read, or a file read changes."""
    _csv(tmp_path / "b.csv", range(0, 30))
    tail = PartsTail(tmp_path)
    assert tail.poll() > 0 and [p.name for p in tail.paths] == ["b.csv"]
    _csv(tmp_path / "c.csv", range(30, 60))
    tail.poll()
    assert [p.name for p in tail.paths] == ["b.csv", "c.csv"]  # b.csv complete, c.csv newest
    _csv(tmp_path / "a.csv", range(-30, 0))
    with pytest.raises(InputError, match="a.csv: arrived after c.csv was read, but its "
                                         "name sorts before it"):
        tail.poll()
    (tmp_path / "a.csv").unlink()
    with open(tmp_path / "b.csv", "a") as fh:
        fh.write("99,60,9000\n")
    with pytest.raises(InputError, match="b.csv: changed after it was read"):
        tail.poll()


def test_a_parquet_part_without_its_footer_waits_and_is_an_error_only_at_the_end(tmp_path):
    frame = pd.DataFrame({"time_s": np.arange(50.0), "surface_rpm": 60.0})
    frame.to_parquet(tmp_path / "scratch.pq.bin", index=False)
    blob = (tmp_path / "scratch.pq.bin").read_bytes()
    (tmp_path / "scratch.pq.bin").unlink()
    (tmp_path / "p00.parquet").write_bytes(blob[:len(blob) // 2])
    tail = PartsTail(tmp_path)
    assert tail.poll() == 0 and not tail.ready()
    with pytest.raises(InputError, match="unreadable Parquet file"):
        tail.poll(final=True)
    (tmp_path / "p00.parquet").write_bytes(blob)
    assert tail.poll() == 50 and tail.ready()


def test_the_mark_of_the_parts_read_is_the_one_a_run_continues_from(tmp_path):
    """The live mark passes :func:`drillfric.runner.resume.changed` for the folder's well
    (a restarted live or a fleet re-run continues it)."""
    (tmp_path / "well.toml").write_text('[well]\nname = "w"\ndata = "."\n')
    _csv(tmp_path / "h0.csv", range(0, 30))
    with open(tmp_path / "h1.csv", "w") as fh:
        fh.write("time_s,surface_rpm,surface_torque_Nm\n"
                 + "".join(f"{t},60,9000\n" for t in range(30, 60)) + "60,6")
    tail = follow(tmp_path)
    assert isinstance(tail, PartsTail)
    tail.poll()
    well = tail.open(tmp_path, {})
    found = tail.mark()
    assert found["parts"][-1]["bytes"] < (tmp_path / "h1.csv").stat().st_size  # cut row waits
    assert changed(found, well) == ""
    again = PartsTail(tmp_path)  # a restart from the saved mark: the same bytes hashed
    again.restart(found)
    again.well_for(well)
    assert again.end == tail.end and again.mark() == found


# ---------------------------------------------------------------- bare CR line ends
def test_bare_cr_ends_a_line_and_a_cr_lf_cut_between_writes_is_one_line_end(tmp_path):
    """Regression (issue 24): `run` reads lines ended by a bare CR, live's Tail did not
    follow them. A CR at the end of what was written waits for the next byte."""
    path = tmp_path / "cr.csv"
    path.write_bytes(b"time_s,surface_rpm\r0,60\r")
    tail = Tail(path)
    assert tail.poll() == len(b"time_s,surface_rpm\r")  # the last CR may start a CR LF
    assert tail.lines() == 1
    with open(path, "ab") as fh:
        fh.write(b"\n1,61\r\n2,6")
    assert tail.poll() == len(b"time_s,surface_rpm\r0,60\r\n1,61\r\n")
    assert tail.lines() == 3  # CR LF counted once
    with open(path, "ab") as fh:
        fh.write(b"2\r3,63\r")
    assert tail.poll() == path.stat().st_size - 1 - len(b"3,63")
    assert tail.poll(final=True) == path.stat().st_size  # the data ended: the CR ends it
    assert tail.lines() == 5
    assert tail.mark() == csv_mark(path, tail.end)


@pytest.mark.parametrize("ending", [b"\r", b"\r\n", b"\n"])
def test_rows_read_through_the_tail_in_cut_writes_are_the_rows_run_reads(tmp_path, ending):
    """Every line ending `run` reads: the rows live feeds — read up to where the tail says
    the complete lines end, after each write cut at random bytes — are those of a whole read."""
    from drillfric.io.well import open_well
    from drillfric.runner.resume import unread

    whole = (b"time_s,surface_rpm,surface_torque_Nm" + ending
             + b"".join(f"{t * 0.01:.2f},{60 + t % 7},9000".encode() + ending
                        for t in range(400)))
    (tmp_path / "w.csv").write_bytes(whole)
    expected = open_well(tmp_path / "w.csv").load().surface
    path = tmp_path / "grow" / "w.csv"
    path.parent.mkdir()
    rng = random.Random(len(ending))
    tail, before, rows, at = Tail(path), None, [], 0
    path.write_bytes(whole[:200])
    well = open_well(path)
    while at < len(whole):
        at = min(len(whole), at + rng.randint(1, 300))
        path.write_bytes(whole[:at])
        tail.poll(final=at == len(whole))
        now = tail.mark()
        rows += list(unread(well, before, now, 50))
        before = now
    got = pd.concat(rows, ignore_index=True)
    assert len(got) == len(expected) == 400
    np.testing.assert_array_equal(got.iloc[:, 1].to_numpy(float),
                                  expected["surface_rpm"].to_numpy(float))


def test_a_well_directory_naming_one_file_follows_that_file(tmp_path):
    (tmp_path / "well.toml").write_text('[well]\ndata = "log.csv"\n')
    assert isinstance(follow(tmp_path), Tail) and follow(tmp_path).path == tmp_path / "log.csv"
    (tmp_path / "sub").mkdir()
    with pytest.raises(InputError, match="no well.toml"):
        follow(tmp_path / "sub")


def test_live_on_a_folder_without_well_toml_exits_2_with_one_line(tmp_path):
    (tmp_path / "feed").mkdir()
    code, err = _finish(_drillfric("live", tmp_path / "feed", "--out", tmp_path / "out",
                                   "--until-idle", 1), 30)
    assert code == 2 and "no well.toml" in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()

