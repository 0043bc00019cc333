"""Readers that can crash, run where a crash is contained (docs/security.md).

The Excel (python-calamine, Rust) and DLIS (dlisio, C++) parsers are native code: a hostile
file can make them abort (a sheet declaring a cell at ``XFD1048576`` makes calamine
allocate 512 GiB) or segfault (dlisio on thousands of zero-length logical records). Python
cannot catch either, so such a file is read by a short-lived child process,
``python -P -m drillfric.io.isolated FORMAT PATH``:

- the child limits its own address space (``RLIMIT_AS``, :func:`memory_limit_bytes`) and
  core dumps before it imports a parser (POSIX; elsewhere only the time limit applies);
- it is killed after :func:`time_limit_s`;
- it opens the file with the in-process reader (:func:`drillfric.io.excel.open_excel`,
  :func:`drillfric.io.dlis.open_dlis`), reads every row and writes one Arrow IPC stream to
  its standard output — plain columns and a JSON header (columns, units, row count, depth
  index); text columns travel as text, the form every later step reads them in — or, for a
  file it cannot read, one JSON line with the problem and the fix (exit code 2). Nothing is
  unpickled, no temporary file is written;
- anything else — a signal, another exit code, no answer in time — is one
  :class:`~drillfric.errors.InputError` naming the file and what happened ("the DLIS reader
  crashed (signal 11, SIGSEGV)").

The parent holds the columns in memory (both parsers read a sheet or frame whole anyway) and
hands them on in chunks, as every reader does. Cost: one Python start-up per file opened
(measured in docs/security.md).
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pandas as pd

from drillfric.errors import InputError
from drillfric.io.source import RawSource, data_format

#: Readers run in a child process: format → (module, function, what the messages call it).
READERS = {"excel": ("drillfric.io.excel", "open_excel", "Excel"),
           "dlis": ("drillfric.io.dlis", "open_dlis", "DLIS")}
#: Share of the machine's memory a reader may map (its address-space limit).
MEMORY_SHARE = 0.5
#: Time a reader may take: a base plus a rate per MB of file [s, s/MB] (dlisio reads a
#: 9 MB, 200 000-row frame in 88 s on a loaded 2-core machine: 3× margin).
TIME_BASE_S, TIME_PER_MB_S = 120.0, 30.0
#: Exit code of a child that reports a file it cannot read (one JSON line on stdout).
REPORTED = 2
_HEADER = b"drillfric"


def memory_limit_bytes() -> int | None:
    """Address-space limit of a reader child: :data:`MEMORY_SHARE` of physical memory
    (None where the machine's memory cannot be read)."""
    try:
        total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):
        return None
    return int(MEMORY_SHARE * total) if total > 0 else None


def time_limit_s(path: Path) -> float:
    """Seconds a reader child may take for ``path``: :data:`TIME_BASE_S` plus
    :data:`TIME_PER_MB_S` per MB."""
    return TIME_BASE_S + TIME_PER_MB_S * path.stat().st_size / 1e6


# --------------------------------------------------------------------------- parent side
def open_isolated(path: Path, *, timeout_s: float | None = None) -> RawSource:
    """Open an Excel or DLIS file through a reader child process.

    Parameters
    ----------
    path : Path
        An ``.xlsx`` or ``.dlis`` file.
    timeout_s : float, optional
        Time limit [s] (default :func:`time_limit_s`).

    Raises
    ------
    InputError
        The reader reported the file unreadable, crashed, ran out of memory or time.
    """
    path = Path(path)
    fmt = data_format(path)
    name = READERS[fmt][2]
    if fmt == "excel":  # what rules the crash out cheaply is checked before any child
        from drillfric.io.excel import check_workbook

        check_workbook(path)
    limit = time_limit_s(path) if timeout_s is None else timeout_s
    fix = "re-save or re-export the file, or export the log as CSV or Parquet"
    try:
        done = subprocess.run(_command(fmt, path), stdin=subprocess.DEVNULL,
                              capture_output=True, timeout=limit, env=_child_env())
    except subprocess.TimeoutExpired:
        raise InputError(f"the {name} reader did not finish within {limit:.0f} s (stopped)",
                         file=path, fix=fix) from None
    except OSError as exc:
        raise InputError(f"cannot start the {name} reader ({exc.strerror})", file=path,
                         fix="check that the Python running drillfric can start "
                             "processes") from None
    if done.returncode == 0:
        return _source(path, fmt, done.stdout, name)
    if done.returncode == REPORTED and done.stdout.startswith(b"{"):
        report = json.loads(done.stdout)
        raise InputError(report["problem"], file=path, fix=report.get("fix"))
    raise InputError(_crash(name, done.returncode, done.stderr), file=path, fix=fix)


def _command(fmt: str, path: Path) -> list[str]:
    limit = memory_limit_bytes()
    # -P: nothing from the working directory is imported in the child
    return [sys.executable, "-P", "-m", "drillfric.io.isolated", fmt, str(path.resolve()),
            str(limit or 0)]


def _child_env() -> dict:
    """The environment with drillfric importable (a source checkout need not be installed)
    and native back-traces off."""
    root = str(Path(__file__).resolve().parents[2])  # the folder holding drillfric/
    env = dict(os.environ, RUST_BACKTRACE="0")
    env["PYTHONPATH"] = os.pathsep.join(p for p in (root, env.get("PYTHONPATH")) if p)
    env.pop("PYTHONSTARTUP", None)
    return env


def _crash(name: str, code: int, stderr: bytes) -> str:
    """One line for a child that died: signal or exit code, and running out of memory."""
    text = stderr.decode("utf-8", "replace")
    memory = "memory allocation" in text or "MemoryError" in text or "bad_alloc" in text
    if code < 0:
        try:
            what = f"signal {-code}, {signal.Signals(-code).name}"
        except ValueError:
            what = f"signal {-code}"
    else:
        what = f"exit code {code}"
    if memory:
        limit = memory_limit_bytes()
        room = f" of {limit / 1024**3:.1f} GiB" if limit else ""
        asked = re.search(r"memory allocation of (\d+) bytes", text)
        size = f" ({int(asked[1]) / 1024**3:,.0f} GiB at once)" if asked else ""
        return f"the {name} reader ran out of memory ({what}): the file asks for more than " \
               f"the reader's limit{room}{size}"
    return f"the {name} reader crashed ({what})"


def _source(path: Path, fmt: str, payload: bytes, name: str) -> RawSource:
    """The RawSource of a child's Arrow stream."""
    import pyarrow as pa

    try:
        table = pa.ipc.open_stream(pa.py_buffer(payload)).read_all()
        head = json.loads(table.schema.metadata[_HEADER])
    except (pa.ArrowException, KeyError, TypeError, ValueError) as exc:
        raise InputError(f"the {name} reader returned no readable table "
                         f"({type(exc).__name__})", file=path,
                         fix="report this as a bug, with the file") from None
    columns = head["columns"]
    units = {tuple(k) if isinstance(k, list) else k: v for k, v in head["units"]}

    def read(chunk_rows: int) -> Iterator[pd.DataFrame]:
        for start in range(0, table.num_rows, chunk_rows):
            frame = table.slice(start, chunk_rows).to_pandas()
            frame.columns = columns
            yield frame

    return RawSource(path, fmt, columns, units, head["rows"], read,
                     depth_index=head["depth_index"], where=head.get("where"))


# --------------------------------------------------------------------------- child side
def _limit_self(memory_bytes: int) -> None:
    """Address-space and core-dump limits of this process (POSIX; nothing elsewhere)."""
    try:
        import resource
    except ImportError:
        return
    wanted = [(resource.RLIMIT_CORE, 0)]
    if memory_bytes > 0:
        wanted.append((resource.RLIMIT_AS, memory_bytes))
    for kind, value in wanted:
        try:
            _, hard = resource.getrlimit(kind)
            value = value if hard == resource.RLIM_INFINITY else min(value, hard)
            resource.setrlimit(kind, (value, hard))
        except (ValueError, OSError):  # e.g. macOS refuses RLIMIT_AS: the time limit holds
            pass


def _table(source: RawSource):
    """The whole source as an Arrow table with positional column names and a JSON header."""
    import pyarrow as pa

    chunks = list(source.chunks())
    frame = pd.concat(chunks, ignore_index=True) if chunks else pd.DataFrame(
        columns=source.columns)
    arrays = {}
    for i in range(frame.shape[1]):
        values = frame.iloc[:, i]
        if values.dtype == object:  # later steps read mixed cells as text (astype("string"))
            values = values.astype("string")
        arrays[f"c{i}"] = pa.array(values, from_pandas=True)
    head = {"columns": [str(c) for c in frame.columns], "rows": source.rows,
            "units": [[list(k) if isinstance(k, tuple) else k, v]
                      for k, v in source.units.items()],
            "depth_index": source.depth_index, "where": source.where}
    table = pa.table(arrays) if arrays else pa.table({})
    return table.replace_schema_metadata({_HEADER: json.dumps(head).encode()})


def _child(fmt: str, path: str, memory_bytes: int) -> int:
    """Read ``path`` and write the Arrow stream (0) or one JSON error line (2) to stdout."""
    _limit_self(memory_bytes)
    out = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)  # whatever a library prints goes to stderr, not into the stream
    import importlib

    import pyarrow as pa

    module, function, name = READERS[fmt]
    try:
        table = _table(getattr(importlib.import_module(module), function)(Path(path)))
    except InputError as exc:
        return _report(out, exc.problem, exc.fix)
    except MemoryError:
        return _report(out, f"the {name} reader ran out of memory: the file asks for more "
                            f"than the reader's limit of {memory_bytes / 1024**3:.1f} GiB",
                       "export the log as CSV or Parquet")
    with pa.ipc.new_stream(out, table.schema) as writer:
        writer.write_table(table)
    out.close()
    return 0


def _report(out, problem: str, fix: str | None) -> int:
    out.write(json.dumps({"problem": problem, "fix": fix}).encode())
    out.close()
    return REPORTED


if __name__ == "__main__":
    sys.exit(_child(sys.argv[1], sys.argv[2], int(sys.argv[3])))
