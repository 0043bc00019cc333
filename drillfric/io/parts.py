"""A well's log split over several files of one format in a folder — the hourly or daily
CSV or Parquet exports of a rig recorder — read as one log, its files in name order, numbers
in names by value (``p9`` before ``p10``; docs/ingestion.md "A well on disk", docs/fleet.md
"Only what is new").
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

import pandas as pd

from drillfric.errors import InputError
from drillfric.io.atomic import OUT_FILES, RECORDING_SUFFIX
from drillfric.io.readers import data_format, open_source
from drillfric.io.source import RawSource
from drillfric.io.text import printable
from drillfric.units import parse_unit

#: Formats whose files a folder may hold as parts of one log.
PART_FORMATS = ("csv", "parquet")
#: Names of files in a data folder that are sidecars, not parts.
_SIDECAR_TAGS = (".survey.", ".truth.", ".tubular.")


def folder_parts(folder: Path, named=()) -> tuple[Path, ...] | None:
    """The data files of a folder holding one log in parts (name order), or None when it
    holds none. Hidden files and sidecars are not parts, nor any file in ``named`` — the
    files the well's configuration names as something else (its ``[survey] file``, a
    survey or configuration given on the command line): a survey ``deviation.csv`` beside
    the hourly parts was read as a part of the log (issue 30, tenth attack).

    Raises
    ------
    InputError
        Files of several formats (or of a format read only whole) in the folder.
    """
    if not folder.is_dir():
        return None
    others = {_identity(Path(p)) for p in named if p is not None} - {None}
    files = sorted((p for p in folder.iterdir() if p.is_file() and not p.name.startswith(".")
                   and not any(tag in p.name for tag in _SIDECAR_TAGS)
                   and p.suffix.lower() not in (".toml", ".json", ".md")
                   and not _drillfrics(p.name) and _identity(p) not in others),
                   key=lambda p: natural_key(p.name))
    if not files:
        return None
    formats = {_format(p) for p in files}
    if len(formats) > 1 or not formats <= set(PART_FORMATS):
        raise InputError(f"a data folder holds files of {', '.join(sorted(formats))}: its "
                         "files must be parts of one log of one format", file=folder,
                         fix="keep only the log's CSV or Parquet files in the folder")
    return tuple(files)


#: ``DataFrame.attrs`` key of a part's raw chunks: the part's file name, for messages
#: (:class:`~drillfric.io.timebase.TimeTracker`: two overlapping exports named).
PART_ATTR = "drillfric_part"


def _tagged(source: RawSource) -> RawSource:
    """``source`` whose raw chunks carry its file name in ``attrs[PART_ATTR]``."""
    read, name = source._read, source.path.name

    def tagged(*args):
        for chunk in read(*args):
            chunk.attrs[PART_ATTR] = name
            yield chunk

    return replace(source, _read=tagged)


def natural_key(name: str) -> tuple:
    """Sort key of a part's name with its numbers compared by value: the hourly parts
    ``p9``, ``p10``, ``p11`` of a recorder that does not pad its numbers sorted as
    ``p10, p11, p9`` and were refused as overlapping (issue 30, tenth attack).

    Examples
    --------
    >>> sorted(["p10.csv", "p9.csv", "p11.csv"], key=natural_key)
    ['p9.csv', 'p10.csv', 'p11.csv']
    >>> sorted(["2026-11-27_10.csv", "2026-11-27_09.csv"], key=natural_key)[0]
    '2026-11-27_09.csv'
    """
    runs = re.split(r"(\d+)", name)
    return tuple(int(r) if i % 2 else r for i, r in enumerate(runs)), name


def _identity(path: Path):
    """What tells two names of one file apart from two files (device and inode, else the
    resolved path); None for a file that is not there."""
    try:
        st = path.stat()
    except OSError:
        return None
    return (st.st_dev, st.st_ino)


def _drillfrics(name: str) -> bool:
    """A file drillfric writes in OUT (--out may be the data folder itself: the next night
    read its own fleet.html and fleet_summary.parquet as parts of the log)."""
    return name.casefold() in OUT_FILES or name.casefold().endswith(RECORDING_SUFFIX)


def _format(path: Path) -> str:
    try:
        return data_format(path)
    except InputError:
        return f"'{printable(path.suffix or path.name)}'"


def _unit_clash(first: dict, other: dict) -> tuple[str, str, str] | None:
    """The first column whose stated unit differs between two parts (column, the first
    part's unit, the other's), or None: spellings of one unit (``N.m``, ``N·m``) agree; a
    unit stated in one part only is not a clash (it is read as the first part states)."""
    for column, unit in other.items():
        theirs = first.get(column)
        if isinstance(column, str) and unit and theirs and not _same(theirs, unit):
            return column, theirs, unit
    return None


def _same(a: str, b: str) -> bool:
    """Whether two unit spellings are one unit (text that is no unit compares as text)."""
    if a.strip().lower() == b.strip().lower():
        return True
    try:
        ua, ub = parse_unit(a), parse_unit(b)
    except InputError:
        return False
    try:
        return abs((1.0 * ua).to(ub).magnitude - 1.0) <= 1e-9
    except Exception:  # noqa: BLE001 — pint's DimensionalityError and kin: not one unit
        return False


def open_parts(paths) -> RawSource:
    """One raw source from the parts of a log (each opened as the file it is; every part
    must have the first part's columns). Its ``parts`` are the parts' own sources."""
    sources = tuple(_tagged(open_source(p)) for p in paths)
    first = sources[0]
    for src in sources[1:]:
        if src.columns != first.columns:
            raise InputError(f"columns differ from those of {printable(first.path.name)}",
                             file=src.path, fix="give every part of the log the same columns")
        clash = _unit_clash(first.units, src.units)
        if clash:
            column, theirs, mine = clash
            raise InputError(f"column '{printable(column)}' is in '{printable(mine)}' here and "
                             f"in '{printable(theirs)}' in {printable(first.path.name)}: the "
                             "parts would be read in the first part's unit",
                             file=src.path, fix="write every part of the log in the same units "
                                                "(convert this part), or run it as a well of "
                                                "its own")
    rows = None if any(s.rows is None for s in sources) else sum(s.rows for s in sources)

    def read(chunk_rows: int) -> Iterator[pd.DataFrame]:
        for src in sources:
            yield from src.chunks(chunk_rows)

    return replace(RawSource(first.path.parent, first.format, first.columns, first.units, rows,
                             read), parts=sources)
