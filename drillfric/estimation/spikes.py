"""Isolated spikes and drop-outs in a fast log, found and dropped before estimation (issue
34 item 4, docs/ingestion.md "EDR defects").

An acquisition system writes the occasional single-sample spike (a bit error, a
multiplexer glitch: up to 10× the value) or drop-out (0 for a sample) into a speed or
torque channel. In a fast log neither can be motion: the string's fastest motion is its
first torsional mode, a cycle of 4 wave travel times (docs/theory.md §3, 3.3 s at 2300 m),
and one or two samples that jump to 3 times the median of their 5-sample neighbourhood or
drop below a tenth of it (by more than a quarter of the channel's typical magnitude and
far more than its noise) move faster than that once the
cycle spans at least :data:`MIN_SAMPLES_PER_CYCLE` samples. Such samples are dropped; the
measurement grid bridges them by linear interpolation
(:class:`~drillfric.estimation.observer.Measurements`).
In a slower log a slip peak may be 1–2 samples wide: there only a spike beyond
:data:`SLOW_SPIKE_FACTOR` times its neighbourhood is taken, which no motion reaches.

A steady step (a set-point change, the torque drop of a slip) is never taken: the median of
a window centred on a step's edge is the level the sample is at.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import median_filter

from drillfric.estimation.creep import true_runs
from drillfric.units import RPM_TO_RAD_S

#: Half the neighbourhood [samples]: a pulse of up to this many samples is isolated (an
#: EDR's spikes and drop-outs are single samples, two where they happen to fall side by
#: side: 1 in 10 of them at 5 % of the samples; a soft drive's speed dips last 3 samples or
#: more at 32 samples per cycle and are kept).
HALF_WINDOW = 2
#: A sample is a spike where it leaves the running median of its neighbourhood by more than
#: this many robust standard deviations of the channel (1.4826 × the median absolute
#: deviation from the running median over the whole segment: a local one, from 7 samples,
#: took 6 % of the demo's noisy samples for spikes)...
THRESHOLD = 8.0
#: ...and beyond this share of the channel's median magnitude (so that noise about 0 — a
#: stopped top drive's ±600 N·m and ±2 RPM on the demo, the 24 h benchmark well's torque
#: passing through 0 — is not taken: a 2 % floor took 17–43 samples of each clean demo
#: stand, 10 % 90–110 of each benchmark stand)...
FLOOR_SHARE = 0.25
#: ...and by a factor of the running median itself: above this many times it (a spike of
#: 10×), or below this share of it (a drop-out to about 0). Motion stays within: the
#: torque's reflections off the BHA make pulses of +20 % at 20 Hz (the demo), a slip's
#: torque peak one sample of 1.5× at 10 Hz (the second plant family's 3000-m string, which
#: a threshold of +50 % had taken for a spike).
SPIKE_FACTOR = 3.0
DROP_SHARE = 0.1
#: In a log too slow to tell a slip's peak from a spike (below :data:`MIN_SAMPLES_PER_CYCLE`),
#: only a spike beyond this many times its neighbourhood's median is taken: no motion of the
#: string reaches it at the surface (a slip's torque peak is 1.5–2.5× the mean, a soft
#: drive's speed overshoot under 2×), and 10× spikes had left μ_k unconverged at 5 and 1 Hz
#: (benchmarks/validate_edr.py).
SLOW_SPIKE_FACTOR = 5.0
#: Samples per shortest stick-slip cycle (4 × the wave travel time) from which one sample
#: is under a thirtieth of the string's fastest motion (a soft drive's speed dips to near 0
#: for about a tenth of its cycle: 3 samples or more).
MIN_SAMPLES_PER_CYCLE = 32
#: Shortest held value: one reading repeated exactly for this long [s] (issue 34: a device
#: that stops updating holds its last value for 1–10 s)...
HOLD_MIN_S = 1.0
#: ...and over at least this many samples (a value read twice in a row is common in a log
#: written to one decimal)...
HOLD_MIN_SAMPLES = 3
#: ...and so long that the log would show one that long by chance fewer than this many
#: times: n_pairs · p^(samples − 1), p the share of consecutive samples that repeat outside
#: such runs (a channel written coarser than its noise repeats often, and is left alone)...
HOLD_CHANCE = 0.01
#: ...in a channel where such runs cover at most this share of the samples (beyond, the
#: channel is steady below its resolution or forward-filled at a slower rate: "Logging
#: rate" in docs/bit_speed.md, not a defect).
HOLD_MAX_SHARE = 0.2


def isolated_spikes(x, factor: float = SPIKE_FACTOR, drops: bool = True) -> np.ndarray:
    """Where ``x`` (samples of one channel, uniformly spaced) has an isolated spike (beyond
    ``factor`` times its neighbourhood's median) or, with ``drops``, a drop-out (module
    docstring): a boolean mask.

    Examples
    --------
    >>> x = np.full(50, 60.0) + np.sin(np.arange(50) / 5.0)
    >>> x[20], x[35] = 600.0, 0.0
    >>> np.flatnonzero(isolated_spikes(x)).tolist()
    [20, 35]
    >>> step = np.r_[np.full(25, 60.0), np.full(25, 40.0)]
    >>> bool(isolated_spikes(step).any())
    False
    """
    x = np.asarray(x, dtype=float)
    size = 2 * HALF_WINDOW + 1
    if x.size < size:
        return np.zeros(x.size, dtype=bool)
    level = median_filter(x, size=size, mode="nearest")
    deviation = np.abs(x - level)
    spread = 1.4826 * float(np.median(deviation))
    floor = FLOOR_SHARE * float(np.median(np.abs(x)))
    off = np.abs(x) > factor * np.abs(level)
    if drops:
        off |= np.abs(x) < DROP_SHARE * np.abs(level)
    return off & (deviation > max(THRESHOLD * spread, floor))


def lost_torque(surface_rpm, torque_Nm) -> np.ndarray:
    """Runs of samples whose torque reads exactly 0 while the top drive turns at half its
    median speed or more, between samples that read more than :data:`FLOOR_SHARE` of the
    channel's median magnitude (a boolean mask): a turning string carries its friction
    torque, so such a run is torque the acquisition lost (the eighth attack of issue 30:
    1-s bursts of zeros every 10 s gave μ_k 0.251 for 0.28), at any rate. A torque that
    hovers about 0 and reads 0 on its way is not taken.

    Examples
    --------
    >>> q = np.full(12, 9e3)
    >>> q[[2, 3]] = 0.0  # lost
    >>> q[[7, 8, 9]] = 300.0, 0.0, -200.0  # passing through 0
    >>> np.flatnonzero(lost_torque(np.full(12, 60.0), q)).tolist()
    [2, 3]
    """
    w = np.abs(np.asarray(surface_rpm, dtype=float))
    q = np.asarray(torque_Nm, dtype=float)
    if q.size < 3:
        return np.zeros(q.size, dtype=bool)
    turning = (w >= 0.5 * float(np.median(w))) & (w > 0.0)
    return _zeros_between(q, turning, FLOOR_SHARE * float(np.median(np.abs(q))))


def lost_speed(time_s, surface_rpm, torque_Nm, top_drive_inertia_kg_m2: float) -> np.ndarray:
    """Runs of samples whose speed reads exactly 0 between samples the top drive could not
    have reached from rest within one sample (a boolean mask): more than twice the
    segment's largest torque can accelerate its inertia in a sample spacing,
    2·max|τ|·Δt/I_TD (docs/theory.md §3, eq. 7), and more than :data:`FLOOR_SHARE` of the
    channel's median magnitude. A speed that decelerates to rest as a top drive can is kept
    (the eighth attack of issue 30: 5 % of the speed samples read 0 at 110 RPM, some two
    and three side by side, and drew a trace 21 RPM RMS from the bit's).

    Examples
    --------
    >>> rpm = np.full(12, 110.0)
    >>> rpm[[3, 4, 5]] = 0.0  # lost
    >>> rpm[8:] = 3.0, 1.0, 0.0, 0.0  # coming to rest
    >>> np.flatnonzero(lost_speed(np.arange(12) * 0.05, rpm, np.full(12, 20e3), 2900.0))
    array([3, 4, 5])
    """
    t = np.asarray(time_s, dtype=float)
    w = np.asarray(surface_rpm, dtype=float)
    if w.size < 3:
        return np.zeros(w.size, dtype=bool)
    step_rpm = (2.0 * float(np.max(np.abs(torque_Nm))) * float(np.median(np.diff(t)))
                / top_drive_inertia_kg_m2) / RPM_TO_RAD_S
    jump = max(step_rpm, FLOOR_SHARE * float(np.median(np.abs(w))))
    return _zeros_between(w, np.ones(w.size, dtype=bool), jump)


def _zeros_between(x: np.ndarray, candidate: np.ndarray, beyond: float) -> np.ndarray:
    """Runs of exact zeros of ``x`` where ``candidate`` holds, with a sample on each side
    whose magnitude exceeds ``beyond`` (a boolean mask)."""
    lost = np.zeros(x.size, dtype=bool)
    for first, last in true_runs((x == 0.0) & candidate):
        if first > 0 and last + 1 < x.size and min(abs(x[first - 1]), abs(x[last + 1])) > beyond:
            lost[first:last + 1] = True
    return lost


def held_values(time_s, x) -> np.ndarray:
    """Samples that repeat an earlier reading of ``x`` exactly, in runs no chance repeat
    explains (a boolean mask; the run's first sample, the real reading, is not in it): runs
    of one non-zero value lasting :data:`HOLD_MIN_S` and :data:`HOLD_MIN_SAMPLES`, rarer by
    chance than :data:`HOLD_CHANCE` given the channel's own repeat rate, in a channel where
    they cover at most :data:`HOLD_MAX_SHARE` (module constants). A value of 0 is left to
    :func:`lost_torque` and :func:`lost_speed` (a stopped top drive reads 0 for minutes).

    Examples
    --------
    >>> t = np.arange(100) * 0.1
    >>> x = 60.0 + np.sin(t)
    >>> x[40:60] = x[40]  # held for 2 s
    >>> np.flatnonzero(held_values(t, x)).tolist() == list(range(41, 60))
    True
    """
    t = np.asarray(time_s, dtype=float)
    x = np.asarray(x, dtype=float)
    held = np.zeros(x.size, dtype=bool)
    if x.size < HOLD_MIN_SAMPLES:
        return held
    same = x[1:] == x[:-1]
    runs = [(i, j + 1) for i, j in true_runs(same)
            if j + 2 - i >= HOLD_MIN_SAMPLES and t[j + 1] - t[i] >= HOLD_MIN_S and x[i] != 0]
    pairs_in_runs = sum(last - first for first, last in runs)
    if pairs_in_runs > HOLD_MAX_SHARE * same.size:
        return held
    chance = max(float(same.sum()) - pairs_in_runs, 1.0) / same.size
    for first, last in runs:
        if same.size * chance ** (last - first) < HOLD_CHANCE:
            held[first + 1:last + 1] = True
    return held


def spans_s(time_s, mask) -> tuple[tuple[float, float], ...]:
    """[s] From the sample before each run of ``mask`` to the sample after it (the run's
    ends where it starts or ends the record).

    Examples
    --------
    >>> spans_s(np.arange(6.0), np.array([0, 1, 1, 0, 0, 1], dtype=bool))
    ((0.0, 3.0), (4.0, 5.0))
    """
    t = np.asarray(time_s, dtype=float)
    return tuple((float(t[max(a - 1, 0)]), float(t[min(b + 1, t.size - 1)]))
                 for a, b in true_runs(np.asarray(mask, dtype=bool)))


def defects(time_s, cycle_s: float, surface_rpm, torque_Nm,
            top_drive_inertia_kg_m2: float) -> np.ndarray:
    """Samples to drop (a boolean mask): torque or speed lost while turning
    (:func:`lost_torque`, :func:`lost_speed`), and, where the shortest stick-slip cycle
    ``cycle_s`` [s] spans at least :data:`MIN_SAMPLES_PER_CYCLE` samples of ``time_s`` [s],
    isolated spikes and drop-outs of the speed or the torque (:func:`isolated_spikes`);
    in a slower log only spikes beyond :data:`SLOW_SPIKE_FACTOR`."""
    t = np.asarray(time_s, dtype=float)
    drop = lost_torque(surface_rpm, torque_Nm) | lost_speed(t, surface_rpm, torque_Nm,
                                                             top_drive_inertia_kg_m2)
    if t.size < 2:
        return drop
    if cycle_s / float(np.median(np.diff(t))) < MIN_SAMPLES_PER_CYCLE:
        return (drop | isolated_spikes(surface_rpm, SLOW_SPIKE_FACTOR, drops=False)
                | isolated_spikes(torque_Nm, SLOW_SPIKE_FACTOR, drops=False))
    return drop | isolated_spikes(surface_rpm) | isolated_spikes(torque_Nm)
