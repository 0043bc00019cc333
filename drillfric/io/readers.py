"""Format readers for rig surface data (Parquet, CSV, HDF5, LAS 2.0) and the dispatch by extension.

Each reader opens a file cheaply (schema, header, units; no data) into a :class:`RawSource`
whose :meth:`RawSource.chunks` yields the raw columns in blocks of rows, so that a large
file never has to be in memory at once: Parquet by record batches (pyarrow), CSV by pandas
chunks, HDF5 by row slices through h5py only (:mod:`drillfric.io.hdf5`: nothing in a file is
ever unpickled), LAS as one block (lasio reads LAS files whole). Channel recognition and unit
conversion happen later (:mod:`drillfric.io.channels`); readers only report the units the
file itself states.

Every failure to read becomes an :class:`~drillfric.errors.InputError` naming the file.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pandas as pd

from drillfric.errors import InputError
from drillfric.io.source import RawSource

#: Extensions of surface data files, by format.
FORMATS = {".parquet": "parquet", ".pq": "parquet", ".csv": "csv", ".txt": "csv",
           ".tsv": "csv", ".h5": "hdf5", ".hdf5": "hdf5", ".las": "las", ".xml": "witsml",
           ".dlis": "dlis", ".xlsx": "excel"}
#: LAS index curves that make a log depth-indexed (LAS 2.0 names the depth index DEPT).
_DEPTH_INDEX = frozenset({"DEPT", "DEPTH", "MD", "DMEA", "TVD"})
#: Units of a depth index as LAS headers spell them.
_DEPTH_UNITS = frozenset({"M", "FT", "F", "METER", "METERS", "METRE", "METRES", "FEET"})


def data_format(path: Path) -> str:
    """Format name for a data file's extension, or InputError for an unknown extension."""
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        known = ", ".join(sorted({e for e in FORMATS}))
        raise InputError(f"unknown file extension '{path.suffix or '(none)'}'", file=path,
                         fix=f"give a surface data file ending in one of {known}")
    return fmt


def open_source(path: str | Path, *, hdf_key: str = "surface") -> RawSource:
    """Open a surface data file by its extension.

    Parameters
    ----------
    path : str or Path
        Data file (``.parquet``, ``.csv``, ``.h5``/``.hdf5``, ``.las``).
    hdf_key : str
        Group or table holding the surface data in an HDF5 file.

    Raises
    ------
    InputError
        Missing, empty, unknown extension, truncated or unreadable.
    """
    path = Path(path)
    fmt = data_format(path)
    if not path.is_file():
        raise InputError("file not found", file=path, fix="check the path")
    if path.stat().st_size == 0:
        raise InputError("file is empty", file=path, fix="give a file with data rows")
    if fmt == "hdf5":
        from drillfric.io.hdf5 import open_hdf5

        return open_hdf5(path, hdf_key)
    if fmt == "csv":
        from drillfric.io.delimited import open_delimited

        return open_delimited(path)
    return {"parquet": _open_parquet, "las": _open_las, "witsml": _open_witsml,
            "dlis": _open_dlis, "excel": _open_excel}[fmt](path)


# --------------------------------------------------------------------------- Parquet
def _open_parquet(path: Path) -> RawSource:
    import pyarrow as pa
    import pyarrow.parquet as pq

    corrupt = InputError("not a readable Parquet file (truncated or corrupt)", file=path,
                         fix="re-export or re-copy the file")
    try:
        meta = pq.ParquetFile(path)
        schema = meta.schema_arrow
    except (pa.ArrowException, OSError) as exc:
        raise corrupt from exc
    units = {}
    for fld in schema:
        md = fld.metadata or {}
        unit = md.get(b"unit") or md.get(b"units")
        if unit:
            units[fld.name] = unit.decode()
            units[("source", fld.name)] = "header"

    def read(chunk_rows: int) -> Iterator[pd.DataFrame]:
        try:
            for batch in pq.ParquetFile(path).iter_batches(batch_size=chunk_rows):
                # ignore_metadata: a pandas index stays a column under its schema name
                yield pa.Table.from_batches([batch]).to_pandas(ignore_metadata=True)
        except (pa.ArrowException, OSError) as exc:
            raise corrupt from exc

    return RawSource(path, "parquet", list(schema.names), units, meta.metadata.num_rows, read)


# --------------------------------------------------------------------------- LAS
def _open_las(path: Path) -> RawSource:
    import lasio

    try:
        las = lasio.read(str(path), ignore_header_errors=False)
        frame = las.df().reset_index()
    except Exception as exc:  # noqa: BLE001 — lasio raises many types for malformed files
        raise InputError(f"not a readable LAS 2.0 file ({type(exc).__name__}: {exc})",
                         file=path, fix="check the ~Curve and ~ASCII sections") from exc
    columns = [c.mnemonic for c in las.curves]
    frame.columns = columns
    units = {c.mnemonic: c.unit for c in las.curves if c.unit}
    units.update({("source", c): "header" for c in list(units)})

    def read(chunk_rows: int) -> Iterator[pd.DataFrame]:
        for start in range(0, len(frame), chunk_rows):
            yield frame.iloc[start:start + chunk_rows].reset_index(drop=True)

    return RawSource(path, "las", columns, units, len(frame), read,
                     depth_index=_depth_index(las.curves[0]) if las.curves else None)


def _depth_index(curve) -> str | None:
    """``"DEPT [M]"`` when a LAS index curve is a depth (by mnemonic or length unit)."""
    unit = (curve.unit or "").strip().upper()
    if curve.mnemonic.strip().upper() in _DEPTH_INDEX or unit in _DEPTH_UNITS:
        return f"{curve.mnemonic} [{curve.unit}]" if curve.unit else curve.mnemonic
    return None


# --------------------------------------------------------------------------- WITSML, DLIS, Excel
def _open_witsml(path: Path) -> RawSource:
    from drillfric.io.witsml import open_witsml

    return open_witsml(path)


def _open_dlis(path: Path) -> RawSource:
    from drillfric.io.dlis import open_dlis

    return open_dlis(path)


def _open_excel(path: Path) -> RawSource:
    from drillfric.io.excel import open_excel

    return open_excel(path)
