"""Advisory locks that work on every platform drillfric imports on (docs/security.md).

Two kinds of lock guard ``--out``:

- :func:`lock_file` — a lock file held for a whole fleet run (``OUT/.fleet.lock``), taken
  without waiting: a second fleet on the same OUT is refused, not queued. It uses the
  ``filelock`` package (``flock`` on POSIX, ``LockFileEx`` on Windows).
- :func:`lock_directory` — an exclusive lock on a directory for the short swap of a result
  directory into place. On POSIX this is ``flock`` on the directory's own descriptor (no
  file is added to OUT; it also holds between machines sharing OUT over NFS, where Linux
  maps ``flock`` to POSIX locks). Where ``fcntl`` does not exist (Windows) it is a
  ``filelock`` lock file in the system temporary directory named by a hash of the
  directory's path, which serialises the writers of one machine.

``fcntl`` is imported only when a lock is taken, never at module import, so every drillfric
module imports on Windows.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path


class Busy(Exception):
    """The lock is held by another process (or another lock object of this one)."""


@contextmanager
def lock_file(path: Path) -> Iterator[None]:
    """Hold the lock file ``path`` (created if missing) for the ``with`` block, or raise
    :class:`Busy` at once when another holder has it.

    Raises
    ------
    Busy
        Someone else holds it.
    OSError
        The lock file cannot be created (read-only directory …).
    """
    from filelock import FileLock, Timeout

    lock = FileLock(str(path), timeout=0, is_singleton=False)
    try:
        lock.acquire()
    except Timeout:
        raise Busy(str(path)) from None
    try:
        yield
    finally:
        lock.release()


@contextmanager
def lock_directory(folder: Path) -> Iterator[None]:
    """Hold an exclusive lock on ``folder`` for the ``with`` block, waiting for it."""
    try:
        import fcntl
    except ImportError:
        fcntl = None
    if fcntl is None:
        from filelock import FileLock

        key = hashlib.sha256(str(Path(folder).resolve()).encode()).hexdigest()[:32]
        with FileLock(os.path.join(tempfile.gettempdir(), f"drillfric-{key}.lock")):
            yield
        return
    fd = os.open(folder, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fd, fcntl.LOCK_UN)
    finally:
        os.close(fd)
