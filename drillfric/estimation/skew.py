"""Channel skew: the lag of the logged torque behind the logged speed, identified from the
data with an honest verdict, and corrected before estimation (docs/theory.md §5.3).

Rig recorders often log torque and speed from different devices; a torque logged ``L`` s
late shifts the phase the observer reads the downhole state from. At one stick-slip
frequency a lag is a phase shift that cannot be told from the inertia or damping terms;
broadband content — set-point steps, start-ups, stops — times it. The lag profile
(:func:`lag_profile`) is the share of the high-passed torque explained, at each candidate
lag, by the top-drive equation τ_m = I_TD·dω₀/dt + τ(0) with the string's instantaneous
response τ(0) ≈ Z·ω₀ (both coefficients free); :func:`identify_lag` states the lag only
where the profile's best peak is interior, clearly better than every rival peak (a periodic
stick-slip gives rivals one period away as good as the best) and narrow (its profile-
likelihood half-width within :data:`TOLERANCE_S`); otherwise "not identified", with why.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from drillfric.estimation.segment_data import SegmentData
from drillfric.units import RPM_TO_RAD_S

#: Lags searched for a claim, ± [s] (the issue's −2…+2 s with a margin for "interior").
SEARCH_S = 3.0
#: Extra lags profiled beyond the search range to see rival peaks one stick-slip period
#: away (periods of deep strings reach ~6 s; a profile twice wider sees one rival) [s].
RIVAL_SPAN_S = 4.0
#: Nearest a rival peak may be to the best one to count as a rival [s].
RIVAL_SEPARATION_S = 0.5
#: Largest share of the best peak's R² a rival may reach for the lag to be identified:
#: stick-slip alone gives rivals at 0.85–0.95 of the best, set-point steps below 0.15.
RIVAL_RATIO = 0.5
#: Smallest R² of the best peak: below it the torque does not follow the speed at any lag.
MIN_R2 = 0.05
#: Largest uncertainty of a lag stated as identified [s] (issue 34: ±0.2 s at 10–100 Hz).
TOLERANCE_S = 0.2
#: Smoothing of both channels before the profile (sensor noise; the event edges stay) [s].
SMOOTH_S = 0.2
#: High-pass window: the moving mean removed (the friction level, the slow set-point) [s].
HIGH_PASS_S = 4.0
#: Finest lag step profiled [s] (a faster log is profiled at this interval: the smoothing
#: leaves nothing finer, and the parabola's vertex times the peak between steps).
PROFILE_STEP_S = 0.05
#: Profile-likelihood drop of a 95 % interval (χ²₁ 95 % / 2).
CHI2_HALF_95 = 1.92


@dataclass(frozen=True)
class Skew:
    """The torque's lag behind the speed a segment was estimated with.

    Attributes
    ----------
    lag_s : float or None
        Lag applied [s] (positive: the torque lags the speed); None when not identified
        (nothing applied).
    uncertainty_s : float or None
        95 % half-width of an identified lag [s] (0 for a configured one).
    source : str
        ``"config"`` (``[channels] lag_s``), ``"identified"`` or ``"not identified"``.
    reason : str or None
        Why the lag is not identified.
    """

    lag_s: float | None
    uncertainty_s: float | None
    source: str
    reason: str | None = None

    @property
    def known(self) -> bool:
        """Whether the lag is known (configured or identified)."""
        return self.lag_s is not None


@dataclass(frozen=True)
class LagProfile:
    """The lag profile of one segment: R² of the top-drive equation at each lag.

    Attributes
    ----------
    lags_s : ndarray
        Candidate lags [s], spaced by the sample interval.
    r2 : ndarray
        Share of the high-passed torque's variance explained at each lag [-].
    n_eff : float
        Independent samples behind each R² (duration / smoothing window) [-].
    interval_s : float
        The log's own sample interval [s] (the profile's step is not finer than
        :data:`PROFILE_STEP_S`).
    """

    lags_s: np.ndarray
    r2: np.ndarray
    n_eff: float
    interval_s: float


def moving_mean(values: np.ndarray, width: int) -> np.ndarray:
    """Centred moving mean over ``width`` samples, zeros beyond the ends (the values of
    ``np.convolve(values, ones(width)/width, "same")``) by a running sum: O(n) at any width
    (1: the values).

    Examples
    --------
    >>> x = np.arange(10.0)
    >>> bool(np.allclose(moving_mean(x, 4), np.convolve(x, np.ones(4) / 4, mode="same")))
    True
    """
    if width <= 1:
        return values
    lead = (width - 1) // 2
    total = np.cumsum(np.concatenate((np.zeros(width - lead), values, np.zeros(lead))))
    return (total[width:] - total[:-width]) / width


def high_pass(values: np.ndarray, width: int) -> np.ndarray:
    """The values less their centred moving mean over ``width`` samples: the same linear
    filter on both sides of τ_m = I_TD·dω₀/dt + Z·ω₀ keeps the equation (and its timing)."""
    return values - moving_mean(values, width)


def lag_profile(time_s: np.ndarray, rpm: np.ndarray, torque_Nm: np.ndarray, *,
                torque_on_speed: bool = False) -> LagProfile | None:
    """R²(L) of the top-drive equation τ_m(t + L) = I_TD·dω₀/dt + Z·ω₀ (docs/theory.md §5.3,
    eq. 5.3a) at each candidate lag L, the coefficients free.

    Both channels are smoothed over :data:`SMOOTH_S` at their own rate, put on a uniform
    grid at the median interval (not finer than :data:`PROFILE_STEP_S`) and high-passed (the
    :data:`HIGH_PASS_S` moving mean removed; one linear filter on both sides keeps the
    equation and its timing). By default dω₀/dt is regressed on ω₀ and the shifted torque
    (the noisy derivative is the response: its noise biases nothing); with
    ``torque_on_speed`` the shifted torque on ω₀ and dω₀/dt (the torque's noise the
    response, the derivative's noise a bias). :func:`judge_profile` asks both to agree.

    Parameters
    ----------
    time_s : ndarray
        Sample times [s].
    rpm : ndarray
        Top-drive speed [RPM].
    torque_Nm : ndarray
        Logged torque [N·m].
    torque_on_speed : bool
        Which side of the equation is the response (above).

    Returns
    -------
    LagProfile or None
        None when the segment is too short for the lags searched.
    """
    logged_dt = float(np.median(np.diff(time_s)))
    dt = max(logged_dt, PROFILE_STEP_S)
    grid = np.arange(time_s[0], time_s[-1], dt)
    k, hp = max(1, round(SMOOTH_S / logged_dt)), max(3, round(HIGH_PASS_S / dt))
    omega = np.interp(grid, time_s, moving_mean(rpm * RPM_TO_RAD_S, k))
    speed, accel = high_pass(omega, hp), high_pass(np.gradient(omega, dt), hp)
    torque = high_pass(np.interp(grid, time_s, moving_mean(torque_Nm, k)), hp)
    shifts = np.arange(-round((SEARCH_S + RIVAL_SPAN_S) / dt),
                       round((SEARCH_S + RIVAL_SPAN_S) / dt) + 1)
    rows = np.arange(hp + shifts[-1], grid.size - hp - shifts[-1])
    if rows.size < 10 * hp:
        return None
    r2 = _r2_by_shift(accel[rows], speed[rows], torque, rows[0] + shifts, torque_on_speed)
    return LagProfile(shifts * dt, r2, rows.size * dt / max(SMOOTH_S, dt), logged_dt)


def _r2_by_shift(accel: np.ndarray, speed: np.ndarray, torque: np.ndarray,
                 starts: np.ndarray, torque_on_speed: bool) -> np.ndarray:
    """R² of the two-regressor fit at every shift at once (no intercept: high-passed).

    ``accel`` and ``speed`` are the fixed rows; the torque enters as
    ``torque[start:start + n]`` for each of ``starts`` (consecutive). Each fit needs only
    inner products, and the ones with the shifted torque are cross-correlations — one pass
    each instead of a regression per lag. The normal equations are solved with a
    pseudo-inverse, as a least-squares fit with a zero regressor would be. BLAS on one
    thread: numpy's correlate is a dot product per lag, and OpenBLAS's idle threads spin —
    on a 100-Hz stand beside the observer's kernels they cost 4–8× the work.
    """
    from threadpoolctl import threadpool_limits

    n = accel.size
    window = torque[starts[0]:starts[-1] + n]
    with threadpool_limits(limits=1):
        speed_torque = np.correlate(window, speed, mode="valid")
        accel_torque = np.correlate(window, accel, mode="valid")
    cumulative = np.concatenate(([0.0], np.cumsum(window * window)))
    torque_torque = cumulative[n:] - cumulative[:-n]
    speed_speed, speed_accel, accel_accel = speed @ speed, speed @ accel, accel @ accel
    if torque_on_speed:  # torque on [speed, accel]
        gram = np.broadcast_to([[speed_speed, speed_accel], [speed_accel, accel_accel]],
                               (starts.size, 2, 2))
        moment, response = np.stack([speed_torque, accel_torque], axis=1), torque_torque
    else:  # accel on [speed, torque]
        gram = np.empty((starts.size, 2, 2))
        gram[:, 0, 0], gram[:, 1, 1] = speed_speed, torque_torque
        gram[:, 0, 1] = gram[:, 1, 0] = speed_torque
        moment = np.stack([np.full(starts.size, speed_accel), accel_torque], axis=1)
        response = np.full(starts.size, accel_accel)
    explained = np.einsum("ki,kij,kj->k", moment, np.linalg.pinv(gram), moment)
    return explained / np.maximum(response, 1e-300)


def judge_profile(profile: LagProfile) -> Skew:
    """The verdict on a lag profile: identified (lag ± 95 % half-width) or why not.

    Identified only where the best peak within ±:data:`SEARCH_S` (sub-sample by a parabola)
    is interior, explains at least :data:`MIN_R2`, beats every rival peak at least
    :data:`RIVAL_SEPARATION_S` away by 1/:data:`RIVAL_RATIO`, and its profile-likelihood
    interval ℓ(L) = −(n_eff/2)·ln(1 − R²(L)), ℓ* − ℓ ≤ 1.92 (not narrower than one sample
    interval nor one profile step) is within ±:data:`TOLERANCE_S`.
    """
    lags, r2 = profile.lags_s, profile.r2
    inside = np.flatnonzero(np.abs(lags) <= SEARCH_S)
    best = inside[np.argmax(r2[inside])]
    if best in (inside[0], inside[-1]):
        return _unidentified(f"the best lag is at the edge of the ±{SEARCH_S:g} s searched")
    if r2[best] < MIN_R2:
        return _unidentified("the torque does not follow the speed's changes at any lag")
    peaks = np.flatnonzero((r2[1:-1] >= r2[:-2]) & (r2[1:-1] >= r2[2:])) + 1
    rivals = peaks[np.abs(lags[peaks] - lags[best]) >= RIVAL_SEPARATION_S]
    rival = float(r2[rivals].max()) if rivals.size else 0.0
    if rival > RIVAL_RATIO * r2[best]:
        return _unidentified(f"rival lags explain the torque as well ({rival / r2[best]:.0%} "
                             f"of the best): the speed varies at one stick-slip frequency, "
                             f"no set-point step, start-up or stop times the lag")
    half = _half_width(profile, best)
    if half > TOLERANCE_S:
        return _unidentified(f"the lag's 95 % interval is ±{half:.2f} s, wider than "
                             f"±{TOLERANCE_S:g} s")
    return Skew(float(_vertex(lags, r2, best)), half, "identified")


def _vertex(lags: np.ndarray, r2: np.ndarray, i: int) -> float:
    """Sub-sample lag of the peak at ``i``: the vertex of the parabola through 3 points."""
    a, b, c = r2[i - 1], r2[i], r2[i + 1]
    denom = a - 2.0 * b + c
    step = lags[1] - lags[0]
    return lags[i] if denom >= 0 else lags[i] + 0.5 * step * (a - c) / denom


def _half_width(profile: LagProfile, best: int) -> float:
    """95 % half-width of the peak at ``best`` [s]: the connected profile-likelihood
    interval, not narrower than one sample interval of the log nor one step of the profile
    (a sampled record times an event no finer: the simulator's 10-Hz stands read 0.06 s
    early, 5-Hz ones 0.10 s, 100-Hz ones 0.02 s)."""
    ell = -0.5 * profile.n_eff * np.log(np.clip(1.0 - profile.r2, 1e-12, None))
    inside = ell[best] - ell <= CHI2_HALF_95
    lo = best
    while lo > 0 and inside[lo - 1]:
        lo -= 1
    hi = best
    while hi < inside.size - 1 and inside[hi + 1]:
        hi += 1
    step = float(profile.lags_s[1] - profile.lags_s[0])
    return max(0.5 * float(profile.lags_s[hi] - profile.lags_s[lo]), profile.interval_s, step)


def _unidentified(why: str) -> Skew:
    return Skew(None, None, "not identified", f"channel skew not identified: {why}")


def identify_lag(time_s: np.ndarray, rpm: np.ndarray, torque_Nm: np.ndarray) -> Skew:
    """The torque's lag behind the speed from one segment's samples, or why not identified.

    Examples
    --------
    >>> t = np.arange(0.0, 20.0, 0.1)
    >>> identify_lag(t, np.full(t.size, 60.0), np.full(t.size, 9e3)).source
    'not identified'
    """
    finite = np.isfinite(time_s) & np.isfinite(rpm) & np.isfinite(torque_Nm)
    time_s, rpm, torque_Nm = time_s[finite], rpm[finite], torque_Nm[finite]
    if time_s.size < 3:
        return _unidentified("too few samples")
    dt = float(np.median(np.diff(time_s)))
    if dt > TOLERANCE_S:
        return _unidentified(f"the log's interval ({dt:.3g} s) cannot time a lag to "
                             f"±{TOLERANCE_S:g} s")
    profiles = [lag_profile(time_s, rpm, torque_Nm, torque_on_speed=side)
                for side in (False, True)]
    if profiles[0] is None:
        return _unidentified("the segment is too short for the lags searched")
    return agree(*(judge_profile(p) for p in profiles))


def agree(accel_side: Skew, torque_side: Skew) -> Skew:
    """The lag of the two regressions of :func:`lag_profile`, identified only where both
    are and they agree: the noise of either side's regressor biases its lag, never both
    alike (the noisy speed's derivative pulls the torque-side lag early). The lag is the
    acceleration side's; its ± holds the two lags' difference.

    Examples
    --------
    >>> agree(Skew(1.0, 0.05, "identified"), Skew(1.1, 0.05, "identified")).uncertainty_s
    0.1
    """
    for side in (accel_side, torque_side):
        if not side.known:
            return side
    half = max(accel_side.uncertainty_s, torque_side.uncertainty_s,
               round(abs(accel_side.lag_s - torque_side.lag_s), 12))
    if half > TOLERANCE_S:
        return _unidentified(f"the lag read from the torque ({torque_side.lag_s:+.2f} s) and "
                             f"from the speed's changes ({accel_side.lag_s:+.2f} s) disagree "
                             f"beyond ±{TOLERANCE_S:g} s (noise in the speed, or a string "
                             "response the top-drive equation leaves out)")
    return Skew(accel_side.lag_s, half, "identified")


def shift_torque(data: SegmentData, lag_s: float) -> SegmentData:
    """The segment with its torque moved ``lag_s`` earlier: τ(t) := τ_logged(t + lag_s)
    (linear interpolation), the rows the shift leaves without a torque dropped."""
    if lag_s == 0.0:
        return data
    t = data.time_s
    keep = (t + lag_s >= t[0]) & (t + lag_s <= t[-1])

    def moved(values):
        return None if values is None else np.interp(t[keep] + lag_s, t, values)

    return replace(data, time_s=t[keep], surface_rpm=data.surface_rpm[keep],
                   surface_torque_Nm=moved(data.surface_torque_Nm),
                   bit_rpm=None if data.bit_rpm is None else data.bit_rpm[keep],
                   torque_min_Nm=moved(data.torque_min_Nm),
                   torque_max_Nm=moved(data.torque_max_Nm))


def correct(data: SegmentData, configured_s: float | None) -> tuple[SegmentData, Skew]:
    """The segment corrected for the channel skew, and the skew: the configured lag
    (``[channels] lag_s``) when given, else the identified one; uncorrected when not
    identified."""
    if configured_s is not None:
        return shift_torque(data, configured_s), Skew(configured_s, 0.0, "config")
    skew = identify_lag(data.time_s, data.surface_rpm, data.surface_torque_Nm)
    return (shift_torque(data, skew.lag_s) if skew.known else data), skew
