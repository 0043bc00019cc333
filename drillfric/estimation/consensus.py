"""The well's friction factors from its segments: pooling of short segments and the
consensus (docs/theory.md "Well consensus", docs/segmentation.md).

Both take the segments' :class:`~drillfric.result.SegmentRecord` and never make a value
up: a well-level number comes from converged segments (or pools of short ones that agree),
else it is None.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.stats import t as student_t

from drillfric.estimation.batch.settings import mu_k_tolerance
from drillfric.result import Flag, SegmentRecord
from drillfric.vocabulary import Kind, Method, Status

#: Flags a short segment may carry and still be pooled (it is only too short: a few torque
#: cycles leave its own μ_k uncertain, which is what pooling answers; ``bistable_regime``
#: concerns only the μ_s bound, withheld, not μ_k; ``bit_speed_drift``,
#: ``stick_slip_beyond_validated`` and ``channel_skew_unidentified`` only the bit-speed trace
#: and its statistics; ``observer_deadlock_averted`` an observer start the guard released,
#: not the batch μ_k pooled — it had kept every 30–60-s rotation of a string that does not
#: stick-slip out of the friction log, and with it every on-bottom T_bit nearby).
_POOLABLE = frozenset({"too_short_to_converge", "observer_starts_disagree",
                       "estimators_disagree", "bit_speed_drift", "mu_k_uncertain",
                       "bistable_regime", "stick_slip_beyond_validated",
                       "stick_slip_undetermined", "channel_skew_unidentified",
                       "observer_deadlock_averted"})
#: Short segments pool when the string's friction torque added between their bit depths is
#: at most this share of the torque at the deeper one, |ΔT_N|/T_N (docs/theory.md "Pooling
#: along depth"). The reported μ_k is the torque-weighted mean of μ(x) over the whole
#: string, so a friction change of ±50 % in the hole drilled between the members moves it
#: by at most 0.10 × 50 % = 5 %, the converged tolerance: typically 3–5 stands.
POOL_TORQUE_SHARE = 0.10
#: Without T_N (no torque and drag) segments pool only within this depth [m] (one stand).
POOL_DEPTH_M = 5.0
#: ...the 95 % half-width of their mean, t₀.₉₇₅,ₙ₋₁·sd/√n (Student's t: 3–5 pieces hold
#: little information on their own scatter), is within the converged tolerance
#: (:func:`mu_k_tolerance`)...
_P95 = 0.975
#: ...and together they hold at least this much rotation [s] (the converged minimum).
POOL_MIN_ROTATION_S = 90.0
#: Validated tolerance of an identified μ_s (docs/validation.md: every claim within 10 % on
#: both plant families), relative: the floor of a μ_s's 95 % half-width, since the spread
#: of the fits behind one claim leaves out the model-form error (the demo's 0.585 ± 0.003
#: for a true 0.600).
MU_S_TOLERANCE = 0.10


def mean_half_width(mu: np.ndarray) -> float:
    """95 % half-width of the mean of the pieces ``mu`` [-], t₀.₉₇₅,ₙ₋₁·sd/√n (0 for one
    piece): the sd of n pieces is itself uncertain, so the normal 1.96 would understate it
    (by 6.5× for two pieces, 2.2× for three).

    Examples
    --------
    >>> round(mean_half_width(np.array([0.24, 0.25, 0.26])), 4)
    0.0248
    """
    if mu.size < 2:
        return 0.0
    return float(student_t.ppf(_P95, mu.size - 1) * np.std(mu, ddof=1) / np.sqrt(mu.size))


def torque_share(a: SegmentRecord, b: SegmentRecord) -> float:
    """Share of the string's friction torque between the bit depths of ``a`` and ``b``,
    |T_N,a − T_N,b| / max(T_N) [-] (docs/theory.md "Pooling along depth"); without a T_N,
    0 within :data:`POOL_DEPTH_M` and infinite beyond.

    Examples
    --------
    >>> from drillfric.result import SegmentRecord
    >>> torque_share(SegmentRecord(T_N_Nm=40e3), SegmentRecord(T_N_Nm=42e3))  # doctest: +ELLIPSIS
    0.0476...
    """
    if a.T_N_Nm and b.T_N_Nm:
        return abs(a.T_N_Nm - b.T_N_Nm) / max(a.T_N_Nm, b.T_N_Nm)
    near = abs((a.bit_depth_m or 0.0) - (b.bit_depth_m or 0.0)) <= POOL_DEPTH_M
    return 0.0 if near else float("inf")


def pool_short_segments(records: list[SegmentRecord]) -> tuple[list, list[dict]]:
    """Pool short off-bottom segments at neighbouring bit depths whose μ_k agree into one
    estimate.

    Segments too short to converge alone (only ``too_short_to_converge`` keeps them from
    it) whose depths lie within :data:`POOL_TORQUE_SHARE` of the string's friction torque
    (:func:`torque_share`, from the shallowest of the group; so a change of friction along
    the hole moves their μ_k little, and their scatter is the estimator's), whose batch
    μ_k's mean has a 95 % half-width from their scatter within the
    converged tolerance of their logging (:func:`mu_k_tolerance`) and which together
    rotate for :data:`POOL_MIN_ROTATION_S`, give a converged estimate: the
    rotation-weighted mean μ_k. Returns the records (members flagged
    ``pooled``) and the pools (summary.json ``pooled``: members, depth span, μ_k, spread).
    """

    short = [r for r in records if r.status is Status.OK and r.kind is Kind.OFF_BOTTOM
             and not r.converged and r.method == Method.BATCH and r.mu_k is not None
             and set(r.quality_flags) <= _POOLABLE]
    groups: list[list[SegmentRecord]] = []
    for r in sorted(short, key=lambda r: r.bit_depth_m):
        if groups and torque_share(groups[-1][0], r) <= POOL_TORQUE_SHARE:
            groups[-1].append(r)
        else:
            groups.append([r])
    pools, members = [], {}
    for group in groups:
        mu = np.array([r.mu_k for r in group])
        weight = np.array([r.duration_s for r in group])
        tolerance = max(mu_k_tolerance(r.sample_interval_s) for r in group)
        if len(group) < 2 or weight.sum() < POOL_MIN_ROTATION_S or \
                mean_half_width(mu) > tolerance * mu.mean():
            continue
        depths = [r.bit_depth_m for r in group]
        pool = {"segment_ids": [r.id for r in group],
                "bit_depth_m": float(np.median(depths)),
                "md_from_m": float(min(depths)), "md_to_m": float(max(depths)),
                "mu_k": float(np.sum(mu * weight) / weight.sum()),
                "mu_k_spread": float(mu.max() - mu.min()), "rotation_s": float(weight.sum())}
        pools.append(pool)
        members |= {r.id: pool for r in group}
    return [_pooled(r, members[r.id]) if r.id in members else r for r in records], pools


def _pooled(record: SegmentRecord, pool: dict) -> SegmentRecord:
    span = f"{pool['md_from_m']:.0f}–{pool['md_to_m']:.0f} m" \
        if pool["md_to_m"] - pool["md_from_m"] >= 1.0 else f"{pool['bit_depth_m']:.0f} m"
    note = (f"pooled with segments {', '.join(map(str, pool['segment_ids']))} at "
            f"{span}: μ_k = {pool['mu_k']:.3f} over "
            f"{pool['rotation_s']:.0f} s of rotation")
    return replace(record, quality_flags=record.quality_flags + (Flag.POOLED,),
                   message="; ".join(filter(None, [record.message, note])))


def consensus(records: list[SegmentRecord], pools: list[dict] = ()) -> dict:
    """Well-level friction factors from the segments (never a made-up value), with their
    uncertainty and support (docs/theory.md "Well consensus").

    Only converged, off-bottom segments with status ok count, and pools of short segments
    (:func:`pool_short_segments`) as one each. μ_k: their median; μ_s: the median over those
    that identify it; otherwise the median of their lower bounds (each is claimed valid, so
    the median is too, and one unreliable segment cannot set it).

    ``mu_k_uncertainty`` / ``mu_s_uncertainty`` [-] (:func:`uncertainty`), ``mu_k_range``
    (lowest and highest supporting value) and ``mu_k_support`` / ``mu_s_support``: the
    segments behind the number (pool members counted) ``of`` the off-bottom rotating
    segments of the well.
    """
    ok = [r for r in records if r.status is Status.OK and r.kind is Kind.OFF_BOTTOM
          and r.converged]
    off = sum(r.kind is Kind.OFF_BOTTOM for r in records)
    k_rows = [r for r in ok if r.mu_k is not None]
    mu_k = [r.mu_k for r in k_rows] + [p["mu_k"] for p in pools]
    by_id = {r.id: r for r in records}
    own_k = [entry_half_width([r], r.mu_k) for r in k_rows] + [
        entry_half_width([by_id[i] for i in p["segment_ids"]], p["mu_k"]) for p in pools]
    s_rows = [r for r in ok if r.mu_s_identifiable and r.mu_s is not None]
    mu_s = [r.mu_s for r in s_rows]
    bounds = [r.mu_s_lower_bound for r in ok if r.mu_s_lower_bound is not None]
    k_support = len(k_rows) + sum(len(p["segment_ids"]) for p in pools)
    return {"mu_k": float(np.median(mu_k)) if mu_k else None,
            "mu_s": float(np.median(mu_s)) if mu_s else None,
            "mu_s_lower_bound": None if mu_s or not bounds else float(np.median(bounds)),
            "mu_k_uncertainty": uncertainty(mu_k, own_k),
            "mu_k_range": [float(min(mu_k)), float(max(mu_k))] if mu_k else None,
            "mu_k_support": {"segments": k_support, "of": off},
            "mu_s_uncertainty": uncertainty(mu_s, [max(r.mu_s_spread or 0.0,
                                                       MU_S_TOLERANCE * r.mu_s)
                                                   for r in s_rows]),
            "mu_s_support": {"segments": len(s_rows) if mu_s else len(bounds), "of": off}}


def entry_half_width(members: list[SegmentRecord], mu_k: float) -> float:
    """The 95 % half-width of one μ_k entry — a converged segment, or a pool of ``members``
    — [-]: the validated tolerance of its logging (:func:`mu_k_tolerance`, 5 % at ≤ 0.2 s,
    else 10 %: the model-form error found on both plant families, docs/validation.md
    "Calibrated intervals"), or where larger the scatter of a pool's pieces
    (:func:`mean_half_width`), half the spread of the observer's starts that gave a
    segment's number; the tolerance combined in quadrature with what the assumed viscous
    damping may move it by (``mu_k_damping_uncertainty``: independent errors). One rule for
    the headline's ū and the friction log's entries. (A torque match of 2 % had been the
    floor; on the second plant family every headline ± so made excluded the truth, errors
    2–4 %.)

    Examples
    --------
    >>> from drillfric.result import SegmentRecord
    >>> round(entry_half_width([SegmentRecord(mu_k=0.3, sample_interval_s=0.01)], 0.3), 4)
    0.015
    """
    tolerance = max(mu_k_tolerance(r.sample_interval_s) for r in members)
    scatter = mean_half_width(np.array([r.mu_k for r in members]))
    observer = max(((r.mu_k_spread or 0.0) / 2.0 for r in members
                    if r.method == Method.OBSERVER), default=0.0)
    damping = max((r.mu_k_damping_uncertainty or 0.0 for r in members), default=0.0)
    return max(float(np.hypot(tolerance * mu_k, damping)), scatter, observer)


def uncertainty(values: list[float], own: list[float]) -> float | None:
    """The ± of a well-level factor [-]: √(s² + ū²), with s half the 16–84 % range of the
    supporting segments' values (their scatter along the well; 0 for one segment) and ū
    the median of the segments' own uncertainties ``own``. None without values.

    Examples
    --------
    >>> round(uncertainty([0.20, 0.22, 0.24], [0.004, 0.004, 0.005]), 4)
    0.0142
    >>> uncertainty([0.2], [0.004]), uncertainty([], [])
    (0.004, None)
    """
    if not values:
        return None
    lo, hi = np.percentile(values, [16.0, 84.0])
    scatter = (hi - lo) / 2.0
    own_median = float(np.median(own)) if len(own) else 0.0
    return float(np.hypot(scatter, own_median))
