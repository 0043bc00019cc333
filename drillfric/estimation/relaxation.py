"""Relaxation cycles of a soft top drive, found in the log (docs/theory.md §6.4 "Relaxation
cycles").

A PI top drive whose integral gain is too small to deliver the break-away torque quickly
cannot keep the string turning once it sticks: the string stays stuck while the top drive
crawls far below its set-point, winding it up at the rate the integral grows, until the
torque reaches μ_s∫F_c dx; the string then breaks free, the wound-up torque and the integral
throw the top drive to several hundred RPM, the integral unwinds and the string sticks
again — a cycle of one to a few minutes.

Over such a cycle the mean surface torque is mostly *static* torque: the wind-up, which
rises from about μ_k∫F_c dx to μ_s∫F_c dx over the longest part of the cycle. Matching it
(:mod:`drillfric.estimation.batch`) measures the break-away torque and the timing of the
cycle, not μ_k: a model whose stalls last a little longer or shorter than the rig's moves
μ_k by tens of per cent, and replaying the drive does not put its stalls in step (the
validation saw −15…+35 % at 100 Hz to 1-s means, docs/validation.md). A stall is:

- the top-drive speed averaged over :data:`STALL_SMOOTH_S` below the crawl line for at
  least :data:`MIN_STALL_S` (longer than the stuck phase of ordinary stick-slip); the crawl
  line is the larger of ω_c and :data:`CRAWL_FRACTION` of the set-point. The integral action
  of a PI drive holds its mean speed at the set-point, so the rotation's mean speed is taken
  for it. A drive a little stiffer than one that crawls below ω_c (k_p = ζ, k_i = 300 N·m/rad
  on the validation well) winds the stuck string up for 20–30 s at 3–18 RPM — about ω_c, not
  below it — against a 40-RPM set-point: the same relaxation cycle, which the ω_c line
  alone missed (its μ_k was reported converged and 6–32 % high, docs/validation.md),
- after the top drive has turned above the crawl line in the record (a stall, not a
  start-up: a creep from rest is the same physics, but the fit leaves it out of μ_k),
- with the top drive still turning (mean speed ≥ the rest threshold) while the torque winds
  up by at least :data:`MIN_WINDUP` of the rotating mean torque,
- and followed by rotation above the crawl line (the break-away burst).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drillfric.estimation.creep import REST_FRACTION, smooth
from drillfric.io.text import plural

#: Shortest stall counted [s]: as long as the longest bridged soft-torque dip
#: (segmentation.dip_max_s) and longer than the stick-slip period of a string up to ~6 km
#: (4L/c ≈ 7 s), whose stuck phase is a part of it.
MIN_STALL_S = 10.0
#: Least rise of the smoothed torque over a stall, relative to the mean torque of the
#: rotation (a stuck string wound from about μ_k to μ_s of its capacity rises by
#: μ_s/μ_k − 1, > 50 % for μ_s ≥ 1.5 μ_k).
MIN_WINDUP = 0.25
#: A top drive held below this share of its set-point (the rotation's mean speed) is
#: crawling [-]: between slips of ordinary stick-slip the 3-s mean speed stays above it, or
#: dips below it for ≤ 3 s (validation plants, k_i = 2500 N·m/rad, k_p = 0.3–3 ζ).
CRAWL_FRACTION = 0.5
#: The speed is averaged over this before the stalls are looked for [s]: the crawl is slow,
#: and a torsional wave or sensor noise must not split a stall.
STALL_SMOOTH_S = 3.0


@dataclass(frozen=True)
class RelaxationCycles:
    """Stalls and bursts of a soft top drive found in a log.

    Attributes
    ----------
    stalls : int
        Number of stalls (each followed by a burst).
    stall_s : float
        Median duration of a stall [s].
    crawl_rad_s : float
        Median mean top-drive speed during a stall [rad/s].
    windup_Nm : float
        Median rise of the smoothed torque over a stall [N·m].
    burst_rad_s : float
        Highest smoothed top-drive speed after a stall [rad/s].
    period_s : float or None
        Median time between stall starts [s] (None with one stall).
    crawl_line_rad_s : float
        The speed below which the top drive counted as crawling [rad/s]: the larger of ω_c
        and :data:`CRAWL_FRACTION` of the set-point.
    """

    stalls: int
    stall_s: float
    crawl_rad_s: float
    windup_Nm: float
    burst_rad_s: float
    period_s: float | None
    crawl_line_rad_s: float

    def describe(self, interval_s: float) -> str:
        """One line for the messages; ``interval_s`` is the log's effective interval [s]."""
        period = "" if self.period_s is None else f", every {self.period_s:.0f} s"
        return (f"relaxation cycles of a soft top drive ({plural(self.stalls, 'stall')} of "
                f"{self.stall_s:.0f} s: the top drive crawls at "
                f"{self.crawl_rad_s * 30 / np.pi:.1f} RPM (below "
                f"{self.crawl_line_rad_s * 30 / np.pi:.1f} RPM) while the torque winds up "
                f"by {self.windup_Nm / 1e3:.1f} kN·m, then bursts to "
                f"{self.burst_rad_s * 30 / np.pi:.0f} RPM{period}; logged every "
                f"{interval_s:.3g} s): the mean torque of such cycles is mostly the static "
                "wind-up — it measures the break-away and the cycle's timing, not μ_k — so "
                "μ_k is not converged; a stiffer integral gain (or a record of steady "
                "rotation) would make it measurable")


def find(time_s, omega_rad_s, torque_bar_Nm, omega_c_rad_s: float,
         mean_torque_Nm: float, setpoint_rad_s: float = 0.0) -> RelaxationCycles | None:
    """The stalls of a uniform log (module docstring), or None without any.

    ``omega_rad_s`` is the logged top-drive speed, ``torque_bar_Nm`` the string torque
    smoothed over about 1 s, ``mean_torque_Nm`` the mean torque of the rotation used for
    μ_k [N·m], ``setpoint_rad_s`` the drive's set-point, taken as the mean speed of that
    rotation [rad/s] (0: the crawl line is ω_c alone).

    Examples
    --------
    Turning at 4 rad/s, stuck for 40 s crawling at 0.5 rad/s while the torque rises from
    15 to 30 kN·m, bursting to 25 rad/s, and turning again:

    >>> t = np.arange(0.0, 120.0, 0.5)
    >>> w = np.where((t >= 40) & (t < 80), 0.5, 4.0)
    >>> w[(t >= 80) & (t < 90)] = 25.0
    >>> tau = np.where((t >= 40) & (t < 80), 15e3 + 375.0 * (t - 40), 15e3)
    >>> c = find(t, w, tau, 1.0, 16e3)
    >>> c.stalls, c.stall_s, round(c.windup_Nm), round(c.burst_rad_s)
    (1, 37.0, 13875, 25)

    The same stall crawling at 1.5 rad/s, above ω_c = 1 rad/s but below half the 4-rad/s
    set-point:

    >>> w[(t >= 40) & (t < 80)] = 1.5
    >>> find(t, w, tau, 1.0, 16e3) is None, find(t, w, tau, 1.0, 16e3, 4.0).stalls
    (True, 1)
    """
    t = np.asarray(time_s, dtype=float)
    w = smooth(np.asarray(omega_rad_s, dtype=float), float(np.median(np.diff(t))),
               STALL_SMOOTH_S)
    tau = np.asarray(torque_bar_Nm, dtype=float)
    # Both lines are tried: the higher one can join a stall below ω_c to a start-up or to
    # the record's end (neither counts), the lower one misses a crawl around ω_c.
    found = [_stalls(t, w, tau, line, omega_c_rad_s, mean_torque_Nm)
             for line in (omega_c_rad_s, max(omega_c_rad_s,
                                             CRAWL_FRACTION * abs(setpoint_rad_s)))]
    return max(found, key=lambda c: 0 if c is None else c.stalls)


def _stalls(t, w, tau, line: float, omega_c_rad_s: float,
            mean_torque_Nm: float) -> RelaxationCycles | None:
    """The stalls below the crawl ``line`` [rad/s] of the smoothed speed ``w`` (:func:`find`)."""
    below = np.abs(w) < line
    edges = np.flatnonzero(np.diff(np.r_[0, below.astype(np.int8), 0]))
    found = []
    for i0, i1 in zip(edges[::2], edges[1::2], strict=True):  # below the line: i0 … i1 − 1
        if i0 == 0 or i1 >= t.size or t[i1 - 1] - t[i0] < MIN_STALL_S:
            continue  # a start-up, the record's end, or a short dip
        windup = float(tau[i1 - 1] - np.min(tau[i0:i1]))
        crawl = float(np.mean(np.abs(w[i0:i1])))
        if crawl >= REST_FRACTION * omega_c_rad_s and \
                windup >= MIN_WINDUP * abs(mean_torque_Nm):
            nxt = edges[np.searchsorted(edges, i1, side="right"):][:1]
            stop = int(nxt[0]) if nxt.size else t.size
            found.append((t[i0], t[i1 - 1] - t[i0], crawl, windup,
                          float(np.max(np.abs(w[i1:stop])))))
    if not found:
        return None
    starts, stall, crawl, windup, burst = (np.array(x) for x in zip(*found, strict=True))
    return RelaxationCycles(stalls=len(found), stall_s=float(np.median(stall)),
                            crawl_rad_s=float(np.median(crawl)),
                            windup_Nm=float(np.median(windup)), burst_rad_s=float(burst.max()),
                            period_s=float(np.median(np.diff(starts))) if len(found) > 1
                            else None, crawl_line_rad_s=line)
