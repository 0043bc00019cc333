"""Checks that a named input is a regular file before anything opens it.

A path that exists but is a directory, a device (``/dev/zero``, ``/dev/tty``) or a FIFO is
"not a regular file", not "not found": opening a FIFO or a terminal for reading blocks until
someone writes, and a device can stream for ever (docs/security.md).
"""

from __future__ import annotations

from pathlib import Path

from drillfric.errors import DrillfricError, InputError


def require_file(path: Path, what: str = "file", *, error: type[DrillfricError] = InputError,
                 fix: str = "check the path") -> Path:
    """``path`` when it is a regular file (or a link to one); else ``error`` saying
    ``"{what} not found"`` or ``"{what} is not a regular file (…)"``."""
    if not path.exists():
        raise error(f"{what} not found", file=path, fix=fix)
    if not path.is_file():
        kind = "a directory" if path.is_dir() else "a device, FIFO or socket"
        raise error(f"{what} is not a regular file ({kind})", file=path,
                    fix=f"give a regular file ({fix})")
    return path


def special(path: Path) -> bool:
    """Whether ``path`` exists but is neither a regular file nor a directory (a device, a
    FIFO or a socket): a sidecar there is refused rather than ignored."""
    return path.exists() and not path.is_file() and not path.is_dir()


def require_inside(path: Path, folder: Path, what: str, *, fix: str) -> Path:
    """``path`` when it lies inside ``folder`` once links are resolved; else InputError.

    A file found or named *for* the user — a sidecar beside the data, a file a well's
    configuration names, a part of a log folder — must not lead out of that folder (a link
    or ``../`` to ``/etc/passwd`` or to another well's data): drillfric reads only what the
    user named (docs/security.md). A file elsewhere is given on the command line instead.
    """
    if not path.resolve().is_relative_to(folder.resolve()):
        raise InputError(f"{what} leads outside {folder.name or folder}/ (a link or '..')",
                         file=path, fix=fix)
    return path
