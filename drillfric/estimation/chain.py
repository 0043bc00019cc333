"""Friction factors and bit speed of one rotating segment: a declared chain of named steps.

The chain of docs/theory.md §5–§6 for one segment at one bit depth (the shape of pvlib's
ModelChain: each step a function with typed inputs and outputs, :func:`estimate_segment`
only wires them):

0. :func:`drillfric.estimation.skew.correct` — the torque moved by its lag behind the speed,
   configured (``[channels] lag_s``) or identified from set-point steps, start-ups and stops
   (§5.3); a lag not identified leaves the torque as logged and withholds the trace (step 8);
1. :func:`build_models` — torque and drag at the bit depth gives F_c(x) (§2); the string,
   the measurements on a uniform grid, and the observer (a copy of the plant, §5);
2. :func:`starts_pass` — the adaptive observer from every configured start (plus the
   previous segment's estimates, the warm start) over the first ``observer.starts_window_s``:
   the online estimates, their spread and settling;
3. :func:`batch_fit` — the speed-driven fit (§6.4): μ_k by mean-torque matching, μ_s where a
   creep identifies it, or a lower bound from the stick-slip onset; of a reaming segment
   (estimated over the pipe's motion, :func:`while_moving`), :func:`moving_fit`: the fit with
   the friction split by the axial speed, within a fixed point on μ of the moving load
   case's F_c (§3.3), run before step 2;
4. :func:`drillfric.estimation.verdict.decide` — what may be claimed (pure rules);
5. :func:`seeded_pass` — the observer once more over the whole segment, seeded with the
   refined factors (held, not adapted, by default) as a small ensemble spread over the
   uncertainty of μ_s: the bit speed is the weighted ensemble mean, the members' min–max its
   band;
6. :func:`fit_evidence` — the fitted speed-driven model over the whole segment against the
   measured torque (run beside step 5);
7. :func:`bit_speed_resolution` — whether the logging resolves the stick-slip cycle;
8. :func:`trace_verdict` — the trace's checks and
   :func:`drillfric.estimation.verdict.decide_trace`, what of it may be shown (pure rules);
9. :func:`moving_friction` — μ_k(t) from windowed re-fits of the mean torque over the
   whole segment and the drift test (docs/theory.md §6.6, flag ``mu_k_drift``).

The estimate is built once from what the steps gave (``_assemble``): every flag and withheld
field comes from the two rule tables of :mod:`drillfric.estimation.verdict`. The steps take
the well's :class:`~drillfric.estimation.settings.ChainSettings`, never the configuration.
"""

from __future__ import annotations

import contextlib
import os
import threading
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field, replace

import numba
import numpy as np

from drillfric import torque_drag, torsional
from drillfric.drillstring import DrillString
from drillfric.errors import DrillfricError, ModelError
from drillfric.estimation import batch, bit_torque, bit_trace, damping, inertia, skew, spikes
from drillfric.estimation.batch.settings import TORQUE_SMOOTH_S, mu_k_tolerance
from drillfric.estimation.creep import smooth
from drillfric.estimation.diagnostics import Diagnostics, diagnose, settled_mask
from drillfric.estimation.friction_trend import FrictionTrend, drift_verdict, friction_trend
from drillfric.estimation.gains import design_gains
from drillfric.estimation.observer import (
    BitSpeedEstimate,
    Measurements,
    Observer,
    ObserverRecord,
    ObserverState,
    ensemble_bit_speed,
    observe,
)
from drillfric.estimation.sampling import LoggingInterval, Resolution, logging_interval, resolution
from drillfric.estimation.segment_data import SegmentData, SkipSegment, check_reach
from drillfric.estimation.settings import ChainSettings
from drillfric.estimation.torque_scale import check_torque_scale
from drillfric.estimation.verdict import (
    Evidence,
    TraceEvidence,
    TraceVerdict,
    Verdict,
    decide,
    decide_trace,
    withheld_factors,
)
from drillfric.friction import FrictionProfile
from drillfric.io.text import plural
from drillfric.io.timebase import find_gaps
from drillfric.result import Flag
from drillfric.units import RPM_TO_RAD_S
from drillfric.vocabulary import Kind, LoadCase, Method
from drillfric.wellpath import WellPath

#: Largest cell of the batch fit's model [m] (docs/theory.md §6.4).
BATCH_MAX_DX_M = 5.0


@dataclass(frozen=True)
class SegmentEstimate:
    """Estimates and diagnostics of one segment (a row of segments.parquet + traces).

    Attributes
    ----------
    mu_s, mu_k : float or None
        Reported friction factors [-] (μ_s only where identified).
    mu_s_identifiable : bool
    mu_s_lower_bound : float or None
    mu_s_spread, mu_k_spread : float or None
        Spread of the observer's starts [-].
    mu_k_damping : float or None
        Half-width of a batch μ_k from the viscous damping assumed [-]
        (:func:`~drillfric.estimation.batch.fit.damping_half_width`).
    converged : bool
    method : Method
    settling_time_s : float or None
    residual_rms_rpm : float
    stick_slip_severity : float
        Severity of the ensemble's members pooled with their weights [-].
    stuck_fraction : float
        Share of the time the pooled members' bit turns no faster than ω_c [-].
    stick_slip_from_s, stick_slip_to_s : float
        Both taken over this span [s] (:func:`statistics_from`, :func:`statistics_to`).
    mu_k_observer, mu_s_observer : float
        Observer consensus (first pass) [-].
    mu_td : float or None
        Static torque-and-drag back-calculated friction factor [-] (cross-check).
    T_N_Nm : float
        ∫F_c dx at this depth [N·m].
    flags : tuple of Flag
    messages : tuple of str
    starts : ndarray, shape (S, 2)
        Observer starts (μ_s, μ_k); the seeded final pass is start S.
    first, final : ObserverRecord
        Observer records of the first pass (all starts) and the seeded pass (one start per
        ensemble member, the seed first; :func:`drillfric.estimation.observer.ensemble_bit_speed`).
    mu_s_seed : float
        μ_s the seeded pass used (identified, else the batch model's regime value or bound);
        the next segment's warm start.
    bit : BitSpeedEstimate
        Bit speed of the seeded ensemble (weighted mean and band).
    bit_rms_error_rpm : float or None
        RMS error of the estimated bit speed when the truth is known [RPM].
    evidence : FitEvidence
        The fitted model's string torque against the measured one.
    bit_speed : Resolution
        Whether a bit-speed trace is reported: the logging resolves the stick-slip cycle,
        the bit is off bottom and the trace passes the kinematic check
        (:func:`drillfric.estimation.bit_trace.bit_speed_claim`); else the reason.
    kinematics : KinematicCheck
        The trace's kinematic check (docs/bit_speed.md).
    bit_windows_withheld : tuple of (float, float)
        [t_from_s, t_to_s) of the 30-s windows whose bit speed is withheld (window by
        window, docs/bit_speed.md) in a trace shown otherwise.
    bit_statistics : bool
        Whether the stuck fraction and the severity may be reported: the logging resolves
        the cycle, the bit is off bottom and the estimated severity is below
        :data:`~drillfric.estimation.bit_trace.SEVERITY_VALIDATED_BELOW` (they are validated
        within their tolerance also where the kinematic check withholds the trace,
        docs/bit_speed.md).
    logged : LoggingInterval
        The log's effective interval and, with min/max channels, the torque swing within it.
    torque_terms : TorqueTerms or None
        The mean speed, the mean torque's standard error and the modelled torque not
        proportional to μ_k (:func:`drillfric.estimation.bit_torque.torque_terms`).
    friction_zone : str
        Which factor μ is: "open_hole" (the cased part's factor given) or "effective"
        (torque-weighted over the whole string).
    samples_dropped : int
        Speed or torque samples dropped as isolated spikes or drop-outs.
    samples_held : int
        Speed or torque samples that held an earlier reading.
    factors_withheld : str
        Why the segment's friction factors are not shown ("" when they are:
        :func:`~drillfric.estimation.verdict.withheld_factors`).
    skew : Skew or None
        The torque's lag behind the speed the segment was corrected for, or why it is not
        identified (:func:`drillfric.estimation.skew.correct`).
    trend : FrictionTrend or None
        μ_k(t) of the windowed re-fits and the drift test (docs/theory.md §6.6); None where
        the segment's μ_k is not a converged batch value.
    inertia : Inertia or None
        What the data say of the top-drive inertia (:func:`top_drive_inertia`).
    viscous : ViscousSlope or None
        The viscous damping the set-points identify (:func:`viscous_damping`).
    """

    mu_s: float | None
    mu_k: float | None
    mu_s_identifiable: bool
    mu_s_lower_bound: float | None
    mu_s_spread: float | None
    mu_k_spread: float | None
    mu_k_damping: float | None
    converged: bool
    method: Method
    settling_time_s: float | None
    residual_rms_rpm: float
    stick_slip_severity: float
    stuck_fraction: float
    stick_slip_from_s: float
    stick_slip_to_s: float
    mu_k_observer: float
    mu_s_observer: float
    mu_td: float | None
    T_N_Nm: float
    flags: tuple
    messages: tuple
    starts: np.ndarray
    first: ObserverRecord = field(repr=False)
    final: ObserverRecord = field(repr=False)
    bit: BitSpeedEstimate | None = field(default=None, repr=False)
    bit_rms_error_rpm: float | None = None
    td: torque_drag.TDResult | None = field(default=None, repr=False)
    mu_s_seed: float | None = None
    evidence: FitEvidence | None = field(default=None, repr=False)
    bit_speed: Resolution | None = None
    kinematics: bit_trace.KinematicCheck | None = None
    bit_windows_withheld: tuple = ()
    bit_statistics: bool = False
    logged: LoggingInterval | None = None
    torque_terms: bit_torque.TorqueTerms | None = None
    friction_zone: str = "effective"
    samples_dropped: int = 0
    samples_held: int = 0
    factors_withheld: str = ""
    skew: skew.Skew | None = None
    trend: FrictionTrend | None = field(default=None, repr=False)
    inertia: inertia.Inertia | None = None
    viscous: damping.ViscousSlope | None = None


def _path_for(settings: ChainSettings, path: WellPath | None, bit_depth_m: float
              ) -> WellPath:
    """The survey's path, or without one the assumed tortuous vertical path to the bit."""
    if path is None:
        return settings.td.path_to(None, bit_depth_m)
    check_reach(path, bit_depth_m)
    return path


def build_observer(settings: ChainSettings, string, td: torque_drag.TDResult,
                   sample_dt_s: float | None = None, mu_s: float = 0.0,
                   mu_k: float = 0.0) -> Observer:
    """Observer for this string and F_c profile (docs/theory.md §5); ``sample_dt_s`` is the
    logging interval of the measurements [s]. With a cased zone of unknown static friction,
    (``mu_s``, ``mu_k``) tie it to the open hole's ratio (the observer's own μ̂ multiply the
    open hole's F_c only: docs/theory.md §3.2)."""
    grid = torsional.make_grid(string, settings.cells)
    batch_settings = settings.batch
    plant = settings.friction.plant(
        grid, td.fc_at(grid.x_m), mu_s, mu_k, omega_c_rad_s=batch_settings.omega_c_rad_s,
        k_t_per_s=batch_settings.k_t_per_s,
        top_drive_inertia_kg_m2=batch_settings.top_drive_inertia_kg_m2,
        cased_static="tied" if mu_k > 0 else "kinetic")
    n_pipe = int(grid.section_start[1])
    gains = design_gains(settings.gains, string, plant.T_N_Nm, grid.x_m[:n_pipe], grid.dt_s,
                         sample_dt_s)
    observer = settings.observer
    return Observer(plant, gains, law=observer.law, mu_max=observer.mu_max,
                    deadlock_s=observer.deadlock_s, hold=observer.interpolation == "hold")


def _starts(settings: ChainSettings, warm, mu_max) -> np.ndarray:
    starts = [list(s) for s in settings.observer.starts]
    if warm is not None and all(v is not None for v in warm):
        starts.append([max(warm[0], warm[1]), warm[1]])
    out = np.clip(np.asarray(starts, dtype=float), 0.0, mu_max)
    out[:, 0] = np.maximum(out[:, 0], out[:, 1])
    return out


def _batch_cells(settings: ChainSettings, bit_depth_m: float) -> int:
    """Cells of the speed-driven fit: ``model.cells``, refined to Δx ≤ 5 m (docs/theory.md §6.4:
    at 10 m the fit was biased by 10–14 %)."""
    return max(settings.cells, int(np.ceil(bit_depth_m / BATCH_MAX_DX_M)))


def ensemble_starts(mu_s: float, mu_k: float, members: int, spread: float,
                    mu_max: float) -> np.ndarray:
    """Ensemble of (μ_s, μ_k) for the final pass, the seed first [-].

    μ_s·(1 + δ) for δ evenly spaced over [−spread, +spread]; where μ_s ≥ μ_k or μ_s ≤ μ_max
    cuts that interval, the cut side is compressed into what is left (the seed keeps
    δ = 0), or, when one side is gone, the members spread over the other side alone.
    Members never coincide: fewer are returned when the interval is empty (spread 0, or
    μ_s = μ_k = μ_max).
    """
    low = max(-spread, mu_k / mu_s - 1.0) if mu_s > 0 else 0.0
    high = min(spread, mu_max / mu_s - 1.0) if mu_s > 0 else 0.0
    offsets = np.linspace(-spread, spread, members) if members > 1 else np.zeros(1)
    if low < 0.0 < high and spread > 0:
        offsets = np.where(offsets < 0, offsets * (-low / spread), offsets * (high / spread))
    else:
        offsets = np.linspace(low, high, members) if members > 1 else np.zeros(1)
    offsets = np.unique(np.round(offsets, 12))
    offsets = offsets[np.argsort(np.abs(offsets), kind="stable")]
    mu_s_members = np.clip(mu_s * (1.0 + offsets), mu_k, mu_max)
    return np.column_stack([mu_s_members, np.full(offsets.size, mu_k)])


def _final_pass(settings: ChainSettings, observer: Observer, meas: Measurements,
                mu_s: float, mu_k: float, *, adapt: bool, output_rate_hz: float
                ) -> ObserverRecord:
    """The observer over the whole segment from the refined factors, as an ensemble
    (``observer.ensemble_members``, ``observer.ensemble_spread``); μ̂ held unless ``adapt``."""
    if not adapt:
        observer = replace(observer, gains=replace(observer.gains, l_k=0.0, l_s=0.0))
    members = ensemble_starts(mu_s, mu_k, settings.observer.ensemble_members,
                              settings.observer.ensemble_spread, observer.mu_max)
    state = ObserverState.from_starts(observer, members, omega0_rad_s=meas.surface_rad_s[0],
                                      t_s=meas.t0_s, torque_top_Nm=_initial_torque(meas))
    final, _ = observe(observer, meas, state, output_rate_hz=output_rate_hz)
    check_bounded(final, meas)
    return final


def _initial_torque(meas: Measurements, span_s: float = 0.5) -> float:
    """Measured torque at the start of a segment [N·m] (median over ``span_s``: the twist the
    string holds when the segment starts from rest)."""
    n = max(1, int(round(span_s / meas.dt_s)))
    return float(np.median(meas.motor_torque_Nm[:n]))


def _open_hole_friction(profile: FrictionProfile):
    """μ → the torque-and-drag friction of the profile with μ in the open hole (None: one
    zone)."""
    if profile.zone != "open_hole":
        return None
    cased = (lambda mu: profile.ratio * mu) if profile.ratio is not None else (
        lambda mu: profile.cased_kinetic)
    return lambda mu: torque_drag.SectionFriction(profile.shoe_md_m, cased(mu), mu)


def _td_cross_check(models: SegmentModels, settings: ChainSettings) -> float | None:
    """Static friction factor from the mean rotating string torque (T&D back-calculation)."""
    meas, td = models.meas, settings.td
    if models.axial is not None:
        return None  # the back-calculation models the string turning in place
    rotating = np.abs(meas.surface_rad_s) > 2.0 * settings.omega_c_rad_s
    if rotating.sum() < 10:
        return None
    torque = batch.measured_string_torque(meas.time_s, meas.surface_rad_s,
                                          meas.motor_torque_Nm, "motor",
                                          settings.top_drive_inertia_kg_m2)
    try:
        return float(torque_drag.back_calculate_friction(
            models.path, models.string, surface_torque_Nm=float(np.mean(torque[rotating])),
            load_case="rotating_off_bottom", friction_of=_open_hole_friction(settings.friction),
            mud_out_kg_m3=td.mud_out_kg_m3, mud_in_kg_m3=td.mud_in_kg_m3,
            element_length_m=td.element_length_m))
    except DrillfricError:
        return None


#: Rotation left out after the top drive first exceeds ω_c when the fit's evidence is scored
#: [s]: a fixed start-up allowance for the misfit and swing shown beside a segment (the μ_k
#: fit itself leaves out each run's own start-up, docs/theory.md §6.4 "Start-up").
EVIDENCE_SKIP_S = 30.0


@dataclass(frozen=True)
class FitEvidence:
    """The fitted model against the data, the evidence beside a segment's numbers.

    Attributes
    ----------
    time_s, measured_Nm, model_Nm : ndarray
        The record's uniform time grid [s], measured and modelled string torque [N·m].
    misfit_rms_Nm : float or None
        RMS of the 1-s smoothed difference over the rotation after the start-up [N·m].
    swing_Nm : float or None
        5th–95th percentile swing of the measured torque there [N·m].
    mean_Nm : float or None
        Mean measured string torque there [N·m].
    scored : ndarray of bool or None
        The samples "there" (after the start-up); None when too few.
    """

    time_s: np.ndarray
    measured_Nm: np.ndarray
    model_Nm: np.ndarray
    misfit_rms_Nm: float | None
    swing_Nm: float | None
    mean_Nm: float | None
    scored: np.ndarray | None = None

    @property
    def quality(self) -> float | None:
        """Misfit relative to the swing [-] (None without rotation)."""
        if self.misfit_rms_Nm is None or not self.swing_Nm:
            return None
        return self.misfit_rms_Nm / self.swing_Nm


@dataclass(frozen=True)
class SegmentModels:
    """What every estimator of one segment shares (step 1).

    Attributes
    ----------
    path : WellPath
        The survey's path, or the assumed tortuous vertical one.
    string : DrillString
        The string at the segment's bit depth.
    td : TDResult
        Torque and drag at that depth for the segment's load case (F_c, T_N).
    meas : Measurements
        Top-drive speed and motor torque on a uniform grid.
    observer : Observer
        The observer (plant copy and gains) for this string and F_c.
    on_bottom : bool
    logged : LoggingInterval
        The log's effective sample interval (docs/bit_speed.md "Logging rate").
    sample_times_s : ndarray
        Times of the logged samples the measurements rest on [s]: the segment's, without
        the EDR defects :mod:`drillfric.estimation.spikes` dropped and without the held
        values (the bit's motion over them was not observed).
    dropped : int
        How many samples were so dropped.
    held : int
        How many samples held an earlier reading (:func:`~drillfric.estimation.spikes.held_values`).
    held_spans_s : tuple of (float, float)
        [s] From the last real reading before each run of held samples to the first after
        it: the batch fit's torque statistics leave them out.
    axial : drillfric.torsional.Axial or None
        The pipe's axial speed on the measurements' grid while it reams (None: in place).
    """

    path: WellPath
    string: DrillString
    td: torque_drag.TDResult
    meas: Measurements
    observer: Observer
    on_bottom: bool
    logged: LoggingInterval
    sample_times_s: np.ndarray = field(repr=False)
    dropped: int = 0
    axial: torsional.Axial | None = field(default=None, repr=False)
    held: int = 0
    held_spans_s: tuple = ()


def build_models(settings: ChainSettings, path: WellPath | None, data: SegmentData, *,
                 rate_hz: float | None = None, torque_channel=None,
                 mu_moving: float | None = None) -> SegmentModels:
    """Step 1: string, torque and drag, measurements and observer of one segment.

    A reaming segment (``data.axial_speed_m_s`` ≠ 0) takes the moving load case —
    ``rotating_slack_off`` running in, ``rotating_pick_up`` pulling out — at its |v| and
    median RPM (docs/theory.md §2 steps 3–4): F_c then depends on μ through the axial share
    of the drag, solved at ``mu_moving`` (default: the configured factor; :func:`moving_fit`
    iterates it), and the models get v(t) (:func:`axial_series`).

    Raises
    ------
    SkipSegment
        No side force (vertical hole): friction does not act on the torque.
    DrillfricError
        Survey above the bit, or an implausible torque scale (wrong unit).
    """
    fix = "give the well's survey" + (
        "" if path is not None else " (or a nominal survey.tortuosity_deg_30m > 0)")
    path = _path_for(settings, path, data.bit_depth_m)
    on_bottom = data.kind == Kind.ON_BOTTOM
    if data.axial_speed_m_s:
        td = settings.td.solve(path, data.bit_depth_m, **_moving_case(settings, data,
                                                                      mu_moving))
    else:
        td = settings.td.solve(path, data.bit_depth_m, wob_N=data.wob_N,
                               load_case=LoadCase.ROTATING_ON_BOTTOM if on_bottom
                               else LoadCase.ROTATING_OFF_BOTTOM)
    if td.T_N_Nm < 1.0:
        raise SkipSegment(f"no side force on the string at {data.bit_depth_m:.0f} m (T_N = "
                          f"{td.T_N_Nm:.2g} N·m: vertical hole), friction does not act on the "
                          "torque", fix=fix)
    check_torque_scale(data, td.T_N_Nm, settings.omega_c_rad_s, torque_channel=torque_channel)
    string = settings.td.string(data.bit_depth_m)
    bad = spikes.defects(data.time_s, 4.0 * bit_trace.travel_time_s(string), data.surface_rpm,
                         data.surface_torque_Nm, settings.top_drive_inertia_kg_m2)
    data = _without(data, bad)
    meas = Measurements.from_samples(
        data.time_s, data.surface_rpm * RPM_TO_RAD_S, data.surface_torque_Nm,
        torque_kind=settings.torque_kind,
        top_drive_inertia_kg_m2=settings.top_drive_inertia_kg_m2, rate_hz=rate_hz)
    observer = build_observer(settings, string, td, sample_dt_s=meas.dt_s)
    logged = logging_interval(data.time_s, data.surface_rpm, data.surface_torque_Nm,
                              averaging_s=settings.sample_averaging_s, model_dt_s=meas.dt_s,
                              torque_min_Nm=data.torque_min_Nm,
                              torque_max_Nm=data.torque_max_Nm,
                              echo_s=2.0 * bit_trace.travel_time_s(string))
    held = (spikes.held_values(data.time_s, data.surface_rpm)
            | spikes.held_values(data.time_s, data.surface_torque_Nm))
    return SegmentModels(path, string, td, meas, observer, on_bottom, logged,
                         data.time_s[~held], int(bad.sum()), axial_series(data, meas),
                         int(held.sum()), spikes.spans_s(data.time_s, held))


def _moving_case(settings: ChainSettings, data: SegmentData, mu: float | None) -> dict:
    """Torque-and-drag arguments of a reaming segment's moving load case at μ (None: the
    configured friction): |v| and the median top-drive RPM while the pipe moves."""
    t0, t1 = data.axial_span_s or (data.time_s[0], data.time_s[-1])
    inside = (data.time_s >= t0) & (data.time_s <= t1)
    rpm = float(np.median(np.abs(data.surface_rpm[inside] if inside.any()
                                 else data.surface_rpm)))
    case = LoadCase.ROTATING_SLACK_OFF if data.axial_speed_m_s > 0 else \
        LoadCase.ROTATING_PICK_UP
    friction = None
    if mu is not None:
        friction = _open_hole_friction(settings.friction)
        friction = friction(mu) if friction is not None else mu
    return dict(load_case=case, axial_speed_m_s=abs(data.axial_speed_m_s), rpm=rpm,
                friction=friction)


def while_moving(data: SegmentData) -> SegmentData:
    """A reaming segment's samples while the pipe moves at its speed (``axial_span_s``): the
    moving load case's F_c holds there only — before and after, the string turns in place
    with the rotating case's (a run of the fit has one F_c). Other segments unchanged."""
    if not data.axial_speed_m_s or data.axial_span_s is None:
        return data
    t0, t1 = data.axial_span_s
    outside = (data.time_s < t0) | (data.time_s > t1)
    return _without(data, outside) if (~outside).sum() >= 20 else data


def axial_series(data: SegmentData, meas: Measurements) -> torsional.Axial | None:
    """A reaming segment's axial speed on the measurements' grid: v within
    ``data.axial_span_s``, 0 outside it (the block's short ramps cut at their middle by
    :func:`drillfric.segmentation.axial_motion`); None in place."""
    if not data.axial_speed_m_s:
        return None
    t = meas.time_s
    t0, t1 = data.axial_span_s or (t[0], t[-1])
    v = np.where((t >= t0 - 0.5 * meas.dt_s) & (t <= t1 + 0.5 * meas.dt_s),
                 data.axial_speed_m_s, 0.0)
    return torsional.Axial(v, meas.dt_s, meas.t0_s)


def _without(data: SegmentData, drop: np.ndarray) -> SegmentData:
    """``data`` without the samples where ``drop`` is true (every per-sample array)."""
    if not drop.any():
        return data
    keep = ~drop
    return replace(data, **{name: getattr(data, name)[keep] for name in (
        "time_s", "surface_rpm", "surface_torque_Nm", "bit_rpm", "torque_min_Nm",
        "torque_max_Nm") if getattr(data, name) is not None})


def starts_pass(settings: ChainSettings, models: SegmentModels, warm: tuple | None,
                output_rate_hz: float) -> tuple[np.ndarray, ObserverRecord, Diagnostics]:
    """Step 2: the observer from every start over ``observer.starts_window_s``; returns the
    starts (μ_s, μ_k), their record and its diagnostics."""
    meas, observer = models.meas, models.observer
    starts = _starts(settings, warm, observer.mu_max)
    state = ObserverState.from_starts(observer, starts, omega0_rad_s=meas.surface_rad_s[0],
                                      t_s=meas.t0_s, torque_top_Nm=_initial_torque(meas))
    window_end = min(meas.t_end_s, meas.t0_s + settings.observer.starts_window_s)
    first, _ = observe(observer, meas, state, output_rate_hz=output_rate_hz,
                       t_end_s=window_end)
    check_bounded(first, meas)
    return starts, first, diagnose(first, settings.omega_c_rad_s)


#: How far the observer's surface-speed estimate may stray beyond the logged speed before
#: it is taken as diverged: the innovation e = ω̂₀ − ω₀ is driven to 0 (docs/theory.md §5),
#: so a bounded, tracking observer stays within a few times the speed it is fed.
DIVERGED_FACTOR, DIVERGED_FLOOR_RAD_S = 10.0, 50.0


def check_bounded(record: ObserverRecord, meas: Measurements) -> None:
    """ModelError when the observer diverged: its estimates not finite, or its surface speed
    beyond :data:`DIVERGED_FACTOR` × the largest logged speed (a top-drive inertia of 10⁻⁶
    kg·m², inside the key's range, drove ω̂₀ to 10¹² and still printed a μ_k)."""
    bound = DIVERGED_FACTOR * float(np.nanmax(np.abs(meas.surface_rad_s))) + \
        DIVERGED_FLOOR_RAD_S
    speeds = (record.surface_rad_s_est, record.bit_rad_s_est)
    if not all(np.isfinite(x).all() and np.abs(x).max(initial=0.0) <= bound for x in speeds):
        raise ModelError("the observer diverged (its speed estimates ran past ten times the "
                         "logged speed): its model of this rig cannot follow the log",
                         fix="check [rig] top_drive_inertia_kg_m2 and [model] k_t_per_s, and "
                             "that the torque and speed channels are the top drive's")


def batch_fit(settings: ChainSettings, models: SegmentModels) -> batch.BatchResult:
    """Step 3: the speed-driven fit over the first ``batch.window_s`` (docs/theory.md §6.4)."""
    meas = models.meas
    n_fit = min(meas.surface_rad_s.size, int(settings.batch.window_s / meas.dt_s) + 1)
    return batch.refine(meas.time_s[:n_fit], meas.surface_rad_s[:n_fit],
                        meas.motor_torque_Nm[:n_fit], string=models.string,
                        fc_Nm_m=models.td.fc_at, settings=settings.batch, torque_kind="motor",
                        cells=_batch_cells(settings, models.string.bit_depth_m),
                        profile=settings.friction, sample_interval_s=models.logged.interval_s,
                        axial=models.axial, unobserved_s=models.held_spans_s)


#: Passes of the moving load case's fixed point (docs/theory.md §3.3): F_c at μ, fit μ_k,
#: F_c again at it; the fitted μ_k moves by a few % at most after the second pass.
MOVING_PASSES = 3
#: The fixed point stops once μ_k moves by less than this between passes [-].
MOVING_TOLERANCE = 0.005


def moving_fit(settings: ChainSettings, path: WellPath | None, data: SegmentData,
               models: SegmentModels, rate_hz: float | None, torque_channel
               ) -> tuple[SegmentModels, batch.BatchResult, str]:
    """Step 3 of a reaming segment: the batch fit within a fixed point on μ.

    While the pipe moves, F_c depends on μ through the axial share of the drag (the tension;
    docs/theory.md §2 steps 3–4, §3.3): torque and drag at a μ guess (the configured
    factor), fit μ_k, solve again at it and refit — at most :data:`MOVING_PASSES` fits,
    stopping once μ_k moves by less than :data:`MOVING_TOLERANCE`. Returns the models and
    fit of the last pass and the sentence that states it."""
    refined, trail = batch_fit(settings, models), []
    for _ in range(MOVING_PASSES - 1):
        if refined.mu_k is None:
            break
        trail.append(refined.mu_k)
        models = build_models(settings, path, data, rate_hz=rate_hz,
                              torque_channel=torque_channel, mu_moving=refined.mu_k)
        refined = batch_fit(settings, models)
        if refined.mu_k is None or abs(refined.mu_k / trail[-1] - 1.0) < MOVING_TOLERANCE:
            break
    way = "reaming (rotating slack-off)" if data.axial_speed_m_s > 0 else \
        "back-reaming (rotating pick-up)"
    passes = " → ".join(f"{m:.3f}" for m in trail + ([refined.mu_k] if refined.mu_k else []))
    note = (f"{way} at {abs(data.axial_speed_m_s):.2g} m/s: F_c of the moving load case, "
            "the model splitting each cell's friction between torque and drag (docs/theory.md "
            "§3.3); F_c depends on μ through the drag, solved as a fixed point "
            f"({passes or 'no μ_k'})")
    return models, refined, note


def evidence(settings: ChainSettings, models: SegmentModels, diag: Diagnostics,
             refined: batch.BatchResult) -> Evidence:
    """What steps 2 and 3 found, for :func:`~drillfric.estimation.verdict.decide`."""
    meas = models.meas
    turning_s = float(np.sum(np.abs(meas.surface_rad_s) > settings.omega_c_rad_s) * meas.dt_s)
    return Evidence(batch_mu_k=refined.mu_k, batch_flags=tuple(refined.flags),
                    batch_messages=tuple(refined.messages),
                    mu_s_lower_bound=refined.mu_s_lower_bound,
                    mu_s_model=refined.details.mu_s_model, mu_s=refined.mu_s,
                    observer_mu_k=diag.mu_k, observer_converged=diag.converged,
                    observer_flags=tuple(Flag(f"observer_{f}") for f in diag.flags),
                    turning_s=turning_s, on_bottom=models.on_bottom,
                    batch_mu_k_sigma=refined.details.mu_k_sigma,
                    axial_speed_m_s=_axial_speed(models))


def _axial_speed(models: SegmentModels) -> float:
    """The pipe's axial speed while it moves [m/s] (0 in place)."""
    if models.axial is None:
        return 0.0
    v = np.asarray(models.axial.values)
    return float(v[np.flatnonzero(v)[0]])


def seeded_pass(settings: ChainSettings, models: SegmentModels, verdict: Verdict,
                output_rate_hz: float) -> tuple[ObserverRecord, BitSpeedEstimate]:
    """Step 5: the ensemble seeded with the verdict's factors over the whole segment, and
    the bit speed it gives (weighted mean and band)."""
    observer = models.observer
    if not settings.friction.static_known:  # tie the cased μ_s to the seed
        observer = replace(observer, plant=build_observer(
            settings, models.string, models.td, models.meas.dt_s, verdict.mu_s_seed,
            verdict.mu_k).plant)
    final = _final_pass(settings, observer, models.meas, verdict.mu_s_seed, verdict.mu_k,
                        adapt=verdict.adapt_final or settings.observer.adapt_final,
                        output_rate_hz=output_rate_hz)
    bit = ensemble_bit_speed(final, _memory_s(observer, models.meas),
                             settings.speed_noise_rad_s)
    return final, bit


def fit_evidence(settings: ChainSettings, models: SegmentModels, verdict: Verdict,
                 mu_s: float | None) -> FitEvidence:
    """Step 6: the fitted speed-driven model over the whole segment against the measured
    string torque, with its misfit relative to the torque swing."""
    meas = models.meas
    t, measured, model = batch.model_string_torque(
        meas.time_s, meas.surface_rad_s, meas.motor_torque_Nm, string=models.string,
        fc_Nm_m=models.td.fc_at, settings=settings.batch,
        mu_s=mu_s if mu_s is not None else verdict.mu_s_seed, mu_k=verdict.mu_k,
        cells=_batch_cells(settings, models.string.bit_depth_m), profile=settings.friction,
        axial=models.axial)
    fast = np.flatnonzero(np.abs(meas.surface_rad_s) > settings.omega_c_rad_s)
    scored = t >= (t[fast[0]] + EVIDENCE_SKIP_S if fast.size else np.inf)
    if scored.sum() < 10:
        return FitEvidence(t, measured, model, None, None, None)
    dt = float(t[1] - t[0]) if t.size > 1 else 1.0
    misfit = smooth(measured - model, dt, TORQUE_SMOOTH_S)[scored]
    low, high = np.percentile(measured[scored], [5.0, 95.0])
    return FitEvidence(t, measured, model, float(np.sqrt(np.mean(misfit ** 2))),
                       float(high - low), float(np.mean(measured[scored])), scored)


def _model_at(settings: ChainSettings, models: SegmentModels, verdict: Verdict, mu_s: float | None):
    """(μ-scale, bit torque [N·m]) → the evidence's model string torque at (scale·μ_s,
    scale·μ_k) with that Coulomb bit [N·m] (the torque line of
    :func:`drillfric.estimation.bit_torque.torque_terms`)."""
    meas = models.meas
    mu_s = mu_s if mu_s is not None else verdict.mu_s_seed

    def model_at(scale: float, bit_Nm: float = 0.0) -> np.ndarray:
        return batch.model_string_torque(
            meas.time_s, meas.surface_rad_s, meas.motor_torque_Nm, string=models.string,
            fc_Nm_m=models.td.fc_at, settings=settings.batch, mu_s=scale * mu_s,
            mu_k=scale * verdict.mu_k, cells=_batch_cells(settings, models.string.bit_depth_m),
            profile=settings.friction, bit_torque_Nm=bit_Nm, axial=models.axial)[2]
    return model_at


def bit_speed_resolution(models: SegmentModels) -> Resolution:
    """Step 7: does the logging resolve the stick-slip cycle? The shortest cycle is the
    string's first torsional period, 4 × the wave travel time to the free bit (docs/theory.md
    §3), against the log's effective interval (:mod:`drillfric.estimation.sampling`)."""
    return resolution(models.logged, 4.0 * models.observer.plant.grid.travel_time_s)


def estimate_segment(settings: ChainSettings, path: WellPath | None, data: SegmentData, *,
                     warm: tuple | None = None, rate_hz: float | None = None,
                     output_rate_hz: float | None = None, progress=None,
                     torque_channel=None) -> SegmentEstimate:
    """Estimate μ_s, μ_k and the bit speed of one rotating segment: the chain of steps.

    Parameters
    ----------
    settings : ChainSettings
        The well's settings (:meth:`ChainSettings.from_config`, built once per well).
    path : WellPath or None
        Well path; None: no survey, a vertical hole with the nominal tortuosity
        ``survey.tortuosity_deg_30m`` (exactly vertical when it is 0).
    data : SegmentData
    warm : (μ_s, μ_k), optional
        Previous segment's estimates, added as a start (warm start across windows).
    rate_hz : float, optional
        Resample the input to this rate first (``run --rate``).
    output_rate_hz : float, optional
        Rate of the observer records (default ``observer.output_rate_hz``).
    progress : callable, optional
        Called with a fraction of the segment's work as it advances.
    torque_channel : drillfric.io.channels.Mapping, optional
        How the torque channel was read, for the advice of :func:`check_torque_scale`.

    Raises
    ------
    SkipSegment
        No side force (vertical hole): friction does not act on the torque.
    DrillfricError
        The segment cannot be estimated (survey above the bit, implausible torque scale).
    """
    tick = progress or (lambda amount: None)
    out_rate = output_rate_hz or settings.observer.output_rate_hz
    data, skewed = skew.correct(data, settings.torque_lag_s)
    data = while_moving(data)
    models = build_models(settings, path, data, rate_hz=rate_hz, torque_channel=torque_channel)
    moving_note = ()
    if models.axial is not None:  # the fixed point on μ first: the observer takes its F_c
        models, refined, note = moving_fit(settings, path, data, models, rate_hz,
                                           torque_channel)
        moving_note = (note,)
    starts, first, diag = starts_pass(settings, models, warm, out_rate)
    tick(0.3)
    if models.axial is None:
        refined = batch_fit(settings, models)
    tick(0.5)
    verdict = decide(evidence(settings, models, diag, refined))
    verdict = replace(verdict, messages=moving_note + verdict.messages)
    fitted_result = beside(fit_evidence, settings, models, verdict, refined.mu_s)
    final, bit = seeded_pass(settings, models, verdict, out_rate)
    tick(0.2)
    fitted = fitted_result()
    rig = top_drive_inertia(settings, models, fitted)
    trace, kinematics, (stats_from, stats_to) = trace_verdict(settings, models, refined,
                                                              verdict, final, bit, skewed, rig)
    viscous = viscous_damping(settings, models, verdict, fitted)
    fitted, verdict, refined = with_damping(settings, models, verdict, refined, fitted, viscous)
    terms = bit_torque.torque_terms(models.meas, fitted, _model_at(settings, models, verdict,
                                                                 refined.mu_s)
                                    if models.on_bottom else None, verdict.mu_k)
    trend = moving_friction(settings, models, verdict, fitted)
    estimate = _assemble(settings, models, data, Steps(starts, first, diag, refined, verdict,
                                                       trace, final, bit, fitted, terms,
                                                       kinematics, stats_from, trend,
                                                       stats_to))
    return replace(estimate, skew=skewed, inertia=rig, viscous=viscous)


def viscous_damping(settings: ChainSettings, models: SegmentModels, verdict: Verdict,
                    fitted: FitEvidence) -> damping.ViscousSlope | None:
    """Step 7b: the viscous damping a segment's steady set-points identify (docs/theory.md
    §6.4 "The damping identified", eq. 6.4k), from the fitted model's torque of step 6 (no
    model run of its own); None where there is no converged batch μ_k off bottom in place."""
    if (verdict.method is not Method.BATCH or not verdict.converged or fitted.scored is None
            or models.on_bottom or models.axial is not None):
        return None
    usable = fitted.scored.copy()
    for a, b in models.held_spans_s:
        usable &= (fitted.time_s < a) | (fitted.time_s > b)
    speed = np.interp(fitted.time_s, models.meas.time_s, models.meas.surface_rad_s)
    return damping.identify(fitted.time_s, fitted.measured_Nm, fitted.model_Nm, speed, usable,
                            inertia_kg_m2=models.string.polar_mass_moment_kg_m2,
                            k_t_per_s=settings.batch.k_t_per_s)


def with_damping(settings: ChainSettings, models: SegmentModels, verdict: Verdict,
                 refined: batch.BatchResult, fitted: FitEvidence,
                 viscous: damping.ViscousSlope | None
                 ) -> tuple[FitEvidence, Verdict, batch.BatchResult]:
    """The evidence, verdict and fit with an identified damping in place of the configured
    one (eq. 6.4k): the model's torque gains Δk·J·ω(t), μ_k loses Δk·J·ω̄_B/T_N (ω̄_B the
    top drive's mean speed over the batch window the fit matched), and μ_k's interval
    carries the identified damping's half-width instead of the assumed range."""
    if viscous is None or not viscous.identified:
        return fitted, verdict, refined
    J = models.string.polar_mass_moment_kg_m2
    delta = (viscous.k_t_per_s - settings.batch.k_t_per_s) * J  # [N·m·s/rad]
    speed = np.abs(np.interp(fitted.time_s, models.meas.time_s, models.meas.surface_rad_s))
    window = fitted.scored & (fitted.time_s <= models.meas.t0_s + settings.batch.window_s)
    mean_speed = float(np.mean(speed[window])) if window.any() else float(np.mean(speed))
    T_N = models.observer.plant.T_N_Nm
    mu_k = verdict.mu_k - delta * mean_speed / T_N
    spread = viscous.uncertainty_per_s * J * mean_speed / T_N
    details = replace(refined.details, mu_k_damping=spread)
    note = refined.interval_note
    if note is not None:
        sigma = 2.0 * (refined.details.mu_k_sigma or 0.0)
        tolerance = mu_k_tolerance(models.logged.interval_s)
        half = max(sigma, float(np.hypot(tolerance * mu_k, spread)))
        note = (f"μ_k = {mu_k:.3f} ± {half:.3f} (95 %: the validated {100 * tolerance:.0f} % "
                f"of this logging and ±{spread:.3f} for the viscous damping identified; "
                f"statistical 2σ ± {sigma:.3f}) — {verdict.mu_k:.3f} at the configured "
                f"k_t = {settings.batch.k_t_per_s:g} 1/s, less {delta * mean_speed:.0f} N·m "
                "of viscous torque the set-points show")
    fitted = replace(fitted, model_Nm=fitted.model_Nm + delta * speed)
    return (fitted, replace(verdict, mu_k=mu_k, messages=verdict.messages + (viscous.note,)),
            replace(refined, mu_k=mu_k, details=details, interval_note=note))


def moving_friction(settings: ChainSettings, models: SegmentModels, verdict: Verdict,
                    fitted: FitEvidence) -> FrictionTrend | None:
    """Step 9: μ_k(t) of windowed re-fits over the whole segment and the drift test
    (docs/theory.md §6.6), from the fitted model's torque of step 6 (no model run of its
    own); None where the batch μ_k is not converged over its window (nothing to move from).
    The seeded trace's checks do not enter: a trace that runs away from a constant μ_k is
    what a drift makes."""
    if verdict.method is not Method.BATCH or not verdict.converged or fitted.scored is None:
        return None
    meas = models.meas
    speed = np.interp(fitted.time_s, meas.time_s, np.abs(meas.surface_rad_s))
    fast = np.flatnonzero(speed > settings.omega_c_rad_s)
    if fast.size == 0:
        return None
    usable = fitted.scored & (fitted.time_s <= fitted.time_s[fast[-1]])
    for a, b in models.held_spans_s:  # held readings: not evidence of the friction (§6.6)
        usable &= (fitted.time_s < a) | (fitted.time_s > b)
    trend = friction_trend(fitted.time_s, fitted.measured_Nm, fitted.model_Nm, usable,
                           mu_k=verdict.mu_k, T_N_Nm=models.observer.plant.T_N_Nm,
                           tolerance=mu_k_tolerance(models.logged.interval_s),
                           window_s=settings.batch.trend_window_s,
                           anchor_end_s=meas.t0_s + settings.batch.window_s)
    # on bottom μ_k(t) is the apparent friction: a change of the bit torque (the WOB) moves
    # it as friction would, so it is not called a drift of the friction (§6.6)
    return replace(trend, drift=False) if models.on_bottom else trend


def trace_verdict(settings: ChainSettings, models: SegmentModels, refined: batch.BatchResult,
                  verdict: Verdict, final: ObserverRecord, bit: BitSpeedEstimate,
                  skewed: skew.Skew | None = None, rig: inertia.Inertia | None = None
                  ) -> tuple[TraceVerdict, bit_trace.KinematicCheck, tuple[float, float]]:
    """Step 8: the checks of the seeded trace (whole-segment kinematics, window by window,
    the members' statistics) and what of it the rules of
    :func:`~drillfric.estimation.verdict.decide_trace` show (``skewed``: the channels'
    timing, :func:`drillfric.estimation.skew.correct`); with the span over which the
    stuck fraction and severity are taken [s] (:func:`statistics_from`,
    :func:`statistics_to`)."""
    kinematics = bit_trace.check_segment_trace(models.string, models.meas, final.time_s,
                                               bit.rad_s, settings.speed_noise_rad_s)
    unknown = _unknown_spans(models, refined, final.time_s)
    windows = _windows(settings, models, final.time_s, bit.rad_s, unknown)
    late = settled_mask(final.time_s)
    settled = final.time_s[late]
    runaway = bit_trace.runs_away(kinematics, float(settled[-1] - settled[0])
                                  if settled.size > 1 else 0.0)
    start = statistics_from(final.time_s, unknown, windows.withheld)
    end = statistics_to(models.meas.time_s, models.meas.surface_rad_s, start)
    span = (final.time_s >= start) & (final.time_s <= end)
    severity = bit_trace.mixture_severity(final.bit_rad_s_est[span], bit.weights[span])
    trace = decide_trace(TraceEvidence(
        logging=bit_speed_resolution(models), on_bottom=models.on_bottom, check=kinematics,
        windows=windows, converged=verdict.converged,
        runaway_note=_runaway_note(verdict.mu_k, kinematics) if runaway else None,
        severe_note=bit_trace.statistics_note(severity),
        undetermined_note=_undetermined(final, bit, span, windows, severity, settings,
                                        refined.mu_s is not None),
        moving=models.axial is not None,
        skew_note=None if skewed is None or skewed.known else skewed.reason,
        inertia_note=None if rig is None else rig.reason,
        inertia_contradicted=rig is not None and rig.source == "contradicted"))
    return trace, kinematics, (start, end)


def top_drive_inertia(settings: ChainSettings, models: SegmentModels,
                      fitted: FitEvidence) -> inertia.Inertia:
    """Step 7b: what the segment's data say of the top-drive inertia the motor torque is
    corrected with, from the fitted model's string torque of step 6 (no model run of its
    own; :func:`drillfric.estimation.inertia.assess`, docs/theory.md §5.4)."""
    meas = models.meas
    return inertia.assess(fitted.time_s, np.interp(fitted.time_s, meas.time_s,
                                                   meas.surface_rad_s),
                          np.interp(fitted.time_s, meas.time_s, meas.motor_torque_Nm),
                          fitted.model_Nm, settings.top_drive_inertia_kg_m2,
                          settings.torque_kind)


def statistics_from(time_s: np.ndarray, unknown: tuple, withheld: tuple = ()) -> float:
    """Time from which the stuck fraction and severity are taken [s]: after the start-up
    (:func:`~drillfric.estimation.diagnostics.settled_mask`) and after every span whose bit
    speed depends on a μ_s the data did not identify (``unknown``: the start-up from rest,
    each creep with its break-free), to the end of the 30-s windows withheld over them
    (``withheld``): the statistics of the rotation at its set-point, not of its transients
    (docs/bit_speed.md "Stuck fraction and severity")."""
    settled = time_s[settled_mask(time_s)]
    first = float(settled[0]) if settled.size else float(time_s[-1])
    over = [b for a, b in withheld if any(lo < b and hi > a for lo, hi in unknown)]
    return max([first] + [float(b) for _, b in unknown] + [float(b) for b in over])


#: The rotation's set-point ends where the top drive's speed, averaged over
#: :data:`SET_POINT_SMOOTH_S`, was last at this share of its level (its median over the
#: statistics' span): the stop that ends a rotation — a ramp to rest — is not stick-slip.
SET_POINT_SHARE = 0.9
SET_POINT_SMOOTH_S = 1.0


def statistics_to(time_s: np.ndarray, surface_rad_s: np.ndarray, start_s: float) -> float:
    """Time to which the stuck fraction and severity are taken [s]: the last time the top
    drive's speed (its :data:`SET_POINT_SMOOTH_S` mean) was at :data:`SET_POINT_SHARE` of
    its level after ``start_s`` — the set-point's end, before the ramp to rest that ends
    a rotation (a steady 120-RPM stand's 5-s stop had read a severity of 0.55, "moderate
    stick-slip", and cut at a speed drop-out 0.05; docs/bit_speed.md "Stuck fraction and
    severity").

    Examples
    --------
    >>> t = np.arange(0.0, 100.0, 0.1)
    >>> w = np.where(t < 90.0, 12.0, np.maximum(12.0 - 2.4 * (t - 90.0), 0.0))
    >>> round(statistics_to(t, w, 10.0), 1)
    90.5
    """
    span = time_s >= start_s
    if span.sum() < 3:
        return float(time_s[-1])
    speed = smooth(np.abs(surface_rad_s), float(np.median(np.diff(time_s))),
                   SET_POINT_SMOOTH_S)
    level = float(np.median(speed[span]))
    at = np.flatnonzero(span & (speed >= SET_POINT_SHARE * level))
    return float(time_s[at[-1]]) if at.size else float(time_s[-1])


def _undetermined(final: ObserverRecord, bit: BitSpeedEstimate, span: np.ndarray,
                  windows: bit_trace.WindowVerdict, severity: float,
                  settings: ChainSettings, mu_s_known: bool) -> str:
    """Why the stuck fraction and severity are not determined ("" when they are): too short
    a rotation after the transients (:data:`~drillfric.estimation.bit_trace.
    MIN_STATISTICS_S`), a window of it withheld, stick-slip whose stuck phases rest on a μ_s
    the data did not identify (:func:`~drillfric.estimation.bit_trace.stops_without_mu_s`),
    or members that disagree."""
    time_s = final.time_s
    if not span.any() or time_s[span][-1] - time_s[span][0] < bit_trace.MIN_STATISTICS_S:
        return ("stuck fraction and severity withheld: less than "
                f"{bit_trace.MIN_STATISTICS_S:g} s of rotation after the start-up and the "
                "creeps whose break-free depends on the unidentified μ_s (docs/bit_speed.md)")
    if any(np.any(span & (time_s >= a) & (time_s < b)) for a, b in windows.withheld):
        return ("stuck fraction and severity withheld: the bit trace is withheld over some "
                "of their windows (window by window, docs/bit_speed.md)")
    members, weights = final.bit_rad_s_est[span], bit.weights[span]
    if not mu_s_known and (why := bit_trace.stops_without_mu_s(
            severity, bit_trace.stuck_share(members, weights, settings.omega_c_rad_s))):
        return why
    return bit_trace.members_disagree(members, severity, settings.omega_c_rad_s)


def _dropped_note(models: SegmentModels) -> tuple[str, ...]:
    """The message of a segment whose log had isolated spikes, drop-outs or held values."""
    notes = ()
    if models.dropped:
        notes += (f"{plural(models.dropped, 'speed or torque sample')} dropped as spikes, "
                  "drop-outs or samples lost while turning (values no motion of the string or "
                  "the top drive can take; bridged by interpolation, docs/ingestion.md \"EDR "
                  "defects\")",)
    if models.held:
        notes += (f"{plural(models.held, 'speed or torque sample')} held an earlier reading "
                  f"for {spikes.HOLD_MIN_S:g} s or more (a device that stopped updating): left "
                  "out of μ_k's cycle statistics and of the bit trace (docs/ingestion.md "
                  "\"EDR defects\")",)
    return notes


def beside(work, *args):
    """``work(*args)`` started on a thread of its own when numba may use more than one
    thread, else deferred; returns the callable that gives its result (raising what it
    raised).

    The seeded ensemble (5 members on 2 threads) leaves one core idle for a third of its
    pass; the fitted model over the segment (:func:`fit_evidence`, a nogil plant run that
    does not depend on the ensemble) fills it at a low priority (:func:`_yielding`; issue
    32, docs/performance.md). With one numba thread (a fleet running one well per core)
    nothing runs beside: no oversubscription. The numbers are the same either way
    (neither touches the other's arrays).
    """
    if numba.get_num_threads() < 2:
        return lambda: work(*args)
    pool = ThreadPoolExecutor(1, thread_name_prefix="drillfric-beside")
    job = pool.submit(_yielding, work, *args)
    pool.shutdown(wait=False)
    return job.result


def _yielding(work, *args):
    """``work(*args)`` on a thread that yields its core to the ensemble's member threads
    (Linux: the thread's nice value 19, so it runs where a core would idle, instead of
    slowing the member thread the ensemble waits for)."""
    if hasattr(os, "setpriority"):
        with contextlib.suppress(OSError):
            os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), 19)
    return work(*args)


def _runaway_note(mu_k: float, check: bit_trace.KinematicCheck) -> str:
    """Why a segment whose seeded trace runs away is not converged."""
    side = "ahead of" if check.lag_rpm > 0 else "behind"
    return (f"not converged: the observer seeded with μ_k = {mu_k:.3f} runs the bit "
            f"{abs(check.lag_rpm):.1f} RPM {side} the top drive over {check.t_from_s:.0f}–"
            f"{check.t_to_s:.0f} s, {check.drift_rad / check.allowed_rad:.0f}× the twist the "
            "string can hold: the fitted factors do not describe this record")


def _unknown_spans(models: SegmentModels, refined, time_s: np.ndarray) -> tuple:
    """[t_from_s, t_to_s) of the spans whose bit speed depends on μ_s where it was not
    identified: the start-up from rest and each creep with its break-free (to a wave round
    trip and 10 s after its end); none where μ_s was identified."""
    if refined.mu_s is not None:
        return ()
    travel = bit_trace.travel_time_s(models.string)
    settled = time_s[settled_mask(time_s)]
    start = ((time_s[0], settled[0] if settled.size else time_s[-1]),)
    return start + tuple((a, b + 2.0 * travel + 10.0) for a, b in
                         (refined.details.creeps_found or []))


def _windows(settings: ChainSettings, models: SegmentModels, time_s: np.ndarray,
             bit_rad_s: np.ndarray, unknown: tuple) -> bit_trace.WindowVerdict:
    """The window-by-window check of the trace (docs/bit_speed.md "Window by window"); the
    windows over ``unknown`` (:func:`_unknown_spans`) depend on the unidentified μ_s; windows
    over a gap between the logged samples (``models.sample_times_s``, after the EDR defects
    were dropped) longer than the wave travel time were not observed."""
    travel = bit_trace.travel_time_s(models.string)
    meas = models.meas
    return bit_trace.window_check(time_s, bit_rad_s, meas.time_s, meas.surface_rad_s,
                                  meas.motor_torque_Nm,
                                  bit_trace.compliance_rad_Nm(models.string), travel,
                                  settings.speed_noise_rad_s, unknown,
                                  find_gaps(models.sample_times_s, travel, 1.0 / meas.dt_s))


@dataclass(frozen=True)
class Steps:
    """What the chain's steps gave for one segment, for :func:`_assemble`."""

    starts: np.ndarray
    first: ObserverRecord
    diag: Diagnostics
    refined: batch.BatchResult
    verdict: Verdict
    trace: TraceVerdict
    final: ObserverRecord
    bit: BitSpeedEstimate
    fitted: FitEvidence
    terms: bit_torque.TorqueTerms | None
    kinematics: bit_trace.KinematicCheck
    stats_from_s: float
    trend: FrictionTrend | None = None
    stats_to_s: float = float("inf")


def _assemble(settings: ChainSettings, models: SegmentModels, data: SegmentData,
              steps: Steps) -> SegmentEstimate:
    """The segment's estimate from the chain's results, built once: the factors' verdict
    and the trace's verdict decide every flag and withheld field (diagnostics of what is
    reported)."""
    verdict, trace, refined, final, bit = (steps.verdict, steps.trace, steps.refined,
                                           steps.final, steps.bit)
    reported = diagnose(bit.record(final), settings.omega_c_rad_s)
    span = (final.time_s >= steps.stats_from_s) & (final.time_s <= steps.stats_to_s)
    members, weights = final.bit_rad_s_est[span], bit.weights[span]
    messages = list(verdict.messages)
    fits = refined.details.creep_fits
    at_top = bool(fits) and fits[-1][1] > 1.05 * verdict.mu_k  # not at μ_s = μ_k
    if Flag.CREEP_FIT_AT_BOUND in verdict.flags and at_top:
        messages.append(_creep_advice(models.string, models.td.T_N_Nm, verdict.mu_k, refined,
                                      models.meas))
    trend = steps.trend
    mu_k = trend.mean if trend is not None and trend.drift else verdict.mu_k
    drift_flags, drift_messages = drift_verdict(trend)
    severity = bit_trace.mixture_severity(members, weights)
    quiet = trace.statistics and bool(bit_trace.quiet_note(severity))
    return SegmentEstimate(
        mu_s=refined.mu_s, mu_k=mu_k, mu_s_identifiable=refined.mu_s_identifiable,
        mu_s_lower_bound=verdict.mu_s_lower_bound,
        mu_s_spread=_mu_s_spread(settings, refined, steps.diag),
        mu_k_spread=steps.diag.mu_k_spread, converged=trace.converged, method=verdict.method,
        mu_k_damping=refined.details.mu_k_damping if verdict.method is Method.BATCH else None,
        settling_time_s=steps.diag.settling_time_s, residual_rms_rpm=reported.residual_rms_rpm,
        stick_slip_severity=None if quiet else severity,
        stuck_fraction=bit_trace.stuck_share(members, weights, settings.omega_c_rad_s),
        stick_slip_from_s=steps.stats_from_s,
        stick_slip_to_s=min(steps.stats_to_s, float(final.time_s[-1])),
        mu_k_observer=steps.diag.mu_k, mu_s_observer=steps.diag.mu_s,
        mu_td=_td_cross_check(models, settings), T_N_Nm=models.observer.plant.T_N_Nm,
        flags=verdict.flags + trace.flags + drift_flags,
        messages=tuple(messages) + (() if drift_flags else  # the fit's ± is its window's
                                    _interval_note(refined, verdict, trace))
        + trace.messages + drift_messages
        + _span_note(trace, final.time_s, steps.stats_from_s, steps.stats_to_s)
        + ((bit_trace.quiet_note(severity),) if quiet else ()) + _dropped_note(models),
        starts=steps.starts, first=steps.first, final=final, bit=bit,
        bit_rms_error_rpm=_bit_error(final.time_s, bit, data), td=models.td,
        mu_s_seed=verdict.mu_s_seed, evidence=steps.fitted, bit_speed=trace.bit_speed,
        kinematics=steps.kinematics, bit_windows_withheld=trace.windows_withheld,
        bit_statistics=trace.statistics, logged=models.logged, torque_terms=steps.terms,
        friction_zone=settings.friction.zone, samples_dropped=models.dropped,
        samples_held=models.held,
        factors_withheld=withheld_factors(verdict.method, trace.converged,
                                          verdict.flags + trace.flags), trend=trend)


def _span_note(trace: TraceVerdict, time_s: np.ndarray, start_s: float,
               end_s: float) -> tuple[str, ...]:
    """The message of statistics taken after transients the unidentified μ_s decides."""
    settled = time_s[settled_mask(time_s)]
    if not trace.statistics or not settled.size or start_s <= settled[0]:
        return ()
    return (f"stuck fraction and severity over {start_s:.0f}–{min(end_s, time_s[-1]):.0f} s: "
            "the start-up "
            "and creeps before, whose break-free depends on the unidentified μ_s, are left "
            "out (docs/bit_speed.md)",)


def _interval_note(refined: batch.BatchResult, verdict: Verdict, trace: TraceVerdict
                   ) -> tuple[str, ...]:
    """The fit's note of μ_k's 95 % interval, stated only for a converged batch μ_k: a μ_k
    the rules do not call converged (estimators that disagree, a seeded trace that runs
    away, a mean torque too uncertain…) may be off by more than the validated tolerance
    the interval rests on — the lumped plant's were −20 % to +80 % — so it gets no ±."""
    if refined.interval_note is None or verdict.method is not Method.BATCH:
        return ()
    if trace.converged:
        return (refined.interval_note,)
    return (f"μ_k = {verdict.mu_k:.3f} is not converged: no interval is stated for it (the "
            "flags say why)",)


def _creep_advice(string, T_N_Nm: float, mu_k: float, refined: batch.BatchResult,
                  meas: Measurements) -> str:
    """Why a creep did not identify μ_s: the wind-up time it would have needed.

    Under uniform friction the torque falls linearly from the top, so winding the string up
    to break-free takes a twist μ_s·T_N·L/(2GJ) [rad] (pipe G, J; docs/theory.md §3, §6.3), turned
    at
    the creep speed; μ_s ≈ 2μ_k is assumed for the estimate.
    """
    pipe = string.sections[0]
    twist = 2.0 * mu_k * T_N_Nm * string.bit_depth_m / (
        2.0 * pipe.shear_modulus_Pa * pipe.polar_moment_m4)
    t0, t1 = (refined.details.creeps_found or [(meas.t0_s, meas.t0_s)])[0]
    t = meas.time_s
    inside = (t >= t0) & (t <= t1)
    speed = float(np.mean(meas.surface_rad_s[inside])) if inside.any() else 0.0
    if speed <= 0:
        return "the creep did not identify μ_s"
    return (f"the creep ({t1 - t0:.0f} s at {speed / RPM_TO_RAD_S:.1f} RPM) ended before the "
            f"string was wound up to break free: at this depth that takes about "
            f"{twist / speed:.0f} s of creep (for μ_s ≈ 2μ_k) — hold the creep longer")


def _mu_s_spread(settings: ChainSettings, refined: batch.BatchResult, diag: Diagnostics
                 ) -> float | None:
    """Uncertainty of the reported μ_s [-]: the creep fit's change on grid refinement.

    The observer starts' μ_s spread means something only under the paper's law; with the
    default law each start holds its μ̂_s, so that "spread" would restate the starts.
    """
    if refined.mu_s is not None and refined.details.creep_grid_move is not None:
        return float(refined.details.creep_grid_move * refined.mu_s)
    return diag.mu_s_spread if settings.observer.law == "paper" else None


def _memory_s(observer: Observer, meas: Measurements) -> float:
    """Memory of the ensemble weights [s]: a wave round trip 2L/c (one Courant-1 step per
    cell each way), at least two logging intervals."""
    return max(2.0 * observer.plant.grid.n_cells * observer.plant.grid.dt_s, 2.0 * meas.dt_s)


def _bit_error(time_s: np.ndarray, bit: BitSpeedEstimate, data: SegmentData) -> float | None:
    """RMS error of the estimated bit speed after the start-up [RPM] (truth known)."""
    if data.bit_rpm is None or not np.all(np.isfinite(data.bit_rpm)):
        return None
    late = settled_mask(time_s)
    truth = np.interp(time_s[late], data.time_s, data.bit_rpm)
    error = bit.rad_s[late] / RPM_TO_RAD_S - truth
    return float(np.sqrt(np.mean(error**2)))
