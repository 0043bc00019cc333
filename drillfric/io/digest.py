"""SHA-256 of a file's first bytes, each byte read once per process.

A nightly re-run of a grown well asks for the digest of one file several times: the fleet's
input stamp (whole file), the check that the bytes read last night are unchanged (a
prefix), the mark the run leaves for the next night (up to the last complete line) and the
summary's ``inputs`` (whole file) — four passes over up to a gigabyte. Here the running
digest is kept at every :data:`STEP` bytes of a file (a SHA-256 state is ~200 bytes), so a
later request continues from the nearest kept state at or below its size. Entries are
keyed by the file's identity (device, inode, size, modification time): a file that changed
is hashed afresh.
"""

from __future__ import annotations

import hashlib
import os
import threading
from collections import OrderedDict
from pathlib import Path

#: Bytes between two kept digest states.
STEP = 1 << 24
#: Bytes read at a time (divides :data:`STEP`).
BLOCK = 1 << 22
#: Files whose digest states are kept (the least recently used is dropped).
KEEP = 8

_lock = threading.Lock()
_kept: OrderedDict[str, tuple[tuple, list]] = OrderedDict()


def sha256_prefix(path: str | Path, size: int | None = None) -> str:
    """Hex SHA-256 of the first ``size`` bytes of ``path`` (None: the whole file).

    Raises
    ------
    OSError
        The file cannot be read; ``ValueError`` when it holds fewer than ``size`` bytes.
    """
    with open(path, "rb") as fh:
        stat = os.fstat(fh.fileno())
        size = stat.st_size if size is None else size
        if size > stat.st_size:
            raise ValueError(f"{path}: {size} bytes asked of a {stat.st_size}-byte file")
        states = _states(str(Path(path).resolve()),
                         (stat.st_dev, stat.st_ino, stat.st_size, stat.st_mtime_ns))
        with _lock:
            k = min(size // STEP, len(states) - 1)
            digest = states[k].copy()
        offset = k * STEP
        fh.seek(offset)
        while offset < size and (block := fh.read(min(BLOCK, size - offset))):
            digest.update(block)
            offset += len(block)
            if offset % STEP == 0:
                with _lock:
                    if len(states) == offset // STEP:
                        states.append(digest.copy())
    return digest.hexdigest()


def _states(key: str, identity: tuple) -> list:
    """The kept digest states of a file (index k: after k·STEP bytes), new when it changed."""
    with _lock:
        found = _kept.get(key)
        if found is None or found[0] != identity:
            found = (identity, [hashlib.sha256()])
            _kept[key] = found
        _kept.move_to_end(key)
        while len(_kept) > KEEP:
            _kept.popitem(last=False)
        return found[1]
