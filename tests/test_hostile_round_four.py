"""Hostile inputs, round four (issue 30): the output folder, the saved state, live
recordings, fleet names and the work a config implies. Each case goes through the CLI with
the strict checks of :func:`tests.test_hostile_files._strict_check` (exit code, one error
line naming the file and the fix, no traceback, nothing written outside ``--out``, no secret
echoed). Cases are named after the attack (lasio's practice).
"""

from __future__ import annotations

import os
import shutil
import socket
import stat
import subprocess
import threading
from datetime import datetime, timedelta
from pathlib import Path

import pytest
from click.testing import CliRunner
from drillfric.cli.main import cli

from drillfric.errors import OutputError
from drillfric.runner.state import STATE_VERSION
from tests.test_hostile_files import _strict_check
from tests.test_hostile_inputs import SECRET, Case, _check, _config, _log, hang_guard

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow


def _secret(root):
    """A file outside OUT that a planted link points at (its content must stay as it is)."""
    folder = root / "secret"
    folder.mkdir(exist_ok=True)
    target = folder / "credentials.txt"
    target.write_text(SECRET + "\n", encoding="utf-8")
    return target


def _well(root, name="w"):
    """A wells folder holding one small well (one segment, skipped: fast)."""
    path = _log(root / "wells" / f"{name}.csv")
    _config(path.with_suffix(".toml"))
    return path


def _planted(root, name, target=None):
    """OUT/NAME as a link to ``target`` (the secret; None: a dangling link)."""
    out = root / "out"
    (out / name).parent.mkdir(parents=True, exist_ok=True)
    (out / name).symlink_to(target if target is not None else root / "secret" / "gone.txt")
    return out / name


# --------------------------------------------------------------- links planted in OUT (3)
@pytest.mark.parametrize("name", ["fleet.html", "fleet_summary.parquet", "manifest.json",
                                  ".fleet.lock"])
def test_fleet_output_planted_as_a_link_is_refused(name, tmp_path, capsys):
    """The fleet's files were written through a link planted in OUT: a file outside OUT
    overwritten (fleet.html.tmp, .manifest.json.tmp-PID … had predictable names)."""
    root = tmp_path / "sandbox"
    root.mkdir()
    _well(root)
    _planted(root, name, _secret(root))
    _strict_check(Case(["fleet", "wells", "--out", "out"], (2,), ("symbolic link",)), root,
                  capsys)
    assert (root / "secret" / "credentials.txt").read_text() == SECRET + "\n"


def test_report_html_planted_as_a_link_is_refused(tmp_path, capsys):
    """`drillfric report OUT/NAME` wrote NAME/report.html.tmp and renamed it: through a link
    planted as report.html the link was replaced, and as report.html.tmp a file elsewhere
    was overwritten."""
    root = tmp_path / "sandbox"
    root.mkdir()
    path = _log(root / "w.csv")
    _config(path.with_suffix(".toml"))
    _strict_check(Case(["run", "w.csv", "--out", "out"], (0,)), root, capsys)
    (root / "out" / "w" / "report.html").unlink()
    _planted(root, "w/report.html", _secret(root))
    _strict_check(Case(["report", "out/w"], (2,), ("symbolic link",)), root, capsys)


def test_live_json_planted_as_a_link_is_refused(tmp_path, capsys):
    root = tmp_path / "sandbox"
    root.mkdir()
    path = _log(root / "w.csv")
    _config(path.with_suffix(".toml"))
    _planted(root, "live.json", _secret(root))
    _strict_check(Case(["live", "w.csv", "--out", "out", "--until-idle", "1"], (2,),
                       ("symbolic link",)), root, capsys)


def test_wits0_recording_planted_as_a_dangling_link_is_refused(tmp_path, capsys):
    """A dangling link at OUT/NAME.wits0.csv made live write the whole recording outside
    OUT (exit 0); pointing at a secrets file, the error printed its first line."""
    root = tmp_path / "sandbox"
    root.mkdir()
    _config(root / "w.toml", '[well]\nname = "rig"\n')
    for target in (None, _secret(root)):
        link = _planted(root, "rig.wits0.csv", target)
        _strict_check(Case(["live", "wits0://127.0.0.1:9", "--config", "w.toml", "--out",
                            "out", "--until-idle", "1"], (2,), ("symbolic link",)), root,
                      capsys)
        assert not (root / "secret" / "gone.txt").exists()
        link.unlink()


# --------------------------------------------------------------- a full disk (7)
@pytest.fixture
def small_disk(tmp_path):
    """A 256-KiB tmpfs at tmp_path/disk (a real ENOSPC); skipped where it cannot be mounted
    (not root)."""
    disk = tmp_path / "disk"
    disk.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=256k", "tmpfs", str(disk)],
                          capture_output=True, check=False)
    if done.returncode:
        pytest.skip("cannot mount a small tmpfs here (needs root)")
    try:
        yield disk
    finally:
        subprocess.run(["umount", "-l", str(disk)], capture_output=True, check=False)


def _fill(disk, leave_bytes: int) -> None:
    """Fill ``disk`` until about ``leave_bytes`` are free."""
    free = shutil.disk_usage(disk).free
    (disk / "filler").write_bytes(b"\0" * max(0, free - leave_bytes))


def test_fleet_on_a_full_disk_fails_each_well_in_one_line_and_leaves_no_temporary(
        tmp_path, small_disk, capsys):
    """A fleet on a full disk left a half-written fleet.html.tmp."""
    root = tmp_path / "sandbox"
    root.mkdir()
    for name in "ab":
        _well(root, name)
    _fill(small_disk, 8192)
    out = small_disk / "out"
    result = CliRunner().invoke(cli, ["fleet", str(root / "wells"), "--out", str(out)])
    text = result.output
    assert result.exit_code == 2 and "Traceback" not in text, text
    assert text.count("no space left on the device") >= 1 and "fix" in text, text
    left = [p.name for p in small_disk.rglob("*") if ".tmp" in p.name]
    assert not left, left


def test_wits0_stream_filling_the_disk_ends_the_receiver_with_one_error_naming_the_path(
        small_disk):
    """A fast WITS0 stream filling the disk gave `internal error: OSError: [Errno 28]` with no
    path and a traceback from the receiver thread."""
    from drillfric.io.wits0 import Row, encode, item_map
    from drillfric.live.wits0_receiver import Receiver, Recording, parse_address, setup

    _fill(small_disk, 4096)
    listener = socket.create_server(("127.0.0.1", 0))
    listener.settimeout(10)
    address = parse_address(f"wits0://127.0.0.1:{listener.getsockname()[1]}")
    recording = Recording(small_disk / "t.wits0.csv", Row(item_map({})).names, False)
    receiver = Receiver(address, setup(address, None, "t"), recording)
    hooked = []
    previous, threading.excepthook = threading.excepthook, hooked.append
    thread = threading.Thread(target=receiver.run, daemon=True)
    thread.start()
    try:
        conn, _ = listener.accept()
        start = datetime(2026, 11, 27, 14, 0, 0)
        for k in range(2000):  # ≈ 60 bytes a line: the 4 KiB left are full after ~70
            if receiver.error is not None:
                break
            frame = encode({"surface_rpm": float(k)}, item_map({}),
                           start + timedelta(seconds=k))
            try:
                conn.sendall(frame)
            except OSError:
                break
        thread.join(10)
        conn.close()
    finally:
        receiver.stop.set()
        thread.join(5)
        listener.close()
        threading.excepthook = previous
    assert not thread.is_alive() and not hooked
    assert isinstance(receiver.error, OutputError)
    assert "no space left" in str(receiver.error) and "t.wits0.csv" in str(receiver.error)


# --------------------------------------------------------------- fleet and live names (5)
@pytest.mark.parametrize("name", ["fleet_summary.parquet", "fleet.html", "manifest.json",
                                  "Live.json", "rig.wits0.csv"])
def test_a_well_named_as_a_file_drillfric_writes_in_out_fails_alone(name, tmp_path, capsys):
    """A well named fleet_summary.parquet, fleet.html or manifest.json broke the whole fleet
    every night (IsADirectoryError, no fleet summary); a live well named live.json could
    never run. Now that well fails in one line and the others run."""
    root = tmp_path / "sandbox"
    root.mkdir()
    _well(root, "good")
    odd = _log(root / "wells" / "odd.csv")
    _config(odd.with_suffix(".toml"), f'[well]\nname = "{name}"\n')
    _strict_check(Case(["fleet", "wells", "--out", "out", "--workers", "1"], (1,),
                       ("drillfric writes in OUT", "1 failed")), root, capsys)
    assert (root / "out" / "fleet_summary.parquet").is_file()
    assert (root / "out" / "good" / "summary.json").is_file()


def test_fleet_writing_into_its_own_wells_folder_does_not_take_its_outputs_for_wells(
        tmp_path, capsys):
    """With --out equal to the wells folder, night 2 read its own fleet_summary.parquet as a
    well and exited 1 every night."""
    root = tmp_path / "sandbox"
    root.mkdir()
    _well(root)
    for night in (1, 2):
        result = CliRunner().invoke(cli, ["fleet", str(root / "wells"), "--out",
                                          str(root / "wells"), "--workers", "1"])
        assert "fleet_summary" not in result.output and "fleet (1 well)" in result.output, \
            (night, result.output)


# --------------------------------------------------------------- silently nothing (6)
def test_a_fleet_in_which_nothing_was_estimated_says_so_and_exits_1(tmp_path):
    """300 wells with nothing estimated: the fleet said "300 ok" and exited 0."""
    root = tmp_path / "sandbox"
    for name in ("a", "b"):
        _well(root, name)
    result = CliRunner().invoke(cli, ["fleet", str(root / "wells"), "--out",
                                      str(root / "out"), "--workers", "1"])
    assert result.exit_code == 1, result.output
    assert "nothing estimated in 2 of 2 wells" in result.output and "a, b" in result.output


def test_a_manual_run_into_a_fleets_out_is_redone_next_night_not_unchanged(tmp_path):
    """`run` with another config into a fleet's OUT was reported next night as "ok
    (unchanged)" with the old results, contradicting OUT/NAME/summary.json."""
    root = tmp_path / "sandbox"
    path = _well(root)
    out = root / "out"
    fleet = ["fleet", str(root / "wells"), "--out", str(out), "--workers", "1"]
    first = CliRunner().invoke(cli, fleet)
    assert "1 processed" in first.output, first.output
    again = CliRunner().invoke(cli, fleet)
    assert "1 ok (0 processed, 1 unchanged" in again.output, again.output
    other = _config(root / "other.toml", "[well]\nbit_depth_m = 1800.0\n")
    manual = CliRunner().invoke(cli, ["run", str(path), "--config", str(other), "--out",
                                      str(out)])
    assert manual.exit_code == 0, manual.output
    night = CliRunner().invoke(cli, fleet)
    assert "1 processed" in night.output, night.output


# --------------------------------------------------------------- the saved state (4)
def _zip_bomb(path):
    """arrays.npz holding one deflated .npy that expands ~1000×."""
    import io
    import zipfile

    import numpy as np

    buf = io.BytesIO()
    np.save(buf, np.zeros(2_000_000))  # 16 MB of zeros: a few kB deflated
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("a0.npy", buf.getvalue())


def _lying_npy(path):
    """arrays.npz whose stored .npy header declares 10¹⁰ floats in a few bytes."""
    import zipfile

    header = b"{'descr': '<f8', 'fortran_order': False, 'shape': (10000000000,), }"
    header += b" " * (117 - len(header)) + b"\n"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_STORED) as archive:
        archive.writestr("a0.npy", b"\x93NUMPY\x01\x00" + len(header).to_bytes(2, "little")
                         + header + b"\0" * 64)


def _many_rows(folder):
    """frame-0.parquet declaring 2×10⁸ rows of one run (a few kB)."""
    import numpy as np
    import pyarrow as pa
    import pyarrow.parquet as pq

    column = pa.array(np.zeros(1_000_000))
    writer = pq.ParquetWriter(folder / "frame-0.parquet", pa.schema([("x", pa.float64())]))
    for _ in range(200):
        writer.write_table(pa.table({"x": column}))
    writer.close()


def _deep_json(folder):
    doc = folder / "engine.json"
    doc.write_text(f'{{"format": "drillfric-engine-state", "version": {STATE_VERSION}, '
                   '"state": ' + "[" * 100_000 + "]" * 100_000 + "}", encoding="utf-8")


def _wrong_type(folder):
    doc = folder / "engine.json"
    doc.write_text(f'{{"format": "drillfric-engine-state", "version": {STATE_VERSION}, '
                   '"state": [1, 2]}', encoding="utf-8")


def _truncated_arrays(folder):
    path = folder / "arrays.npz"
    path.write_bytes(path.read_bytes()[: max(1, path.stat().st_size // 2)])


def _tracks_asking_for_gigabytes(folder):
    """engine.json's track accumulator with max_bins 10⁹ and 10-µs bins (1.8 GB at resume)."""
    import json

    doc = json.loads((folder / "engine.json").read_text())

    def edit(node):
        if isinstance(node, dict):
            if "max_bins" in node:
                node.update(max_bins=1_000_000_000, width_s=1e-5)
            for value in node.values():
                edit(value)
        elif isinstance(node, list):
            for value in node:
                edit(value)

    edit(doc)
    (folder / "engine.json").write_text(json.dumps(doc))


def _text_array(folder):
    """Every array of arrays.npz replaced by one of text (the time buffer's arithmetic then
    failed with UFuncTypeError on every night)."""
    import numpy as np

    with np.load(folder / "arrays.npz") as npz:
        keys = list(npz.files)
    np.savez(folder / "arrays.npz", **{k: np.array(["x"] * 400) for k in keys})


def _fifo(name):
    def plant(folder):
        (folder / name).unlink()
        os.mkfifo(folder / name)
    return plant


def _outside_table(folder):
    """frame-0.parquet a link to a table elsewhere: its rows were read into the results."""
    import pandas as pd

    elsewhere = folder.parents[3] / "secret" / "private.parquet"
    elsewhere.parent.mkdir(exist_ok=True)
    pd.DataFrame({"time_s": [0.0], "surface_rpm": [60.0],
                  "surface_torque_Nm": [31337.0]}).to_parquet(elsewhere)
    for old in folder.glob("frame-*.parquet"):
        old.unlink()
        old.symlink_to(elsewhere)


@pytest.mark.parametrize("damage", [_truncated_arrays, _deep_json, _wrong_type, _many_rows,
                                    lambda f: _zip_bomb(f / "arrays.npz"),
                                    lambda f: _lying_npy(f / "arrays.npz"),
                                    _tracks_asking_for_gigabytes, _text_array,
                                    _fifo("arrays.npz"), _fifo("engine.json"), _outside_table],
                         ids=["truncated_npz", "deep_json", "wrong_type", "frame_of_2e8_rows",
                              "npz_zip_bomb", "npy_header_lying", "tracks_of_1e9_bins",
                              "text_arrays", "fifo_npz", "fifo_engine_json",
                              "table_linked_from_elsewhere"])
def test_a_damaged_saved_state_reruns_the_well_from_its_start(damage, tmp_path, capsys):
    """A truncated arrays.npz, a deep engine.json or a wrong type ended in `internal error`
    naming no file (and the well failed every night until --force); a 2-MB frame declaring
    2×10⁸ rows or a 9.5-MB npz expanding to > 1.8 GB exhausted memory at resume."""
    import json

    import pandas as pd

    root = tmp_path / "sandbox"
    root.mkdir()
    path = _well(root)
    fleet = Case(["fleet", "wells", "--out", "out", "--workers", "1"], (1,))
    _strict_check(fleet, root, capsys)
    state = root / "out" / "w" / "state"
    assert (state / "engine.json").is_file()
    damage(state)
    frame = pd.read_csv(path)
    later = frame.assign(time_s=frame["time_s"] + frame["time_s"].iloc[-1] + 0.1)
    later.to_csv(path, mode="a", header=False, index=False)  # the log grew: resume is tried
    _strict_check(fleet, root, capsys)
    summary = json.loads((root / "out" / "w" / "summary.json").read_text())
    assert summary["resumed"]["from_row"] == 0, summary["resumed"]
    assert "changed since the state was sealed" in summary["resumed"]["reason"] or \
        summary["resumed"]["reason"] == "no saved state", summary["resumed"]  # not a file


@pytest.mark.parametrize("damage", [_truncated_arrays, _deep_json, _many_rows,
                                    lambda f: _zip_bomb(f / "arrays.npz"),
                                    lambda f: _lying_npy(f / "arrays.npz"), _text_array,
                                    _fifo("arrays.npz"), _fifo("engine.json"), _outside_table],
                         ids=["truncated_npz", "deep_json", "frame_of_2e8_rows", "npz_zip_bomb",
                              "npy_header_lying", "text_arrays", "fifo_npz", "fifo_engine_json",
                              "table_linked_from_elsewhere"])
def test_the_state_reader_refuses_damage_before_reading_it(damage, tmp_path):
    """Under the seal, the reader keeps its own limits (a state sealed under a shared
    DRILLFRIC_STATE_KEY is only as safe as the key): each damage is one InputError before
    any array, table or document is loaded whole."""
    import numpy as np
    import pandas as pd

    from drillfric.errors import InputError
    from drillfric.runner.state import read_state, write_state

    state = tmp_path / "state"
    write_state(state, {"a": np.arange(400.0), "t": pd.DataFrame({"x": np.arange(10.0)})})
    damage(state)
    with hang_guard(60), pytest.raises(InputError, match="engine state not readable"):
        read_state(state)


# --------------------------------------------------------------- configs that ask for hours (2)
@pytest.mark.parametrize(("table", "text", "says"), [
    ("model", "element_length_m = 1e-6", "element_length_m"),
    ("model", "cells = 200000", "cells = 200000"),
    ("observer", "starts = " + repr([[0.5, 0.3]] * 20000), "20000 observer.starts"),
    ("observer", "output_rate_hz = 100000", "output_rate_hz"),
])
def test_a_config_implying_hours_of_work_is_refused_up_front(table, text, says, tmp_path,
                                                             capsys):
    """Inside each key's range: element_length_m = 1e-6 reached 22.7 GB, output_rate_hz =
    100000 5 GB in 52 s, 20 000 starts > 120 s at 2.8 GB, cells = 200000 unfinished after
    120 s. Now one line naming the key and the budget, before any work."""
    root = tmp_path / "sandbox"
    root.mkdir()
    path = _log(root / "w.csv")
    _config(path.with_suffix(".toml"), f"[well]\nbit_depth_m = 2000.0\n[{table}]\n{text}\n")
    _strict_check(Case(["run", "w.csv", "--out", "out"], (2,), (says,)), root, capsys)
    assert not (root / "out").exists()


def test_damping_without_a_finite_kalman_design_is_a_model_error_naming_k_t():
    """k_t_per_s = 10000 (in range) gave `internal error: LinAlgError` (no finite solution of
    the Riccati equation): now a ModelError naming the key, which fails the segment in one
    line while the others go on."""
    from drillfric.errors import ModelError
    from drillfric.estimation.gains import kalman_filter_gain
    from tests.test_gains import as_params

    with pytest.raises(ModelError, match="k_t_per_s"):
        kalman_filter_gain(as_params(k_t_per_s=1e4), 40)


def test_units_pint_cannot_tokenize_are_unknown_units_and_multiindex_frames_are_refused():
    """open_well(frame=…) with MultiIndex columns gave tokenize.TokenError (its labels were
    read as units); any text pint's parser chokes on is an unknown unit. Two levels are
    since read as (name, unit) (twelfth attack, F8); three are refused."""
    import numpy as np
    import pandas as pd

    import drillfric
    from drillfric.errors import InputError
    from drillfric.units import parse_unit

    with pytest.raises(InputError, match="unknown unit"):
        parse_unit("('a', 'b'")
    frame = pd.DataFrame(np.ones((10, 3)), columns=pd.MultiIndex.from_tuples(
        [("time_s", "s", "a"), ("surface_rpm", "rpm", "b"), ("surface_torque_Nm", "Nm", "c")]))
    with pytest.raises(InputError, match="MultiIndex"):
        drillfric.open_well(frame=frame)


def test_report_on_a_summary_nested_100000_deep_is_one_line(tmp_path, capsys):
    """`drillfric report` on a 100 000-deep summary.json: RecursionError."""
    root = tmp_path / "sandbox"
    (root / "out" / "w").mkdir(parents=True)
    (root / "out" / "w" / "summary.json").write_text("[" * 100_000 + "]" * 100_000)
    _strict_check(Case(["report", "out/w"], (2,), ("too deeply nested",)), root, capsys)


# ------------------------------------------------ a manifest lying (issue 30, the attack)
def _night(root):
    return CliRunner().invoke(cli, ["fleet", str(root / "wells"), "--out", str(root / "out"),
                                    "--workers", "1"])


@pytest.mark.parametrize("lie", ["entry_a_number", "inputs_a_list", "outputs_a_text",
                                 "input_without_path", "outputs_elsewhere", "extra_input_fifo",
                                 "history_without_segments", "summary_with_text_mu",
                                 "summary_segments_a_number"])
def test_a_manifest_entry_that_is_not_drillfrics_makes_the_well_run_again(lie, tmp_path):
    """manifest.json's entries were trusted: a number or a list where a table goes was an
    internal error every night (--force too); a FIFO named as an input hung the fleet; an
    entry whose outputs lay elsewhere published another folder's results as "unchanged"; a
    history entry without its fields, or a summary.json made up with its digest stored in the
    manifest, was an internal error every night or published text as the well's μ_k."""
    import hashlib
    import json

    import pandas as pd

    root = tmp_path / "sandbox"
    _well(root)
    assert "1 processed" in _night(root).output
    path = root / "out" / "manifest.json"
    manifest = json.loads(path.read_text())
    entry = manifest["wells"]["w"]
    if lie == "entry_a_number":
        manifest["wells"]["w"] = 5
    elif lie == "inputs_a_list":
        entry["inputs"] = []
    elif lie == "outputs_a_text":
        entry["outputs"] = "x"
    elif lie == "input_without_path":
        entry["inputs"]["data"] = {"sha256": "x"}
    elif lie == "outputs_elsewhere":
        elsewhere = root / "elsewhere"
        shutil.copytree(root / "out" / "w", elsewhere)
        entry["outputs"] = {k: v.replace(str(root / "out" / "w"), str(elsewhere))
                            for k, v in entry["outputs"].items()}
    elif lie == "extra_input_fifo":
        os.mkfifo(root / "fifo")
        entry["inputs"]["extra"] = {"path": str(root / "fifo"), "size": 0, "mtime_ns": 0,
                                    "sha256": "00"}
    elif lie == "history_without_segments":
        entry["history"] = [{"utc": "x"}]
    else:  # a summary.json made up, its digest stored in the manifest to match
        summary_path = root / "out" / "w" / "summary.json"
        summary = json.loads(summary_path.read_text())
        summary.update({"mu_k": "abc"} if lie == "summary_with_text_mu" else {"segments": 5})
        summary_path.write_text(json.dumps(summary))
        entry["summary_sha256"] = hashlib.sha256(summary_path.read_bytes()).hexdigest()
    path.write_text(json.dumps(manifest))
    with hang_guard(120):
        night = _night(root)
    assert "Traceback" not in night.output and "internal error" not in night.output, \
        night.output
    assert "1 processed" in night.output, night.output
    table = pd.read_parquet(root / "out" / "fleet_summary.parquet")
    assert {str(Path(d).resolve()) for d in table["result_dir"]} == \
        {str((root / "out" / "w").resolve())}


def test_a_fifo_at_the_wits0_recording_is_refused_not_waited_on(tmp_path, capsys):
    """A FIFO at OUT/NAME.wits0.csv hung live in open() (O_NOFOLLOW only)."""
    root = tmp_path / "sandbox"
    root.mkdir()
    _config(root / "rig.toml", '[well]\nname = "rig"\n')
    (root / "out").mkdir()
    os.mkfifo(root / "out" / "rig.wits0.csv")
    _strict_check(Case(["live", "wits0://127.0.0.1:9", "--config", "rig.toml", "--out", "out",
                        "--until-idle", "1"], (2,), ("FIFO",)), root, capsys)


def test_simulate_recording_more_rows_than_memory_holds_is_refused(tmp_path, capsys):
    """rate_hz = 100000 over 100 000 s asked for 74.5 GiB: internal MemoryError (the rate
    is now at most 10 kHz; 10 kHz over 1 000 000 s asks as much)."""
    root = tmp_path / "sandbox"
    root.mkdir()
    (root / "s.toml").write_text("[simulate]\nbit_depth_m = 1000.0\ncells = 20\n"
                                 "duration_s = 1000000.0\nrate_hz = 10000.0\n")
    _strict_check(Case(["simulate", "s.toml", "--out", "out/o.csv"], (2,), ("rows",)), root,
                  capsys)


def test_a_directory_where_the_fleet_writes_a_file_is_named_not_its_temporary(tmp_path,
                                                                             capsys):
    root = tmp_path / "sandbox"
    root.mkdir()
    _well(root)
    (root / "out" / "fleet.html").mkdir(parents=True)
    text = _check(Case(["fleet", "wells", "--out", "out", "--workers", "1"], (2,),
                       ("a directory stands where drillfric writes",)), root)
    assert "out/fleet.html:" in text and ".tmp" not in text, text



# ------------------------------------------------ the second attack (issue 30)
def test_a_light_stiff_string_cannot_slip_past_the_work_budget(tmp_path, capsys):
    """The budget took steel's wave speed; G = 1e12 Pa and ρ = 2 kg/m³ (each in range) made
    the grid's step 700× shorter and `run` was still going at 120 s."""
    root = tmp_path / "sandbox"
    root.mkdir()
    path = _log(root / "w.csv")
    _config(path.with_suffix(".toml"), """[well]
bit_depth_m = 2000.0
[model]
cells = 2000
[fluid]
mud_density_kg_m3 = 0.0
[[string.sections]]
name = "dp"
od_m = 0.127
id_m = 0.1086
shear_modulus_Pa = 1e12
steel_density_kg_m3 = 2.0
linear_mass_kg_m = 29.0
[[string.sections]]
name = "bha"
od_m = 0.2032
id_m = 0.0714
length_m = 200
shear_modulus_Pa = 1e12
steel_density_kg_m3 = 2.0
linear_mass_kg_m = 220.0
""")
    _strict_check(Case(["run", "w.csv", "--out", "out"], (2,), ("cells = 2000",)), root,
                  capsys)


@pytest.mark.parametrize(("settings", "says"), [
    # the explicit PI drive diverged: simulate wrote inf and 1e305 with exit 0
    ("bit_depth_m = 2000.0\nkp_Nms_rad = 1e7\nduration_s = 20\ncells = 200", "diverged"),
    # 0.05 Hz over a 20-s stand recorded one row and exited 0
    ("bit_depth_m = 1000.0\ncells = 20\nduration_s = 20\nrate_hz = 0.05", "rate_hz"),
])
def test_a_simulation_that_cannot_be_a_record_is_one_line_and_no_file(settings, says,
                                                                     tmp_path, capsys):
    root = tmp_path / "sandbox"
    root.mkdir()
    (root / "s.toml").write_text(f"[simulate]\n{settings}\n")
    _strict_check(Case(["simulate", "s.toml", "--out", "out/s.csv"], (2,), (says,)), root,
                  capsys)
    assert not (root / "out" / "s.csv").exists()


@pytest.mark.parametrize("edit", ["text_time", "huge_id", "negative_rows", "carried_rows"])
def test_a_state_changed_by_anyone_but_drillfric_is_not_continued(edit, tmp_path, capsys):
    """Values of a tampered engine.json got past every check into the feed: `internal
    error` every night (a text time, a 10²⁰ id), a fault blamed on the user's log, a silently
    shorter segment (raw_rows = -5); an estimates.parquet changed in OUT was carried into
    the next night's results. The state is sealed: any change means a run from the start."""
    import json

    import pandas as pd

    root = tmp_path / "sandbox"
    root.mkdir()
    path = _well(root)
    fleet = Case(["fleet", "wells", "--out", "out", "--workers", "1"], (1,))
    _strict_check(fleet, root, capsys)
    folder = root / "out" / "w"
    doc = json.loads((folder / "state" / "engine.json").read_text())
    if edit == "carried_rows":
        frame = pd.read_parquet(folder / "estimates.parquet")
        frame.assign(**{c: 31337.0 for c in frame.columns if c.endswith("_Nm")}).to_parquet(
            folder / "estimates.parquet")
    else:
        state = doc["state"]
        key, value = {"text_time": ("raw_rows", "x"), "huge_id": ("raw_rows", 10 ** 20),
                      "negative_rows": ("raw_rows", -5)}[edit]
        state[key] = value
        (folder / "state" / "engine.json").write_text(json.dumps(doc))
    frame = pd.read_csv(path)
    frame.assign(time_s=frame["time_s"] + 40.0).to_csv(path, mode="a", header=False,
                                                      index=False)
    _strict_check(fleet, root, capsys)
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["resumed"]["from_row"] == 0 and "seal" in summary["resumed"]["reason"] \
        or "changed since" in summary["resumed"]["reason"], summary["resumed"]


def test_an_untouched_state_is_continued(tmp_path, capsys):
    """The seal's other half: a state nobody changed is continued from where it stopped."""
    import json

    import pandas as pd

    root = tmp_path / "sandbox"
    root.mkdir()
    path = _well(root)
    fleet = Case(["fleet", "wells", "--out", "out", "--workers", "1"], (1,))
    _strict_check(fleet, root, capsys)
    assert (root / "out" / "w" / "state" / "seal.json").is_file()
    frame = pd.read_csv(path)
    frame.assign(time_s=frame["time_s"] + 40.0).to_csv(path, mode="a", header=False,
                                                      index=False)
    _strict_check(fleet, root, capsys)
    summary = json.loads((root / "out" / "w" / "summary.json").read_text())
    assert summary["resumed"]["from_row"] == len(frame), summary["resumed"]


@pytest.fixture(scope="module")
def result_dir(stands, tmp_path_factory):
    """OUT/NAME of the three-stand well's run (estimates, tracks, profiles), once."""
    out = tmp_path_factory.mktemp("result")
    done = CliRunner().invoke(cli, ["run", str(stands[0]), "--out", str(out), "--no-report"])
    assert done.exit_code == 0, done.output
    return out / stands[0].stem


@pytest.mark.parametrize(("table", "how"), [("estimates", "text"), ("tracks", "text"),
                                            ("estimates", "list"), ("profiles", "list"),
                                            ("tracks", "codes")])
def test_report_on_crafted_result_tables_is_one_line(table, how, result_dir, tmp_path,
                                                     capsys):
    """`drillfric report` on its own tables made wrong: columns of text or of lists, rig
    states no state has — ArrowTypeError, TypeError, IndexError as internal errors."""
    import numpy as np
    import pandas as pd

    root = tmp_path / "sandbox"
    shutil.copytree(result_dir, root / "out" / "demo")
    path = root / "out" / "demo" / f"{table}.parquet"
    frame = pd.read_parquet(path)
    if how == "text":
        frame = frame.astype(str)
    elif how == "list":
        frame = frame.assign(**{c: [[1.0, 2.0]] * len(frame) for c in frame.columns
                                if c not in ("segment_id", "start_id")})
    else:
        frame = frame.assign(rig_state=np.int64(2 ** 62))
    frame.to_parquet(path)
    _strict_check(Case(["report", "out/demo"], (2,), (f"{table}.parquet",)), root, capsys)


# ------------------------------------------------ the third attack (issue 30)
@pytest.mark.parametrize("plant", ["fifo", "empty", "readable_by_others", "link_to_zero"])
def test_a_state_key_that_is_not_a_key_seals_and_resumes_nothing(plant, tmp_path,
                                                                 monkeypatch):
    """A FIFO as the key hung the run; a link to /dev/zero read 20 GB; an empty or
    world-readable key let anyone forge a seal. None of them is a key."""
    from drillfric.io import seal

    home = tmp_path / "config"
    folder = home / "drillfric"
    folder.mkdir(parents=True)
    path = folder / "state.key"
    if plant == "fifo":
        os.mkfifo(path)
    elif plant == "empty":
        path.write_bytes(b"")
        path.chmod(0o600)
    elif plant == "readable_by_others":
        path.write_bytes(b"k" * 32)
        path.chmod(0o644)
    else:
        path.symlink_to("/dev/zero")
    monkeypatch.setenv("XDG_CONFIG_HOME", str(home))
    monkeypatch.delenv(seal.KEY_ENV, raising=False)
    with hang_guard(30):
        assert seal.key() is None
        state = tmp_path / "state"
        state.mkdir()
        (state / "engine.json").write_text("{}")
        assert not seal.seal(state) and "no key" in seal.broken(state)


def test_a_key_made_on_first_use_is_private_and_kept(tmp_path, monkeypatch):
    from drillfric.io import seal

    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))
    monkeypatch.delenv(seal.KEY_ENV, raising=False)
    first = seal.key()
    path = tmp_path / "drillfric" / "state.key"
    assert len(first) == 32 and path.stat().st_mode & 0o777 == 0o600
    assert seal.key() == first


@pytest.mark.parametrize(("args", "says"), [
    (["--depths="], "finite numbers"), (["--depths=,"], "finite numbers"),
    (["--depths", "0:1e15:1"], "at most 10000"), (["--frictions", "nan,0.2"], "finite"),
    (["--bit-depth", "1e9"], "not a well's"),
    (["--depths", "300:2400:2.1", "--element-length", "0.0121"], "budget")])
def test_td_broomstick_asking_for_petabytes_or_hours_is_one_line(args, says, tmp_path,
                                                                  capsys):
    """--depths 0:1e15:1 asked for 7 PiB; 1000 depths at 1.2-cm elements took 89 s; an
    empty list was an IndexError; NaN frictions drew NaN curves with exit 0; --bit-depth 1e9
    took 13 GB before the element budget said no."""
    root = tmp_path / "sandbox"
    root.mkdir()
    (root / "w.toml").write_text("[well]\nbit_depth_m = 2400.0\n")
    _strict_check(Case(["td", "w.toml", "--broomstick", *args], (2,), (says,)), root, capsys)


@pytest.mark.parametrize(("args", "says"), [(["--speed", "inf"], "--speed"),
                                            (["--tick", "inf"], "--tick"),
                                            (["--to", "fifo"], "not a regular file")])
def test_replay_at_infinite_pace_or_into_a_fifo_is_one_line(args, says, tmp_path, capsys):
    """--speed inf was an OverflowError leaving an empty target; --to a FIFO blocked."""
    root = tmp_path / "sandbox"
    root.mkdir()
    _log(root / "w.csv")
    os.mkfifo(root / "fifo")
    target = [] if "--to" in args else ["--to", "out/t.csv"]
    _strict_check(Case(["replay", "w.csv", *target, *args], (2,), (says,)), root, capsys)
    assert not (root / "out" / "t.csv").exists()


def test_a_followed_file_replaced_by_another_is_one_line_not_spliced(tmp_path):
    """A file renamed over the followed one, as long as it, was spliced silently into one
    log (the old rows, then the new file's); a file rewritten whole with the same first
    bytes (a logger that renames its rewrite over the old file) is followed on."""
    from drillfric.errors import InputError
    from drillfric.live.source import Tail

    path = tmp_path / "g.csv"
    path.write_text("time_s,x\n0,1\n1,2\n")
    tail = Tail(path)
    assert tail.poll() == len(path.read_bytes())
    grown = tmp_path / "new.csv"
    grown.write_text("time_s,x\n0,1\n1,2\n2,3\n")
    os.replace(grown, path)  # the same first bytes, renamed over: followed on
    assert tail.poll() == len(path.read_bytes())
    other = tmp_path / "other.csv"
    other.write_text("time_s,x\n0,9\n1,9\n2,9\n3,9\n")
    os.replace(other, path)
    with pytest.raises(InputError, match="replaced by another"):
        tail.poll()


@pytest.mark.parametrize("rewrite", ["1,2,3\n", "1,7\n2,3\n"],
                         ids=["longer line spliced", "same length, stale value"])
def test_a_followed_file_rewritten_in_place_is_one_line(tmp_path, rewrite):
    """Ninth attack F6: a logger rewriting the followed file in place (same inode, no
    rename) had live read a spliced half-line ("time goes backwards…"), or keep stale rows
    silently when the rewrite kept the length. The last bytes read are checked at every
    poll; appending stays fine."""
    from drillfric.errors import InputError
    from drillfric.live.source import Tail

    path = tmp_path / "g.csv"
    path.write_text("time_s,x\n0,1\n1,2\n")
    tail = Tail(path)
    tail.poll()
    with open(path, "a") as fh:
        fh.write("2,3\n")
    assert tail.poll() == len(path.read_bytes())  # appended: followed on
    with open(path, "r+") as fh:  # rewritten in place from row 1 on, same inode
        fh.seek(len("time_s,x\n0,1\n"))
        fh.write(rewrite)
    with pytest.raises(InputError, match="rewritten in place"):
        tail.poll()


def test_pdf_tables_draw_at_most_their_cap_of_rows():
    """A summary.json of a million 'assumed' lines grew report --pdf past 5 GB."""
    from drillfric.report.pdf import MAX_TABLE_ROWS, table_pages

    few = table_pages("t", ["a", "b"], [["x", "y"]] * 100)
    many = table_pages("t", ["a", "b"], [["x", "y"]] * 100_000)
    assert len(many) <= len(few) * (MAX_TABLE_ROWS // 100 + 1)


# ------------------------------------------------ the fourth attack (issue 30)
@pytest.mark.parametrize("side", ["ok.toml", "ok.survey.csv", "ok.truth.json"])
def test_simulate_never_writes_its_sidecars_through_a_link(side, tmp_path, capsys):
    """A link planted as NAME.toml, NAME.survey.csv or NAME.truth.json beside simulate's
    --out was written through: a file elsewhere overwritten with exit 0."""
    root = tmp_path / "sandbox"
    root.mkdir()
    (root / "ok.toml").write_text("[simulate]\nbit_depth_m = 1000.0\ncells = 50\n"
                                  "duration_s = 20\nrate_hz = 10\n")
    target = _secret(root)
    (root / "out").mkdir()
    (root / "out" / side).symlink_to(target)
    _strict_check(Case(["simulate", "ok.toml", "--out", "out/ok.csv"], (2,),
                       ("symbolic link",)), root, capsys)
    assert not (root / "out" / "ok.csv").exists()
    assert target.read_text() == SECRET + "\n"


def test_a_tiny_top_drive_inertia_is_refused_and_a_diverging_observer_prints_no_mu(
        tmp_path, capsys):
    """top_drive_inertia_kg_m2 = 1e-6 (in range then): the observer ran to 10¹² RPM and a μ_k
    of 0.74 was printed with "severe stick-slip" on a steady log. The key's range now starts
    at 10 kg·m², and an observer that runs away fails its segment in one line."""
    import numpy as np

    from drillfric.errors import ModelError
    from drillfric.estimation.chain import check_bounded
    from drillfric.estimation.observer import Measurements

    root = tmp_path / "sandbox"
    root.mkdir()
    path = _log(root / "w.csv")
    _config(path.with_suffix(".toml"), "[rig]\ntop_drive_inertia_kg_m2 = 1e-6\n")
    _strict_check(Case(["run", "w.csv", "--out", "out"], (2,), ("top_drive_inertia",)), root,
                  capsys)
    meas = Measurements.__new__(Measurements)
    object.__setattr__(meas, "surface_rad_s", np.full(10, 6.0))
    record = type("R", (), {"surface_rad_s_est": np.full((10, 1), 6.0),
                            "bit_rad_s_est": np.full((10, 1), 7e11)})()
    with pytest.raises(ModelError, match="observer diverged"):
        check_bounded(record, meas)
    record.bit_rad_s_est = np.full((10, 1), 12.0)
    check_bounded(record, meas)  # a bit at twice the surface speed: stick-slip, not a runaway


def test_a_wits0_recording_dated_in_the_future_is_named_not_obeyed(tmp_path, capsys):
    """A last line dated 9999 made every frame 'older' and dropped, ending in 'no WITS0
    frame arrived' — the wrong cause and fix, on every restart."""
    from drillfric.io.wits0 import Row, item_map

    root = tmp_path / "sandbox"
    root.mkdir()
    _config(root / "rig.toml", '[well]\nname = "rig"\n')
    names = Row(item_map({})).names
    (root / "out").mkdir()
    (root / "out" / "rig.wits0.csv").write_text(
        ",".join(["time", *names]) + "\n9999-12-31T00:00:00.000000" + "," * len(names) + "\n")
    _strict_check(Case(["live", "wits0://127.0.0.1:9", "--config", "rig.toml", "--out", "out",
                        "--until-idle", "1"], (2,), ("dated more than a day after",)), root,
                  capsys)


# ------------------------------------------------ the fifth attack (issue 30)
def test_out_equal_to_a_directory_wells_data_folder_runs_every_night(tmp_path, capsys):
    """--out equal to a directory well's data folder ([well] data = "."): night 2 read its
    own fleet.html, fleet_summary.parquet and manifest.json as parts of the log and failed
    every night after."""
    root = tmp_path / "sandbox"
    folder = root / "wells" / "b"
    for k in (1, 2):
        _log(folder / f"p{k}.csv", t0=40.0 * (k - 1))
    (folder / "well.toml").write_text('[well]\ndata = "."\n[segmentation]\n'
                                      "min_segment_s = 60.0\n")
    for _ in range(2):
        night = CliRunner().invoke(cli, ["fleet", str(root / "wells"), "--out", str(folder),
                                         "--workers", "1", "--no-report"])
        assert "data folder holds files" not in night.output, night.output
        assert "error" not in night.output.lower() and ("0 failed" in night.output or
                                                       "all 1 well ok" in night.output), \
            night.output


@pytest.mark.parametrize("plant", ["link", "directory"])
def test_td_checks_every_output_before_writing_any(plant, tmp_path, capsys):
    """A link or a directory at the broomstick's plot path: one error line — but the table
    beside it had been written already."""
    root = tmp_path / "sandbox"
    root.mkdir()
    (root / "w.toml").write_text("[well]\nbit_depth_m = 2400.0\n")
    (root / "out").mkdir()
    if plant == "link":
        (root / "out" / "b.png").symlink_to(_secret(root))
    else:
        (root / "out" / "b.png").mkdir()
    _strict_check(Case(["td", "w.toml", "--broomstick", "--depths", "1000:2400:700",
                        "--out", "out/b.parquet"], (2,), ("stands where the output goes",)),
                  root, capsys)
    assert not (root / "out" / "b.parquet").exists()


# ------------------------------------------------ the fifth attack's leftovers (issue 30)
@pytest.mark.parametrize(("table", "key", "value"), [
    ("batch", "window_s", "0.15"),  # the segment failed, blaming the log's time order
    ("simulate", "rpm", "1e6"),  # blamed the controller ("diverged")
    ("simulate", "rate_hz", "1e-300"),  # a one-row simulation, exit 0
])
def test_an_in_range_setting_that_makes_no_sense_names_its_key(table, key, value, tmp_path,
                                                              capsys):
    root = tmp_path / "sandbox"
    root.mkdir()
    path = _log(root / "w.csv")
    _config(path.with_suffix(".toml"), f"[well]\nbit_depth_m = 1000.0\n[{table}]\n"
                                       f"{key} = {value}\n[simulate]\ncells = 20\n"
                                       if table == "batch" else
                                       f"[{table}]\n{key} = {value}\nbit_depth_m = 1000.0\n"
                                       "cells = 20\nduration_s = 20\n")
    args = ["run", "w.csv", "--out", "out"] if table == "batch" else \
        ["simulate", "w.toml", "--out", "out/s.csv"]
    _strict_check(Case(args, (2,), (f"{table}.{key}",)), root, capsys)


def test_live_json_of_a_failed_run_says_so_not_stale_numbers(tmp_path):
    """A live run that stopped on an error left live.json as at its last write: a page
    polling it showed the open segment's numbers as current. The last live.json now says
    the run is not running and why, first in its alerts."""
    import json
    import sys
    import time

    path = _log(tmp_path / "w.csv", seconds=400.0)
    _config(path.with_suffix(".toml"))
    proc = subprocess.Popen([sys.executable, "-m", "drillfric.cli.main", "live", "w.csv",
                             "--out", "out", "--until-idle", "20", "--no-report"],
                            cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    status = tmp_path / "out" / "live.json"
    deadline = time.monotonic() + 60.0
    while time.monotonic() < deadline and not (
            status.exists() and json.loads(status.read_text() or "{}").get("rows")):
        time.sleep(0.1)
    other = _log(tmp_path / "other.csv", seconds=500.0, rpm=90.0)
    os.replace(other, path)  # another file renamed over the followed one: the run fails
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 2, err
    final = json.loads(status.read_text())
    assert final["running"] is False
    assert final["alerts"][0]["kind"] == "run_failed", final["alerts"]
    assert "replaced by another" in final["alerts"][0]["message"]


def test_live_json_of_a_run_that_ended_says_so(tmp_path):
    import json

    path = _log(tmp_path / "w.csv")
    _config(path.with_suffix(".toml"))
    result = CliRunner().invoke(cli, ["live", str(path), "--out", str(tmp_path / "out"),
                                      "--until-idle", "1", "--no-report"])
    assert result.exit_code == 0, result.output
    final = json.loads((tmp_path / "out" / "live.json").read_text())
    assert final["running"] is False and final["alerts"][0]["kind"] == "run_ended"


# ------------------------------------------------ the sixth attack (issue 30)
def test_a_torque_zero_offset_withholds_friction_not_prints_it(tmp_path):
    """2500 N·m added to the demo's torque printed μ_k 0.322 (truth 0.28), status ok: the
    torque read 2.5 kN·m with the string in the slips. Every friction factor is now withheld
    with the offset named (docs/theory.md §2.1 "The torque's zero")."""
    import json

    import pandas as pd

    demo = Path(__file__).resolve().parents[1] / "examples" / "demo"
    frame = pd.read_csv(demo / "demo.csv")
    frame["surface_torque_Nm"] += 2500.0
    frame.to_csv(tmp_path / "off.csv", index=False)
    result = CliRunner().invoke(cli, ["run", str(tmp_path / "off.csv"), "--config",
                                      str(demo / "demo.toml"), "--out", str(tmp_path / "o"),
                                      "--no-report"])
    assert result.exit_code == 0, result.output
    summary = json.loads(next((tmp_path / "o").glob("*/summary.json")).read_text())
    zero = summary["torque_zero"]
    assert zero["verdict"] == "offset" and 2000.0 < zero["in_slips_torque_Nm"] < 3000.0
    assert summary["mu_k"] is None and "torque-zero" in summary["mu_k_reason"]
    assert all(s["mu_k"] is None and s["mu_s"] is None for s in summary["segments"])
    assert any("torque_zero_offset" in s["quality_flags"] for s in summary["segments"])


def test_the_torque_at_rest_is_the_same_in_any_chunking_and_after_a_restore():
    import numpy as np
    import pandas as pd

    from drillfric.config import config_from_dict
    from drillfric.torque_zero import TorqueAtRest

    rng = np.random.default_rng(3)
    n = 5000
    frame = pd.DataFrame({"surface_rpm": np.where(rng.random(n) < 0.5, 0.0, 60.0),
                          "hookload_N": rng.choice([3e5, 1.2e6], n),
                          "surface_torque_Nm": rng.normal(400.0, 50.0, n)})
    cfg = config_from_dict({})
    whole, parts = TorqueAtRest(cfg), TorqueAtRest(cfg)
    whole.feed(frame)
    for a in range(0, n, 777):
        parts.feed(frame.iloc[a:a + 777])
        restored = TorqueAtRest(cfg)
        restored.restore(parts.state())
        parts = restored
    assert np.array_equal(whole.counts, parts.counts)
    zero, rows = whole.in_band(2.9e5, 3.1e5)
    assert rows == int(((frame.surface_rpm == 0) & (frame.hookload_N == 3e5)).sum())
    assert zero == pytest.approx(400.0, rel=0.08)  # to the 15 % of its bin


@pytest.mark.parametrize(("section", "says"), [
    ('tool_joint_od_m = 0.10', "smaller than od_m"),  # μ_k 0.380, μ_s 1.04 printed
    ('tool_joint_od_m = 0.30', "does not fit in the hole"),  # μ_k 0.197, μ_s 0.347 printed
])
def test_a_tool_joint_that_cannot_be_is_refused(section, says, tmp_path, capsys):
    root = tmp_path / "sandbox"
    root.mkdir()
    path = _log(root / "w.csv")
    _config(path.with_suffix(".toml"), f"""[well]
bit_depth_m = 2000.0
bit_diameter_m = 0.2159
[[string.sections]]
name = "dp"
od_m = 0.1465
id_m = 0.123
{section}
[[string.sections]]
name = "bha"
od_m = 0.1714
id_m = 0.0714
length_m = 200
""")
    _strict_check(Case(["run", "w.csv", "--out", "out"], (2,), (says,)), root, capsys)


def test_output_onto_a_device_or_fifo_is_refused_not_replaced(tmp_path):
    """A helper's attack run as root had ``/dev/null`` replaced by a regular file: the
    atomic writer renamed its temporary over whatever stood at the output path. A device,
    FIFO or socket there is now refused in one line and left as it was (a FIFO stands in
    for the device here)."""
    from drillfric.io.atomic import replacing

    fifo = tmp_path / "out.parquet"
    os.mkfifo(fifo)
    with pytest.raises(OutputError, match="device, FIFO or socket"), replacing(fifo) as tmp:
        tmp.write_text("x")
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.parquet"]
