"""Domain exceptions: every user-facing problem names the file, the problem and the fix.

Library code raises these; the CLI turns them into one readable line and exit code 2
(never a traceback unless ``--debug``). Input validation never uses ``assert``.
"""

from __future__ import annotations

from pathlib import Path


class DrillfricError(Exception):
    """A problem the user can fix.

    Parameters
    ----------
    problem : str
        What is wrong, in one sentence without a trailing period.
    file : str or Path, optional
        The file the problem is in (or about).
    fix : str, optional
        What to do about it.
    """

    def __init__(self, problem: str, *, file: str | Path | None = None, fix: str | None = None):
        self.problem = problem
        self.file = None if file is None else str(file)
        self.fix = fix
        super().__init__(self.message)

    @property
    def message(self) -> str:
        """The one-line message shown to users: ``FILE: PROBLEM. Fix: FIX``."""
        text = f"{self.file}: {self.problem}" if self.file else self.problem
        if self.fix:
            text += f" — fix: {self.fix}"
        return text

    def __str__(self) -> str:
        return self.message


class InputError(DrillfricError):
    """An input data file (surface log, survey) is missing, unreadable or inconsistent."""


class ConfigError(DrillfricError):
    """A configuration file or option is invalid (unknown key, wrong type, out of range)."""


class ModelError(DrillfricError):
    """Physically meaningless or unstable model settings (zero inertia, μ_k > μ_s, ...)."""


class OutputError(DrillfricError):
    """Results cannot be written (disk full, read-only, name too long, a file in the way,
    or a directory drillfric did not write where a result would go)."""
