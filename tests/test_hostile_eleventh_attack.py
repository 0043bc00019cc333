"""Regression tests of the eleventh hostile-input attack (issue 30): numbers written the way
people write them, and parts of one log in different units. Each test is named after what
the attack did."""

from __future__ import annotations

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from drillfric.errors import ConfigError, InputError
from drillfric.io.parts import open_parts
from drillfric.units import quantity_value
from tests.test_live import _wait_for


@pytest.mark.parametrize("text, unit", [
    ("2,300 m", "m"), ("2 300 m", "m"), ("2\u00a0300 m", "m"), ("2\u202f300 m", "m"),
    ("7,546.5 ft", "m"), ("2.300,5 m", "m"), ("1,2 sg", "kg/m³"), ("35,5 klbf", "N"),
    ("2 900 kg.m**2", "kg*m**2"), ("8200 ft 2", "m"),
])
def test_a_thousands_separator_or_decimal_comma_in_a_quantity_is_refused(text, unit):
    """``"2,300 m"`` read as 600 m and ``mud_density_kg_m3 = "1,2 sg"`` as 2000 kg/m³ (μ_k
    0.312 for 0.28, exit 0): the number was cut at the separator and pint multiplied the rest
    of it in as part of the unit. A number inside the unit part is refused, naming it."""
    with pytest.raises(ConfigError, match="has a number in its unit part"):
        quantity_value(text, unit, what="key 'x'", file="w.toml")


@pytest.mark.parametrize("text, unit, expected", [
    ("2300 m", "m", 2300.0), ("5 1/2 in", "m", 0.1397), ("2 deg/(30 m)", "rad/m", None),
    ("0.15 rev/gal", "rev/L", None), ("2900 kg.m**2", "kg*m**2", 2900.0),
])
def test_a_units_own_digits_are_still_read(text, unit, expected):
    """Exponents, a scale after '/' or '(' and whole fractions are a unit's own digits."""
    value = quantity_value(text, unit, what="key 'x'")
    assert expected is None or value == pytest.approx(expected)


@pytest.mark.parametrize("text", ["8 1/0 in", "1/0 m"])
def test_a_fraction_over_zero_is_one_line(text):
    """``"8 1/0 in"`` ended in 'internal error: DivisionByZero' naming no file."""
    with pytest.raises(ConfigError, match="divides by 0"):
        quantity_value(text, "m", what="key 'x'", file="w.toml")


def _frame():
    return pd.DataFrame({"TIME": [0.0, 1.0], "RPM": [60.0, 61.0], "TORQUE": [9e3, 9.1e3]})


def test_csv_parts_with_different_units_rows_are_refused(tmp_path):
    """h00.csv's units row said N.m, h01.csv's ft.lbf, the same column names: h01 was read in
    N·m (μ_k 0.203 for 0.279, exit 0). The part whose units differ is refused, naming both."""
    for name, torque_unit in (("h00.csv", "N.m"), ("h01.csv", "ft.lbf")):
        body = _frame().to_csv(index=False).splitlines()
        lines = [body[0], f"s,rpm,{torque_unit}", *body[1:]]
        (tmp_path / name).write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match="'TORQUE' is in 'ft.lbf' here and in 'N.m' in h00"):
        open_parts(sorted(tmp_path.glob("*.csv")))


def test_parquet_parts_with_different_unit_metadata_are_refused(tmp_path):
    """The same with Parquet parts whose field metadata ``unit`` differs."""
    for name, torque_unit in (("h00.parquet", "N.m"), ("h01.parquet", "ft.lbf")):
        table = pa.Table.from_pandas(_frame(), preserve_index=False)
        fields = [f.with_metadata({"unit": torque_unit}) if f.name == "TORQUE" else f
                  for f in table.schema]
        pq.write_table(table.cast(pa.schema(fields)), tmp_path / name)
    with pytest.raises(InputError, match="'TORQUE' is in 'ft.lbf' here"):
        open_parts(sorted(tmp_path.glob("*.parquet")))


def test_parts_spelling_one_unit_two_ways_are_one_log(tmp_path):
    """``N.m`` and ``N·m`` are one unit: no refusal."""
    for name, torque_unit in (("h00.csv", "N.m"), ("h01.csv", "N·m")):
        body = _frame().to_csv(index=False).splitlines()
        (tmp_path / name).write_text("\n".join([body[0], f"s,rpm,{torque_unit}", *body[1:]])
                                     + "\n", encoding="utf-8")
    assert open_parts(sorted(tmp_path.glob("*.csv"))).columns == ["TIME", "RPM", "TORQUE"]


def test_a_manifest_saved_as_csv_utf8_by_excel_keeps_its_well_column(tmp_path):
    """Excel's "CSV UTF-8" starts with a byte-order mark: the first column read as
    '\\ufeffwell', so every well was named after its file (OUT/x1 for ALPHA), silently."""
    from drillfric.fleet.discovery import _read_manifest

    manifest = tmp_path / "wells.csv"
    manifest.write_text("well,data,config\nALPHA,x1.csv,  \n", encoding="utf-8-sig")
    spec, = _read_manifest(manifest)
    assert spec.name == "ALPHA" and spec.data == tmp_path / "x1.csv"
    assert spec.config is None  # a cell of blanks is empty, not the folder '  '


def test_a_json_manifest_entry_naming_a_key_twice_is_refused(tmp_path):
    """``{"data": "a.csv", "data": "b.csv"}`` ran b.csv silently."""
    from drillfric.fleet.discovery import _read_manifest

    manifest = tmp_path / "wells.json"
    manifest.write_text('[{"well": "A", "data": "a.csv", "data": "b.csv"}]')
    with pytest.raises(InputError, match="key 'data' written twice"):
        _read_manifest(manifest)


def test_one_column_configured_for_two_channels_is_refused():
    """``surface_torque = { column = "surface_rpm" }`` ran with the speed read as the torque
    (exit 0, caught only by the μ-range warning)."""
    from drillfric.io.channels import map_channels

    with pytest.raises(InputError, match="'surface_rpm' is taken for both surface_rpm and "
                                         "surface_torque"):
        map_channels(["time_s", "surface_rpm", "surface_torque_Nm"], {},
                     {"surface_torque": {"column": "surface_rpm"}}, file="w.csv")


def test_iso_times_that_lose_their_utc_offset_midway_are_refused(tmp_path):
    """``+02:00`` dropped from row 2001 on: the rest was read as UTC, a silent 2-h jump and
    clock times 2 h off (exit 0). One line naming the row."""
    from click.testing import CliRunner
    from drillfric.cli.main import cli

    stamps = pd.date_range("2024-05-01T12:00:00", periods=40, freq="50ms")
    text = [s.isoformat() + ("+02:00" if i < 20 else "") for i, s in enumerate(stamps)]
    data = tmp_path / "tz.csv"
    pd.DataFrame({"TIME": text, "RPM": 60.0, "TORQUE": 9e3}).to_csv(data, index=False)
    result = CliRunner().invoke(cli, ["-q", "run", str(data), "--out", str(tmp_path / "o")])
    assert result.exit_code == 2, result.output
    assert "data row 21" in result.output and "has no UTC offset" in result.output
    assert not (tmp_path / "o").exists()


def test_one_torque_sample_of_1e30_does_not_fail_the_stand_as_a_unit():
    """One torque sample of 1e30 N·m failed the whole stand ('4e+25x the top … is the torque
    channel in another unit?'): the scale check took the mean. A unit scales every sample,
    so it takes the median; the spike is left to the EDR-defect step, which drops it."""
    import numpy as np

    from drillfric.errors import DrillfricError
    from drillfric.estimation.segment_data import SegmentData
    from drillfric.estimation.torque_scale import check_torque_scale

    t = np.arange(0.0, 60.0, 0.05)
    torque = np.full(t.size, 15e3)
    torque[300] = 1e30
    data = SegmentData(t, np.full(t.size, 60.0), torque, 2210.0)
    check_torque_scale(data, 55e3, 0.1)  # T_N of the demo's stand, order of magnitude
    with pytest.raises(DrillfricError, match="the top of the torque-and-drag range"):
        check_torque_scale(SegmentData(t, np.full(t.size, 60.0), torque * 1e3, 2210.0),
                           55e3, 0.1)


@pytest.mark.slow
def test_a_well_deleted_between_nights_is_not_reported_ok_again(tmp_path):
    """Night 2 after B.csv was deleted read 'all 1 well ok', manifest.json kept B 'ok' and
    OUT/B unmarked, night after night. The fleet says which wells it no longer finds, their
    results stay, marked stale, and manifest.json says since when."""
    import json

    import numpy as np
    from click.testing import CliRunner
    from drillfric.cli.main import cli

    wells = tmp_path / "wells"
    wells.mkdir()
    t = np.arange(0.0, 20.0, 0.1)
    for name in "AB":
        pd.DataFrame({"time_s": t, "surface_rpm": 0.0, "surface_torque_Nm": 0.0}).to_csv(
            wells / f"{name}.csv", index=False)
    out = tmp_path / "out"
    command = ["-q", "fleet", str(wells), "--out", str(out), "--no-report", "--workers", "1"]
    CliRunner().invoke(cli, command)
    (wells / "B.csv").unlink()
    result = CliRunner().invoke(cli, command)
    assert "1 well of earlier runs not found this time (B)" in result.output
    entry = json.loads((out / "manifest.json").read_text())["wells"]["B"]
    assert entry["missing_since_utc"] and (out / "B" / "STALE.json").is_file()
    assert "stale" in json.loads((out / "B" / "summary.json").read_text())


# ---------------------------------------------------------------- F8 WITS0 midnight
def test_wits0_recorder_whose_date_does_not_roll_over_at_midnight_loses_no_frame(tmp_path):
    """A recorder sending 23:59:50 … 00:00:09 all dated 2024-12-01: one warning, then every
    frame after midnight dropped as 'before the previous one' (no count), exit 0. Over real
    TCP: all 20 frames are recorded, those after midnight dated 2024-12-02, one warning says
    so; a frame truly dated before the previous one is counted at the end."""
    import socket
    import threading
    from datetime import datetime, timedelta

    from drillfric.io.wits0 import Row, encode, item_map
    from drillfric.live.wits0_receiver import Receiver, Recording, parse_address, setup

    listener = socket.create_server(("127.0.0.1", 0))
    address = parse_address(f"wits0://127.0.0.1:{listener.getsockname()[1]}")
    start = datetime(2024, 12, 1, 23, 59, 50)
    frames = b""
    for k in range(20):
        true = start + timedelta(seconds=k)
        sent = true.replace(day=1)  # the recorder's date stays 2024-12-01
        frames += encode({"surface_rpm": float(k)}, item_map({}), sent)
    frames += encode({"surface_rpm": 99.0}, item_map({}), datetime(2024, 12, 1, 0, 0, 5))
    warnings = []
    receiver = Receiver(address, setup(address, None, "t"),
                        Recording(tmp_path / "t.wits0.csv", Row(item_map({})).names, False),
                        warn=warnings.append)
    thread = threading.Thread(target=receiver.run, daemon=True)
    listener.settimeout(10)
    thread.start()
    try:
        conn, _ = listener.accept()
        conn.sendall(frames)
        _wait_for(lambda: receiver.frames + sum(receiver.dropped.values()) >= 21, 10)
        receiver.stop.set()
        conn.close()
    finally:
        receiver.stop.set()
        thread.join(5)
        listener.close()
    got = pd.read_csv(tmp_path / "t.wits0.csv")
    assert got["surface_rpm"].tolist() == [float(k) for k in range(20)]
    expected = [(start + timedelta(seconds=k)).isoformat(timespec="microseconds")
                for k in range(20)]
    assert got["time"].tolist() == expected
    midnight = [w for w in warnings if "does not roll over at midnight" in w]
    assert len(midnight) == 1 and "a frame dated 2024-12-01 00:00:00 follows one of " \
        "2024-12-01 23:59:59" in midnight[0]
    assert "recorded as 2024-12-02 from here" in midnight[0]
    assert receiver.dropped == {"order": 1}
    assert "1 of 21 frames not recorded (1 dated before the previous frame)" in \
        receiver.dropped_note()


# ---------------------------------------------------------------- F20 time in hours
def test_a_one_hz_log_with_its_time_in_hours_is_refused_naming_the_unit(tmp_path):
    """A 1-Hz log whose unlabelled time column is in hours: 'the surface speed never exceeds
    2 RPM … (highest: 62.2 RPM)' — a warning that contradicts itself — and exit 0 with
    nothing, though 4 stands were there. One line: samples 0.000278 s apart, is it in
    hours? and the [channels] line."""
    import numpy as np
    from click.testing import CliRunner
    from drillfric.cli.main import cli

    k = np.arange(300)
    rpm = np.where((k > 20) & (k < 260), 60.0, 0.0)
    data = tmp_path / "hours.csv"
    pd.DataFrame({"TIME": k / 3600.0, "surface_rpm": rpm,
                  "surface_torque_Nm": 9e3 * (rpm > 0)}).to_csv(data, index=False)
    result = CliRunner().invoke(cli, ["-q", "run", str(data), "--out", str(tmp_path / "o"),
                                      "--no-report"])
    assert result.exit_code == 2, result.output
    assert "samples 0.000278 s apart" in result.output and "is it in hours?" in result.output
    assert '[channels] time = { column = "TIME", unit = "h" }' in result.output
    assert not (tmp_path / "o").exists()


def test_turning_runs_are_counted_across_chunks():
    from types import SimpleNamespace

    import numpy as np

    from drillfric.io.logcheck import LogCheck

    check = LogCheck(SimpleNamespace())
    for chunk in ([0, 1, 1], [1, 1, 0, 1], [1, 1, 1, 1, 1], [0]):
        check._runs(np.array(chunk, bool))
    assert check.turn_longest == 6 and check.turn_run == 0


# ---------------------------------------------------------------- F12 decimal mark
def test_a_remark_column_of_1_5_does_not_make_a_dot_decimal_file_decimal_comma(tmp_path):
    """A semicolon CSV with dot decimals and a text column holding '1,5' every 50 rows: the
    file was read with a decimal comma, the dot grouping thousands — every value 1000×
    (time 50 s apart, and the error advised milliseconds). The mark is decided column by
    column; one column does not outvote six."""
    from drillfric.io.delimited import open_delimited, sniff_csv

    path = tmp_path / "semidot_remark.csv"
    lines = ["TIME;RPM;TORQUE;Remark"] + [
        f"{0.05 * k:.3f};{0.5 * k:.3f};12.420;{'1,5' if k % 50 == 0 else ''}"
        for k in range(120)]
    path.write_text("\n".join(lines) + "\n")
    assert sniff_csv(path).decimal == "."
    frame = next(open_delimited(path).chunks(1000))
    assert frame["TIME"].iloc[1] == pytest.approx(0.05)
    assert frame["RPM"].iloc[3] == pytest.approx(1.5)
    assert frame["TORQUE"].iloc[0] == pytest.approx(12.42)


@pytest.mark.parametrize("rows, mark", [
    (["12,5;17.240;0,05"], ","),  # 17.240 may group thousands: a comma file
    (["12,5;0.050"], None),  # one column each way: refused
])
def test_the_decimal_mark_is_decided_by_the_numeric_columns(tmp_path, rows, mark):
    from drillfric.io.delimited import sniff_csv

    path = tmp_path / "x.csv"
    path.write_text("\n".join(["A;B;C"[:len(rows[0].split(";")) * 2 - 1], *rows]) + "\n")
    if mark is None:
        with pytest.raises(InputError, match="the decimal mark cannot be told"):
            sniff_csv(path)
    else:
        assert sniff_csv(path).decimal == mark


# ---------------------------------------------------------------- F17 fleet names
def test_mass_with_eszett_and_mass_in_capitals_are_two_wells():
    """'Maß.csv' and 'MASS.csv' in one fleet folder stopped the whole fleet ("would both
    write OUT/Maß"): casefold turns ß into ss, which no file system does. Names are compared
    as case-insensitive file systems compare them (one character to one)."""
    from drillfric.io.results import check_distinct, name_key

    check_distinct([("Maß", "a"), ("MASS", "b")])
    assert name_key("Well") == name_key("WELL") and name_key("Maß") != name_key("MASS")
    with pytest.raises(InputError, match="would both write OUT/WELL and OUT/Well"):
        check_distinct([("Well", "a"), ("WELL", "b")])


def test_one_clashing_pair_does_not_stop_the_whole_fleet(tmp_path):
    """A true clash ('well.csv' and 'WELL.csv', one directory on a case-insensitive file
    system) fails the later well naming both; the other wells run."""
    import numpy as np
    from click.testing import CliRunner
    from drillfric.cli.main import cli

    wells = tmp_path / "wells"
    wells.mkdir()
    t = np.arange(0.0, 20.0, 0.1)
    for name in ("Maß", "MASS", "well", "WELL"):
        pd.DataFrame({"time_s": t, "surface_rpm": 0.0, "surface_torque_Nm": 0.0}).to_csv(
            wells / f"{name}.csv", index=False)
    out = tmp_path / "out"
    result = CliRunner().invoke(cli, ["-q", "fleet", str(wells), "--out", str(out),
                                      "--no-report", "--workers", "1"])
    assert result.exit_code == 1, result.output
    assert "would both write OUT/" in result.output and "WELL.csv" in result.output
    dirs = {p.name for p in out.iterdir() if p.is_dir()}
    assert {"Maß", "MASS"} <= dirs and len(dirs & {"well", "WELL"}) == 1


def test_two_wells_of_one_name_fail_and_the_fleet_carries_on(tmp_path):
    """'A.csv' and 'A.parquet' in one fleet folder stopped the whole fleet (exit 2, no well
    run; noticed after the eleventh attack). Both fail naming each other — neither is the
    well 'A' that manifest.json can record — and 'B' runs."""
    import json

    import numpy as np
    from click.testing import CliRunner
    from drillfric.cli.main import cli

    wells = tmp_path / "wells"
    wells.mkdir()
    t = np.arange(0.0, 20.0, 0.1)
    frame = pd.DataFrame({"time_s": t, "surface_rpm": 0.0, "surface_torque_Nm": 0.0})
    frame.to_csv(wells / "A.csv", index=False)
    frame.to_parquet(wells / "A.parquet")
    frame.to_csv(wells / "B.csv", index=False)
    out = tmp_path / "out"
    result = CliRunner().invoke(cli, ["-q", "fleet", str(wells), "--out", str(out),
                                      "--no-report", "--workers", "1"])
    assert result.exit_code == 1, result.output
    assert "would both write OUT/A" in result.output, result.output
    assert {p.name for p in out.iterdir() if p.is_dir()} == {"B"}
    manifest = json.loads((out / "manifest.json").read_text())["wells"]
    assert manifest["A"]["status"] == "failed" and "would both write" in manifest["A"]["message"]
    assert manifest["B"]["status"] != "failed"


# ---------------------------------------------------------------- F9 one Latin-1 byte
def test_a_utf8_log_with_one_latin1_byte_at_row_3000_is_read_as_the_docs_promise(tmp_path):
    """A UTF-8 log with an operator's note '60°C' in Latin-1 at row 3000: 'cannot parse as
    delimited text (UnicodeDecodeError) — fix: check that every row has the same number of
    fields'. docs/ingestion.md promises UTF-8 or Latin-1 text: the byte is read as Latin-1,
    one warning names the byte and the line."""
    import warnings

    from drillfric.io.delimited import TextWarning, open_delimited

    lines = ["TIME,RPM,TORQUE,Note"] + [f"{0.05 * k:.2f},60.5,12000,ok (beyond the sniff)"
                                        for k in range(3500)]
    raw = ("\n".join(lines[:3000]) + "\n").encode() + b"# operator note: temp 60\xb0C\n" + \
        ("\n".join(lines[3000:]) + "\n").encode() + b"174.95,60.5,12000,caf\xe9\n"
    path = tmp_path / "latin1mid.csv"
    path.write_bytes(raw)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        frame = pd.concat(open_delimited(path).chunks(1000))
    assert len(frame) == 3501 and frame["Note"].iloc[-1] == "café"
    said = [str(w.message) for w in caught if w.category is TextWarning]
    assert len(said) == 1 and "byte 0xB0 is not UTF-8" in said[0] and "60°C" in said[0]


def test_a_utf8_log_with_a_latin1_byte_near_its_top_keeps_its_utf8_units(tmp_path):
    """A UTF-8 log (units row 'kN·m', 'µs') with one Latin-1 byte in an operator's note in
    its first 64 KiB was read wholly as Latin-1: 'kN·m' became 'kNÂ·m' (noticed after the
    eleventh attack). UTF-8 characters beside the stray byte make it a UTF-8 file: the
    units stay, the byte alone is read as Latin-1, with one warning."""
    import warnings

    from drillfric.io.delimited import TextWarning, open_delimited, sniff_csv

    raw = ("TIME,RPM,TORQUE,Note\ns,rpm,kN·m,\n".encode()
           + b"0.00,60.5,12.0,temp 60\xb0C\n"
           + "".join(f"{0.05 * k:.2f},60.5,12.0,ok µ\n" for k in range(1, 50)).encode())
    path = tmp_path / "utf8_with_latin1.csv"
    path.write_bytes(raw)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        layout = sniff_csv(path)
        frame = pd.concat(open_delimited(path).chunks(1000))
    assert layout.encoding == "utf-8-sig" and layout.units["TORQUE"] == "kN·m"
    assert frame["Note"].iloc[0] == "temp 60°C" and frame["Note"].iloc[1] == "ok µ"
    said = [str(w.message) for w in caught if w.category is TextWarning]
    assert len(said) == 1 and "byte 0xB0 is not UTF-8" in said[0]


def test_a_latin1_log_stays_latin1(tmp_path):
    """A wholly Latin-1 log (no UTF-8 character anywhere) is read as Latin-1, unchanged."""
    from drillfric.io.delimited import sniff_csv

    path = tmp_path / "latin1.csv"
    path.write_bytes(b"TIME,RPM,TORQUE,Note\ns,rpm,kN\xb7m,\n0.0,60.5,12.0,caf\xe9\n"
                     b"0.1,60.5,12.0,ok\n")
    layout = sniff_csv(path)
    assert layout.encoding == "latin-1" and layout.units["TORQUE"] == "kN·m"


# ---------------------------------------------------------------- F11 ISO 8601 corners
def _iso_log(tmp_path, stamps):
    data = tmp_path / "iso.csv"
    pd.DataFrame({"TIMESTAMP": stamps, "surface_rpm": 60.0,
                  "surface_torque_Nm": 9e3}).to_csv(data, index=False)
    return data


def test_iso_8601_comma_fraction_is_read():
    """'2024-05-01T12:00:00,05Z' (ISO 8601's decimal comma) was refused as no ISO 8601."""
    import numpy as np

    from drillfric.io.timebase import TimeTracker

    stamps = [f"2024-05-01T12:00:{k // 20:02d},{5 * (k % 20):02d}Z" for k in range(60)]
    tracker = TimeTracker(1.0, file="iso.csv", column="TIMESTAMP")
    seconds, _ = tracker._seconds(pd.Series(stamps))
    assert np.allclose(seconds, np.arange(60) * 0.05)


def test_iso_8601_leap_second_is_refused_saying_why(tmp_path):
    """'2016-12-31T23:59:60.000000Z' was 'cannot read … as an ISO 8601 timestamp'. It is
    valid ISO 8601; the line says it is a leap second, which the time axis cannot hold."""
    from click.testing import CliRunner
    from drillfric.cli.main import cli

    stamps = [f"2016-12-31T23:59:{s:02d}.{ms:03d}Z" for s in (58, 59, 60) for ms in (0, 500)]
    result = CliRunner().invoke(cli, ["inspect", str(_iso_log(tmp_path, stamps))])
    assert result.exit_code == 2, result.output
    assert "'2016-12-31T23:59:60.000Z' at data row 5 is a leap second" in result.output


# ---------------------------------------------------------------- F19 a word after the unit
@pytest.mark.parametrize("text, word", [("8200 ft MD", "MD"), ("2300 m RKB", "RKB"),
                                        ("5 1/2 in TVD", "TVD")])
def test_a_depth_reference_after_the_unit_is_named_as_an_unknown_word(text, word):
    """bit_depth_m = "8200 ft MD": 'is of dimension [length] ** 2 * [time] * [current], not
    a length' (pint read MD as mega-darcies). The word after the unit is named."""
    with pytest.raises(ConfigError, match=f"has an unknown word '{word}' after its unit"):
        quantity_value(text, "m", what="key 'well.bit_depth_m'", file="w.toml")
    assert quantity_value("25 kft lbf", "N*m", what="key 'x'") == pytest.approx(33895.44,
                                                                                rel=1e-6)


# ---------------------------------------------------------------- F15 qualifier as a unit
@pytest.mark.parametrize("columns, key, chosen", [
    (["TIME [s]", "RPM (setpoint)", "SRPM [rpm]", "TORQUE [kN.m]"], "surface_rpm",
     "SRPM [rpm]"),
    (["TIME [s]", "SRPM [rpm]", "TORQUE (max)", "STOR [kN.m]"], "surface_torque",
     "STOR [kN.m]"),
])
def test_a_qualifier_in_parentheses_gives_way_to_a_column_with_a_real_unit(columns, key,
                                                                           chosen):
    """'RPM (setpoint)' beside 'SRPM [rpm]': "unknown unit 'setpoint'" refused the log
    (likewise 'TORQUE (max)' beside 'STOR [kN.m]'). The column whose unit is one is taken."""
    from drillfric.io.channels import map_channels

    assert map_channels(columns, {}, {}, file="w.csv")[key].column == chosen


def test_a_lone_column_with_a_qualifier_is_named_and_can_be_given_its_unit():
    from drillfric.io.channels import map_channels

    columns = ["TIME [s]", "RPM [rpm]", "TORQUE (max)"]
    with pytest.raises(InputError, match="unknown unit 'max' in its name: no torque unit"):
        map_channels(columns, {}, {}, file="w.csv")
    given = {"surface_torque": {"column": "TORQUE (max)", "unit": "kN.m"}}
    assert map_channels(columns, {}, given, file="w.csv")["surface_torque"].factor == 1e3


# ---------------------------------------------------------------- F16 HDF5 shapes, complex
def _h5(path, rpm, torque, notes=True):
    import h5py
    import numpy as np

    with h5py.File(path, "w") as h5:
        group = h5.create_group("surface")
        group["time_s"] = np.arange(100) * 0.05
        group["surface_rpm"] = rpm
        group["surface_torque_Nm"] = torque
        if notes:
            group["notes"] = np.zeros((100, 3))
    return path


def test_hdf5_n_by_1_dataset_is_a_column_and_a_complex_one_is_named(tmp_path):
    """An (N,1) surface_rpm was left out in silence ('required channel surface_rpm not
    found'); a complex torque cast to real with numpy's ComplexWarning. The (N,1) dataset
    is read squeezed (a dataset of another shape is named in a warning); the complex one is
    one line naming it."""
    import warnings

    import numpy as np

    from drillfric.io.hdf5 import Hdf5Warning, open_hdf5

    path = _h5(tmp_path / "twod.h5", np.full((100, 1), 60.0), np.full(100, 9e3))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        source = open_hdf5(path, "surface")
    frame = pd.concat(source.chunks(1000))
    assert frame["surface_rpm"].tolist() == [60.0] * 100 and "notes" not in frame
    said = [str(w.message) for w in caught if w.category is Hdf5Warning]
    assert len(said) == 1 and "'/surface/notes' has shape (100, 3)" in said[0]
    path = _h5(tmp_path / "complex.h5", np.full(100, 60.0), np.full(100, 9e3 + 1j), False)
    with pytest.raises(InputError, match="'/surface/surface_torque_Nm' holds complex"):
        open_hdf5(path, "surface")


def test_wits0_live_restarted_after_a_date_that_did_not_roll_over_continues_the_day():
    """Restarted after such a midnight, the recording's last line (2024-12-02 00:04:59)
    follows frames still dated 2024-12-01: each one 'before the previous', all dropped."""
    from datetime import UTC, datetime

    from drillfric.live.wits0_receiver import FrameClock

    last = datetime(2024, 12, 2, 0, 4, 59, tzinfo=UTC).timestamp()
    clock = FrameClock(None, last)
    stamp, previous = clock.rolled(datetime(2024, 12, 1, 0, 5, 0))
    assert stamp == datetime(2024, 12, 2, 0, 5, 0) and previous is not None
    assert clock.time_s(stamp, 0.0, last) == last + 1.0
    assert clock.rolled(datetime(2024, 12, 1, 0, 5, 1)) == (datetime(2024, 12, 2, 0, 5, 1), None)
    fresh = FrameClock(None, datetime(2024, 12, 1, 12, 0, 0, tzinfo=UTC).timestamp())
    assert fresh.rolled(datetime(2024, 12, 1, 12, 0, 1)) == (datetime(2024, 12, 1, 12, 0, 1),
                                                            None)
