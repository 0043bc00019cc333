"""Format readers for rig surface data: Parquet, CSV, HDF5 and LAS 2.0.

Each reader opens a file cheaply (schema, header, units; no data) into a :class:`RawSource`
whose :meth:`RawSource.chunks` yields the raw columns in blocks of rows, so that a large
file never has to be in memory at once: Parquet by record batches (pyarrow), CSV by pandas
chunks, HDF5 by row slices (a pandas table or plain h5py datasets), LAS as one block
(lasio reads LAS files whole). Channel recognition and unit conversion happen later
(:mod:`drillfric.io.channels`); readers only report the units the file itself states.

Every failure to read becomes an :class:`~drillfric.errors.InputError` naming the file.
"""

from __future__ import annotations

import io
import re
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from drillfric.errors import InputError

#: Extensions of surface data files, by format.
FORMATS = {".parquet": "parquet", ".pq": "parquet", ".csv": "csv", ".txt": "csv",
           ".tsv": "csv", ".h5": "hdf5", ".hdf5": "hdf5", ".las": "las", ".xml": "witsml",
           ".dlis": "dlis", ".xlsx": "excel"}
#: Values meaning "no value" in rig logs (besides empty fields and NaN).
NULL_VALUES = (-999.25, -9999.0)
_DELIMITERS = (",", ";", "\t", "|")
_SNIFF_BYTES = 1 << 16
_NUMBER = re.compile(r"^[-+]?(\d+([.,]\d*)?|[.,]\d+)([eE][-+]?\d+)?$")
_DATE = re.compile(r"^\d{4}-\d{2}-\d{2}([ T]\d{2}:\d{2}(:\d{2}(\.\d*)?)?)?")
#: LAS index curves that make a log depth-indexed (LAS 2.0 names the depth index DEPT).
_DEPTH_INDEX = frozenset({"DEPT", "DEPTH", "MD", "DMEA", "TVD"})
#: Units of a depth index as LAS headers spell them.
_DEPTH_UNITS = frozenset({"M", "FT", "F", "METER", "METERS", "METRE", "METRES", "FEET"})


@dataclass(frozen=True)
class RawSource:
    """An opened surface data file: its columns and stated units, data not yet read.

    Attributes
    ----------
    path : Path
    format : str
        ``"parquet"``, ``"csv"``, ``"hdf5"`` or ``"las"``.
    columns : list of str
        Column labels in file order (``"0"``, ``"1"``, … for a headerless CSV).
    units : dict
        Units the file states per column, and ``("source", column)`` → where they came
        from (``"units row"``, ``"header"``) for :func:`drillfric.io.channels.map_channels`.
    rows : int or None
        Row count when known without reading the data.
    depth_index : str or None
        The index curve of a depth-indexed LAS log (e.g. ``"DEPT [M]"``), else None.
    """

    path: Path
    format: str
    columns: list[str]
    units: dict
    rows: int | None
    _read: Callable[[int], Iterator[pd.DataFrame]] = field(repr=False, compare=False)
    depth_index: str | None = None

    def chunks(self, chunk_rows: int = 200_000) -> Iterator[pd.DataFrame]:
        """Yield the raw data in blocks of at most ``chunk_rows`` rows, labelled by column."""
        if chunk_rows < 1:
            raise ValueError("chunk_rows must be positive")
        yield from self._read(chunk_rows)


def data_format(path: Path) -> str:
    """Format name for a data file's extension, or InputError for an unknown extension."""
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        known = ", ".join(sorted({e for e in FORMATS}))
        raise InputError(f"unknown file extension '{path.suffix or '(none)'}'", file=path,
                         fix=f"give a surface data file ending in one of {known}")
    return fmt


def open_source(path: str | Path, *, hdf_key: str = "surface") -> RawSource:
    """Open a surface data file by its extension.

    Parameters
    ----------
    path : str or Path
        Data file (``.parquet``, ``.csv``, ``.h5``/``.hdf5``, ``.las``).
    hdf_key : str
        Group or table holding the surface data in an HDF5 file.

    Raises
    ------
    InputError
        Missing, empty, unknown extension, truncated or unreadable.
    """
    path = Path(path)
    fmt = data_format(path)
    if not path.is_file():
        raise InputError("file not found", file=path, fix="check the path")
    if path.stat().st_size == 0:
        raise InputError("file is empty", file=path, fix="give a file with data rows")
    opener = {"parquet": _open_parquet, "csv": _open_csv, "hdf5": _open_hdf5,
              "las": _open_las, "witsml": _open_witsml, "dlis": _open_dlis,
              "excel": _open_excel}[fmt]
    return opener(path) if fmt != "hdf5" else opener(path, hdf_key)


# --------------------------------------------------------------------------- Parquet
def _open_parquet(path: Path) -> RawSource:
    import pyarrow as pa
    import pyarrow.parquet as pq

    corrupt = InputError("not a readable Parquet file (truncated or corrupt)", file=path,
                         fix="re-export or re-copy the file")
    try:
        meta = pq.ParquetFile(path)
        schema = meta.schema_arrow
    except (pa.ArrowException, OSError) as exc:
        raise corrupt from exc
    units = {}
    for fld in schema:
        md = fld.metadata or {}
        unit = md.get(b"unit") or md.get(b"units")
        if unit:
            units[fld.name] = unit.decode()
            units[("source", fld.name)] = "header"

    def read(chunk_rows: int) -> Iterator[pd.DataFrame]:
        try:
            for batch in pq.ParquetFile(path).iter_batches(batch_size=chunk_rows):
                # ignore_metadata: a pandas index stays a column under its schema name
                yield pa.Table.from_batches([batch]).to_pandas(ignore_metadata=True)
        except (pa.ArrowException, OSError) as exc:
            raise corrupt from exc

    return RawSource(path, "parquet", list(schema.names), units, meta.metadata.num_rows, read)


# --------------------------------------------------------------------------- CSV
@dataclass(frozen=True)
class CsvLayout:
    """What :func:`sniff_csv` found at the top of a delimited text file.

    Attributes
    ----------
    delimiter, decimal : str
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


def _decode(raw: bytes) -> tuple[str, str]:
    try:
        return raw.decode("utf-8-sig"), "utf-8-sig"
    except UnicodeDecodeError as exc:
        if exc.start >= len(raw) - 3:  # a character cut by the sniff window
            return raw[:exc.start].decode("utf-8-sig"), "utf-8-sig"
        return raw.decode("latin-1"), "latin-1"  # old rig exports: Windows/Latin-1 text


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
        text, encoding = _decode(fh.read(_SNIFF_BYTES))
    lines = [ln for ln in re.split(r"\r\n|\r|\n", text) if ln.strip() and not _is_comment(ln)]
    if len(lines) > 1 and len(text.encode(encoding)) >= _SNIFF_BYTES:
        lines = lines[:-1]  # the last line may be cut by the sniff window
    lines = lines[:50]
    if not lines:
        raise InputError("file holds no data (only blank or # comment lines)", file=path,
                         fix="give a file with data rows")
    delimiter = max(_DELIMITERS, key=lambda d: _delimiter_score(lines, d))
    rows = [[f.strip().strip('"') for f in ln.split(delimiter)] for ln in lines]
    header = not all(_is_value(f) for f in rows[0])
    units_row = header and len(rows) > 1 and any(f for f in rows[1]) and not any(
        f and _is_value(f) for f in rows[1])
    body = rows[(1 + units_row) if header else 0:]
    decimal = "," if delimiter != "," and any(
        re.fullmatch(r"[-+]?\d*,\d+", f) for row in body for f in row) else "."
    n = len(rows[0])
    columns = [c or f"column {i}" for i, c in enumerate(rows[0])] if header else [
        str(i) for i in range(max(len(r) for r in rows))]
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


def _is_comment(line: str) -> bool:
    """A comment line: its first non-blank character is ``#`` (a rig header block, a note).

    Examples
    --------
    >>> _is_comment("  # Rig: Example 1"), _is_comment("12.5,#3")
    (True, False)
    """
    return line.lstrip().startswith("#")


_LINE_END = re.compile(r"(?<=\n)|(?<=\r)(?!\n)")


class _CommentFree(io.TextIOBase):
    """A text file as pandas should see it: without comment lines and leading blank lines.

    pandas reads it through :meth:`read`; whole lines are handed on (a partial last line,
    or a final ``\\r`` that may start a ``\\r\\n``, waits for the next block), and a block
    without ``#`` passes unchanged, so a file without comments costs one substring search
    per block. Leading blank lines go too, so that ``skiprows`` counts the header and the
    units row only.
    """

    def __init__(self, fh):
        self._fh = fh
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
            text = self._clean(text)
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


def _delimiter_score(lines: list[str], delimiter: str) -> tuple[int, int]:
    counts = [ln.count(delimiter) for ln in lines]
    consistent = sum(c == counts[0] for c in counts)
    return (min(counts) > 0, consistent * (counts[0] > 0), counts[0])


def _open_csv(path: Path) -> RawSource:
    layout = sniff_csv(path)
    kwargs = dict(sep=layout.delimiter, decimal=layout.decimal, header=None,
                  names=layout.columns, skipinitialspace=True,
                  skiprows=(1 + layout.units_row) if layout.header else 0,
                  na_values=[str(v) for v in NULL_VALUES], skip_blank_lines=True,
                  index_col=False)

    def read(chunk_rows: int) -> Iterator[pd.DataFrame]:
        try:
            with open(path, encoding=layout.encoding, newline="") as fh, \
                    pd.read_csv(_CommentFree(fh), chunksize=chunk_rows, **kwargs) as reader:
                yield from reader
        except (pd.errors.ParserError, ValueError, UnicodeDecodeError) as exc:
            first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise InputError(f"cannot parse as delimited text ({first})", file=path,
                             fix="check that every row has the same number of fields") from exc

    return RawSource(path, "csv", layout.columns, layout.units, None, read)


# --------------------------------------------------------------------------- HDF5
def _open_hdf5(path: Path, key: str) -> RawSource:
    import h5py

    try:
        with h5py.File(path, "r") as h5:
            node = _surface_node(h5, key, path)
            if isinstance(node, h5py.Group) and "pandas_type" in node.attrs:
                return _pandas_table(path, node.name)
            return _h5py_columns(path, node)
    except OSError as exc:
        raise InputError("not a readable HDF5 file (truncated or corrupt)", file=path,
                         fix="re-export or re-copy the file") from exc


def _surface_node(h5, key: str, path: Path):
    if key in h5:
        return h5[key]
    tables = [k for k in h5 if k not in {"survey", "config"}]
    if key == "surface" and len(tables) == 1:  # a lone table is the surface data
        return h5[tables[0]]
    raise InputError(f"no '/{key}' table in the HDF5 file (it holds: "
                     f"{', '.join('/' + k for k in h5) or 'nothing'})", file=path,
                     fix=f"store the surface data under '/{key}'")


def _pandas_table(path: Path, key: str) -> RawSource:
    try:
        with pd.HDFStore(path, "r") as store:
            storer = store.get_storer(key)
            is_table = bool(getattr(storer, "is_table", False))
            rows = storer.nrows if is_table else None
            columns = list(_labelled(store.select(key, start=0, stop=1) if is_table
                                     else store[key].iloc[:1]).columns)
            units = dict(getattr(storer.attrs, "units", None) or {})
    except (OSError, KeyError, ValueError, TypeError) as exc:
        raise InputError(f"cannot read HDF5 table '{key}' ({exc})", file=path,
                         fix="write it with pandas DataFrame.to_hdf(format='table')") from exc
    units.update({("source", c): "header" for c in list(units)})

    def read(chunk_rows: int) -> Iterator[pd.DataFrame]:
        try:
            with pd.HDFStore(path, "r") as store:
                if not is_table:
                    frame = store[key]
                    for start in range(0, len(frame), chunk_rows):
                        yield _labelled(frame.iloc[start:start + chunk_rows])
                    return
                for start in range(0, rows, chunk_rows):
                    yield _labelled(store.select(key, start=start, stop=start + chunk_rows))
        except (OSError, KeyError, ValueError) as exc:
            raise InputError(f"cannot read HDF5 table '{key}' (truncated or corrupt)",
                             file=path, fix="re-export or re-copy the file") from exc

    return RawSource(path, "hdf5", columns, units, rows, read)


def _labelled(frame: pd.DataFrame) -> pd.DataFrame:
    """Columns labelled by text; a meaningful index (e.g. timestamps) becomes a column."""
    keep_index = not isinstance(frame.index, pd.RangeIndex)
    return frame.reset_index(drop=not keep_index).rename(columns=str)


def _h5py_columns(path: Path, node) -> RawSource:
    import h5py

    if isinstance(node, h5py.Dataset) and node.dtype.names:  # one compound dataset
        columns, rows = list(node.dtype.names), len(node)
        units = {}
    elif isinstance(node, h5py.Group):
        datasets = {k: v for k, v in node.items() if isinstance(v, h5py.Dataset) and v.ndim == 1}
        lengths = {len(v) for v in datasets.values()}
        if not datasets or len(lengths) != 1:
            raise InputError(f"HDF5 group '{node.name}' needs 1-D datasets of equal length "
                             "(one per channel)", file=path,
                             fix="write one dataset per column, all with the same length")
        columns, rows = list(datasets), lengths.pop()
        units = {k: _attr_text(v.attrs.get("unit", v.attrs.get("units")))
                 for k, v in datasets.items()}
        units = {k: u for k, u in units.items() if u}
    else:
        raise InputError(f"HDF5 node '{node.name}' is not a table", file=path,
                         fix="store a group of 1-D datasets or a pandas table")
    units.update({("source", c): "header" for c in list(units)})
    name = node.name

    def read(chunk_rows: int) -> Iterator[pd.DataFrame]:
        try:
            with h5py.File(path, "r") as h5:
                obj = h5[name]
                for start in range(0, rows, chunk_rows):
                    stop = start + chunk_rows
                    if isinstance(obj, h5py.Dataset):
                        block = obj[start:stop]
                        yield pd.DataFrame({c: _decoded(block[c]) for c in columns})
                    else:
                        yield pd.DataFrame({c: _decoded(obj[c][start:stop]) for c in columns})
        except OSError as exc:
            raise InputError("not a readable HDF5 file (truncated or corrupt)", file=path,
                             fix="re-export or re-copy the file") from exc

    return RawSource(path, "hdf5", columns, units, rows, read)


def _attr_text(value) -> str | None:
    if value is None:
        return None
    return value.decode() if isinstance(value, bytes) else str(value)


def _decoded(values: np.ndarray) -> np.ndarray:
    if values.dtype.kind in "SO":
        return np.array([v.decode() if isinstance(v, bytes) else v for v in values],
                        dtype=object)
    return values


# --------------------------------------------------------------------------- LAS
def _open_las(path: Path) -> RawSource:
    import lasio

    try:
        las = lasio.read(str(path), ignore_header_errors=False)
        frame = las.df().reset_index()
    except Exception as exc:  # noqa: BLE001 — lasio raises many types for malformed files
        raise InputError(f"not a readable LAS 2.0 file ({type(exc).__name__}: {exc})",
                         file=path, fix="check the ~Curve and ~ASCII sections") from exc
    columns = [c.mnemonic for c in las.curves]
    frame.columns = columns
    units = {c.mnemonic: c.unit for c in las.curves if c.unit}
    units.update({("source", c): "header" for c in list(units)})

    def read(chunk_rows: int) -> Iterator[pd.DataFrame]:
        for start in range(0, len(frame), chunk_rows):
            yield frame.iloc[start:start + chunk_rows].reset_index(drop=True)

    return RawSource(path, "las", columns, units, len(frame), read,
                     depth_index=_depth_index(las.curves[0]) if las.curves else None)


def _depth_index(curve) -> str | None:
    """``"DEPT [M]"`` when a LAS index curve is a depth (by mnemonic or length unit)."""
    unit = (curve.unit or "").strip().upper()
    if curve.mnemonic.strip().upper() in _DEPTH_INDEX or unit in _DEPTH_UNITS:
        return f"{curve.mnemonic} [{curve.unit}]" if curve.unit else curve.mnemonic
    return None


# --------------------------------------------------------------------------- WITSML, DLIS, Excel
def _open_witsml(path: Path) -> RawSource:
    from drillfric.io.witsml import open_witsml

    return open_witsml(path)


def _open_dlis(path: Path) -> RawSource:
    from drillfric.io.dlis import open_dlis

    return open_dlis(path)


def _open_excel(path: Path) -> RawSource:
    from drillfric.io.excel import open_excel

    return open_excel(path)
