"""The top drive's speed controller, identified from the log (docs/theory.md §6.4 "The
drive").

The batch fit matches the model's mean torque to the data's. In stick-slip the model and the
rig fall out of step within a few cycles (the motion is chaotic), and from then on the mean
is a statistic of the closed loop the model runs in. Driven by the logged speed, the model
runs under an infinitely stiff drive; under a soft drive (the speed dips between slips) that
is another closed loop, whose bit sticks more often: the mean torque then read μ_k 5 % high.

Most top drives are speed controllers of PI type, τ_m = k_p(ω_ref − ω₀) + k_i∫(ω_ref − ω₀)dt,
with ω_ref the driller's set-point. Over a stretch of constant set-point the logged motor
torque is then linear in the logged speed and its integral Ω(t) = ∫ω₀ dt:

    τ_m(t) = a + b·t − k_p ω₀(t) − k_i Ω(t),         a, b constant per stretch,

so k_p and k_i follow by least squares (every series smoothed by the same moving average,
which keeps the linear relation and averages out sensor noise). With them the model replays
the drive in closed loop (``torsional.Drive("fed")``): the logged motor torque plus the
same PI acting on the difference between the logged and the model's speed. In step with the
rig the correction is zero; out of step the model's own top drive responds as the rig's
would. The replay is insensitive to the gains within a factor of 3 (μ_k within 1 % for a
soft and a stiff drive, docs/validation.md), so the identification need only be roughly
right — but it must explain the torque: below :data:`MIN_EXPLAINED` of the torque's
fluctuation the drive is not a PI controller of the logged speed (or the log does not resolve
it) and the model follows the logged speed instead.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drillfric.estimation.creep import smooth

#: Share of the motor torque's fluctuation (about each stretch's linear trend) a PI law on
#: the logged speed must explain for the drive to be replayed: a soft drive logged at
#: 100 Hz … 1-s means 0.93–1.00, a stiff one 0.79–0.85 at 100 Hz and 1-s means, 0.05–0.35 at
#: 5 Hz, 1 Hz and 5-s means (the stiff loop's fast response is not in the log).
MIN_EXPLAINED = 0.75
#: Smoothing of every series before the regression [s] (at least two samples).
SMOOTH_S = 0.5
#: The set-point is taken as constant where the speed averaged over SETPOINT_S stays within
#: SETPOINT_BAND of its median over the stretch (the longest such part is used): a ramp up
#: or down of the set-point is not in the law.
SETPOINT_S, SETPOINT_BAND = 10.0, 0.15
#: Largest speed-loop gain taken as physical [N·m·s/rad]: with 2900 kg·m² a bandwidth of
#: 345 rad/s, beyond any top drive; keeps the explicit PI of the replay stable.
MAX_KP = 1e6


@dataclass(frozen=True)
class DriveModel:
    """A top drive's PI speed controller.

    Attributes
    ----------
    kp_Nms_rad : float
        Proportional gain k_p [N·m·s/rad].
    ki_Nm_rad : float
        Integral gain k_i [N·m/rad].
    explained : float
        Share of the motor torque's fluctuation the PI law explains [-].
    """

    kp_Nms_rad: float
    ki_Nm_rad: float
    explained: float

    @property
    def usable(self) -> bool:
        """Whether the law is physical and explains the torque (:data:`MIN_EXPLAINED`)."""
        return (0.0 < self.kp_Nms_rad <= MAX_KP and self.ki_Nm_rad >= 0.0
                and self.explained >= MIN_EXPLAINED)

    def describe(self) -> str:
        """One line for the messages."""
        law = (f"PI speed control, k_p = {self.kp_Nms_rad:.3g} N·m·s/rad, k_i = "
               f"{self.ki_Nm_rad:.3g} N·m/rad, explaining {100 * self.explained:.0f} % of the "
               "motor torque's fluctuation")
        if self.usable:
            return f"top drive identified from the log as {law}: the model replays it"
        if self.kp_Nms_rad <= 0.0 or self.ki_Nm_rad < 0.0:  # no PI law: its gains mean nothing
            return ("top drive not identified (no PI speed control fits the log: the best "
                    "fit's gains are negative): the model follows the logged speed")
        return (f"top drive not identified (best {law}): the model follows the logged "
                "speed")


def identify(time_s, surface_rad_s, motor_torque_Nm,
             stretches: list[np.ndarray]) -> DriveModel | None:
    """k_p, k_i of the top drive from the samples ``stretches`` (index arrays of constant
    set-point, e.g. rotation after the start-up) of a uniform log; None with too few
    samples.

    Examples
    --------
    A PI drive (k_p = 900, k_i = 2500) holding 6 rad/s against a torque that varies:

    >>> t = np.arange(0.0, 60.0, 0.01)
    >>> w = 6.0 + 0.3 * np.sin(1.3 * t) + 0.1 * np.sin(4.1 * t)
    >>> err = 6.0 - w
    >>> tau = 900.0 * err + 2500.0 * np.cumsum(err) * 0.01 + 8000.0
    >>> m = identify(t, w, tau, [np.arange(t.size)])
    >>> round(m.kp_Nms_rad, -2), round(m.ki_Nm_rad, -2), m.usable
    (900.0, 2500.0, True)
    """
    t = np.asarray(time_s, dtype=float)
    dt = float(np.median(np.diff(t)))
    width = max(SMOOTH_S, 2.0 * dt)
    w = smooth(np.asarray(surface_rad_s, dtype=float), dt, width)
    stretches = [steady_setpoint(s, smooth(w, dt, SETPOINT_S)) for s in stretches]
    tau = smooth(np.asarray(motor_torque_Nm, dtype=float), dt, width)
    omega = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * dt)])
    rows, trend_cols, y = [], [], []
    n = len(stretches)
    for j, idx in enumerate(s for s in stretches if s.size > 10):
        trend = np.zeros((idx.size, 2 * n))
        trend[:, 2 * j] = 1.0
        trend[:, 2 * j + 1] = t[idx] - t[idx[0]]
        trend_cols.append(trend)
        rows.append(np.column_stack([-w[idx], -(omega[idx] - omega[idx[0]])]))
        y.append(tau[idx])
    if not rows or sum(len(r) for r in rows) < 20:
        return None
    trend, law, y = np.vstack(trend_cols), np.vstack(rows), np.concatenate(y)
    trend = trend[:, np.any(trend != 0, axis=0)]
    coef, *_ = np.linalg.lstsq(np.hstack([law, trend]), y, rcond=None)
    base, *_ = np.linalg.lstsq(trend, y, rcond=None)
    around_trend = float(np.var(y - trend @ base))
    residual = float(np.var(y - np.hstack([law, trend]) @ coef))
    explained = 1.0 - residual / around_trend if around_trend > 0 else 0.0
    return DriveModel(float(coef[0]), float(coef[1]), explained)


def steady_setpoint(idx: np.ndarray, w_avg: np.ndarray) -> np.ndarray:
    """The longest run of ``idx`` where the averaged speed ``w_avg`` is within
    :data:`SETPOINT_BAND` of its median there (the set-point taken as constant).

    Examples
    --------
    >>> w = np.r_[np.full(50, 6.0), np.linspace(6.0, 0.0, 10)]
    >>> steady_setpoint(np.arange(60), w)[[0, -1]].tolist()
    [0, 51]
    """
    if idx.size == 0:
        return idx
    level = float(np.median(w_avg[idx]))
    inside = np.abs(w_avg[idx] - level) <= SETPOINT_BAND * abs(level)
    edges = np.flatnonzero(np.diff(np.r_[0, inside.astype(np.int8), 0]))
    starts, ends = edges[::2], edges[1::2]
    if starts.size == 0:
        return idx[:0]
    k = int(np.argmax(ends - starts))
    return idx[starts[k]:ends[k]]
