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
from drillfric.io.text import printable

#: Largest uncompressed size a workbook may declare [bytes] (Excel's own limit of
#: 1 048 576 rows of a rig log's few dozen columns stays well below).
MAX_UNPACKED_BYTES = 4 * 1024**3
#: Largest compression ratio of a member (spreadsheet XML packs 5–50×; zip bombs 1000×).
MAX_RATIO = 200
#: Most cells a worksheet may span, from its first to its last filled row and column:
#: calamine allocates the whole rectangle (32 bytes a cell) before reading a value, so one
#: cell at ``XFD1048576`` beside ``A1`` asks for 512 GiB. 2²⁵ cells (1 GiB) hold Excel's
#: 1 048 576 rows of 32 channels.
MAX_CELLS = 1 << 25
#: Words in a sheet name that mark the sheet holding the log.
SHEET_WORDS = ("surface", "log", "data")
#: Words in a sheet name that mark a sheet holding something else (a survey's "Survey data"
#: was taken for the log by its word "data": issue 30, tenth attack).
NOT_LOG_WORDS = ("survey", "trajectory", "deviation", "directional", "notes", "bha")
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


def check_workbook(path: Path) -> None:
    """Refuse a workbook before any native code reads it: not a zip archive, a zip bomb
    (:func:`_check_archive`), or a worksheet spanning more than :data:`MAX_CELLS` cells —
    by its declared ``<dimension ref=…>`` or by the cells it holds (each sheet's XML is
    streamed through defusedxml, DTDs refused, never unpacked whole).

    Pure Python, so that :mod:`drillfric.io.isolated` runs it in the parent and a hostile
    workbook costs no reader child (docs/security.md).
    """
    _check_archive(path)
    with zipfile.ZipFile(path) as archive:
        for member in archive.infolist():
            if re.fullmatch(r"xl/worksheets/[^/]+\.xml", member.filename):
                span = _check_sheet(archive, member, path)
                if span.uncached:
                    sheet = _sheet_names(archive).get(member.filename, member.filename)
                    raise InputError(
                        f"sheet '{printable(sheet)}' holds {span.uncached} formula cells "
                        f"without their computed values (the first at {span.first_uncached}): "
                        "the workbook was written by a program that does not calculate, so "
                        "those cells read empty", file=path,
                        fix="open the workbook in Excel or LibreOffice and save it (the values "
                            "are then stored), or export the sheet as CSV")


def _sheet_names(archive: zipfile.ZipFile) -> dict[str, str]:
    """``{worksheet member: sheet name}`` from ``xl/workbook.xml`` and its relationships
    (empty when they cannot be read: the member's name is shown instead)."""
    from defusedxml.ElementTree import fromstring

    try:
        book = fromstring(archive.read("xl/workbook.xml"), forbid_dtd=True)
        rels = fromstring(archive.read("xl/_rels/workbook.xml.rels"), forbid_dtd=True)
    except Exception:  # noqa: BLE001 — a name is only for the message
        return {}
    targets = {r.get("Id"): r.get("Target", "") for r in rels}
    out = {}
    for elem in book.iter():
        if elem.tag.rpartition("}")[2] != "sheet":
            continue
        rid = next((v for k, v in elem.attrib.items() if k.rpartition("}")[2] == "id"), None)
        target = targets.get(rid, "").lstrip("/")
        member = target if target.startswith("xl/") else f"xl/{target}"
        out[member] = elem.get("name", member)
    return out


def _check_sheet(archive: zipfile.ZipFile, member: zipfile.ZipInfo, path: Path) -> _Span:
    """InputError when a worksheet declares or fills more than :data:`MAX_CELLS` cells
    (the XML streamed in blocks into a parser target: no element tree is built); else what
    the stream saw (:class:`_Span`: its formula cells without a stored value too)."""
    from xml.etree.ElementTree import ParseError

    from defusedxml import DefusedXmlException
    from defusedxml.ElementTree import DefusedXMLParser

    span = _Span()
    parser = DefusedXMLParser(target=span, forbid_dtd=True)
    try:
        with archive.open(member) as stream:
            while block := stream.read(1 << 16):
                parser.feed(block)
                if span.cells() > MAX_CELLS:
                    raise _too_big(member, span, path)
            parser.close()
    except (ParseError, DefusedXmlException, zipfile.BadZipFile, OSError, ValueError) as exc:
        raise InputError(f"not a readable Excel workbook (sheet XML {member.filename}: "
                         f"{type(exc).__name__})", file=path, fix=_FIX) from None
    return span


def _too_big(member: zipfile.ZipInfo, span: _Span, path: Path) -> InputError:
    return InputError(f"refused: worksheet {member.filename} spans {span.cells():.3g} cells "
                      f"({span.shape()}; the limit is {MAX_CELLS:,}): the reader would "
                      "allocate them all", file=path,
                      fix="delete stray cells far from the table (Ctrl+End shows the last "
                          "one) and save again, or export the log as CSV or Parquet")


_REF = re.compile(r"\$?([A-Z]{1,3})\$?([0-9]{1,7})")


class _Span:
    """First and last row and column of a worksheet's cells (1-based), as streamed: the
    target of an XML parser (:meth:`start` is called for every element)."""

    def __init__(self):
        self.rows: list[int] = []  # [first, last]
        self.cols: list[int] = []
        self._row = 0
        self._col = 0
        self._declared = 0
        # formula cells without a stored value (<c><f>…</f></c>, no <v>): calamine reads
        # them empty (a time column of formulas gave "no data rows": issue 30, tenth attack)
        self.uncached = 0
        self.first_uncached = ""
        self._formula = self._value = self._in_value = False

    def data(self, text: str) -> None:
        if self._in_value and text.strip():
            self._value = True

    def end(self, tag: str) -> None:
        if self._in_value and tag.rpartition("}")[2] == "v":
            self._in_value = False

    def start(self, tag: str, attrib: dict) -> None:
        name = tag.rpartition("}")[2]
        if name == "c":
            self._cell_done()
            self.cell(attrib.get("r"))
        elif name == "f":
            self._formula = True
        elif name == "is":  # an inline string
            self._value = True
        elif name == "v":  # a stored value when it holds text (openpyxl writes <v />)
            self._in_value = True
        elif name == "row":
            self._cell_done()
            self.row(attrib.get("r"))
        elif name == "dimension":
            self.declared(attrib.get("ref", ""))

    def _cell_done(self) -> None:
        if self._formula and not self._value:
            self.uncached += 1
            self.first_uncached = self.first_uncached or f"{_letters(self._col)}{self._row}"
        self._formula = self._value = False

    def close(self) -> None:
        self._cell_done()
        return None

    def declared(self, ref: str) -> None:
        """A ``<dimension ref="A1:XFD1048576">`` (what the writer says the sheet spans)."""
        corners = [_REF.fullmatch(part) for part in ref.upper().split(":")]
        if len(corners) == 2 and all(corners):
            (c0, r0), (c1, r1) = ((_column_number(m[1]), int(m[2])) for m in corners)
            self._declared = (abs(r1 - r0) + 1) * (abs(c1 - c0) + 1)

    def row(self, ref: str | None) -> None:
        self._row = int(ref) if ref and ref.isdigit() else self._row + 1
        self._col = 0

    def cell(self, ref: str | None) -> None:
        match = _REF.fullmatch(ref or "")
        if match:
            self._col, self._row = _column_number(match[1]), int(match[2])
        else:  # a cell without a reference follows the previous one
            self._col += 1
        for bounds, value in ((self.rows, max(self._row, 1)), (self.cols, self._col)):
            if not bounds:
                bounds.extend((value, value))
            bounds[0], bounds[1] = min(bounds[0], value), max(bounds[1], value)

    def cells(self) -> int:
        filled = ((self.rows[1] - self.rows[0] + 1) * (self.cols[1] - self.cols[0] + 1)
                  if self.rows else 0)
        return max(filled, self._declared)

    def shape(self) -> str:
        filled = self.cells() if self.rows and self.cells() > self._declared else 0
        if not filled:
            return "as its <dimension> declares"
        return (f"rows {self.rows[0]:,}–{self.rows[1]:,}, columns "
                f"{_letters(self.cols[0])}–{_letters(self.cols[1])}")


def _column_number(letters: str) -> int:
    """1-based column number of ``A``, ``Z``, ``AA`` … ``XFD``."""
    number = 0
    for char in letters:
        number = 26 * number + ord(char) - 64
    return number


def _letters(column: int) -> str:
    text = ""
    while column > 0:
        column, rest = divmod(column - 1, 26)
        text = chr(65 + rest) + text
    return text


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
    >>> pick_sheet(["Survey data", "Surface log"], [3, 100])  # a survey is no log
    1
    """
    likely = [i for i in range(len(names)) if heights[i]
              and not any(w in names[i].lower() for w in NOT_LOG_WORDS)]
    for i in likely:
        if any(w in names[i].lower() for w in SHEET_WORDS):
            return i
    order = likely + [i for i in range(len(names)) if heights[i] and i not in likely]
    return order[0] if order else 0


def sheet_layout(path: Path, sheet: str) -> SheetLayout:
    """Header, units row and first data row of a sheet, from its first rows."""
    head = []
    for row in _rows(path, sheet):
        head.append(row)
        if len(head) >= _HEAD_ROWS:
            break
    # the header is the first row about as wide as the table: a title row above it (a
    # merged "Torque & drag" over three columns, a rig name) holds fewer cells (issue 30)
    widest = max((len(_filled(row)) for row in head), default=0)
    start = next((i for i, row in enumerate(head)
                  if len(_filled(row)) >= max(2, (widest + 1) // 2)), None)
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


def _log_header(columns: list[str]) -> bool:
    """Whether a sheet's header names a speed or a torque column (a log's, not a survey's)."""
    from drillfric.io.channels import find_column

    return any(find_column(columns, key, {}) for key in ("surface_rpm", "surface_torque"))


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
    if not _log_header(layout.columns):  # another filled sheet's header may be the log's
        for i in (i for i in range(len(names)) if heights[i] and i != at):
            try:
                other = sheet_layout(path, names[i])
            except InputError:
                continue
            if _log_header(other.columns):
                at, layout = i, other
                break
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

    return RawSource(path, "excel", layout.columns, layout.units, rows, read,
                     where=f"sheet '{printable(layout.sheet)}'")
