"""Result directories for the report tests and the report benchmark, built file by file.

The report reads only the files of a result directory (docs/outputs.md and
docs/reports.md "What the report reads"). These helpers write those files directly:

- :func:`add_evidence_files` completes the demo's real result directory with the files
  and columns of the issue-16 contract (tracks.parquet from the demo log, the torque
  columns of estimates.parquet, the new segment keys) so the report can be tested on it
  before ``drillfric run`` writes them;
- :func:`synthetic_result` writes a whole 24 h result directory (100 Hz log decimated to
  tracks, 10 Hz estimates for ~24 segments × 4 starts) for the size and speed benchmark.

Values are plausible, not physics: the tests check that the report shows what the files
hold, not that the estimator is right (that is tests/test_pipeline.py's job).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from drillfric.io.tracks import TrackAccumulator, write_tracks

#: The reason written for a segment whose bit speed is marked not resolved (worded as
#: drillfric.estimation.sampling.resolution words it).
UNRESOLVED_REASON = ("bit speed not resolved: 10-s means give 0.42 per stick-slip cycle "
                     "(the shortest, 4.2 s, needs ≥ 8); log at ≥ 1.9 Hz to see the bit")
#: The segment of the demo marked "bit speed not resolved" by :func:`add_evidence_files`.
UNRESOLVED_SEGMENT = 2


def _tracks_from_log(log: pd.DataFrame, cfg) -> pd.DataFrame:
    from drillfric.segmentation import classify

    acc = TrackAccumulator(float(log["time_s"].iloc[-1] - log["time_s"].iloc[0]))
    acc.feed(log, classify(log, cfg))
    return acc.result()


def add_evidence_files(result_dir: Path, log_csv: Path, *, clock: str | None = None) -> Path:
    """Add the issue-16 files and columns to a result directory written by the demo run.

    ``surface_torque_Nm`` is the demo's noise-free string torque at each estimate time,
    ``surface_torque_est_Nm`` that torque plus a deterministic ripple, and
    ``surface_torque_fit_Nm`` the torque smoothed over 1 s (NaN for segment 1: "the fit
    did not simulate"). Segment keys come from those columns and the log; segment
    :data:`UNRESOLVED_SEGMENT` is marked "bit speed not resolved", its bit columns null as
    the run writes them then. ``clock``: an ISO time to give the log clock time.
    """
    from drillfric.config import config_from_dict
    from drillfric.torque_drag import solve_config
    from drillfric.wellpath import minimum_curvature

    result_dir = Path(result_dir)
    log = pd.read_csv(log_csv)
    summary = json.loads((result_dir / "summary.json").read_text(encoding="utf-8"))
    cfg = config_from_dict(_config_without_nulls(summary["config"]))
    if clock is not None:
        log["timestamp"] = pd.Timestamp(clock) + pd.to_timedelta(log["time_s"], unit="s")
        summary["time_origin_utc"] = pd.Timestamp(clock).isoformat()
    write_tracks(result_dir / "tracks.parquet", _tracks_from_log(log, cfg))
    est = pd.read_parquet(result_dir / "estimates.parquet")
    truth = np.interp(est["time_s"], log["time_s"], log["string_torque_Nm"])
    est["surface_torque_Nm"] = truth
    est["surface_torque_est_Nm"] = truth + 150.0 * np.sin(est["time_s"].to_numpy() / 3.0)
    smooth = pd.Series(truth).rolling(21, center=True, min_periods=1).mean().to_numpy()
    est["surface_torque_fit_Nm"] = np.where(est["segment_id"] == 1, np.nan, smooth)
    unresolved = est["segment_id"] == UNRESOLVED_SEGMENT
    est.loc[unresolved, ["bit_rpm_est", "bit_rpm_est_min", "bit_rpm_est_max"]] = np.nan
    est["bit_stuck"] = est["bit_stuck"].astype("boolean").mask(unresolved)
    est.to_parquet(result_dir / "estimates.parquet", index=False)
    wp = pd.read_parquet(result_dir / "wellpath.parquet")
    path = minimum_curvature(wp["md_m"], wp["inc_rad"], wp["azi_rad"])
    final = est[est["start_id"] == -1]
    for seg in summary["segments"]:
        rows = final[final["segment_id"] == seg["id"]]
        span = log[(log["time_s"] >= seg["t_start_s"]) & (log["time_s"] <= seg["t_end_s"])]
        _segment_keys(seg, rows, span, solve_config(cfg, path, seg["bit_depth_m"]).hookload_N,
                      summary.get("time_origin_utc"))
    (result_dir / "summary.json").write_text(json.dumps(summary), encoding="utf-8")
    pd.DataFrame(summary["segments"]).drop(columns=["quality_flags", "starts"]).to_parquet(
        result_dir / "segments.parquet", index=False)
    return result_dir


def _config_without_nulls(config: dict) -> dict:
    out = {}
    for table, values in config.items():
        if table == "string":
            out[table] = {"sections": [{k: v for k, v in s.items() if v is not None}
                                       for s in values["sections"]]}
        elif isinstance(values, dict):
            out[table] = {k: v for k, v in values.items() if v is not None}
    return out


def _segment_keys(seg: dict, rows: pd.DataFrame, span: pd.DataFrame, model_N: float,
                  origin: str | None) -> None:
    measured = rows["surface_torque_Nm"].to_numpy()
    fit = rows["surface_torque_fit_Nm"].to_numpy()
    misfit = float(np.sqrt(np.nanmean((measured - fit) ** 2))) if np.isfinite(fit).any() \
        else None
    swing = float(np.percentile(measured, 95) - np.percentile(measured, 5))
    seg.update(torque_rms_misfit_Nm=misfit, torque_swing_Nm=swing,
               fit_quality=None if misfit is None else misfit / swing,
               surface_torque_mean_Nm=float(span["string_torque_Nm"].mean()),
               hookload_N=float(span["hookload_N"].median()), hookload_model_N=model_N)
    if seg["id"] == UNRESOLVED_SEGMENT:
        seg.update(bit_speed_resolved=False, bit_speed_reason=UNRESOLVED_REASON,
                   sample_interval_s=10.0, interval_torque_swing=0.45,
                   stick_slip_severity=None, stuck_fraction=None)
    for key, t in (("clock_start_utc", seg["t_start_s"]), ("clock_end_utc", seg["t_end_s"])):
        seg[key] = None if origin is None else \
            (pd.Timestamp(origin) + pd.Timedelta(seconds=t)).isoformat()


# ------------------------------------------------------------------ a synthetic 24 h well
def synthetic_result(out: Path, *, hours: float = 24.0, log_rate_hz: float = 100.0,
                     n_segments: int = 24, segment_s: float = 1800.0, n_starts: int = 4,
                     estimate_rate_hz: float = 10.0, seed: int = 16) -> Path:
    """Write a complete result directory of a synthetic well drilled for ``hours``.

    The log (``log_rate_hz``, fed to the tracks accumulator in 1-hour chunks, never held
    whole) has stick-slip torque and speed while rotating, connections in between;
    ``n_segments`` stands of ``segment_s`` have estimates at ``estimate_rate_hz`` for
    ``n_starts`` starts plus the final pass. Deterministic (``seed``).
    """
    from drillfric.config import load_config

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    duration = hours * 3600.0
    period = duration / n_segments
    starts_s = np.arange(n_segments) * period + 0.05 * period
    depths = 1500.0 + 28.0 * np.arange(n_segments)
    cfg = load_config()
    acc = TrackAccumulator(duration)
    for hour in range(int(np.ceil(hours))):
        t = np.arange(hour * 3600.0, min((hour + 1) * 3600.0, duration), 1.0 / log_rate_hz)
        acc.feed(*_log_chunk(t, starts_s, segment_s, depths, period, rng, cfg))
    write_tracks(out / "tracks.parquet", acc.result())
    _write_estimates(out / "estimates.parquet", starts_s, segment_s, n_starts,
                     estimate_rate_hz, rng)
    segments = [_synthetic_segment(i + 1, starts_s[i], segment_s, depths[i], n_starts, rng)
                for i in range(n_segments)]
    summary = {"well": "synthetic-24h", "drillfric_version": "bench", "mu_k": 0.25,
               "mu_s": None, "mu_s_lower_bound": 0.4, "friction_zone": "open_hole",
               "friction_profile": "open hole below the shoe; cased part known",
               "segments": segments,
               "inputs": {"rows": int(duration * log_rate_hz)},
               "config": cfg.to_dict(), "assumed": [], "indicative": False,
               "counts": {"segments": n_segments, "estimated": n_segments,
                          "converged": n_segments, "skipped": 0, "failed": 0},
               "time_origin_utc": "2024-05-01T00:00:00+00:00", "warnings": []}
    (out / "summary.json").write_text(json.dumps(summary), encoding="utf-8")
    pd.DataFrame(segments).drop(columns=["quality_flags", "starts"]).to_parquet(
        out / "segments.parquet")
    return out


def _log_chunk(t, starts_s, segment_s, depths, period, rng, cfg):
    from drillfric.segmentation import classify

    k = np.minimum((t // period).astype(int), len(starts_s) - 1)
    rotating = (t >= starts_s[k]) & (t < starts_s[k] + segment_s)
    phase = 2 * np.pi * t / 6.0
    rpm = np.where(rotating, 60.0 + 45.0 * np.sin(phase), 0.0)
    torque = np.where(rotating, 18e3 + 6e3 * np.sin(phase - 1.0), 2e3)
    bit = depths[k]
    frame = pd.DataFrame({
        "time_s": t, "surface_rpm": rpm + 0.5 * rng.standard_normal(t.size),
        "surface_torque_Nm": torque + 300.0 * rng.standard_normal(t.size),
        "hookload_N": np.where(rotating, 7e5 + 0.1e3 * bit, 3e5) + 2e3 * rng.standard_normal(
            t.size),
        "bit_depth_m": bit, "hole_depth_m": bit + 5.0,
        "block_position_m": 30.0 - 28.0 * ((t % period) / period),
        "standpipe_pressure_Pa": np.where(rotating, 18e6, 0.5e6),
        "flow_in_m3_s": np.where(rotating, 0.04, 0.0)})
    frame["timestamp"] = pd.Timestamp("2024-05-01T00:00:00Z") + pd.to_timedelta(t, unit="s")
    return frame, classify(frame, cfg)


def _write_estimates(path, starts_s, segment_s, n_starts, rate_hz, rng) -> None:
    import pyarrow as pa
    import pyarrow.parquet as pq

    writer = None
    for i, t0 in enumerate(starts_s):
        t = t0 + np.arange(0.0, segment_s, 1.0 / rate_hz)
        phase = 2 * np.pi * t / 6.0
        rows = []
        for start in [*range(n_starts), -1]:
            measured = 18e3 + 6e3 * np.sin(phase - 1.0) + 300.0 * rng.standard_normal(t.size)
            decay = np.exp(-(t - t0) / 60.0)
            bit = np.maximum(60.0 + 80.0 * np.sin(phase), 0.0)
            rows.append(pd.DataFrame({
                "time_s": t, "segment_id": np.int32(i + 1), "start_id": np.int16(start),
                "mu_s": 0.45 + 0.3 * decay * (start - 1.5) / 2,
                "mu_k": 0.25 + 0.1 * decay * (start - 1.5) / 2,
                "surface_rpm": 60.0 + 45.0 * np.sin(phase),
                "surface_rpm_est": 60.0 + 44.0 * np.sin(phase - 0.05),
                "bit_rpm_est": bit, "bit_stuck": bit <= 9.5,
                "residual_rpm": rng.standard_normal(t.size),
                "bit_rpm_est_min": (bit * 0.9 if start == -1 else np.nan * bit),
                "bit_rpm_est_max": (bit * 1.1 if start == -1 else np.nan * bit),
                "surface_torque_Nm": measured,
                "surface_torque_est_Nm": 18e3 + 5.9e3 * np.sin(phase - 1.02),
                "surface_torque_fit_Nm": 18e3 + 5.8e3 * np.sin(phase - 1.05)}))
        table = pa.Table.from_pandas(pd.concat(rows, ignore_index=True), preserve_index=False)
        if writer is None:
            writer = pq.ParquetWriter(path, table.schema, compression="zstd")
        writer.write_table(table)
    writer.close()


#: The notes of every synthetic stand (worded like the estimators' messages).
SYNTHETIC_MESSAGE = ("top drive identified from the log as PI speed control: the model "
                     "replays it; μ_s not identifiable (stick-slip, no creep); μ_s ≥ 0.40 "
                     "from the stick-slip onset")


def _synthetic_segment(seg_id, t0, segment_s, depth, n_starts, rng) -> dict:
    mu_k = 0.25 + 0.02 * rng.standard_normal()
    return {"id": seg_id, "kind": "off_bottom_rotating", "t_start_s": float(t0),
            "t_end_s": float(t0 + segment_s), "bit_depth_m": float(depth),
            "mu_s": None, "mu_k": mu_k, "mu_s_identifiable": False, "mu_s_lower_bound": 0.4,
            "mu_s_spread": 0.05, "mu_k_spread": 0.01, "converged": True, "method": "batch",
            "settling_time_s": 40.0, "residual_rms_rpm": 1.0, "stick_slip_severity": 0.9,
            "status": "ok", "message": SYNTHETIC_MESSAGE, "duration_s": segment_s,
            "stuck_fraction": 0.2, "mu_td": mu_k + 0.01, "torque_rms_misfit_Nm": 450.0,
            "torque_swing_Nm": 12e3, "fit_quality": 450.0 / 12e3,
            "surface_torque_mean_Nm": 18e3, "hookload_N": 7e5 + 0.1e3 * depth,
            "hookload_model_N": 6.2e5 + 0.1e3 * depth, "bit_speed_resolved": True,
            "bit_speed_reason": "", "friction_zone": "open_hole", "quality_flags": [],
            "sample_interval_s": 0.01, "interval_torque_swing": None,
            "clock_start_utc": None, "clock_end_utc": None,
            "starts": [[0.3, 0.2], [0.6, 0.4], [0.9, 0.1], [0.5, 0.3]][:n_starts]}


#: Segment keys that results written before issue 16 (and the friction profile and
#: logging-rate checks after it) do not have.
NEWER_SEGMENT_KEYS = ("friction_zone", "torque_rms_misfit_Nm", "torque_swing_Nm",
                      "fit_quality", "surface_torque_mean_Nm", "hookload_N", "hookload_model_N",
                      "bit_speed_resolved", "bit_speed_reason", "sample_interval_s",
                      "interval_torque_swing", "clock_start_utc", "clock_end_utc")


def older_result(src: Path, dst: Path) -> Path:
    """A copy of a result directory as versions before issue 16 wrote it: no
    tracks.parquet, no torque columns in estimates.parquet, none of
    :data:`NEWER_SEGMENT_KEYS`, no friction zone in the summary."""
    import shutil

    keys = NEWER_SEGMENT_KEYS
    shutil.copytree(src, dst)
    (dst / "tracks.parquet").unlink(missing_ok=True)
    summary = json.loads((dst / "summary.json").read_text(encoding="utf-8"))
    for key in ("friction_zone", "friction_profile"):
        summary.pop(key, None)
    for seg in summary["segments"]:
        for key in keys:
            seg.pop(key, None)
    (dst / "summary.json").write_text(json.dumps(summary), encoding="utf-8")
    estimates = pd.read_parquet(dst / "estimates.parquet")
    estimates.drop(columns=[c for c in estimates if "torque" in c]).to_parquet(
        dst / "estimates.parquet")
    segments = pd.read_parquet(dst / "segments.parquet")
    segments.drop(columns=[k for k in keys if k in segments]).to_parquet(
        dst / "segments.parquet")
    return dst
