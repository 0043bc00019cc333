"""Rig-state classification and segmentation of surface data into rotating stands.

Implements part 1 of the ``drillfric run`` job (issue 6): every sample gets a rig state
from whatever channels exist, and the rotating stretches are cut into segments (stands,
sections) that carry their kind (on/off bottom), bit depth, duration and a status. The
friction estimation of Aarsnes et al. (JPSE 2019) runs per segment: a segment is one
load case (docs/theory.md §2 item 5: bit boundary off bottom, or on bottom with WOB) at one
string length.

Rules and thresholds (config table ``[segmentation]``) are documented in
docs/segmentation.md; the agreement with published rig-state labels is in
docs/validation.md.

The classifier is causal (each sample depends on the past only, through a small carried
state) and segments depend only on the samples between two non-rotating samples or time
gaps, so :class:`Segmenter` reproduces :func:`segment` exactly on data fed in chunks.
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from drillfric.config import Config
from drillfric.errors import InputError
from drillfric.kernels.lazy import lazy_jit
from drillfric.vocabulary import STATE_KINDS, Kind, RigState

#: Rig states, coded by their position (``np.int8``; new states are appended, codes never
#: move). ``sliding_on_bottom`` (on bottom with the pumps on but no surface rotation: motor
#: drilling), ``reaming`` and ``back_reaming`` (rotating off bottom while the pipe runs in
#: or pulls out faster than ``ream_speed_m_s``) are drillfric's additions.
RIG_STATES = tuple(state.text for state in RigState)
(ROTATING_OFF_BOTTOM, ROTATING_ON_BOTTOM, IN_SLIPS, TRIPPING, IDLE, UNKNOWN,
 SLIDING_ON_BOTTOM, REAMING, BACK_REAMING) = map(int, RigState)  # plain ints in the kernel
#: States that make hole ("drilling"): on bottom, rotating or sliding.
DRILLING_STATES = (ROTATING_ON_BOTTOM, SLIDING_ON_BOTTOM)
#: States in which the string turns (a segment is a run of them).
TURNING_STATES = (ROTATING_OFF_BOTTOM, ROTATING_ON_BOTTOM, REAMING, BACK_REAMING)
#: Segment kind of each turning state (docs/outputs.md ``kind`` values).
KINDS = STATE_KINDS
#: Kinds in which the pipe moves along the hole while it turns: the wall friction splits
#: between axial and tangential (docs/theory.md §3.3). Estimated with their axial speed
#: where it is steady over a short travel (:func:`axial_motion`), else skipped with why
#: (docs/segmentation.md "Reaming").
COMBINED_MOTION_KINDS = (Kind.REAMING, Kind.BACK_REAMING)

#: How the bit depth is known: measured channel, reckoned from the block, or not at all.
_DEPTH_CHANNEL, _DEPTH_BLOCK, _DEPTH_NONE = 0, 1, 2
#: Time constant of the first-order smoothing of the bit speed [s].
_SPEED_TAU_S = 5.0
#: Travel the bit must make for the pipe to count as moving along the hole while it turns
#: [m]: reaming needs the bit to have moved this far within the time it takes at
#: ``ream_speed_m_s`` (on a coarse log: within the last two sample intervals), besides a
#: smoothed speed above the gate. Without it the smoothed speed of the trip before a stand
#: carried "reaming" into the first ~6 s of rotation with the bit at rest (issue 35, the
#: demo's stand starts).
REAM_MIN_TRAVEL_M = 0.1


@dataclass(frozen=True)
class Segment:
    """One rotating stretch of the record (a stand or part of one).

    Attributes
    ----------
    id : int
        Running number, 1-based, in time order.
    kind : Kind
        Off or on bottom, reaming or back-reaming (the last two skipped where their axial
        speed is not steady or their travel too long: :func:`axial_motion`).
    t_start_s, t_end_s : float
        Times of the first and the last sample of the segment [s].
    i_start, i_end : int
        Row indices of the input, ``i_end`` exclusive.
    bit_depth_m : float
        Median bit depth over the segment [m] (NaN when the depth is not known).
    bit_depth_min_m, bit_depth_max_m : float
        Range of the bit depth over the segment [m] (NaN when not known).
    duration_s : float
        ``t_end_s - t_start_s`` [s].
    status : str
        ``"ok"`` or ``"skipped"``.
    message : str
        Why the segment is skipped ("" when ok).
    axial_speed_m_s : float or None
        Of a reaming (> 0, running in) or back-reaming (< 0) segment, the pipe's steady
        axial speed [m/s]: the median rate of the bit depth while it moves (None for the
        other kinds, or where it is not known; :func:`axial_motion`).
    axial_from_s, axial_to_s : float or None
        When the pipe moves at that speed within the segment [s] (None likewise).
    """

    id: int
    kind: Kind
    t_start_s: float
    t_end_s: float
    i_start: int
    i_end: int
    bit_depth_m: float
    bit_depth_min_m: float
    bit_depth_max_m: float
    duration_s: float
    status: str
    message: str
    axial_speed_m_s: float | None = None
    axial_from_s: float | None = None
    axial_to_s: float | None = None


# ----------------------------------------------------------------------------------------
# Classification


#: Time constant of the running level of the rotating torque, against which a speed dip is
#: judged loaded or released [s].
_LOAD_TAU_S = 10.0


def _still_turning(rpm, torque, t, turning, level, dip_start, rotating_rpm, stop_rpm,
                   dip_s, dip_fraction):
    """Rotation latch with hysteresis and loaded dips; returns (turning, dip start).

    Rotation starts above ``rotating_rpm`` and ends below ``stop_rpm`` — unless the string
    stays loaded: a dip below ``stop_rpm`` whose torque holds at least ``dip_fraction`` of
    the rotating torque level, for at most ``dip_s``, is part of the rotation (a soft-torque
    or slow top-drive controller lets the surface speed fall to ~0 between slips while the
    string stays wound up).
    """
    if np.isnan(rpm):
        return turning, dip_start
    if not turning:
        return rpm > rotating_rpm, np.nan
    if rpm > stop_rpm:
        return True, np.nan
    start = t if np.isnan(dip_start) else dip_start
    loaded = level > 0.0 and not np.isnan(torque) and abs(torque) >= dip_fraction * level
    if loaded and t - start <= dip_s:
        return True, start
    return False, np.nan


def _classify_kernel(time_s, rpm, torque_Nm, hookload_N, bit_in_m, hole_in_m, block_m, wob_N,
                     pumps, depth_mode, rotating_rpm, stop_rpm, dip_s, dip_fraction, slips_N,
                     on_bottom_m, wob_on_N, trip_m_s, max_rop_m_s, ream_m_s,
                     carry):
    """Causal per-sample rig state; updates ``carry`` in place (see :func:`classify`).

    Plain Python, compiled by numba for large inputs (:data:`_compiled_kernel`).

    ``carry`` = [previous time, previous block position, previous bit depth, hole depth,
    started flag, smoothed downward bit speed, rotating latch, rotating torque level,
    start of the current speed dip, bit depth and time at its last move by
    :data:`REAM_MIN_TRAVEL_M`]; ``pumps`` is 1 on, 0 off, -1 unknown. Rotation has
    hysteresis (:func:`_still_turning`): it starts above ``rotating_rpm`` and lasts until
    the speed drops below ``stop_rpm`` and the string is unloaded (speed noise at standstill
    does not chatter, a slow creep start-up stays inside its segment, and so do the brief
    stops of a soft-torque drive while the string stays wound up).
    """
    n = time_s.size
    states = np.empty(n, np.int8)
    bit_out = np.empty(n)
    t_prev, block_prev, bit_prev = carry[0], carry[1], carry[2]
    hole, have_prev, v_down = carry[3], carry[4], carry[5]
    turning = carry[6] > 0
    level, dip_start = carry[7], carry[8]
    anchor_bit, anchor_t = carry[9], carry[10]
    for i in range(n):
        in_slips = hookload_N[i] < slips_N  # False for NaN hook load or no threshold (NaN)
        bit = bit_prev
        if depth_mode == _DEPTH_CHANNEL:
            if not np.isnan(bit_in_m[i]):
                bit = bit_in_m[i]
        elif depth_mode == _DEPTH_BLOCK:
            if not np.isnan(block_m[i]):
                # the string moves with the block only while it hangs from the hook
                if not np.isnan(block_prev) and not in_slips:
                    bit = bit + block_prev - block_m[i]
                block_prev = block_m[i]
        dt = time_s[i] - t_prev
        if have_prev > 0 and dt > 0.0 and not np.isnan(bit) and not np.isnan(bit_prev):
            # first-order smoothing of the bit speed (time jitter, depth quantisation)
            v_down += ((bit - bit_prev) / dt - v_down) * min(1.0, dt / _SPEED_TAU_S)
        if depth_mode != _DEPTH_NONE:
            if depth_mode == _DEPTH_CHANNEL and not np.isnan(hole_in_m[i]):
                hole = hole_in_m[i]
            elif np.isnan(hole) or bit > hole:
                hole = bit
        if not np.isnan(bit) and not np.isnan(time_s[i]):
            if np.isnan(anchor_bit):
                anchor_bit = bit  # where the record starts is no move
            elif abs(bit - anchor_bit) >= REAM_MIN_TRAVEL_M:
                anchor_bit, anchor_t = bit, time_s[i]
        window = REAM_MIN_TRAVEL_M / ream_m_s
        if have_prev > 0 and dt > 0.0 and 2.0 * dt > window:
            window = 2.0 * dt  # a coarse log: the travel since the sample before last
        moving = not np.isnan(anchor_t) and time_s[i] - anchor_t <= window
        weighted = wob_N[i] > wob_on_N  # False when WOB is not recorded (NaN)
        # the bit below the hole's bottom cannot be: the hole-depth channel is wrong or
        # lagging, so the depths tell nothing here and the WOB alone decides (a hole depth
        # 20 m above the bit put every rotation on bottom: issue 30, tenth attack)
        below_hole = depth_mode == _DEPTH_CHANNEL and bit - hole > on_bottom_m
        if depth_mode != _DEPTH_NONE and not np.isnan(bit) and not below_hole:
            # going down faster than any drilling: running into hole that was already there
            on_bottom = hole - bit <= on_bottom_m and v_down <= max_rop_m_s
            near = hole - bit <= WOB_NEAR_BOTTOM_M
        else:
            on_bottom = weighted
            near = True
        was = turning
        turning, dip_start = _still_turning(rpm[i], torque_Nm[i], time_s[i], turning, level,
                                            dip_start, rotating_rpm, stop_rpm, dip_s,
                                            dip_fraction)
        # a turning bit with weight on it, within a stand of the hole's bottom, drills
        # whatever the depths say (a hole-depth channel 3 m deep labelled 30-kN drilling off
        # bottom: the bit torque went into μ_k); not while tripping, where a WOB computed
        # from the hook load reads the slack-off's drag
        on_bottom = on_bottom or (turning and weighted and near)
        if turning and rpm[i] > rotating_rpm and not np.isnan(torque_Nm[i]):
            dt_level = time_s[i] - t_prev if was and have_prev > 0 else _LOAD_TAU_S
            level += (abs(torque_Nm[i]) - level) * min(1.0, dt_level / _LOAD_TAU_S)
        elif not turning:
            level = 0.0
        if np.isnan(rpm[i]) or np.isnan(time_s[i]):
            state = UNKNOWN
        elif in_slips:
            state = IN_SLIPS
        elif turning and on_bottom:
            state = ROTATING_ON_BOTTOM
        elif turning and abs(v_down) > ream_m_s and moving:
            state = REAMING if v_down > 0.0 else BACK_REAMING
        elif turning:
            state = ROTATING_OFF_BOTTOM
        elif on_bottom and pumps[i] != 0:
            state = SLIDING_ON_BOTTOM  # pumps on, or not recorded
        elif abs(v_down) > trip_m_s:
            state = TRIPPING
        else:
            state = IDLE
        states[i] = state
        bit_out[i] = bit
        if not np.isnan(time_s[i]):
            t_prev = time_s[i]
            have_prev = 1.0
        bit_prev = bit
    carry[0], carry[1], carry[2] = t_prev, block_prev, bit_prev
    carry[3], carry[4], carry[5] = hole, have_prev, v_down
    carry[6] = 1.0 if turning else 0.0
    carry[7], carry[8] = level, dip_start
    carry[9], carry[10] = anchor_bit, anchor_t
    return states, bit_out


#: A turning bit with weight on it counts as on bottom within this depth of the hole's
#: bottom whatever the depth channels' gap says [m] (one stand).
WOB_NEAR_BOTTOM_M = 30.0

#: :func:`_classify_kernel` compiled (on first use); inputs up to :data:`_PLAIN_ROWS` rows
#: run the plain function (no numba import or kernel load for a small file).
_compiled_kernel = lazy_jit(_classify_kernel, _still_turning)
_PLAIN_ROWS = 20_000


def _column(frame: pd.DataFrame, name: str) -> np.ndarray:
    """Column as float64, or all-NaN when the channel is not recorded."""
    if name in frame:
        return frame[name].to_numpy(dtype=float)
    return np.full(len(frame), np.nan)


def pumps_on(frame: pd.DataFrame, cfg: Config) -> np.ndarray:
    """Pumps on (1), off (0) or not known (-1), from flow in, pump rate, else SPP."""
    for column, key in (("flow_in_m3_s", "pumps_on_m3_s"), ("pump_rate_spm", "pumps_on_spm"),
                        ("standpipe_pressure_Pa", "pumps_on_Pa")):
        if column in frame:
            values = frame[column].to_numpy(dtype=float)
            on = np.where(values > getattr(cfg.segmentation, key), 1, 0).astype(np.int8)
            on[np.isnan(values)] = -1
            return on
    return np.full(len(frame), -1, np.int8)


def _depth_mode(frame: pd.DataFrame) -> int:
    if "bit_depth_m" in frame:
        return _DEPTH_CHANNEL
    if "block_position_m" in frame:
        return _DEPTH_BLOCK
    return _DEPTH_NONE


def _new_carry(frame: pd.DataFrame, cfg: Config) -> np.ndarray:
    start = cfg.segmentation.start_bit_depth_m
    bit0 = 0.0 if _depth_mode(frame) == _DEPTH_BLOCK else np.nan
    if start is not None and _depth_mode(frame) == _DEPTH_BLOCK:
        bit0 = start
    return np.array([np.nan, np.nan, bit0, np.nan, 0.0, 0.0, 0.0, 0.0, np.nan, np.nan, np.nan])


def _classify(frame: pd.DataFrame, cfg: Config, carry: np.ndarray):
    """States and bit depth [m] of a chunk, continuing from ``carry`` (updated)."""
    missing = [name for name in ("time_s", "surface_rpm") if name not in frame]
    if missing:
        raise InputError(f"no {' or '.join(missing)} channel to segment",
                         fix="map the time and surface speed columns in [channels]")
    slips = cfg.segmentation.slips_hookload_N
    seg = cfg.segmentation
    kernel = _classify_kernel if len(frame) <= _PLAIN_ROWS else _compiled_kernel()
    states, bit = kernel(
        _column(frame, "time_s"), _column(frame, "surface_rpm"),
        _column(frame, "surface_torque_Nm"),
        _column(frame, "hookload_N"), _column(frame, "bit_depth_m"),
        _column(frame, "hole_depth_m"), _column(frame, "block_position_m"),
        _column(frame, "wob_N"), pumps_on(frame, cfg), _depth_mode(frame),
        float(seg.rotating_rpm), min(float(seg.rotating_stop_rpm), float(seg.rotating_rpm)),
        float(seg.dip_max_s), float(seg.dip_torque_fraction),
        np.nan if slips is None else float(slips),
        float(cfg.segmentation.on_bottom_m), float(cfg.segmentation.wob_on_bottom_N),
        float(cfg.segmentation.trip_speed_m_s),
        float(cfg.segmentation.max_rop_m_h) / 3600.0, float(cfg.segmentation.ream_speed_m_s),
        carry)
    absolute = (_depth_mode(frame) == _DEPTH_CHANNEL
                or cfg.segmentation.start_bit_depth_m is not None)
    return states, bit if absolute else np.full(len(frame), np.nan)


def classify(frame: pd.DataFrame, cfg: Config) -> np.ndarray:
    """Rig state of every sample (codes into :data:`RIG_STATES`).

    Rules, in order of precedence (thresholds from ``cfg.segmentation``, see
    docs/segmentation.md):

    1. ``unknown`` when the surface speed is null;
    2. ``in_slips`` when hook load < ``slips_hookload_N`` (string weight off the hook);
    3. rotating (``surface_rpm`` > ``rotating_rpm``): ``rotating_on_bottom`` when on bottom,
       else ``reaming`` / ``back_reaming`` when the smoothed bit speed exceeds
       ``ream_speed_m_s`` going down / up, else ``rotating_off_bottom``;
    4. not rotating: ``sliding_on_bottom`` when on bottom with the pumps on (or pumps not
       recorded), ``tripping`` when the smoothed bit speed exceeds ``trip_speed_m_s``,
       else ``idle``.

    On bottom means hole depth − bit depth ≤ ``on_bottom_m`` while the bit does not go down
    faster than ``max_rop_m_h`` (bit speed smoothed to first order, time constant
    :data:`_SPEED_TAU_S`). Where the hole-depth channel reads more than ``on_bottom_m``
    above the bit (which cannot be: the channel is wrong or lagging) the depths decide
    nothing: on bottom means ``wob_N`` > ``wob_on_bottom_N`` there (the run warns,
    :meth:`drillfric.io.logcheck.LogCheck.hole_above_note`). The bit depth is the
    ``bit_depth_m`` channel, else it is reckoned from ``block_position_m`` (the bit moves
    with the block except while in the slips); the hole depth is ``hole_depth_m``, else
    the running maximum of the bit depth. Without either depth channel, on bottom means
    ``wob_N`` > ``wob_on_bottom_N``; with neither, rotating samples count as off bottom.

    Parameters
    ----------
    frame : pandas.DataFrame
        Canonical surface channels (SI): ``time_s``, ``surface_rpm`` [RPM] and any of
        ``surface_torque_Nm``, ``hookload_N``, ``bit_depth_m``, ``hole_depth_m``,
        ``wob_N``, ``block_position_m``, ``standpipe_pressure_Pa``, ``flow_in_m3_s``,
        ``pump_rate_spm`` (NaN for nulls).
    cfg : Config
        Configuration (table ``[segmentation]``).

    Returns
    -------
    numpy.ndarray of int8
        State code per sample.
    """
    return _classify(frame, cfg, _new_carry(frame, cfg))[0]


# ----------------------------------------------------------------------------------------
# Segmentation


def is_gap(spacing_s, max_gap_s: float) -> np.ndarray:
    """Whether a time between samples [s] is a gap: longer than ``segmentation.max_gap_s``
    [s], where a segment ends. The one gap rule of the segmentation, of the log's check
    (:class:`drillfric.io.logcheck.LogCheck`: a median spacing that is a gap makes every
    sample one) and of the gaps ``inspect`` lists (:attr:`drillfric.io.timebase.TimeBase.gaps`).

    Examples
    --------
    >>> is_gap(np.array([1.0, 10.0, 10.5, np.nan]), 10.0)
    array([False, False,  True, False])
    """
    with np.errstate(invalid="ignore"):
        return np.asarray(spacing_s, dtype=float) > max_gap_s


def _pieces(t: np.ndarray, states: np.ndarray, max_gap_s: float) -> list[tuple[int, int]]:
    """Row ranges [start, end) of rotating stretches, split at long gaps and null runs.

    A stretch is a run of rotating or unknown samples; it is split where consecutive
    samples are more than ``max_gap_s`` apart and where a run of unknown samples lasts
    more than ``max_gap_s`` (between the rotating samples around it). Unknown samples at
    either end are trimmed; bridged unknown samples stay inside (the segment is then
    skipped for nulls).
    """
    rotating = np.isin(states, TURNING_STATES)
    rot_idx = np.flatnonzero(rotating)
    if rot_idx.size == 0:
        return []
    known_other = ~rotating & (states != UNKNOWN)
    # between consecutive rotating samples: cut if a known non-rotating sample lies between,
    # or the time between them exceeds max_gap_s (gap or long null run)
    n_other = np.concatenate(([0], np.cumsum(known_other)))
    between_other = n_other[rot_idx[1:]] - n_other[rot_idx[:-1] + 1] > 0
    too_far = is_gap(t[rot_idx[1:]] - t[rot_idx[:-1]], max_gap_s)
    cut = np.flatnonzero(between_other | too_far)
    starts = np.concatenate(([rot_idx[0]], rot_idx[cut + 1]))
    ends = np.concatenate((rot_idx[cut] + 1, [rot_idx[-1] + 1]))
    return list(zip(starts.tolist(), ends.tolist(), strict=True))


def _kind_runs(t: np.ndarray, on: np.ndarray, dwell_s: float) -> list[tuple[int, int, int]]:
    """Cut one piece into runs of constant kind with a minimum dwell (hysteresis).

    ``on`` is the turning state per sample (:data:`TURNING_STATES`; unknown samples already
    carry the previous one). Runs shorter than ``dwell_s`` (first to last sample, plus one
    sample interval) take the kind of their longer neighbour, the shortest first, and equal
    neighbours merge. Returns (start, end, state) with indices relative to the piece.
    """
    change = np.flatnonzero(on[1:] != on[:-1]) + 1
    bounds = np.concatenate(([0], change, [on.size]))
    runs = [[int(a), int(b), int(on[a])] for a, b in zip(bounds[:-1], bounds[1:], strict=True)]
    if len(runs) == 1:
        return [tuple(runs[0])]
    dt = np.diff(t)
    step = float(np.median(dt)) if dt.size else 0.0

    def duration(run):
        return t[run[1] - 1] - t[run[0]] + step

    # the shortest run under the dwell first: it takes the kind of its longer neighbour and
    # merges with it (a chain of short runs no longer passes one run's kind along: 1-s
    # off-bottom blips every 15 s of drilling made a drilled stand off bottom)
    return _absorb_short(runs, duration, dwell_s)


def _absorb_short(runs: list[list], duration, dwell_s: float) -> list[tuple[int, int, int]]:
    """Runs [start, end, kind] with every run shorter than ``dwell_s`` absorbed, the
    shortest first, into its longer neighbour (equal neighbours then merge); O(n log n)."""
    prev = list(range(-1, len(runs) - 1))
    nxt = list(range(1, len(runs) + 1))
    nxt[-1] = -1
    alive = [True] * len(runs)
    heap = [(duration(r), k) for k, r in enumerate(runs)]
    heapq.heapify(heap)
    while heap:
        d, k = heapq.heappop(heap)
        if not alive[k] or d != duration(runs[k]):
            continue  # merged away, or grown since pushed
        if d >= dwell_s:
            break
        near = [j for j in (prev[k], nxt[k]) if j >= 0]
        if not near:
            break
        runs[k][2] = runs[max(near, key=lambda j: duration(runs[j]))][2]
        for j in near:  # equal neighbours join run k
            if runs[j][2] == runs[k][2]:
                runs[k][0], runs[k][1] = min(runs[k][0], runs[j][0]), max(runs[k][1], runs[j][1])
                alive[j] = False
                if j == prev[k]:
                    prev[k] = prev[j]
                    if prev[k] >= 0:
                        nxt[prev[k]] = k
                else:
                    nxt[k] = nxt[j]
                    if nxt[k] >= 0:
                        prev[nxt[k]] = k
        heapq.heappush(heap, (duration(runs[k]), k))
    return [tuple(r) for k, r in enumerate(runs) if alive[k]]


#: Largest fraction of null speed/torque samples a segment may have; fewer are bridged by
#: interpolation (a dropped sample here and there is normal in rig logs).
MAX_NULL_FRACTION = 0.05


def _status(duration_s: float, n_null: dict[str, int], n_rows: int,
            min_s: float) -> tuple[str, str]:
    nulls = [f"{name} ({count} samples)" for name, count in n_null.items() if count]
    if duration_s < min_s:
        return "skipped", f"too short: {duration_s:.3g} s < {min_s:g} s"
    if any(count > MAX_NULL_FRACTION * n_rows for count in n_null.values()):
        return "skipped", ("nulls in " + ", ".join(nulls) + f": more than "
                           f"{MAX_NULL_FRACTION:.0%} of the samples")
    if nulls:
        return "ok", "nulls bridged by interpolation: " + ", ".join(nulls)
    return "ok", ""


def _segments(t, states, bit, nulls, cfg: Config, offset: int, first_id: int) -> list[Segment]:
    """Segments of a block of samples (row indices shifted by ``offset``)."""
    dwell = float(cfg.segmentation.kind_dwell_s)
    min_s = float(cfg.segmentation.min_segment_s)
    turning = pd.Series(np.where(np.isin(states, TURNING_STATES), states.astype(float), np.nan))
    # unknown samples keep the previous kind
    on = turning.ffill().fillna(ROTATING_OFF_BOTTOM).to_numpy().astype(np.int8)
    out: list[Segment] = []
    for a, b in _pieces(t, states, float(cfg.segmentation.max_gap_s)):
        for ra, rb, state in _kind_runs(t[a:b], on[a:b], dwell):
            i0, i1 = a + ra, a + rb
            depth = bit[i0:i1]
            finite = depth[np.isfinite(depth)]
            t0, t1 = float(t[i0]), float(t[i1 - 1])
            n_null = {name: int(np.count_nonzero(mask[i0:i1])) for name, mask in nulls.items()}
            if t1 - t0 < float(cfg.segmentation.min_rotation_s):
                continue  # a blip of speed noise, not rotation
            status, message = _status(t1 - t0, n_null, i1 - i0, min_s)
            motion = None
            if KINDS[state] in COMBINED_MOTION_KINDS:
                motion = axial_motion(KINDS[state], depth, t[i0:i1])
                if motion.withheld:
                    status, message = "skipped", motion.withheld
            known = motion is not None and np.isfinite(motion.speed_m_s)
            out.append(Segment(
                id=first_id + len(out),
                kind=KINDS[state],
                t_start_s=t0, t_end_s=t1, i_start=offset + i0, i_end=offset + i1,
                bit_depth_m=float(np.median(finite)) if finite.size else float("nan"),
                bit_depth_min_m=float(finite.min()) if finite.size else float("nan"),
                bit_depth_max_m=float(finite.max()) if finite.size else float("nan"),
                duration_s=t1 - t0, status=status, message=message,
                axial_speed_m_s=motion.speed_m_s if known else None,
                axial_from_s=motion.from_s if known else None,
                axial_to_s=motion.to_s if known else None))
    return out


#: Span of the bit depth's rate [s]: (depth(t + span/2) − depth(t − span/2))/span, which
#: takes the depth channel's quantisation (0.01 m: 2.5 % at 0.1 m/s) below the steadiness
#: test's tolerance.
AXIAL_RATE_SPAN_S = 4.0
#: A reaming segment's pipe speed counts as steady when its 10th and 90th percentiles over
#: the motion lie within this share of the median [-]: one speed then stands for the motion
#: (the models take v piecewise constant, docs/theory.md §3.3).
AXIAL_STEADY = 0.15
#: Longest travel of a reaming segment estimated as one [m]: F_c (T_N) is taken at its
#: median depth, which a longer travel through a changing section would not represent.
MAX_REAM_TRAVEL_M = 30.0


@dataclass(frozen=True)
class AxialMotion:
    """The pipe's motion over a reaming segment (:func:`axial_motion`).

    Attributes
    ----------
    speed_m_s : float
        Median rate of the bit depth while the pipe moves [m/s], + running in (NaN: none).
    from_s, to_s : float
        First and last time the pipe moves at half that speed or more [s].
    withheld : str
        Why the segment cannot be estimated ("" when it can).
    """

    speed_m_s: float
    from_s: float
    to_s: float
    withheld: str = ""


def axial_motion(kind: str, depth_m: np.ndarray, time_s: np.ndarray) -> AxialMotion:
    """The axial speed of a reaming / back-reaming segment and whether it can be
    estimated: a steady speed (:data:`AXIAL_STEADY`) over a travel of at most
    :data:`MAX_REAM_TRAVEL_M`, and no jump of the depth channel.

    The rate is the bit depth's change over :data:`AXIAL_RATE_SPAN_S`; the motion is where
    its magnitude reaches half its 90th percentile (the block's ramps cut at their middle).

    >>> t = np.arange(0.0, 100.0, 0.1)
    >>> m = axial_motion("reaming", 2000.0 + 0.2 * np.clip(t - 20.0, 0.0, 60.0), t)
    >>> round(m.speed_m_s, 3), round(m.from_s), round(m.to_s), m.withheld
    (0.2, 20, 80, '')
    """
    ok = np.isfinite(depth_m) & np.isfinite(time_s)
    d, t = np.asarray(depth_m, float)[ok], np.asarray(time_s, float)[ok]
    nan = float("nan")
    name = kind.replace("_", "-")
    if t.size < 3 or t[-1] - t[0] < AXIAL_RATE_SPAN_S:
        return AxialMotion(nan, nan, nan, f"{name}: too short to measure the pipe's speed")
    jump = _depth_jump(kind, d, t)
    if jump:
        return AxialMotion(nan, nan, nan, jump)
    half = 0.5 * AXIAL_RATE_SPAN_S
    lo, hi = np.maximum(t - half, t[0]), np.minimum(t + half, t[-1])
    rate = (np.interp(hi, t, d) - np.interp(lo, t, d)) / np.maximum(hi - lo, 1e-9)
    sign = 1.0 if kind == Kind.REAMING else -1.0
    along = sign * rate
    peak = float(np.percentile(along, 90.0))
    if not peak > 0:
        return AxialMotion(nan, nan, nan, f"{name}: the bit depth does not move "
                           f"{'down' if sign > 0 else 'up'}; μ and the bit speed are withheld")
    moving = along >= 0.5 * peak
    first, last = np.flatnonzero(moving)[[0, -1]]
    core = along[first:last + 1]
    speed = float(np.median(core))
    p10, p90 = np.percentile(core, [10.0, 90.0])
    motion = AxialMotion(sign * speed, float(t[first]), float(t[last]))
    way = "running in" if sign > 0 else "pulling out"
    if p10 < (1.0 - AXIAL_STEADY) * speed or p90 > (1.0 + AXIAL_STEADY) * speed:
        return replace(motion, withheld=(
            f"{name} at an unsteady speed: the pipe moves at {min(sign * p10, sign * p90):+.2f}"
            f" to {max(sign * p10, sign * p90):+.2f} m/s (10th and 90th percentile, + down; "
            f"{way} at a median "
            f"{speed:.2f} m/s), more than ±"
            f"{100 * AXIAL_STEADY:.0f} % apart: one axial speed does not stand for the "
            "motion, μ and the bit speed are withheld (docs/segmentation.md)"))
    travel = speed * (motion.to_s - motion.from_s)
    if travel > MAX_REAM_TRAVEL_M:
        return replace(motion, withheld=(
            f"{name} over {travel:.0f} m (> {MAX_REAM_TRAVEL_M:.0f} m): the string and its "
            "side forces change along the travel, which one depth does not stand for; μ and "
            "the bit speed are withheld (docs/segmentation.md)"))
    return motion


#: A bit depth changing faster than this within one sample is no pipe motion (trips run
#: at up to ~1.5 m/s): a depth reset or a re-zeroed block [m/s].
DEPTH_JUMP_M_S = 5.0

#: A depth reset is a jump of at least this many metres in one sample: a smaller change is
#: read noise or timestamp jitter however short the sample's time step (issue 35: DSATS
#: segment 70, 0.14 m in 0.02 s, read as a "jump" at 7 m/s) [m].
DEPTH_JUMP_MIN_M = 1.0


def _depth_jump(kind: str, depth_m: np.ndarray, time_s: np.ndarray) -> str:
    """Why a reaming / back-reaming segment is no pipe motion: the jump of the depth channel
    that made it look like reaming (a depth reset 127 → 168 m in 2 s had read "running in
    at 0 m/s": issue 35 item 7); "" when the depth moves no faster than a trip.

    A jump is judged by its size: more than :data:`DEPTH_JUMP_MIN_M` and more than a trip
    at :data:`DEPTH_JUMP_M_S` travels in the sample's time step. A speed over a jittery
    time step alone is no jump (0.14 m in 0.02 s is 7 m/s, but no reset).

    >>> _depth_jump("reaming", np.r_[np.full(5, 127.0), np.full(5, 168.2)],
    ...             np.arange(10.0)).split(" (")[0]
    'reaming? the bit depth jumps by 41.2 m within one sample'
    >>> _depth_jump("reaming", np.r_[np.full(5, 127.0), np.full(5, 127.14)],
    ...             np.r_[np.arange(5.0), 4.02 + np.arange(5.0)])
    ''
    """
    step = np.abs(np.diff(depth_m))
    reach = np.maximum(DEPTH_JUMP_MIN_M, DEPTH_JUMP_M_S * np.diff(time_s))
    over = step - reach
    if over.size and over.max() > 0:
        return (f"{kind.replace('_', '-')}? the bit depth jumps by {step[over.argmax()]:.1f} m "
                "within one sample (a depth reset or a re-zeroed block, not pipe motion): "
                "μ and the bit speed are withheld; check the depth channel")
    return ""


def _nulls(frame: pd.DataFrame) -> dict[str, np.ndarray]:
    """Null masks of the channels the estimation needs."""
    return {name: np.isnan(_column(frame, name))
            for name in ("surface_rpm", "surface_torque_Nm") if name in frame}


def segment(frame: pd.DataFrame, cfg: Config, *, states: np.ndarray | None = None
            ) -> list[Segment]:
    """Cut the rotating stretches of a record into segments (stands, sections).

    A segment is a maximal run of rotating samples (``rotating_off_bottom`` /
    ``rotating_on_bottom``), split where rotation stops (any other known state), where
    consecutive samples are more than ``max_gap_s`` apart, where nulls of the surface speed
    last longer than ``max_gap_s``, and where the kind (on/off bottom) changes for at least
    ``kind_dwell_s`` (shorter excursions keep the current kind). Segments with nulls in the
    surface speed or torque, or shorter than ``min_segment_s``, are kept with status
    ``"skipped"`` and the reason.

    Parameters
    ----------
    frame : pandas.DataFrame
        Canonical surface channels (see :func:`classify`).
    cfg : Config
        Configuration (table ``[segmentation]``).
    states : numpy.ndarray, optional
        Precomputed :func:`classify` output (the bit depth is still reckoned here).

    Returns
    -------
    list of Segment
        In time order, ids from 1.
    """
    computed, bit = _classify(frame, cfg, _new_carry(frame, cfg))
    if states is not None and len(states) != len(frame):
        raise ValueError(f"states has {len(states)} values for {len(frame)} rows")
    states = computed if states is None else np.asarray(states, dtype=np.int8)
    return _segments(_column(frame, "time_s"), states, bit, _nulls(frame), cfg, 0, 1)


class Segmenter:
    """Streaming :func:`segment`: feed chunks of rows, get segments as they complete.

    The classifier carries its state across chunks, and only the rows after the last
    point where no later data can change a segment (a known non-rotating sample or a time
    gap longer than ``max_gap_s``) are kept, so the segments are identical to
    ``segment(pd.concat(chunks), cfg)`` while memory stays bounded by the longest rotating
    stretch.

    Parameters
    ----------
    cfg : Config
        Configuration (table ``[segmentation]``).

    Examples
    --------
    Rotation from t = 20 s to t = 79 s, fed in two chunks:

    >>> from drillfric.config import load_config
    >>> rpm = np.r_[np.zeros(20), np.full(60, 60.0), np.zeros(20)]
    >>> frame = pd.DataFrame({"time_s": np.arange(100.0), "surface_rpm": rpm,
    ...                       "surface_torque_Nm": 100.0 * rpm})
    >>> seg = Segmenter(load_config())
    >>> done = seg.feed(frame.iloc[:50]) + seg.feed(frame.iloc[50:]) + seg.close()
    >>> [(s.kind.value, s.i_start, s.i_end, s.duration_s, s.status) for s in done]
    [('off_bottom_rotating', 20, 80, 59.0, 'ok')]
    """

    def __init__(self, cfg: Config):
        self._cfg = cfg
        self._carry: np.ndarray | None = None
        self._buffer: dict[str, np.ndarray] = {}
        self._offset = 0  # row index of the first buffered row
        self._next_id = 1
        self.last_states: np.ndarray | None = None  # rig states of the last chunk fed
        self.last_bit_depth_m: np.ndarray | None = None  # its bit depths (NaN: not known)

    def feed(self, chunk: pd.DataFrame) -> list[Segment]:
        """Consume the next rows; return the segments completed by them (maybe none)."""
        if self._carry is None:
            self._carry = _new_carry(chunk, self._cfg)
        states, bit = _classify(chunk, self._cfg, self._carry)
        self.last_states, self.last_bit_depth_m = states, bit
        new = {"t": _column(chunk, "time_s"), "states": states, "bit": bit}
        new.update({f"null:{k}": v for k, v in _nulls(chunk).items()})
        self._buffer = {k: np.concatenate((self._buffer[k], v)) if self._buffer else v
                        for k, v in new.items()}
        return self._emit(final=False)

    @property
    def pending_from(self) -> int:
        """Row index of the first row not yet assigned to an emitted segment (rows before it
        are final and may be dropped by the caller)."""
        return self._offset

    def close(self) -> list[Segment]:
        """Return the segments still open at the end of the data."""
        return self._emit(final=True)

    def state(self) -> dict:
        """What continues the segmentation (classifier carry, rows not yet in a segment,
        next id): plain values and arrays (docs/api.md "Feeding a well in chunks")."""
        return {"carry": self._carry, "buffer": dict(self._buffer), "offset": self._offset,
                "next_id": self._next_id}

    def restore(self, state: dict) -> None:
        """Continue from a :meth:`state`."""
        self._carry = None if state["carry"] is None else np.array(state["carry"], float)
        if self._carry is not None and self._carry.size < 11:  # saved before issue 35
            self._carry = np.concatenate([self._carry, np.full(11 - self._carry.size, np.nan)])
        self._buffer = {k: np.asarray(v) for k, v in state["buffer"].items()}
        self._offset, self._next_id = int(state["offset"]), int(state["next_id"])

    def _safe_cut(self) -> int:
        """Last buffer index before which no later data can change a segment."""
        t, states = self._buffer["t"], self._buffer["states"]
        rotating = np.isin(states, TURNING_STATES)
        other = np.flatnonzero(~rotating & (states != UNKNOWN))
        gaps = np.flatnonzero(is_gap(np.diff(t), self._cfg.segmentation.max_gap_s)) + 1
        candidates = np.concatenate((other, gaps))
        return int(candidates.max()) if candidates.size else 0

    def _emit(self, final: bool) -> list[Segment]:
        if not self._buffer:
            return []
        cut = len(self._buffer["t"]) if final else self._safe_cut()
        if cut == 0:
            return []
        part = {k: v[:cut] for k, v in self._buffer.items()}
        nulls = {k.split(":", 1)[1]: v for k, v in part.items() if k.startswith("null:")}
        out = _segments(part["t"], part["states"], part["bit"], nulls, self._cfg,
                        self._offset, self._next_id)
        self._next_id += len(out)
        self._offset += cut
        self._buffer = {k: v[cut:] for k, v in self._buffer.items()}
        return out


#: Seconds of data before a segment handed to the estimator, so that a start-up (and a creep
#: break-over) is seen from rest.
PREROLL_S = 5.0
#: Columns a segment's rows keep (what estimation and the segment's measured values need).
SEGMENT_COLUMNS = ("time_s", "surface_rpm", "surface_torque_Nm", "bit_depth_m", "wob_N",
                   "bit_rpm", "hookload_N", "timestamp", "surface_torque_min_Nm",
                   "surface_torque_max_Nm", "flow_in_m3_s", "pump_rate_spm",
                   "standpipe_pressure_Pa")


class SegmentStream:
    """Segments with their rows, from chunks of canonical surface data.

    Wraps a :class:`Segmenter` and owns the rows it has not finished with: each segment
    comes with its rows (:data:`SEGMENT_COLUMNS`) from up to :data:`PREROLL_S` before it —
    never before the end of the previous segment, and only after the last null of speed or
    torque — so a start-up is seen from rest. Rows no segment can need are dropped as the
    stream advances: memory is bounded by the longest rotating stretch.

    Examples
    --------
    >>> from drillfric.config import load_config
    >>> rpm = np.r_[np.zeros(20), np.full(60, 60.0), np.zeros(20)]
    >>> frame = pd.DataFrame({"time_s": np.arange(100.0), "surface_rpm": rpm,
    ...                       "surface_torque_Nm": 100.0 * rpm})
    >>> stream = SegmentStream(load_config())
    >>> out = stream.feed(frame.iloc[:50]) + stream.feed(frame.iloc[50:]) + stream.close()
    >>> [(seg.i_start, len(rows), float(rows["time_s"].iloc[0])) for seg, rows in out]
    [(20, 65, 15.0)]
    """

    def __init__(self, cfg: Config):
        self._segmenter = Segmenter(cfg)
        self._buffer = pd.DataFrame()
        self._start = 0  # input row index of the first buffered row
        self._last_end = 0  # input row after the last emitted segment

    def feed(self, chunk: pd.DataFrame) -> list[tuple[Segment, pd.DataFrame]]:
        """Consume the next rows; return the segments they complete, with their rows."""
        keep = chunk[[c for c in SEGMENT_COLUMNS if c in chunk]].reset_index(drop=True)
        self._buffer = pd.concat([self._buffer, keep], ignore_index=True) \
            if len(self._buffer) else keep
        out = self._rows(self._segmenter.feed(chunk))
        drop = _rows_done(self._buffer, self._segmenter.pending_from - self._start)
        if drop > 0:
            self._buffer = self._buffer.iloc[drop:].reset_index(drop=True)
            self._start += drop
        return out

    def close(self) -> list[tuple[Segment, pd.DataFrame]]:
        """The segments still open at the end of the data, with their rows."""
        return self._rows(self._segmenter.close())

    def state(self) -> dict:
        """What continues the stream: the segmenter's state and the rows kept for the
        segments still open (a DataFrame)."""
        return {"segmenter": self._segmenter.state(), "rows": self._buffer.copy(),
                "start": self._start, "last_end": self._last_end}

    def restore(self, state: dict) -> None:
        """Continue from a :meth:`state`."""
        self._segmenter.restore(state["segmenter"])
        self._buffer = state["rows"].reset_index(drop=True)
        self._start, self._last_end = int(state["start"]), int(state["last_end"])

    @property
    def last_states(self) -> np.ndarray | None:
        """Rig state codes of the last chunk fed (:data:`RIG_STATES`)."""
        return self._segmenter.last_states

    @property
    def last_bit_depth_m(self) -> np.ndarray | None:
        """Bit depth of every row of the last chunk fed [m]: the channel, else reckoned from
        the block (:func:`classify`); NaN where not known."""
        return self._segmenter.last_bit_depth_m

    def _rows(self, segments: list[Segment]) -> list[tuple[Segment, pd.DataFrame]]:
        out = []
        for seg in segments:
            lo = _preroll_start(self._buffer, seg.i_start - self._start,
                                max(self._last_end - self._start, 0))
            out.append((seg, self._buffer.iloc[lo:seg.i_end - self._start]))
            self._last_end = seg.i_end
        return out


def _preroll_start(buffer: pd.DataFrame, lo: int, floor: int) -> int:
    """First buffer row handed on for a segment starting at row ``lo``: up to
    :data:`PREROLL_S` earlier, not before ``floor`` and after the last null of speed or
    torque."""
    if lo <= floor:
        return lo
    t = buffer["time_s"].to_numpy()
    start = floor + int(np.searchsorted(t[floor:lo], t[lo] - PREROLL_S))
    pre = buffer.iloc[start:lo]
    bad = ~np.isfinite(pre["surface_rpm"].to_numpy(float))
    if "surface_torque_Nm" in pre:
        bad |= ~np.isfinite(pre["surface_torque_Nm"].to_numpy(float))
    if bad.any():
        start += int(np.flatnonzero(bad)[-1]) + 1
    return start


def _rows_done(buffer: pd.DataFrame, pending: int) -> int:
    """How many leading buffer rows no segment can need any more: those before the
    segmenter's pending row, less the pre-roll a segment starting there may take."""
    if pending <= 0:
        return 0
    t = buffer["time_s"].to_numpy()
    ref = t[pending] if pending < t.size else t[-1]
    return int(np.searchsorted(t[:pending], ref - PREROLL_S))


def above_rotary(depth_m: float) -> str:
    """Why a segment or a move with its bit at or above the rotary table is not used."""
    return (f"the bit is at or above the rotary table (bit depth {depth_m:.1f} m): the string "
            "is not in the hole (the BHA made up or laid out) — if it was, check the "
            "bit-depth channel's datum")
