"""Top-drive inertia: how much a segment's outputs rest on it, and what its data say of it
(docs/theory.md §5.4, issue 34 item 2).

With a logged motor torque (``rig.torque_kind = "motor"``) the string's torque at the top is
τ(0) = τ_m − I_TD·dω₀/dt (docs/theory.md §3, eq. 7): the observer reads the downhole state
from it, so a wrong I_TD (a gear change doubles or halves the effective inertia) puts
ΔI·dω₀/dt into the torque it reads, through every acceleration. A logged string torque
does not carry the term (nothing here applies).

Per segment, from the fitted speed-driven model of step 6 (no model run of its own:
vectorised NumPy over the segment's grid):

1. the **share**: the RMS of the inertia correction I_TD·dω₀/dt against the RMS of the
   torque's own variation (both smoothed over :data:`SMOOTH_S` and high-passed over
   :data:`HIGH_PASS_S`; the variation taken as at least :data:`VARIATION_FLOOR` of the mean
   torque). Below :data:`MATERIAL_SHARE` the trace does not rest on the inertia
   (a stiff drive holds ω₀ through stick-slip): 0.4–2.5× the configured value left the
   validation sweep's windows and severities within tolerance there;
2. the **identification**: the top-drive equation τ_m − τ̂(0) = I_TD·dω₀/dt with τ̂(0) the
   fitted model's string torque, I_TD the slope of a least-squares fit of the filtered
   sides. Identified only where the fit's profile-likelihood 95 % interval (n_eff = the
   duration over :data:`HIGH_PASS_S`: the model's misfit is correlated over a stick-slip
   period) is within ±:data:`TOLERANCE` and the reverse regression (dω₀/dt on the torque)
   agrees within it — which needs the torque's variation explained by the acceleration
   (R² ≥ ~0.8), not by the model's misfit;
3. the **verdict**: where the share is material and the inertia not identified, or
   identified and beyond ±:data:`TOLERANCE` of the configured one, the bit-speed trace and
   its statistics are withheld (``top_drive_inertia_unconfirmed`` /
   ``top_drive_inertia_contradicted``); μ_k matches mean torques, which the inertia term
   does not move (the mean of dω₀/dt over a segment is the change of speed over its
   length), and stands.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drillfric.estimation.skew import high_pass, moving_mean

#: Smoothing of both sides before the fit [s] (sensor noise, which the derivative
#: amplifies; the accelerations of set-point steps, start-ups and a soft drive stay).
SMOOTH_S = 1.0
#: High-pass window: the moving mean removed (the friction level, the slow set-point) [s].
HIGH_PASS_S = 4.0
#: Share of the torque's variation the inertia correction may reach before the trace rests
#: on the inertia (the validation's stiff stick-slip stands 0.09–0.10; set-point steps
#: 0.24–0.32 at 5–100 Hz, a soft-torque drive 1.9).
MATERIAL_SHARE = 0.2
#: The torque's variation is taken as at least this share of its mean level: in steady
#: rotation (no stick-slip) the speed noise's derivative against the torque's noise is no
#: measure of what the trace rests on (the steady plant read 1.0 without it, 0.14 with).
VARIATION_FLOOR = 0.15
#: Largest relative uncertainty of an inertia stated as identified, and the largest
#: departure from the configured value it confirms (issue 34: ±25 % at 10–100 Hz).
TOLERANCE = 0.25
#: χ²₁ 95 % quantile (the profile-likelihood interval: 2·Δℓ ≤ 3.84).
CHI2_95 = 3.84


@dataclass(frozen=True)
class Inertia:
    """What a segment's data say of the top-drive inertia.

    Attributes
    ----------
    configured_kg_m2 : float
        ``rig.top_drive_inertia_kg_m2`` [kg·m²].
    share : float or None
        RMS of the inertia correction against the RMS of the torque's variation [-] (None:
        too short, or a string torque).
    identified_kg_m2, uncertainty_kg_m2 : float or None
        The identified inertia and its 95 % half-width [kg·m²] (None: not identified).
    source : str
        ``"not used"`` (a string torque), ``"immaterial"`` (the trace does not rest on it),
        ``"confirmed"`` (identified within ±25 % of the configured), ``"contradicted"``
        (identified beyond), ``"not identified"``.
    reason : str or None
        Why the trace is withheld ("the inertia ..."), None when it is not.
    """

    configured_kg_m2: float
    share: float | None
    identified_kg_m2: float | None
    uncertainty_kg_m2: float | None
    source: str
    reason: str | None = None


def identify(time_s: np.ndarray, surface_rad_s: np.ndarray, motor_torque_Nm: np.ndarray,
             model_torque_Nm: np.ndarray) -> tuple[float, float, float, float, float] | None:
    """The fit of the top-drive equation (docs/theory.md §5.4, eq. 5.4a) on a uniform grid.

    Returns
    -------
    (I, half_width, I_reverse, r2, rms_accel_over_torque) or None
        Slope [kg·m²], its profile-likelihood 95 % half-width [kg·m²], the reverse
        regression's slope [kg·m²], the share of the filtered torque difference explained
        [-], and RMS(dω₀/dt)/max(RMS(τ_m), :data:`VARIATION_FLOOR`·|mean τ_m|) of the
        filtered sides [1/(kg·m²)]; None when the segment is shorter than a few high-pass
        windows or has no acceleration.
    """
    t = np.asarray(time_s, dtype=float)
    if t.size < 3:
        return None
    dt = float(t[1] - t[0])
    k, hp = max(1, round(SMOOTH_S / dt)), max(3, round(HIGH_PASS_S / dt))
    rows = slice(hp + k, t.size - hp - k)
    if t.size - 2 * (hp + k) < 3 * hp:
        return None
    accel = high_pass(np.gradient(moving_mean(surface_rad_s, k), dt), hp)[rows]
    torque = high_pass(moving_mean(motor_torque_Nm, k), hp)[rows]
    diff = high_pass(moving_mean(motor_torque_Nm - model_torque_Nm, k), hp)[rows]
    xx, xy, yy = float(accel @ accel), float(accel @ diff), float(diff @ diff)
    level = VARIATION_FLOOR * abs(float(np.mean(motor_torque_Nm[rows])))
    tt = max(float(torque @ torque), accel.size * level ** 2)
    if xx <= 0.0 or tt <= 0.0 or yy <= 0.0:
        return None
    slope = xy / xx
    rss_min = max(yy - xy * slope, 1e-12 * yy)
    n_eff = max(accel.size * dt / HIGH_PASS_S, 1.0)
    half = float(np.sqrt(rss_min * np.expm1(CHI2_95 / n_eff) / xx))
    reverse = yy / xy if xy != 0.0 else np.inf
    return slope, half, float(reverse), xy * xy / (xx * yy), float(np.sqrt(xx / tt))


def assess(time_s: np.ndarray, surface_rad_s: np.ndarray, motor_torque_Nm: np.ndarray,
           model_torque_Nm: np.ndarray, configured_kg_m2: float,
           torque_kind: str = "motor") -> Inertia:
    """The verdict on one segment's top-drive inertia (module docstring).

    Examples
    --------
    >>> t = np.arange(0.0, 60.0, 0.1)
    >>> w = 6.0 + np.sin(t)
    >>> tau = 2900.0 * np.cos(t) + 5e3
    >>> assess(t, w, tau, np.full(t.size, 5e3), 2900.0).source
    'confirmed'
    >>> assess(t, w, tau, np.full(t.size, 5e3), 2900.0, "string").source
    'not used'
    """
    configured = float(configured_kg_m2)
    if torque_kind != "motor":
        return Inertia(configured, None, None, None, "not used")
    fit = identify(time_s, surface_rad_s, motor_torque_Nm, model_torque_Nm)
    if fit is None:
        return Inertia(configured, None, None, None, "immaterial")
    slope, half, reverse, _, accel_share = fit
    share = configured * accel_share
    half = max(half, abs(reverse - slope))
    known = slope > 0 and half <= TOLERANCE * slope
    value, pm = (slope, half) if known else (None, None)
    if known and abs(slope / configured - 1.0) > TOLERANCE and \
            abs(slope - configured) > half:
        return Inertia(configured, share, value, pm, "contradicted", (
            f"top-drive inertia contradicted: the data give {slope:.0f} ± {half:.0f} kg·m² "
            f"against the configured {configured:.0f} (rig.top_drive_inertia_kg_m2; a gear "
            f"change?)"))
    if known:
        return Inertia(configured, share, value, pm, "confirmed")
    if share < MATERIAL_SHARE:
        return Inertia(configured, share, None, None, "immaterial")
    return Inertia(configured, share, None, None, "not identified", (
        f"top-drive inertia not identified: its correction I_TD·dω₀/dt is {share:.0%} of the "
        f"torque's variation, so the trace rests on rig.top_drive_inertia_kg_m2 "
        f"({configured:.0f} kg·m²), and the torque the fitted model leaves is not explained "
        f"by the accelerations (a gear change would go unseen)"))
