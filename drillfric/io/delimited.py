"""Delimited text logs (CSV, TSV, semicolon, pipe): layout sniffing and chunked reading.

The top of a file tells the delimiter, the decimal mark, whether a header and a units row are
there, and the text encoding (UTF-8 with or without BOM, UTF-16/32 with a BOM, else Latin-1 of
old rig exports). Comment lines (``#``) are skipped as pandas reads (:class:`_CommentFree`).

Untrusted files are read in bounded work: a line longer than :data:`MAX_LINE_CHARS` is
refused (a single huge line would otherwise be buffered and rescanned, quadratic in its
length), and a file whose top is not text (NUL bytes, control characters) is refused as
"not a text file" without echoing its bytes (docs/security.md).
"""

from __future__ import annotations

import codecs
import csv
import io
import re
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from drillfric.errors import InputError
from drillfric.io.grouping import ungroup
from drillfric.io.source import NULL_VALUES, RawSource
from drillfric.io.text import printable

#: Longest line read [characters] (documented in docs/ingestion.md): rig exports with a few
#: hundred channels have lines of a few kB.
MAX_LINE_CHARS = 1 << 20
_DELIMITERS = (",", ";", "\t", "|")
_SNIFF_BYTES = 1 << 16
_NUMBER = re.compile(r"^[-+]?(\d+([.,]\d*)?|[.,]\d+)([eE][-+]?\d+)?$")
_DATE = re.compile(r"^\d{4}-\d{2}-\d{2}([ T]\d{2}:\d{2}(:\d{2}(\.\d*)?)?)?")
#: Byte-order marks and the codec they announce (UTF-32 before UTF-16: FF FE 00 00).
_BOMS = ((codecs.BOM_UTF32_LE, "utf-32"), (codecs.BOM_UTF32_BE, "utf-32"),
         (codecs.BOM_UTF8, "utf-8-sig"), (codecs.BOM_UTF16_LE, "utf-16"),
         (codecs.BOM_UTF16_BE, "utf-16"))
#: Largest share of control characters (other than tab, CR, LF) in the text at the top of a
#: file that is still read as text.
_MAX_CONTROL_SHARE = 0.01
#: Text encodings whose rows can be read from a byte offset (UTF-16/32 are read whole).
_SEEKABLE = ("utf-8-sig", "latin-1")
_NOT_TEXT_FIX = "give a delimited text export (CSV) of the log, or a Parquet/HDF5/LAS file"


@dataclass(frozen=True)
class CsvLayout:
    """What :func:`sniff_csv` found at the top of a delimited text file.

    Attributes
    ----------
    delimiter, decimal : str
        The decimal mark; with a decimal comma, a dot groups thousands ("17.240,5").
    header : bool
        Whether the first line names the columns.
    units_row : bool
        Whether the second line holds units.
    columns : list of str
    units : dict
        ``{column: unit}`` from the units row.
    encoding : str
    """

    delimiter: str
    decimal: str
    header: bool
    units_row: bool
    columns: list[str]
    units: dict
    encoding: str


def _encoding(head: bytes) -> str:
    """Text encoding from the first bytes: a BOM, else UTF-8 when it decodes or when it
    holds UTF-8 characters beside its stray bytes (those are read as Latin-1,
    :func:`_latin1`), else Latin-1.

    A UTF-8 log with one Latin-1 byte near its top had been read wholly as Latin-1: its
    ``°`` and ``µ`` turned into ``Â°`` and ``Âµ`` (issue 30, noticed after the eleventh attack).
    """
    for bom, codec in _BOMS:
        if head.startswith(bom):
            return codec
    try:
        head.decode("utf-8")
    except UnicodeDecodeError as exc:
        if exc.start >= len(head) - 3:  # merely a character cut by the sniff window
            return "utf-8-sig"
        text = head.decode("utf-8", errors="surrogateescape")
        if not any(c >= "\x80" and not _NOT_UTF8.match(c) for c in text):
            return "latin-1"  # old rig exports: Windows/Latin-1 text
    return "utf-8-sig"


def _decode(raw: bytes, path: Path) -> tuple[str, str]:
    """The text at the top of a file and its encoding; InputError when it is not text."""
    codec = _encoding(raw)
    if codec.startswith("utf-8"):
        decoder = codecs.getincrementaldecoder(codec)(errors="surrogateescape")
        text = _latin1(decoder.decode(raw), path)
    else:
        text = codecs.getincrementaldecoder(codec)(errors="replace").decode(raw)
    control = sum(1 for c in text if c < " " and c not in "\t\r\n")
    if "\x00" in text or control > _MAX_CONTROL_SHARE * max(len(text), 1):
        raise InputError("not a text file (binary data where delimited text was expected)",
                         file=path, fix=_NOT_TEXT_FIX)
    return text, codec


def _is_value(text: str) -> bool:
    """A data value: a number (either decimal mark), a date, or empty."""
    text = text.strip().strip('"')
    return text == "" or bool(_NUMBER.match(text)) or bool(_DATE.match(text)) or (
        text.lower() in {"nan", "null", "-nan"})


def sniff_csv(path: Path) -> CsvLayout:
    """Find delimiter, decimal mark, header and units row from the top of a text file.

    Line endings may be LF, CRLF or CR only. The delimiter is the one of ``, ; TAB |``
    that splits the first lines into the same, largest number of fields; a decimal comma
    is recognised when the delimiter is not a comma and values look like ``12,5``.
    """
    with path.open("rb") as fh:
        raw = fh.read(_SNIFF_BYTES)
        while len(raw) < MAX_LINE_CHARS and not re.search(rb"[\r\n]", raw.lstrip(b"\r\n")):
            more = fh.read(_SNIFF_BYTES)  # the first line is longer than the window
            if not more:
                break
            raw += more
    text, encoding = _decode(raw, path)
    cut = len(raw) >= _SNIFF_BYTES
    lines = [ln for ln in re.split(r"\r\n|\r|\n", text) if ln.strip() and not _is_comment(ln)]
    if cut and len(lines) == 1:
        raise _too_long(path)
    if len(lines) > 1 and cut:
        lines = lines[:-1]  # the last line may be cut by the sniff window
    top, lines = lines, lines[:50]
    if not lines:
        raise InputError("file holds no data (only blank or # comment lines)", file=path,
                         fix="give a file with data rows")
    delimiter = max(_DELIMITERS, key=lambda d: _delimiter_score(lines, d))
    rows = [[f.strip().strip('"') for f in fields] for fields in _fields(lines, delimiter)]
    header = not all(_is_value(f) for f in rows[0])
    units_row = header and len(rows) > 1 and any(f for f in rows[1]) and not any(
        f and _is_value(f) for f in rows[1])
    body = rows[(1 + units_row) if header else 0:]
    n = len(rows[0])
    columns = [c or f"column {i}" for i, c in enumerate(rows[0])] if header else [
        str(i) for i in range(max(len(r) for r in rows))]
    # the decimal mark is voted on over the whole window (64 KiB), not the first 50 lines:
    # a German log's first value ≥ 1000 ('1.050') may come after them (issue 30, twelfth
    # attack F4)
    decimal = "." if delimiter == "," else _decimal_mark(
        body + [[f.strip().strip('"') for f in fields] for fields in
                _fields(top[len(lines):], delimiter)], columns, path)
    if header and len(set(columns)) < n:
        raise InputError("duplicate column names in the header", file=path,
                         fix="give every column a distinct name")
    units = {}
    if units_row:
        for col, unit in zip(columns, rows[1], strict=False):
            if unit and unit not in {"-", "none", "unitless"}:
                units[col] = unit.strip("[]()")
                units[("source", col)] = "units row"
    return CsvLayout(delimiter, decimal, header, units_row, columns, units, encoding)


#: A value only a decimal comma writes (``12,5``), and one only a decimal dot writes — a
#: dot that cannot group thousands (``0.050``, ``2210.000``, ``12.5``; ``17.240`` can).
_COMMA_DECIMAL = re.compile(r"[-+]?(\d{1,3}(\.\d{3})+|\d*),\d+")  # 12,5 or 17.240,5
_DOT_DECIMAL = re.compile(r"[-+]?\d*\.\d+")
_DOT_GROUPED = re.compile(r"[-+]?[1-9]\d{0,2}(\.\d{3})+")
#: Dots only a thousands grouping writes (``1.234.567``: two of them), and the fraction of a
#: clock time (``12:00:00,050``), whose mark is the file's decimal mark.
_DOTS_GROUPED = re.compile(r"[-+]?[1-9]\d{0,2}(\.\d{3}){2,}")
_CLOCK_FRACTION = re.compile(r"\d{2}:\d{2}:\d{2}([.,])\d+")


def _decimal_mark(body: list[list[str]], columns: list[str], path: Path) -> str:
    """The decimal mark of a file not delimited by commas, decided column by column: a
    column with values like ``12,5`` votes for the comma, one with values only a dot writes
    (``0.050``) for the dot. One column of the other kind — a remark of ``1,5`` beside
    dot-decimal numbers — does not decide the file (issue 30, eleventh attack: every value
    read 1000× as a dot grouping thousands); as many of each is refused.

    Raises
    ------
    InputError
        As many columns write a decimal comma as a decimal dot.
    """
    comma, dot, grouped = {}, {}, {}
    for row in body:
        for i, f in enumerate(row):
            f = ungroup(f)  # "2 210,00", "2'210.5": the mark after the groups is the decimal
            clock = _CLOCK_FRACTION.search(f)
            if _COMMA_DECIMAL.fullmatch(f) or _DOTS_GROUPED.fullmatch(f) or (
                    clock and clock[1] == ","):
                comma.setdefault(i, f)
            elif (_DOT_DECIMAL.fullmatch(f) and not _DOT_GROUPED.fullmatch(f)) or clock:
                dot.setdefault(i, f)
            elif _DOT_GROUPED.fullmatch(f):
                grouped.setdefault(i, f)
    comma = {i: f for i, f in comma.items() if i not in dot}  # "1.5" and "1,5": no vote
    if not comma and not dot and grouped:
        g = next(iter(grouped))
        name = f"'{columns[g]}'" if g < len(columns) else f"column {g}"
        raise InputError(
            f"the decimal mark cannot be told: column {printable(name)} writes "
            f"'{printable(grouped[g], 20)}', a dot before 3 digits in every value (a decimal "
            f"point, or thousands grouped by a dot as a decimal-comma locale writes them: "
            f"{grouped[g]} or {grouped[g].replace('.', '')}?), and no value in the file's "
            "top shows a decimal mark", file=path,
            fix="export the log with decimals (2.210,00 or 2210.00) or without thousands "
                "separators")
    if not comma:
        return "."
    if len(comma) > len(dot):
        return ","
    if len(comma) < len(dot):
        return "."

    def name(i: int) -> str:
        return f"'{columns[i]}'" if i < len(columns) else f"column {i}"

    c, d = next(iter(comma)), next(iter(dot))
    raise InputError(f"the decimal mark cannot be told: column {name(c)} writes "
                     f"'{comma[c]}' (a decimal comma), column {name(d)} '{dot[d]}' (a "
                     "decimal dot), as many columns each way", file=path,
                     fix="export the log with one decimal mark throughout")


def _is_comment(line: str) -> bool:
    """A comment line: its first non-blank character is ``#`` (a rig header block, a note).

    Examples
    --------
    >>> _is_comment("  # Rig: Example 1"), _is_comment("12.5,#3")
    (True, False)
    """
    return line.lstrip().startswith("#")


_LINE_END = re.compile(r"(?<=\n)|(?<=\r)(?!\n)")


class TextWarning(UserWarning):
    """A delimited text file read with a repair (bytes that are not UTF-8 read as Latin-1)."""


#: Bytes that are not UTF-8, as ``surrogateescape`` decodes them (U+DC80–U+DCFF).
_NOT_UTF8 = re.compile("[\udc80-\udcff]")
#: Files whose stray Latin-1 bytes were said (once a file in a process).
_LATIN1_SAID: set[str] = set()


def _latin1(text: str, path: Path | None) -> str:
    """``text`` decoded as UTF-8 with ``surrogateescape``, its bytes that are not UTF-8
    read as Latin-1 (the docs promise UTF-8 or Latin-1 text: a UTF-8 log with one Latin-1
    ``°`` in an operator's note at row 3000 had been refused blaming its field counts —
    issue 30, eleventh attack), and said once in a warning quoting the line."""
    if not _NOT_UTF8.search(text):
        return text
    fixed = _NOT_UTF8.sub(lambda m: chr(ord(m[0]) - 0xDC00), text)
    key = str(path)
    if key not in _LATIN1_SAID:
        _LATIN1_SAID.add(key)
        at = _NOT_UTF8.search(text).start()
        start = max(text.rfind("\n", 0, at), text.rfind("\r", 0, at)) + 1
        line = re.split(r"\r|\n", fixed[start:], maxsplit=1)[0]
        warnings.warn_explicit(
            f"{path}: byte 0x{ord(text[at]) - 0xDC00:02X} is not UTF-8, which the file's top "
            f"is: read as Latin-1, in the line '{printable(line, 60)}' (save the file as "
            "UTF-8 to silence this)", TextWarning, __file__, 0, module=__name__, registry={})
    return fixed


class _CommentFree(io.TextIOBase):
    """A text file as pandas should see it: without comment lines and leading blank lines.

    pandas reads it through :meth:`read`; whole lines are handed on (a partial last line,
    or a final ``\\r`` that may start a ``\\r\\n``, waits for the next block), and a block
    without ``#`` passes unchanged, so a file without comments costs one substring search
    per block. Leading blank lines go too, so that ``skiprows`` counts the header and the
    units row only.
    """

    def __init__(self, fh, path: Path | None = None):
        self._fh = fh
        self._path = path
        self._tail = ""
        self._top = True  # before the first line of content

    def readable(self) -> bool:
        return True

    def read(self, size: int | None = -1) -> str:
        """Up to about ``size`` characters of whole, comment-free lines ("" at the end)."""
        while True:
            block = self._fh.read(size if size and size > 0 else -1)
            text, self._tail = self._tail + block, ""
            if block:
                # a final "\r" waits: it may be the first half of "\r\n"
                cut = max(text.rfind("\n"), text.rfind("\r", 0, len(text) - 1)) + 1
                text, self._tail = text[:cut], text[cut:]
                if len(self._tail) > MAX_LINE_CHARS:
                    raise _too_long(self._path)
            text = self._clean(_latin1(text, self._path))
            if text or not block:
                return text

    def _clean(self, text: str) -> str:
        if not self._top and "#" not in text:
            return text
        lines = [ln for ln in _LINE_END.split(text) if ln and not _is_comment(ln)]
        if self._top:
            while lines and not lines[0].strip():
                lines.pop(0)
            self._top = not lines
        return "".join(lines)


def _fields(lines: list[str], delimiter: str) -> list[list[str]]:
    """The fields of each line as RFC 4180 quoting and pandas read them: a delimiter inside
    a quoted field (``"Hook load, avg"``) does not split it — the header had been split
    there and every later name moved one column right of its data (issue 30, twelfth
    attack F3). A line is read alone (a quote left open ends with it)."""
    out = []
    for ln in lines:
        try:
            out.append(next(csv.reader([ln], delimiter=delimiter, skipinitialspace=True), [""]))
        except csv.Error:  # a field beyond the csv module's limit (131 072 characters)
            out.append(ln.split(delimiter))
    return out


def _delimiter_score(lines: list[str], delimiter: str) -> tuple[int, int]:
    counts = [len(f) - 1 for f in _fields(lines, delimiter)]
    consistent = sum(c == counts[0] for c in counts)
    return (min(counts) > 0, consistent * (counts[0] > 0), counts[0])


def open_delimited(path: Path) -> RawSource:
    """Open a delimited text log (layout from :func:`sniff_csv`), read in chunks."""
    layout = sniff_csv(path)
    # a decimal comma's locale groups thousands with a dot: "17.240" is 17240, never 17.24
    # (issue 30, eighth attack: every value ≥ 1000 of such a file shrank 1000×)
    grouping = {"thousands": "."} if layout.decimal == "," else {}
    kwargs = dict(sep=layout.delimiter, decimal=layout.decimal, header=None, **grouping,
                  names=layout.columns, skipinitialspace=True,
                  skiprows=(1 + layout.units_row) if layout.header else 0,
                  na_values=[str(v) for v in NULL_VALUES], skip_blank_lines=True,
                  index_col=False)

    def read(chunk_rows: int, start: int = 0, stop: int | None = None
             ) -> Iterator[pd.DataFrame]:
        """Rows of bytes [start, stop) (``start`` at a line's beginning, past the header)."""
        args = kwargs | {"skiprows": 0} if start else kwargs
        try:
            with open(path, "rb") as raw:
                raw.seek(start)
                # a UTF-8 file's stray non-UTF-8 bytes: read as Latin-1 (_latin1)
                fh = io.TextIOWrapper(io.BufferedReader(_Window(raw, stop)),
                                      encoding=layout.encoding, newline="",
                                      errors="surrogateescape"
                                      if layout.encoding.startswith("utf-8") else "strict")
                with pd.read_csv(_CommentFree(fh, path), chunksize=chunk_rows, **args) as reader:
                    yield from reader
        except UnicodeDecodeError as exc:
            raise InputError(f"bytes that are not {layout.encoding.upper()} text "
                             f"({printable(str(exc), 80)})", file=path,
                             fix="save the file as UTF-8") from exc
        except (pd.errors.ParserError, ValueError) as exc:
            raise InputError(f"cannot parse as delimited text ({_parser_problem(exc)})",
                             file=path,
                             fix="check that every row has the same number of fields") from exc

    return RawSource(path, "csv", layout.columns, layout.units, None, read,
                     seek="byte" if layout.encoding in _SEEKABLE else None)


class _Window(io.RawIOBase):
    """A binary file read up to byte ``stop`` (None: its end), from where it stands."""

    def __init__(self, fh, stop: int | None):
        self._fh, self._stop = fh, stop

    def readable(self) -> bool:
        return True

    def readinto(self, buffer) -> int:
        size = len(buffer)
        if self._stop is not None:
            size = max(min(size, self._stop - self._fh.tell()), 0)
        data = self._fh.read(size)
        buffer[:len(data)] = data
        return len(data)




def _too_long(path: Path | None) -> InputError:
    return InputError(f"a line is longer than {MAX_LINE_CHARS:,} characters: not a log "
                      "drillfric can read", file=path,
                      fix="check the export (one sample per line; line breaks LF, CRLF or CR)")


def _parser_problem(exc: Exception) -> str:
    """The parser's complaint without the file text it may quote."""
    first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    match = re.search(r"Expected \d+ fields in line \d+, saw \d+", first)
    return match.group(0) if match else type(exc).__name__
