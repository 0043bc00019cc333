"""What one estimated segment of a time log gives: its :class:`~drillfric.result.
SegmentRecord` and its output rows (estimates.parquet, profiles.parquet; docs/outputs.md).
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from drillfric.estimation.bit_torque import rate_of_penetration_m_h
from drillfric.estimation.chain import SegmentEstimate
from drillfric.estimation.diagnostics import settled_mask
from drillfric.estimation.motor import MotorSpeed, motor_speed
from drillfric.estimation.observer import ObserverRecord
from drillfric.estimation.segment_data import SegmentData
from drillfric.hookload import withhold_friction
from drillfric.io.timebase import clock_at, origin_of
from drillfric.result import SEEDED_START_ID, SegmentRecord
from drillfric.segmentation import Segment, pumps_on
from drillfric.units import RPM_TO_RAD_S
from drillfric.vocabulary import Kind, Status

if TYPE_CHECKING:
    from drillfric.config import Config


#: The note (and ``bit_speed_reason``) of a segment whose bit speed is shown while the pumps
#: ran and no motor is declared (issue 34 item 5): the trace is the string's bottom speed; a
#: mud motor would add its own (≈ k·flow).
MOTOR_NOTE = ("the pumps were on while the string turned: the bit speed shown is the "
              "string's bottom speed and includes no mud motor — with a motor the bit turns "
              "faster by its speed; declare it with [bha] motor_rev_per_litre")

#: The note of an on-bottom segment drilled with the pumps on and no motor declared: its MSE
#: takes the surface speed as the bit's.
MSE_NOTE = ("the pumps were on while drilling: mse_Pa takes the string's speed as the bit's "
            "— with a mud motor the bit turns faster and the MSE is higher; declare it with "
            "[bha] motor_rev_per_litre")
#: The note of a segment whose trace is shown with a declared motor turning: the stick-slip
#: statistics are those of the string's bottom, not of the bit the motor turns.
BHA_STATISTICS_NOTE = ("stick_slip_severity and stuck_fraction are the BHA's (the string's "
                       "bottom, bha_rpm_est): the mud motor turns the bit faster by "
                       "motor_rpm_mean")
#: The note of a segment with a declared motor whose flow is missing while the pumps may run.
FLOW_MISSING_NOTE = ("the flow is missing while the pumps may run: the bit speed (BHA + "
                     "motor) is withheld on those rows")

#: Bit-speed columns of estimates.parquet that a withheld window empties.
_SPEED_COLUMNS = ("bit_rpm_est", "bit_rpm_est_min", "bit_rpm_est_max", "bha_rpm_est",
                  "bha_rpm_est_min", "bha_rpm_est_max")


def pumped(rows: pd.DataFrame, cfg: Config) -> bool:
    """Whether the pumps ran (flow, pump rate or standpipe pressure above its
    ``segmentation.pumps_on_*``) through most of a segment's turning rows."""
    turning = rows["surface_rpm"].to_numpy(float) > cfg.segmentation.rotating_rpm
    on = pumps_on(rows, cfg)[turning]
    known = on >= 0
    return bool(known.sum()) and float(np.mean(on[known] == 1)) >= 0.5


def segment_record(seg: Segment, depth: float, status: Status, message: str, rows: pd.DataFrame,
            est: SegmentEstimate | None = None) -> SegmentRecord:
    """A segment's :class:`SegmentRecord` (the estimate's numbers when there is one)."""
    base = dict(id=seg.id, kind=Kind(seg.kind), t_start_s=seg.t_start_s, t_end_s=seg.t_end_s,
                bit_depth_m=depth, status=status, duration_s=seg.duration_s, message=message,
                hookload_N=_median(_while_moving(rows, seg), "hookload_N"), **_clock(rows, seg),
                axial_speed_m_s=seg.axial_speed_m_s,
                **_drilling(seg, rows))
    if est is None:
        return SegmentRecord(**base)
    record = SegmentRecord(**base | dict(
        message="; ".join([message] * bool(message) + list(est.messages)),
        mu_s=est.mu_s, mu_k=est.mu_k, mu_s_identifiable=est.mu_s_identifiable,
        mu_s_lower_bound=est.mu_s_lower_bound, mu_s_spread=est.mu_s_spread,
        mu_k_spread=est.mu_k_spread, converged=est.converged, method=est.method,
        mu_k_damping_uncertainty=est.mu_k_damping,
        settling_time_s=est.settling_time_s, residual_rms_rpm=est.residual_rms_rpm,
        mu_k_observer=est.mu_k_observer,
        # the observer's μ_s is no estimate where μ_s is not identifiable (a fifth newcomer
        # read 0.648 beside "not identifiable" in summary.json): null, as a withheld factor
        mu_s_observer=est.mu_s_observer if est.mu_s_identifiable else None, mu_td=est.mu_td,
        T_N_Nm=est.T_N_Nm, quality_flags=est.flags, starts=tuple(map(tuple, est.starts.tolist())),
        friction_zone=est.friction_zone, hookload_model_N=est.td.hookload_N,
        **_evidence_fields(est), **_bit_fields(est), **_torque_terms(est), **_skew(est),
        **_inertia(est), **_viscous(est)))
    if est.factors_withheld:
        record = withhold_friction(record, est.factors_withheld, None)
    # the windows' numbers stand where the segment's factors are withheld by its own rules:
    # a seeded trace that runs away from a constant μ_k is what a drift makes (§6.6)
    return replace(record, **_trend_fields(est))


def _inertia(est: SegmentEstimate) -> dict:
    """What the data say of the top-drive inertia (docs/bit_speed.md, Top-drive inertia)."""
    rig = est.inertia
    if rig is None:
        return {}
    return dict(top_drive_inertia_share=rig.share,
                top_drive_inertia_kg_m2_identified=rig.identified_kg_m2,
                top_drive_inertia_uncertainty_kg_m2=rig.uncertainty_kg_m2,
                top_drive_inertia_source=rig.source)


def _viscous(est: SegmentEstimate) -> dict:
    """The viscous damping the set-points identify (docs/theory.md §6.4)."""
    slope = est.viscous
    if slope is None:
        return {}
    return dict(k_t_identified_per_s=slope.k_t_per_s,
                k_t_identified_uncertainty_per_s=slope.uncertainty_per_s)


def _skew(est: SegmentEstimate) -> dict:
    """The torque's lag the segment was corrected for (docs/bit_speed.md, Channel skew)."""
    skew = est.skew
    if skew is None:
        return {}
    return dict(torque_lag_s=skew.lag_s, torque_lag_uncertainty_s=skew.uncertainty_s,
                torque_lag_source=skew.source)


def _while_moving(rows: pd.DataFrame, seg: Segment) -> pd.DataFrame:
    """The rows of a reaming segment while the pipe moves at its speed (its hook load is
    the moving load case's, docs/theory.md §2 steps 3–4); all rows of the other kinds."""
    if seg.axial_speed_m_s is None or "time_s" not in rows:
        return rows
    t = rows["time_s"].to_numpy(float)
    inside = (t >= seg.axial_from_s) & (t <= seg.axial_to_s)
    return rows[inside] if inside.any() else rows


def _drilling(seg: Segment, rows: pd.DataFrame) -> dict:
    """WOB and ROP of an on-bottom segment (docs/theory.md §2.3)."""
    if seg.kind != Kind.ON_BOTTOM:
        return {}
    return dict(wob_N=_median(rows, "wob_N"), rop_m_h=rate_of_penetration_m_h(rows))


def _torque_terms(est: SegmentEstimate) -> dict:
    terms = est.torque_terms
    if terms is None:
        return {}
    return dict(surface_rpm_mean=terms.surface_rpm_mean,
                surface_torque_turning_Nm=terms.surface_torque_turning_Nm,
                surface_torque_sem_Nm=terms.surface_torque_sem_Nm,
                torque_per_mu_Nm=terms.torque_per_mu_Nm, torque_fixed_Nm=terms.torque_fixed_Nm)


def _trend_fields(est: SegmentEstimate) -> dict:
    """μ_k's trend over the segment and its first and last window (docs/theory.md §6.6)."""
    trend = est.trend
    if trend is None or not np.isfinite(trend.mu_k).any():
        return {}
    ok = trend.mu_k[np.isfinite(trend.mu_k)]
    rate = None if trend.rate_per_h is None else float(trend.rate_per_h)
    return dict(mu_k_drift_per_h=rate, mu_k_first=float(ok[0]), mu_k_last=float(ok[-1]))


def _evidence_fields(est: SegmentEstimate) -> dict:
    ev = est.evidence
    return dict(torque_rms_misfit_Nm=ev.misfit_rms_Nm, torque_swing_Nm=ev.swing_Nm,
                fit_quality=ev.quality, surface_torque_mean_Nm=ev.mean_Nm)


def _bit_fields(est: SegmentEstimate) -> dict:
    """The bit-speed statistics, or null with the reason where the trace is withheld (the
    stuck fraction and severity stay where only the kinematic check withheld it; they are
    null where the stick-slip is beyond their validated range, the reason in the message)."""
    logged = dict(sample_interval_s=est.logged.interval_s,
                  interval_torque_swing=est.logged.torque_swing,
                  samples_dropped=est.samples_dropped, samples_held=est.samples_held)
    kept = dict(stick_slip_severity=est.stick_slip_severity,
                stuck_fraction=est.stuck_fraction,
                stick_slip_from_s=est.stick_slip_from_s,
                stick_slip_to_s=est.stick_slip_to_s) if est.bit_statistics else {}
    if not est.bit_speed.resolved:
        return logged | kept | dict(bit_speed_resolved=False,
                                    bit_speed_reason=est.bit_speed.reason)
    return logged | kept | dict(bit_speed_resolved=True,
                                bit_speed_windows_withheld=len(est.bit_windows_withheld),
                                bit_rms_error_rpm=est.bit_rms_error_rpm)


def _median(rows: pd.DataFrame, column: str) -> float | None:
    if column not in rows or not rows[column].notna().any():
        return None
    return float(np.nanmedian(rows[column].to_numpy(float)))


def _origin(rows: pd.DataFrame) -> pd.Timestamp | None:
    """Clock time (UTC) of ``time_s = 0`` from a segment's rows, None without absolute time."""
    if "timestamp" not in rows or rows.empty:
        return None
    first = pd.to_datetime(rows["timestamp"].iloc[:1], utc=True).iloc[0]
    return origin_of(first, float(rows["time_s"].iloc[0]))


def _clock(rows: pd.DataFrame, seg: Segment) -> dict:
    """Clock times of the segment's ends when the log has absolute time."""
    origin = _origin(rows)
    if origin is None:
        return {}
    return {"clock_start_utc": iso(clock_at(origin, seg.t_start_s)),
            "clock_end_utc": iso(clock_at(origin, seg.t_end_s))}


def _with_clock(frame: pd.DataFrame, rows: pd.DataFrame) -> pd.DataFrame:
    """estimates rows with their clock time (``timestamp``, UTC) beside ``time_s`` when the
    log has absolute time."""
    origin = _origin(rows)
    if origin is not None:
        frame.insert(1, "timestamp", clock_at(origin, frame["time_s"].to_numpy(float)))
    return frame


def output_frames(seg: Segment, est: SegmentEstimate, data: SegmentData, rows: pd.DataFrame,
                  omega_c: float, cfg: Config) -> dict[str, pd.DataFrame]:
    """The output rows of an estimated segment: ``estimates`` (with clock time when the log
    has it; the bit speed with a declared motor's, :func:`with_motor`) and its
    torque-and-drag ``profile`` (``omega_c``: the static band [rad/s])."""
    frame = with_motor(_estimate_frame(seg.id, est, data, omega_c), rows,
                       row_motor(rows, cfg, seg.kind == Kind.ON_BOTTOM))
    return {"estimates": _with_clock(frame, rows), "profile": _profile_frame(seg.id, est)}


def row_motor(rows: pd.DataFrame, cfg: Config, on_bottom: bool) -> MotorSpeed | None:
    """The speed band a declared mud motor (``[bha] motor_rev_per_litre``) adds at each of
    the segment's rows [rad/s] (docs/theory.md §2.4); None without a declared motor."""
    k = cfg.bha.motor_rev_per_litre
    if k is None:
        return None
    flow = rows["flow_in_m3_s"].to_numpy(float) if "flow_in_m3_s" in rows else None
    return motor_speed(flow, pumps_on(rows, cfg), k, cfg.bha.motor_speed_drop, on_bottom)


def with_motor(frame: pd.DataFrame, rows: pd.DataFrame,
               motor: MotorSpeed | None) -> pd.DataFrame:
    """estimates rows with the bit speed of the BHA plus a declared motor (eq. 2.4c):
    ``bit_rpm_est`` = ``bha_rpm_est`` + the motor's mid speed, the band the BHA's band plus
    the motor's low and high speeds; the bit is not stuck where the motor turns, unknown
    where its speed is (flow missing). Without a motor the bit's columns are the BHA's."""
    if motor is None:
        return frame
    at = frame["time_s"].to_numpy(float)
    t = rows["time_s"].to_numpy(float)
    low, mid, high = (np.interp(at, t, v) / RPM_TO_RAD_S
                      for v in (motor.low, motor.mid, motor.high))
    frame["bit_rpm_est"] = frame["bha_rpm_est"].to_numpy(float) + mid
    frame["bit_rpm_est_min"] = (frame["bha_rpm_est_min"].to_numpy(float) + low
                                ).astype(np.float32)
    frame["bit_rpm_est_max"] = (frame["bha_rpm_est_max"].to_numpy(float) + high
                                ).astype(np.float32)
    stuck = frame["bit_stuck"].astype("boolean")
    stuck[(mid > 0) & stuck.notna().to_numpy()] = False
    stuck[np.isnan(mid)] = pd.NA
    frame["bit_stuck"] = stuck
    return frame


def motor_fields(rows: pd.DataFrame, cfg: Config, on_bottom: bool, frame: pd.DataFrame | None,
                 record: SegmentRecord) -> dict:
    """A segment's fields from the mud motor (issue 34 item 5): without a declared motor,
    where a trace is shown with the pumps on, :data:`MOTOR_NOTE` (message and
    ``bit_speed_reason``), on bottom with the pumps on :data:`MSE_NOTE`; with one,
    ``motor_rpm_mean``, the notes that the stick-slip statistics are the BHA's and where
    the flow is missing, and ``bit_rms_error_rpm`` of the bit's speed (BHA + motor) where
    the input has the truth."""
    motor = row_motor(rows, cfg, on_bottom)
    if motor is None:
        return _undeclared(rows, cfg, on_bottom, record)
    turning = rows["surface_rpm"].to_numpy(float) > cfg.segmentation.rotating_rpm
    mid = motor.mid[turning] / RPM_TO_RAD_S
    mean = float(np.nanmean(mid)) if np.isfinite(mid).any() else None
    notes = [BHA_STATISTICS_NOTE] * bool(mean and record.stuck_fraction is not None) + \
        [FLOW_MISSING_NOTE] * bool(np.isnan(mid).any())
    fields = dict(motor_rpm_mean=mean, message=_joined(record.message, *notes))
    error = _bit_error_rpm(frame) if record.bit_rms_error_rpm is not None else None
    return fields | ({"bit_rms_error_rpm": error} if error is not None else {})


def _undeclared(rows: pd.DataFrame, cfg: Config, on_bottom: bool,
                record: SegmentRecord) -> dict:
    """Without a declared motor, what a pumped segment says: on bottom, that its MSE takes
    the string's speed (:data:`MSE_NOTE`); off bottom with a trace shown, that the trace is
    the string's bottom speed (:data:`MOTOR_NOTE`, also its ``bit_speed_reason``)."""
    if not pumped(rows, cfg):
        return {}
    if on_bottom:
        return dict(message=_joined(record.message, MSE_NOTE))
    return dict(message=_joined(record.message, MOTOR_NOTE),
                bit_speed_reason=MOTOR_NOTE) if record.bit_speed_resolved else {}


def _joined(*parts: str) -> str:
    return "; ".join(p for p in parts if p)


def _bit_error_rpm(frame: pd.DataFrame | None) -> float | None:
    """RMS error of the seeded pass's bit speed (BHA + motor) against the input's truth
    after the start-up [RPM], over the rows where both are known."""
    if frame is None or "bit_rpm" not in frame:
        return None
    seeded = frame[frame["start_id"] == SEEDED_START_ID]
    late = seeded[settled_mask(seeded["time_s"].to_numpy(float))]
    error = (late["bit_rpm_est"] - late["bit_rpm"]).to_numpy(float)
    error = error[np.isfinite(error)]
    return float(np.sqrt(np.mean(error ** 2))) if error.size else None


def _estimate_frame(seg_id: int, est: SegmentEstimate, data: SegmentData,
                    omega_c: float) -> pd.DataFrame:
    """estimates.parquet rows of one segment: every start (``start_id`` 0…), then the pass
    seeded with the batch-refined factors (``start_id`` = :data:`SEEDED_START_ID`): its
    ensemble as one start (``est.bit``: weighted means, the bit stuck where stuck members
    carry most of the weight) with the members' min–max bit speed as
    ``bit_rpm_est_min/max`` (NaN on the starts' rows) and μ_k(t) of the windowed re-fits
    with its half-width (``est.trend``, docs/theory.md §6.6; null where the segment's
    factors are withheld, unless the friction moved: a seeded trace that runs away from a
    constant μ_k is what a drift makes). The string's bottom speed is also ``bha_rpm_est``
    (``_min/_max``): the bit's until a motor's is added (:func:`with_motor`). Where the
    logging does not resolve the stick-slip cycle the speed columns are null: no trace is
    drawn from such data; so are they in the 30-s windows the window-by-window check
    withheld (``est.bit_windows_withheld``).
    """
    first = _record_frame(seg_id, est.first, 0, data,
                          np.abs(est.first.bha_rad_s_est) <= omega_c, est)
    seeded = _record_frame(seg_id, est.bit.record(est.final), SEEDED_START_ID, data,
                           est.bit.stuck(est.final, omega_c), est)
    seeded["bit_rpm_est_min"] = (est.bit.low_rad_s / RPM_TO_RAD_S).astype(np.float32)
    seeded["bit_rpm_est_max"] = (est.bit.high_rad_s / RPM_TO_RAD_S).astype(np.float32)
    if est.trend is not None and (est.trend.drift or not est.factors_withheld):
        seeded["mu_k"], seeded["mu_k_half_width"] = est.trend.at(
            seeded["time_s"].to_numpy(float))
    elif est.factors_withheld:  # the seed is the factor the segment's rules withheld
        seeded["mu_k"] = np.nan
    frame = pd.concat([first, seeded], ignore_index=True)
    for name in ("", "_min", "_max"):
        frame["bha_rpm_est" + name] = frame["bit_rpm_est" + name]
    gone = np.zeros(len(frame), dtype=bool) if est.bit_speed.resolved else \
        np.ones(len(frame), dtype=bool)
    t = frame["time_s"].to_numpy(float)
    for a, b in est.bit_windows_withheld:
        gone |= (t >= a) & (t < b)
    if gone.any():
        frame.loc[gone, list(_SPEED_COLUMNS)] = np.nan
        stuck = frame["bit_stuck"].astype("boolean")
        stuck[gone] = pd.NA
        frame["bit_stuck"] = stuck
    return frame


def _record_frame(seg_id: int, rec: ObserverRecord, offset: int, data: SegmentData,
                  stuck: np.ndarray, est: SegmentEstimate) -> pd.DataFrame:
    """Rows of one observer record, one per time and start (``start_id`` from ``offset``);
    ``stuck`` is the bit-stuck flag per time and start (R, S) or per time (R,)."""
    n_t, n_s = rec.mu_k.shape
    ev = est.evidence
    at = lambda t, y: np.repeat(np.interp(rec.time_s, t, y), n_s)  # noqa: E731
    cols = {
        "time_s": np.repeat(rec.time_s, n_s),
        "segment_id": np.full(n_t * n_s, seg_id, dtype=np.int32),
        "start_id": np.tile(np.arange(n_s, dtype=np.int16) + offset, n_t),
        "mu_s": rec.mu_s.ravel(), "mu_k": rec.mu_k.ravel(),
        "mu_k_half_width": np.full(n_t * n_s, np.nan),
        "surface_rpm": at(data.time_s, data.surface_rpm),
        "surface_rpm_est": rec.surface_rad_s_est.ravel() / RPM_TO_RAD_S,
        "bit_rpm_est": rec.bit_rad_s_est.ravel() / RPM_TO_RAD_S,
        "bit_stuck": np.asarray(stuck, dtype=bool).ravel(),
        "residual_rpm": rec.residual_rad_s.ravel() / RPM_TO_RAD_S,
        "surface_torque_Nm": at(ev.time_s, ev.measured_Nm),
        "surface_torque_est_Nm": rec.surface_torque_est_Nm.ravel(),
        "surface_torque_fit_Nm": at(ev.time_s, ev.model_Nm),
        "bit_rpm_est_min": np.full(n_t * n_s, np.nan, dtype=np.float32),
        "bit_rpm_est_max": np.full(n_t * n_s, np.nan, dtype=np.float32)}
    if data.bit_rpm is not None:
        cols["bit_rpm"] = at(data.time_s, data.bit_rpm)
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


def iso(stamp) -> str | None:
    """ISO 8601 UTC text of a timestamp (None when the log has no clock time)."""
    if stamp is None or pd.isna(stamp):
        return None
    stamp = pd.Timestamp(stamp)
    stamp = stamp.tz_localize("UTC") if stamp.tzinfo is None else stamp.tz_convert("UTC")
    return stamp.isoformat()
