"""An engine's state on disk: JSON, one ``.npz`` of arrays and Parquet tables — nothing
that executes code when read (no pickle; docs/api.md "The engine's state").

A state is a tree of plain values (dict, list, str, int, float, bool, None), numpy arrays
and DataFrames. :func:`write_state` puts the tree into ``engine.json`` with every array
replaced by ``{"$array": KEY}`` (stored under KEY in ``arrays.npz``, read back with
``allow_pickle=False``), every DataFrame by ``{"$frame": "frame-N.parquet"}`` and every
non-finite float by ``{"$float": "nan" | "inf" | "-inf"}``. :func:`read_state` reverses it and
refuses anything else: a state is input too (docs/security.md).
"""

from __future__ import annotations

import json
import math
import re
import zipfile
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq

from drillfric.errors import InputError
from drillfric.io.atomic import own_file

#: ``engine.json`` ``format`` and ``version`` of the state this drillfric writes and reads.
STATE_FORMAT = "drillfric-engine-state"
STATE_VERSION = 2  # 2: the torque at rest (drillfric.torque_zero) joined the accumulators
_DOC, _ARRAYS = "engine.json", "arrays.npz"
_FRAME_NAME = re.compile(r"^frame-\d{1,6}\.parquet$")
_FIX = "run the well again from its start (drillfric fleet --force)"
#: Largest engine.json read [bytes] (a state is a few MB; the rows live in arrays and tables).
MAX_DOC_BYTES = 64 << 20
#: Deepest nesting of engine.json (the engine's state is a few levels deep).
MAX_DEPTH = 64
#: Decoded bytes a state table may hold per byte of its file, and the floor below which any
#: table is read (floats compress ~1–3×; a 2-MB file declaring 2×10⁸ rows is refused).
MAX_TABLE_RATIO, MIN_TABLE_BYTES = 50, 64 << 20
#: dtype kinds of the arrays a state holds (bool, integers, floats, datetimes).
_ARRAY_KINDS = "biufMm"


def write_state(folder: Path, state: dict) -> None:
    """Write ``state`` into ``folder`` (created; its files replaced)."""
    folder.mkdir(parents=True, exist_ok=True)
    arrays: dict[str, np.ndarray] = {}
    frames: list[pd.DataFrame] = []

    def encode(value):
        if isinstance(value, dict):
            return {str(k): encode(v) for k, v in value.items()}
        if isinstance(value, list | tuple):
            return [encode(v) for v in value]
        if isinstance(value, np.ndarray):
            key = f"a{len(arrays)}"
            arrays[key] = value
            return {"$array": key}
        if isinstance(value, pd.DataFrame):
            frames.append(value)
            return {"$frame": f"frame-{len(frames) - 1}.parquet"}
        if isinstance(value, np.generic):
            value = value.item()
        if isinstance(value, float) and not math.isfinite(value):
            return {"$float": str(value)}
        return value

    doc = {"format": STATE_FORMAT, "version": STATE_VERSION, "state": encode(state)}
    for i, frame in enumerate(frames):
        frame.to_parquet(folder / f"frame-{i}.parquet", index=False)
    np.savez(folder / _ARRAYS, **arrays)
    (folder / _DOC).write_text(json.dumps(doc), encoding="utf-8")


def read_state(folder: Path) -> dict:
    """The state written by :func:`write_state`.

    Raises
    ------
    InputError
        No state there, another format or version, or unreadable parts.
    """
    try:
        for part in (folder / _DOC, folder / _ARRAYS):
            own_file(part)  # a link would be read outside OUT, a FIFO would hang
        if (folder / _DOC).stat().st_size > MAX_DOC_BYTES:
            raise ValueError(f"{_DOC} is larger than {MAX_DOC_BYTES >> 20} MB")
        doc = json.loads((folder / _DOC).read_text(encoding="utf-8"))
        if not isinstance(doc, dict) or doc.get("format") != STATE_FORMAT:
            raise ValueError("not an engine state")
        if doc.get("version") != STATE_VERSION:
            raise ValueError(f"state version {doc.get('version')!r}, this drillfric reads "
                             f"{STATE_VERSION}")
        _check_depth(doc["state"])
        _check_arrays(folder / _ARRAYS)
        with np.load(folder / _ARRAYS, allow_pickle=False) as npz:
            arrays = {k: npz[k] for k in npz.files}
        return _decode(doc["state"], arrays, folder)
    except (OSError, ValueError, KeyError, TypeError, RecursionError, EOFError,
            zipfile.BadZipFile) as exc:
        why = str(exc) if isinstance(exc, ValueError | KeyError) else type(exc).__name__
        raise InputError(f"engine state not readable ({why})", file=folder, fix=_FIX) \
            from exc


def _check_depth(value) -> None:
    """ValueError when ``value`` nests deeper than :data:`MAX_DEPTH` (iterative: a deep
    document cannot exhaust the stack here)."""
    stack = [(value, 1)]
    while stack:
        item, depth = stack.pop()
        if depth > MAX_DEPTH:
            raise ValueError(f"nested deeper than {MAX_DEPTH} levels")
        children = item.values() if isinstance(item, dict) else item if \
            isinstance(item, list) else ()
        stack += [(child, depth + 1) for child in children]


def _check_arrays(path: Path) -> None:
    """ValueError unless every member of ``path`` is a stored (uncompressed: np.savez)
    .npy whose header declares no more bytes than it holds — read before any array, so a
    small archive cannot expand into gigabytes."""
    from numpy.lib import format as npy

    with zipfile.ZipFile(path) as archive:
        for info in archive.infolist():
            if info.compress_type != zipfile.ZIP_STORED:
                raise ValueError(f"{info.filename}: compressed (drillfric stores arrays "
                                 "uncompressed)")
            with archive.open(info) as stream:
                read = {(1, 0): npy.read_array_header_1_0,
                        (2, 0): npy.read_array_header_2_0}.get(npy.read_magic(stream))
                if read is None:
                    raise ValueError(f"{info.filename}: not an .npy of version 1 or 2")
                shape, _, dtype = read(stream)
            if dtype.kind not in _ARRAY_KINDS:
                raise ValueError(f"{info.filename}: {dtype} is not a number array")
            if math.prod(shape) * dtype.itemsize > info.file_size:
                raise ValueError(f"{info.filename}: declares more than it holds")


def _read_table(path: Path) -> pd.DataFrame:
    """A state table, refused before reading when its declared rows would decode to more
    than :data:`MAX_TABLE_RATIO` × its size (and :data:`MIN_TABLE_BYTES`)."""
    meta = pq.ParquetFile(own_file(path)).metadata
    decoded = meta.num_rows * max(1, meta.num_columns) * 8
    if decoded > max(MIN_TABLE_BYTES, MAX_TABLE_RATIO * path.stat().st_size):
        raise ValueError(f"{path.name}: declares {meta.num_rows:.3g} rows in "
                         f"{path.stat().st_size:.3g} bytes")
    return pd.read_parquet(path)


def _decode(value, arrays: dict, folder: Path):
    if isinstance(value, list):
        return [_decode(v, arrays, folder) for v in value]
    if not isinstance(value, dict):
        return value
    if set(value) == {"$array"}:
        return arrays[value["$array"]]
    if set(value) == {"$float"}:
        if value["$float"] not in ("nan", "inf", "-inf"):
            raise ValueError("bad float")
        return float(value["$float"])
    if set(value) == {"$frame"}:
        name = value["$frame"]
        if not isinstance(name, str) or not _FRAME_NAME.match(name):
            raise ValueError("bad table name")
        return _read_table(folder / name)
    return {k: _decode(v, arrays, folder) for k, v in value.items()}
