"""Result files of ``drillfric run`` written safely: atomic, marked, never outside ``--out``.

A well's results go to ``OUT/NAME`` (NAME one safe path component, :func:`drillfric.io.well.
safe_name`). They are written into a hidden temporary directory beside it and renamed into
place at the end (:class:`ResultDirectory`), so a well directory is complete or absent:

- every directory drillfric writes carries a marker file (:data:`MARKER`); an existing
  ``OUT/NAME`` is replaced only when it carries the marker — a directory, file or link that
  drillfric did not write is never replaced or removed;
- the swap (old result aside, new one in, old one removed) happens under an exclusive lock
  on OUT, so concurrent writers of one well do not trip over each other;
- temporary directories of runs that were killed (their process is gone) are removed by the
  next run of that well; an interrupted run (SIGINT, SIGTERM turned into KeyboardInterrupt
  by the CLI) removes its own;
- a failure to write (disk full, read-only, name too long, a file where a directory must
  go) becomes one :class:`~drillfric.errors.OutputError` naming the path and the fix.

docs/security.md describes the rules; the column schema is :mod:`drillfric.result`.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import shutil
import socket
import time
import uuid
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from drillfric.errors import InputError, OutputError
from drillfric.io.atomic import is_write_problem, output_error, own_file, replacing
from drillfric.io.digest import sha256_prefix
from drillfric.io.locks import lock_directory
from drillfric.result import ESTIMATE_COLUMNS, segment_table

#: The file that marks a directory as written by drillfric (JSON: version, well, state).
MARKER = ".drillfric-result"
#: Age after which a temporary directory of another host counts as abandoned [s] (on
#: storage shared with a remote cluster, another host's process cannot be asked).
FOREIGN_STALE_S = 86400.0
_TMP, _OLD = ".tmp-", ".old-"
_HOST = hashlib.sha256(socket.gethostname().encode()).hexdigest()[:6]


def file_sha256(path: str | Path) -> str:
    """SHA-256 of a file, read in blocks (constant memory; a file already hashed in this
    process, or a prefix of it, is not read again: :mod:`drillfric.io.digest`)."""
    return sha256_prefix(path)


def jsonable(value):
    """Plain JSON value: NaN/inf → None, numpy scalars → Python, tuples → lists."""
    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist())
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, Path):
        return str(value)
    return value


# --------------------------------------------------------------------------- directories
def _marker(path: Path, well: str, state: str) -> None:
    from drillfric._version import __version__

    (path / MARKER).write_text(json.dumps({"drillfric": __version__, "well": well,
                                           "state": state}) + "\n", encoding="utf-8")


def is_result_dir(path: Path) -> bool:
    """Whether ``path`` is a real directory (not a link) that drillfric wrote: it carries
    :data:`MARKER`, or (results of versions before the marker) a summary.json of a run."""
    if not path.is_dir() or path.is_symlink():
        return False
    if (path / MARKER).is_file():
        return True
    try:
        summary = read_json(path / "summary.json")
    except InputError:
        return False
    return {"drillfric_version", "segments"} <= set(summary)


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def remove_stale(out_root: Path, dir_name: str | None = None) -> None:
    """Remove temporary and set-aside directories of ``dir_name`` (all wells when None) left
    by runs whose process is gone — only those carrying drillfric's marker."""
    if not out_root.is_dir():
        return
    prefix = "." if dir_name is None else f".{dir_name}"
    for entry in out_root.iterdir():
        name = entry.name
        if not name.startswith(prefix) or (_TMP not in name and _OLD not in name):
            continue
        head, _, tail = name.rpartition(_TMP if _TMP in name else _OLD)
        if dir_name is not None and head != f".{dir_name}":
            continue
        if _TMP in name and _in_use(entry, tail):
            continue  # another live run is writing it
        if is_result_dir(entry):
            shutil.rmtree(entry, ignore_errors=True)


def _token() -> str:
    """``PID-HOST-RANDOM`` of a temporary directory name."""
    return f"{os.getpid()}-{_HOST}-{uuid.uuid4().hex[:8]}"


def _in_use(entry: Path, tail: str) -> bool:
    """Whether the run that made a temporary directory may still be writing it."""
    pid, host, *_ = tail.split("-") + ["", ""]
    if host != _HOST:  # another machine's run: only abandoned ones are removed
        try:
            return time.time() - entry.stat().st_mtime < FOREIGN_STALE_S
        except OSError:
            return False
    return pid.isdigit() and _pid_alive(int(pid))


class ResultDirectory:
    """``with ResultDirectory(out, name, well) as tmp:`` write into ``tmp``; on success it
    becomes ``out/name`` atomically, on any exception nothing is left behind.

    Parameters
    ----------
    out_root : Path
        ``--out`` (created with its missing parents; removed again when the run fails and
        they are left empty).
    dir_name : str
        A safe path component (:func:`drillfric.io.well.safe_name`).
    well : str
        The well's name, recorded in the marker.

    Raises
    ------
    OutputError
        ``out/name`` exists and was not written by drillfric, or writing failed.
    """

    def __init__(self, out_root, dir_name: str, well: str):
        self.out_root = Path(out_root)
        self.final = self.out_root / dir_name
        self.dir_name = dir_name
        self.well = well
        self.tmp: Path | None = None
        self._created: list[Path] = []

    def __enter__(self) -> Path:
        try:
            if self.out_root.is_dir():
                with lock_directory(self.out_root):  # not while another writer swaps
                    self.check_replaceable()
            else:
                self.check_replaceable()
            self._created = missing_dirs(self.out_root)
            self.out_root.mkdir(parents=True, exist_ok=True)
            remove_stale(self.out_root, self.dir_name)
            self.tmp = self.out_root / f".{self.dir_name}{_TMP}{_token()}"
            self.tmp.mkdir()
            _marker(self.tmp, self.well, "incomplete")
        except OSError as exc:
            self._discard()
            raise output_error(exc, self.out_root) from None
        return self.tmp

    def check_replaceable(self) -> None:
        """Refuse early when ``out/name`` is something drillfric did not write."""
        if self.out_root.exists() and not self.out_root.is_dir():
            raise OutputError("cannot write results: a file stands where the output "
                              "directory must go", file=self.out_root,
                              fix="remove or rename that file, or choose another --out")
        if os.path.lexists(self.final) and not is_result_dir(self.final):
            raise OutputError("exists and was not written by drillfric: not replaced",
                              file=self.final, fix="move it away or choose another --out")

    def __exit__(self, exc_type, exc, tb):
        if exc_type is not None:
            self._discard()
            if isinstance(exc, OSError) and _is_output_problem(exc, self.out_root):
                raise output_error(exc, self.final) from None
            return False
        try:
            _marker(self.tmp, self.well, "complete")
            self._swap()
        except OSError as err:
            self._discard()
            raise output_error(err, self.final) from None
        except BaseException:
            self._discard()
            raise
        return False

    def _swap(self) -> None:
        old = self.out_root / f".{self.dir_name}{_OLD}{_token()}"
        with lock_directory(self.out_root):
            self.check_replaceable()  # another process may have put something there
            if os.path.lexists(self.final):
                os.replace(self.final, old)
            os.replace(self.tmp, self.final)
        self.tmp = None
        shutil.rmtree(old, ignore_errors=True)

    def _discard(self) -> None:
        if self.tmp is not None:
            shutil.rmtree(self.tmp, ignore_errors=True)
            self.tmp = None
        remove_empty(self._created)


def _is_output_problem(exc: OSError, out_root: Path) -> bool:
    """An OSError about the results (a path under OUT, or a full/read-only disk), not about
    an input file."""
    name = exc.filename
    if name is not None:
        try:
            Path(name).resolve().relative_to(out_root.resolve())
            return True
        except ValueError:
            return False
    return is_write_problem(exc)


def missing_dirs(path: Path) -> list[Path]:
    """``path`` and its ancestors that do not exist yet, deepest first (to undo with
    :func:`remove_empty` when nothing could be written)."""
    missing = []
    for folder in (Path(path), *Path(path).parents):
        if folder.exists():
            break
        missing.append(folder)
    return missing


def remove_empty(folders: list[Path]) -> None:
    """Remove ``folders`` (deepest first) while they are empty; another writer's files stay."""
    for folder in folders:
        try:
            folder.rmdir()
        except OSError:
            return


def name_key(name: str) -> str:
    """``name`` as a file system compares it: NFC (macOS folds NFD into it) and each
    character's simple case mapping — one character to one character, as NTFS's upcase
    table and APFS's case folding do. ``casefold`` expands ``ß`` to ``ss`` and had taken
    ``Maß`` and ``MASS`` for one directory, which no file system does (issue 30, eleventh
    attack).

    Examples
    --------
    >>> name_key("Maß") == name_key("MASS"), name_key("WELL") == name_key("well")
    (False, True)
    >>> name_key("Ma\u1e9e") == name_key("Maß"), name_key("ΟΔΟΣ") == name_key("οδος")
    (True, True)
    """
    import unicodedata

    def simple(c: str, how) -> str:
        mapped = how(c)
        return mapped if len(mapped) == 1 else c

    return "".join(simple(simple(c, str.upper), str.lower)
                   for c in unicodedata.normalize("NFC", name))


def collisions(outputs: list[tuple[str, str]]) -> dict[int, tuple[int, str]]:
    """Of ``outputs`` — (dir_name, what names it: the well's file or manifest row) — those
    that would write the ``OUT/NAME`` of an earlier one: by index, the earlier one's index
    and a line naming both. Names are compared as a case-insensitive file system compares
    them (:func:`name_key`: OUT may be on one)."""
    seen: dict[str, int] = {}
    clash: dict[int, tuple[int, str]] = {}
    for i, (dir_name, source) in enumerate(outputs):
        key = name_key(dir_name)
        if key not in seen:
            seen[key] = i
            continue
        first, where = seen[key], ""
        if outputs[first][0] != dir_name:
            where = (f" and OUT/{outputs[first][0]} (one directory on a case-insensitive "
                     "file system)")
        clash[i] = first, (f"{outputs[first][1]} and {source} would both write "
                           f"OUT/{dir_name}{where}: one well's results would be lost")
    return clash


#: How a clash of two wells' output directories is fixed.
DISTINCT_FIX = "give each well its own [well] name (or 'well' column in a manifest)"


def check_distinct(outputs: list[tuple[str, str]]) -> None:
    """Refuse wells of one run that would write the same ``OUT/NAME`` (:func:`collisions`).

    Raises
    ------
    InputError
        Two wells share an output directory (before anything is written).
    """
    from drillfric.errors import InputError

    for _, line in collisions(outputs).values():
        raise InputError(line, fix=DISTINCT_FIX)


#: The file that marks a result directory as stale: a later run of its well failed.
STALE = "STALE.json"


def mark_stale(folder: Path, reason: str, when_utc: str) -> bool:
    """Mark the results in ``folder`` (a directory drillfric wrote) as stale: a later run
    of the well failed, so they are an earlier run's. Writes :data:`STALE` (why, when) and
    ``"stale"`` into summary.json (replaced atomically, so a job reading summary.json alone
    sees it); the next successful run replaces the directory and the mark with it.

    Returns whether ``folder`` was marked (False: nothing drillfric wrote is there).
    """
    if not is_result_dir(folder):
        return False
    stale = {"since_utc": when_utc, "reason": reason,
             "meaning": "these are the results of an earlier run; the latest run of this "
                        "well failed (reason)"}
    with lock_directory(folder.parent):
        if not is_result_dir(folder):
            return False
        summary_path = folder / "summary.json"
        try:
            summary = read_json(summary_path)
        except InputError:
            summary = None
        if summary is not None:
            with replacing(summary_path) as tmp:
                write_json(tmp, summary | {"stale": stale})
        with replacing(folder / STALE) as tmp:
            write_json(tmp, stale)
    return True


# --------------------------------------------------------------------------- files
def arrow_schema(with_truth: bool, with_clock: bool = False) -> pa.Schema:
    """estimates.parquet's schema from :data:`drillfric.result.ESTIMATE_COLUMNS` (every
    column nullable: a bit speed the logging cannot resolve is null); ``timestamp`` with
    ``with_clock`` (the log has absolute time), ``bit_rpm`` with ``with_truth``."""
    left_out = {name for name, kept in (("bit_rpm", with_truth), ("timestamp", with_clock))
                if not kept}
    return pa.schema([(c.name, _arrow_type(c.type)) for c in ESTIMATE_COLUMNS
                      if c.name not in left_out])


def _arrow_type(alias: str) -> pa.DataType:
    """Arrow type of a schema alias (``"float64"``; ``"timestamp[us, UTC]"``, a time zone
    pyarrow's aliases lack)."""
    if alias == "timestamp[us, UTC]":
        return pa.timestamp("us", tz="UTC")
    return pa.type_for_alias(alias)


class EstimatesWriter:
    """Append observer records to estimates.parquet, one row group per segment."""

    def __init__(self, path: Path, with_truth: bool, with_clock: bool = False):
        self.path = path
        self.schema = arrow_schema(with_truth, with_clock)
        self._writer = pq.ParquetWriter(path, self.schema, compression="zstd")

    def write(self, frame: pd.DataFrame) -> None:
        """Append one segment's rows (columns of :attr:`schema`)."""
        table = pa.Table.from_pandas(frame[self.schema.names], schema=self.schema,
                                     preserve_index=False)
        self._writer.write_table(table)

    def write_table(self, table: pa.Table) -> None:
        """Append rows already in this file's schema (one segment's, from an earlier file)."""
        self._writer.write_table(table.cast(self.schema))

    def close(self) -> None:
        """Finish the file."""
        self._writer.close()


#: Largest JSON file of drillfric's read back (a 24 h well's summary.json is a few MB).
MAX_JSON_BYTES = 256 << 20


def read_json(path: Path, *, fix: str = "rerun 'drillfric run' to rewrite the results") -> dict:
    """A JSON object drillfric wrote (summary.json, manifest.json …), read as untrusted: a
    link, FIFO or directory there (:func:`~drillfric.io.atomic.own_file`), or an unreadable,
    undecodable, too deeply nested or non-object file is one InputError naming it (never
    its content).

    Raises
    ------
    InputError
    """
    try:
        if own_file(Path(path)).stat().st_size > MAX_JSON_BYTES:
            raise ValueError(f"larger than {MAX_JSON_BYTES >> 20} MiB")
        value = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError) as exc:
        why = "too deeply nested" if isinstance(exc, RecursionError) else \
            "not UTF-8" if isinstance(exc, UnicodeDecodeError) else \
            f"not JSON ({exc.msg})" if isinstance(exc, json.JSONDecodeError) else \
            (exc.strerror or type(exc).__name__) if isinstance(exc, OSError) else str(exc)
        raise InputError(f"unreadable {Path(path).name}: {why}", file=path, fix=fix) from None
    if not isinstance(value, dict):
        raise InputError(f"{Path(path).name} is not a JSON object", file=path, fix=fix)
    return value


def write_json(path: Path, payload: dict) -> None:
    """Write ``payload`` as indented JSON (NaN-free)."""
    path.write_text(json.dumps(jsonable(payload), indent=2, ensure_ascii=False) + "\n",
                    encoding="utf-8")


def write_segments(path: Path, records) -> None:
    """segments.parquet: one row per :class:`~drillfric.result.SegmentRecord`, with the
    schema's types (a column null in every row keeps its type)."""
    pq.write_table(segment_table(records), path)
