"""Continue a well's run from the state its last results kept: only the rows appended since
(docs/fleet.md "Only what is new").

A delimited text file that grew is recognised by its content: the state records the byte
length of the file it read, a SHA-256 of those bytes and whether they ended with a complete
line (:func:`csv_mark`); the file continues it when its first bytes hash the same
(:func:`changed`). Anything else — no state, another drillfric, configuration or rate,
earlier bytes changed, a format read only whole — is run from the start, and the summary
says why (summary.json ``resumed``).
"""

from __future__ import annotations

import hashlib
from pathlib import Path

from drillfric.errors import InputError
from drillfric.io.well import Well

from .engine import Engine, mismatch
from .finish import DirectorySink
from .state import read_state

_BLOCK = 1 << 22
#: Text encodings read from a byte offset (a UTF-16/32 file is read whole).
_SEEKABLE = ("utf-8-sig", "latin-1")


def csv_mark(path: Path, size: int) -> dict:
    """What a run read of a delimited text file: its first ``size`` bytes."""
    digest = hashlib.sha256()
    last = b""
    with open(path, "rb") as fh:
        left = size
        while left > 0 and (block := fh.read(min(_BLOCK, left))):
            digest.update(block)
            left -= len(block)
            last = block[-1:]
    return {"format": "csv", "bytes": size, "sha256": digest.hexdigest(),
            "ends_line": last in (b"\n", b"\r")}


def changed(mark: dict | None, path: Path) -> str:
    """Why ``path`` does not continue what ``mark`` recorded ("" when it does)."""
    if not mark or mark.get("format") != "csv":
        return "the earlier run read no delimited text file"
    size = path.stat().st_size
    if size < mark["bytes"]:
        return f"the file is shorter than the {mark['bytes']} bytes read before"
    if not mark.get("ends_line"):
        return "the earlier rows did not end with a complete line"
    if csv_mark(path, mark["bytes"])["sha256"] != mark["sha256"]:
        return "earlier rows changed (the first bytes differ from those read before)"
    return ""


def resumable(well: Well) -> bool:
    """Whether the well's data can be continued from a byte offset (a delimited text file
    in a byte-seekable encoding)."""
    source = well.source
    return (not well.files.in_memory and source is not None
            and source.encoding in _SEEKABLE)


def resume(well: Well, previous: Path, sink: DirectorySink, **kw) -> tuple[Engine | None, str]:
    """An engine continuing the run of ``previous`` (a result directory), its output rows
    seeded into ``sink``; or None and why it cannot."""
    if not resumable(well):
        return None, "its data is not a delimited text file read by byte offset"
    folder = previous / "state"
    if not (folder / "engine.json").is_file():
        return None, "no saved state"
    try:
        state = read_state(folder)
    except InputError as exc:
        return None, exc.message
    why = mismatch(state, well, kw.get("rate_hz")) or changed(state.get("source"),
                                                              well.files.data)
    if why:
        return None, why
    engine = Engine(well, sink=sink, **kw)
    engine.restore(state)
    sink.seed(previous, {r.id for r in engine.records})
    engine.resumed = {"from_row": engine.raw_rows, "from_byte": state["source"]["bytes"],
                      "reason": ""}
    return engine, ""
