"""Where a surface record can tell μ_s: creep start-ups and rotating runs, docs/theory.md §6.2–6.3.

A *creep* (or break-over) is a start from rest with no trapped twist in which the top drive
turns slower than the static/kinetic switching speed ω_c for 10–30 s: every moving element
is then in the static band and the surface-torque build-up is governed by μ_s (docs/theory.md §6.3).
A *rotating run* is a stretch in which the top drive turns forward; its samples far enough
from the start-up carry the kinetic friction μ_k through the mean torque (docs/theory.md §6.4).

Everything works on the top-drive speed smoothed over about a second, so that logging noise
(0.5 RPM is typical) does not split or invent segments. All times in s, speeds in rad/s.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import uniform_filter1d

from drillfric.errors import InputError

#: A top drive slower than this fraction of ω_c counts as at rest.
REST_FRACTION = 0.1
#: A creep ends when the smoothed speed reaches this fraction of ω_c (margin for noise).
CREEP_TOP_FRACTION = 0.9


def smooth(values, dt_s: float, width_s: float) -> np.ndarray:
    """Centred moving average over ``width_s`` [s] (at least one sample; ends held).

    Parameters
    ----------
    values : array_like
        Uniformly sampled series.
    dt_s : float
        Sample interval [s].
    width_s : float
        Averaging window [s]; a window shorter than two samples returns a copy.

    Examples
    --------
    >>> smooth([0.0, 3.0, 0.0, 3.0], 1.0, 3.0).tolist()
    [1.0, 1.0, 2.0, 2.0]
    """
    y = np.asarray(values, dtype=float)
    n = int(round(width_s / dt_s))
    if n < 2:
        return y.copy()
    return uniform_filter1d(y, size=n, mode="nearest")


def true_runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Maximal index ranges [i0, i1] (inclusive) where ``mask`` is true."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    starts = np.flatnonzero(edges == 1)
    ends = np.flatnonzero(edges == -1) - 1
    return list(zip(starts.tolist(), ends.tolist(), strict=True))


def rotating_runs(omega_bar_rad_s, omega_c_rad_s: float,
                  rest_rad_s: float | None = None) -> list[tuple[int, int]]:
    """Index ranges (inclusive) in which the smoothed top-drive speed is above rest.

    Parameters
    ----------
    omega_bar_rad_s : array_like
        Smoothed top-drive speed [rad/s].
    omega_c_rad_s : float
        Static/kinetic switching speed ω_c [rad/s].
    rest_rad_s : float, optional
        Rest threshold [rad/s] (default :data:`REST_FRACTION`·ω_c).

    Examples
    --------
    >>> rotating_runs([0.0, 2.0, 2.0, 0.0, 3.0], 1.0)
    [(1, 2), (4, 4)]
    """
    rest = REST_FRACTION * omega_c_rad_s if rest_rad_s is None else rest_rad_s
    return true_runs(np.asarray(omega_bar_rad_s, dtype=float) > rest)


def bridge_loaded_dips(runs: list[tuple[int, int]], time_s, torque_Nm, *,
                       max_dip_s: float = 10.0,
                       fraction: float = 0.5) -> list[tuple[int, int]]:
    """Join rotating runs separated by a brief stop while the string stays loaded.

    A soft-torque or slow top-drive controller lets the surface speed fall to ~0 between
    slips while the string stays wound up: that is one rotation, not many short ones
    (the segmentation's rule, :func:`drillfric.segmentation._still_turning`). Two runs are
    joined when the stop between them lasts at most ``max_dip_s`` and the smoothed torque
    holds at least ``fraction`` of the previous run's mean torque throughout it.

    Examples
    --------
    >>> t = np.arange(10.0)
    >>> tau = np.array([5, 5, 5, 4, 5, 5, 0, 0, 5, 5.0])
    >>> bridge_loaded_dips([(0, 2), (4, 5), (8, 9)], t, tau, max_dip_s=3.0)
    [(0, 5), (8, 9)]
    """
    t = np.asarray(time_s, dtype=float)
    tau = np.abs(np.asarray(torque_Nm, dtype=float))
    out: list[list[int]] = []
    for i0, i1 in runs:
        if out:
            a0, a1 = out[-1]
            gap = tau[a1 + 1:i0]
            level = float(np.mean(tau[a0:a1 + 1]))
            if t[i0] - t[a1] <= max_dip_s and gap.size and level > 0 and \
                    float(gap.min()) >= fraction * level:
                out[-1][1] = i1
                continue
        out.append([i0, i1])
    return [(a, b) for a, b in out]


def find_creeps(time_s, surface_rad_s, omega_c_rad_s: float, *, torque_Nm=None,
                min_hold_s: float = 10.0, rest_s: float = 2.0, smooth_s: float = 1.0,
                rest_rad_s: float | None = None,
                max_rest_torque_fraction: float = 0.1) -> list[tuple[float, float]]:
    """Creep start-ups: from rest, top drive below ω_c for at least ``min_hold_s`` (§6.3).

    A creep starts at the last at-rest sample of a stretch at rest that lasted ``rest_s``
    (or began with the record) and ends when the smoothed speed first reaches
    :data:`CREEP_TOP_FRACTION`·ω_c or returns to rest. With ``torque_Nm``, a start whose mean
    torque over the preceding rest exceeds ``max_rest_torque_fraction`` of the largest
    smoothed torque in the creep is rejected: that torque is twist trapped during the stop,
    which the model (starting with zero twist) cannot know (docs/theory.md §6.4, restarts).

    Parameters
    ----------
    time_s : array_like
        Sample times [s], increasing.
    surface_rad_s : array_like
        Top-drive speed ω₀ [rad/s].
    omega_c_rad_s : float
        Static/kinetic switching speed ω_c [rad/s].
    torque_Nm : array_like, optional
        String torque at surface [N·m] (for the trapped-twist check).
    min_hold_s, rest_s, smooth_s : float
        Shortest creep, shortest preceding rest, speed smoothing window [s].
    rest_rad_s : float, optional
        Rest threshold [rad/s] (default :data:`REST_FRACTION`·ω_c).
    max_rest_torque_fraction : float
        See above [-].

    Returns
    -------
    list of (t_start_s, t_end_s)
    """
    t = np.asarray(time_s, dtype=float)
    w = np.asarray(surface_rad_s, dtype=float)
    if t.ndim != 1 or t.shape != w.shape or t.size < 2 or np.any(np.diff(t) <= 0):
        raise InputError("creep detection needs equal-length time and speed series with "
                         "increasing times", fix="sort the record by time and drop duplicates")
    dt = float(np.median(np.diff(t)))
    w_bar = smooth(w, dt, max(smooth_s, 3 * dt))
    rest = REST_FRACTION * omega_c_rad_s if rest_rad_s is None else rest_rad_s
    top = CREEP_TOP_FRACTION * omega_c_rad_s
    tau_bar = None if torque_Nm is None else smooth(torque_Nm, dt, smooth_s)
    creeps = []
    for r0, r1 in true_runs(np.abs(w_bar) <= rest):
        start = r1 + 1
        if start >= t.size or (t[r1] - t[r0] < rest_s - 0.5 * dt and r0 > 0):
            continue
        stop = start
        while stop + 1 < t.size and rest < w_bar[stop + 1] < top:
            stop += 1
        if w_bar[start] >= top or t[stop] - t[r1] < min_hold_s:
            continue
        if tau_bar is not None:
            trapped = abs(float(np.mean(tau_bar[r0:r1 + 1])))
            if trapped > max_rest_torque_fraction * float(np.max(np.abs(tau_bar[r1:stop + 1]))):
                continue
        creeps.append((float(t[r1]), float(t[stop])))
    return creeps
