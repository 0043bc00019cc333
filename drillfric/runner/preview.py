"""What ``drillfric run`` will do with a time log, told without estimating it.

``drillfric inspect`` shows a log and says what run will make of it (issue 35 items 5 and
7: it had called Volve F-4's segments usable that run then skipped, "only 7 samples", and
F-9's that run failed, the string longer than the bit depth). Both answers come from the
functions run itself calls, on the log's rows in run's chunks:

- :func:`refusal` — the checks of the log as a whole (the first chunk's rate, depth
  reckoning and work budget, :func:`~drillfric.runner.checks.check_first_chunk`; the log
  check, :class:`~drillfric.io.logcheck.LogCheck`): the error run would stop with;
- :func:`segment_verdicts` — the segments run's stream cuts, with their rows
  (:class:`~drillfric.segmentation.SegmentStream`), each through the checks before the
  estimation chain (:func:`~drillfric.runner.checks.precheck`: the segmentation's verdict,
  the sample count, ω_c, the survey's and the string's reach of the bit).

Neither imports the estimation chain (:mod:`drillfric.runner.checks`): inspect stays within
its start-up budget.

What the chain itself finds (no side force in a vertical hole, a torque in the wrong unit,
a fit that does not converge) needs the models solved and is left to run.
"""

from __future__ import annotations

import functools
from collections.abc import Iterator
from dataclasses import replace

import numpy as np
import pandas as pd

from drillfric import hookload
from drillfric.config import STRING_ASSUMED
from drillfric.errors import DrillfricError
from drillfric.io.logcheck import LogCheck
from drillfric.io.well import CHUNK_ROWS, Well
from drillfric.segmentation import Segment, SegmentStream
from drillfric.vocabulary import Kind, Status

from .checks import Precheck, bit_depth_default, check_first_chunk, precheck


def refusal(well: Well, surface: pd.DataFrame, duplicates_dropped: int,
            chunk_rows: int = CHUNK_ROWS) -> DrillfricError | None:
    """The error ``run`` would stop this time log with, or None.

    Parameters
    ----------
    well : Well
        The opened well.
    surface : pandas.DataFrame
        Its canonical rows (:attr:`drillfric.io.well.WellData.surface`).
    duplicates_dropped : int
        Rows dropped for a repeated time (the time base's count).
    chunk_rows : int
        Rows of run's chunks (the first chunk's checks look at those only).
    """
    check = LogCheck(well)
    try:
        check_first_chunk(well, surface.iloc[:chunk_rows])
        for chunk in _chunks(surface, chunk_rows):
            check.feed(chunk)
        check.finish(duplicates_dropped)
    except DrillfricError as exc:
        return exc
    return None


def segment_verdicts(well: Well, surface: pd.DataFrame, assumed: list[str],
                     chunk_rows: int = CHUNK_ROWS) -> list[tuple[Segment, Precheck]]:
    """Every segment ``run`` cuts from ``surface`` (canonical rows), in order, with what
    becomes of it before the estimation chain (status OK: run estimates it). What run
    assumes for them (a bit depth the log does not give) is appended to ``assumed``."""
    return [(seg, pre) for seg, _, pre in segment_rows(well, surface, assumed, chunk_rows)]


def segment_rows(well: Well, surface: pd.DataFrame, assumed: list[str],
                 chunk_rows: int = CHUNK_ROWS) -> list[tuple[Segment, pd.DataFrame, Precheck]]:
    """:func:`segment_verdicts` with each segment's rows (for :func:`string_weight_check`)."""
    stream = SegmentStream(well.config)
    done = [pair for chunk in _chunks(surface, chunk_rows) for pair in stream.feed(chunk)]
    fallback = functools.cache(lambda: bit_depth_default(well, assumed))
    verdicts = [(seg, rows, precheck(well, seg, rows, fallback))
                for seg, rows in done + stream.close()]
    if well.config.segmentation.slips_hookload_N is not None:  # the slips are a rig state
        return verdicts
    plateaus = functools.cache(lambda: hookload.find_plateaus(surface, well.config))
    return [(seg, rows, _in_slips(seg, rows, pre, plateaus)) for seg, rows, pre in verdicts]


def string_weight_check(well: Well, surface: pd.DataFrame,
                        verdicts: list[tuple[Segment, pd.DataFrame, Precheck]]) -> dict:
    """What run's hook-load check (:func:`drillfric.hookload.judge`, docs/theory.md §2.1)
    will do with the segments run estimates, told before estimating them: the off-bottom
    rotating ones' median hook load against the soft-string model's off-bottom hook load at
    their bit depth (one torque-and-drag solve per segment), the block weight from the
    log's plateaus. Segments the chain itself then skips are still counted here.

    Returns
    -------
    dict
        ``verdict`` (as summary.json ``hookload.verdict``), ``string_weight_ratio`` (the
        measured string weight over the modelled one; None without a block weight),
        ``withheld_segments`` (ids), ``reason`` and ``line`` (one sentence for inspect;
        "" when run will show the friction factors).
    """
    from drillfric.result import SegmentRecord
    from drillfric.torque_drag import TDSettings

    cfg = well.config
    td = functools.cache(lambda: TDSettings.from_config(cfg))
    records = []
    for seg, rows, pre in verdicts:
        if pre.status is not Status.OK:
            continue
        hook = _median_hookload(rows)
        model = None
        if seg.kind == Kind.OFF_BOTTOM and seg.axial_speed_m_s is None and hook is not None:
            try:
                model = hookload.modelled_string_weight_N(
                    td(), td().path_to(well.survey, pre.bit_depth_m), pre.bit_depth_m)
            except DrillfricError:  # the survey does not reach the bit: run fails it
                continue
        records.append(SegmentRecord(id=seg.id, kind=Kind(seg.kind), status=Status.OK,
                                     bit_depth_m=pre.bit_depth_m, hookload_N=hook,
                                     hookload_model_N=model))
    plateaus = hookload.find_plateaus(surface, cfg)
    if cfg.hookload.calibrate_string_weight:
        return {"verdict": "calibrated", "string_weight_ratio": None, "withheld_segments": [],
                "reason": None, "line": "run will calibrate the string's weight to the hook "
                "load (hookload.calibrate_string_weight)"}
    outcome = hookload.judge(records, plateaus, cfg)
    summary = outcome.summary
    withheld = list(summary.get("withheld_segments") or [])
    ratio = summary.get("string_weight_ratio")
    out = {"verdict": summary.get("verdict"), "string_weight_ratio": ratio,
           "withheld_segments": withheld, "reason": summary.get("reason"), "line": ""}
    if withheld:
        string = "the string (assumed default)" if any(
            n.startswith(STRING_ASSUMED) for n in well.assumed) else "the configured string"
        weighs = (f"the hook load measures {ratio:.2f}× the modelled weight of {string}"
                  if ratio is not None else f"{string}: {summary.get('reason')}")
        out["line"] = (f"{weighs}: run will withhold the friction factors of "
                       f"{len(withheld)} of {len(records)} segments — configure [[string]] "
                       "(sections, or --string with a WITSML tubular) or the block weight "
                       "(docs/theory.md §2.1)")
    return out


def _median_hookload(rows: pd.DataFrame) -> float | None:
    if "hookload_N" not in rows:
        return None
    hook = rows["hookload_N"].to_numpy(float)
    return float(np.nanmedian(hook)) if np.isfinite(hook).any() else None


def _in_slips(seg: Segment, rows: pd.DataFrame, pre: Precheck, plateaus) -> Precheck:
    """``pre`` skipped as run's hook-load check skips a rotation in the slips (issue 35,
    :func:`drillfric.hookload.in_slips_reason`; only without ``slips_hookload_N``)."""
    if seg.kind != Kind.OFF_BOTTOM or pre.status is Status.FAILED \
            or "hookload_N" not in rows or not rows["hookload_N"].notna().any():
        return pre
    why = hookload.in_slips_reason(float(np.nanmedian(rows["hookload_N"].to_numpy(float))),
                                   pre.bit_depth_m, plateaus())
    if not why:
        return pre
    return replace(pre, status=Status.SKIPPED, data=None,
                   message="; ".join(filter(None, [why, pre.message])))


def _chunks(surface: pd.DataFrame, chunk_rows: int) -> Iterator[pd.DataFrame]:
    for start in range(0, len(surface), chunk_rows):
        yield surface.iloc[start:start + chunk_rows]
