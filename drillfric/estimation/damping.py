"""The viscous slope of a stand with two or more steady set-points (docs/theory.md §6.4
"The damping identified", issue 34 item 3).

The model's mean string torque holds a viscous part k_t·J·ω̄ (J = ∫ρJ dx, ω̄ the mean
top-drive speed; eq. 2–3): over a whole number of cycles every element's mean speed is the
top drive's, so the part is linear in ω̄ whatever the stick-slip. Where the true damping
differs (heavy mud) by Δk, the measured mean torque M_i at set-point i misses the fitted
model's m_i by

    M_i − m_i = c + Δk·J·ω̄_i                                                    (6.4k)

with c common to the set-points (the friction's share of the batch fit's error). Two or
more set-points at different speeds give Δk — the *apparent* viscous slope, mixed with any
rate dependence of the friction and the mud the model does not have — by weighted least
squares, each level's M_i − m_i with the standard error of its whole-cycle mean (√2: the
model's scatters as much, as in §6.6). Only levels of steady rotation count: in stick-slip
the mean torque also turns on μ_s and the cycle's shape, which the model has only
approximately (3× the configured damping read 0.17 ± 0.04 1/s for 0.1 with a stick-slipping
60-RPM level among steady ones). k_t + Δk is *identified* where its 95 % half-width
is within :data:`TOLERANCE` of it; otherwise "not identified", and μ_k's interval carries
the assumed damping's range instead (``model.k_t_uncertainty_factor``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drillfric.estimation.batch.harness import cycle_mean, cycle_mean_error
from drillfric.estimation.batch.settings import STICK_SLIP_FLUCTUATION, TORQUE_SMOOTH_S
from drillfric.estimation.creep import smooth, true_runs

#: The set-point is taken as constant while the top-drive speed averaged over SETPOINT_S [s]
#: stays within SETPOINT_BAND of the level's mean (docs/theory.md §6.4).
SETPOINT_S, SETPOINT_BAND = 10.0, 0.05
#: A level counts from SETTLE_S [s] after it is reached (the string's response to the
#: change) and when it then lasts at least MIN_LEVEL_S [s].
SETTLE_S, MIN_LEVEL_S = 10.0, 40.0
#: Two levels count as distinct set-points when their speeds differ by this share [-].
MIN_SPEED_STEP = 0.15
#: The issue's tolerance of an identified viscous slope, ±30 % (95 % half-width) [-].
TOLERANCE = 0.30
_Z95 = 1.96


@dataclass(frozen=True)
class ViscousSlope:
    """The viscous damping rate a segment's set-points identify, or why not.

    Attributes
    ----------
    k_t_per_s : float or None
        Identified apparent damping rate k_t + Δk [1/s] (None: not identified).
    uncertainty_per_s : float or None
        Its 95 % half-width [1/s].
    levels : int
        Steady set-points used.
    note : str
        One line for the segment's messages.
    """

    k_t_per_s: float | None
    uncertainty_per_s: float | None
    levels: int
    note: str

    @property
    def identified(self) -> bool:
        """Whether the set-points identify the damping within :data:`TOLERANCE`."""
        return self.k_t_per_s is not None


def levels(time_s: np.ndarray, speed_rad_s: np.ndarray, usable: np.ndarray
           ) -> list[slice]:
    """The steady set-points among the ``usable`` samples of a uniform record: runs where
    the top-drive speed averaged over :data:`SETPOINT_S` stays within
    :data:`SETPOINT_BAND` of the run's mean, from :data:`SETTLE_S` after the run starts,
    at least :data:`MIN_LEVEL_S` long.

    Examples
    --------
    >>> t = np.arange(0.0, 300.0, 0.1)
    >>> w = np.where(t < 150.0, 6.0, 9.0)
    >>> [(round(t[s.start]), round(t[s.stop - 1])) for s in levels(t, w, t >= 0.0)]
    [(10, 147), (163, 300)]
    """
    t = np.asarray(time_s, dtype=float)
    dt = float(t[1] - t[0]) if t.size > 1 else 1.0
    w = smooth(np.abs(np.asarray(speed_rad_s, dtype=float)), dt, SETPOINT_S)
    step = max(1, int(round(1.0 / dt)))  # the levels are judged on a 1-s grid
    settle, shortest = SETTLE_S / dt, MIN_LEVEL_S / dt
    out = []
    for a, b in true_runs(np.asarray(usable, dtype=bool)):
        grid = np.arange(a, b + 1, step)
        k = 0
        while k < grid.size:
            j, total = k, 0.0
            while j < grid.size:
                mean = (total + w[grid[j]]) / (j - k + 1)
                if abs(w[grid[j]] - mean) > SETPOINT_BAND * abs(mean):
                    break
                total += w[grid[j]]
                j += 1
            start, stop = int(grid[k]), (int(grid[j]) if j < grid.size else b + 1)
            if stop - start - settle >= shortest and total > 0.0:
                out.append(slice(start + int(round(settle)), stop))
            k = max(j, k + 1)
    return out

def identify(time_s, measured_Nm, model_Nm, speed_rad_s, usable, *, inertia_kg_m2: float,
             k_t_per_s: float) -> ViscousSlope:
    """Eq. 6.4k over the steady set-points of one segment.

    Parameters
    ----------
    time_s : array_like
        Uniform sample times [s].
    measured_Nm, model_Nm : array_like
        Measured string torque and the fitted model's (at the configured k_t) [N·m].
    speed_rad_s : array_like
        Top-drive speed [rad/s].
    usable : array_like of bool
        Samples compared (turning, after the start-up, no held readings).
    inertia_kg_m2 : float
        J = ∫ρJ dx, the string's polar mass moment [kg·m²].
    k_t_per_s : float
        The configured damping rate the model ran with [1/s].
    """
    t = np.asarray(time_s, dtype=float)
    dt = float(t[1] - t[0]) if t.size > 1 else 1.0
    meas, model = np.asarray(measured_Nm, float), np.asarray(model_Nm, float)
    speed = np.abs(np.asarray(speed_rad_s, dtype=float))
    rows = []
    steady_meas = smooth(meas, dt, TORQUE_SMOOTH_S)
    steady_model = smooth(model, dt, TORQUE_SMOOTH_S)
    for s in levels(t, speed, usable):
        error = cycle_mean_error([meas[s]], dt)
        if error is None or _stick_slip(steady_meas[s]) or _stick_slip(steady_model[s]):
            continue
        gap = cycle_mean([meas[s]], dt) - cycle_mean([model[s]], dt)
        rows.append((float(np.mean(speed[s])), gap, np.sqrt(2.0) * error[0]))
    speeds = np.array([r[0] for r in rows])
    if len(rows) < 2 or np.ptp(speeds) < MIN_SPEED_STEP * speeds.max():
        return ViscousSlope(None, None, len(rows), (
            "viscous damping not identified: the segment has "
            f"{'no' if not rows else 'one'} set-point of steady rotation (no stick-slip) "
            f"of {MIN_LEVEL_S:g} s or more at a speed {100 * MIN_SPEED_STEP:.0f} % from "
            "another; μ_k's interval carries the damping assumed "
            "(model.k_t_uncertainty_factor)"))
    slope, sigma = _weighted_slope(speeds, np.array([r[1] for r in rows]),
                                   np.array([r[2] for r in rows]))
    k_t = k_t_per_s + slope / inertia_kg_m2
    half = _Z95 * sigma / inertia_kg_m2
    described = (f"{k_t:.3g} ± {half:.2g} 1/s from {len(rows)} set-points at "
                 + ", ".join(f"{v * 30.0 / np.pi:.0f}" for v in speeds) + " RPM")
    if k_t <= 0.0 or half > TOLERANCE * k_t:
        return ViscousSlope(None, None, len(rows), (
            f"viscous damping not identified ({described}, configured {k_t_per_s:g} 1/s: "
            f"wider than ±{100 * TOLERANCE:.0f} %); μ_k's interval carries the damping "
            "assumed (model.k_t_uncertainty_factor)"))
    return ViscousSlope(k_t, half, len(rows), (
        f"viscous damping identified: apparent k_t = {described} (configured "
        f"{k_t_per_s:g} 1/s; the mud's damping and any rate dependence of the friction "
        "together, docs/theory.md §6.4)"))


def _stick_slip(smoothed_Nm: np.ndarray) -> bool:
    """Whether a level's smoothed torque stick-slips (:data:`STICK_SLIP_FLUCTUATION`): its
    mean then turns on μ_s and the cycle's shape, which the model has only approximately,
    and a difference between levels would be read as damping."""
    mean = float(np.mean(smoothed_Nm))
    return mean == 0.0 or float(np.std(smoothed_Nm)) > STICK_SLIP_FLUCTUATION * abs(mean)


def _weighted_slope(x: np.ndarray, y: np.ndarray, sigma: np.ndarray) -> tuple[float, float]:
    """Slope of y on x by weighted least squares and its standard error.

    >>> s, e = _weighted_slope(np.array([1.0, 2.0]), np.array([3.0, 5.0]), np.ones(2))
    >>> round(s, 6), round(e, 6)
    (2.0, 1.414214)
    """
    w = 1.0 / np.maximum(sigma, 1e-12) ** 2
    xm = np.sum(w * x) / np.sum(w)
    sxx = np.sum(w * (x - xm) ** 2)
    slope = float(np.sum(w * (x - xm) * y) / sxx)
    return slope, float(np.sqrt(1.0 / sxx))
