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
  samples (:func:`held_interval_s`);
- the width of a moving average written at the full rate: an acquisition system that
  smooths a channel over w samples and logs every sample looks like a fast log but holds
  no more than one value per w samples (:func:`moving_average_s`).

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
#: Moving averages: the spectrum of the sample-to-sample differences of a w-sample moving
#: average is |2 sin(π f w Δt)|²/w² times the raw signal's, with a null at every multiple of
#: 1/(w Δt). A log is taken as smoothed when the mean log-power at those frequencies lies
#: this far below the mean log-power half-way between them (e³ ≈ 20×; raw logs of the demo,
#: the 24 h benchmark well and the real field logs score −0.2 … −1.5, moving averages of
#: 1–5 s at 20 Hz −5 … −9: docs/bit_speed.md "Smoothed logs").
SMOOTHED_DEPTH = 3.0
#: ...with at least this many nulls below the Nyquist frequency (fewer cannot be told from
#: the raw spectrum's own dips)...
SMOOTHED_MIN_NULLS = 4
#: ...scored at the nulls in the upper half of the band only (frequencies ≥ this many
#: cycles per sample, where the noise, not the signal, fills a raw log's spectrum): a
#: stick-slip torque of nearly half-wave-symmetric shape has mostly odd harmonics, a comb
#: with nulls at the even ones, which over the whole band took a 5-Hz spot-sampled lumped
#: record's torque for a 2.2-s moving average (docs/bit_speed.md "Smoothed logs")...
SMOOTHED_BAND = 0.25
#: ...and at least this many samples (the spectrum's resolution: nulls 4 bins apart at the
#: widest width looked at, a quarter of an 8192-sample block: 20 s at 100 Hz).
SMOOTHED_MIN_SAMPLES = 1024
_WELCH_SAMPLES = 8192
_BLOCKS = 32
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
        What sets it: "samples" (the spacing), "means" (averaging), "held values" or
        "moving averages".
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


def moving_average_s(time_s, *series, echo_s: float | None = None) -> float | None:
    """Width of a moving average written at the full rate [s], or None (module docstring).

    For each of ``series`` and each width w of 2·:data:`SMOOTHED_MIN_NULLS` + 1 …
    :data:`_WELCH_SAMPLES`/4 samples whose nulls lie at least 4 bins apart, the score is
    the mean of log P(k/(wΔt)) − log P((k + ½)/(wΔt)) over its nulls in the upper half of
    the band (:data:`SMOOTHED_BAND`), P the median spectrum of the sample-to-sample
    differences (:func:`_median_spectrum`); a width counts only where a quarter spacing
    from its nulls keeps power (a comb of nulls, not of a periodic signal's lines). A score
    at or below −:data:`SMOOTHED_DEPTH` says the series is smoothed; of the widths that
    score within 70 % of the deepest, the widest is the moving average's (the nulls of w
    samples are also those of its divisors). Returns the widest over the series times the
    median sample spacing.

    ``echo_s``: the string's round-trip wave travel time [s]. A torque wave and its echo
    off the bit, τ(t) ∝ g(t) − g(t − echo_s), put the same comb of nulls into the spectrum
    as a moving average of that width (the second plant family's 3000-m string at 5 Hz:
    2.2 s); widths within 10 % of echo_s/j, j = 1, 2, …, are not taken.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> t = np.arange(20000) * 0.05
    >>> x = np.cumsum(rng.normal(size=t.size)) + rng.normal(size=t.size)
    >>> moving_average_s(t, x) is None
    True
    >>> smoothed = np.convolve(x, np.ones(40) / 40, mode="valid")
    >>> round(moving_average_s(t[:smoothed.size], smoothed), 6)
    2.0
    """
    t = np.asarray(time_s, dtype=float)
    if t.size < SMOOTHED_MIN_SAMPLES:
        return None
    dt = float(np.median(np.diff(t)))
    echo = None if not echo_s else echo_s / dt
    widths = [w for w in (_smoothed_width(np.asarray(x, dtype=float), echo) for x in series)
              if w is not None]
    return max(widths) * dt if widths else None


def _smoothed_width(x: np.ndarray, echo: float | None = None) -> int | None:
    """The moving average's width in samples (:func:`moving_average_s`), or None."""
    d = np.diff(x[np.isfinite(x)])
    if d.size < SMOOTHED_MIN_SAMPLES or not np.any(d):
        return None
    f, power = _median_spectrum(d)
    log_p = np.log(power + 1e-300 + 1e-12 * power.max())
    widths, nulls = _NULLS
    # nulls ≥ 4 bins apart in this spectrum, in its upper half: a stick-slip cycle's odd
    # harmonics make a comb of their own below (see SMOOTHED_BAND)
    resolved = (widths <= (f.size - 1) // 2) & (nulls / widths >= SMOOTHED_BAND)
    if echo:  # the string's echo and its divisors [samples] (moving_average_s)
        j = np.maximum(np.round(echo / widths), 1.0)
        resolved &= np.abs(widths * j - echo) > 0.1 * echo
    widths, nulls = widths[resolved], nulls[resolved]
    at = np.interp(nulls / widths, f, log_p)
    candidates = np.unique(widths)
    if candidates.size == 0:
        return None
    count = np.bincount(widths)[candidates]

    def mean_gap(offset: float) -> np.ndarray:
        """Per width: mean log-power at the nulls minus at ``offset`` of a null spacing."""
        gap = at - np.interp((nulls + offset) / widths, f, log_p)
        return np.bincount(widths, weights=gap)[candidates] / count

    scores = mean_gap(0.5)
    # a comb of nulls, not of lines: a quarter spacing from a null a moving average keeps
    # half its peak power, a line spectrum (a periodic signal) its floor
    comb = mean_gap(0.25) <= 0.5 * scores
    if not comb.any() or scores[comb].min() > -SMOOTHED_DEPTH:
        return None
    deepest = float(scores[comb].min())
    return int(candidates[comb & (scores <= 0.7 * deepest)].max())


def _median_spectrum(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies [cycles per sample] and the median over at most :data:`_BLOCKS` Hann
    periodograms of :data:`_WELCH_SAMPLES`-sample blocks spread evenly over ``d`` (a
    median, so that a jump or a gap in a few blocks does not fill the nulls; a bounded
    number of blocks, so that a long segment costs no more than a few)."""
    from scipy.signal import periodogram

    n = min(d.size, _WELCH_SAMPLES)
    blocks = int(min(_BLOCKS, max(1, 2 * d.size // n - 1)))
    starts = np.linspace(0, d.size - n, blocks).astype(int)
    f, power = periodogram(d[starts[:, None] + np.arange(n)], window="hann",
                           detrend="constant", axis=-1)
    return f, np.median(power, axis=0)


def _null_table() -> tuple[np.ndarray, np.ndarray]:
    """Every (width w, null k) pair :func:`_smoothed_width` looks at: w from
    2·:data:`SMOOTHED_MIN_NULLS` + 1 to a quarter of a Welch segment, k = 1 … (w − 1)/2."""
    widths = np.arange(2 * SMOOTHED_MIN_NULLS + 1, _WELCH_SAMPLES // 4 + 1)
    counts = (widths - 1) // 2
    w = np.repeat(widths, counts)
    k = np.arange(w.size) - np.repeat(np.cumsum(counts) - counts, counts) + 1
    return w, k


_NULLS = _null_table()


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
                     torque_max_Nm=None, echo_s: float | None = None) -> LoggingInterval:
    """The effective interval of a segment's log (module docstring); ``model_dt_s`` is the
    step the estimator resamples to when it is coarser than the log (``run --rate``) [s];
    ``echo_s`` the string's round-trip wave travel time [s] (:func:`moving_average_s`)."""
    t = np.asarray(time_s, dtype=float)
    spacing = max(float(np.median(np.diff(t))) if t.size > 1 else 0.0, model_dt_s or 0.0)
    swing = None
    if torque_min_Nm is not None and torque_max_Nm is not None:
        swing = interval_torque_swing(torque_Nm, torque_min_Nm, torque_max_Nm)
        if swing is not None:
            averaging_s = max(averaging_s or 0.0, spacing)
    # each channel on its own: a torque sampled and held at 1 Hz beside a 10-Hz speed holds
    # the estimate to 1-s torques (a ninth attack's trace, 48 RPM RMS, was shown resolved)
    held = max(held_interval_s(t, surface_rpm) or 0.0, held_interval_s(t, torque_Nm) or 0.0)
    # held values are a moving average of their hold over their updates: said as held
    smoothed = 0.0 if held else moving_average_s(t, surface_rpm, torque_Nm,
                                                  echo_s=echo_s) or 0.0
    candidates = [(averaging_s or 0.0, "means"), (held, "held values"),
                  (smoothed, "moving averages"), (spacing, "samples")]
    interval, kind = max(candidates, key=lambda c: c[0])
    return LoggingInterval(interval, kind, swing)


def resolution(logged: LoggingInterval, period_s: float) -> Resolution:
    """Whether ``logged`` resolves a stick-slip cycle of ``period_s`` [s] (the shortest)."""
    per_cycle = period_s / max(logged.interval_s, 1e-12)
    if per_cycle >= MIN_SAMPLES_PER_CYCLE:
        return Resolution(True, per_cycle)
    fix = ("log the raw samples (the acquisition system's smoothing off) to see the bit"
           if logged.kind == "moving averages" else
           f"log at ≥ {MIN_SAMPLES_PER_CYCLE / period_s:.2g} Hz to see the bit")
    reason = (f"bit speed not resolved: {logged.interval_s:.3g}-s {logged.kind} give "
              f"{per_cycle:.2g} per stick-slip cycle (the shortest, {period_s:.2g} s, needs "
              f"≥ {MIN_SAMPLES_PER_CYCLE:g}); {fix}")
    if logged.torque_swing is not None:
        verdict = ("the string is probably stick-slipping" if logged.torque_swing
                   > STICK_SLIP_SWING else "no sign of stick-slip")
        reason += (f" (the torque swings by {100 * logged.torque_swing:.0f} % of its mean "
                   f"within each interval: {verdict})")
    return Resolution(False, per_cycle, reason)
