"""The result of a run, declared once: segments, estimates, the well summary and what a run
returns (:class:`WellResult`) and reports as it goes (:class:`RunProgress`).

Every output that describes a segment — ``summary.json`` ``segments``, ``segments.parquet``,
the report's tables and ``fleet_summary.parquet`` — is built from :class:`SegmentRecord`;
every column of ``estimates.parquet`` from :data:`ESTIMATE_COLUMNS`. Units are in the names
(docs/nomenclature.md) and in each field's metadata; docs/outputs.md is generated from here
(:func:`outputs_markdown`) and a test keeps the two equal.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields
from enum import StrEnum
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa

from drillfric.vocabulary import Kind, Method, Status


class Flag(StrEnum):
    """Conditions a reader of a segment's numbers must know (docs/outputs.md)."""

    OBSERVER_STARTS_DISAGREE = "observer_starts_disagree"
    OBSERVER_DEADLOCK_AVERTED = "observer_deadlock_averted"
    NO_ROTATION = "no_rotation"
    ROTATION_TOO_SHORT = "rotation_too_short"
    REGIME_MISMATCH = "regime_mismatch"
    MU_K_NOT_CONVERGED = "mu_k_not_converged"
    CREEP_RATE_TOO_LOW = "creep_rate_too_low"
    CREEP_FIT_AT_BOUND = "creep_fit_at_bound"
    CREEP_NOT_GRID_CONVERGED = "creep_not_grid_converged"
    MU_S_NOT_EXPLAINED = "mu_s_not_explained"
    BISTABLE_REGIME = "bistable_regime"
    STICK_SLIP_NOT_REPRODUCED = "stick_slip_not_reproduced"
    ESTIMATORS_DISAGREE = "estimators_disagree"
    TOO_SHORT_TO_CONVERGE = "too_short_to_converge"
    OUTSIDE_TYPICAL_RANGE = "outside_typical_range"
    BIT_TORQUE_IN_FRICTION = "bit_torque_in_friction"
    POOLED = "pooled"
    BIT_SPEED_DRIFT = "bit_speed_drift"
    STICK_SLIP_BEYOND_VALIDATED = "stick_slip_beyond_validated"
    STICK_SLIP_UNDETERMINED = "stick_slip_undetermined"
    HOOKLOAD_CONTRADICTS_STRING = "hookload_contradicts_string"
    STRING_WEIGHT_UNVERIFIED = "string_weight_unverified"
    STRING_WEIGHT_CALIBRATED = "string_weight_calibrated"
    TORQUE_ZERO_OFFSET = "torque_zero_offset"
    RELAXATION_CYCLES = "relaxation_cycles"
    MU_K_UNCERTAIN = "mu_k_uncertain"
    MU_K_DEPENDS_ON_MU_S = "mu_k_depends_on_mu_s"
    FACTORS_RUN_AWAY = "factors_run_away"
    PIPE_MOVING = "pipe_moving"
    CHANNEL_SKEW_UNIDENTIFIED = "channel_skew_unidentified"
    MU_K_DRIFT = "mu_k_drift"
    TOP_DRIVE_INERTIA_UNCONFIRMED = "top_drive_inertia_unconfirmed"
    TOP_DRIVE_INERTIA_CONTRADICTED = "top_drive_inertia_contradicted"

    @classmethod
    def _missing_(cls, value):
        """Flags renamed since results were written: ``observer_not_converged`` (until
        0.1.0) is ``observer_starts_disagree`` — the segment may well be converged."""
        return {"observer_not_converged": cls.OBSERVER_STARTS_DISAGREE}.get(value)


#: What each flag means (docs/outputs.md).
FLAG_MEANINGS = {
    Flag.OBSERVER_STARTS_DISAGREE: "the observer's starts did not agree (spread above tolerance)",
    Flag.OBSERVER_DEADLOCK_AVERTED: "an observer start stuck while the top drive turned was "
                                    "released by the deadlock guard",
    Flag.NO_ROTATION: "the fit window holds no rotation above ω_c",
    Flag.ROTATION_TOO_SHORT: "no rotating run outlasts its start-up transient by 3 whole "
                             "torque cycles (μ_k unfitted)",
    Flag.REGIME_MISMATCH: "the model could not be put in the data's regime (stick-slip or "
                          "steady): μ_k may be biased by a few %",
    Flag.MU_K_NOT_CONVERGED: "the mean torque was matched to worse than 2 %",
    Flag.CREEP_RATE_TOO_LOW: "a creep start-up was found but logged below 2 Hz: μ_s not fitted",
    Flag.CREEP_FIT_AT_BOUND: "the creep fit ran to its search bound: μ_s not reported",
    Flag.CREEP_NOT_GRID_CONVERGED: "the creep μ_s moved by more than 3 % on grid refinement: "
                                   "not reported",
    Flag.MU_S_NOT_EXPLAINED: "the creep fit's μ_s failed a check (misfit, sensitivity, the "
                             "slips after it, its two halves, the cased static hypotheses): "
                             "not reported, the message says which",
    Flag.BISTABLE_REGIME: "whether the model sticks is not monotone in μ_s: no lower bound",
    Flag.STICK_SLIP_NOT_REPRODUCED: "the model does not stick-slip for any μ_s: no lower bound",
    Flag.ESTIMATORS_DISAGREE: "batch and observer μ_k differ by more than a factor 1.5: not "
                              "converged",
    Flag.TOO_SHORT_TO_CONVERGE: "less than 90 s of rotation: not converged",
    Flag.OUTSIDE_TYPICAL_RANGE: "μ_k outside 0.05–0.8: check string, survey, torque units",
    Flag.BIT_TORQUE_IN_FRICTION: "on bottom: the bit torque is in the apparent friction",
    Flag.BIT_SPEED_DRIFT: "the bit-speed trace drifts from the top drive by more than the "
                          "string's twist allows, by under a third of its stick-slip swing: "
                          "shown, its phase approximate",
    Flag.STICK_SLIP_UNDETERMINED: "stuck fraction and severity withheld: the ensemble's "
                                  "members, whose μ_s spans its uncertainty, disagree on them "
                                  "beyond ±0.05 / ±12 % (docs/bit_speed.md)",
    Flag.STICK_SLIP_BEYOND_VALIDATED: "stick-slip more severe than the stuck fraction and the "
                                      "severity are validated for (estimated severity ≥ 2.1): "
                                      "both withheld",
    Flag.RELAXATION_CYCLES: "the string stalls while a soft top drive crawls below ω_c, "
                            "then bursts free (a relaxation cycle): the mean torque is "
                            "mostly static wind-up, μ_k not converged",
    Flag.POOLED: "too short alone; pooled with other short segments at neighbouring depths "
                 "(within 10 % of the string's friction torque) whose μ_k agree (summary.json "
                 "pooled)",
    Flag.RELAXATION_CYCLES: "the string stalls while a soft top drive crawls far below its "
                            "set-point (below ω_c or half its mean speed), then bursts free "
                            "(a relaxation cycle): the mean torque is mostly static wind-up, "
                            "μ_k not converged",
    Flag.MU_K_UNCERTAIN: "the mean torque of the record's torque cycles scatters too much: "
                         "μ_k's 2σ statistical uncertainty exceeds 5 %, not converged",
    Flag.FACTORS_RUN_AWAY: "the observer seeded with the fitted factors drives the bit "
                           "ahead of or behind the top drive over most of the rotation, "
                           "three times beyond any twist the string can hold: the factors "
                           "do not describe the record, μ_k not converged",
    Flag.MU_K_DEPENDS_ON_MU_S: "the model stick-slipped only with μ_s = 4 μ_k, not 2.5 μ_k, "
                               "and the mean-torque μ_k of the two differ by more than 5 %: "
                               "the unidentified μ_s sets μ_k, not converged",
    Flag.POOLED: "too short alone; pooled with other short segments at the same depth whose "
                 "μ_k agree (summary.json pooled)",
    Flag.HOOKLOAD_CONTRADICTS_STRING: "the hook load contradicts the configured string's "
                                      "weight beyond hookload.tolerance (docs/theory.md "
                                      "§2.1): friction factors withheld (null)",
    Flag.STRING_WEIGHT_UNVERIFIED: "the log holds no in-slips period and no [hookload] "
                                   "block_weight_N is given, so the string weight μ scales "
                                   "with (1/W) cannot be measured (docs/theory.md §2.1): "
                                   "friction factors withheld (null)",
    Flag.STRING_WEIGHT_CALIBRATED: "the string's buoyed weight was scaled to the hook load "
                                   "before estimation (hookload.calibrate_string_weight; "
                                   "summary.json hookload)",
    Flag.TORQUE_ZERO_OFFSET: "the torque reads more than 3 % of the rotating torque with "
                             "the string in the slips, where it should read zero: a zero "
                             "offset that moves μ by as much (summary.json torque_zero, "
                             "docs/theory.md §2.1): friction factors withheld (null)",
    Flag.PIPE_MOVING: "the pipe moves along the hole as it turns (reaming, back-reaming): μ_s "
                      "is not identifiable (no point sticks in torsion once |v| > ω_c·r_c), "
                      "the observer's μ_k is left out of the agreement and its bit speed "
                      "withheld (it has no axial model, docs/theory.md §3.3)",
    Flag.CHANNEL_SKEW_UNIDENTIFIED: "the torque's lag behind the speed is neither configured "
                                    "([channels] lag_s) nor identified from the segment's "
                                    "set-point steps, start-ups or stops: the bit speed, "
                                    "stuck fraction and severity, whose phase rests on the "
                                    "channels' timing, are withheld (docs/bit_speed.md, "
                                    "Channel skew)",
    Flag.MU_K_DRIFT: "the friction moved within the segment beyond its uncertainty (windowed "
                     "re-fits of the mean torque after torque and drag, docs/theory.md §6.6): "
                     "mu_k_drift_per_h is its rate, μ_k the mean over the drift, "
                     "estimates.parquet's μ_k column μ_k(t)",
    Flag.TOP_DRIVE_INERTIA_UNCONFIRMED: "the inertia correction I_TD·dω₀/dt of the logged "
                                        "motor torque is a material share of the torque's "
                                        "variation and the segment's data do not identify "
                                        "I_TD: the bit speed, stuck fraction and severity, "
                                        "which rest on rig.top_drive_inertia_kg_m2, are "
                                        "withheld (docs/bit_speed.md, Top-drive inertia)",
    Flag.TOP_DRIVE_INERTIA_CONTRADICTED: "the segment's data identify a top-drive inertia "
                                         "beyond ±25 % of rig.top_drive_inertia_kg_m2 (a gear "
                                         "change?): the bit speed, stuck fraction and "
                                         "severity are withheld (docs/bit_speed.md, Top-drive "
                                         "inertia)",
}


class WellFlag(StrEnum):
    """Conditions a reader of a well's headline must know (summary.json ``quality_flags``)."""

    MU_K_WITHHELD = "mu_k_withheld"
    LOW_SUPPORT = "low_support"
    WIDE_SPREAD = "wide_spread"
    INDICATIVE = "indicative"
    SEGMENTS_OUTSIDE_TYPICAL_RANGE = "segments_outside_typical_range"
    STRING_WEIGHT_INCONSISTENT = "string_weight_inconsistent"
    HOOKLOAD_CONTRADICTS_STRING = "hookload_contradicts_string"
    STRING_WEIGHT_UNVERIFIED = "string_weight_unverified"
    STRING_WEIGHT_NOT_CHECKED = "string_weight_not_checked"
    SEGMENTS_FAILED = "segments_failed"


_FIT = "drillfric.estimation.batch."
_VERDICT = "drillfric.estimation.verdict."
#: The rule table of the flags: for each, the function(s) that raise it (dotted names), pure
#: rules of evidence, each held by a table of cases in the tests. The fit's stages raise
#: what they find (evidence); :func:`drillfric.estimation.verdict.decide` and
#: :func:`~drillfric.estimation.verdict.decide_trace` decide what a segment claims from it;
#: the well-wide checks (string weight, torque zero, pooling) then withhold or mark. No
#: other function raises a flag (tests/test_rule_table.py scans the code for it).
FLAG_RAISED_BY = {
    Flag.OBSERVER_STARTS_DISAGREE: ("drillfric.estimation.chain.evidence",),
    Flag.OBSERVER_DEADLOCK_AVERTED: ("drillfric.estimation.chain.evidence",),
    Flag.NO_ROTATION: (_FIT + "fit.refine",),
    Flag.ROTATION_TOO_SHORT: (_FIT + "fit.refine",),
    Flag.REGIME_MISMATCH: (_FIT + "kinetic.fit_kinetic",),
    Flag.MU_K_NOT_CONVERGED: (_FIT + "kinetic.fit_kinetic",),
    Flag.CREEP_RATE_TOO_LOW: (_FIT + "fit._static_stages",),
    Flag.CREEP_FIT_AT_BOUND: (_FIT + "creep_fit.fit_creeps",),
    Flag.CREEP_NOT_GRID_CONVERGED: (_FIT + "creep_fit.fit_creeps",),
    Flag.MU_S_NOT_EXPLAINED: (_FIT + "creep_fit._judged",),
    Flag.BISTABLE_REGIME: (_FIT + "onset.onset_bound",),
    Flag.STICK_SLIP_NOT_REPRODUCED: (_FIT + "onset.onset_bound",),
    Flag.ESTIMATORS_DISAGREE: (_VERDICT + "_batch_converged",),
    Flag.TOO_SHORT_TO_CONVERGE: (_VERDICT + "_long_enough",),
    Flag.OUTSIDE_TYPICAL_RANGE: (_VERDICT + "decide", "drillfric.estimation.friction_log._record"),
    Flag.BIT_TORQUE_IN_FRICTION: (_VERDICT + "decide", "drillfric.estimation.friction_log._record"),
    Flag.POOLED: ("drillfric.estimation.consensus._pooled",),
    Flag.BIT_SPEED_DRIFT: (_VERDICT + "decide_trace",),
    Flag.STICK_SLIP_BEYOND_VALIDATED: (_VERDICT + "decide_trace",),
    Flag.STICK_SLIP_UNDETERMINED: (_VERDICT + "decide_trace",),
    Flag.HOOKLOAD_CONTRADICTS_STRING: ("drillfric.hookload.weight_verdict",),
    Flag.STRING_WEIGHT_UNVERIFIED: ("drillfric.hookload.weight_verdict",),
    Flag.STRING_WEIGHT_CALIBRATED: ("drillfric.hookload.weight_verdict",),
    Flag.TORQUE_ZERO_OFFSET: ("drillfric.torque_zero.withhold_offset",),
    Flag.RELAXATION_CYCLES: (_FIT + "fit.refine",),
    Flag.MU_K_UNCERTAIN: (_VERDICT + "_batch_converged",),
    Flag.MU_K_DEPENDS_ON_MU_S: (_FIT + "kinetic.fit_kinetic",),
    Flag.FACTORS_RUN_AWAY: (_VERDICT + "decide_trace",),
    Flag.PIPE_MOVING: (_VERDICT + "_pipe_moving",),
    Flag.CHANNEL_SKEW_UNIDENTIFIED: (_VERDICT + "decide_trace",),
    Flag.MU_K_DRIFT: ("drillfric.estimation.friction_trend.drift_verdict",),
    Flag.TOP_DRIVE_INERTIA_UNCONFIRMED: (_VERDICT + "decide_trace",),
    Flag.TOP_DRIVE_INERTIA_CONTRADICTED: (_VERDICT + "decide_trace",),
}


#: What each well flag means (docs/outputs.md); each comes with a line in ``warnings``.
WELL_FLAG_MEANINGS = {
    WellFlag.MU_K_WITHHELD: "segments were estimated but none gives a well μ_k (null): "
                            "mu_k_reason says why",
    WellFlag.LOW_SUPPORT: "the well μ_k rests on fewer than 3 segments (mu_k_support)",
    WellFlag.WIDE_SPREAD: "mu_k_uncertainty is above 25 % of the well μ_k: its segments "
                          "disagree",
    WellFlag.INDICATIVE: "defaults were assumed (assumed, e.g. no survey): the numbers are "
                         "indicative",
    WellFlag.SEGMENTS_OUTSIDE_TYPICAL_RANGE: "segments flagged outside_typical_range "
                                             "(μ outside 0.05–0.8)",
    WellFlag.STRING_WEIGHT_INCONSISTENT: "in off-bottom segments the modelled rotating hook "
                                         "load exceeds the measured one by more than 5 % "
                                         "(the report's string-weight check)",
    WellFlag.HOOKLOAD_CONTRADICTS_STRING: "the hook-load check withheld segments' friction "
                                          "factors (hookload, docs/theory.md §2.1)",
    WellFlag.STRING_WEIGHT_UNVERIFIED: "the log holds no in-slips period and no "
                                       "[hookload] block_weight_N is given: the string "
                                       "weight, which μ scales with (1/W), cannot be "
                                       "measured, and the friction factors are withheld",
    WellFlag.STRING_WEIGHT_NOT_CHECKED: "nothing in the log could check the configured "
                                        "string's weight, which μ scales with (1/W): no hook "
                                        "load, no off-bottom rotating segment with one, or a "
                                        "depth-indexed log",
    WellFlag.SEGMENTS_FAILED: "segments whose estimation failed (counts.failed)",
}


def _f(unit: str, doc: str, default=None, **kw):
    """A schema field with its unit and meaning."""
    return field(default=default, metadata={"unit": unit, "doc": doc}, **kw)


@dataclass(frozen=True)
class SegmentRecord:
    """One segment of a well: a row of ``segments.parquet``, an entry of ``summary.json``.

    The first 18 fields are the binding keys of the interface, in their order; the rest are
    drillfric's additions. ``None`` is null (JSON) / NaN (Parquet).
    """

    id: int = _f("", "segment number, 1-based, in time order", 0)
    kind: Kind = _f("", "load case: off_bottom_rotating, on_bottom_rotating, reaming or "
                        "back_reaming (the last two estimated with the moving load case "
                        "where the pipe's speed is steady over ≤ 30 m, docs/theory.md §3.3)",
                    Kind.OFF_BOTTOM)
    t_start_s: float = _f("s", "time of the segment's first sample", 0.0)
    t_end_s: float = _f("s", "time of the segment's last sample", 0.0)
    bit_depth_m: float | None = _f("m", "median bit depth (or the assumed depth)")
    mu_s: float | None = _f("-", "static friction factor, only where the data identify it")
    mu_k: float | None = _f("-", "kinetic friction factor")
    mu_s_identifiable: bool = _f("", "whether μ_s is identified by these data", False)
    mu_s_lower_bound: float | None = _f("-", "lower bound on μ_s where only bounded")
    mu_s_spread: float | None = _f("-", "uncertainty of μ_s (creep fit's change on grid "
                                        "refinement)")
    mu_k_spread: float | None = _f("-", "spread of the observer starts' μ_k")
    mu_k_damping_uncertainty: float | None = _f("-", "half-width of a batch μ_k from the "
                                                     "viscous damping assumed (k_t within "
                                                     "model.k_t_uncertainty_factor), combined "
                                                     "in quadrature with the tolerance in its "
                                                     "95 % interval")
    converged: bool = _f("", "whether μ_k is converged (agreeing estimators, ≥ 90 s)", False)
    method: Method = _f("", "estimator of the numbers: batch, observer, td_backcalc (a "
                             "depth-indexed log's friction log) or none", Method.NONE)
    settling_time_s: float | None = _f("s", "time the observer starts took to settle")
    residual_rms_rpm: float | None = _f("RPM", "RMS innovation of the reported observer pass")
    stick_slip_severity: float | None = _f("-", "(max − min)/(2·mean) of the estimated BHA "
                                                "speed (the bit's without a mud motor) from "
                                                "stick_slip_from_s to stick_slip_to_s (ensemble "
                                                "members pooled; ±12 %); null "
                                                "where beyond its validated range (flag "
                                                "stick_slip_beyond_validated), not "
                                                "determined (stick_slip_undetermined) or "
                                                "below 0.2 (no stick-slip: not stated)")
    status: Status = _f("", "ok, skipped or failed", Status.OK)
    message: str = _f("", "why skipped/failed, and what to know about the numbers", "")
    duration_s: float = _f("s", "t_end_s − t_start_s", 0.0)
    stuck_fraction: float | None = _f("-", "share of the time from stick_slip_from_s to "
                                           "stick_slip_to_s the BHA is stuck, |ω_BHA| ≤ ω_c (the "
                                           "bit's without a mud motor; ensemble members "
                                           "pooled; ±0.05); null where beyond its "
                                           "validated range or not determined")
    stick_slip_from_s: float | None = _f("s", "the stuck fraction and severity are taken "
                                              "from this time to stick_slip_to_s: after the "
                                              "start-up and after any creep whose break-free "
                                              "depends on an unidentified μ_s (the rotation at "
                                              "its set-point, not its transients)")
    stick_slip_to_s: float | None = _f("s", "...to this time: the last at which the top "
                                            "drive's speed (1-s mean) was at 90 % of its "
                                            "level, before the ramp to rest that ends the "
                                            "rotation (a stop is not stick-slip)")
    mu_k_observer: float | None = _f("-", "observer consensus μ_k (first pass)")
    mu_s_observer: float | None = _f("-", "observer consensus μ_s (first pass); null where "
                                          "μ_s is not identifiable (mu_s_identifiable false)")
    mu_td: float | None = _f("-", "static torque-and-drag back-calculated friction factor")
    T_N_Nm: float | None = _f("N·m", "∫F_c dx at this depth: torque per unit friction factor")
    bit_rms_error_rpm: float | None = _f("RPM", "RMS error of the bit speed (synthetic truth)")
    quality_flags: tuple[Flag, ...] = _f("", "conditions to know (Flag; a list, not JSON "
                                             "text)", ())
    starts: tuple[tuple[float, float], ...] = _f("-", "observer starts (μ_s, μ_k) by "
                                                      "start_id (a list of pairs)", ())
    friction_zone: str | None = _f("", "which factor μ is: open_hole (cased part known from "
                                       "the configuration) or effective (torque-weighted over "
                                       "the whole string)")
    torque_rms_misfit_Nm: float | None = _f("N·m", "RMS of measured − fitted-model string "
                                                   "torque (1-s smoothed) over the rotation")
    torque_swing_Nm: float | None = _f("N·m", "swing of the measured string torque (5th–95th "
                                              "percentile) over the rotation")
    fit_quality: float | None = _f("-", "torque_rms_misfit_Nm / torque_swing_Nm (stick-slip "
                                        "drifts in phase: ~0.3–0.6 is normal there)")
    surface_torque_mean_Nm: float | None = _f("N·m", "mean measured rotating string torque")
    hookload_N: float | None = _f("N", "median measured hook load over the segment (of a "
                                       "reaming segment: while the pipe moves)")
    hookload_model_N: float | None = _f("N", "modelled rotating off-bottom hook load at this "
                                             "depth (torque and drag, no block weight; of a "
                                             "reaming segment the rotating slack-off / pick-up "
                                             "case at its axial speed and the fitted μ)")
    axial_speed_m_s: float | None = _f("m/s", "of a reaming (+, running in) or back-reaming "
                                              "(−) segment, the pipe's steady axial speed "
                                              "(median bit-depth rate while it moves)")
    bit_speed_resolved: bool | None = _f("", "whether a bit-speed trace is reported: the "
                                             "logging resolves the stick-slip cycle, the bit "
                                             "is off bottom and the trace passes the "
                                             "kinematic check")
    bit_speed_windows_withheld: int | None = _f("", "30-s windows of a trace shown whose bit "
                                                    "speed is withheld (null rows) by the "
                                                    "window-by-window kinematic check or "
                                                    "because it depends on an unidentified "
                                                    "μ_s (docs/bit_speed.md)")
    bit_speed_reason: str | None = _f("", "why the bit speed is not reported; of a trace "
                                          "shown with the pumps on and no motor declared, "
                                          "that it is the string's bottom speed")
    motor_rpm_mean: float | None = _f("RPM", "mean speed the declared mud motor adds to the "
                                             "BHA's over the turning rows (k·flow; on bottom "
                                             "less the half of its largest drop, "
                                             "docs/theory.md §2.4)")
    torque_lag_s: float | None = _f("s", "lag of the logged torque behind the speed the "
                                         "segment was corrected for (positive: the torque "
                                         "lags); null where not identified "
                                         "(docs/bit_speed.md, Channel skew)")
    torque_lag_uncertainty_s: float | None = _f("s", "95 % half-width of an identified "
                                                     "torque_lag_s (0: configured)")
    torque_lag_source: str | None = _f("", "config ([channels] lag_s), identified, or not "
                                           "identified (the reason in the message)")
    top_drive_inertia_share: float | None = _f("", "RMS of the inertia correction "
                                                   "I_TD·dω₀/dt against the RMS of the "
                                                   "torque's variation (docs/bit_speed.md, "
                                                   "Top-drive inertia); null for a string "
                                                   "torque")
    top_drive_inertia_kg_m2_identified: float | None = _f(
        "kg·m²", "top-drive inertia the segment's data identify (null: not identified)")
    top_drive_inertia_uncertainty_kg_m2: float | None = _f(
        "kg·m²", "95 % half-width of top_drive_inertia_kg_m2_identified")
    top_drive_inertia_source: str | None = _f(
        "", "not used (string torque), immaterial, confirmed, contradicted or not identified "
            "(the reason in the message)")
    k_t_identified_per_s: float | None = _f(
        "1/s", "apparent viscous damping rate the segment's steady set-points identify (the "
               "mud's damping and any rate dependence of the friction; μ_k is then corrected "
               "for it, docs/theory.md §6.4); null: not identified or not tried")
    k_t_identified_uncertainty_per_s: float | None = _f(
        "1/s", "95 % half-width of k_t_identified_per_s")
    sample_interval_s: float | None = _f("s", "effective interval of the log: the largest of "
                                              "the spacing, the averaging interval, the "
                                              "update interval of held values and the width "
                                              "of a moving average written at the full rate")
    samples_dropped: int | None = _f("", "speed or torque samples dropped before estimation "
                                         "as isolated spikes or drop-outs (EDR defects, "
                                         "docs/ingestion.md)")
    samples_held: int | None = _f("", "speed or torque samples that repeated an earlier "
                                      "reading for 1 s or more beyond chance (a device that "
                                      "stopped updating): left out of μ_k's cycle "
                                      "statistics, the bit trace's windows over them "
                                      "withheld (docs/ingestion.md)")
    interval_torque_swing: float | None = _f("-", "median (max − min)/|mean| of the torque "
                                                  "within each logged interval (min/max "
                                                  "channels; > 0.3: stick-slip)")
    clock_start_utc: str | None = _f("", "clock time of t_start_s (ISO 8601, UTC) when the log "
                                         "has absolute time")
    clock_end_utc: str | None = _f("", "clock time of t_end_s (ISO 8601, UTC)")
    wob_N: float | None = _f("N", "median weight on bit over the segment (on bottom)")
    rop_m_h: float | None = _f("m/h", "rate of penetration: advance of the hole depth over "
                                      "the segment (on bottom; null without hole depth)")
    surface_rpm_mean: float | None = _f("RPM", "mean top-drive speed over the rotation")
    surface_torque_turning_Nm: float | None = _f("N·m", "mean measured string torque while "
                                                        "the top drive turns (as "
                                                        "surface_torque_mean_Nm without the "
                                                        "torque held after the stop)")
    surface_torque_sem_Nm: float | None = _f("N·m", "standard error of "
                                                    "surface_torque_turning_Nm (10-s block "
                                                    "means)")
    torque_per_mu_Nm: float | None = _f("N·m", "on bottom: the model's mean string torque "
                                               "without bit torque is torque_fixed_Nm + "
                                               "μ_k·torque_per_mu_Nm (speed-driven model at "
                                               "the on-bottom load case, docs/theory.md §2.3)")
    torque_fixed_Nm: float | None = _f("N·m", "on bottom: the part of that model torque not "
                                              "proportional to μ_k (cased hole, viscous, "
                                              "start-up)")
    bit_torque_Nm: float | None = _f("N·m", "torque on bit T_bit = T_on − (μ_k·"
                                            "torque_per_mu_Nm + torque_fixed_Nm), "
                                            "μ_k from off-bottom rotation nearby: the "
                                            "bit's dissipative torque, its mean power over "
                                            "its mean speed (docs/theory.md §2.3 eq. 2.2d; "
                                            "null: bit_torque_reason)")
    bit_torque_uncertainty_Nm: float | None = _f("N·m", "95 % half-width of bit_torque_Nm "
                                                        "(μ_k's uncertainty and the torque "
                                                        "noise)")
    bit_torque_mu_k: float | None = _f("-", "the off-bottom μ_k the bit torque rests on")
    bit_torque_mu_k_uncertainty: float | None = _f("-", "95 % half-width of bit_torque_mu_k: "
                                                        "its validated tolerance (5 % logged "
                                                        "at ≤ 0.2 s, else 10 %) or its "
                                                        "members' scatter")
    bit_torque_evidence: tuple[int, ...] = _f("", "ids of the off-bottom segments "
                                                  "bit_torque_mu_k comes from", ())
    mu_bit: float | None = _f("-", "bit friction coefficient 3·T_bit/(WOB·D_bit) "
                                   "(well.bit_diameter_m)")
    mu_bit_uncertainty: float | None = _f("-", "95 % half-width of mu_bit (from T_bit's)")
    mse_Pa: float | None = _f("Pa", "downhole mechanical specific energy (Teale, with "
                                    "T_bit): WOB/A + 2π·N·T_bit/(A·ROP), N the bit's mean "
                                    "speed: the surface's plus motor_rpm_mean")
    mse_uncertainty_Pa: float | None = _f("Pa", "95 % half-width of mse_Pa (from T_bit's and a "
                                                "motor's speed drop)")
    bit_torque_reason: str | None = _f("", "why bit_torque_Nm, mu_bit or mse_Pa is null")
    mu_k_drift_per_h: float | None = _f("1/h", "linear trend of μ_k(t) over the segment's "
                                               "independent windows (docs/theory.md §6.6); "
                                               "the friction moved where the flag "
                                               "mu_k_drift says so")
    mu_k_first: float | None = _f("-", "μ_k of the segment's first window (μ_k(t), "
                                       "batch.trend_window_s)")
    mu_k_last: float | None = _f("-", "μ_k of the segment's last window")

    def to_json(self) -> dict:
        """Plain JSON values (enums as text, NaN as None), in field order."""
        return {k: _plain(v) for k, v in asdict(self).items()}

    @classmethod
    def from_json(cls, values: dict) -> SegmentRecord:
        """The record of a :meth:`to_json` (an engine state's, docs/api.md): enums and
        tuples restored; unknown keys are refused (ValueError)."""
        unknown = set(values) - set(SEGMENT_FIELDS)
        if unknown:
            raise ValueError(f"unknown segment fields {sorted(unknown)}")
        typed = dict(values)
        for name, enum in (("kind", Kind), ("status", Status), ("method", Method)):
            if name in typed:
                typed[name] = enum(typed[name])
        typed["quality_flags"] = tuple(Flag(f) for f in typed.get("quality_flags", ()))
        typed["starts"] = tuple(tuple(float(v) for v in s) for s in typed.get("starts", ()))
        typed["bit_torque_evidence"] = tuple(int(i) for i in
                                             typed.get("bit_torque_evidence", ()))
        return cls(**typed)


#: Field names of :class:`SegmentRecord` in output order.
SEGMENT_FIELDS: tuple[str, ...] = tuple(f.name for f in fields(SegmentRecord))
#: The binding keys of the interface (the first fields).
SEGMENT_KEYS: tuple[str, ...] = SEGMENT_FIELDS[:18]
#: List fields (Arrow lists in segments.parquet, Python lists in summary.json).
SEGMENT_LIST_FIELDS = ("quality_flags", "starts", "bit_torque_evidence")
#: Numeric fields (null is NaN in tables).
SEGMENT_NUMBER_FIELDS: tuple[str, ...] = tuple(
    f.name for f in fields(SegmentRecord) if f.type in ("float", "float | None"))


@dataclass(frozen=True)
class Column:
    """One column of ``estimates.parquet``: name (unit suffix), Arrow type, unit, meaning."""

    name: str
    type: str
    unit: str
    doc: str


#: Columns of estimates.parquet in order; ``timestamp`` only when the log has absolute
#: time, ``bit_rpm`` only when the input has the truth.
ESTIMATE_COLUMNS: tuple[Column, ...] = (
    Column("time_s", "float64", "s", "time of the row"),
    Column("timestamp", "timestamp[us, UTC]", "UTC", "clock time of time_s (only when the "
                                                     "log has absolute time)"),
    Column("segment_id", "int32", "", "segment id (segments.parquet)"),
    Column("start_id", "int16", "", "observer start (0…), −1 for the seeded ensemble pass"),
    Column("mu_s", "float64", "-", "μ̂_s of the start"),
    Column("mu_k", "float64", "-", "μ̂_k of the start; on the seeded rows μ_k(t) from the "
                                   "windowed re-fits of the mean torque (docs/theory.md §6.6): "
                                   "the level the windows agree on where the friction did not "
                                   "move, interpolated between window centres where it did; "
                                   "null where withheld (a change faster than the windows "
                                   "resolve, the ends of a drifting segment)"),
    Column("mu_k_half_width", "float64", "-", "95 % half-width of μ_k(t) (seeded rows)"),
    Column("surface_rpm", "float64", "RPM", "measured top-drive speed"),
    Column("surface_rpm_est", "float64", "RPM", "observer's top-drive speed"),
    Column("bit_rpm_est", "float64", "RPM", "estimated bit speed: the BHA's plus a declared "
                                            "mud motor's (docs/theory.md §2.4; null where "
                                            "the flow is missing while the pumps may run)"),
    Column("bha_rpm_est", "float64", "RPM", "estimated speed of the string's bottom (BHA, "
                                            "above a mud motor): bit_rpm_est without a "
                                            "declared motor"),
    Column("bit_stuck", "bool", "", "estimated bit in the static band (ω within ±ω_c: the "
                                    "BHA stuck and no declared motor turning); null "
                                    "where the bit speed is not resolved"),
    Column("residual_rpm", "float64", "RPM", "innovation ω̂₀ − ω₀"),
    Column("surface_torque_Nm", "float64", "N·m", "measured string torque at surface "
                                                  "(inertia-corrected motor torque)"),
    Column("surface_torque_est_Nm", "float64", "N·m", "the start's modelled string torque at "
                                                      "surface τ̂(0)"),
    Column("surface_torque_fit_Nm", "float64", "N·m", "the batch fit's model driven by the "
                                                      "measured speed, at the fitted factors"),
    Column("bit_rpm", "float64", "RPM", "measured bit speed (synthetic truth only)"),
    Column("bit_rpm_est_min", "float32", "RPM", "ensemble band: lowest member (seeded rows)"),
    Column("bit_rpm_est_max", "float32", "RPM", "ensemble band: highest member (seeded rows)"),
    Column("bha_rpm_est_min", "float32", "RPM", "the BHA's ensemble band: lowest member "
                                                "(seeded rows); the bit's band adds the "
                                                "motor's speed after its largest drop"),
    Column("bha_rpm_est_max", "float32", "RPM", "the BHA's ensemble band: highest member; "
                                                "the bit's band adds the motor's no-load "
                                                "speed"),
)
ESTIMATE_NAMES: tuple[str, ...] = tuple(c.name for c in ESTIMATE_COLUMNS)
#: ``start_id`` of the final observer pass seeded with the batch-refined factors.
SEEDED_START_ID = -1


#: Well-level columns of fleet_summary.parquet (before the segment fields).
FLEET_WELL_COLUMNS = ("well", "well_status", "well_message", "well_failed_segments",
                      "well_first_run", "well_new_segments", "well_changes", "result_dir",
                      "stale_result_dir", "well_mu_s", "well_mu_k", "well_mu_s_lower_bound",
                      "well_mu_apparent", "well_mu_apparent_segments", "well_mu_drag",
                      "well_mu_drag_connections", "drillfric_version", "segment_id")
#: Segment columns fleet_summary.parquet adds after the segment fields: the apparent μ of an
#: on-bottom segment, kept out of its ``mu_k`` (issue 35: one column mixed the two).
FLEET_SEGMENT_EXTRA = ("mu_apparent",)


def segment_is_apparent(row: dict) -> bool:
    """Whether a segment's μ (summary.json ``mu_k``) is apparent: on bottom, or flagged
    ``bit_torque_in_friction`` — the bit torque is in it."""
    flags = row.get("quality_flags")
    return row.get("kind") == Kind.ON_BOTTOM or (
        isinstance(flags, list | tuple) and Flag.BIT_TORQUE_IN_FRICTION in flags)


def well_friction_columns(summary: dict | None) -> dict:
    """The friction factors of a well besides its μ_k, as fleet_summary.parquet and
    fleet.html state them: the median apparent μ of its ok on-bottom segments (with their
    count) and the median drag-based μ of its connections (``drag.log`` ``mu_drag``, with
    their count); None where there are none."""
    summary = summary or {}
    apparent = [float(s["mu_k"]) for s in summary.get("segments") or []
                if s.get("status") == Status.OK and segment_is_apparent(s)
                and isinstance(s.get("mu_k"), int | float) and np.isfinite(s["mu_k"])]
    drag = [float(r["mu_drag"]) for r in ((summary.get("drag") or {}).get("log") or [])
            if isinstance(r, dict) and isinstance(r.get("mu_drag"), int | float)
            and np.isfinite(r["mu_drag"])]
    return {"well_mu_apparent": float(np.median(apparent)) if apparent else None,
            "well_mu_apparent_segments": len(apparent),
            "well_mu_drag": float(np.median(drag)) if drag else None,
            "well_mu_drag_connections": len(drag)}


def _plain(value):
    if isinstance(value, StrEnum):
        return value.value
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not np.isfinite(value):
        return None
    return value


def segment_columns(records) -> dict[str, list]:
    """segments.parquet as columns of plain values (list fields as lists)."""
    rows = [r.to_json() for r in records]
    return {name: [row[name] for row in rows] for name in SEGMENT_FIELDS}


def segment_arrow_types() -> dict[str, pa.DataType]:
    """Arrow type of every segments.parquet column (a column null in every row keeps its
    type): numbers float64, flags and counts as declared, text string, ``quality_flags``
    a list of strings, ``starts`` a list of (μ_s, μ_k) pairs and segment ids a list of
    ints."""
    kinds = {"float": "float64", "float | None": "float64", "int": "int32",
             "int | None": "int32", "bool": "bool",
             "bool | None": "bool", "tuple[Flag, ...]": "list<string>",
             "tuple[tuple[float, float], ...]": "list<list<float64>>",
             "tuple[int, ...]": "list<int32>"}
    return {f.name: _ARROW[kinds.get(f.type, "string")] for f in fields(SegmentRecord)}


def segment_table(records) -> pa.Table:
    """segments.parquet as an Arrow table with the schema's types (lists as Arrow lists)."""
    schema = pa.schema(list(segment_arrow_types().items()))
    return pa.table(segment_columns(records), schema=schema)


def segments_frame(records) -> pd.DataFrame:
    """The segments as pandas reads segments.parquet back: missing numbers NaN, lists as
    arrays (the same table from :func:`drillfric.api.run` and ``load_result``)."""
    return segment_table(records).to_pandas()


def segments_from_json(rows: list[dict]) -> pd.DataFrame:
    """summary.json's ``segments`` as :func:`segments_frame` gives them (missing numbers NaN);
    a key this version does not know is kept as it is."""
    frame = pd.DataFrame(rows)
    for name in SEGMENT_NUMBER_FIELDS:
        if name in frame:
            frame[name] = pd.to_numeric(frame[name], errors="coerce").astype(float)
    return frame


_ARROW = {"float64": pa.float64(), "int32": pa.int32(), "bool": pa.bool_(),
          "string": pa.string(), "list<string>": pa.list_(pa.string()),
          "list<list<float64>>": pa.list_(pa.list_(pa.float64())),
          "list<int32>": pa.list_(pa.int32())}


def _short(dotted: str) -> str:
    """A rule's dotted name without the package: ``estimation.verdict.decide``."""
    return dotted.removeprefix("drillfric.")


def outputs_markdown() -> str:
    """The column reference of docs/outputs.md, rendered from this schema."""
    lines = ["## segments (summary.json `segments`, segments.parquet)", "",
             "| field | unit | meaning |", "|---|---|---|"]
    lines += [f"| `{f.name}` | {f.metadata['unit']} | {f.metadata['doc']} |"
              for f in fields(SegmentRecord)]
    lines += ["", "## estimates.parquet", "", "| column | type | unit | meaning |",
              "|---|---|---|---|"]
    lines += [f"| `{c.name}` | {c.type} | {c.unit} | {c.doc} |" for c in ESTIMATE_COLUMNS]
    lines += ["", "## flags (segments' `quality_flags`)", "",
              "Each flag is raised by the rule named beside it (`drillfric.result."
              "FLAG_RAISED_BY`), a pure function of the evidence.", "",
              "| flag | meaning | raised by |", "|---|---|---|"]
    lines += [f"| `{f.value}` | {FLAG_MEANINGS[f]} | "
              f"{', '.join(f'`{_short(r)}`' for r in FLAG_RAISED_BY[f])} |" for f in Flag]
    lines += ["", "## well flags (summary.json `quality_flags`)", "", "| flag | meaning |",
              "|---|---|"]
    lines += [f"| `{f.value}` | {WELL_FLAG_MEANINGS[f]} |" for f in WellFlag]
    return "\n".join(lines) + "\n"


@dataclass(frozen=True)
class RunProgress:
    """Where a run stands (for a progress bar with an ETA).

    Attributes
    ----------
    rows_done : int
        Input rows read and, up to the last finished segment, estimated.
    rows_total : int or None
        Rows of the input when known cheaply (Parquet metadata, a CSV line count).
    segments_done : int
    """

    rows_done: int
    rows_total: int | None
    segments_done: int

    @property
    def fraction(self) -> float | None:
        """Share of the input done [-], None when the size is not known."""
        if not self.rows_total:
            return None
        return min(self.rows_done / self.rows_total, 1.0)


@dataclass(repr=False)
class WellResult:
    """What a run of one well produced (the API's return value; the CLI prints from it).

    Attributes
    ----------
    well : str
        The well's name.
    summary : dict
        summary.json (docs/outputs.md).
    segments : pandas.DataFrame
        One row per segment (:class:`SegmentRecord` fields).
    out_dir : Path or None
        ``OUT/NAME`` when results were written, else None.
    failed : int
        Segments whose estimation failed.
    warnings : list of str
        What the user should know (also ``summary["warnings"]``).
    tracks : pandas.DataFrame or None
        The whole log decimated for plotting (tracks.parquet).

    The headline numbers are typed properties read from ``summary``: :attr:`mu_k`,
    :attr:`mu_s`, :attr:`mu_s_lower_bound`, :attr:`counts`, :attr:`status`,
    :attr:`indicative`.
    """

    well: str
    summary: dict
    segments: pd.DataFrame
    out_dir: Path | None = None
    failed: int = 0
    warnings: list = field(default_factory=list)
    tracks: pd.DataFrame | None = field(default=None, repr=False)
    _estimates: pd.DataFrame | None = field(default=None, repr=False)

    @property
    def estimates(self) -> pd.DataFrame:
        """estimates.parquet's rows (read from ``out_dir`` when the run wrote them)."""
        if self._estimates is None and self.out_dir is not None:
            self._estimates = pd.read_parquet(self.out_dir / "estimates.parquet")
        return self._estimates if self._estimates is not None else pd.DataFrame(
            columns=list(ESTIMATE_NAMES))

    @property
    def report(self) -> Path | None:
        """report.html when it was written."""
        path = None if self.out_dir is None else self.out_dir / "report.html"
        return path if path is not None and path.is_file() else None

    # the headline numbers, typed, as summary.json has them (docs/outputs.md)
    @property
    def mu_k(self) -> float | None:
        """The well's kinetic friction factor [-] (median of the converged segments), None
        when no segment gives one."""
        return self.summary.get("mu_k")

    @property
    def mu_s(self) -> float | None:
        """The well's static friction factor [-], only where the data identify it."""
        return self.summary.get("mu_s")

    @property
    def mu_s_lower_bound(self) -> float | None:
        """A lower bound on μ_s [-] where it is only bounded (and ``mu_s`` is None)."""
        return self.summary.get("mu_s_lower_bound")

    @property
    def counts(self) -> dict[str, int]:
        """Segments: ``segments``, ``estimated``, ``converged``, ``skipped``, ``failed``."""
        return dict(self.summary.get("counts", {}))

    @property
    def indicative(self) -> bool:
        """Whether something was assumed (``summary["assumed"]``): the numbers are then
        indicative."""
        return bool(self.summary.get("indicative"))

    @property
    def status(self) -> str:
        """``"estimated"`` (a well μ_k), ``"not_estimated"`` (segments, none converged: no
        μ_k is claimed) or ``"no_segments"`` (no rotation found)."""
        if self.mu_k is not None:
            return "estimated"
        return "not_estimated" if self.counts.get("segments") else "no_segments"

    def __repr__(self) -> str:
        mu_s = (f"{self.mu_s:.3f}" if self.mu_s is not None else
                f"≥ {self.mu_s_lower_bound:.3f}" if self.mu_s_lower_bound is not None else "—")
        mu_k = "—" if self.mu_k is None else f"{self.mu_k:.3f}"
        c = self.counts
        where = "" if self.out_dir is None else f", out_dir='{self.out_dir}'"
        return (f"<WellResult {self.well!r}: {self.status}, μ_k {mu_k}, μ_s {mu_s}; "
                f"{c.get('segments', 0)} segment{'s' * (c.get('segments') != 1)} "
                f"({c.get('converged', 0)} converged, "
                f"{c.get('failed', 0)} failed); {len(self.warnings)} "
                f"warning{'s' * (len(self.warnings) != 1)}"
                f"{' (indicative)' * self.indicative}{where}>")
