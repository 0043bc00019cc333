"""Regression tests of the leftovers of the tenth hostile-input attack (issue 30, "Hostile
and ordinary inputs, round four"): what the attack found silent or unclear after the first
round of fixes. Each test is named after what the attack did."""

from __future__ import annotations

import json
import os
from datetime import datetime

import numpy as np
import pandas as pd
import pytest

from drillfric.config import config_from_dict
from drillfric.errors import ConfigError, InputError
from drillfric.io.well import open_well
from tests.io.io_frames import surface_frame

TOML = '[well]\nname = "w"\n'


def _csv(path, frame: pd.DataFrame):
    frame.to_csv(path, index=False)
    return path


# --------------------------------------------------------------- 1. a dead speed column
@pytest.mark.parametrize("dead, live", [("Rotary Speed", "Top Drive Speed"),
                                        ("RPM", "TDRPM")])
def test_a_dead_rotary_speed_column_gives_way_to_the_live_top_drive_speed(tmp_path, dead,
                                                                          live):
    """The mnemonic table preferred a rotary-table speed of all zeros over the live
    top-drive speed: nothing rotated, nothing was estimated, exit 0. A channel whose chosen
    column holds one value throughout is read from a candidate that changes, and the run
    says so naming both columns."""
    frame = surface_frame()
    frame.insert(1, live, frame.pop("surface_rpm"))
    frame.insert(2, dead, 0.0)
    well = open_well(_csv(tmp_path / "w.csv", frame))
    assert well.mappings["surface_rpm"].column == live
    note = next(n for n in well.assumed if "mnemonic table prefers" in n)
    assert f"'{live}'" in note and f"'{dead}'" in note and "the one value 0" in note


def test_a_speed_column_the_configuration_names_is_never_switched(tmp_path):
    frame = surface_frame()
    frame.insert(1, "TDRPM", frame.pop("surface_rpm"))
    frame.insert(2, "RPM", 0.0)
    _csv(tmp_path / "w.csv", frame)
    (tmp_path / "w.toml").write_text(TOML + '[channels]\nsurface_rpm = { column = "RPM" }\n')
    well = open_well(tmp_path / "w.csv")
    assert well.mappings["surface_rpm"].column == "RPM"
    assert not any("mnemonic table" in n for n in well.assumed)


def test_two_live_speed_columns_keep_the_mnemonic_tables_choice(tmp_path):
    frame = surface_frame()
    frame.insert(1, "TDRPM", frame["surface_rpm"] + 1.0)
    frame.insert(2, "RPM", frame.pop("surface_rpm"))
    well = open_well(_csv(tmp_path / "w.csv", frame))
    assert well.mappings["surface_rpm"].column == "RPM"


# --------------------------------------------------------------- 2, 3. folder wells
def _folder(tmp_path, names, starts, survey: str | None = None):
    folder = tmp_path / "well"
    folder.mkdir()
    for name, start in zip(names, starts, strict=True):
        part = surface_frame(rows=50)
        part["time_s"] += start
        _csv(folder / name, part)
    toml = '[well]\nname = "w"\ndata = "."\n'
    if survey is not None:
        pd.DataFrame({"md_m": [0.0, 1000.0, 2600.0], "inc_deg": [0.0, 10.0, 20.0],
                      "azi_deg": [0.0, 0.0, 0.0]}).to_csv(folder / survey, index=False)
        toml += f'[survey]\nfile = "{survey}"\n'
    (folder / "well.toml").write_text(toml)
    return folder


def test_unpadded_hourly_parts_p9_p10_p11_are_read_in_number_order(tmp_path):
    """p9, p10, p11 were read as p10, p11, p9 and refused as overlapping, with a fix that
    said to delete rows. Numbers in part names sort by value."""
    folder = _folder(tmp_path, ["p10.csv", "p9.csv", "p11.csv"], [10.0, 0.0, 20.0])
    well = open_well(folder)
    assert [p.name for p in well.files.parts] == ["p9.csv", "p10.csv", "p11.csv"]
    assert len(well.load().surface) == 150


def test_overlapping_parts_are_told_a_fix_that_changes_no_file(tmp_path):
    folder = _folder(tmp_path, ["a.csv", "b.csv"], [10.0, 0.0])
    with pytest.raises(InputError, match="the two parts of the log overlap") as err:
        open_well(folder).load()
    assert "the files are never changed" in err.value.fix
    assert "remove the rows" not in err.value.fix


def test_a_survey_named_by_well_toml_is_not_a_part_of_the_log(tmp_path):
    """A folder well's survey, ``deviation.csv`` (no ``.survey.`` in its name), named by
    well.toml's [survey] file, was read as a part of the log ("columns differ")."""
    folder = _folder(tmp_path, ["p1.csv", "p2.csv"], [0.0, 10.0], survey="deviation.csv")
    well = open_well(folder)
    assert [p.name for p in well.files.parts] == ["p1.csv", "p2.csv"]
    assert well.files.survey.name == "deviation.csv"
    assert well.survey is not None


def test_a_survey_given_on_the_command_line_inside_the_folder_is_not_a_part(tmp_path):
    folder = _folder(tmp_path, ["p1.csv", "p2.csv"], [0.0, 10.0], survey="deviation.csv")
    (folder / "well.toml").write_text('[well]\nname = "w"\ndata = "."\n')
    well = open_well(folder, survey=folder / "deviation.csv")
    assert [p.name for p in well.files.parts] == ["p1.csv", "p2.csv"]


# --------------------------------------------------------------- 4. a FIFO in a fleet folder
@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_a_fifo_in_a_fleet_folder_is_named_as_not_a_regular_file(tmp_path):
    """A FIFO among the wells gave "None: cannot read (None)". The well fails in one line
    naming the file and the problem, without opening it (no hang), and the fleet goes on."""
    from drillfric.fleet.run import _file_stamp, _os_line

    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    with pytest.raises(InputError, match="pipe.csv: input file is not a regular file"):
        _file_stamp(fifo, {})
    assert _os_line(FileNotFoundError("gone"), fifo) == f"{fifo}: cannot read (gone)"
    assert "None" not in _os_line(OSError(), fifo)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_a_fleet_with_a_fifo_runs_its_other_wells(tmp_path):
    from drillfric.fleet.discovery import discover
    from drillfric.fleet.run import run_many

    wells = tmp_path / "wells"
    wells.mkdir()
    os.mkfifo(wells / "pipe.csv")
    _csv(wells / "ok.csv", surface_frame(rows=200))
    result = run_many(discover(wells), tmp_path / "out", workers=1, report=False)
    by_name = {w.well: w for w in result.wells}
    assert by_name["ok"].status == "ok"
    assert by_name["pipe"].status == "failed"
    assert "not a regular file" in by_name["pipe"].message
    assert "None" not in by_name["pipe"].message


# --------------------------------------------------------------- 5. Excel
def _workbook(path, build):
    openpyxl = pytest.importorskip("openpyxl")
    wb = openpyxl.Workbook()
    build(wb)
    wb.save(path)
    return path


def test_excel_formula_cells_without_values_are_named_with_their_sheet(tmp_path):
    """A time column of formulas saved by a program that does not calculate read empty:
    "no data rows". One line names the sheet, the cells and how to store the values."""
    from drillfric.io.excel import check_workbook

    def build(wb):
        ws = wb.active
        ws.title = "Surface log"
        ws.append(["time_s", "surface_rpm", "surface_torque_Nm"])
        for _ in range(5):
            ws.append(["=(ROW()-2)*0.2", 60.0, 1e4])

    path = _workbook(tmp_path / "w.xlsx", build)
    with pytest.raises(InputError, match="sheet 'Surface log' holds 5 formula cells without "
                                         r"their computed values \(the first at A2\)") as err:
        check_workbook(path)
    assert "save it" in err.value.fix


def test_excel_survey_sheet_named_data_is_not_taken_for_the_log(tmp_path):
    """A workbook with "Survey data" before "Surface log" was read from its survey sheet (its
    name has "data"): "surface_rpm not found; columns found: MD, INC, AZI"."""
    from drillfric.io.excel import open_excel

    def build(wb):
        ws = wb.active
        ws.title = "Survey data"
        ws.append(["MD", "INC", "AZI"])
        ws.append([0, 0, 0])
        ws2 = wb.create_sheet("Sheet2")
        ws2.append(["time_s", "surface_rpm", "surface_torque_Nm"])
        for i in range(5):
            ws2.append([0.2 * i, 60.0, 1e4])

    source = open_excel(_workbook(tmp_path / "w.xlsx", build))
    assert source.columns == ["time_s", "surface_rpm", "surface_torque_Nm"]
    assert source.where == "sheet 'Sheet2'"


def test_excel_without_a_log_sheet_names_the_sheet_it_read(tmp_path):
    def build(wb):
        ws = wb.active
        ws.title = "Survey data"
        ws.append(["MD", "INC", "AZI"])
        ws.append([0, 0, 0])
        wb.create_sheet("Sheet9").append(["MD", "X", "Y"])

    with pytest.raises(InputError, match=r"w.xlsx \(sheet 'Sheet9'\): required channel "
                                         "surface_rpm not found"):
        open_well(_workbook(tmp_path / "w.xlsx", build))


def test_excel_merged_title_row_above_the_header_is_skipped(tmp_path):
    from drillfric.io.excel import open_excel

    def build(wb):
        ws = wb.active
        ws.append(["Rig X export", "", "Torque & drag", "", ""])
        ws.merge_cells("C1:E1")
        ws.append(["time_s", "surface_rpm", "surface_torque_Nm", "hookload_N", "bit_depth_m"])
        for i in range(5):
            ws.append([0.2 * i, 60.0, 1e4, 1e6, 2500.0])

    source = open_excel(_workbook(tmp_path / "w.xlsx", build))
    assert source.columns[:3] == ["time_s", "surface_rpm", "surface_torque_Nm"]
    assert source.rows == 5


# --------------------------------------------------------------- 6. narrow Parquet floats
def test_float32_parquet_time_too_coarse_for_its_samples_is_one_clear_line(tmp_path):
    """A float32 time at 7×10⁵ s (0.0625-s steps) under 5-Hz samples was "840 timestamps
    repeated with other values" blaming the recorder; at 2×10⁶ s every one."""
    frame = surface_frame()
    frame["time_s"] = (frame["time_s"] + 7e5).astype(np.float32)
    frame.to_parquet(tmp_path / "w.parquet")
    with pytest.raises(InputError, match=r"time column 'time_s' is stored as float32 \(single "
                                         r"precision\): at 7.001e\+05 s it resolves only 0.0625 s"):
        open_well(tmp_path / "w.parquet")


def test_float32_and_float16_parquet_values_are_read_widened(tmp_path):
    frame = surface_frame()
    frame["time_s"] = frame["time_s"].astype(np.float32)
    frame["surface_torque_Nm"] = frame["surface_torque_Nm"].astype(np.float32)
    with np.errstate(over="ignore"):
        frame["hookload_N"] = frame["hookload_N"].astype(np.float16)  # 1.2e6 N: infinite
    frame.to_parquet(tmp_path / "w.parquet")
    well = open_well(tmp_path / "w.parquet")
    data = well.load().surface
    np.testing.assert_allclose(data["time_s"], surface_frame()["time_s"], atol=1e-4)
    assert data["surface_torque_Nm"].notna().all()
    note = next(n for n in well.assumed if "float16" in n)
    assert "'hookload_N'" in note and "overflowed to infinity" in note


# --------------------------------------------------------------- 7. --starts
def test_an_invalid_starts_option_is_blamed_on_the_option_not_the_toml():
    """``--starts 9:0.1`` was refused as "w.toml: observer.mu_max = 1.5 is below …"."""
    with pytest.raises(ConfigError) as err:
        config_from_dict({"observer": {"mu_max": 1.5}}, file="w.toml",
                         overrides={"observer.starts": [[9.0, 0.1]]})
    assert err.value.file == "command line --starts (observer.starts)"
    assert "correct --starts" in err.value.fix
    with pytest.raises(ConfigError) as err:  # the file's own fault still names the file
        config_from_dict({"observer": {"mu_max": 1.5, "starts": [[9.0, 0.1]]}}, file="w.toml")
    assert err.value.file == "w.toml"


# --------------------------------------------------------------- 8. fleet manifest
@pytest.mark.parametrize("entry, message", [
    ({"well": "A", "type": "depth", "data": "a.csv"}, "has column 'type', which drillfric "
                                                      "does not read"),
    ({"well": ["x"], "data": "a.csv"}, "entry 1: well is a list, not a text"),
    ({"well": True, "data": "a.csv"}, "entry 1: well is a bool, not a text"),
    ({"well": "A", "data": "a.csv", "config": {"a": 1}}, "entry 1: config is a dict"),
])
def test_a_manifest_entry_declaring_what_drillfric_does_not_read_is_refused(tmp_path, entry,
                                                                            message):
    """A manifest's declared well type (and a well name given as a list, a dict, a bool)
    was ignored in silence: the well ran under its file stem as whatever its data were."""
    from drillfric.fleet.discovery import discover

    manifest = tmp_path / "wells.json"
    manifest.write_text(json.dumps([entry]))
    with pytest.raises(InputError, match=message):
        discover(manifest)


def test_a_manifest_csv_with_an_extra_column_is_refused_and_a_numeric_name_kept(tmp_path):
    from drillfric.fleet.discovery import discover

    (tmp_path / "wells.csv").write_text("well,data,type\nA,a.csv,depth\n")
    with pytest.raises(InputError, match="column 'type'"):
        discover(tmp_path / "wells.csv")
    (tmp_path / "wells.json").write_text(json.dumps([{"well": 5, "data": "a.csv"}]))
    assert discover(tmp_path / "wells.json")[0].name == "5"
    (tmp_path / "trailing.csv").write_text("well,data,\nA,a.csv,\n")  # a trailing comma
    assert discover(tmp_path / "trailing.csv")[0].name == "A"


# --------------------------------------------------------------- 9. hole above the bit
def test_hole_depth_above_the_bit_leaves_on_bottom_to_the_wob(tmp_path):
    """A hole-depth channel 20 m above the bit put every rotation on bottom (μ_k withheld,
    "only apparent friction", no word of the impossible depths). Where the hole reads above
    the bit the depths decide nothing: the WOB does, and the run warns once."""
    from drillfric.io.logcheck import LogCheck
    from drillfric.segmentation import RIG_STATES, classify

    frame = surface_frame()
    frame["hole_depth_m"] = frame["bit_depth_m"] - 20.0
    states = [RIG_STATES[s] for s in classify(frame, config_from_dict({}))]
    assert set(states) == {"rotating_off_bottom"}
    frame["wob_N"] = 50e3
    assert {RIG_STATES[s] for s in classify(frame, config_from_dict({}))} == {"rotating_on_bottom"}

    well = open_well(_csv(tmp_path / "w.csv", frame.drop(columns="wob_N")))
    check = LogCheck(well)
    check.feed(well.load().surface)
    note = check.hole_above_note()
    assert "reads above the bit depth" in note and "in 500 rows" in note
    assert "by up to 20 m" in note and "wrong or lagging" in note
    restored = LogCheck(well)
    restored.restore(check.state())
    assert restored.hole_above_note() == note


def test_hole_depth_a_little_above_the_bit_is_still_on_bottom():
    from drillfric.segmentation import RIG_STATES, classify

    frame = surface_frame()
    frame["hole_depth_m"] = frame["bit_depth_m"] - 0.2  # within on_bottom_m: a lag
    assert {RIG_STATES[s] for s in classify(frame, config_from_dict({}))} == {"rotating_on_bottom"}


# --------------------------------------------------------------- 10. WITS0
def test_wits0_underscore_and_other_python_only_numbers_are_not_readings():
    """``0118 1_0`` was read as 10 (Python's float accepts digit separators), ``nan`` and
    ``inf`` as numbers: a WITS value is an ASCII decimal."""
    from drillfric.io.wits0 import number

    assert [number(t) for t in ("12.5", "-3", "+.5", "1e3", "2.5E-01")] == \
        [12.5, -3.0, 0.5, 1000.0, 0.25]
    assert all(np.isnan(number(t)) for t in ("1_0", "nan", "inf", "Infinity", "0x10",
                                              "١٠", "1 0", "12.5\n"))


def test_wits0_item_repeated_in_one_frame_with_two_values_discards_the_frame():
    from drillfric.io.wits0 import Decoder

    decoder = Decoder()
    frames = decoder.feed(b"&&\r\n011810.0\r\n011899.0\r\n!!\r\n"
                          b"&&\r\n011812.0\r\n011812.0\r\n012060\r\n!!\r\n")
    assert frames == [{"0118": "12.0", "0120": "60"}]
    assert decoder.discarded == 1


def test_wits0_rejected_frames_items_never_reach_the_next_frame(tmp_path):
    """A frame refused for its clock (dated before the previous one) had already given its
    values to the row: the next frame, omitting that item, recorded the refused value."""
    from drillfric.io.wits0 import Row, encode, item_map
    from drillfric.live.wits0_receiver import Receiver, Recording, parse_address, setup

    address = parse_address("wits0://127.0.0.1:5000")
    warned: list[str] = []
    receiver = Receiver(address, setup(address, None, "t"),
                        Recording(tmp_path / "t.wits0.csv", Row(item_map({})).names, False),
                        warn=warned.append)
    items = item_map({})
    t0 = datetime(2026, 12, 7, 10, 0, 0)
    receiver._take(encode({"surface_rpm": 60.0, "surface_torque_Nm": 10e3}, items, t0), 1.0)
    refused = encode({"surface_torque_Nm": 99e3}, items, t0.replace(minute=0, second=0,
                                                                   hour=9))
    receiver._take(refused, 2.0)
    receiver._take(encode({"surface_rpm": 61.0}, items, t0.replace(second=2)), 3.0)
    receiver.recording.close()
    got = pd.read_csv(tmp_path / "t.wits0.csv")
    assert got["surface_torque_Nm"].tolist() == [10e3, 10e3]
    assert any("before the previous frame" in w for w in warned)


# --------------------------------------------------------------- 11. angle units
@pytest.mark.parametrize("unit", ["Grad", "Mrad", "krad", "kdeg"])
def test_grad_is_never_gigaradians_nor_silently_degrees(unit):
    """``INC (Grad)`` was read as gigaradians (pint: G = giga): inclination 1.7e11°."""
    from drillfric.units import conversion_factor

    with pytest.raises(InputError, match=f"unit '{unit}' reads as .*radians|degrees") as err:
        conversion_factor(unit, "angle")
    assert "'gon' for gradians" in err.value.fix


def test_gradians_and_prefixed_radians_are_angles_in_a_rotary_speed():
    """``gon/s`` and ``mrad/s`` were taken for cycles per time (2π too fast): pint names
    them ``grade`` and ``milliradian``, not in the table of angle names."""
    from drillfric.io.channels import BY_KEY, factor
    from drillfric.units import conversion_factor

    speed = BY_KEY["surface_rpm"]
    assert conversion_factor("grad", "angle") == pytest.approx(np.pi / 200)
    assert factor("gon/s", speed) == pytest.approx(60.0 / 400)
    assert factor("grad/s", speed) == pytest.approx(60.0 / 400)
    assert factor("mrad/s", speed) == pytest.approx(1e-3 * 60.0 / (2 * np.pi))


# --------------------------------------------------------------- 12. WITSML unit clash
def _witsml(path, curve_unit: str, list_unit: str):
    curves = [("TIME", "s"), ("RPM", "rpm"), ("TORQUE", curve_unit), ("BITDEP", "m")]
    info = "".join(f"<logCurveInfo uid='{m}'><mnemonic>{m}</mnemonic><unit>{u}</unit>"
                   "</logCurveInfo>" for m, u in curves)
    rows = "".join(f"<data>{0.2 * i},60,{10 + i % 2},2500</data>" for i in range(50))
    path.write_text(
        "<?xml version='1.0' encoding='UTF-8'?><logs xmlns='http://www.witsml.org/schemas/"
        "1series' version='1.4.1.1'><log uidWell='w' uidWellbore='wb' uid='l'><nameWell>w"
        "</nameWell><nameWellbore>w</nameWellbore><name>w</name><indexType>elapsed time"
        "</indexType><indexCurve>TIME</indexCurve>" + info + "<logData><mnemonicList>TIME,RPM,"
        f"TORQUE,BITDEP</mnemonicList><unitList>s,rpm,{list_unit},m</unitList>{rows}"
        "</logData></log></logs>")
    return path


def test_witsml_unitlist_and_logcurveinfo_stating_two_units_is_refused(tmp_path):
    """Verified: a WITSML 1.4.1.1 log whose logCurveInfo says kft·lbf and whose unitList says
    kN·m was read in the unitList's unit in silence (μ_k 0.203 for 0.28)."""
    path = _witsml(tmp_path / "w.xml", "kft.lbf", "kN.m")
    with pytest.raises(InputError, match="states two units for surface_torque_Nm .*its "
                                         "unitList says 'kN.m'; its logCurveInfo says "
                                         "'kft.lbf'"):
        open_well(path)
    (tmp_path / "w.toml").write_text(TOML + '[channels]\nsurface_torque = { unit = "kft.lbf" }\n')
    assert open_well(path).mappings["surface_torque"].unit == "kft.lbf"


def test_witsml_unitlist_and_logcurveinfo_in_one_unit_is_read(tmp_path):
    well = open_well(_witsml(tmp_path / "w.xml", "kN.m", "kN.m"))
    assert well.mappings["surface_torque"].unit == "kN.m"
    well = open_well(_witsml(tmp_path / "v.xml", "kN.m", ""))  # the unitList leaves it out
    assert well.mappings["surface_torque"].unit == "kN.m"

