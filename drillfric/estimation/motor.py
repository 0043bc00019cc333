"""A declared mud motor's speed from the flow in (docs/theory.md §2.4).

A positive displacement motor in the BHA turns the bit relative to the string's bottom at a
speed proportional to the flow through it, ω_m = 2π·k·Q (eq. 2.4a, k in rev per m³); under
the bit's load on bottom it turns slower, by at most the share ``drop`` of that no-load
speed (eq. 2.4b). The bit turns at the string's bottom speed plus ω_m (eq. 2.4c).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Litres per cubic metre: ``[bha] motor_rev_per_litre`` to rev/m³.
LITRES_PER_M3 = 1000.0


def motor_speed_rad_s(flow_m3_s, rev_per_litre: float) -> np.ndarray:
    """No-load speed of a mud motor ω_m = 2π·k·Q [rad/s] (docs/theory.md eq. 2.4a).

    Parameters
    ----------
    flow_m3_s : array_like
        Flow in through the motor Q [m³/s].
    rev_per_litre : float
        The motor's displacement constant k [rev/L].

    Examples
    --------
    >>> round(float(motor_speed_rad_s(0.03, 0.1)) * 60 / (2 * np.pi), 6)  # 1800 L/min
    180.0
    """
    return 2.0 * np.pi * rev_per_litre * LITRES_PER_M3 * np.asarray(flow_m3_s, dtype=float)


@dataclass(frozen=True)
class MotorSpeed:
    """The speed a declared motor adds to the string's bottom speed at each row [rad/s]:
    ``low`` ≤ ``mid`` ≤ ``high`` (equal off bottom; on bottom the speed after the largest
    drop and the no-load speed). With the pumps off ``low`` and ``mid`` are 0 and ``high``
    the no-load speed of what flow is still logged (below the pumps-on threshold); NaN
    where the flow is missing while the pumps may run."""

    low: np.ndarray
    mid: np.ndarray
    high: np.ndarray


def motor_speed(flow_m3_s: np.ndarray | None, pumps: np.ndarray, rev_per_litre: float,
                drop: float, on_bottom: bool) -> MotorSpeed:
    """The motor's speed band at each row (docs/theory.md eqs. 2.4a–b) [rad/s].

    Parameters
    ----------
    flow_m3_s : ndarray or None
        Flow in per row [m³/s]; None: the log has no flow channel.
    pumps : ndarray of int
        Pumps on (1), off (0) or unknown (−1) per row (:func:`drillfric.segmentation.
        pumps_on`): off gives 0 (the band's top the no-load speed of the flow still logged);
        on or unknown needs the flow.
    rev_per_litre : float
        k [rev/L].
    drop : float
        Largest share of the no-load speed lost under the bit's load [-] (on bottom only).
    on_bottom : bool
        Whether the bit drills (the motor carries the bit torque).

    Examples
    --------
    >>> rpm = lambda w: (w * 60 / (2 * np.pi)).round(6).tolist()
    >>> m = motor_speed(np.array([0.03, 0.001, np.nan]), np.array([1, 0, 1]), 0.1, 0.3, True)
    >>> rpm(m.low), rpm(m.mid), rpm(m.high)
    ([126.0, 0.0, nan], [153.0, 0.0, nan], [180.0, 6.0, nan])
    """
    pumps = np.asarray(pumps)
    flow = np.full(pumps.size, np.nan) if flow_m3_s is None \
        else np.asarray(flow_m3_s, dtype=float)
    no_load = motor_speed_rad_s(flow, rev_per_litre)
    off = pumps == 0
    low = np.where(off, 0.0, no_load * (1.0 - drop) if on_bottom else no_load)
    high = np.where(off, np.nan_to_num(no_load, nan=0.0), no_load)
    return MotorSpeed(low=low, mid=np.where(off, 0.0, 0.5 * (low + high)), high=high)
