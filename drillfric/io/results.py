"""Result files of ``drillfric run`` (INTERFACE.md "Outputs of run"), written atomically.

A run writes into a hidden temporary directory beside the final one and renames it into
place at the end, so an interrupted run never leaves a half-written well directory.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

#: Columns of estimates.parquet (INTERFACE.md), ``bit_rpm`` only with downhole truth.
ESTIMATE_COLUMNS = ("time_s", "segment_id", "start_id", "mu_s", "mu_k", "surface_rpm",
                    "surface_rpm_est", "bit_rpm_est", "bit_stuck", "residual_rpm")
#: Written after INTERFACE.md's columns (``bit_rpm`` included): the band of the seeded
#: ensemble's bit speed (NaN on the starts' rows).
BAND_COLUMNS = ("bit_rpm_est_min", "bit_rpm_est_max")
#: Binding keys of each segment in summary.json / segments.parquet (INTERFACE.md).
SEGMENT_KEYS = ("id", "kind", "t_start_s", "t_end_s", "bit_depth_m", "mu_s", "mu_k",
                "mu_s_identifiable", "mu_s_lower_bound", "mu_s_spread", "mu_k_spread",
                "converged", "method", "settling_time_s", "residual_rms_rpm",
                "stick_slip_severity", "status", "message")


def file_sha256(path: str | Path, block: int = 1 << 20) -> str:
    """SHA-256 of a file, read in blocks (constant memory)."""
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        while chunk := fh.read(block):
            digest.update(chunk)
    return digest.hexdigest()


def jsonable(value):
    """Plain JSON value: NaN/inf → None, numpy scalars → Python, tuples → lists."""
    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist())
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, Path):
        return str(value)
    return value


@contextmanager
def atomic_directory(final: Path) -> Iterator[Path]:
    """Yield a temporary directory that replaces ``final`` only if the block succeeds.

    On failure nothing is left behind: the temporary directory is removed, and so are the
    parent directories this call created (``--out`` of a run whose input was unreadable
    does not appear as an empty directory).
    """
    final = Path(final)
    created = missing_dirs(final.parent)
    tmp = final.parent / f".{final.name}.tmp-{os.getpid()}"
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    try:
        yield tmp
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        remove_empty(created)
        raise
    old = final.parent / f".{final.name}.old-{os.getpid()}"
    if final.exists():
        os.replace(final, old)
    os.replace(tmp, final)
    shutil.rmtree(old, ignore_errors=True)


def missing_dirs(path: Path) -> list[Path]:
    """``path`` and its ancestors that do not exist yet, deepest first (to undo with
    :func:`remove_empty` when nothing could be written)."""
    missing = []
    for folder in (Path(path), *Path(path).parents):
        if folder.exists():
            break
        missing.append(folder)
    return missing


def remove_empty(folders: list[Path]) -> None:
    """Remove ``folders`` (deepest first) while they are empty; another writer's files stay."""
    for folder in folders:
        try:
            folder.rmdir()
        except OSError:
            return


class EstimatesWriter:
    """Append observer records to estimates.parquet, one row group per segment."""

    def __init__(self, path: Path, with_truth: bool):
        self.path = path
        names = list(ESTIMATE_COLUMNS) + (["bit_rpm"] * with_truth) + list(BAND_COLUMNS)
        types = {"segment_id": pa.int32(), "start_id": pa.int16(), "bit_stuck": pa.bool_(),
                 **dict.fromkeys(BAND_COLUMNS, pa.float32())}
        self.schema = pa.schema([(n, types.get(n, pa.float64())) for n in names])
        self._writer = pq.ParquetWriter(path, self.schema, compression="zstd")

    def write(self, frame: pd.DataFrame) -> None:
        """Append one segment's rows (columns of :attr:`schema`)."""
        table = pa.Table.from_pandas(frame[self.schema.names], schema=self.schema,
                                     preserve_index=False)
        self._writer.write_table(table)

    def close(self) -> None:
        """Finish the file."""
        self._writer.close()


def write_json(path: Path, payload: dict) -> None:
    """Write ``payload`` as indented JSON (NaN-free)."""
    path.write_text(json.dumps(jsonable(payload), indent=2, ensure_ascii=False) + "\n",
                    encoding="utf-8")


def write_segments(path: Path, segments: list[dict]) -> None:
    """segments.parquet: the summary's segment table as columns (+ team extras)."""
    frame = pd.DataFrame([jsonable(s) for s in segments])
    if frame.empty:
        frame = pd.DataFrame(columns=list(SEGMENT_KEYS))
    for col in frame.columns:
        if frame[col].map(lambda v: isinstance(v, (list, dict))).any():
            frame[col] = frame[col].map(json.dumps)
    frame.to_parquet(path, index=False)
