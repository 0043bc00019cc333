"""HDF5 surface tables read through h5py only — nothing in a file is ever executed.

pandas writes HDF5 through PyTables, which unpickles attributes whose text ends in "." and
stores object columns of "fixed" frames as pickles: opening such a file with pandas or
PyTables can run code chosen by whoever made the file (docs/security.md). drillfric never
lets either library open an input file. It reads, with h5py:

- a **group of 1-D datasets**, one per channel (``unit``/``units`` attributes), or one
  **compound dataset** whose fields are the channels;
- a **pandas "table"** (``DataFrame.to_hdf(format="table")``): a compound dataset
  ``table`` whose fields are the index and blocks of columns; the column names of a block
  are stored as protocol-0 pickle *text* (``values_block_0_kind``), which
  :func:`pickle_literal` parses as data (lists, tuples, dicts, text, numbers, None) and
  refuses anything else — no pickle module, no import, no call;
- a **pandas "fixed" frame** (``format="fixed"``): plain arrays of names and values; an
  object block (a pickle per value) is refused.

Nothing outside the named file is read (docs/security.md): a dataset whose raw data live in
another file (*external storage*), a *virtual dataset* (mapped from other files) and an
*external link* are refused before any data is read, and every node is reached through
:func:`node_at`, which never follows a link out of the file. A dataset may declare at most
:data:`MAX_PACKING_RATIO` times the file's size and at most :data:`MAX_DATASET_BYTES`, so a
4 kB file declaring 10¹² rows of unwritten chunks is refused instead of read for ever.

Every failure is an :class:`~drillfric.errors.InputError` naming the file.
"""

from __future__ import annotations

import codecs
import warnings
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pandas as pd

from drillfric.errors import InputError
from drillfric.io.source import RawSource, RowsDigest

_CORRUPT_FIX = "re-export or re-copy the file"
_PICKLED = "refused: the file stores data as Python pickles, which can run code when read"
_PICKLE_FIX = ("export the data as a pandas 'table' (DataFrame.to_hdf(format='table')) with "
               "numeric columns, or as Parquet/CSV")


#: Largest ratio of the bytes a dataset declares to the size of the file holding it.
#: Deflate (gzip, what pandas and h5py compress with) cannot pack more than 1032:1, so a real
#: compressed log stays below; a 4 kB file declaring 10¹² rows of float64 is 2·10⁹:1.
MAX_PACKING_RATIO = 2000
#: Largest size a dataset may declare [bytes]: 1 TiB, a year of 100 Hz samples of 40
#: float64 channels.
MAX_DATASET_BYTES = 1 << 40
#: Deepest chain of soft links followed (HDF5's own limit is 16).
_MAX_SOFT_LINKS = 16
_OUTSIDE_FIX = "copy the data into the file itself (drillfric reads only the files it is given)"


class UnsafePickle(ValueError):
    """Pickle text that is not plain data (a class, a call, a binary protocol)."""


# --------------------------------------------------------------------------- pickle text
def _pickle_ops(text: bytes) -> Iterator[tuple[str, bytes]]:
    """Tokens (opcode, argument) of protocol-0 pickle text, without interpreting them."""
    if text[:1] == b"\x80":
        raise UnsafePickle("binary pickle protocol")
    lines = {"V", "S", "I", "L", "F", "p", "g", "P"}
    pos = 0
    while pos < len(text):
        op = chr(text[pos])
        pos += 1
        if op in lines or op in ("c", "i"):
            count = 2 if op in ("c", "i") else 1
            end = pos
            for _ in range(count):
                end = text.find(b"\n", end)
                if end < 0:
                    raise UnsafePickle("truncated pickle text")
                end += 1
            yield op, text[pos:end - 1]
            pos = end
        else:
            yield op, b""
        if op == ".":
            return
    raise UnsafePickle("pickle text without STOP")


def pickle_literal(text: bytes):
    """Plain data from protocol-0 pickle text, never executing it.

    Accepts only what a list of column names and similar metadata need: marks, lists,
    tuples, dicts, appends/set-items, memo put/get, text (V, S), integers (I, L), floats
    (F) and None. Anything else — a global (class or function), a call, a binary
    protocol — raises :class:`UnsafePickle`.

    Examples
    --------
    >>> pickle_literal(b"(lp0\\nVtime_s\\np1\\naVRPM\\np2\\na.")
    ['time_s', 'RPM']
    >>> pickle_literal(b"cos\\nsystem\\n(S'id'\\ntR.")
    Traceback (most recent call last):
    ...
    drillfric.io.hdf5.UnsafePickle: opcode 'c' is not plain data
    """
    stack: list = []
    memo: dict = {}
    mark = object()
    for op, arg in _pickle_ops(bytes(text)):
        if op == "(":
            stack.append(mark)
        elif op in ("l", "t", "d"):
            k = _last_mark(stack, mark)
            items = stack[k + 1:]
            del stack[k:]
            stack.append(list(items) if op == "l" else tuple(items) if op == "t"
                         else dict(zip(items[::2], items[1::2], strict=True)))
        elif op in ("a", "e"):
            k = len(stack) - 1 if op == "a" else _last_mark(stack, mark)
            items = stack[k:] if op == "a" else stack[k + 1:]
            del stack[k:]
            _expect(stack[-1], list).extend(items)
        elif op in ("s", "u"):
            k = len(stack) - 2 if op == "s" else _last_mark(stack, mark)
            items = stack[k:] if op == "s" else stack[k + 1:]
            del stack[k:]
            _expect(stack[-1], dict).update(zip(items[::2], items[1::2], strict=True))
        elif op == "p":
            memo[arg] = stack[-1]
        elif op == "g":
            stack.append(memo[arg])
        elif op == "V":
            stack.append(codecs.decode(arg, "raw_unicode_escape"))
        elif op == "S":
            stack.append(_quoted(arg))
        elif op in ("I", "L"):
            stack.append(_integer(arg))
        elif op == "F":
            stack.append(float(arg))
        elif op == "N":
            stack.append(None)
        elif op == ".":
            if len(stack) != 1:
                raise UnsafePickle("malformed pickle text")
            return stack[0]
        else:
            raise UnsafePickle(f"opcode {op!r} is not plain data")
    raise UnsafePickle("pickle text without STOP")


def _last_mark(stack: list, mark) -> int:
    for k in range(len(stack) - 1, -1, -1):
        if stack[k] is mark:
            return k
    raise UnsafePickle("malformed pickle text")


def _expect(value, kind):
    if not isinstance(value, kind):
        raise UnsafePickle("malformed pickle text")
    return value


def _quoted(arg: bytes) -> str:
    text = arg.decode("latin-1")
    if len(text) < 2 or text[0] not in "'\"" or text[-1] != text[0]:
        raise UnsafePickle("malformed string in pickle text")
    return codecs.decode(text[1:-1].encode("latin-1"), "unicode_escape")


def _integer(arg: bytes) -> int | bool:
    text = arg.decode("ascii").rstrip("L")
    if text in ("00", "01"):  # protocol 0 spells booleans I00 / I01
        return text == "01"
    return int(text)


def _index_name(info: bytes) -> str | None:
    """The index name pandas records in a table's ``info`` attribute (read as tokens only;
    ``info`` also holds pickled classes such as a frequency, which are never built)."""
    try:
        ops = list(_pickle_ops(bytes(info)))
    except UnsafePickle:
        return None
    for k in range(len(ops) - 2):
        if ops[k] == ("V", b"index_name") and ops[k + 1][0] == "p" and ops[k + 2][0] == "V":
            return codecs.decode(ops[k + 2][1], "raw_unicode_escape")
    return None


# --------------------------------------------------------------------------- opening
def open_hdf5(path: Path, key: str):
    """Open the surface table ``key`` of an HDF5 file (a lone table if ``key`` is absent).

    Returns a :class:`drillfric.io.source.RawSource`.

    Raises
    ------
    InputError
        Not HDF5, truncated, no such table, or a table that would need unpickling.
    """
    import h5py

    try:
        with h5py.File(path, "r") as h5:
            name = _surface_name(h5, key, path)
            node = node_at(h5, name, path)
            kind = _attr_text(node.attrs.get("pandas_type"))
            if kind == "frame_table":
                layout = _pandas_table_layout(node, path)
            elif kind is not None:
                layout = _pandas_fixed_layout(node, path, kind)
            else:
                layout = _plain_layout(node, path)
    except OSError as exc:
        raise InputError("not a readable HDF5 file (truncated or corrupt)", file=path,
                         fix=_CORRUPT_FIX) from exc
    return _source(path, name, *layout)


def _source(path: Path, name: str, columns, units, rows, reader):
    units = dict(units)
    units.update({("source", c): "header" for c in list(units)})

    def read(chunk_rows: int, start: int = 0, stop: int | None = None
             ) -> Iterator[pd.DataFrame]:
        """Rows [start, stop) (None: to the end)."""
        import h5py

        end = rows if stop is None else min(stop, rows)
        try:
            with h5py.File(path, "r") as h5:
                node = node_at(h5, name, path)
                for first in range(start, end, chunk_rows):
                    yield reader(node, first, min(first + chunk_rows, end))
        except (OSError, KeyError) as exc:
            raise InputError("not a readable HDF5 file (truncated or corrupt)", file=path,
                             fix=_CORRUPT_FIX) from exc

    digest = RowsDigest(columns, units, lambda a, b: read(200_000, a, b), rows)
    return RawSource(path, "hdf5", columns, units, rows, read, seek="row", digest=digest)


def _surface_name(h5, key: str, path: Path) -> str:
    """Path of the surface table: ``key``, else the lone table of the file."""
    if h5.get(key, getlink=True) is not None:
        return key
    tables = [k for k in h5 if k not in {"survey", "config"}]
    if key == "surface" and len(tables) == 1:  # a lone table is the surface data
        return tables[0]
    listed = ", ".join("/" + _printable(k) for k in list(h5)[:10]) or "nothing"
    raise InputError(f"no '/{_printable(key)}' table in the HDF5 file (it holds: {listed})",
                     file=path, fix=f"store the surface data under '/{_printable(key)}'")


# --------------------------------------------------------------------------- staying inside
def node_at(h5, name: str, path: Path, depth: int = 0):
    """The group or dataset at ``name`` in the open file ``h5``, reached without leaving it.

    Each step of the path is looked at as a link first: an external (or user-defined) link
    is refused, a soft link is resolved inside the file (at most :data:`_MAX_SOFT_LINKS`
    deep), and a dataset is checked by :func:`check_dataset` before it is returned.

    Raises
    ------
    InputError
        A link out of the file, a missing node, or a dataset :func:`check_dataset` refuses.
    """
    import h5py

    node = h5["/"]
    for part in [p for p in name.split("/") if p]:
        if not isinstance(node, h5py.Group):
            raise _missing(name, path)
        link = node.get(part, getlink=True)
        here = f"{node.name.rstrip('/')}/{part}"
        if link is None:
            raise _missing(name, path)
        if isinstance(link, h5py.SoftLink):
            if depth >= _MAX_SOFT_LINKS:
                raise InputError(f"HDF5 soft link '{_printable(here)}' is part of a loop or a "
                                 f"chain longer than {_MAX_SOFT_LINKS}", file=path,
                                 fix=_CORRUPT_FIX)
            target = link.path if link.path.startswith("/") else f"{node.name}/{link.path}"
            node = node_at(h5, target, path, depth + 1)
        elif isinstance(link, h5py.HardLink):
            node = node[part]
        else:
            raise InputError(f"refused: HDF5 link '{_printable(here)}' points into another "
                             "file", file=path, fix=_OUTSIDE_FIX)
    if isinstance(node, h5py.Dataset):
        check_dataset(node, path)
    return node


def members(group, path: Path) -> dict:
    """The members of ``group`` by name, each reached through :func:`node_at`."""
    return {k: node_at(group.file, f"{group.name.rstrip('/')}/{k}", path) for k in group}


def check_dataset(ds, path: Path) -> None:
    """Refuse a dataset whose data live outside the file or whose declared size is absurd.

    External storage (raw data in another file, e.g. ``/etc/passwd``) and virtual datasets
    (mapped from other files) would read outside the named file; a declared size above
    :data:`MAX_PACKING_RATIO` × the file size or :data:`MAX_DATASET_BYTES` would be read
    (from fill values) for as long as it takes.
    """
    where = _printable(ds.name)
    if ds.external:
        raise InputError(f"refused: HDF5 dataset '{where}' keeps its data in another file "
                         "(external storage)", file=path, fix=_OUTSIDE_FIX)
    if ds.is_virtual:
        raise InputError(f"refused: HDF5 dataset '{where}' is a virtual dataset (its data "
                         "are mapped from other files)", file=path, fix=_OUTSIDE_FIX)
    declared = ds.dtype.itemsize * float(np.prod(ds.shape, dtype=float)) if ds.shape else 0.0
    limit = min(MAX_PACKING_RATIO * path.stat().st_size, MAX_DATASET_BYTES)
    if declared > limit:
        raise InputError(f"refused: HDF5 dataset '{where}' declares {declared:.4g} bytes "
                         f"({len(ds) if ds.shape else 1:.4g} rows) in a file of "
                         f"{path.stat().st_size:.4g} bytes (the limit is {MAX_PACKING_RATIO}× "
                         f"the file size, at most {MAX_DATASET_BYTES / 2**40:.4g} TiB)",
                         file=path, fix="re-export the data (the file declares more than it "
                                        "can hold: truncated, or crafted)")


def _missing(name: str, path: Path) -> InputError:
    return InputError(f"HDF5 node '{_printable(name)}' not found", file=path,
                      fix=_CORRUPT_FIX)


# --------------------------------------------------------------------------- layouts
def _plain_layout(node, path: Path):
    """A group of equal-length 1-D datasets, or one compound dataset."""
    import h5py

    if isinstance(node, h5py.Dataset) and node.dtype.names:
        columns = list(node.dtype.names)
        _refuse_objects(path, [node.dtype[c] for c in columns],
                        [f"{node.name}: field {c}" for c in columns])

        def read(ds, a, b):
            block = ds[a:b]
            return pd.DataFrame({c: _decoded(block[c]) for c in columns})

        return columns, {}, len(node), read
    if not isinstance(node, h5py.Group):
        raise InputError(f"HDF5 node '{_printable(node.name)}' is not a table", file=path,
                         fix="store a group of 1-D datasets or a pandas table")
    found = {k: v for k, v in members(node, path).items() if isinstance(v, h5py.Dataset)}
    # an (N, 1) dataset is a column (MATLAB and some writers store vectors so); it had been
    # left out in silence: "required channel surface_rpm not found" (issue 30, eleventh
    # attack). A dataset of another shape is no column, and a warning names it.
    datasets = {k: v for k, v in found.items()
                if v.ndim == 1 or v.ndim == 2 and v.shape[1] == 1}
    for k, v in found.items():
        if k not in datasets:
            warnings.warn_explicit(
                f"{path}: HDF5 dataset '{_printable(v.name)}' has shape {v.shape}, not one "
                "value per row (N or N×1): not read as a column", Hdf5Warning, __file__, 0,
                module=__name__, registry={})
    lengths = {len(v) for v in datasets.values()}
    if not datasets or len(lengths) != 1:
        raise InputError(f"HDF5 group '{_printable(node.name)}' needs 1-D datasets of equal "
                         "length (one per channel)", file=path,
                         fix="write one dataset per column, all with the same length")
    _refuse_objects(path, [v.dtype for v in datasets.values()],
                    [v.name for v in datasets.values()])
    columns = list(datasets)
    units = {k: _attr_text(v.attrs.get("unit", v.attrs.get("units")))
             for k, v in datasets.items()}

    def read(group, a, b):
        return pd.DataFrame({c: _decoded(_member(group, c, path)[a:b].reshape(-1))
                             for c in columns})

    return columns, {k: u for k, u in units.items() if u}, lengths.pop(), read


def _pandas_table_layout(node, path: Path):
    """``DataFrame.to_hdf(format="table")``: fields ``index`` and ``values_block_k`` (or one
    field per data column)."""
    import h5py

    table = _member(node, "table", path, required=False)
    if not isinstance(table, h5py.Dataset) or not table.dtype.names:
        raise InputError("pandas HDF5 table without its 'table' dataset", file=path,
                         fix=_CORRUPT_FIX)
    fields, columns = [], []
    for field in table.dtype.names:
        if field == "index":
            continue
        kind = table.attrs.get(f"{field}_kind")
        names = _block_names(kind, path) if kind is not None else [field]
        fields.append((field, names, _attr_text(table.attrs.get(f"{field}_dtype")) or ""))
        columns += names
    _refuse_objects(path, [table.dtype[f] for f, _, _ in fields],
                    [f"{table.name}: field {f}" for f, _, _ in fields])
    index_kind = _attr_text(table.attrs.get("index_kind")) or ""
    index_name = None
    if index_kind.startswith("datetime64"):
        index_name = _index_name(node.attrs.get("info", b"")) or "index"
        columns = [index_name] + columns

    def read(group, a, b):
        block = _member(group, "table", path)[a:b]
        out = {}
        if index_name is not None:
            out[index_name] = _as_datetime(block["index"], index_kind)
        for field, names, dtype in fields:
            values = block[field].reshape(len(block), -1)
            for j, name in enumerate(names):
                out[name] = _as_datetime(values[:, j], dtype) if dtype.startswith(
                    "datetime64") else _decoded(values[:, j])
        return pd.DataFrame(out)

    return columns, {}, len(table), read


def _pandas_fixed_layout(node, path: Path, kind: str):
    """``DataFrame.to_hdf(format="fixed")``: ``axis0`` names, ``blockK_items`` and
    ``blockK_values`` arrays; an object block (``VLARRAY`` of pickles) is refused."""
    import h5py

    if kind != "frame" or _member(node, "axis0", path, required=False) is None:
        raise InputError(f"pandas HDF5 object of type '{_printable(kind)}' is not a table",
                         file=path, fix=_PICKLE_FIX)
    blocks = []
    for k in range(int(node.attrs.get("nblocks", 0))):
        values = _member(node, f"block{k}_values", path, required=False)
        if not isinstance(values, h5py.Dataset) or _attr_text(
                values.attrs.get("CLASS")) != "ARRAY":
            raise InputError(_PICKLED, file=path, fix=_PICKLE_FIX)
        _refuse_objects(path, [values.dtype], [values.name])
        names = [_decoded_text(n) for n in _member(node, f"block{k}_items", path)[()]]
        blocks.append((k, names))
    columns = [_decoded_text(n) for n in _member(node, "axis0", path)[()]]
    rows = len(_member(node, "axis1", path))

    def read(group, a, b):
        out = {}
        for k, names in blocks:
            values = _member(group, f"block{k}_values", path)[a:b]
            for j, name in enumerate(names):
                out[name] = _decoded(values[:, j])
        return pd.DataFrame({c: out[c] for c in columns if c in out})

    return columns, {}, rows, read


def _member(group, name: str, path: Path, *, required: bool = True):
    """``group[name]`` through :func:`node_at` (None when absent and not ``required``)."""
    import h5py

    if not required and (not isinstance(group, h5py.Group)
                         or group.get(name, getlink=True) is None):
        return None
    return node_at(group.file, f"{group.name.rstrip('/')}/{name}", path)


def _block_names(kind, path: Path) -> list[str]:
    try:
        names = pickle_literal(bytes(kind))
    except (UnsafePickle, ValueError, KeyError, IndexError, TypeError) as exc:
        raise InputError(_PICKLED, file=path, fix=_PICKLE_FIX) from exc
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        raise InputError(_PICKLED, file=path, fix=_PICKLE_FIX)
    return names


class Hdf5Warning(UserWarning):
    """Something of an HDF5 file not read (a dataset that is no column)."""


def _refuse_objects(path: Path, dtypes, names=None) -> None:
    """Object (``O``) and variable-length fields hold pickles or references: refused; so
    are complex numbers (no reading is complex: they had been cast to real with numpy's
    ComplexWarning, the imaginary part dropped — issue 30, eleventh attack), naming the
    dataset."""
    for k, dtype in enumerate(dtypes):
        base = dtype.base if dtype.subdtype else dtype
        if base.kind == "O" or base.kind == "V" and not base.names:
            raise InputError(_PICKLED, file=path, fix=_PICKLE_FIX)
        if base.kind == "c":
            name = _printable(names[k]) if names is not None else "a dataset"
            raise InputError(f"HDF5 dataset '{name}' holds complex numbers ({base}): no "
                             "channel of a surface log is complex", file=path,
                             fix="store the readings as real numbers (float64)")


# --------------------------------------------------------------------------- values
def _as_datetime(values: np.ndarray, dtype: str) -> np.ndarray:
    """pandas datetime columns are int64 counts of ``dtype``'s unit since the epoch."""
    unit = dtype[dtype.find("[") + 1:dtype.find("]")] if "[" in dtype else "ns"
    return pd.to_datetime(np.asarray(values, dtype=np.int64), unit=unit).to_numpy()


def _attr_text(value) -> str | None:
    if value is None:
        return None
    if isinstance(value, np.ndarray) and value.size == 1:
        value = value.item()
    return value.decode("utf-8", "replace") if isinstance(value, bytes) else str(value)


def _decoded_text(value) -> str:
    return value.decode("utf-8", "replace") if isinstance(value, bytes) else str(value)


def _decoded(values: np.ndarray) -> np.ndarray:
    if values.dtype.kind == "S":
        return np.array([_decoded_text(v) for v in values], dtype=object)
    return values


def _printable(text: str, limit: int = 60) -> str:
    from drillfric.io.text import printable

    return printable(text, limit)
