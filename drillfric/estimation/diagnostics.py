"""Per-window diagnostics of the friction estimates (issue 5, part 5).

From an observer record (several starts) and the batch result: consensus and spread across
starts, settling time, innovation RMS, fraction of time the estimated BHA is stuck,
stick-slip severity, and flags. Pure functions on arrays; SI inside, RPM only in the names
of the values meant for people (``residual_rms_rpm``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from drillfric.units import RPM_TO_RAD_S

#: Fraction of the window (at its end) whose mean is the converged estimate.
TAIL_FRACTION = 0.3
#: Relative band around the consensus that every start must stay inside to be settled.
SETTLE_BAND = 0.05
#: Absolute floor of that band [-] (small friction factors).
SETTLE_FLOOR = 0.01
#: Start-up excluded from the stick-slip statistics [s] (at most 30 % of the window).
STARTUP_S = 30.0


@dataclass(frozen=True)
class Diagnostics:
    """Diagnostics of one window (segment).

    Attributes
    ----------
    mu_k, mu_s : float
        Consensus (median over starts of the tail mean) of the observer estimates [-].
    mu_k_spread, mu_s_spread : float
        Max − min of the starts' tail means [-].
    settling_time_s : float or None
        Time from the window start after which every start's μ̂_k stays within
        ±max(5 %, 0.01) of the consensus [s]; None if never.
    converged : bool
        Settled before the tail began and spread inside the band.
    residual_rms_rpm : float
        RMS of the innovation ω̂₀ − ω₀ over the tail, all starts [RPM].
    stuck_fraction : float
        Fraction of samples after the start-up whose estimated BHA speed is within ±ω_c [-].
    stick_slip_severity : float
        (max − min)/(2·mean) of the estimated bit speed after the start-up (1st/99th
        percentiles) [-]; > 1 means the bit stops (full stick-slip), 0 is steady rotation.
    flags : tuple of str
    """

    mu_k: float
    mu_s: float
    mu_k_spread: float
    mu_s_spread: float
    settling_time_s: float | None
    converged: bool
    residual_rms_rpm: float
    stuck_fraction: float
    stick_slip_severity: float
    flags: tuple = field(default_factory=tuple)


def settled_mask(time_s: np.ndarray) -> np.ndarray:
    """Samples after the start-up (rest, ramp): from min(:data:`STARTUP_S`, 30 % of the
    window) after its start."""
    span = time_s[-1] - time_s[0]
    return time_s >= time_s[0] + min(STARTUP_S, 0.3 * span)


def tail_mask(time_s: np.ndarray, fraction: float = TAIL_FRACTION) -> np.ndarray:
    """Samples in the last ``fraction`` of the window."""
    t0, t1 = time_s[0], time_s[-1]
    return time_s >= t1 - fraction * (t1 - t0)


def settling_time(time_s: np.ndarray, mu: np.ndarray, target: float) -> float | None:
    """First time after which every start stays within the settle band of ``target`` [s].

    Parameters
    ----------
    time_s : ndarray, shape (R,)
    mu : ndarray, shape (R, S)
    target : float
    """
    band = max(SETTLE_BAND * abs(target), SETTLE_FLOOR)
    outside = np.any(np.abs(mu - target) > band, axis=1)
    if not outside.any():
        return 0.0
    last = int(np.flatnonzero(outside)[-1])
    if last == time_s.size - 1:
        return None
    return float(time_s[last + 1] - time_s[0])


def stick_slip_severity(bit_rad_s: np.ndarray) -> float:
    """(ω_max − ω_min)/(2·ω_mean) of a bit-speed series, robust percentiles [-].

    Examples
    --------
    >>> round(stick_slip_severity(np.array([0.0, 2.0] * 50)), 2)
    1.0
    """
    mean = float(np.mean(bit_rad_s))
    if abs(mean) < 1e-9:
        return 0.0
    hi, lo = np.percentile(bit_rad_s, [99.0, 1.0])
    return float((hi - lo) / (2.0 * abs(mean)))


def diagnose(record, omega_c_rad_s: float) -> Diagnostics:
    """Diagnostics of an :class:`~drillfric.estimation.observer.ObserverRecord`.

    Parameters
    ----------
    record : ObserverRecord
    omega_c_rad_s : float
        Static/kinetic switching speed ω_c [rad/s].
    """
    tail = tail_mask(record.time_s)
    mu_k_tail = record.mu_k[tail].mean(axis=0)
    mu_s_tail = record.mu_s[tail].mean(axis=0)
    mu_k = float(np.median(mu_k_tail))
    mu_s = float(np.median(mu_s_tail))
    spread_k = float(np.ptp(mu_k_tail))
    settle = settling_time(record.time_s, record.mu_k, mu_k)
    tail_start = float(record.time_s[tail][0] - record.time_s[0])
    band = max(SETTLE_BAND * mu_k, SETTLE_FLOOR)
    converged = settle is not None and settle <= tail_start and spread_k <= 2 * band
    flags = []
    if not converged:
        flags.append("not_converged")
    if np.any(record.deadlock_events > 0):
        flags.append("deadlock_averted")
    best = int(np.argmin(np.abs(mu_k_tail - mu_k)))
    late = settled_mask(record.time_s)
    bit = record.bit_rad_s_est[late, best]
    return Diagnostics(
        mu_k=mu_k, mu_s=mu_s, mu_k_spread=spread_k, mu_s_spread=float(np.ptp(mu_s_tail)),
        settling_time_s=settle, converged=bool(converged),
        residual_rms_rpm=float(np.sqrt(np.mean(record.residual_rad_s[tail] ** 2))
                               / RPM_TO_RAD_S),
        stuck_fraction=float(np.mean(np.abs(record.bha_rad_s_est[late, best])
                                     <= omega_c_rad_s)),
        stick_slip_severity=stick_slip_severity(bit), flags=tuple(flags))
