"""An opened surface data file (:class:`RawSource`) and the rig-log null values.

Every format reader (:mod:`drillfric.io.readers`, :mod:`drillfric.io.delimited`,
:mod:`drillfric.io.hdf5`, :mod:`drillfric.io.witsml`, :mod:`drillfric.io.dlis`,
:mod:`drillfric.io.excel`) returns a :class:`RawSource`. The format table (:data:`FORMATS`,
:func:`data_format`) is here too; the dispatch by extension stays in
:mod:`drillfric.io.readers`, which imports the format modules, never the other way round.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from drillfric.errors import InputError

#: Values meaning "no value" in rig logs (besides empty fields and NaN).
NULL_VALUES = (-999.25, -9999.0)


@dataclass(frozen=True)
class RawSource:
    """An opened surface data file: its columns and stated units, data not yet read.

    Attributes
    ----------
    path : Path
    format : str
        ``"parquet"``, ``"csv"``, ``"hdf5"`` or ``"las"``.
    columns : list of str
        Column labels in file order (``"0"``, ``"1"``, … for a headerless CSV).
    units : dict
        Units the file states per column, and ``("source", column)`` → where they came
        from (``"units row"``, ``"header"``) for :func:`drillfric.io.channels.map_channels`.
    rows : int or None
        Row count when known without reading the data.
    depth_index : str or None
        The index curve of a depth-indexed LAS log (e.g. ``"DEPT [M]"``), else None.
    parts : tuple of RawSource
        For a log split over files in a folder (:mod:`drillfric.io.parts`): each file's own
        source, in reading order; else empty.
    seek : str or None
        How :meth:`window` addresses rows: ``"byte"`` (a delimited text file: byte
        offsets), ``"row"`` (Parquet, WITSML, HDF5, LAS: row numbers); None: the source is
        read whole.
    digest : callable or None
        ``digest(n)``: a SHA-256 (hex) of what gives the values of the first ``n`` rows (None:
        of all :attr:`rows`) — their stated columns, units and contents — for a source whose
        growth is recognised by its rows' content rather than its bytes (a WITSML log
        rewritten with more rows, an HDF5 table, a LAS file: docs/fleet.md "Only what is
        new"); None for the others.
    narrow : dict
        Columns stored in fewer bits than a float64 (Parquet float32, float16):
        ``{column: (type name, largest magnitude from the file's statistics, NaN when
        unknown)}``; they are read widened to float64 (:func:`drillfric.io.well.check_narrow`
        says where the narrow type lost what a run needs).
    where : str or None
        Which part of the file was read, for messages (an Excel workbook's sheet:
        ``"sheet 'Surface log'"``); None when the file is one table.
    """

    path: Path
    format: str
    columns: list[str]
    units: dict
    rows: int | None
    _read: Callable[[int], Iterator[pd.DataFrame]] = field(repr=False, compare=False)
    depth_index: str | None = None
    seek: str | None = None
    parts: tuple = ()
    digest: Callable[[int | None], str] | None = field(default=None, repr=False,
                                                       compare=False)
    narrow: dict = field(default_factory=dict, repr=False, compare=False)
    where: str | None = None

    def chunks(self, chunk_rows: int = 200_000) -> Iterator[pd.DataFrame]:
        """Yield the raw data in blocks of at most ``chunk_rows`` rows, labelled by column."""
        if chunk_rows < 1:
            raise ValueError("chunk_rows must be positive")
        yield from self._read(chunk_rows)

    def window(self, start: int, stop: int | None,
               chunk_rows: int = 200_000) -> Iterator[pd.DataFrame]:
        """The rows between positions ``start`` and ``stop`` (None: the end) in the unit of
        :attr:`seek` — bytes (``start`` 0 or a line's beginning past the header) or rows —
        in blocks as :meth:`chunks`."""
        if self.seek is None:
            raise ValueError(f"a {self.format} source is read whole")
        yield from self._read(chunk_rows, start, stop)

class RowsDigest:
    """:attr:`RawSource.digest` of a source read by row number (HDF5, LAS): a SHA-256 of
    the columns and units it states and of its first ``n`` rows' values (pandas' per-row
    hashes, the same whatever the blocks read). The hash goes on from the rows it last
    covered, so the check of a grown file (its earlier rows) and its mark (all its rows)
    read its rows once.

    Parameters
    ----------
    columns, units
        What the source states (``units``: column → unit).
    window : callable
        ``window(start, stop)``: the rows [start, stop) in blocks.
    rows : int
        The source's rows now.
    """

    def __init__(self, columns: list[str], units: dict,
                 window: Callable[[int, int], Iterator[pd.DataFrame]], rows: int):
        stated = {str(k): v for k, v in units.items() if isinstance(k, str)}
        self._described = json.dumps([list(columns), stated], sort_keys=True).encode()
        self._window, self._rows = window, rows
        self._at, self._hash = 0, hashlib.sha256(self._described)

    def __call__(self, n: int | None = None) -> str:
        n = self._rows if n is None else min(n, self._rows)
        if n < self._at:
            self._at, self._hash = 0, hashlib.sha256(self._described)
        for chunk in self._window(self._at, n):
            self._hash.update(pd.util.hash_pandas_object(chunk, index=False).to_numpy()
                              .tobytes())
        self._at = n
        return self._hash.hexdigest()


#: Extensions of surface data files, by format.
FORMATS = {".parquet": "parquet", ".pq": "parquet", ".csv": "csv", ".txt": "csv",
           ".tsv": "csv", ".h5": "hdf5", ".hdf5": "hdf5", ".las": "las", ".xml": "witsml",
           ".dlis": "dlis", ".xlsx": "excel"}


def data_format(path: Path) -> str:
    """Format name for a data file's extension, or InputError for an unknown extension."""
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        known = ", ".join(sorted({e for e in FORMATS}))
        raise InputError(f"unknown file extension '{path.suffix or '(none)'}'", file=path,
                         fix=f"give a surface data file ending in one of {known}")
    return fmt
