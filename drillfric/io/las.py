"""LAS 2.0 logs through lasio, in bounded time and without lasio's own output.

lasio reads a LAS file whole, and its header parse is quadratic in the number of items of a
section (every item appended is compared with all before it: 1 000 curves 1.9 s, 2 000
7 s, 4 000 36 s, measured with lasio 0.31). Before lasio sees a file, :func:`header_items`
counts the items of each header section in one pass over the header (lines of at most
:data:`~drillfric.io.delimited.MAX_LINE_CHARS`), and a file with more than
:data:`MAX_SECTION_ITEMS` items in a section, or larger than :data:`MAX_LAS_BYTES`, is
refused with one line (docs/security.md). lasio's logged warnings quote the file's text:
they are caught, made printable and re-issued as :class:`LasWarning` naming the file.

Every failure to read becomes an :class:`~drillfric.errors.InputError` naming the file.
"""

from __future__ import annotations

import logging
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pandas as pd

from drillfric.errors import InputError
from drillfric.io.delimited import MAX_LINE_CHARS
from drillfric.io.source import RawSource, RowsDigest
from drillfric.io.text import printable

#: Most items (curves, parameters, well lines) a LAS header section may hold: rig and
#: wireline logs hold tens to a few hundred curves; lasio takes ~2 s for 1 000.
MAX_SECTION_ITEMS = 1000
#: Largest LAS file read [bytes]: lasio reads a file whole, into several times its size in
#: memory (CSV and Parquet are read in chunks and have no such limit).
MAX_LAS_BYTES = 1 << 30
#: LAS index curves that make a log depth-indexed (LAS 2.0 names the depth index DEPT).
_DEPTH_INDEX = frozenset({"DEPT", "DEPTH", "MD", "DMEA", "TVD"})
#: Units of a depth index as LAS headers spell them.
_DEPTH_UNITS = frozenset({"M", "FT", "F", "METER", "METERS", "METRE", "METRES", "FEET"})
#: Longest piece of a lasio message quoted [characters].
_QUOTE = 120


class LasWarning(UserWarning):
    """Something lasio noticed while reading a LAS file (the message made printable)."""


def open_las(path: Path) -> RawSource:
    """Open a LAS 2.0 file (read whole) into a :class:`~drillfric.io.source.RawSource`.

    Raises
    ------
    InputError
        Larger than :data:`MAX_LAS_BYTES`, a header section with more than
        :data:`MAX_SECTION_ITEMS` items, or not readable as LAS 2.0.
    """
    import lasio

    _check_size(path)
    try:
        with _lasio_warnings(path), warnings.catch_warnings():
            # lasio builds its frame column by column (pandas warns of fragmentation)
            warnings.simplefilter("ignore", pd.errors.PerformanceWarning)
            las = lasio.read(str(path), ignore_header_errors=False)
            frame = las.df().reset_index()
    except Exception as exc:  # noqa: BLE001 — lasio raises many types for malformed files
        raise InputError(f"not a readable LAS 2.0 file ({type(exc).__name__}: "
                         f"{printable(exc, _QUOTE)})", file=path,
                         fix="check the ~Curve and ~ASCII sections") from exc
    columns = [c.mnemonic for c in las.curves]
    frame.columns = columns
    units = {c.mnemonic: c.unit for c in las.curves if c.unit}
    units.update({("source", c): "header" for c in list(units)})

    def read(chunk_rows: int, start: int = 0, stop: int | None = None
             ) -> Iterator[pd.DataFrame]:
        """Rows [start, stop) (None: to the end)."""
        end = len(frame) if stop is None else min(stop, len(frame))
        for first in range(start, end, chunk_rows):
            yield frame.iloc[first:min(first + chunk_rows, end)].reset_index(drop=True)

    digest = RowsDigest(columns, units, lambda a, b: read(200_000, a, b), len(frame))
    return RawSource(path, "las", columns, units, len(frame), read,
                     depth_index=_depth_index(las.curves[0]) if las.curves else None,
                     seek="row", digest=digest)


def header_items(path: Path) -> dict[str, int]:
    """Items per header section (``{"~C": 12, …}``), counted up to the ``~A`` section.

    One pass over the header, reading at most :data:`MAX_LINE_CHARS` per line; blank lines
    and ``#`` comments are not items, nor are the lines of ``~O`` (free text).
    """
    counts: dict[str, int] = {}
    section = None
    with path.open("rb") as fh:
        while line := fh.readline(MAX_LINE_CHARS + 1):
            if len(line) > MAX_LINE_CHARS:
                raise InputError(f"a header line is longer than {MAX_LINE_CHARS:,} characters",
                                 file=path, fix="check that the file is a LAS 2.0 export")
            text = line.strip()
            if text.startswith(b"~"):
                section = text[:2].upper().decode("latin-1")
                if section == "~A":
                    break
            elif section is not None and section != "~O" and text and not text.startswith(
                    b"#"):
                counts[section] = counts.get(section, 0) + 1
    return counts


def _check_size(path: Path) -> None:
    size = path.stat().st_size
    if size > MAX_LAS_BYTES:
        raise InputError(f"LAS file of {size / 2**30:.4g} GiB: more than the "
                         f"{MAX_LAS_BYTES / 2**30:.4g} GiB read whole", file=path,
                         fix="export the log as CSV or Parquet (read in chunks)")
    for section, count in header_items(path).items():
        if count > MAX_SECTION_ITEMS:
            raise InputError(f"LAS section {printable(section)} holds {count:,} items: more "
                             f"than the {MAX_SECTION_ITEMS:,} drillfric reads", file=path,
                             fix="export only the channels needed (time, surface speed and "
                                 "torque, hook load, depths)")


class _Collect(logging.Handler):
    def __init__(self):
        super().__init__(logging.WARNING)
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.messages.append(record.getMessage())


@contextmanager
def _lasio_warnings(path: Path):
    """lasio's logged warnings, caught while reading and re-issued as :class:`LasWarning`
    (made printable, naming the file) instead of reaching stderr raw."""
    logger = logging.getLogger("lasio")
    handler, propagate = _Collect(), logger.propagate
    # a logging.config.dictConfig elsewhere in the process (Dask's, on import) disables the
    # loggers that existed then (lasio's module loggers): its warnings would vanish
    family = [logging.getLogger(n) for n in list(logging.root.manager.loggerDict)
              if n == "lasio" or n.startswith("lasio.")]
    disabled = [lg.disabled for lg in family]
    logger.addHandler(handler)
    logger.propagate = False
    for lg in family:
        lg.disabled = False
    try:
        yield
    finally:
        logger.removeHandler(handler)
        logger.propagate = propagate
        for lg, was in zip(family, disabled, strict=True):
            lg.disabled = was
    for message in dict.fromkeys(handler.messages):
        # warn_explicit with a fresh registry: each file's warnings are shown, even when an
        # earlier read in this process gave the same text (the default filter shows a
        # warning once per code location and text)
        warnings.warn_explicit(f"{path.name}: LAS reader: {printable(message, _QUOTE)}",
                               LasWarning, __file__, 0, module=__name__, registry={})


def _depth_index(curve) -> str | None:
    """``"DEPT [M]"`` when a LAS index curve is a depth (by mnemonic or length unit)."""
    unit = (curve.unit or "").strip().upper()
    if curve.mnemonic.strip().upper() in _DEPTH_INDEX or unit in _DEPTH_UNITS:
        return f"{curve.mnemonic} [{curve.unit}]" if curve.unit else curve.mnemonic
    return None
