"""The torque on bit of on-bottom segments from the off-bottom friction nearby, and the
friction log of a drilling record (docs/theory.md §2.3, issue 22 item 1).

On bottom the surface torque holds the string's friction and the bit–rock torque; the model
has no bit law, so the μ_k of an on-bottom segment is "apparent". Engineers separate the
two with the torque difference on and off bottom. Here:

1. every rotating segment carries the pieces of its modelled mean torque that are not
   μ_k·T_N — the known cased-hole friction and the viscous torque at its mean speed — and
   the standard error of its measured mean torque (:func:`torque_terms`);
2. the off-bottom friction factors of the record, converged segments and pools of short
   ones at neighbouring depths (:func:`drillfric.estimation.consensus.pool_short_segments`),
   make a friction log along depth (:func:`friction_log`), each μ_k with its uncertainty;
3. each on-bottom segment takes the friction-log entry nearest in the string's friction
   torque, no further than :data:`~drillfric.estimation.consensus.POOL_TORQUE_SHARE` of it
   (a few stands), and gets T_bit = T_on − (μ_k·T_N + T_fixed), where T_N is the string's
   ∫F_c dx at the on-bottom load case (the WOB changes the axial load and hence the side
   forces), then μ_bit = 3·T_bit/(WOB·D_bit) and Teale's mechanical specific energy from
   T_bit; or null with the reason (:func:`assess`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from drillfric.estimation.consensus import POOL_TORQUE_SHARE, entry_half_width
from drillfric.result import SegmentRecord
from drillfric.units import RPM_TO_RAD_S
from drillfric.vocabulary import Kind, Status

#: Block length of the standard error of a mean torque [s]: longer than a stick-slip
#: period (4 × the wave travel time, 2–10 s), so block means are nearly independent.
BLOCK_S = 10.0
_Z95 = 1.96


@dataclass(frozen=True)
class TorqueTerms:
    """What one rotating segment gives the bit-torque separation.

    Attributes
    ----------
    surface_rpm_mean : float
        Mean top-drive speed over the scored rotation [RPM].
    surface_torque_turning_Nm : float or None
        Mean measured string torque while the top drive turns [N·m].
    surface_torque_sem_Nm : float or None
        Its standard error [N·m] (None: too short).
    torque_per_mu_Nm, torque_fixed_Nm : float or None
        The model's mean string torque over the scored rotation without bit torque is
        ``torque_fixed_Nm + μ_k·torque_per_mu_Nm`` [N·m] (on bottom only, else None).
    """

    surface_rpm_mean: float
    surface_torque_turning_Nm: float | None
    surface_torque_sem_Nm: float | None
    torque_per_mu_Nm: float | None = None
    torque_fixed_Nm: float | None = None


#: The second model run of :func:`torque_terms` is at this multiple of the first μ [-].
LINE_STEP = 0.75


def torque_terms(meas, fitted, model_at=None, mu_k: float | None = None) -> TorqueTerms:
    """:class:`TorqueTerms` of a segment.

    On bottom, the bit torque that, with friction μ, makes the model's mean torque equal the
    measured one, T_bit(μ), is found at two friction factors with the speed-driven model of
    docs/theory.md §6.4 at the on-bottom load case (F_c with the WOB), driven by the
    segment's measured speed, and taken as a line between them (docs/theory.md §2.3):

    1. at the apparent μ_a (the segment's fit, ``fitted``: no bit torque) T_bit = the mean
       measured − modelled torque, ≈ 0;
    2. at :data:`LINE_STEP`·μ_a, T_bit = the measured mean − the model's without bit, then
       corrected once by the model run with that Coulomb bit (the bit changes how the
       string sticks and slips, and so its mean friction).

    The line is stored as the model's off-bottom torque T_off(μ) = T_on − T_bit(μ) =
    ``torque_fixed_Nm + μ·torque_per_mu_Nm``. While the whole string slides both runs are
    exact and the line is the model's; in stick-slip it is the model's own interpolation.

    Parameters
    ----------
    meas : Measurements
        The segment's top-drive speed on its uniform grid.
    fitted : FitEvidence
        Measured and modelled string torque at the apparent factors, and the scored samples.
    model_at : callable, optional
        (μ scale, bit torque [N·m]) → the model's string torque on ``fitted.time_s`` [N·m];
        None off bottom (no line).
    mu_k : float, optional
        The apparent μ_k the evidence was modelled at [-].
    """
    scored = _turning(fitted, meas)
    t = fitted.time_s[scored]
    omega = np.interp(t, meas.time_s, meas.surface_rad_s) if t.size else meas.surface_rad_s
    measured = fitted.measured_Nm[scored]
    terms = TorqueTerms(float(np.mean(omega)) / RPM_TO_RAD_S,
                        float(np.mean(measured)) if measured.size else None,
                        mean_standard_error(t, measured))
    if model_at is None or not mu_k or not scored.any():
        return terms
    t_on = float(np.mean(measured))
    bit_a = t_on - float(np.mean(fitted.model_Nm[scored]))
    bit_b = t_on - float(np.mean(model_at(LINE_STEP)[scored]))
    if bit_b > 0:
        bit_b += t_on - float(np.mean(model_at(LINE_STEP, bit_b)[scored]))
    slope = (bit_b - bit_a) / ((1.0 - LINE_STEP) * mu_k)  # −dT_bit/dμ = dT_off/dμ
    return replace(terms, torque_per_mu_Nm=slope, torque_fixed_Nm=t_on - bit_a - slope * mu_k)


def _turning(fitted, meas) -> np.ndarray:
    """The scored samples up to the stop: the wound-up string held at rest after it holds
    static friction the model cannot know, so the means end where the top drive last
    turned at half its median speed."""
    if fitted.scored is None:
        return np.zeros(fitted.time_s.size, dtype=bool)
    omega = np.interp(fitted.time_s, meas.time_s, meas.surface_rad_s)
    fast = np.flatnonzero(fitted.scored & (omega > 0.5 * np.median(omega[fitted.scored])))
    keep = fitted.scored.copy()
    if fast.size:
        keep[fast[-1] + 1:] = False
    return keep


def mean_standard_error(time_s: np.ndarray, x: np.ndarray, block_s: float = BLOCK_S
                        ) -> float | None:
    """Standard error of the mean of ``x`` from :data:`BLOCK_S` block means [unit of x];
    None with fewer than 3 blocks.

    Examples
    --------
    >>> t = np.arange(0.0, 100.0, 0.01)
    >>> round(mean_standard_error(t, np.sin(2 * np.pi * t)), 3)  # whole periods: ≈ 0
    0.0
    """
    if time_s.size < 3:
        return None
    block = np.floor((time_s - time_s[0]) / block_s).astype(int)
    counts = np.bincount(block)
    full = counts >= 0.5 * counts.max()
    means = np.bincount(block, weights=x)[full] / counts[full]
    if means.size < 3:
        return None
    return float(np.std(means, ddof=1) / np.sqrt(means.size))


def rate_of_penetration_m_h(rows: pd.DataFrame) -> float | None:
    """Rate of penetration over a segment [m/h]: the least-squares slope of the hole depth
    (else the bit depth) against time; None without depth or when it does not advance."""
    for name in ("hole_depth_m", "bit_depth_m"):
        if name not in rows:
            continue
        t, depth = rows["time_s"].to_numpy(float), rows[name].to_numpy(float)
        ok = np.isfinite(t) & np.isfinite(depth)
        if ok.sum() < 3 or np.ptp(t[ok]) <= 0:
            continue
        slope = float(np.polyfit(t[ok] - t[ok][0], depth[ok], 1)[0]) * 3600.0
        return slope if slope > 0 else None
    return None


# --------------------------------------------------------------------- friction log
def friction_log(records: list[SegmentRecord], pools: list[dict]) -> list[dict]:
    """The off-bottom μ_k of a record along depth (summary.json ``off_bottom_friction_log``): each
    converged segment and each pool of short ones, shallow to deep, with the μ_k's 95 %
    half-width (:func:`~drillfric.estimation.consensus.entry_half_width`) and the T_N at
    its ends (for the distance to an on-bottom segment)."""
    by_id = {r.id: r for r in records}
    pooled = {i for p in pools for i in p["segment_ids"]}
    entries = []
    for r in records:
        if r.status is Status.OK and r.kind is Kind.OFF_BOTTOM and r.converged and \
                r.mu_k is not None and r.id not in pooled:
            entries.append(_entry([r], r.mu_k))
    for p in pools:
        entries.append(_entry([by_id[i] for i in p["segment_ids"]], p["mu_k"]))
    return sorted(entries, key=lambda e: e["md_from_m"])


def _entry(members: list[SegmentRecord], mu_k: float) -> dict:
    ends = sorted(members, key=lambda r: r.bit_depth_m)
    return {"segment_ids": [r.id for r in members], "md_from_m": ends[0].bit_depth_m,
            "md_to_m": ends[-1].bit_depth_m, "mu_k": float(mu_k),
            "mu_k_uncertainty": float(entry_half_width(members, mu_k)),
            "rotation_s": float(sum(r.duration_s for r in members)),
            "T_N_from_Nm": ends[0].T_N_Nm, "T_N_to_Nm": ends[-1].T_N_Nm}


def off_bottom_T_N(records: list[SegmentRecord]):
    """T_N [N·m] of the off-bottom load case as a function of bit depth [m]: linear
    through the estimated off-bottom segments, extended with the end slopes (one segment:
    T_N ∝ depth); None without any."""
    pts = sorted({(r.bit_depth_m, r.T_N_Nm) for r in records
                  if r.status is Status.OK and r.kind is Kind.OFF_BOTTOM and r.T_N_Nm
                  and r.bit_depth_m})
    if not pts:
        return None
    d, tn = np.array(pts).T
    if d.size == 1 or np.ptp(d) == 0:
        return lambda depth: tn[-1] * depth / d[-1]

    def at(depth: float) -> float:
        if depth < d[0]:
            return tn[0] + (depth - d[0]) * (tn[1] - tn[0]) / (d[1] - d[0])
        if depth > d[-1]:
            return tn[-1] + (depth - d[-1]) * (tn[-1] - tn[-2]) / (d[-1] - d[-2])
        return float(np.interp(depth, d, tn))
    return at


def _share_to(entry: dict, T_N: float) -> float:
    """Share of the friction torque between T_N and the nearest end of ``entry`` [-]."""
    ends = [v for v in (entry["T_N_from_Nm"], entry["T_N_to_Nm"]) if v]
    if not ends:
        return np.inf
    if min(ends) <= T_N <= max(ends):
        return 0.0
    return min(abs(T_N - e) / max(T_N, e) for e in ends)


# --------------------------------------------------------------------- on bottom
def assess(records: list[SegmentRecord], pools: list[dict], bit_diameter_m: float | None,
           motor_drop: float | None = None) -> tuple[list[SegmentRecord], list[dict]]:
    """The bit torque, μ_bit and MSE of every estimated on-bottom segment (or null with the
    reason), and the record's friction log.

    Parameters
    ----------
    records : list of SegmentRecord
        The well's segments, pooled.
    pools : list of dict
        The pools of short segments (summary.json ``pooled``).
    bit_diameter_m : float or None
        D_bit [m] (``well.bit_diameter_m``); None: μ_bit and MSE are null.
    motor_drop : float or None
        With a declared mud motor, the largest share of its speed it loses on bottom
        (``bha.motor_speed_drop``); None: no motor, the bit turns at the surface's mean speed.
    """
    log = friction_log(records, pools)
    T_N_off = off_bottom_T_N(records)
    out = []
    for r in records:
        if r.status is Status.OK and r.kind is Kind.ON_BOTTOM:
            r = replace(r, **on_bottom_fields(r, log, T_N_off, bit_diameter_m, motor_drop))
        out.append(r)
    return out, [{k: v for k, v in e.items() if not k.startswith("T_N")} for e in log]


def on_bottom_fields(r: SegmentRecord, log: list[dict], T_N_off,
                     bit_diameter_m: float | None, motor_drop: float | None = None) -> dict:
    """The bit-torque fields of one on-bottom record (docs/theory.md §2.3)."""
    if r.surface_torque_turning_Nm is None or r.torque_per_mu_Nm is None:
        return {"bit_torque_reason": "no rotating torque to separate (too short)"}
    source = _nearest(log, T_N_off(r.bit_depth_m) if T_N_off else None)
    if source is None:
        return {"bit_torque_reason": (
            "no off-bottom μ_k within reach: no converged or pooled off-bottom rotation "
            f"within {POOL_TORQUE_SHARE:.0%} of the string's friction torque of this depth "
            "(a few stands); rotate off bottom ≥ 30 s before connections")}
    mu, u_mu = source["mu_k"], source["mu_k_uncertainty"]
    t_bit = r.surface_torque_turning_Nm - (mu * r.torque_per_mu_Nm + r.torque_fixed_Nm)
    noise = _Z95 * (r.surface_torque_sem_Nm or 0.0)
    u_bit = float(np.hypot(u_mu * r.torque_per_mu_Nm, noise))
    fields = {"bit_torque_mu_k": mu, "bit_torque_mu_k_uncertainty": u_mu,
              "bit_torque_evidence": tuple(source["segment_ids"])}
    if t_bit + u_bit < 0:
        return fields | {"bit_torque_reason": (
            f"the on-bottom torque is {-t_bit:.0f} N·m below the modelled off-bottom torque "
            f"at μ_k = {mu:.3f} (±{u_bit:.0f} N·m): string, WOB or μ_k contradict the "
            "data")}
    fields |= {"bit_torque_Nm": float(t_bit), "bit_torque_uncertainty_Nm": u_bit}
    return fields | _bit_measures(r, t_bit, u_bit, bit_diameter_m, motor_drop)


def _nearest(log: list[dict], T_N: float | None) -> dict | None:
    """The friction-log entry nearest in friction torque, within the pooling share."""
    if T_N is None or not log:
        return None
    share, entry = min(((_share_to(e, T_N), i) for i, e in enumerate(log)))
    return log[entry] if share <= POOL_TORQUE_SHARE else None


def _bit_measures(r: SegmentRecord, t_bit: float, u_bit: float,
                  bit_diameter_m: float | None, motor_drop: float | None) -> dict:
    """μ_bit and Teale's MSE from T_bit at the bit's mean speed (:func:`bit_speed_rpm`), or
    the reason they are null."""
    if not r.wob_N or r.wob_N <= 0:
        return {"bit_torque_reason": "no weight on bit logged: μ_bit and MSE not computed"}
    if bit_diameter_m is None:
        return {"bit_torque_reason": "no bit diameter (set well.bit_diameter_m): μ_bit and "
                                     "MSE not computed"}
    out = {"mu_bit": mu_bit(t_bit, r.wob_N, bit_diameter_m),
           "mu_bit_uncertainty": mu_bit(u_bit, r.wob_N, bit_diameter_m)}
    if not r.rop_m_h or not r.surface_rpm_mean:
        return out | {"bit_torque_reason": "the bit did not advance (no rate of "
                                           "penetration): MSE not computed"}
    speed = bit_speed_rpm(r.surface_rpm_mean, r.motor_rpm_mean, motor_drop)
    if speed is None:
        return out | {"bit_torque_reason": "the mud motor's speed is not known (flow "
                                           "missing): MSE not computed"}
    rpm, u_rpm = speed
    mse = lambda w, t, n: teale_mse_Pa(w, t, n, r.rop_m_h, bit_diameter_m)  # noqa: E731
    return out | {"mse_Pa": mse(r.wob_N, t_bit, rpm),
                  "mse_uncertainty_Pa": float(np.hypot(mse(0.0, u_bit, rpm),
                                                       mse(0.0, t_bit, u_rpm)))}


def bit_speed_rpm(surface_rpm_mean: float, motor_rpm_mean: float | None,
                  motor_drop: float | None) -> tuple[float, float] | None:
    """The bit's mean speed on bottom and its 95 % half-width [RPM]: the surface's mean
    (the BHA's, in the mean) plus a declared motor's (docs/theory.md eq. 2.4c), whose
    on-bottom speed k·Q·(1 − drop/2) is known to ±k·Q·drop/2 (eq. 2.4b); None where a
    motor is declared (``motor_drop`` not None) but its speed is not known.

    Examples
    --------
    >>> bit_speed_rpm(60.0, None, None)
    (60.0, 0.0)
    >>> bit_speed_rpm(60.0, 153.0, 0.3)  # k·Q = 180 RPM, 126–180 on bottom
    (213.0, 27.0)
    """
    if motor_drop is None:
        return surface_rpm_mean, 0.0
    if motor_rpm_mean is None:
        return None
    return surface_rpm_mean + motor_rpm_mean, motor_rpm_mean * motor_drop / (2.0 - motor_drop)


def mu_bit(bit_torque_Nm: float, wob_N: float, bit_diameter_m: float) -> float:
    """Bit friction coefficient μ_bit = 3·T_bit/(WOB·D_bit) [-], the inverse of
    :func:`drillfric.torsional.bit_torque_cap` (uniform contact over the face).

    Examples
    --------
    >>> round(mu_bit(1295.4, 60e3, 0.2159), 3)
    0.3
    """
    return float(3.0 * bit_torque_Nm / (wob_N * bit_diameter_m))


def teale_mse_Pa(wob_N: float, bit_torque_Nm: float, rpm: float, rop_m_h: float,
                 bit_diameter_m: float) -> float:
    """Teale's mechanical specific energy [Pa] (docs/theory.md Eq. 2.2c):
    MSE = WOB/A + 2π·N·T_bit/(A·ROP), A = πD²/4, N [rev/s], ROP [m/s].

    Examples
    --------
    >>> round(teale_mse_Pa(100e3, 3000.0, 120.0, 20.0, 0.2159) / 1e6)  # MPa
    188
    """
    area = np.pi * bit_diameter_m ** 2 / 4.0
    return float(wob_N / area + 2.0 * np.pi * (rpm / 60.0) * bit_torque_Nm
                 / (area * rop_m_h / 3600.0))
