"""A depth-indexed log: its static friction log (:mod:`drillfric.estimation.friction_log`)
finished as every run is (:mod:`drillfric.runner.finish`).

Writes summary.json (the keys a time log's has, plus ``index = "depth"`` and
``friction_log``), segments.parquet, profiles.parquet, wellpath.parquet (with a survey),
friction_log.parquet (the medians of each window, the bit torque assumed and the modelled
hook load) and an estimates.parquet without rows (no time series).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import replace

import numpy as np
import pandas as pd

from drillfric.config import TOP_DRIVE_INERTIA_ASSUMED
from drillfric.estimation.friction_log import (
    NO_OBSERVER,
    WindowResult,
    estimate,
    read_depth_log,
)
from drillfric.friction import FrictionProfile
from drillfric.hookload import light_string, weight_verdict, withhold_friction
from drillfric.io.text import plural
from drillfric.io.well import CHUNK_ROWS, Well
from drillfric.result import RunProgress, WellResult
from drillfric.torque_drag import TDResult
from drillfric.vocabulary import Kind, Status

from .finish import ReportWriter, Sink, deliver, finish, summarise

#: summary.json ``hookload`` of a depth-indexed log: the string-weight check of
#: docs/theory.md §2.1 needs the time log's in-slips rows and off-bottom rotating segments.
UNCHECKED = {"verdict": "not_checked", "reason": "a depth-indexed log: the hook-load check "
             "of the string weight runs on time-indexed logs (docs/theory.md §2.1)"}
UNCHECKED_WARNING = ("string weight not checked: a depth-indexed log's friction factors rest "
                     "on the configured string's weight (μ scales as 1/W; docs/theory.md "
                     "§2.1): run the time-indexed log to check it against the hook load")
#: Spacing of the torque-and-drag profile rows written per window [m].
PROFILE_STEP_M = 10.0


def run_depth_log(well: Well, out_root=None, *, rate_hz: float | None = None,
                  report: ReportWriter | None = None,
                  progress: Callable[[RunProgress], None] | None = None,
                  chunk_rows: int = CHUNK_ROWS) -> WellResult:
    """:func:`drillfric.runner.run_well` for a depth-indexed log: the friction log, its
    summary and, with ``out_root``, the result files of ``OUT/NAME`` (the module's list)
    and the report. Parameters as there; ``rate_hz`` does not apply (a warning says so).
    """
    t_wall = time.perf_counter()
    return deliver(well, out_root, lambda sink: _friction_log(well, sink, rate_hz, progress,
                                                              chunk_rows, t_wall), report)


def _friction_log(well: Well, sink: Sink, rate_hz, progress, chunk_rows,
                  t_wall) -> WellResult:
    """Every window back-calculated, its profile into ``sink``, the run finished."""
    log = read_depth_log(well, chunk_rows)
    tick = (lambda done: progress(RunProgress(len(log), len(log), done))) if progress else None
    results, notes = estimate(well, log, tick)
    results, weighed = _weighed(results, well.config.hookload.tolerance)
    for r in results:
        sink.add({"profile": _profile(r.window.id, r.td)} if r.td is not None else {}, False)
    records = [r.record for r in results]
    warnings = [NO_OBSERVER] + (["--rate does not apply to a depth-indexed log: ignored"]
                                if rate_hz is not None else [])
    # the observer does not run: what it would assume of the rig is not assumed here
    assumed = [n for n in well.assumed if n != TOP_DRIVE_INERTIA_ASSUMED]
    summary = summarise(well, records, [], rows=len(log),
                        assumed=assumed + _assumptions(well, results, notes),
                        warnings=warnings, wall_s=time.perf_counter() - t_wall,
                        profile=FrictionProfile.from_config(well.config))
    summary.update(index="depth", friction_log=_log_summary(well, log, results),
                   hookload=weighed)
    if weighed["verdict"] == "contradicted":
        withheld = f"friction factors withheld by the hook-load check: {weighed['reason']}"
        summary["warnings"].append(withheld)
        summary["friction_log"]["mu_k_reason"] = withheld
        if summary["mu_k"] is None:
            summary["mu_k_reason"] = withheld
    elif any(r.record.status is Status.OK for r in results):
        summary["warnings"].append(UNCHECKED_WARNING)
    return finish(sink, well, summary, records,
                  tables={"friction_log.parquet": log_table(results)})


def _weighed(results: list[WindowResult], tolerance: float
             ) -> tuple[list[WindowResult], dict]:
    """The windows after the one-sided hook-load check of a depth log
    (:func:`drillfric.hookload.light_string`, over the windows that log the WOB): where the
    hook load says the configured string is too heavy, every estimated window's friction
    factors withheld; summary.json ``hookload``."""
    # the model subtracts the logged WOB: a window without one says nothing of the string
    estimated = [r for r in results if r.td is not None and np.isfinite(r.window.wob_N)]
    why = light_string([r.window.hookload_N for r in estimated],
                       [r.td.hookload_N for r in estimated], tolerance)
    if not why:
        return results, dict(UNCHECKED)
    out = []
    for r in results:
        rule = weight_verdict(r.record.status, why, "", False)
        out.append(replace(r, record=withhold_friction(r.record, rule.withhold, rule.flag))
                   if rule.withhold else r)
    return out, {"verdict": "contradicted", "reason": why, "tolerance": tolerance,
                 "withheld_segments": [r.record.id for r in out
                                       if r.record.status is Status.OK and r.td is not None]}


def _assumptions(well: Well, results: list[WindowResult], notes: list[str]) -> list[str]:
    """What the friction log assumed beyond the well's own: the load-case rule, the bit
    torque."""
    out = list(notes)
    if any(r.window.kind is Kind.ON_BOTTOM and r.td is not None for r in results):
        cfg = well.config.friction_log
        out.append("on bottom, apparent friction: the bit torque is not separated" if
                   cfg.bit_mu == 0 else f"on bottom: bit torque μ_bit·WOB·D_bit/3 with μ_bit "
                   f"= {cfg.bit_mu:g}, D_bit = {cfg.bit_diameter_m:g} m (friction_log)")
    return out


def _log_summary(well: Well, log: pd.DataFrame, results: list[WindowResult]) -> dict:
    """summary.json ``friction_log``: the windows, the apparent on-bottom consensus and why
    there is no off-bottom one (``mu_k_reason``, null when ``mu_k`` is given)."""
    md = log["measured_depth_m"].to_numpy(float)
    apparent = [r.record.mu_k for r in results if r.record.status is Status.OK
                and r.window.kind is Kind.ON_BOTTOM and r.record.mu_k is not None]
    return {"window_m": well.config.friction_log.window_m, "rows": len(log),
            "md_start_m": float(md.min()), "md_end_m": float(md.max()),
            "bit_mu": well.config.friction_log.bit_mu,
            "mu_apparent": float(np.median(apparent)) if apparent else None,
            "mu_k_reason": _no_off_bottom_reason(results)}


def _no_off_bottom_reason(results: list[WindowResult]) -> str | None:
    """Why the log gives no off-bottom friction factor (None when it gives one)."""
    off = [r for r in results if r.window.kind is Kind.OFF_BOTTOM]
    if any(r.record.status is Status.OK for r in off):
        return None
    if off:
        return (f"no off-bottom window was estimated ({plural(len(off), 'off-bottom window')} "
                "skipped or failed)")
    return ("no rotating row is off bottom, so the log holds only apparent on-bottom "
            "friction, bit torque included")


def _profile(seg_id: int, td: TDResult) -> pd.DataFrame:
    """profiles.parquet rows of one window: the solution every ~:data:`PROFILE_STEP_M`."""
    frame = td.to_frame().drop(columns="azi_deg")
    step = max(1, int(PROFILE_STEP_M // max(float(np.diff(td.md_m).mean()), 1e-9)))
    keep = np.unique(np.r_[np.arange(0, len(frame) - 1, step), len(frame) - 2])
    frame = frame.iloc[keep].reset_index(drop=True)
    frame.insert(0, "segment_id", np.int32(seg_id))
    return frame


def log_table(results: list[WindowResult]) -> pd.DataFrame:
    """friction_log.parquet: one row per window and load case, SI (docs/ingestion.md)."""
    rows = []
    for r in results:
        w, rec = r.window, r.record
        rows.append({"segment_id": w.id, "kind": w.kind.value, "md_top_m": w.md_top_m,
                     "md_bottom_m": w.md_bottom_m, "bit_depth_m": w.bit_depth_m,
                     "rows": w.rows, "surface_torque_Nm": w.surface_torque_Nm,
                     "surface_rpm": w.surface_rpm, "wob_N": w.wob_N,
                     "hookload_N": w.hookload_N, "bit_torque_Nm": r.bit_torque_Nm,
                     "mu": np.nan if rec.mu_k is None else rec.mu_k,
                     "T_N_Nm": np.nan if r.td is None else r.td.T_N_Nm,
                     "hookload_model_N": np.nan if r.td is None else r.td.hookload_N,
                     "status": rec.status.value})
    return pd.DataFrame(rows)
