"""What a report reads from a result directory (INTERFACE.md "Outputs of run").

Only files of the directory are read (``summary.json`` and the Parquet tables next to it),
so ``drillfric report RESULT_DIR`` can rebuild a report long after the run. Estimates are
read for the segments that are drawn only, and decimated for plotting.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from drillfric.errors import InputError
from drillfric.result import ESTIMATE_NAMES, SEGMENT_FIELDS, SEGMENT_NUMBER_FIELDS

_NUMERIC = SEGMENT_NUMBER_FIELDS  # None in summary.json becomes NaN


@dataclass(frozen=True)
class ResultData:
    """The contents of a result directory a report needs.

    Attributes
    ----------
    result_dir : Path
    summary : dict
        summary.json as read.
    segments : DataFrame
        The segments of summary.json, one row each; missing numbers are NaN.
    profiles : DataFrame or None
        profiles.parquet (torque-and-drag profile per estimated segment).
    wellpath : DataFrame or None
        wellpath.parquet (only when the run had a survey).
    """

    result_dir: Path
    summary: dict
    segments: pd.DataFrame
    profiles: pd.DataFrame | None
    wellpath: pd.DataFrame | None


def segments_frame(rows: list[dict]) -> pd.DataFrame:
    """The ``segments`` list of a summary.json as a table with NaN for missing numbers."""
    frame = pd.DataFrame(rows)
    for col in SEGMENT_FIELDS:  # older results lack some fields
        if col not in frame and col not in _NUMERIC:
            frame[col] = pd.Series([None] * len(frame), dtype=object)
    for col in _NUMERIC:
        frame[col] = pd.to_numeric(frame[col], errors="coerce") if col in frame else np.nan
    frame["converged"] = frame["converged"].fillna(False).astype(bool)
    frame["mu_s_identifiable"] = frame["mu_s_identifiable"].fillna(False).astype(bool)
    frame["message"] = frame["message"].fillna("").astype(str)
    frame["flags"] = [list(f) if isinstance(f, list | tuple) else [] for f in frame["flags"]]
    frame["starts"] = [list(s) if isinstance(s, list | tuple) else [] for s in frame["starts"]]
    return frame


def load_result(result_dir: Path) -> ResultData:
    """Read a result directory written by ``drillfric run``.

    Raises
    ------
    InputError
        The directory or its summary.json is missing or unreadable.
    """
    result_dir = Path(result_dir)
    path = result_dir / "summary.json"
    if not result_dir.is_dir():
        raise InputError("not a directory", file=result_dir,
                         fix="give the OUT/NAME directory written by 'drillfric run'")
    if not path.is_file():
        raise InputError("no summary.json: not a drillfric result directory", file=result_dir,
                         fix="give the OUT/NAME directory written by 'drillfric run'")
    try:
        summary = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"unreadable summary.json ({exc})", file=path,
                         fix="rerun 'drillfric run' to rewrite the results") from None
    if not isinstance(summary, dict) or not isinstance(summary.get("segments", []), list):
        raise InputError("summary.json is not a drillfric summary", file=path,
                         fix="rerun 'drillfric run' to rewrite the results")
    return ResultData(result_dir, summary, segments_frame(summary.get("segments", [])),
                      _optional_parquet(result_dir / "profiles.parquet"),
                      _optional_parquet(result_dir / "wellpath.parquet"))


def _optional_parquet(path: Path) -> pd.DataFrame | None:
    if not path.is_file():
        return None
    try:
        return pd.read_parquet(path)
    except (OSError, ValueError) as exc:
        raise InputError(f"unreadable Parquet file ({exc})", file=path,
                         fix="rerun 'drillfric run' to rewrite the results") from None


def segment_estimates(result_dir: Path, ids: list[int],
                      max_points: int = 1200) -> dict[int, pd.DataFrame]:
    """Estimates of the given segments, every start, decimated to ≤ ``max_points`` per start.

    Decimation keeps every k-th sample (no averaging), so stick-slip stays visible as long
    as a cycle spans several kept samples; the figures are for reading, the Parquet file
    keeps every sample.
    """
    path = Path(result_dir) / "estimates.parquet"
    if not ids or not path.is_file():
        return {}
    import pyarrow.parquet as pq

    try:
        names = pq.read_schema(path).names
        columns = [c for c in ESTIMATE_NAMES if c in names]  # older results lack some
        table = pq.read_table(path, columns=columns,
                              filters=[("segment_id", "in", [int(i) for i in ids])])
    except (OSError, ValueError) as exc:
        raise InputError(f"unreadable estimates ({exc})", file=path,
                         fix="rerun 'drillfric run' to rewrite the results") from None
    frame = table.to_pandas()
    out = {}
    for seg_id, rows in frame.groupby("segment_id", sort=True):
        parts = []
        for _, one in rows.groupby("start_id", sort=True):
            step = max(1, int(np.ceil(len(one) / max_points)))
            parts.append(one.sort_values("time_s").iloc[::step])
        out[int(seg_id)] = pd.concat(parts, ignore_index=True)
    return out
