"""Where the compiled kernels are kept, and whether this installation has compiled them.

numba compiles the kernels on their first use and keeps the machine code on disk
(``cache=True``). drillfric puts that cache in one per-user directory (never beside the
inputs, never in ``--out``): ``$NUMBA_CACHE_DIR`` when set, else

- Linux and other POSIX: ``$XDG_CACHE_HOME/drillfric/numba`` (``~/.cache/drillfric/numba``);
- macOS: ``~/Library/Caches/drillfric/numba``;
- Windows: ``%LOCALAPPDATA%\\drillfric\\Cache\\numba``.

Deleting the directory is safe: the next run compiles again (docs/performance.md, "First
run"). :func:`is_warm` tells from a stamp in that directory whether the kernels of this
installation (its kernel sources, numba and Python versions) have been compiled there.
"""

from __future__ import annotations

import hashlib
import os
import sys
from pathlib import Path

#: Sources whose compiled code the cache holds (relative to the drillfric package).
_KERNEL_SOURCES = ("kernels/plant.py", "kernels/observer.py", "segmentation.py",
                   "torque_drag.py", "hookload.py")


def cache_dir() -> Path:
    """The per-user directory of compiled kernels (``$NUMBA_CACHE_DIR`` wins)."""
    given = os.environ.get("NUMBA_CACHE_DIR")
    if given:
        return Path(given)
    home = Path.home()
    if sys.platform == "win32":
        base = Path(os.environ.get("LOCALAPPDATA") or home / "AppData" / "Local")
        return base / "drillfric" / "Cache" / "numba"
    if sys.platform == "darwin":
        return home / "Library" / "Caches" / "drillfric" / "numba"
    base = Path(os.environ.get("XDG_CACHE_HOME") or home / ".cache")
    return base / "drillfric" / "numba"


def configure() -> None:
    """Point numba's cache at :func:`cache_dir` (before numba is imported, through its
    environment variable; after, through its config). A user's ``NUMBA_CACHE_DIR`` stays."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    os.environ["NUMBA_CACHE_DIR"] = str(cache_dir())
    numba_config = sys.modules.get("numba.core.config")
    if numba_config is not None:
        numba_config.CACHE_DIR = os.environ["NUMBA_CACHE_DIR"]


def _stamp(kind: str) -> Path:
    """The stamp of one warm-up ``kind`` for this installation's kernels."""
    import numba

    package = Path(__file__).resolve().parent.parent
    # numba keys its cache by the sources' location too: another install (a clone, a venv)
    # of the same version compiles anew, so its stamp must differ
    digest = hashlib.sha256(f"{numba.__version__} {sys.version} {package}".encode())
    for name in _KERNEL_SOURCES:  # numba recompiles when a source's content or time changes
        source = package / name
        digest.update(source.read_bytes() + str(source.stat().st_mtime_ns).encode())
    return cache_dir() / f"drillfric-{kind}-{digest.hexdigest()[:16]}.ready"


def is_warm(kind: str) -> bool:
    """Whether the kernels of warm-up ``kind`` were compiled into :func:`cache_dir` (by this
    installation — its location and kernel sources — numba and Python)."""
    return _stamp(kind).is_file()


def mark_warm(kind: str) -> None:
    """Record that the kernels of ``kind`` are compiled (a failure to write is ignored:
    the next run then warms up again)."""
    stamp = _stamp(kind)
    try:
        stamp.parent.mkdir(parents=True, exist_ok=True)
        stamp.touch()
    except OSError:
        pass
