"""Files drillfric writes: made fresh, never through a link, swapped in whole.

Every output file goes through :func:`replacing` (written in a private temporary directory
beside it — ``mkdtemp``: an unpredictable name, mode 0700 — then renamed over the target in
one step) or, for a recording that grows line by line, :func:`open_appending` (``O_NOFOLLOW``).
A target that is a symbolic link is refused: a link planted in OUT (``fleet.html``,
``NAME/report.html``, ``NAME.wits0.csv`` → a file elsewhere) would otherwise carry
drillfric's writes outside ``--out``. An OSError while writing (a full disk, a read-only
file system) becomes one :class:`~drillfric.errors.OutputError` naming the path, with the
temporary removed: nothing half-written is left (docs/security.md).
"""

from __future__ import annotations

import errno
import os
import shutil
import stat
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from drillfric.errors import OutputError

_FIXES = {
    errno.ENOSPC: ("no space left on the device", "free disk space or choose another --out"),
    errno.EDQUOT: ("disk quota exceeded", "free space in your quota or choose another --out"),
    errno.EFBIG: ("file too large for the file system or a size limit",
                  "choose another --out (or raise the file-size limit)"),
    errno.EROFS: ("read-only file system", "choose a writable --out"),
    errno.EACCES: ("permission denied", "choose a writable --out"),
    errno.EPERM: ("operation not permitted", "choose a writable --out"),
    errno.ENAMETOOLONG: ("path too long", "use a shorter --out or well name"),
    errno.ENOTDIR: ("a file stands where a directory must go",
                    "remove or rename that file, or choose another --out"),
    errno.EEXIST: ("a file stands where a directory must go",
                   "remove or rename that file, or choose another --out"),
    errno.ELOOP: ("a symbolic link stands where drillfric writes (it writes through no link)",
                  "remove the link, or choose another --out"),
    errno.EISDIR: ("a directory stands where drillfric writes a file",
                   "remove or rename that directory, or choose another --out"),
}
LINK_FIX = _FIXES[errno.ELOOP][1]
#: Files drillfric itself writes in OUT beside the wells' directories (the fleet's and
#: live's, docs/outputs.md): no well may be named so, no data folder holds them as parts of
#: a log, discovery takes none for a well. Compared case-folded.
OUT_FILES = frozenset({"manifest.json", "fleet_summary.parquet", "fleet.html", "live.json"})
#: Suffix of live's WITS0 recordings in OUT (``OUT/NAME.wits0.csv``).
RECORDING_SUFFIX = ".wits0.csv"


def output_error(exc: OSError, where: Path, *, named: bool = False) -> OutputError:
    """One-line :class:`OutputError` for an OSError met while writing results (the path
    the error names, else ``where``; ``where`` always when ``named``: a temporary's path
    means nothing to the reader; never the content of a file)."""
    problem, fix = _FIXES.get(exc.errno, (f"cannot write ({exc.strerror or exc})",
                                          "check --out and the disk"))
    path = where if named else exc.filename or where
    return OutputError(f"cannot write results: {problem}", file=path, fix=fix)


def is_write_problem(exc: OSError) -> bool:
    """Whether an OSError is one of a full, read-only or forbidden output (not an input's)."""
    return exc.errno in _FIXES


def own_file(path: Path) -> Path:
    """``path`` when it is a regular file itself — not a link, a FIFO, a device or a
    directory: a file drillfric wrote in OUT and reads back (summary.json, manifest.json,
    the saved state, a recording). Anyone may plant something else there: a link would be
    read outside OUT, a FIFO would hang the open.

    Raises
    ------
    FileNotFoundError
        Nothing there.
    ValueError
        Something there that drillfric does not write (the caller names it in its error).
    """
    mode = os.lstat(path).st_mode
    if not stat.S_ISREG(mode):
        kind = "a symbolic link" if stat.S_ISLNK(mode) else "a directory" if \
            stat.S_ISDIR(mode) else "a FIFO, device or socket"
        raise ValueError(f"{Path(path).name} is {kind}, not a file drillfric wrote")
    return Path(path)


def refuse_link(path: Path) -> None:
    """OutputError when ``path`` is a symbolic link (dangling or not), or a device, FIFO or
    socket: a rename over ``/dev/null`` (``simulate --out /dev/null`` run as root) replaced
    the device with a regular file for every program on the machine."""
    if os.path.islink(path):
        raise OutputError("cannot write results: a symbolic link stands where drillfric "
                          "writes (it writes through no link)", file=path, fix=LINK_FIX)
    try:
        mode = os.lstat(path).st_mode
    except OSError:
        return
    if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
        raise OutputError("cannot write results: a device, FIFO or socket stands where "
                          "drillfric writes a file (it would replace it)", file=path,
                          fix="choose a file path in a folder of your own for the output")


@contextmanager
def replacing(path: Path) -> Iterator[Path]:
    """Write ``path`` whole or not at all: yields a temporary path to write (any writer that
    takes a path), then renames it over ``path``.

    Raises
    ------
    OutputError
        ``path`` is a symbolic link, or writing failed (an OSError, named by path); the
        temporary is removed in every case.
    """
    path = Path(path)
    refuse_link(path)
    try:
        private = Path(tempfile.mkdtemp(prefix=f".{path.name[:40]}.", suffix=".tmp",
                                        dir=path.parent))
    except OSError as exc:
        raise output_error(exc, path) from None
    try:
        yield private / path.name
        refuse_link(path)  # planted while the file was written
        os.replace(private / path.name, path)
    except OSError as exc:
        raise output_error(exc, path, named=True) from None
    finally:
        shutil.rmtree(private, ignore_errors=True)


def write_text_replacing(path: Path, text: str) -> None:
    """:func:`replacing` for a text file (UTF-8; an undecodable file name's surrogate is
    replaced)."""
    with replacing(path) as tmp:
        tmp.write_text(text, encoding="utf-8", errors="replace")


def open_appending(path: Path):
    """A binary file object appending to ``path`` (created 0644 when missing), opened
    without following a link; OutputError when ``path`` is a link or cannot be opened."""
    try:
        fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT | os.O_NOFOLLOW, 0o644)
    except OSError as exc:
        raise output_error(exc, path) from None
    return os.fdopen(fd, "ab")
