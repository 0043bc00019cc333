"""Excel workbooks through open_source (drillfric.io.excel), built with openpyxl."""

from __future__ import annotations

import datetime as dt
import zipfile

import numpy as np
import pandas as pd
import pytest

from drillfric.errors import InputError
from drillfric.io.readers import open_source

openpyxl = pytest.importorskip("openpyxl")

START = dt.datetime(2024, 5, 1, 23, 59, 58)


def _book(path, sheets: dict[str, list[list]]) -> None:
    book = openpyxl.Workbook()
    book.remove(book.active)
    for name, rows in sheets.items():
        sheet = book.create_sheet(name)
        for row in rows:
            sheet.append(row)
    book.save(path)


def _log_rows(n: int = 5) -> list[list]:
    return [["Rig log export"], [],  # a title row and a blank row above the table
            ["Time", "SRPM", "Torque", "Hookload"], [None, "rpm", "kN.m", "klbf"]] + [
        [START + dt.timedelta(seconds=i), 60.0 + i, 10.0 + 0.5 * i, 200 + i] for i in range(n)]


def _read(path, chunk_rows: int = 2) -> pd.DataFrame:
    return pd.concat(list(open_source(path).chunks(chunk_rows)), ignore_index=True)


def test_header_units_row_and_date_cells_round_trip(tmp_path):
    path = tmp_path / "log.xlsx"
    _book(path, {"Sheet1": _log_rows()})
    source = open_source(path)
    assert source.columns == ["Time", "SRPM", "Torque", "Hookload"]
    assert {c: source.units.get(c) for c in source.columns} == {
        "Time": None, "SRPM": "rpm", "Torque": "kN.m", "Hookload": "klbf"}
    assert source.units[("source", "Torque")] == "units row" and source.rows == 5
    frame = _read(path)
    expected = pd.date_range(START, periods=5, freq="1s")  # across midnight, absolute
    assert frame["Time"].tolist() == expected.tolist()
    assert frame["Torque"].tolist() == [10.0, 10.5, 11.0, 11.5, 12.0]


def test_the_sheet_named_like_the_log_is_read(tmp_path):
    path = tmp_path / "book.xlsx"
    _book(path, {"Notes": [["well", "A-12"], ["rig", "X"]], "Surface data": _log_rows(3)})
    assert open_source(path).columns[0] == "Time" and len(_read(path)) == 3


def test_empty_cells_are_missing_and_durations_are_seconds(tmp_path):
    rows = [["ETIM", "RPM", "TORQUE"], ["s", "rpm", "kN.m"],
            [dt.timedelta(seconds=0), 60, None], [dt.timedelta(seconds=1.5), None, 3]]
    _book(tmp_path / "d.xlsx", {"Sheet": rows})
    frame = _read(tmp_path / "d.xlsx")
    assert frame["ETIM"].tolist() == [0.0, 1.5]
    assert np.isnan(frame["TORQUE"].iloc[0]) and np.isnan(frame["RPM"].iloc[1])


def test_headerless_sheet_has_numbered_columns(tmp_path):
    _book(tmp_path / "h.xlsx", {"Sheet": [[0, 60, 10], [1, 61, 11]]})
    source = open_source(tmp_path / "h.xlsx")
    assert source.columns == ["0", "1", "2"] and source.units == {}
    assert _read(tmp_path / "h.xlsx")["1"].tolist() == [60.0, 61.0]


def test_chunks_cover_every_row_once(tmp_path):
    _book(tmp_path / "c.xlsx", {"Sheet": _log_rows(7)})
    sizes = [len(c) for c in open_source(tmp_path / "c.xlsx").chunks(3)]
    assert sizes == [3, 3, 1]


@pytest.mark.parametrize(("build", "problem"), [
    (lambda p: p.write_text("TIME,RPM\n0,1\n"), "not a readable Excel workbook"),
    (lambda p: _book(p, {"Sheet": [["only one cell"]]}), "holds no table"),
    (lambda p: _book(p, {"Sheet": [["A", "A"], [1, 2]]}), "duplicate column names"),
])
def test_bad_workbooks_are_one_line_input_errors(tmp_path, build, problem):
    path = tmp_path / "bad.xlsx"
    build(path)
    with pytest.raises(InputError, match=problem) as info:
        open_source(path)
    assert "\n" not in str(info.value) and str(path) in str(info.value)


def test_zip_bomb_is_refused_before_unpacking(tmp_path):
    """A member of 64 MB of zeros deflates ~1000×: refused from the zip directory alone."""
    path = tmp_path / "bomb.xlsx"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("xl/worksheets/sheet1.xml", bytes(64 * 1024 * 1024))
    assert path.stat().st_size < 1024 * 1024
    with pytest.raises(InputError, match="possible zip bomb"):
        open_source(path)
