"""Hostile files, round three (issue 20, the independent attack): inputs that broke main
after the round-two fixes, each through the CLI with the strict checks of
:func:`tests.test_hostile_files._strict_check` (exit code, one error line naming the file
and the fix, no traceback, nothing written outside ``--out``, nothing unprintable, within
30 s). Cases are named after the attack (lasio's practice).
"""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pandas as pd
import pytest

from tests.test_hostile_files import _strict_check
from tests.test_hostile_inputs import Case, _config, _log
from tests.test_hostile_round_two import xlsx_cell_at_xfd1048576


def _log_with(path, *, header=None, units=None):
    """The small rotating log of :func:`_log`, its torque column renamed ``header`` and/or
    a units row ``units`` under the header."""
    _log(path)
    lines = path.read_text(encoding="utf-8").splitlines()
    if header is not None:
        lines[0] = lines[0].replace("surface_torque_Nm", header)
    if units is not None:
        lines.insert(1, ",".join(units))
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    _config(path.with_suffix(".toml"))
    return path


# --------------------------------------------------------------------------- units (pint)
def case_unit_power_tower_in_a_column_name(root):
    """pint evaluates numbers in a unit: 'N*m*9**9**9' is an exact integer of 370 million
    digits — inspect and run hung for ever."""
    path = _log_with(root / "w.csv", header="Torque [N*m*9**9**9]")
    return [Case([cmd, path, *extra], (2,), ("unknown unit",))
            for cmd, extra in (("inspect", []), ("run", ["--out", "out"]))]


def case_unit_power_tower_in_the_config_channels(root):
    path = _log(root / "w.csv")
    _config(path.with_suffix(".toml"), '[channels]\nsurface_torque = { unit = "N*m^9^9^9" }\n')
    return [Case(["run", path, "--out", "out"], (2,), ("unknown unit",))]


def case_unit_power_tower_in_a_survey_header(root):
    path = _log(root / "w.csv")
    _config(path.with_suffix(".toml"))
    (root / "w.survey.csv").write_text("md [m*9**9**9],inc_deg,azi_deg\n0,0,0\n1000,10,20\n",
                                       encoding="utf-8")
    return [Case(["inspect", path], (2,), ("unknown unit",))]


def case_unit_dividing_by_zero_in_a_units_row(root):
    """'N*m/0' in a units row was "internal error: ZeroDivisionError"."""
    path = _log_with(root / "w.csv", units=("s", "rpm", "N*m/0"))
    return [Case(["inspect", path], (2,), ("unknown unit 'N*m/0'",))]


def case_config_quantity_overflowing_the_exact_conversion(root):
    """'10 ppg*9**9**9' was "internal error: Overflow" in the exact decimal conversion."""
    path = _log(root / "w.csv")
    _config(path.with_suffix(".toml"), '[fluid]\nmud_density_kg_m3 = "10 ppg*9**9**9"\n')
    return [Case(["run", path, "--out", "out"], (2,), ("mud_density_kg_m3",))]


# --------------------------------------------------------------------------- TOML, manifests
def case_toml_arrays_nested_100000_deep(root):
    """tomllib recurses per nesting level: "internal error: RecursionError"."""
    path = _log(root / "w.csv")
    path.with_suffix(".toml").write_text("x = " + "[" * 100_000 + "]" * 100_000 + "\n",
                                         encoding="utf-8")
    return [Case([cmd, path, *extra], (2,), ("nested too deep",))
            for cmd, extra in (("inspect", []), ("run", ["--out", "out"]))]


def case_manifest_json_nested_100000_deep(root):
    (root / "m.json").write_text("[" * 100_000 + "]" * 100_000, encoding="utf-8")
    return [Case(["fleet", root / "m.json", "--out", "out"], (2,), ("nested too deep",))]


def case_manifest_path_with_a_nul_byte(root):
    """A NUL in a manifest path was "internal error: ValueError: embedded null byte"."""
    _log(root / "w.csv")
    (root / "m.json").write_text(json.dumps([{"data": "w.csv\x00/../../etc/passwd"}]),
                                 encoding="utf-8")
    return [Case(["fleet", root / "m.json", "--out", "out"], (2,), ("NUL",))]


# --------------------------------------------------------------------------- time, columns
def case_timestamps_in_the_year_0001(root):
    """A clock never set (0001-01-01) parsed at second resolution and overflowed the
    nanosecond arithmetic: "internal error: OutOfBoundsDatetime"."""
    stamps = pd.date_range("2024-01-01", periods=400, freq="100ms").astype(str)
    pd.DataFrame({"time": stamps.str.replace("2024", "0001"), "surface_rpm": 60.0,
                  "surface_torque_Nm": 8000.0}).to_csv(root / "w.csv", index=False)
    _config(root / "w.toml")
    return [Case(["inspect", root / "w.csv"], (2,), ("outside the years 1677–2262",))]


def case_csv_with_100000_columns(root):
    """Each column was ranked against every mnemonic with a regex each time: > 40 s."""
    path = root / "w.csv"
    extra = 100_000
    with path.open("w", encoding="utf-8") as fh:
        fh.write("time_s,surface_rpm,surface_torque_Nm" + "".join(
            f",c{i}" for i in range(extra)) + "\n")
        for t in np.arange(0.0, 4.0, 0.1):
            fh.write(f"{t:.1f},60,8000" + ",1" * extra + "\n")
    _config(root / "w.toml")
    return [Case(["inspect", path], (0,), ("rows       40",))]


# --------------------------------------------------------------------------- Excel, up front
def _xlsx_with_sheet(path, edit):
    """The round-two workbook with its sheet XML changed by ``edit``."""
    bomb = xlsx_cell_at_xfd1048576(path.with_name("template.xlsx"))
    with zipfile.ZipFile(bomb) as src, zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as dst:
        for info in src.infolist():
            data = src.read(info.filename)
            if info.filename.endswith("sheet1.xml"):
                data = edit(data.decode()).encode()
            dst.writestr(info.filename, data)
    bomb.unlink()
    return path


_FAR_ROW = '<row r="1048576"><c r="XFD1048576"><v>2</v></c></row>'


def case_xlsx_dimension_declaring_the_whole_sheet(root):
    """<dimension ref="A1:XFD1048576"> on a two-cell sheet: refused from the declaration,
    in the parent, before any reader child starts."""
    path = _xlsx_with_sheet(root / "dim.xlsx", lambda t: t.replace(
        "<sheetData>", '<dimension ref="A1:XFD1048576"/><sheetData>').replace(
        _FAR_ROW, '<row r="2"><c r="B2"><v>2</v></c></row>'))
    return [Case(["inspect", path], (2,), ("as its <dimension> declares",))]


def case_xlsx_cells_without_references_far_down(root):
    """Cells without an r attribute follow each other: 40 of them on row 1 048 576 span
    42 million cells."""
    path = _xlsx_with_sheet(root / "noref.xlsx", lambda t: t.replace(
        _FAR_ROW, '<row r="1048576">' + "<c><v>1</v></c>" * 40 + "</row>"))
    return [Case(["run", path, "--out", "out"], (2,), ("rows 1–1,048,576, columns A–AN",))]


# --------------------------------------------------------------------------- reads outside
def _secret_folder(root):
    """Another folder beside the well's, holding a file that is not the user's to read."""
    secret = root / "secret"
    secret.mkdir()
    (secret / "s.csv").write_text("md_m,inc_deg,azi_deg\n0,0,0\n# API_KEY=sk-live-0123456789\n",
                                  encoding="utf-8")
    _log(secret / "other_well.csv")
    return secret


def case_sidecar_symlink_leading_out_of_the_wells_folder(root):
    """A NAME.survey.csv beside the data that is a link to a file elsewhere was read as the
    well's survey (found for the user, never named by them)."""
    secret, well = _secret_folder(root), root / "well"
    path = _log_with(well / "w.csv")
    (well / "w.survey.csv").symlink_to(secret / "s.csv")
    return [Case(["run", path, "--out", "out"], (2,), ("leads outside well/",))]


def case_well_toml_naming_data_outside_its_folder(root):
    """[well] data = "../secret/other_well.csv" read another well's data as this one's."""
    _secret_folder(root)
    well = root / "well"
    well.mkdir()
    (well / "well.toml").write_text('[well]\ndata = "../secret/other_well.csv"\n',
                                    encoding="utf-8")
    return [Case(["run", well, "--out", "out"], (2,), ("leads outside well/",))]


def case_config_survey_file_leading_out_of_its_folder(root):
    """A sidecar configuration's [survey] file = "../secret/s.csv" was read as the survey."""
    _secret_folder(root)
    path = _log(root / "well" / "w.csv")
    _config(path.with_suffix(".toml"), '[survey]\nfile = "../secret/s.csv"\n')
    return [Case(["run", path, "--out", "out"], (2,), ("leads outside well/",))]


CASES = {name[5:]: fn for name, fn in sorted(globals().items()) if name.startswith("case_")}


@pytest.mark.parametrize("name", sorted(CASES))
def test_hostile_file_round_three(name, tmp_path, capsys):
    root = tmp_path / "sandbox"
    root.mkdir()
    for case in CASES[name](root):
        _strict_check(case, root, capsys)
