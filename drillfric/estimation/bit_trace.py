"""What a bit-speed trace may claim: the kinematic check, the on-bottom rule, stuck and severity.

**Kinematics** (docs/bit_speed.md "Kinematic check"). The top drive and the bit are the two
ends of one string. Integrating eq. (1) of docs/theory.md §3, ∂τ/∂t + JG ∂ω/∂x = 0, along
the string gives ω_bit − ω₀ = −dΘ/dt with Θ = ∫ τ/(GJ) dx the string's twist, so over any
window [t₁, t₂] of length T

    mean(ω_bit) − mean(ω₀) = −(Θ(t₂) − Θ(t₁)) / T.

The twist is bounded by the torque the string carries: with τ(x) between min(τ_lo, 0) and
τ_hi (the measured extremes of the surface torque; off bottom the bit end carries 0) and
the string's compliance C = Σ L_i/(G_i J_i), |ΔΘ| ≤ C·(τ_hi − min(τ_lo, 0)) — twice the twist of
a string whose torque falls linearly from τ_hi to 0, so a true trace uses about 80 % of it
(measured on simulated severe stick-slip). A trace whose accumulated angle
∫(ω̂_bit − ω₀) dt changes by more than that bound, plus the speed noise's random walk and one
output interval at the peak speed (the trace's samples are integrated), over any window
claims a bit running ahead of or behind its top drive for longer than any twist allows:
it is withheld with the window and the mean lag as the reason. A mean lag within the
accuracy claimed in steady rotation (:data:`MEAN_LAG_TOLERANCE_RPM` × the window) is
allowed on top: such a trace is not false within its tolerance.

**On bottom** the estimators have no bit–rock torque (docs/theory.md §3, "Bit"): the trace is
withheld there whatever the check says (issue 22: seven on-bottom traces at 10 Hz were worse
than the surface speed).

**Stuck and severity.** The bit is stuck while it turns no faster than ω_c: inside the
static band of the friction law (docs/theory.md §3) the friction holds the bit, which may
still creep a few RPM under a held torque. The stuck fraction and the stick-slip severity
are statistics of the ensemble's members pooled with their weights (the mixture), not of
their weighted mean: members drift apart in phase, and their mean smooths the slips (its
severity read 7–14 % low on the validation truths, docs/validation.md "Bit-speed
statistics"). In stick-slip more severe than that (estimated severity ≥
:data:`SEVERITY_VALIDATED_BELOW`) they read up to 26 % (severity) and 0.13 (stuck) low
(benchmarks/validate_severity.py): the members carry a μ_s the data did not identify, and
the stick phases they draw depend on it. There both are withheld.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from drillfric.estimation.sampling import Resolution
from drillfric.units import RPM_TO_RAD_S

#: Percentiles of the measured torque taken as its extremes (a glitch does not widen the
#: twist bound) [%].
TORQUE_PERCENTILES = (0.1, 99.9)
#: Standard deviations of the speed noise's random walk allowed on top of the twist bound.
NOISE_SIGMAS = 3.0
#: Mean lag within the bit-speed accuracy claimed in steady rotation (≤ 2 RPM RMS,
#: docs/validation.md) is not a false claim: a window of length T may drift by this × T more
#: [RPM]. (On the trust plant "steady" the trace ran 1.3 RPM behind for 5 minutes.)
MEAN_LAG_TOLERANCE_RPM = 2.0
#: A trace that fails the check with a mean lag of at most this share of its RMS swing about
#: the top drive is shown with the flag ``bit_speed_drift`` instead of withheld [-]: the lag
#: adds at most its size to the RMS error (triangle inequality), which in severe stick-slip
#: (swing 40–70 RPM, trace error 19–35 RPM RMS, docs/validation.md) keeps the trace well
#: ahead of the surface speed; a trace lagging a steady top drive (swing ≈ lag) is withheld.
DRIFT_SHARE_OF_SWING = 1.0 / 3.0
#: The stuck fraction and the severity are reported only below this estimated severity [-]
#: (issue 22, docs/validation.md "Severe stick-slip"). In severe off-bottom stick-slip
#: (truth 2.9–3.7, stuck 0.63–0.74) 11 of 15 records were outside the tolerance, down to
#: −26 % on the severity (μ_s not identified: the ensemble's μ_s/μ_k ratio 2.5 against
#: 2.7–3.2, and members released by the deadlock guard stick-slip less), and a truth of
#: 2.88 already read 2.41 (−16 %). A truth ≥ 2.88 read −26 % low at worst gives ≥ 2.13,
#: so an estimate below 2.1 comes from stick-slip where every record was within tolerance.
SEVERITY_VALIDATED_BELOW = 2.1
#: Estimated severity [-] below which no number is stated: a rotation without stick-slip
#: swings its bit by a few % to ~10 % (validate_trust's steady plant: truth 0.033; its cased
#: stand 0.09–0.10), where the estimate's own noise, 0.007–0.016, is more than its ±12 %
#: (0.040 for 0.033, +19 %; 0.104 for 0.088, +18 % at 5 Hz). Below 0.2 a severity says only
#: "no stick-slip" (the bit's speed within ±20 % of its mean); the stuck fraction still holds.
SEVERITY_STATED_FROM = 0.2
#: Estimated severities [-] at which the bit grazes rest: (ω99 − ω1)/(2ω̄) ≈ 1 puts its
#: slowest speeds near zero, and the stuck fraction, a threshold statistic, turns on whether
#: it just stops. On the lumped plant every estimate in 0.77–0.94 was outside the tolerance
#: (stuck 0.06 for 0.14–0.23, severity −15…−27 %), and the 100-RPM record's 0.87 too, while
#: 0.59–0.71 (the bit well clear of rest) and 1.63 held (docs/validation.md).
GRAZING = (0.75, 1.3)
#: Least rotation after the transients [s] over which the stuck fraction and severity are
#: taken (:func:`drillfric.estimation.chain.statistics_from`): several stick-slip periods
#: (3–20 s for 1500–6000 m of pipe), so that a share of time is a statistic of the cycle.
MIN_STATISTICS_S = 60.0
#: The stated tolerances of the stuck fraction [-] and of the severity [share] (docs/
#: bit_speed.md "Stuck fraction and severity").
STUCK_TOLERANCE = 0.05
SEVERITY_TOLERANCE = 0.12
#: Members' severities closer than this are in agreement whatever their size [-] (steady
#: rotation reads 0.01–0.02, where 12 % of it is no spread at all).
SEVERITY_FLOOR = 0.05


@dataclass(frozen=True)
class KinematicCheck:
    """Whether a bit-speed trace keeps to its top drive within what the twist allows.

    Attributes
    ----------
    passed : bool
    drift_rad : float
        Largest change of ∫(ω̂_bit − ω₀) dt over any window of the trace [rad].
    allowed_rad : float
        The twist bound plus the noise and sampling allowance [rad].
    t_from_s, t_to_s : float
        The window of that largest change [s].
    lag_rpm : float
        mean(ω̂_bit) − mean(ω₀) over that window [RPM] (negative: the bit behind).
    swing_rpm : float
        RMS of ω̂_bit − ω₀ over that window [RPM]: the stick-slip the trace draws about the
        top drive (the error of the surface speed taken as the bit speed, were the trace
        right).
    """

    passed: bool
    drift_rad: float
    allowed_rad: float
    t_from_s: float
    t_to_s: float
    lag_rpm: float
    swing_rpm: float = 0.0

    @property
    def approximate(self) -> bool:
        """Failed, but by a mean lag of at most :data:`DRIFT_SHARE_OF_SWING` of the trace's
        swing: a mean offset ε adds at most ε to a trace's RMS error, so such a trace stays
        within its stated accuracy and well ahead of the surface speed (shown, flagged)."""
        return not self.passed and abs(self.lag_rpm) <= DRIFT_SHARE_OF_SWING * self.swing_rpm

    @property
    def reason(self) -> str:
        """Why the trace is withheld ("" when it passed)."""
        if self.passed:
            return ""
        side = "behind" if self.lag_rpm < 0 else "ahead of"
        return (f"bit speed withheld: the estimated bit runs {abs(self.lag_rpm):.1f} RPM "
                f"{side} the top drive on average over {self.t_from_s:.0f}–{self.t_to_s:.0f} "
                f"s, a twist change of {self.drift_rad:.0f} rad where the string's torque "
                f"range allows {self.allowed_rad:.0f} rad (kinematic check, docs/bit_speed.md)")


#: A seeded trace drifting beyond this many times its allowance, over at least
#: :data:`RUNAWAY_SHARE` of the settled rotation, says the fitted factors do not describe
#: the record (the lumped plant's false μ_k: −20 % at 10 Hz, its trace 38.7 RPM ahead for
#: 242 s, 981 rad against 119; right factors drifted at most 9.5× over ≤ 62 s there).
RUNAWAY_TIMES = 3.0
RUNAWAY_SHARE = 0.5


def runs_away(check: KinematicCheck, settled_s: float) -> bool:
    """Whether the trace of the seeded pass runs away from its top drive for most of the
    settled rotation (``settled_s`` [s]): :data:`RUNAWAY_TIMES` × its allowance over at least
    :data:`RUNAWAY_SHARE` of it."""
    return (not check.passed and check.drift_rad > RUNAWAY_TIMES * check.allowed_rad
            and check.t_to_s - check.t_from_s >= RUNAWAY_SHARE * settled_s)


def compliance_rad_Nm(string) -> float:
    """Torsional compliance of the whole string C = Σ L_i/(G_i J_i) [rad/(N·m)].

    Examples
    --------
    >>> from drillfric.drillstring import build_string
    >>> s = build_string([{"name": "DP", "od_m": 0.127, "id_m": 0.1086}], 1000.0)
    >>> round(compliance_rad_Nm(s) * 79.3e9 * s.sections[0].polar_moment_m4, 6)
    1000.0
    """
    return float(sum(s.length_m / (s.shear_modulus_Pa * s.polar_moment_m4)
                     for s in string.sections))


def twist_bound_rad(torque_Nm: np.ndarray, compliance: float) -> float:
    """Largest change of the string's twist the measured torque allows [rad]:
    C·(τ_hi − min(τ_lo, 0)), τ_lo/τ_hi the :data:`TORQUE_PERCENTILES` of the torque."""
    q = np.asarray(torque_Nm, dtype=float)
    q = q[np.isfinite(q)]
    if q.size == 0:
        return 0.0
    lo, hi = np.percentile(q, TORQUE_PERCENTILES)
    return float(compliance * (max(hi, 0.0) - min(lo, 0.0)))


def check_trace(time_s, bit_rad_s, surface_time_s, surface_rad_s, twist_bound: float,
                noise_rad_s: float) -> KinematicCheck:
    """Kinematic check of an estimated bit speed against the measured top-drive speed.

    Parameters
    ----------
    time_s, bit_rad_s : ndarray
        The trace: sample times [s] and estimated bit speed [rad/s].
    surface_time_s, surface_rad_s : ndarray
        Measured top-drive speed [s], [rad/s] (uniform samples).
    twist_bound : float
        Largest twist change the string allows [rad] (:func:`twist_bound_rad`).
    noise_rad_s : float
        Standard deviation of the measured speed [rad/s].
    """
    t, bit = np.asarray(time_s, dtype=float), np.asarray(bit_rad_s, dtype=float)
    ts, ws = np.asarray(surface_time_s, dtype=float), np.asarray(surface_rad_s, dtype=float)
    if t.size < 2 or ts.size < 2 or not np.all(np.isfinite(bit)):
        return KinematicCheck(t.size >= 2 and np.all(np.isfinite(bit)), 0.0, twist_bound,
                              0.0, 0.0, 0.0)
    surface_angle = np.interp(t, ts, _angle(ts, ws))
    drift = _angle(t, bit) - surface_angle
    lag = MEAN_LAG_TOLERANCE_RPM * RPM_TO_RAD_S
    a, b = _worst_window(drift, t, lag)
    change = float(drift[b] - drift[a])
    dt_surface = float(np.median(np.diff(ts)))
    walk = NOISE_SIGMAS * noise_rad_s * np.sqrt(dt_surface * (t[-1] - t[0]))
    sampling = float(np.max(np.abs(bit))) * float(np.max(np.diff(t)))
    allowed = twist_bound + walk + sampling + lag * float(t[b] - t[a])
    span = max(t[b] - t[a], 1e-9)
    gap = bit[a:b + 1] - np.interp(t[a:b + 1], ts, ws)
    swing = float(np.sqrt(np.mean(gap ** 2))) / RPM_TO_RAD_S
    return KinematicCheck(abs(change) <= allowed, abs(change), float(allowed), float(t[a]),
                          float(t[b]), change / span / RPM_TO_RAD_S, swing)


def _worst_window(drift: np.ndarray, time_s: np.ndarray, lag_rad_s: float) -> tuple[int, int]:
    """Indices (a ≤ b) of the window whose |drift(b) − drift(a)| − ``lag_rad_s``·(t_b − t_a)
    is largest (O(n): the largest drop of drift + lag·t and rise of drift − lag·t after a
    running extreme); the last visit of the extreme, so the window is the shortest."""
    best = (-np.inf, 0, 0)
    for sign in (1.0, -1.0):
        rise = sign * drift - lag_rad_s * time_s
        low = np.minimum.accumulate(rise)
        b = int(np.argmax(rise - low))
        a = int(np.flatnonzero(rise[:b + 1] <= low[b] + 1e-12)[-1])
        if rise[b] - low[b] > best[0]:
            best = (rise[b] - low[b], a, b)
    return best[1], best[2]


def _angle(time_s: np.ndarray, speed_rad_s: np.ndarray) -> np.ndarray:
    """Angle turned since the first sample [rad] (trapezoidal rule)."""
    steps = 0.5 * (speed_rad_s[1:] + speed_rad_s[:-1]) * np.diff(time_s)
    return np.concatenate(([0.0], np.cumsum(steps)))


def check_segment_trace(string, meas, time_s, bit_rad_s, noise_rad_s: float) -> KinematicCheck:
    """:func:`check_trace` of a segment's trace against its measurements (``meas``:
    :class:`~drillfric.estimation.observer.Measurements`) on ``string``'s twist bound."""
    bound = twist_bound_rad(meas.motor_torque_Nm, compliance_rad_Nm(string))
    return check_trace(time_s, bit_rad_s, meas.time_s, meas.surface_rad_s, bound, noise_rad_s)


def bit_speed_claim(resolution: Resolution, check: KinematicCheck,
                    on_bottom: bool) -> Resolution:
    """What may be reported of the bit speed: the logging's :class:`Resolution`, withheld
    (``resolved`` false with the reason) on bottom and where the kinematic check fails."""
    if not resolution.resolved:
        return resolution
    if on_bottom:
        return replace(resolution, resolved=False, reason=(
            "bit speed withheld on bottom: the model has no bit–rock torque, and on "
            "simulated on-bottom records the trace was not better than the surface speed "
            "(docs/bit_speed.md)"))
    if not check.passed and not check.approximate:
        return replace(resolution, resolved=False, reason=check.reason)
    return resolution


def drift_note(check: KinematicCheck) -> str:
    """The message of a trace shown with the flag ``bit_speed_drift``."""
    side = "behind" if check.lag_rpm < 0 else "ahead of"
    return (f"bit speed shown with its phase approximate: the trace runs "
            f"{abs(check.lag_rpm):.1f} RPM {side} the top drive over "
            f"{check.t_from_s:.0f}–{check.t_to_s:.0f} s, more than the string's twist allows "
            f"but under a third of its {check.swing_rpm:.0f} RPM stick-slip swing (kinematic "
            "check, docs/bit_speed.md)")


def stuck_share(member_bit_rad_s: np.ndarray, weights: np.ndarray,
                omega_c_rad_s: float) -> float:
    """Share of the time the bit is stuck, |ω_bit| ≤ ω_c, over the members pooled with
    their weights [-] (``member_bit_rad_s``, ``weights``: shape (R, S), rows of weights sum
    to 1).

    Examples
    --------
    >>> bit = np.array([[0.0, 5.0], [5.0, 5.0]])
    >>> float(stuck_share(bit, np.full((2, 2), 0.5), 1.0))
    0.25
    """
    stuck = np.abs(member_bit_rad_s) <= omega_c_rad_s
    return float(np.sum(weights * stuck) / max(weights.shape[0], 1))


def mixture_severity(member_bit_rad_s: np.ndarray, weights: np.ndarray) -> float:
    """Stick-slip severity (ω_99 − ω_1)/(2·ω_mean) of the members pooled with their
    weights (weighted percentiles) [-]; 0 for a bit at rest.

    Examples
    --------
    >>> bit = np.column_stack([np.tile([0.0, 2.0], 50), np.tile([2.0, 0.0], 50)])
    >>> round(mixture_severity(bit, np.full(bit.shape, 0.5)), 2)
    1.0
    """
    x, w = np.ravel(member_bit_rad_s), np.ravel(weights)
    mean = float(np.sum(w * x) / max(np.sum(w), 1e-300))
    if abs(mean) < 1e-9:
        return 0.0
    order = np.argsort(x, kind="stable")
    cum = np.cumsum(w[order])
    lo, hi = np.interp([0.01 * cum[-1], 0.99 * cum[-1]], cum, x[order])
    return float((hi - lo) / (2.0 * abs(mean)))


def quiet_note(severity: float) -> str:
    """Why no severity is stated below :data:`SEVERITY_STATED_FROM` ("" at or above it).

    Examples
    --------
    >>> quiet_note(0.04)[:41]
    'no stick-slip: the severity is below 0.2,'
    >>> quiet_note(0.5)
    ''
    """
    if not severity < SEVERITY_STATED_FROM:
        return ""
    return (f"no stick-slip: the severity is below {SEVERITY_STATED_FROM:g}, where the "
            "estimate's "
            "own noise is its size: no number stated (docs/bit_speed.md)")


def statistics_note(severity: float) -> str:
    """Why the stuck fraction and the severity are withheld ("" when they may be reported):
    the estimated ``severity`` [-] shows stick-slip beyond :data:`SEVERITY_VALIDATED_BELOW`.

    Examples
    --------
    >>> statistics_note(1.5)
    ''
    >>> statistics_note(2.6)[:60]
    'severe stick-slip: stuck fraction and severity withheld, the'
    """
    if not severity >= SEVERITY_VALIDATED_BELOW:
        return ""
    return (f"severe stick-slip: stuck fraction and severity withheld, the estimated "
            f"severity is {SEVERITY_VALIDATED_BELOW:g} or more, beyond where they are "
            "validated; there they read up to 26 % and 0.13 low (docs/bit_speed.md)")


# ---------------------------------------------------------------------- window by window
#: Windows of the window-by-window check [s]: a fixed grid from the segment's first row
#: (docs/bit_speed.md "Window by window"); a partial last window counts when at least
#: :data:`MIN_WINDOW_S` long, else it joins the window before.
WINDOW_S = 30.0
MIN_WINDOW_S = 15.0
#: Share of a trace's windows withheld beyond which the whole trace is withheld [-].
MAX_WITHHELD_SHARE = 0.5


@dataclass(frozen=True)
class WindowVerdict:
    """The windows of a trace withheld by the window-by-window check.

    Attributes
    ----------
    windows : int
        Windows of the trace.
    withheld : tuple of (float, float)
        [t_from_s, t_to_s) of each withheld window [s].
    reason : str
        Why (the worst window, or the creep), "" when none is withheld.
    """

    windows: int
    withheld: tuple[tuple[float, float], ...] = ()
    reason: str = ""

    @property
    def too_many(self) -> bool:
        """More than :data:`MAX_WITHHELD_SHARE` of the windows withheld."""
        return self.windows > 0 and len(self.withheld) > MAX_WITHHELD_SHARE * self.windows


def window_grid(t_from_s: float, t_to_s: float) -> list[tuple[float, float]]:
    """[start, end) of the :data:`WINDOW_S` windows from ``t_from_s`` to ``t_to_s`` [s].

    Examples
    --------
    >>> window_grid(0.0, 70.0)
    [(0.0, 30.0), (30.0, 70.0)]
    >>> window_grid(0.0, 80.0)
    [(0.0, 30.0), (30.0, 60.0), (60.0, 80.0)]
    """
    edges = list(np.arange(t_from_s, t_to_s, WINDOW_S)) + [t_to_s]
    if len(edges) > 2 and edges[-1] - edges[-2] < MIN_WINDOW_S:
        del edges[-2]
    return [(float(a), float(b)) for a, b in zip(edges[:-1], edges[1:], strict=True)]


def window_check(time_s, bit_rad_s, surface_time_s, surface_rad_s, torque_Nm,
                 compliance: float, travel_s: float, noise_rad_s: float,
                 unknown_spans: tuple = (), gap_spans: tuple = ()) -> WindowVerdict:
    """The kinematic check of docs/bit_speed.md window by window.

    Over a window of length T the bit's mean speed is the top drive's minus the change of
    the string's twist over T (module docstring), and the twist at any instant is bounded
    by the torque the string carries then: C·(τ_hi − min(τ_lo, 0)) with the surface torque's
    extremes over the window and one wave travel time ``travel_s`` before it (what reaches
    the string's far end started at the top that much earlier). A window whose trace mean
    differs from the top drive's by more than that twist over T, the speed noise's random
    walk and :data:`MEAN_LAG_TOLERANCE_RPM` claims a bit running away from its string: it
    is withheld. So are the windows overlapping ``unknown_spans`` ([t_from_s, t_to_s)
    pairs): where μ_s was not identified, a creep's and its break-free's bit speed depend
    on it; and the windows overlapping ``gap_spans``, stretches the log has no sample in
    (:func:`drillfric.io.timebase.find_gaps`), over which the trace is the observer's
    guess.

    Parameters
    ----------
    time_s, bit_rad_s : ndarray
        The trace [s], [rad/s].
    surface_time_s, surface_rad_s, torque_Nm : ndarray
        The measured top-drive speed [rad/s] and string torque [N·m] on their times [s].
    compliance : float
        The string's torsional compliance C [rad/(N·m)] (:func:`compliance_rad_Nm`).
    travel_s : float
        One-way torsional wave travel time along the string [s].
    noise_rad_s : float
        Standard deviation of the measured speed [rad/s].
    """
    t, bit = np.asarray(time_s, float), np.asarray(bit_rad_s, float)
    ts, ws = np.asarray(surface_time_s, float), np.asarray(surface_rad_s, float)
    tau = np.asarray(torque_Nm, float)
    if t.size < 2 or ts.size < 2:
        return WindowVerdict(0)
    dt = float(np.median(np.diff(ts)))
    grid = window_grid(float(t[0]), float(t[-1]) + float(np.median(np.diff(t))))
    withheld, worst, why = [], (0.0, ""), []
    for a, b in grid:
        for spans, reason in ((gap_spans, _GAP_REASON), (unknown_spans, _CREEP_REASON)):
            if any(lo < b and hi > a for lo, hi in spans):
                withheld.append((a, b))
                why.append(reason)
                break
        else:
            off = _off_its_string(a, b, (t, bit), (ts, ws, tau), compliance, travel_s,
                                  noise_rad_s * np.sqrt(dt))
            if off is not None:
                withheld.append((a, b))
                worst = max(worst, off)
    reasons = [worst[1]] * bool(worst[1]) + sorted(set(why), key=why.index)
    return WindowVerdict(len(grid), tuple(withheld), "; ".join(reasons) if withheld else "")


#: Why windows over a creep or over a gap of the log are withheld.
_CREEP_REASON = ("bit speed withheld over the start-up from rest or a creep, with its "
                 "break-free: μ_s was not identified, and the bit's speed there depends on it")
_GAP_REASON = ("bit speed withheld where the log has a gap longer than the string's wave "
               "travel time: the bit's motion there was not observed")


def _off_its_string(a: float, b: float, trace, top, compliance: float, travel_s: float,
                    walk_rad: float) -> tuple[float, str] | None:
    """(excess [rad/s], reason) of a window [a, b) whose trace mean runs off its top drive
    by more than the twist its torques allow (:func:`window_check`), else None.
    ``trace`` = (t, ω̂_bit), ``top`` = (t, ω₀, τ), ``walk_rad``: the speed noise's random
    walk per √s [rad]."""
    (t, bit), (ts, ws, tau) = trace, top
    inside, turning = (t >= a) & (t < b), (ts >= a) & (ts < b)
    load = (ts >= a - travel_s) & (ts < b) & np.isfinite(tau)
    if inside.sum() < 2 or turning.sum() < 2 or not load.any():
        return None
    span = b - a
    lo, hi = np.percentile(tau[load], TORQUE_PERCENTILES)
    twist = compliance * (max(hi, 0.0) - min(lo, 0.0))
    allowed = (twist + NOISE_SIGMAS * walk_rad * np.sqrt(span)) / span \
        + MEAN_LAG_TOLERANCE_RPM * RPM_TO_RAD_S
    gap = float(np.mean(bit[inside]) - np.mean(ws[turning]))
    if abs(gap) <= allowed:
        return None
    return abs(gap) - allowed, _window_reason(a, b, gap, allowed)


def _window_reason(a: float, b: float, gap_rad_s: float, allowed_rad_s: float) -> str:
    side = "ahead of" if gap_rad_s > 0 else "behind"
    return (f"the estimated bit runs {abs(gap_rad_s) / RPM_TO_RAD_S:.1f} RPM {side} the top "
            f"drive on average over {a:.0f}–{b:.0f} s where the string's twist allows "
            f"{allowed_rad_s / RPM_TO_RAD_S:.1f} RPM (window-by-window kinematic check, "
            "docs/bit_speed.md)")


def travel_time_s(string) -> float:
    """One-way torsional wave travel time along ``string`` [s]: Σ L_i/c_i."""
    return float(sum(s.length_m / s.wave_speed_m_s for s in string.sections))


def stops_without_mu_s(severity: float, stuck: float) -> str:
    """Why the stuck fraction and severity of a segment whose μ_s was not identified are
    withheld ("" when the bit does not stop: severity below :data:`GRAZING` and at most
    2×:data:`STUCK_TOLERANCE` stuck).

    How long the bit sticks each cycle, and so both numbers, turns on μ_s: the torque it
    must wind up to break free. On the lumped plant, over the rotation after their creeps,
    82 pairs printed with μ_s unidentified were 71 within the tolerance and 11 not — stuck
    −0.15…+0.15, severity −14…+24 % — all in stick-slip (estimated severity 1.4–1.9, or 0.69
    with 0.11 stuck at 6000 m); the 32 without stick-slip (severity ≤ 0.59, stuck ≤ 0.05)
    all held (docs/bit_speed.md).

    Examples
    --------
    >>> stops_without_mu_s(0.55, 0.04)
    ''
    >>> stops_without_mu_s(1.7, 0.5)[:44]
    'stuck fraction and severity withheld: the bi'
    """
    if severity < GRAZING[0] and stuck <= 2.0 * STUCK_TOLERANCE:
        return ""
    return (f"stuck fraction and severity withheld: the bit stops in the cycle (estimated "
            f"severity {severity:.2f}), and how long it sticks turns on μ_s, which the data "
            "did not identify (docs/bit_speed.md)")


def members_disagree(member_bit_rad_s: np.ndarray, severity: float,
                     omega_c_rad_s: float) -> str:
    """Why the stuck fraction and the severity are not determined by the data ("" when they
    are): the ensemble's members carry μ_s across its uncertainty (``observer.
    ensemble_spread``), and where their own statistics (each member's trace, shape (S, R)
    columns) spread beyond the tolerance — ±:data:`STUCK_TOLERANCE` stuck, ±:data:`SEVERITY_
    TOLERANCE` of the severity (half the range) — the μ_s the data did not fix decides them
    (on the lumped plant, docs/validation.md: stuck 0.06 for 0.23, severity −25 %)."""
    if GRAZING[0] <= severity <= GRAZING[1]:
        return (f"stuck fraction and severity withheld: an estimated severity of {severity:.2f} "
                "puts the bit's slowest speeds at the edge of rest, where whether it stops "
                "each cycle — and so both numbers — depends on the friction law's detail "
                "more than on the data (docs/bit_speed.md)")
    bit = np.asarray(member_bit_rad_s, dtype=float)
    if bit.ndim != 2 or bit.shape[1] < 2 or bit.shape[0] < 2:
        return ""
    own_stuck = np.mean(np.abs(bit) <= omega_c_rad_s, axis=0)
    mean = np.abs(np.mean(bit, axis=0))
    lo, hi = np.percentile(bit, [1.0, 99.0], axis=0)
    own_severity = np.where(mean > 1e-9, (hi - lo) / (2.0 * np.maximum(mean, 1e-9)), 0.0)
    stuck_half = 0.5 * float(np.ptp(own_stuck))
    severity_half = 0.5 * float(np.ptp(own_severity))
    if stuck_half <= STUCK_TOLERANCE and \
            severity_half <= max(SEVERITY_TOLERANCE * severity, SEVERITY_FLOOR):
        return ""
    return (f"stuck fraction and severity withheld: the ensemble's members, whose μ_s spans "
            f"its uncertainty, give {np.min(own_stuck):.2f}–{np.max(own_stuck):.2f} stuck and "
            f"a severity of {np.min(own_severity):.2f}–{np.max(own_severity):.2f}, beyond "
            f"±{STUCK_TOLERANCE:g} and ±{100 * SEVERITY_TOLERANCE:.0f} %: the data do not fix "
            "them (docs/bit_speed.md)")
