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
from pathlib import Path

import numpy as np
import pandas as pd

from drillfric.errors import InputError

#: ``engine.json`` ``format`` and ``version`` of the state this drillfric writes and reads.
STATE_FORMAT = "drillfric-engine-state"
STATE_VERSION = 1
_DOC, _ARRAYS = "engine.json", "arrays.npz"
_FRAME_NAME = re.compile(r"^frame-\d{1,6}\.parquet$")
_FIX = "run the well again from its start (drillfric fleet --force)"


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
        doc = json.loads((folder / _DOC).read_text(encoding="utf-8"))
        if not isinstance(doc, dict) or doc.get("format") != STATE_FORMAT:
            raise ValueError("not an engine state")
        if doc.get("version") != STATE_VERSION:
            raise ValueError(f"state version {doc.get('version')!r}, this drillfric reads "
                             f"{STATE_VERSION}")
        with np.load(folder / _ARRAYS, allow_pickle=False) as npz:
            arrays = {k: npz[k] for k in npz.files}
        return _decode(doc["state"], arrays, folder)
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise InputError(f"engine state not readable ({exc})", file=folder, fix=_FIX) from exc


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
        return pd.read_parquet(folder / name)
    return {k: _decode(v, arrays, folder) for k, v in value.items()}
