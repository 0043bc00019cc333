"""What ``drillfric live`` follows (docs/live.md "Sources"): a text file a rig logger appends
to (:class:`Tail`), or a well directory into which the files of its log arrive
(:class:`PartsTail`, the folder rules of :mod:`drillfric.io.parts`).

Both say how much data has arrived complete (:meth:`~Tail.poll`: a count that only grows),
whether enough has arrived to open the well (:meth:`~Tail.ready`), open it, and give the
mark of what was read in the format :mod:`drillfric.runner.resume` checks a continued run
against (:meth:`~Tail.mark`), so a live run killed outright continues from its saved state.
"""

from __future__ import annotations

import hashlib
import os
import re
from pathlib import Path

import pyarrow as pa

from drillfric.config import read_toml
from drillfric.errors import InputError
from drillfric.files import require_inside
from drillfric.io.digest import sha256_prefix
from drillfric.io.parts import folder_parts
from drillfric.io.readers import open_source
from drillfric.io.source import FORMATS
from drillfric.io.text import plural, printable
from drillfric.io.well import Well, open_well, with_parts
from drillfric.io.wellfiles import arriving_data, config_named
from drillfric.runner.resume import csv_mark, parquet_mark, parts_mark

#: Complete data lines wanted before a CSV file's layout is sniffed (header + rows).
FIRST_LINES = 20
#: A line end: LF, CR LF or a bare CR (as ``drillfric run`` reads them, io/delimited.py).
_LINE_END = re.compile(rb"\r\n|\r|\n")
#: Most bytes read from a growing file in one poll (the rest at the next poll): a file
#: that jumps by gigabytes (a sparse file, a copy) cannot fill the memory.
MAX_BLOCK = 64 * 2**20
#: Longest line a rig log may hold [bytes]: a longer one (a never-ending line, a run of NUL
#: bytes) is no text log, not a line to wait for.
MAX_LINE_BYTES = 2**20
#: Last bytes read kept and compared with the file at every poll [bytes]: a file rewritten in
#: place (same inode) shifts or changes them.
TAIL_BYTES = 4096


def follow(path: Path) -> Tail | PartsTail:
    """The tail of a live source: a data file (which may not exist yet), or a well directory
    whose ``well.toml`` names the file or the folder of parts its data arrive in."""
    path = Path(path)
    if not path.is_dir():
        return Tail(path)
    data = arriving_data(path)
    if data.is_dir() or data.suffix.lower() not in FORMATS:
        well_toml = path / "well.toml"
        return PartsTail(data, config_named(well_toml, read_toml(well_toml)))
    return Tail(data)


def lines_end(block: bytes, final: bool = False) -> int:
    """Where the last complete line of ``block`` ends (0: none). A line ends with LF, CR LF
    or a bare CR; a CR that is the block's last byte waits for the next one (it may be the
    first half of a CR LF cut by a write) unless ``final``."""
    newline = block.rfind(b"\n")
    cr = block.rfind(b"\r", 0, len(block) if final else max(len(block) - 1, 0))
    return max(newline, cr) + 1


class Tail:
    """The complete lines of a growing text file.

    Parameters
    ----------
    path : Path
        The file.
    start : int
        Bytes already read (a line's end), hashed again on creation.
    """

    def __init__(self, path: Path, start: int = 0):
        self.path, self.end = Path(path), 0
        self._digest = hashlib.sha256()
        self._identity: tuple[int, int] | None = None  # (device, inode) of what was read
        self._tail = b""  # the last bytes read, to see a rewrite in place
        if start:
            self._take(start)

    def poll(self, final: bool = False) -> int:
        """Where the complete lines end now [bytes] (a partial last line is not counted;
        ``final``: the data ended, a last bare CR ends its line).

        Raises
        ------
        InputError
            The file became shorter than what was read (rewritten, not appended to).
        """
        try:
            info = self.path.stat()
            size, identity = info.st_size, (info.st_dev, info.st_ino)
        except FileNotFoundError:
            size, identity = 0, self._identity
        if size < self.end:
            raise InputError(f"the file shrank to {plural(size, 'byte')} after {self.end} were "
                             "read",
                             file=self.path, fix="append to the file; restart live on a new "
                                                 "--out for a rewritten file")
        if self.end and self._identity not in (None, identity) and not self._same_start():
            raise InputError("the file was replaced by another (renamed over it) whose first "
                             f"{plural(self.end, 'byte')} are not the ones read: its rows cannot "
                             "continue them", file=self.path,
                             fix="append to the file; restart live on a new --out for a "
                                 "rewritten file")
        if self.end and identity == self._identity and not self._same_tail():
            raise InputError("the file was rewritten in place: its last bytes read are no longer "
                             "the ones read", file=self.path,
                             fix="append to the file; restart live on a new --out for a "
                                 "rewritten file")
        self._identity = identity
        while size > self.end:  # the partial last line is read again: it may have ended
            with open(self.path, "rb") as fh:  # in blocks: memory bounded by MAX_BLOCK
                fh.seek(self.end)
                block = fh.read(min(size - self.end, MAX_BLOCK))
            cut = lines_end(block, final and self.end + len(block) >= size)
            if not cut and len(block) > MAX_LINE_BYTES:
                raise InputError(f"a line of more than {MAX_LINE_BYTES} bytes after byte "
                                 f"{self.end}: this is no text log", file=self.path,
                                 fix="follow the rig log's CSV file (lines end with a line end)")
            if not cut:
                break
            self._take(self.end + cut, block[:cut])
        return self.end

    def _same_tail(self) -> bool:
        """Whether the file still holds the last bytes read where they were read (a logger
        that rewrites its file in place, same inode, shifts or changes them: the ninth
        attack's spliced half-line, or stale rows kept silently)."""
        try:
            with open(self.path, "rb") as fh:
                fh.seek(self.end - len(self._tail))
                return fh.read(len(self._tail)) == self._tail
        except OSError:
            return False

    def _same_start(self) -> bool:
        """Whether the file now starts with the bytes read so far (a logger that rewrites
        its file whole and renames it over the old one keeps them; another file does not)."""
        try:
            return sha256_prefix(self.path, self.end) == self._digest.hexdigest()
        except (OSError, ValueError):
            return False

    def lines(self) -> int:
        """How many complete lines there are up to :attr:`end`, counted up to
        :data:`FIRST_LINES` (for the first sniff)."""
        count, done = 0, 0
        with open(self.path, "rb") as fh:  # in blocks: a file of gigabytes is not held
            while done < self.end and count < FIRST_LINES:
                block = fh.read(min(self.end - done, MAX_BLOCK))
                if not block:
                    break
                if block.endswith(b"\r") and done + len(block) < self.end:
                    block += fh.read(1)  # a CR LF cut by the block is one line end
                count += len(_LINE_END.findall(block))
                done += len(block)
        return count

    def ready(self, final: bool = False) -> bool:
        """Whether enough lines arrived to read the file's layout: a header and
        :data:`FIRST_LINES` rows (``final``: a header and one row)."""
        return self.end > 0 and self.lines() >= (2 if final else FIRST_LINES)

    def open(self, path: Path, open_kw: dict) -> Well:
        """The well of the live source ``path`` (this file, or the directory naming it)."""
        return open_well(path, **open_kw)

    def well_for(self, well: Well) -> Well:
        """The well to read the rows with (the file's: unchanged)."""
        return well

    def restart(self, found: dict | None) -> None:
        """Continue after the mark ``found`` (None: from the start)."""
        self.end, self._digest, self._tail = 0, hashlib.sha256(), b""
        if found:
            self._take(found["bytes"])

    def _take(self, end: int, block: bytes | None = None) -> None:
        if block is None:
            with open(self.path, "rb") as fh:
                fh.seek(self.end)
                block = fh.read(end - self.end)
        self._digest.update(block)
        self._tail = (self._tail + block)[-TAIL_BYTES:]
        self.end = end

    def mark(self) -> dict:
        """The mark of the bytes read (:func:`drillfric.runner.resume.csv_mark`'s format)."""
        return {"format": "csv", "bytes": self.end, "sha256": self._digest.hexdigest(),
                "ends_line": True}

    def growth(self):
        """Changes whenever the file grows (the file's size; None while it is missing)."""
        try:
            return self.path.stat().st_size
        except OSError:
            return None


class PartsTail:
    """The parts of one log arriving in a folder, in name order (:mod:`drillfric.io.parts`).

    A part is *read* once it is complete enough: a Parquet file when its footer is readable
    (one still being written is tried again at the next poll); a CSV file when a later file
    arrived (then it is read whole) or, the newest one, by its complete lines, as
    :class:`Tail` follows a file, once it holds a header and :data:`FIRST_LINES` rows. A file
    arriving with a name sorting before one already read, or a file read before that was
    removed or whose size changed, is an error: the log's order cannot be kept.

    Parameters
    ----------
    folder : Path
        The folder the log's files arrive in.
    named : tuple of Path
        Files the configuration names as something else (its survey): never parts.
    """

    def __init__(self, folder: Path, named=()):
        self.folder = Path(folder)
        self.named = tuple(named)
        self.paths: tuple[Path, ...] = ()  # the parts read, in order
        self.end = 0
        self._done: list[dict] = []  # marks of the complete parts (name first)
        self._sizes: list[int] = []  # their sizes [bytes] when read
        self._last: Tail | None = None  # the newest part, a CSV file still growing
        self._source = None  # the well's source (its columns and units: the mark's)

    def poll(self, final: bool = False) -> int:
        """Read the parts that arrived complete; a count that grows with the data read.

        Raises
        ------
        InputError
            A file out of order, removed or changed after it was read; files of several
            formats; at the ``final`` poll, a Parquet file still unreadable.
        """
        listed = folder_parts(self.folder, self.named) if self.folder.is_dir() else None
        listed = listed or ()
        self._check(listed)
        if self._last is not None:
            if len(listed) > len(self.paths):
                self._complete_last()  # a later file arrived: the newest is complete
            else:
                self._last.poll(final)
        if self._last is None:
            for path in listed[len(self.paths):]:
                if not self._add(path, newest=path == listed[-1], final=final):
                    break
        self.end = sum(_end(m) for m in self._done) + (self._last.end if self._last else 0)
        return self.end

    def ready(self, final: bool = False) -> bool:  # noqa: ARG002 — the parts' rule
        """Whether a first part was read (then the well can be opened)."""
        return bool(self.paths)

    def open(self, path: Path, open_kw: dict) -> Well:
        """The well of the directory ``path``, its log read from the parts read so far."""
        return self.well_for(open_well(path, header=False, **open_kw))

    def well_for(self, well: Well) -> Well:
        """``well`` reading exactly the parts read so far (reopened when parts came)."""
        have = tuple(p.path for p in well.source.parts) if well.source is not None else None
        if have != self.paths:
            well = with_parts(well, self.paths)
        self._source = well.source
        return well

    def restart(self, found: dict | None) -> None:
        """Continue after the mark ``found`` (None: from the first part)."""
        self.paths, self._done, self._sizes, self._last = (), [], [], None
        for part in (found or {}).get("parts", ()):
            path = self.folder / part["name"]
            self.paths += (path,)
            if part is found["parts"][-1] and part["format"] == "csv":
                self._last = Tail(path, part["bytes"])
            else:
                self._done.append(part)
                self._sizes.append(path.stat().st_size)
        self.end = sum(_end(m) for m in self._done) + (self._last.end if self._last else 0)

    def mark(self) -> dict:
        """The mark of the parts read (:func:`drillfric.runner.resume.mark`'s format)."""
        parts = list(self._done)
        if self._last is not None:
            parts.append({"name": self._last.path.name} | self._last.mark()
                         | {"end": self._last.end})
        return parts_mark(self._source, parts)

    def growth(self):
        """Changes whenever a file arrives in the folder or grows."""
        try:
            return tuple(sorted((e.name, e.stat().st_size) for e in os.scandir(self.folder)
                                if e.is_file()))
        except OSError:
            return None

    # ------------------------------------------------------------------ parts
    def _check(self, listed: tuple[Path, ...]) -> None:
        """The parts read come first in the folder, in order, their sizes unchanged."""
        if listed[:len(self.paths)] != self.paths:
            gone = [p for p in self.paths if p not in listed]
            if gone:
                raise _order_error(gone[0], "was removed or renamed after it was read")
            early = next(p for p in listed if p not in self.paths)
            raise _order_error(early, f"arrived after {printable(self.paths[-1].name)} was "
                                      "read, but its name sorts before it")
        for path, size in zip(self.paths, self._sizes, strict=False):
            now = path.stat().st_size
            if now != size:
                raise _order_error(path, f"changed after it was read (its size went from "
                                         f"{size} to {now} bytes)")

    def _complete_last(self) -> None:
        """The newest CSV part is followed by a later file: read it whole (as a run does)."""
        path = self._last.path
        size = path.stat().st_size
        self._done.append({"name": path.name} | csv_mark(path, size) | {"end": size})
        self._sizes.append(size)
        self._last = None

    def _add(self, path: Path, *, newest: bool, final: bool) -> bool:
        """Read the part ``path`` when it is complete enough; True when it was."""
        require_inside(path, self.folder, "file of the data folder",
                       fix="copy the files into the data folder")
        if path.suffix.lower() in (".parquet", ".pq"):
            mark = _parquet_part(path, final)
            if mark is None:
                return False
            self._done.append({"name": path.name} | mark)
            self._sizes.append(path.stat().st_size)
        elif newest:
            tail = Tail(path)
            tail.poll(final)
            if not tail.ready(final):
                return False
            self._last = tail
        else:
            size = path.stat().st_size
            self._done.append({"name": path.name} | csv_mark(path, size) | {"end": size})
            self._sizes.append(size)
        self.paths += (path,)
        return True


def _parquet_part(path: Path, final: bool) -> dict | None:
    """The mark of a Parquet part, or None while its footer is not readable (still being
    written; at the ``final`` poll an error)."""
    try:
        return parquet_mark(path, open_source(path))
    except (OSError, pa.ArrowException, InputError) as exc:
        if final:
            raise InputError(f"unreadable Parquet file ({exc}): it was still being written "
                             "when live stopped, or it is damaged", file=path,
                             fix="let the file be written completely, then run live again "
                                 "(it continues where it stopped)") from None
        return None


def _end(found: dict) -> int:
    return found["bytes"] if found["format"] == "csv" else found["rows"]


def _order_error(path: Path, problem: str) -> InputError:
    return InputError(f"{problem}: the order of the log's files cannot be kept", file=path,
                      fix="give the files names that sort in time order and leave the files "
                          "read alone; a restarted live starts again from the first row")
