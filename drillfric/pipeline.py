"""``drillfric run``: one well, stand by stand (issue 6).

ingest (streamed in chunks) → segment into rotating stands → per segment: torque and drag
at its bit depth, observer from the configured starts (warm-started from the previous
segment), batch refinement, seeded observer pass (:mod:`drillfric.estimation.chain`) → outputs of
INTERFACE.md (summary.json, estimates.parquet, segments.parquet, report) written atomically.

Memory stays bounded: only the rows of the segment being assembled are held (rows the
segmenter has finished with are dropped), and estimates are appended to Parquet per segment.
Library code: no printing; progress goes through a callback.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from drillfric import __version__
from drillfric.errors import DrillfricError, InputError
from drillfric.estimation.chain import (
    SegmentData,
    SegmentEstimate,
    SkipSegment,
    check_segment,
    estimate_segment,
)
from drillfric.estimation.observer import ObserverRecord
from drillfric.io.results import (
    EstimatesWriter,
    atomic_directory,
    file_sha256,
    write_json,
    write_segments,
)
from drillfric.io.timebase import check_plausible_rate, nominal_rate_hz
from drillfric.io.well import (
    assumed_units,
    channel_mappings,
    iter_surface,
    load_setup,
    resolve_well,
)
from drillfric.segmentation import Segment, Segmenter
from drillfric.units import RPM_TO_RAD_S
from drillfric.wellpath import WellPath

#: Bit depth assumed when neither the log, the config nor a survey gives one [m].
DEFAULT_BIT_DEPTH_M = 2500.0
#: Seconds of data before a segment handed to the estimator, so that a start-up (and a
#: creep break-over) is seen from rest.
PREROLL_S = 5.0
#: ``start_id`` of the final observer pass seeded with the batch-refined factors.
SEEDED_START_ID = -1
#: Relative margin by which a requested rate may exceed the data's nominal rate (timing
#: jitter) before it counts as upsampling.
RATE_MARGIN = 0.01
_KEEP = ("time_s", "surface_rpm", "surface_torque_Nm", "bit_depth_m", "wob_N", "bit_rpm")


@dataclass
class RunResult:
    """What a run produced (the CLI turns it into a summary line and an exit code).

    Attributes
    ----------
    name : str
    out_dir : Path
        OUT/NAME, complete.
    summary : dict
        Contents of summary.json.
    failed : int
        Segments whose estimation failed.
    warnings : list of str
        What the user should know about the run (also ``summary["warnings"]``).
    """

    name: str
    out_dir: Path
    summary: dict
    failed: int = 0
    warnings: list = field(default_factory=list)

    @property
    def report(self) -> Path:
        """Path of report.html."""
        return self.out_dir / "report.html"


def _bit_depth_default(cfg, survey: WellPath | None, assumed: list) -> float:
    """Bit depth [m] of segments the log gives none for: ``[well] bit_depth_m``, else a
    simulated well's ``[simulate] bit_depth_m``, else (announced in ``assumed``) the
    survey's last station or :data:`DEFAULT_BIT_DEPTH_M`."""
    for key in ("well.bit_depth_m", "simulate.bit_depth_m"):
        if cfg[key] is not None:
            return cfg[key]
    if survey is not None:
        assumed.append(f"bit depth {survey.md_max_m:.0f} m (the survey's last station): the "
                       "log has no bit depth")
        return survey.md_max_m
    assumed.append(f"bit depth {DEFAULT_BIT_DEPTH_M:.0f} m: neither the log nor a survey "
                   "gives one")
    return DEFAULT_BIT_DEPTH_M


def _preroll_start(buffer: pd.DataFrame, lo: int, floor: int) -> int:
    """First buffer row handed to the estimator for a segment starting at row ``lo``.

    Up to :data:`PREROLL_S` earlier (the start-up seen from rest), but not before ``floor``
    (the end of the previous segment) and only after the last null of speed or torque.
    """
    if lo <= floor:
        return lo
    t = buffer["time_s"].to_numpy()
    start = floor + int(np.searchsorted(t[floor:lo], t[lo] - PREROLL_S))
    pre = buffer.iloc[start:lo]
    bad = ~(np.isfinite(pre["surface_rpm"].to_numpy(float))
            & np.isfinite(pre["surface_torque_Nm"].to_numpy(float)))
    if bad.any():
        start += int(np.flatnonzero(bad)[-1]) + 1
    return start


def _rows_done(buffer: pd.DataFrame, pending: int) -> int:
    """How many leading buffer rows no segment can need any more: those before the
    segmenter's pending row, less the pre-roll a segment starting there may take."""
    if pending <= 0:
        return 0
    t = buffer["time_s"].to_numpy()
    ref = t[pending] if pending < t.size else t[-1]
    return int(np.searchsorted(t[:pending], ref - PREROLL_S))


def effective_rate(rate_hz: float | None, time_s: np.ndarray) -> tuple[float | None, str | None]:
    """The rate to resample to [Hz] and, when it differs from ``rate_hz``, why.

    A requested rate above the data's nominal rate would only interpolate between logged
    samples (upsampling invents nothing the observer could use, and costs time): the data
    are then estimated at their own rate (None) and a warning says so.

    Parameters
    ----------
    rate_hz : float or None
        Requested rate (``run --rate``) [Hz].
    time_s : ndarray
        Sample times of (the start of) the log [s].

    Examples
    --------
    >>> effective_rate(5.0, np.arange(10.0))[0] is None
    True
    >>> effective_rate(0.5, np.arange(10.0))
    (0.5, None)
    """
    data_rate = nominal_rate_hz(time_s)
    if rate_hz is None or data_rate <= 0 or rate_hz <= data_rate * (1.0 + RATE_MARGIN):
        return rate_hz, None
    return None, (f"requested rate {rate_hz:g} Hz is above the data's logging rate "
                  f"({data_rate:.3g} Hz): estimated at the data's rate, not upsampled")


def well_name(path, *, config=None) -> str:
    """The name a well's results go under (OUT/NAME): ``[well] name`` or the file stem."""
    data_path, _, _ = resolve_well(path, config=config)
    cfg, _ = load_setup(path, config=config)
    return cfg["well.name"] or (Path(path).name if Path(path).is_dir() else data_path.stem)


def _segment_data(rows: pd.DataFrame, seg: Segment, fallback_depth: float) -> SegmentData:
    """The estimator's samples: rows with both speed and torque (the few nulls a segment
    may hold are bridged when the measurements are put on a uniform grid)."""
    rows = rows[np.isfinite(rows["surface_rpm"].to_numpy(float))
                & np.isfinite(rows["surface_torque_Nm"].to_numpy(float))]
    depth = seg.bit_depth_m if np.isfinite(seg.bit_depth_m) else fallback_depth
    wob = float(np.nanmedian(rows["wob_N"])) if "wob_N" in rows and \
        rows["wob_N"].notna().any() else 0.0
    truth = rows["bit_rpm"].to_numpy(float) if "bit_rpm" in rows else None
    return SegmentData(rows["time_s"].to_numpy(float), rows["surface_rpm"].to_numpy(float),
                       rows["surface_torque_Nm"].to_numpy(float), float(depth), kind=seg.kind,
                       wob_N=max(wob, 0.0), bit_rpm=truth)


def _segment_row(seg: Segment, est: SegmentEstimate | None, status: str, message: str,
                 depth: float) -> dict:
    row = {"id": seg.id, "kind": seg.kind, "t_start_s": seg.t_start_s,
           "t_end_s": seg.t_end_s, "bit_depth_m": depth, "mu_s": None, "mu_k": None,
           "mu_s_identifiable": False, "mu_s_lower_bound": None, "mu_s_spread": None,
           "mu_k_spread": None, "converged": False, "method": "none",
           "settling_time_s": None, "residual_rms_rpm": None, "stick_slip_severity": None,
           "status": status, "message": message, "duration_s": seg.duration_s}
    if est is not None:
        row.update({k: getattr(est, k) for k in (
            "mu_s", "mu_k", "mu_s_identifiable", "mu_s_lower_bound", "mu_s_spread",
            "mu_k_spread", "converged", "method", "settling_time_s", "residual_rms_rpm",
            "stick_slip_severity", "stuck_fraction", "mu_k_observer", "mu_s_observer",
            "mu_td", "T_N_Nm", "bit_rms_error_rpm")})
        row["flags"] = list(est.flags)
        row["starts"] = est.starts.tolist()  # start_id i of estimates.parquet (−1: seeded)
        row["message"] = "; ".join([message] * bool(message) + list(est.messages))
    return row


def _estimate_frame(seg_id: int, est: SegmentEstimate, data: SegmentData,
                    omega_c: float) -> pd.DataFrame:
    """estimates.parquet rows of one segment: every start (``start_id`` 0…), then the pass
    seeded with the batch-refined factors (``start_id`` = :data:`SEEDED_START_ID`): its
    ensemble as one start (``est.bit``: weighted means, the bit stuck where stuck members
    carry most of the weight) with the members' min–max bit speed as
    ``bit_rpm_est_min/max`` (NaN on the starts' rows).
    """
    first = _record_frame(seg_id, est.first, 0, data,
                          np.abs(est.first.bha_rad_s_est) <= omega_c)
    seeded = _record_frame(seg_id, est.bit.record(est.final), SEEDED_START_ID, data,
                           est.bit.stuck(est.final, omega_c))
    seeded["bit_rpm_est_min"] = (est.bit.low_rad_s / RPM_TO_RAD_S).astype(np.float32)
    seeded["bit_rpm_est_max"] = (est.bit.high_rad_s / RPM_TO_RAD_S).astype(np.float32)
    return pd.concat([first, seeded], ignore_index=True)


def _record_frame(seg_id: int, rec: ObserverRecord, offset: int, data: SegmentData,
                  stuck: np.ndarray) -> pd.DataFrame:
    """Rows of one observer record, one per time and start (``start_id`` from ``offset``);
    ``stuck`` is the bit-stuck flag per time and start (R, S) or per time (R,)."""
    n_t, n_s = rec.mu_k.shape
    measured = np.interp(rec.time_s, data.time_s, data.surface_rpm)
    cols = {
        "time_s": np.repeat(rec.time_s, n_s),
        "segment_id": np.full(n_t * n_s, seg_id, dtype=np.int32),
        "start_id": np.tile(np.arange(n_s, dtype=np.int16) + offset, n_t),
        "mu_s": rec.mu_s.ravel(), "mu_k": rec.mu_k.ravel(),
        "surface_rpm": np.repeat(measured, n_s),
        "surface_rpm_est": rec.surface_rad_s_est.ravel() / RPM_TO_RAD_S,
        "bit_rpm_est": rec.bit_rad_s_est.ravel() / RPM_TO_RAD_S,
        "bit_stuck": np.asarray(stuck, dtype=bool).ravel(),
        "residual_rpm": rec.residual_rad_s.ravel() / RPM_TO_RAD_S,
        "bit_rpm_est_min": np.full(n_t * n_s, np.nan, dtype=np.float32),
        "bit_rpm_est_max": np.full(n_t * n_s, np.nan, dtype=np.float32)}
    if data.bit_rpm is not None:
        cols["bit_rpm"] = np.repeat(np.interp(rec.time_s, data.time_s, data.bit_rpm), n_s)
    return pd.DataFrame(cols)


def _profile_frame(seg_id: int, est: SegmentEstimate, step_m: float = 10.0) -> pd.DataFrame:
    """Torque-and-drag profile of a segment every ~``step_m`` (profiles.parquet)."""
    td = est.td
    keep = np.unique(np.r_[np.arange(0, td.md_m.size - 1, max(1, int(step_m // max(
        np.diff(td.md_m).mean(), 1e-9)))), td.md_m.size - 2])
    return pd.DataFrame({"segment_id": np.int32(seg_id), "md_m": td.md_m[keep],
                         "inc_deg": np.degrees(td.inc_rad[keep]),
                         "tension_N": td.tension_N[keep], "torque_Nm": td.torque_Nm[keep],
                         "normal_force_N_m": td.normal_force_N_m[keep],
                         "fc_Nm_m": td.fc_Nm_m[keep]})


def consensus(rows: list[dict]) -> dict:
    """Well-level friction factors from the segments (never a made-up value).

    Only converged, off-bottom segments with status ok count. μ_k: their median; μ_s: the
    median over those that identify it; otherwise the median of their lower bounds (each is
    claimed valid, so the median is too, and one unreliable segment cannot set it).
    """
    ok = [r for r in rows if r["status"] == "ok" and r["kind"] == "off_bottom_rotating"
          and r["converged"]]
    mu_k = [r["mu_k"] for r in ok if r["mu_k"] is not None]
    mu_s = [r["mu_s"] for r in ok if r["mu_s_identifiable"] and r["mu_s"] is not None]
    bounds = [r["mu_s_lower_bound"] for r in ok if r["mu_s_lower_bound"] is not None]
    return {"mu_k": float(np.median(mu_k)) if mu_k else None,
            "mu_s": float(np.median(mu_s)) if mu_s else None,
            "mu_s_lower_bound": None if mu_s or not bounds else float(np.median(bounds))}


def run_well(path, out_root, *, config=None, survey=None, overrides=None,
             rate_hz: float | None = None, starts=None, pdf: bool = False,
             progress: Callable[[float], None] | None = None,
             chunk_rows: int = 200_000) -> RunResult:
    """Run the whole estimation on one well and write OUT/NAME atomically.

    Parameters
    ----------
    path : str or Path
        The well (data file, HDF5 bundle or directory; INTERFACE.md).
    out_root : str or Path
        Output directory; results go to ``out_root/NAME``.
    config, survey : path, optional
        Overrides of the sidecar configuration and survey.
    overrides : dict, optional
        ``{"table.key": value}`` from the command line.
    rate_hz : float, optional
        Resample the input to this rate before estimation; a rate above the data's own is
        not used (:func:`effective_rate`: a warning in ``summary["warnings"]``).
    starts : list of (μ_s, μ_k), optional
        Observer starts (overrides ``observer.starts``).
    pdf : bool
        Also write report.pdf.
    progress : callable, optional
        Called with the fraction of the input rows processed since the last call.

    Raises
    ------
    DrillfricError
        Unreadable input or configuration (nothing is written).
    """
    t_wall = time.perf_counter()
    data_path, config_path, survey_path = resolve_well(path, config=config, survey=survey)
    overrides = dict(overrides or {})
    if starts is not None:
        overrides["observer.starts"] = [list(map(float, s)) for s in starts]
    cfg, well_path = load_setup(path, config=config, survey=survey, overrides=overrides)
    name = well_name(path, config=config)
    mappings = channel_mappings(path, cfg, config=config)
    assumed = cfg.assumed_with(well_path) + assumed_units(mappings)
    torque_channel = mappings["surface_torque_Nm"]
    warnings: list[str] = []
    rate_used = rate_hz
    fallback_depth = None
    total_rows = _count_rows(data_path)
    segmenter = Segmenter(cfg)
    rows_out: list[dict] = []
    profiles: list[pd.DataFrame] = []
    warm = None
    failed = 0
    buffer = pd.DataFrame()
    buffer_start = 0
    last_end = 0  # row after the last emitted segment: the next pre-roll starts no earlier
    n_rows = 0
    has_truth = None
    final = Path(out_root) / name
    with atomic_directory(final) as tmp:
        writer = None
        try:
            def handle(done: list[Segment]):
                nonlocal warm, failed, fallback_depth, writer, last_end
                for seg in done:
                    lo = _preroll_start(buffer, seg.i_start - buffer_start,
                                        max(last_end - buffer_start, 0))
                    rows = buffer.iloc[lo: seg.i_end - buffer_start]
                    last_end = seg.i_end
                    if fallback_depth is None and not np.isfinite(seg.bit_depth_m):
                        fallback_depth = _bit_depth_default(cfg, well_path, assumed)
                    depth = seg.bit_depth_m if np.isfinite(seg.bit_depth_m) else fallback_depth
                    if seg.status != "ok":
                        rows_out.append(_segment_row(seg, None, seg.status, seg.message,
                                                     depth))
                        continue
                    data = _segment_data(rows, seg, depth)
                    try:
                        check_segment(data, cfg)
                        est = estimate_segment(cfg, well_path, data, warm=warm,
                                               rate_hz=rate_used,
                                               torque_channel=torque_channel)
                    except SkipSegment as exc:
                        rows_out.append(_segment_row(seg, None, "skipped", exc.problem,
                                                     depth))
                        continue
                    except DrillfricError as exc:
                        failed += 1
                        rows_out.append(_segment_row(seg, None, "failed", exc.message,
                                                     depth))
                        continue
                    if writer is None:
                        writer = EstimatesWriter(tmp / "estimates.parquet",
                                                 data.bit_rpm is not None)
                    writer.write(_estimate_frame(seg.id, est, data, cfg.omega_c_rad_s))
                    rows_out.append(_segment_row(seg, est, "ok", "", depth))
                    profiles.append(_profile_frame(seg.id, est))
                    if est.converged and seg.kind == "off_bottom_rotating":
                        warm = (est.mu_s_seed, est.mu_k)

            for chunk in iter_surface(path, config=config, survey=survey,
                                      chunk_rows=chunk_rows):
                if has_truth is None:
                    has_truth = "bit_rpm" in chunk
                    check_plausible_rate(chunk["time_s"].to_numpy(), file=data_path)
                    rate_used, note = effective_rate(rate_hz, chunk["time_s"].to_numpy())
                    warnings += [note] * bool(note)
                keep = chunk[[c for c in _KEEP if c in chunk]]
                buffer = pd.concat([buffer, keep], ignore_index=True) if len(buffer) else \
                    keep.reset_index(drop=True)
                n_rows += len(chunk)
                handle(segmenter.feed(chunk))
                drop = _rows_done(buffer, segmenter.pending_from - buffer_start)
                if drop > 0:
                    buffer = buffer.iloc[drop:].reset_index(drop=True)
                    buffer_start += drop
                if progress and total_rows:
                    progress(len(chunk) / total_rows)
            handle(segmenter.close())
            if n_rows == 0:
                raise InputError("no data rows", file=data_path,
                                 fix="check that the file holds samples below its header")
        finally:
            if writer is not None:
                writer.close()
        if writer is None:
            EstimatesWriter(tmp / "estimates.parquet", bool(has_truth)).close()
        summary = _summary(name, cfg, rows_out, assumed, data_path, config_path, survey_path,
                           n_rows, rate_hz, rate_used, time.perf_counter() - t_wall)
        summary["warnings"] = list(warnings)
        write_json(tmp / "summary.json", summary)
        write_segments(tmp / "segments.parquet", rows_out)
        if profiles:
            pd.concat(profiles, ignore_index=True).to_parquet(tmp / "profiles.parquet",
                                                              index=False)
        if well_path is not None:
            pd.DataFrame(well_path.at(well_path.md_m)).to_parquet(tmp / "wellpath.parquet",
                                                                 index=False)
        report_problem = _write_report(tmp, pdf)
        if report_problem:
            summary["warnings"].append(report_problem)
            write_json(tmp / "summary.json", summary)
    return RunResult(name, final, summary, failed, summary["warnings"])


def _write_report(result_dir: Path, pdf: bool) -> str | None:
    """Write the report; a failure is a warning, not a lost run (the results stand)."""
    from drillfric.report import write_well_report

    try:
        write_well_report(result_dir, pdf=pdf)
    except Exception as exc:  # noqa: BLE001 — the estimates are written; say what failed
        return f"report not written: {type(exc).__name__}: {exc}"
    return None


def _summary(name, cfg, rows, assumed, data_path, config_path, survey_path, n_rows, rate_hz,
             rate_used, wall_s) -> dict:
    files = {"data": data_path, "config": config_path, "survey": survey_path}
    inputs = {k: {"path": str(Path(p).resolve()), "sha256": file_sha256(p)}
              for k, p in files.items()
              if p is not None and Path(p).is_file()}
    inputs.update(rows=n_rows, resampled_rate_hz=rate_used, requested_rate_hz=rate_hz)
    n_ok = sum(r["status"] == "ok" for r in rows)
    n_conv = sum(r["status"] == "ok" and r["converged"] for r in rows)
    return {"well": name, "drillfric_version": __version__, **consensus(rows),
            "segments": rows, "inputs": inputs, "config": cfg.to_dict(),
            "assumed": assumed, "indicative": bool(assumed),
            "counts": {"segments": len(rows), "estimated": n_ok, "converged": n_conv,
                       "skipped": sum(r["status"] == "skipped" for r in rows),
                       "failed": sum(r["status"] == "failed" for r in rows)},
            "run_time_s": wall_s}


def _count_rows(data_path: Path) -> int:
    """Row count for the progress bar: Parquet metadata, else a fast line count."""
    suffix = data_path.suffix.lower()
    try:
        if suffix == ".parquet":
            import pyarrow.parquet as pq

            return pq.ParquetFile(data_path).metadata.num_rows
        if suffix == ".csv":
            count = 0
            with open(data_path, "rb") as fh:
                while block := fh.read(1 << 22):
                    count += block.count(b"\n") or block.count(b"\r")
            return count
    except OSError:
        return 0
    return 0
