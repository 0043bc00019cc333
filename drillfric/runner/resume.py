"""Continue a well's run from the state its last results kept: only the rows appended since
(docs/fleet.md "Only what is new").

A data file that grew is recognised by its content, not its name or date (:func:`mark`,
:func:`changed`):

- a delimited text file: the bytes up to its last complete line, a SHA-256 of them; it
  continues when its first bytes hash the same (a last line not ended yet — the logger
  writing it at the nightly cut — is read for tonight's results, but not continued from:
  :func:`tail`, read again complete the next night);
- a Parquet file rewritten with more rows: a SHA-256 of each row group's bytes, and of the
  last group's values; it continues when the same groups come first — the last one may
  have been rewritten larger, then its first rows must hold the same values;
- a source that states its rows' content (:attr:`~drillfric.io.source.RawSource.digest`:
  a WITSML log, each numbered part of one): the rows read and their digest; it continues
  when its first rows have the same digest;
- a log in parts (a folder of hourly files, a WITSML log in numbered files): each part's
  mark, and the columns and units of the whole; the parts read come first, unchanged but
  the last, which may have grown.

Anything else — no state, another drillfric, configuration or rate, earlier rows changed, a
format read only whole — is run from the start, and the summary says why (summary.json
``resumed``).
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from pathlib import Path

import pandas as pd
import pyarrow.parquet as pq

from drillfric.errors import InputError
from drillfric.io.digest import sha256_prefix
from drillfric.io.seal import broken
from drillfric.io.well import Well

from .engine import Engine, mismatch
from .finish import DirectorySink
from .state import read_state

_BLOCK = 1 << 22
_TAIL_BLOCK = 1 << 16


def mark(well: Well) -> dict:
    """What a run reads of the well's data now (for a folder of files: of each file)."""
    source = well.source
    if source.parts:
        last = len(source.parts) - 1
        return parts_mark(source, [{"name": p.path.name} | source_mark(p, whole=i < last)
                                   for i, p in enumerate(source.parts)])
    # the columns and units too: a Parquet log whose torque unit was corrected in its
    # footer alone kept its row groups' bytes, and a night-2 run its old numbers (issue 30,
    # thirteenth attack)
    return source_mark(source) | {"columns": list(source.columns), "units": _units(source)}


def parts_mark(source, parts: list[dict]) -> dict:
    """The mark of a log in parts (``source``): its columns and units, and ``parts``, each
    part's mark with its ``name``."""
    return {"format": "parts", "columns": list(source.columns), "units": _units(source),
            "parts": parts}


def _units(source) -> dict:
    """The units a source states, by column (JSON-comparable)."""
    return {k: v for k, v in sorted(source.units.items(), key=str) if isinstance(k, str)}


def source_mark(source, *, whole: bool = False) -> dict:
    """What a run reads of one file now (a delimited text file: up to its last complete
    line, unless ``whole`` — a part of a log followed by others)."""
    kind = _kind(source)
    if kind == "csv":
        size = source.path.stat().st_size
        return csv_mark(source.path, size if whole else lines_end(source.path, size)) \
            | {"end": size}
    if kind == "rows":
        return {"format": "rows", "rows": source.rows, "sha256": source.digest(None)}
    return parquet_mark(source.path, source)


def _kind(source) -> str:
    """How a file's growth is recognised: ``"csv"`` (its bytes), ``"rows"`` (its rows'
    digest), ``"parquet"`` (its row groups)."""
    if source.seek == "byte":
        return "csv"
    return "rows" if source.digest is not None else "parquet"


def _end(found: dict) -> int:
    """Where the data a mark recorded ends (bytes or rows)."""
    return found["bytes"] if found["format"] == "csv" else found["rows"]


def unread(well: Well, before: dict | None, now: dict, chunk_rows: int):
    """The raw rows between the marks ``before`` (None: the start) and ``now``."""
    if not well.source.parts:
        start = 0 if before is None else _end(before)
        yield from well.source.window(start, _end(now), chunk_rows)
        return
    k = len(before["parts"]) - 1 if before else 0
    for i, (part, found) in enumerate(zip(well.source.parts, now["parts"], strict=True)):
        if i >= k:
            start = _end(before["parts"][i]) if before and i == k else 0
            yield from part.window(start, _end(found), chunk_rows)


def tail(well: Well, now: dict, chunk_rows: int):
    """The raw rows past the mark ``now`` up to the end of the data: a last line not ended
    yet (fed to :meth:`~drillfric.runner.engine.Engine.close`, not to the state)."""
    source, found = (well.source.parts[-1], now["parts"][-1]) if well.source.parts \
        else (well.source, now)
    if found["format"] == "csv" and found["end"] > found["bytes"]:
        yield from source.window(found["bytes"], found["end"], chunk_rows)


def lines_end(path: Path, size: int) -> int:
    """Where the last complete line (ended by LF or CR) of a file's first ``size`` bytes
    ends (0: none), read backwards from ``size``."""
    with open(path, "rb") as fh:
        end = size
        while end > 0:
            begin = max(end - _TAIL_BLOCK, 0)
            fh.seek(begin)
            block = fh.read(end - begin)
            at = max(block.rfind(b"\n"), block.rfind(b"\r"))
            if at >= 0:
                return begin + at + 1
            end = begin
    return 0


def csv_mark(path: Path, size: int) -> dict:
    """What a run read of a delimited text file: its first ``size`` bytes."""
    last = b""
    if size > 0:
        with open(path, "rb") as fh:
            fh.seek(size - 1)
            last = fh.read(1)
    return {"format": "csv", "bytes": size, "sha256": sha256_prefix(path, size),
            "ends_line": last in (b"\n", b"\r")}


def parquet_mark(path: Path, source) -> dict:
    """What a run reads of a Parquet file: its rows, each row group's rows and byte hash,
    and a hash of the last group's values."""
    meta = pq.ParquetFile(path).metadata
    groups = [{"rows": meta.row_group(i).num_rows, "sha256": _group_hash(path, meta, i)}
              for i in range(meta.num_row_groups)]
    last = groups[-1]["rows"] if groups else 0
    return {"format": "parquet", "rows": meta.num_rows, "groups": groups,
            "last_values": _values_hash(source, meta.num_rows - last, meta.num_rows)}


def _group_hash(path: Path, meta, i: int) -> str:
    """SHA-256 of the bytes of row group ``i`` (its column chunks)."""
    group = meta.row_group(i)
    spans = []
    for c in range(group.num_columns):
        col = group.column(c)
        begin = col.dictionary_page_offset if col.has_dictionary_page else col.data_page_offset
        spans.append((begin, begin + col.total_compressed_size))
    begin, end = min(a for a, _ in spans), max(b for _, b in spans)
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        fh.seek(begin)
        left = end - begin
        while left > 0 and (block := fh.read(min(_BLOCK, left))):
            digest.update(block)
            left -= len(block)
    return digest.hexdigest()


def _values_hash(source, start: int, stop: int) -> str:
    """SHA-256 of the values of rows [start, stop) (column names and contents)."""
    digest = hashlib.sha256()
    for chunk in source.window(start, stop):
        digest.update("\x1f".join(chunk.columns).encode())
        digest.update(pd.util.hash_pandas_object(chunk, index=False).to_numpy().tobytes())
    return digest.hexdigest()


def changed(found: dict | None, well: Well) -> str:
    """Why the well's data does not continue what ``found`` recorded ("" when it does)."""
    if not well.source.parts:
        if found and "columns" in found and (  # (live's tail marks record no columns)
                found["columns"] != list(well.source.columns)
                or found.get("units") != _units(well.source)):
            return "the log's columns or units changed"
        return _source_changed(found, well.source)
    if not found or found.get("format") != "parts":
        return "the earlier run read another kind of data"
    source = well.source
    if found.get("columns") != list(source.columns) or found.get("units") != _units(source):
        return "the log's columns or units changed (a new part brings other curves)"
    names = [p.path.name for p in well.source.parts]
    earlier = [p["name"] for p in found["parts"]]
    if names[:len(earlier)] != earlier:
        return "earlier files of the data folder changed (renamed, removed or inserted)"
    for i, (part, before) in enumerate(zip(well.source.parts, found["parts"], strict=False)):
        why = _source_changed(before, part)
        if not why and i < len(earlier) - 1 and _size_now(part) != _end(before):
            why = "it grew, but it is not the last file read"
        if why:
            return f"{part.path.name}: {why}"
    return ""


def _size_now(source) -> int:
    """A file's length now, as a mark counts it (bytes or rows)."""
    if source.seek == "byte":
        return source.path.stat().st_size
    return source.rows


def _source_changed(found: dict | None, source) -> str:
    """Why one file does not continue what ``found`` recorded ("" when it does)."""
    path = source.path
    if not found or found.get("format") != _kind(source):
        return "the earlier run read another kind of file"
    if found["format"] == "parquet":
        return _parquet_changed(found, path, source)
    if found["format"] == "rows":
        return _rows_changed(found, source)
    size = path.stat().st_size
    if size < found["bytes"]:
        return f"the file is shorter than the {found['bytes']} bytes read before"
    if not found.get("ends_line") and size > found["bytes"]:
        return "the earlier rows did not end with a complete line"
    if csv_mark(path, found["bytes"])["sha256"] != found["sha256"]:
        return "earlier rows changed (the first bytes differ from those read before)"
    return ""


def _rows_changed(found: dict, source) -> str:
    """Why a source marked by its rows' digest does not continue ``found`` ("" if it does)."""
    if source.rows < found["rows"]:
        return f"the data hold fewer rows than the {found['rows']} read before"
    if source.digest(found["rows"]) != found["sha256"]:
        return (f"earlier rows changed (the first {found['rows']} rows or their columns "
                "differ from those read before)")
    return ""


def _parquet_changed(found: dict, path: Path, source) -> str:
    meta = pq.ParquetFile(path).metadata
    if meta.num_rows < found["rows"]:
        return f"the file holds fewer rows than the {found['rows']} read before"
    groups = found["groups"]
    if meta.num_row_groups < len(groups):
        return "the file holds fewer row groups than before"
    start = 0
    for i, group in enumerate(groups):
        same = meta.row_group(i).num_rows == group["rows"] and \
            _group_hash(path, meta, i) == group["sha256"]
        if not same and (i < len(groups) - 1 or meta.row_group(i).num_rows < group["rows"]
                         or _values_hash(source, start, start + group["rows"])
                         != found["last_values"]):
            return f"earlier rows changed (row group {i} differs from the one read before)"
        start += group["rows"]
    return ""


def resumable(well: Well) -> bool:
    """Whether the well's data can be continued where a run stopped (a delimited text file
    in a byte-seekable encoding, a Parquet or WITSML file, or a log in parts of them)."""
    source = well.source
    if well.files.in_memory or source is None:
        return False
    return all(p.seek is not None for p in source.parts or (source,))


def _read_whole(well: Well) -> str:
    """Why a well's data cannot be continued (:func:`resumable` is False)."""
    if well.files.in_memory or well.source is None:
        return "data given in memory"
    fmt = well.source.format
    if fmt == "csv":
        return "a delimited text file in an encoding read from its start (UTF-16, …)"
    return {"dlis": "DLIS is read whole, in an isolated process",
            "excel": "Excel is read whole, in an isolated process"}.get(
                fmt, f"{fmt} is read whole")


def resume(well: Well, previous: Path, sink: DirectorySink, **kw) -> tuple[Engine | None, str]:
    """An engine continuing the run of ``previous`` (a result directory), its output rows
    seeded into ``sink``; or None and why it cannot."""
    if not resumable(well):
        return None, f"its data file is read whole ({_read_whole(well)})"
    engine, why = restored(well, previous / "state", lambda: Engine(well, sink=sink, **kw),
                           rate_hz=kw.get("rate_hz"))
    if engine is None:
        return None, why
    sink.seed(previous, {r.id for r in engine.records})
    engine.resumed = {"from_row": engine.raw_rows, "reason": ""}
    return engine, ""


def restored(well: Well, folder: Path, make: Callable[[], Engine], *,
             rate_hz: float | None = None,
             also: Callable[[dict], str] | None = None) -> tuple[Engine | None, str]:
    """An engine (``make()``) continuing the state saved in ``folder`` (OUT/NAME/state), or
    None and why not: no state, another drillfric, configuration, rate or data (``also``
    adds a check of the state's source), or a state that cannot be read. The state lies in
    OUT, where anyone may have written it (docs/security.md): whatever is wrong with it,
    the well runs from its start and the summary's ``resumed`` says why — never an error.
    """
    if not (folder / "engine.json").is_file():
        return None, "no saved state"
    if why := broken(folder):  # not the state this user's drillfric wrote: not trusted
        return None, why
    try:
        state = read_state(folder)
        why = mismatch(state, well, rate_hz) or changed(state.get("source"), well) or \
            (also(state) if also is not None else "")
        if why:
            return None, why
        engine = make()
        engine.restore(state)
    except InputError as exc:
        return None, exc.message
    except (KeyError, TypeError, ValueError, IndexError, AttributeError,
            RecursionError) as exc:  # a well-formed file, but not a state we wrote
        return None, f"engine state not readable ({type(exc).__name__})"
    return engine, ""
