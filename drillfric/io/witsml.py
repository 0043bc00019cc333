"""WITSML 1.4.1 (and 1.3.1) data objects: logs, trajectories and tubulars.

A WITSML file holds one kind of object under a plural root (``logs``, ``trajectorys``,
``tubulars``, ``bhaRuns``; a singular root such as ``log`` is accepted too), in the
namespace ``http://www.witsml.org/schemas/1series`` or none. Three kinds are read:

- **log** → a :class:`~drillfric.io.source.RawSource` (:func:`open_witsml`): columns are the
  ``logData/mnemonicList`` names in data order (which may differ from the order of the
  ``logCurveInfo`` elements), units the ``unitList``, values the comma-separated ``data``
  rows; the log's ``nullValue`` (or a curve's own) becomes NaN. A date-time index stays
  ISO 8601 text (absolute time, read as UTC by the time base); a depth index makes the
  source depth-indexed (``depth_index``). Several logs in one file: the one holding the
  surface channels is read (:func:`pick_log`). A log split over numbered files
  (``00001.xml``, ``00002.xml`` …) is read as one source by :func:`open_witsml_parts`.
- **trajectory** and **tubular** → the survey and the string
  (:mod:`drillfric.io.witsml_objects`).

Files are untrusted: they are parsed with defusedxml with any DTD refused (a WITSML file
never declares one), so entity expansion ("billion laughs") and external entities cannot
happen; logs are read incrementally (data rows are dropped from the tree once read), so a
large log is held one chunk at a time. Every failure is an InputError naming the file.
"""

from __future__ import annotations

import functools
import hashlib
import io
import json
import re
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from itertools import islice
from pathlib import Path
from xml.etree.ElementTree import ParseError

import numpy as np
import pandas as pd
from defusedxml import DefusedXmlException
from defusedxml.ElementTree import iterparse

from drillfric.errors import InputError
from drillfric.io.channels import CHANNELS, find_column
from drillfric.io.source import RawSource
from drillfric.io.text import printable
from drillfric.units import conversion_factor

#: Namespace of WITSML 1.x data objects (1.3.1 and 1.4.1 share it).
NAMESPACE = "http://www.witsml.org/schemas/1series"
#: Index types of depth-indexed logs.
DEPTH_INDEX_TYPES = frozenset({"measured depth", "vertical depth", "length"})
#: Units meaning "no unit" (the Volve date-time index says "unitless").
_NO_UNIT = frozenset({"", "unitless", "none", "n/a", "-"})
#: The WITSML objects drillfric reads (a log as surface data, a trajectory as the survey,
#: a tubular as the string) and the BHA run it recognises.
OBJECT_KINDS = frozenset({"log", "trajectory", "tubular", "bhaRun"})
#: A numbered part of an exported log: ``00001.xml`` (a WITSML store's folder of one log) or
#: ``NAME_1.xml`` (parts named after their log).
_PART_FILE = re.compile(r"^(?:(?P<log>.+)_)?(?P<number>\d+)\.xml$", re.IGNORECASE)
FIX_EXPORT = "export the object again from the WITSML store (version 1.4.1)"


# --------------------------------------------------------------------------- parsing
def local_name(tag: str) -> str:
    """Element name without its namespace."""
    return tag.rsplit("}", 1)[-1]


def _events(path: Path, events=("start", "end")) -> Iterator[tuple[str, object]]:
    """Hardened incremental parse: defusedxml, any DTD refused; errors → InputError."""
    try:
        yield from iterparse(str(path), events=events, forbid_dtd=True)
    except DefusedXmlException as exc:
        raise InputError("XML declares a DTD or entities, which a WITSML file never does "
                         "(refused: entity expansion and external entities are unsafe)",
                         file=path, fix=FIX_EXPORT) from exc
    except ParseError as exc:
        line, column = exc.position
        raise InputError(f"not well-formed XML (line {line}, column {column}); the file may "
                         "be truncated", file=path, fix=FIX_EXPORT) from exc


def parse_tree(path: Path):
    """Element tree of an object file (trajectory, tubular), hardened; a log's rows
    (``logData``) leave the tree once read, so a log file that also holds a trajectory or
    a tubular is held without its data."""
    root = None
    stack: list = []
    for event, elem in _events(path):
        if event == "start":
            root = elem if root is None else root
            stack.append(elem)
            continue
        stack.pop()
        if stack and local_name(elem.tag) == "logData":
            stack[-1].remove(elem)
    if root is None:
        raise InputError("XML file has no root element", file=path, fix=FIX_EXPORT)
    return root


def _root(path: Path):
    """The root element, read from the file's first start tag only."""
    for _, elem in _events(path, ("start",)):
        return elem
    raise InputError("XML file has no root element", file=path, fix=FIX_EXPORT)


def object_kind(path) -> str:
    """Kind of WITSML object a file holds (``"log"``, ``"trajectory"``, ``"tubular"`` …).

    Reads only the root tag: a plural root names its objects (``logs`` → ``"log"``,
    ``trajectorys`` → ``"trajectory"``), a singular root is the object itself; any other
    root (a wrapper holding several kinds, see :func:`object_kinds`) is named as it is.

    Raises
    ------
    InputError
        Not XML, a DTD, or not a WITSML 1.x object (e.g. WITSML 2.0).
    """
    path = Path(path)
    root = _root(path)
    check_namespace(root, path)
    return _root_kind(local_name(root.tag)) or local_name(root.tag)


def _root_kind(name: str) -> str | None:
    """The object kind a standard root holds (``logs``/``log`` → ``"log"``), else None."""
    single = name[:-1] if name.endswith("s") else name
    return single if single in OBJECT_KINDS else None


def object_kinds(path) -> frozenset[str]:
    """The kinds of WITSML object (:data:`OBJECT_KINDS`) a file holds.

    A standard file holds one kind under a plural root (read from the root tag alone); a
    file whose root is not one (a wrapper such as ``<witsml>`` around ``<logs>`` and
    ``<trajectorys>``) is scanned, its log rows dropped as they are read.

    Raises
    ------
    InputError
        Not XML, a DTD, or not a WITSML 1.x object.
    """
    path = Path(path)
    root = _root(path)
    check_namespace(root, path)
    kind = _root_kind(local_name(root.tag))
    if kind is not None:
        return frozenset({kind})
    found: set[str] = set()
    stack: list = []
    for event, elem in _events(path):
        if event == "start":
            found |= {local_name(elem.tag)} & OBJECT_KINDS
            stack.append(elem)
            continue
        stack.pop()
        if stack and local_name(elem.tag) in OBJECT_KINDS:
            stack[-1].remove(elem)
    return frozenset(found)


def check_namespace(root, path: Path) -> None:
    namespace = root.tag[1:].split("}")[0] if root.tag.startswith("{") else ""
    if namespace not in ("", NAMESPACE):
        version = "WITSML 2.x" if "energyml" in namespace else "an XML file that is not WITSML"
        raise InputError(f"{version} (namespace not {NAMESPACE}); drillfric reads WITSML "
                         "1.3.1/1.4.1 objects", file=path, fix=FIX_EXPORT)


def measure(elem, name: str, path: Path, *, required: bool = True):
    """(value, uom) of a measure child such as ``<md uom="m">12.5</md>`` (None if absent)."""
    child = next((c for c in elem if local_name(c.tag) == name), None)
    if child is None or not (child.text or "").strip():
        if required:
            raise InputError(f"{local_name(elem.tag)} without {name}", file=path, fix=FIX_EXPORT)
        return None
    try:
        value = float(child.text)
    except ValueError as exc:
        raise InputError(f"{local_name(elem.tag)}/{name} is not a number", file=path,
                         fix=FIX_EXPORT) from exc
    uom = child.get("uom")
    if not uom:
        raise InputError(f"{local_name(elem.tag)}/{name} has no uom attribute", file=path,
                         fix=FIX_EXPORT)
    return value, uom


def text_of(elem, name: str) -> str | None:
    child = next((c for c in elem if local_name(c.tag) == name), None)
    return None if child is None or child.text is None else child.text.strip()


def unit_factor(uom: str, kind: str, what: str, path: Path) -> float:
    try:
        return conversion_factor(uom, kind)
    except InputError as exc:
        raise InputError(f"{what}: {exc.problem}", file=path, fix=FIX_EXPORT) from exc


# --------------------------------------------------------------------------- logs
@dataclass(frozen=True)
class LogHeader:
    """What a WITSML ``<log>`` says about its data, read without keeping the data.

    Attributes
    ----------
    position : int
        0-based position of the log in its file.
    uid, name : str
    index_type : str
        ``"date time"``, ``"measured depth"``, ``"elapsed time"`` … (lower case).
    index_curve : str
        Mnemonic of the index column.
    direction : str
        ``"increasing"`` or ``"decreasing"``.
    mnemonics, units : tuple of str
        Columns in data order and their units (``""`` when none).
    nulls : tuple
        Null value per column (text) or None.
    text_columns : tuple of str
        Columns kept as text (date-time and string curves, the date-time index).
    rows : int
        Number of ``data`` rows.
    first_index, last_index : str or None
        Index value of the first and last data row.
    wellbore : str
        ``nameWellbore`` of the log, else its ``nameWell`` (``""`` when neither).
    rows_sha256 : str
        SHA-256 (hex) of the ``data`` rows' texts (each stripped, followed by a newline).
    curve_units : tuple of str
        The unit each column's ``logCurveInfo`` states when :attr:`units` are the
        ``unitList``'s (``""`` where none or the same): a second statement of the unit, which
        must agree (:func:`drillfric.io.channels.map_channels` refuses two).
    """

    position: int
    uid: str
    name: str
    index_type: str
    index_curve: str
    direction: str
    mnemonics: tuple[str, ...]
    units: tuple[str, ...]
    nulls: tuple[str | None, ...]
    text_columns: tuple[str, ...]
    rows: int
    first_index: str | None
    last_index: str | None
    wellbore: str = ""
    rows_sha256: str = ""
    curve_units: tuple[str, ...] = ()

    @property
    def depth_indexed(self) -> bool:
        """Whether the index is a depth."""
        return self.index_type in DEPTH_INDEX_TYPES

    @property
    def index_unit(self) -> str:
        """Unit of the index column (``""`` when none)."""
        return self.units[self.mnemonics.index(self.index_curve)]


class _LogScan:
    """Accumulates one ``<log>``'s header while its elements stream past."""

    _FIELDS = ("name", "indexType", "indexCurve", "direction", "nullValue", "nameWell",
               "nameWellbore")

    def __init__(self, position: int, uid: str):
        self.position, self.uid = position, uid
        self.fields: dict[str, str] = {}
        self.curves: list[dict] = []
        self.mnemonic_list: list[str] | None = None
        self.unit_list: list[str] | None = None
        self.rows = 0
        self.first_row: str | None = None
        self.last_row: str | None = None
        self.rows_sha256 = hashlib.sha256()

    def end(self, name: str, parent: str, elem) -> None:
        text = (elem.text or "").strip()
        if parent == "log" and name in self._FIELDS:
            self.fields[name] = text
        elif parent == "log" and name == "logCurveInfo":
            self.curves.append({local_name(c.tag): (c.text or "").strip() for c in elem})
        elif parent == "logData" and name == "mnemonicList":
            self.mnemonic_list = [m.strip() for m in text.split(",")]
        elif parent == "logData" and name == "unitList":
            self.unit_list = [u.strip() for u in text.split(",")]
        elif parent == "logData" and name == "data":
            self.rows += 1
            self.first_row = text if self.first_row is None else self.first_row
            self.last_row = text
            self.rows_sha256.update(text.encode() + b"\n")

    def header(self, path: Path) -> LogHeader:
        names, units = self._columns(path)
        curves = {c.get("mnemonic", ""): c for c in self.curves}
        stated = tuple(curves.get(n, {}).get("unit", "") if self.unit_list is not None
                       and self.mnemonic_list is not None else "" for n in names)
        index_type = self.fields.get("indexType", "").lower()
        index_curve = self.fields.get("indexCurve") or names[0]
        if index_curve not in names:
            raise InputError(f"log index curve '{index_curve}' is not among the data columns",
                             file=path, fix=FIX_EXPORT)
        log_null = self.fields.get("nullValue") or None
        nulls = tuple(curves.get(n, {}).get("nullValue") or log_null for n in names)
        dated = index_type.replace(" ", "") == "datetime"
        text = tuple(n for n in names
                     if curves.get(n, {}).get("typeLogData", "") in ("date time", "string")
                     or (n == index_curve and dated))
        at = names.index(index_curve)
        return LogHeader(self.position, self.uid, self.fields.get("name", ""), index_type,
                         index_curve, self.fields.get("direction", "increasing").lower(),
                         tuple(names), tuple(units), nulls, text, self.rows,
                         _field(self.first_row, at), _field(self.last_row, at),
                         self.fields.get("nameWellbore") or self.fields.get("nameWell", ""),
                         self.rows_sha256.hexdigest(), stated)

    def _columns(self, path: Path) -> tuple[list[str], list[str]]:
        """Column names in data order and their units (mnemonicList, else logCurveInfo)."""
        if self.mnemonic_list is not None:
            names = self.mnemonic_list
            by_curve = {c.get("mnemonic", ""): c.get("unit", "") for c in self.curves}
            units = self.unit_list or [by_curve.get(n, "") for n in names]
        else:  # WITSML 1.3.1: the curves in columnIndex (else document) order
            order = sorted(self.curves, key=lambda c: parse_int(c.get("columnIndex"), 0))
            names = [c.get("mnemonic", "") for c in order]
            units = [c.get("unit", "") for c in order]
        if not names or not all(names):
            raise InputError("log without column mnemonics (no mnemonicList or logCurveInfo)",
                             file=path, fix=FIX_EXPORT)
        if len(units) != len(names):
            raise InputError(f"log unitList has {len(units)} units for {len(names)} "
                             "mnemonics", file=path, fix=FIX_EXPORT)
        if len(set(names)) < len(names):
            raise InputError("log mnemonicList repeats a mnemonic", file=path,
                             fix=FIX_EXPORT)
        return names, units


def parse_int(text: str | None, default: int) -> int:
    try:
        return int(text)
    except (TypeError, ValueError):
        return default


def _field(row: str | None, at: int) -> str | None:
    if row is None:
        return None
    fields = row.split(",")
    return fields[at].strip() if at < len(fields) else None


def read_log_headers(path) -> list[LogHeader]:
    """Headers of every ``<log>`` in a WITSML file (one pass, data rows not kept).

    Raises
    ------
    InputError
        Not WITSML, unsafe XML, malformed, or a file holding no log.
    """
    path = Path(path)
    stack: list = []
    logs: list[LogHeader] = []
    scan: _LogScan | None = None
    for event, elem in _events(path):
        name = local_name(elem.tag)
        if event == "start":
            if not stack:
                check_namespace(elem, path)
            if name == "log" and scan is None:
                scan = _LogScan(len(logs), elem.get("uid", ""))
            stack.append(elem)
            continue
        stack.pop()
        parent = local_name(stack[-1].tag) if stack else ""
        if scan is not None:
            scan.end(name, parent, elem)
        if name == "log" and scan is not None:
            logs.append(scan.header(path))
            scan = None
        if stack and name in ("data", "log", "logCurveInfo"):
            stack[-1].remove(elem)  # keep memory bounded: read elements leave the tree
    if not logs:
        kind = object_kind(path)
        raise InputError(f"WITSML file holds {kind} objects, not a log", file=path,
                         fix="give a WITSML log as the surface data (a trajectory is a "
                             "survey: --survey or [survey] file)")
    return logs


def pick_log(logs: list[LogHeader]) -> LogHeader:
    """The log to read from a file holding several: the surface channels' log.

    Ranked by: time-indexed before depth-indexed; most of the required channels (time,
    surface RPM, surface torque) recognised; most channels recognised; most rows.
    """
    def found(log: LogHeader, keys) -> int:
        count = 0
        for key in keys:
            try:
                count += find_column(list(log.mnemonics), key, {}) is not None
            except InputError:  # two columns claim the channel: it is there
                count += 1
        return count

    required = [c.key for c in CHANNELS if c.required]
    return max(logs, key=lambda log: (not log.depth_indexed, found(log, required),
                                      found(log, [c.key for c in CHANNELS]), log.rows))


def _choose(logs: list[LogHeader], log: str | None, path: Path) -> LogHeader:
    if log is None:
        return pick_log(logs)
    for header in logs:
        if log in (header.uid, header.name):
            return header
    names = ", ".join(f"'{printable(h.name or h.uid)}'" for h in logs)
    raise InputError(f"no log '{printable(log)}' in the file (it holds {names})", file=path,
                     fix="give the uid or name of one of the listed logs")


def _row_texts(path: Path, position: int) -> Iterator[str]:
    """The ``data`` rows of the log at ``position``, streamed (read rows leave the tree)."""
    stack: list = []
    seen = -1
    for event, elem in _events(path):
        name = local_name(elem.tag)
        if event == "start":
            seen += name == "log"
            stack.append(elem)
            continue
        stack.pop()
        if name == "data" and seen == position and stack and local_name(stack[-1].tag) == "logData":
            yield elem.text or ""
        if name == "log" and seen == position:
            return
        if stack and name in ("data", "log", "logCurveInfo"):
            stack[-1].remove(elem)


def _frame(rows: list[str], header: LogHeader, path: Path) -> pd.DataFrame:
    """One block of ``data`` rows as a frame: numbers as floats, text columns as text."""
    names = list(header.mnemonics)
    text = {i: str for i, n in enumerate(names) if n in header.text_columns}
    try:
        frame = pd.read_csv(io.StringIO("\n".join(rows)), header=None, dtype=text,
                            skipinitialspace=True, skip_blank_lines=False)
    except pd.errors.EmptyDataError:  # only empty <data/> rows
        frame = pd.DataFrame(index=range(len(rows)))
    except (pd.errors.ParserError, ValueError) as exc:
        raise InputError(f"a log data row has more values than the {len(names)} names of "
                         "its mnemonicList", file=path, fix=FIX_EXPORT) from exc
    if frame.shape[1] > len(names):
        raise InputError(f"log data rows have {frame.shape[1]} values for the {len(names)} "
                         "names of the mnemonicList", file=path, fix=FIX_EXPORT)
    frame = frame.set_axis(names[:frame.shape[1]], axis=1).reindex(columns=names)
    for column, null in zip(names, header.nulls, strict=True):
        if null is not None:
            frame[column] = _without_null(frame[column], null)
    return frame


def _without_null(values: pd.Series, null: str) -> pd.Series:
    """``values`` with the null value replaced by NaN (compared as numbers when numeric)."""
    if pd.api.types.is_numeric_dtype(values):
        try:
            return values.mask(values == float(null))
        except ValueError:
            return values
    return values.mask(values.astype("string").str.strip() == null.strip())


def _chunks(path: Path, header: LogHeader, chunk_rows: int, start: int = 0,
            stop: int | None = None) -> Iterator[pd.DataFrame]:
    """The log's data rows [start, stop) (None: to the end) in frames of ``chunk_rows``."""
    rows: list[str] = []
    for text in islice(_row_texts(path, header.position), start, stop):
        rows.append(text)
        if len(rows) == chunk_rows:
            yield _frame(rows, header, path)
            rows = []
    if rows:
        yield _frame(rows, header, path)


def _units(header: LogHeader) -> dict:
    """The units the log states per column (its ``unitList``, else its ``logCurveInfo``),
    and ``("also", column)`` → (unit, where) for a column whose ``logCurveInfo`` states
    another spelling than the ``unitList``: :func:`drillfric.io.channels.map_channels`
    refuses the two when they differ (a log saying kft·lbf in one and kN·m in the other was
    read in the ``unitList``'s unit in silence, μ_k 0.203 for 0.28: issue 30, tenth attack)."""
    units: dict = {}
    curve_units = header.curve_units or ("",) * len(header.mnemonics)
    for column, unit, curve in zip(header.mnemonics, header.units, curve_units, strict=True):
        if unit.strip().lower() not in _NO_UNIT and column not in header.text_columns:
            units[column] = unit.strip()
            units[("source", column)] = "header"
        curve = curve.strip()
        if not curve or curve.lower() in _NO_UNIT or column in header.text_columns \
                or curve == unit.strip():
            continue
        if column in units:
            units[("source", column)] = "unitList"
            units[("also", column)] = (curve, "logCurveInfo")
        else:  # the unitList leaves it blank
            units[column], units[("source", column)] = curve, "logCurveInfo"
    return units


def _depth_index(header: LogHeader) -> str | None:
    """The depth index column with its unit (``"DEPT [m]"``), None for a time log."""
    if not header.depth_indexed:
        return None
    unit = header.index_unit
    return f"{header.index_curve} [{unit}]" if unit else header.index_curve


def _source(path: Path, header: LogHeader) -> RawSource:
    def read(chunk_rows: int, start: int = 0, stop: int | None = None):
        return _chunks(path, header, chunk_rows, start, stop)

    return RawSource(path, "witsml", list(header.mnemonics), _units(header), header.rows,
                     read, depth_index=_depth_index(header), seek="row",
                     digest=_digest(path, header))


def _digest(path: Path, header: LogHeader) -> Callable[[int | None], str]:
    """:attr:`RawSource.digest` of a log: what the header says of its columns and the rows'
    texts (the first ``n``: read again up to there; all: hashed by the header scan)."""
    described = json.dumps([header.index_type, header.index_curve, header.direction,
                            header.mnemonics, header.units, header.nulls,
                            header.text_columns]).encode()

    def digest(n: int | None = None) -> str:
        rows = header.rows_sha256
        if n is not None and n != header.rows:
            texts = hashlib.sha256()
            for text in islice(_row_texts(path, header.position), n):
                texts.update(text.strip().encode() + b"\n")
            rows = texts.hexdigest()
        return hashlib.sha256(described + rows.encode()).hexdigest()

    return digest


def open_witsml(path, *, log: str | None = None) -> RawSource:
    """Open a WITSML log file as a raw source (header read now, data rows on demand).

    Parameters
    ----------
    path : str or Path
        A WITSML 1.4.1/1.3.1 file holding one or more ``<log>`` objects.
    log : str, optional
        uid or name of the log to read; default :func:`pick_log`.

    Raises
    ------
    InputError
        Unsafe or malformed XML, not WITSML 1.x, no log, inconsistent column lists.
    """
    path = Path(path)
    header = _choose(read_log_headers(path), log, path)
    if header.rows == 0:
        raise InputError(f"WITSML log '{header.name or header.uid}' has no data rows",
                         file=path, fix="export the log with its logData")
    return _source(path, header)


# --------------------------------------------------------------------------- multi-file logs
def _part_key(path: Path) -> tuple[str, int] | None:
    """(log name, number) of a numbered part file (``""`` for ``00001.xml``), else None."""
    match = _PART_FILE.match(path.name)
    return None if match is None else (match["log"] or "", int(match["number"]))


def _numbered(folder: Path, log: str) -> list[Path]:
    """The numbered part files of ``log`` in ``folder`` (``log`` ``""``: ``00001.xml`` …), by
    number."""
    parts = [(key[1], p) for p in folder.iterdir()
             if (key := _part_key(p)) is not None and key[0] == log and p.is_file()]
    return [p for _, p in sorted(parts)]


def split_log(path) -> tuple[Path, tuple[Path, ...]] | None:
    """The log a well given as ``path`` reads from several numbered files, if it does.

    A folder holding numbered parts (``00001.xml``, ``00002.xml`` … as WITSML stores
    export a growing log) is one log, named by the folder; so is the folder of a numbered
    part file when it holds another numbered part. A file ``NAME_1.xml`` beside
    ``NAME_2.xml`` … is one log with its siblings, named ``NAME`` (the folder / ``NAME``,
    a path that need not exist). A lone numbered file is read alone: None.

    Returns
    -------
    (name, parts) or None
        The path naming the log (the folder, or ``folder / NAME``) and its parts by number.
    """
    path = Path(path)
    if path.is_dir():
        parts = _numbered(path, "")
        return (path, tuple(parts)) if parts else None
    key = _part_key(path)
    if key is None or not path.is_file():
        return None
    parts = _numbered(path.parent, key[0])
    if len(parts) < 2:
        return None
    return (path.parent / key[0] if key[0] else path.parent), tuple(parts)


def log_title(path) -> str:
    """A well name from a WITSML log file: its wellbore and log names (``"NO 15/9-F-4
    GwdTime"``), for a log whose file names (numbered parts) say nothing; ``""`` if none."""
    header = pick_log(read_log_headers(path))
    return " ".join(t for t in (header.wellbore, header.name) if t)


def witsml_log_parts(folder) -> list[Path]:
    """The numbered part files of one exported log (``00001.xml``, ``00002.xml`` …), by number.

    WITSML stores export a growing log as numbered chunk files in the log's folder; pass
    the result to :func:`open_witsml_parts`.

    Raises
    ------
    InputError
        No numbered ``.xml`` file in the folder.
    """
    folder = Path(folder)
    parts = _numbered(folder, "")
    if not parts:
        raise InputError("no numbered WITSML part files (00001.xml, 00002.xml …) in the "
                         "folder", file=folder, fix="give the folder of one exported log")
    return parts


def _index_keys(values: pd.Series, header: LogHeader) -> np.ndarray:
    """Index values as sortable numbers (ns since 1970 for date-time indexes)."""
    if header.index_curve in header.text_columns:
        stamps = pd.to_datetime(values.astype("string").str.strip(), format="ISO8601",
                                utc=True, errors="coerce")
        ns = stamps.dt.tz_convert(None).to_numpy(dtype="datetime64[ns]")
        out = ns.astype("int64").astype(float)
        out[np.isnat(ns)] = np.nan
        return out
    return pd.to_numeric(values, errors="coerce").to_numpy(dtype=float)


def _key(header: LogHeader, text: str | None) -> float:
    """One index value as :func:`_index_keys` gives it (NaN: none)."""
    return float(_index_keys(pd.Series([text], dtype=object), header)[0])


def _first_key(header: LogHeader) -> float:
    key = _key(header, header.first_index)
    return key if np.isfinite(key) else np.inf


def _reaches(paths: list[Path], headers: list[LogHeader], sign: float
             ) -> Callable[[int], float]:
    """``before(i)``: the furthest index (× ``sign``) of the parts before part ``i``, past
    which part ``i``'s rows are kept. A part reaches its last row's index (WITSML orders a
    log's rows by ``direction``); a part whose last row has none is read for it."""
    @functools.cache
    def reach(j: int) -> float:
        key = sign * _key(headers[j], headers[j].last_index)
        if np.isfinite(key):
            return key
        return max((float(np.nanmax(sign * _index_keys(c[headers[j].index_curve],
                                                        headers[j]), initial=-np.inf))
                    for c in _chunks(paths[j], headers[j], 100_000)), default=-np.inf)

    return lambda i: max((reach(j) for j in range(i)), default=-np.inf)


def _same_log(headers: list[LogHeader], paths: list[Path]) -> None:
    first = headers[0]
    for header, path in zip(headers[1:], paths[1:], strict=True):
        if first.uid and header.uid and header.uid != first.uid:
            raise InputError(f"part is log '{header.uid}', the first part is log "
                             f"'{first.uid}'", file=path,
                             fix="give the parts of one log only")
        if (header.index_type, header.index_curve) != (first.index_type, first.index_curve):
            raise InputError("part has another index than the first part", file=path,
                             fix="give the parts of one log only")


def _merged_units(headers: list[LogHeader], paths: list[Path]) -> tuple[list[str], dict]:
    columns: list[str] = []
    units: dict = {}
    for header, path in zip(headers, paths, strict=True):
        for column, unit in _units(header).items():
            if not isinstance(column, tuple) and units.get(column, unit) != unit:
                raise InputError(f"part gives {printable(column)} in '{printable(unit)}', an "
                                 f"earlier part in '{printable(units[column])}'", file=path,
                                 fix="re-export the log with one unit per curve")
            units[column] = unit
        columns += [c for c in header.mnemonics if c not in columns]
    return columns, units


def open_witsml_parts(paths, *, log: str | None = None) -> RawSource:
    """One raw source from the parts of a log split over several files.

    Parts are read in index order (by their first index value, reversed for a decreasing
    log), whatever the order of ``paths``; a part's rows whose index does not go past the
    last index of the parts before it (an overlap) are dropped. Columns are the union of
    the parts' columns (NaN where a part lacks one). The source's ``parts`` are the parts
    in that order, each read by row number (its ``data`` rows, overlap dropped), so that a
    fleet re-run reads only a new part's rows (docs/fleet.md "Only what is new").

    Parameters
    ----------
    paths : iterable of str or Path
        Part files, e.g. :func:`witsml_log_parts` of the log's folder.
    log : str, optional
        uid or name of the log in each part (default :func:`pick_log`).

    Raises
    ------
    InputError
        A part is unreadable, belongs to another log, or states another unit for a curve.
    """
    paths = [Path(p) for p in paths]
    if not paths:
        raise InputError("no WITSML part files given", fix="give the parts of one log")
    headers = [_choose(read_log_headers(p), log, p) for p in paths]
    _same_log(headers, paths)
    order = sorted(range(len(paths)), key=lambda i: _first_key(headers[i]),
                   reverse=headers[0].direction == "decreasing")
    paths, headers = [paths[i] for i in order], [headers[i] for i in order]
    columns, units = _merged_units(headers, paths)
    sign = -1.0 if headers[0].direction == "decreasing" else 1.0
    before = _reaches(paths, headers, sign)
    depth = _depth_index(headers[0])

    def part(i: int) -> RawSource:
        path, header = paths[i], headers[i]

        def read(chunk_rows: int, start: int = 0, stop: int | None = None
                 ) -> Iterator[pd.DataFrame]:
            last = before(i)
            for chunk in _chunks(path, header, chunk_rows, start, stop):
                keys = sign * _index_keys(chunk[header.index_curve], header)
                kept = chunk[~(keys <= last)].reindex(columns=columns)
                if len(kept):
                    yield kept.reset_index(drop=True)

        return RawSource(path, "witsml", columns, units, header.rows, read, depth_index=depth,
                         seek="row", digest=_digest(path, header))

    parts = tuple(part(i) for i in range(len(paths)))

    def read(chunk_rows: int) -> Iterator[pd.DataFrame]:
        for source in parts:
            yield from source.chunks(chunk_rows)

    return RawSource(paths[0], "witsml", columns, units, None, read, depth_index=depth,
                     parts=parts)
