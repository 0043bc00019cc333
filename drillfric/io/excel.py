"""Excel workbooks (``.xlsx``) read with python-calamine: one sheet as a raw source.

The sheet read is the first whose name says it holds the log (it contains ``surface``,
``log`` or ``data``, case-insensitive), else the first non-empty worksheet. Within it, the
layout is the one of a delimited text file:

- title rows above the table (rows with fewer than two filled cells) are skipped;
- the first row with two or more filled cells is the header, unless all its cells are
  numbers or dates (then the columns are ``0``, ``1``, … and need a ``[channels]`` mapping);
- the row under the header is a **units row** when its filled cells are all text that is
  not a number (``s``, ``rpm``, ``kN.m``), as in CSV files.

Cells keep their type: numbers stay numbers, date-time cells become absolute times
(``datetime64``, as written: Excel stores no time zone), durations (``[h]:mm:ss``) and
times of day become seconds; empty cells are missing values.

A workbook is a zip archive: one that declares more than :data:`MAX_UNPACKED_BYTES`
uncompressed, or a member packed more than :data:`MAX_RATIO` times, is refused before
being opened (a zip bomb). calamine parses a sheet whole; rows are then handed on in
chunks. Every failure is an InputError naming the file.
"""

from __future__ import annotations

import datetime as dt
import re
import zipfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from drillfric.errors import InputError
from drillfric.io.source import RawSource

#: Largest uncompressed size a workbook may declare [bytes] (Excel's own limit of
#: 1 048 576 rows of a rig log's few dozen columns stays well below).
MAX_UNPACKED_BYTES = 4 * 1024**3
#: Largest compression ratio of a member (spreadsheet XML packs 5–50×; zip bombs 1000×).
MAX_RATIO = 200
#: Words in a sheet name that mark the sheet holding the log.
SHEET_WORDS = ("surface", "log", "data")
_HEAD_ROWS = 50
_NUMBER = re.compile(r"^\s*[-+]?(\d+([.,]\d*)?|[.,]\d+)([eE][-+]?\d+)?\s*$")
_FIX = "save the workbook again from Excel (.xlsx), or export the sheet as CSV"


@dataclass(frozen=True)
class SheetLayout:
    """Where the table of a sheet starts and what its header says.

    Attributes
    ----------
    sheet : str
    columns : list of str
    units : dict
        ``{column: unit}`` from the units row, with ``("source", column)`` entries.
    data_row : int
        0-based row (within the sheet's rows) of the first data row.
    """

    sheet: str
    columns: list[str]
    units: dict
    data_row: int


def _check_archive(path: Path) -> None:
    """Refuse what is not a zip archive, or is a zip bomb, before calamine opens it."""
    if not zipfile.is_zipfile(path):
        raise InputError("not a readable Excel workbook (.xlsx is a zip archive; this is "
                         "not one)", file=path, fix=_FIX)
    try:
        with zipfile.ZipFile(path) as archive:
            members = archive.infolist()
    except (zipfile.BadZipFile, OSError) as exc:
        raise InputError("not a readable Excel workbook (corrupt zip archive)", file=path,
                         fix=_FIX) from exc
    unpacked = sum(m.file_size for m in members)
    packed_hard = any(m.file_size > MAX_RATIO * max(m.compress_size, 1) and m.file_size > 1 << 20
                      for m in members)
    if unpacked > MAX_UNPACKED_BYTES or packed_hard:
        raise InputError(f"workbook unpacks to {unpacked / 1024**2:.0f} MB"
                         + (f" with a member packed over {MAX_RATIO}×" if packed_hard else "")
                         + ": refused as a possible zip bomb", file=path,
                         fix="export the sheet as CSV or Parquet")


def _workbook(path: Path):
    from python_calamine import CalamineWorkbook

    try:
        return CalamineWorkbook.from_path(str(path))
    except Exception as exc:  # noqa: BLE001 — calamine raises its own and OS errors
        raise InputError(f"not a readable Excel workbook ({type(exc).__name__})", file=path,
                         fix=_FIX) from exc


def _rows(path: Path, sheet: str) -> Iterator[list]:
    try:
        yield from _workbook(path).get_sheet_by_name(sheet).iter_rows()
    except InputError:
        raise
    except Exception as exc:  # noqa: BLE001 — calamine raises its own and OS errors
        raise InputError(f"cannot read sheet '{sheet}' ({type(exc).__name__})", file=path,
                         fix=_FIX) from exc


def _row_count(sheet) -> int:
    """Rows :meth:`iter_rows` yields: up to the last filled row (leading empty rows count)."""
    return 0 if sheet.end is None else sheet.end[0] + 1


def _filled(row: list) -> list:
    return [c for c in row if c != "" and c is not None]


def _is_value(cell) -> bool:
    """A data value: a number, a date or time, or text that reads as a number."""
    if isinstance(cell, str):
        return bool(_NUMBER.match(cell))
    return True


def pick_sheet(names: list[str], heights: list[int]) -> int:
    """Index of the sheet holding the log: the first named like it, else the first filled.

    Examples
    --------
    >>> pick_sheet(["Notes", "Surface log"], [1, 100])
    1
    >>> pick_sheet(["Sheet1", "Sheet2"], [0, 10])
    1
    """
    for i, name in enumerate(names):
        if heights[i] and any(w in name.lower() for w in SHEET_WORDS):
            return i
    return next((i for i, h in enumerate(heights) if h), 0)


def sheet_layout(path: Path, sheet: str) -> SheetLayout:
    """Header, units row and first data row of a sheet, from its first rows."""
    head = []
    for row in _rows(path, sheet):
        head.append(row)
        if len(head) >= _HEAD_ROWS:
            break
    start = next((i for i, row in enumerate(head) if len(_filled(row)) >= 2), None)
    if start is None:
        raise InputError(f"sheet '{sheet}' holds no table (no row with two or more cells)",
                         file=path, fix="put the log in the first sheet, one column per "
                                        "channel under a header row")
    header = head[start]
    if all(_is_value(c) for c in _filled(header)):
        return SheetLayout(sheet, [str(i) for i in range(len(header))], {}, start)
    columns = [str(c).strip() if c not in ("", None) else f"column {i}"
               for i, c in enumerate(header)]
    if len(set(columns)) < len(columns):
        raise InputError(f"duplicate column names in the header of sheet '{sheet}'",
                         file=path, fix="give every column a distinct name")
    below = head[start + 1] if start + 1 < len(head) else []
    units_row = bool(_filled(below)) and all(isinstance(c, str) and not _is_value(c)
                                             for c in _filled(below))
    units: dict = {}
    if units_row:
        for column, unit in zip(columns, below, strict=False):
            unit = str(unit).strip().strip("[]()")
            if unit and unit.lower() not in {"-", "none", "unitless"}:
                units[column] = unit
                units[("source", column)] = "units row"
    return SheetLayout(sheet, columns, units, start + 1 + units_row)


def _cell_seconds(cell):
    if isinstance(cell, dt.timedelta):
        return cell.total_seconds()
    return 3600.0 * cell.hour + 60.0 * cell.minute + cell.second + cell.microsecond / 1e6


def _column(cells: list) -> pd.Series:
    """One column of cells as numbers, absolute times or text (empty → missing)."""
    values = [None if c == "" else c for c in cells]
    if any(isinstance(v, dt.datetime | dt.date) for v in values):
        stamps = [v if isinstance(v, dt.datetime | dt.date) else None for v in values]
        return pd.Series(pd.to_datetime(stamps), dtype="datetime64[ns]")
    values = [_cell_seconds(v) if isinstance(v, dt.timedelta | dt.time) else
              float(v) if isinstance(v, bool) else v for v in values]
    series = pd.Series(values, dtype=object)
    if all(v is None or isinstance(v, int | float) for v in values):
        return series.astype(float)
    return series


def _block(rows: list[list], columns: list[str]) -> pd.DataFrame:
    width = len(columns)
    fixed = [(list(r) + [""] * width)[:width] for r in rows]
    cells = list(zip(*fixed, strict=True)) if fixed else [()] * width
    return pd.DataFrame({c: _column(list(v)) for c, v in zip(columns, cells, strict=True)})


def open_excel(path) -> RawSource:
    """Open the log sheet of an Excel workbook as a raw source.

    Parameters
    ----------
    path : str or Path
        An ``.xlsx`` workbook.

    Raises
    ------
    InputError
        Not a workbook, a possible zip bomb, no sheet with a table, duplicate header names.
    """
    path = Path(path)
    _check_archive(path)
    book = _workbook(path)
    names = list(book.sheet_names)
    try:
        heights = [_row_count(book.get_sheet_by_name(n)) for n in names]
    except Exception as exc:  # noqa: BLE001 — calamine raises its own and OS errors
        raise InputError(f"cannot read the sheets ({type(exc).__name__})", file=path,
                         fix=_FIX) from exc
    if not any(heights):
        raise InputError("workbook has no filled sheet", file=path, fix="give a workbook "
                         "whose first sheet holds the log")
    at = pick_sheet(names, heights)
    layout = sheet_layout(path, names[at])
    rows = heights[at] - layout.data_row

    def read(chunk_rows: int) -> Iterator[pd.DataFrame]:
        block: list[list] = []
        for i, row in enumerate(_rows(path, layout.sheet)):
            if i < layout.data_row:
                continue
            block.append(row)
            if len(block) == chunk_rows:
                yield _block(block, layout.columns)
                block = []
        if block:
            yield _block(block, layout.columns)

    return RawSource(path, "excel", layout.columns, layout.units, rows, read)
