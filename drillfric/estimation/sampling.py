"""How a segment was logged, and whether that resolves the stick-slip cycle.

A bit-speed trace, a stuck fraction and a creep fit mean something only when the log samples
the motion they describe. What matters is the **effective interval** of the log, the largest
of (docs/bit_speed.md "Logging rate"):

- the sample spacing;
- the averaging interval of each sample: ``rig.sample_averaging_s`` (EDR means); a log that
  carries the torque's interval minimum and maximum is made of interval aggregates, so its
  spacing is its averaging interval;
- the update interval of held values: a log resampled from a slower one (forward-filled)
  repeats each value until the next update, so the speed and torque change only every k
  samples (:func:`held_interval_s`).

The shortest stick-slip cycle is the string's first torsional period, a quarter wave from
the top drive to the free bit: 4 × the wave travel time (docs/theory.md §3). Below
:data:`MIN_SAMPLES_PER_CYCLE` effective samples per cycle the bit speed is not resolved. The
torque's interval minimum and maximum still show whether the string stick-slips
(:func:`interval_torque_swing`), which the reason then says.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Effective samples per shortest stick-slip cycle needed for a bit-speed trace: the
#: validation's 5-Hz records (≈ 16 per cycle at 2300 m) kept the severe stick-slip error at
#: 25–31 RPM; 1-Hz ones (≈ 3) follow the cycle only in the mean (docs/bit_speed.md).
MIN_SAMPLES_PER_CYCLE = 6.0
#: Held values: share of the changes that must come at one regular step for the log to be
#: taken as resampled from a slower one, and the least number of changes looked at.
HELD_SHARE, HELD_MIN_CHANGES = 0.8, 10
#: Relative torque swing within an interval, (max − min)/|mean|, above which the string is
#: said to stick-slip: a sinusoidal swing of the batch fit's stick-slip threshold (std/mean
#: 0.1, docs/theory.md §6.4) spans 2√2·0.1 ≈ 0.3.
STICK_SLIP_SWING = 0.3


@dataclass(frozen=True)
class LoggingInterval:
    """The effective interval of a segment's log.

    Attributes
    ----------
    interval_s : float
        Effective sample interval [s].
    kind : str
        What sets it: "samples" (the spacing), "means" (averaging) or "held values".
    torque_swing : float or None
        Median (max − min)/|mean| of the torque within each logged interval [-]; None
        without min/max channels.
    """

    interval_s: float
    kind: str
    torque_swing: float | None = None


@dataclass(frozen=True)
class Resolution:
    """Whether the logging resolves the stick-slip cycle.

    Attributes
    ----------
    resolved : bool
    samples_per_cycle : float
        Shortest stick-slip cycle over the effective sample interval [-].
    reason : str
        Why not ("" when resolved).
    """

    resolved: bool
    samples_per_cycle: float
    reason: str = ""


def held_interval_s(time_s, *series) -> float | None:
    """Update interval of a log whose values are held between updates [s], or None.

    The samples where any of ``series`` changes are the updates; when at least
    :data:`HELD_SHARE` of the steps between updates are within ±20 % (±1 sample) of their
    median, and that median is ≥ 2 samples, the log repeats each value for that many
    samples. Quantised spot values also repeat, but at irregular steps.

    Examples
    --------
    >>> t = np.arange(100.0)
    >>> held_interval_s(t, np.repeat(np.arange(20.0), 5))
    5.0
    >>> held_interval_s(t, np.arange(100.0)) is None
    True
    """
    t = np.asarray(time_s, dtype=float)
    if t.size < 3:
        return None
    changed = np.zeros(t.size - 1, dtype=bool)
    for s in series:
        v = np.asarray(s, dtype=float)
        changed |= np.diff(v) != 0
    steps = np.diff(np.flatnonzero(changed))
    if steps.size < HELD_MIN_CHANGES:
        return None
    median = float(np.median(steps))
    regular = np.abs(steps - median) <= max(1.0, 0.2 * median)
    if median < 2 or np.mean(regular) < HELD_SHARE:
        return None
    return float(np.mean(steps[regular])) * float(np.median(np.diff(t)))


def interval_torque_swing(mean_Nm, min_Nm, max_Nm) -> float | None:
    """Median relative torque swing within each logged interval, (max − min)/|mean| [-].

    Examples
    --------
    >>> interval_torque_swing([10.0, 10.0], [6.0, 7.0], [14.0, 13.0])
    0.7
    """
    mean, lo, hi = (np.asarray(x, dtype=float) for x in (mean_Nm, min_Nm, max_Nm))
    ok = np.isfinite(mean) & np.isfinite(lo) & np.isfinite(hi) & (np.abs(mean) > 0)
    if not ok.any():
        return None
    return float(np.median((hi[ok] - lo[ok]) / np.abs(mean[ok])))


def logging_interval(time_s, surface_rpm, torque_Nm, *, averaging_s: float | None = None,
                     model_dt_s: float | None = None, torque_min_Nm=None,
                     torque_max_Nm=None) -> LoggingInterval:
    """The effective interval of a segment's log (module docstring); ``model_dt_s`` is the
    step the estimator resamples to when it is coarser than the log (``run --rate``) [s]."""
    t = np.asarray(time_s, dtype=float)
    spacing = max(float(np.median(np.diff(t))) if t.size > 1 else 0.0, model_dt_s or 0.0)
    swing = None
    if torque_min_Nm is not None and torque_max_Nm is not None:
        swing = interval_torque_swing(torque_Nm, torque_min_Nm, torque_max_Nm)
        if swing is not None:
            averaging_s = max(averaging_s or 0.0, spacing)
    held = held_interval_s(t, surface_rpm, torque_Nm) or 0.0
    candidates = [(averaging_s or 0.0, "means"), (held, "held values"), (spacing, "samples")]
    interval, kind = max(candidates, key=lambda c: c[0])
    return LoggingInterval(interval, kind, swing)


def resolution(logged: LoggingInterval, period_s: float) -> Resolution:
    """Whether ``logged`` resolves a stick-slip cycle of ``period_s`` [s] (the shortest)."""
    per_cycle = period_s / max(logged.interval_s, 1e-12)
    if per_cycle >= MIN_SAMPLES_PER_CYCLE:
        return Resolution(True, per_cycle)
    reason = (f"bit speed not resolved: {logged.interval_s:.3g}-s {logged.kind} give "
              f"{per_cycle:.2g} per stick-slip cycle (the shortest, {period_s:.2g} s, needs "
              f"≥ {MIN_SAMPLES_PER_CYCLE:g}); log at ≥ {MIN_SAMPLES_PER_CYCLE / period_s:.2g} "
              "Hz to see the bit")
    if logged.torque_swing is not None:
        verdict = ("the string is probably stick-slipping" if logged.torque_swing
                   > STICK_SLIP_SWING else "no sign of stick-slip")
        reason += (f" (the torque swings by {100 * logged.torque_swing:.0f} % of its mean "
                   f"within each interval: {verdict})")
    return Resolution(False, per_cycle, reason)
