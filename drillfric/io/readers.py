"""Format readers for rig surface data (Parquet, CSV, HDF5, LAS 2.0) and the dispatch by extension.

Each reader opens a file cheaply (schema, header, units; no data) into a :class:`RawSource`
whose :meth:`RawSource.chunks` yields the raw columns in blocks of rows, so that a large
file never has to be in memory at once: Parquet by record batches (pyarrow), CSV by pandas
chunks, HDF5 by row slices through h5py only (:mod:`drillfric.io.hdf5`: nothing in a file is
ever unpickled), LAS as one block (:mod:`drillfric.io.las`: lasio reads LAS files whole).
Channel recognition and unit conversion happen later (:mod:`drillfric.io.channels`);
readers only report the units the file itself states.

Every failure to read becomes an :class:`~drillfric.errors.InputError` naming the file.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pandas as pd

from drillfric.errors import InputError
from drillfric.files import require_file
from drillfric.io.source import RawSource, data_format
from drillfric.io.text import printable

#: Most rows a Parquet file may declare per byte of file: run-length and delta encoding pack
#: constant and evenly spaced columns to almost nothing, but a real log (a torque column) needs
#: bytes per row; a 4 kB file declaring 10¹² rows of one run would be read for ever.
MAX_ROWS_PER_BYTE = 100
#: Most rows a Parquet file may declare: 2³², over a year of 100 Hz samples.
MAX_ROWS = 1 << 32

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
    require_file(path)
    if path.stat().st_size == 0:
        raise InputError("file is empty", file=path, fix="give a file with data rows")
    if fmt == "hdf5":
        from drillfric.io.hdf5 import open_hdf5

        return open_hdf5(path, hdf_key)
    if fmt == "csv":
        from drillfric.io.delimited import open_delimited

        return open_delimited(path)
    return {"parquet": _open_parquet, "las": _open_las, "witsml": _open_witsml,
            "dlis": _open_native, "excel": _open_native}[fmt](path)


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
    _refuse_nested(schema, path)
    check_rows(meta.metadata.num_rows, path)
    units = {}
    for fld in schema:
        md = fld.metadata or {}
        unit = md.get(b"unit") or md.get(b"units")
        if unit:
            units[fld.name] = unit.decode()
            units[("source", fld.name)] = "header"

    def read(chunk_rows: int, start: int = 0, stop: int | None = None
             ) -> Iterator[pd.DataFrame]:
        """Rows [start, stop) (row numbers; None: to the end)."""
        try:
            source = pq.ParquetFile(path)
            groups, skip = _groups_from(source.metadata, start)
            left = None if stop is None else max(stop - start, 0)
            for batch in source.iter_batches(batch_size=chunk_rows, row_groups=groups):
                cut = min(skip, batch.num_rows)
                batch, skip = batch.slice(cut), skip - cut
                if left is not None:
                    batch = batch.slice(0, left)
                    left -= batch.num_rows
                if batch.num_rows:
                    # ignore_metadata: a pandas index stays a column under its schema name
                    yield pa.Table.from_batches([batch]).to_pandas(ignore_metadata=True)
        except (pa.ArrowException, OSError) as exc:
            raise corrupt from exc

    return RawSource(path, "parquet", list(schema.names), units, meta.metadata.num_rows, read,
                     seek="row", narrow=_narrow_floats(schema, meta.metadata))


def _narrow_floats(schema, metadata) -> dict:
    """``{column: (type, largest magnitude)}`` of the float32/float16 columns, the
    magnitude from the row groups' statistics (NaN when they give none): read before any
    data, so that a time column too coarse for its samples is one clear line (issue 30, tenth
    attack), not every timestamp "repeated with other values"."""
    import numpy as np
    import pyarrow.types as pt

    out = {}
    for j, fld in enumerate(schema):
        if not (pt.is_float16(fld.type) or pt.is_float32(fld.type)):
            continue
        dtype = np.float16 if pt.is_float16(fld.type) else np.float32
        largest = 0.0
        try:
            for g in range(metadata.num_row_groups):
                stats = metadata.row_group(g).column(j).statistics
                if stats is None or not stats.has_min_max:
                    raise ValueError("no statistics")
                for v in (stats.min, stats.max):
                    value = (float(np.frombuffer(v, "<f2")[0]) if isinstance(v, bytes)
                             else float(v))
                    largest = max(largest, abs(value))
        except (ValueError, TypeError, IndexError):
            largest = float("nan")
        out[fld.name] = (dtype.__name__, largest)
    return out


def _groups_from(metadata, start: int) -> tuple[list[int], int]:
    """The row groups holding rows from ``start`` on, and the rows of the first to skip."""
    first = 0
    for i in range(metadata.num_row_groups):
        rows = metadata.row_group(i).num_rows
        if first + rows > start:
            return list(range(i, metadata.num_row_groups)), start - first
        first += rows
    return [], 0


def check_rows(rows: int, path: Path) -> None:
    """Refuse a Parquet file declaring more rows than :data:`MAX_ROWS` or
    :data:`MAX_ROWS_PER_BYTE` × its size (read before any data)."""
    size = path.stat().st_size
    if rows > min(MAX_ROWS_PER_BYTE * size, MAX_ROWS):
        raise InputError(f"refused: the Parquet file declares {rows:.4g} rows in {size:.4g} "
                         f"bytes (the limit is {MAX_ROWS_PER_BYTE} rows per byte, at most "
                         f"{MAX_ROWS:.4g} rows)", file=path,
                         fix="re-export the data (the file declares more than it can hold: "
                             "crafted, or split it into parts)")


def _refuse_nested(schema, path: Path) -> None:
    """A nested column (list, struct, map, union) holds many values per row: refused with
    its name and type (not reported as a corrupt file)."""
    import pyarrow.types as pt

    for fld in schema:
        kind = fld.type
        if pt.is_dictionary(kind):
            kind = kind.value_type
        if pt.is_nested(kind):
            raise InputError(f"unsupported column type: column '{printable(fld.name)}' is a "
                             f"nested Parquet {printable(kind)} (drillfric reads one number, "
                             "text or timestamp per row and column)", file=path,
                             fix="flatten the column to one value per row, or drop it")


# ------------------------------------------------------------------ LAS, WITSML, DLIS, Excel
def _open_las(path: Path) -> RawSource:
    from drillfric.io.las import open_las

    return open_las(path)


def _open_witsml(path: Path) -> RawSource:
    from drillfric.io.witsml import open_witsml

    return open_witsml(path)


def _open_native(path: Path) -> RawSource:
    """DLIS and Excel: native parsers, run in a contained child process."""
    from drillfric.io.isolated import open_isolated

    return open_isolated(path)
