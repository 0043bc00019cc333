"""DLIS (RP66 v1) logs read with dlisio: one frame of a file as a raw source.

A DLIS file holds logical files; each holds frames, a frame a table of channels whose
first channel is the index (time or depth). The frame read is the one holding the surface
channels: the most of the required channels (time, surface RPM, surface torque)
recognised by mnemonic, then time-indexed before depth-indexed, then the most rows.
Columns are the frame's channel names (``NAME (origin.copy)`` when a name repeats), units
the channel objects' ``units``. Channels of more than one value per sample (arrays,
images) are left out. dlisio reads a frame whole, so the frame must fit in memory; it is
then handed on in chunks.

The index is time-like when the frame's index type says so (``TIME``) or the index
channel's unit is a time; depth-like (``depth_index`` set) for a ``BOREHOLE-DEPTH`` /
``VERTICAL-DEPTH`` index or a length unit. Every failure is an InputError naming the file.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pandas as pd

from drillfric.errors import InputError
from drillfric.io.channels import CHANNELS, find_column
from drillfric.io.source import RawSource
from drillfric.units import conversion_factor

_DEPTH_TYPES = frozenset({"BOREHOLE-DEPTH", "VERTICAL-DEPTH"})
_FIX = "re-export the log as DLIS (RP66 v1), or as LAS or CSV"


def _load(path: Path):
    """All logical files of a DLIS file (a context manager); unreadable → InputError."""
    from dlisio import dlis

    try:
        return dlis.load(str(path))
    except Exception as exc:  # noqa: BLE001 — dlisio raises RuntimeError, OSError, ValueError …
        raise InputError(f"not a readable DLIS file ({type(exc).__name__})", file=path,
                         fix=_FIX) from exc


def _unit_is(unit: str | None, kind: str) -> bool:
    if not unit:
        return False
    try:
        conversion_factor(unit, kind)
    except InputError:
        return False
    return True


def _index_kind(frame) -> str:
    """``"time"``, ``"depth"`` or ``""`` for a frame's index channel."""
    index_type = (frame.index_type or "").upper()
    unit = frame.channels[0].units if frame.channels else None
    if index_type in _DEPTH_TYPES or _unit_is(unit, "length"):
        return "depth"
    if index_type == "TIME" or _unit_is(unit, "time"):
        return "time"
    return ""


def _scalar_channels(frame) -> list:
    return [c for c in frame.channels if list(c.dimension or [1]) == [1]]


def _names(channels) -> list[str]:
    """Column names: channel names, made unique with ``(origin.copy)`` where they repeat."""
    plain = [c.name for c in channels]
    return [name if plain.count(name) == 1 else f"{name} ({c.origin}.{c.copynumber})"
            for name, c in zip(plain, channels, strict=True)]


def _rank(frame, rows: int) -> tuple:
    names = _names(_scalar_channels(frame))
    found = 0
    for channel in (c for c in CHANNELS if c.required):
        try:
            found += find_column(names, channel.key, {}) is not None
        except InputError:  # two columns claim it: it is there
            found += 1
    return found, _index_kind(frame) == "time", rows


def _frames(files) -> list[tuple]:
    """(frame, rows, position) for every frame of every logical file."""
    out = []
    for lf_at, logical in enumerate(files):
        for frame in logical.frames:
            rows = len(logical.fdata_index.get(frame.fingerprint, []))
            out.append((frame, rows, (lf_at, frame.fingerprint)))
    return out


def _frame_data(path: Path, position: tuple) -> pd.DataFrame:
    """The frame at ``position`` read whole, scalar channels only, labelled by name."""
    lf_at, fingerprint = position
    with _load(path) as files:
        frame = next(f for f in files[lf_at].frames if f.fingerprint == fingerprint)
        channels = _scalar_channels(frame)
        try:
            curves = frame.curves()
        except Exception as exc:  # noqa: BLE001 — dlisio raises several types on bad data
            raise InputError(f"cannot read the data of DLIS frame {frame.name} "
                             f"({type(exc).__name__})", file=path, fix=_FIX) from exc
        wanted = {c.fingerprint for c in channels}
        fields = [n for n, c in zip(curves.dtype.names[1:], frame.channels, strict=True)
                  if c.fingerprint in wanted]
        return pd.DataFrame({name: np.asarray(curves[field]) for name, field
                             in zip(_names(channels), fields, strict=True)})


def open_dlis(path) -> RawSource:
    """Open the frame of a DLIS file holding the surface channels as a raw source.

    Parameters
    ----------
    path : str or Path
        A ``.dlis`` file (RP66 v1).

    Raises
    ------
    InputError
        Not a readable DLIS file, or one without frames or data.
    """
    path = Path(path)
    with _load(path) as files:
        frames = _frames(files)
        if not frames:
            raise InputError("DLIS file has no frame (no channel data)", file=path, fix=_FIX)
        frame, rows, position = max(frames, key=lambda f: _rank(f[0], f[1]))
        channels = _scalar_channels(frame)
        columns = _names(channels)
        units = {n: c.units.strip() for n, c in zip(columns, channels, strict=True)
                 if c.units and c.units.strip()}
        units.update({("source", c): "header" for c in list(units)})
        depth = None
        if _index_kind(frame) == "depth" and columns:
            depth = f"{columns[0]} [{units[columns[0]]}]" if columns[0] in units else columns[0]
    if rows == 0:
        raise InputError(f"DLIS frame {frame.name} has no data rows", file=path, fix=_FIX)

    def read(chunk_rows: int) -> Iterator[pd.DataFrame]:
        data = _frame_data(path, position)
        for start in range(0, len(data), chunk_rows):
            yield data.iloc[start:start + chunk_rows].reset_index(drop=True)

    return RawSource(path, "dlis", columns, units, rows, read, depth_index=depth)
