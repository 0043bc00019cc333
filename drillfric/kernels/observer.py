"""Compiled (numba) kernel of the adaptive observer, docs/theory.md §5 (eqs. 32–44 of [1]).

The observer is a copy of the Courant-1 plant of :mod:`drillfric.kernels.plant` (same transport,
junction, friction and top-drive steps, called from there, with the friction profile and law
of docs/theory.md §3.2) plus output injection of the innovation e = ω̂₀ − ω₀ and the friction
adaptation laws. Several members (starts: initial guesses of μ_s, μ_k, or ensemble members)
advance in one call. They are independent, so each runs its whole time window on its own
(:func:`observe_member`, members outermost, cells innermost); :func:`observer_kernel` loops
over a range of them without the GIL, and :func:`run_observer` runs disjoint ranges on
threads (as many as numba may use) when asked — the same numbers as one serial call, and one
compiled kernel instead of a serial and a ``prange`` one (the parallel-loop compilation cost
~2.5 s of a first run). The plain-NumPy twin is
:func:`drillfric.kernels.observer_numpy.run_observer`.

[1] U.J.F. Aarsnes, J. Auriol, F. Di Meglio, R.J. Shor, "Estimating friction factors while
    drilling", JPSE 179 (2019) 80–91.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
from numba import get_num_threads, literally, njit

from drillfric.kernels.plant import (
    LAW_STEP,
    drive_value,
    inflows,
    padded_size,
    pass_cells,
    top_drive_step,
    unpadded,
    variant,
    work_buffer,
)

#: Columns of the observer record, per start.
OBS_COLUMNS = ("mu_s", "mu_k", "surface_rad_s_est", "bit_rad_s_est", "bha_rad_s_est",
               "residual_rad_s", "surface_torque_est_Nm")
LAW_CORRECTED, LAW_PAPER = 0, 1


@njit(cache=True)
def measured_value(u, t0, dt, t, hold):
    """A uniformly sampled measurement at time t: linear interpolation, or the last sample
    (zero-order hold, as in the paper) when ``hold`` is true; held beyond the ends."""
    if not hold:
        return drive_value(u, t0, dt, t)
    s = (t - t0) / dt
    return u[min(max(int(s), 0), u.size - 1)] if s > 0.0 else u[0]


@njit(cache=True, inline="always")
def adapt(mu_s, mu_k, e, stuck, l_s, l_k, dt, law, mu_max):
    """Friction adaptation, eqs. (42)–(44) of [1]; returns (μ̂_s, μ̂_k).

    Sliding BHA: dμ̂_k/dt = +l_k e. Stuck BHA: the paper's law dμ̂_s/dt = −l_s e
    (``law`` = paper) or, by default, μ̂_s held (docs/theory.md §6.1: every μ_s law tried ends at
    its clamp, on μ̂_k or wherever its start put it; μ_s comes from the batch fit). Then
    μ̂_s ← max(μ̂_s, μ̂_k) (eq. 44) and both are clamped to [0, μ_max].
    """
    if stuck:
        if law == LAW_PAPER:
            mu_s -= dt * l_s * e
    else:
        mu_k += dt * l_k * e
    mu_k = min(max(mu_k, 0.0), mu_max)
    mu_s = min(max(mu_s, mu_k), mu_max)
    return mu_s, mu_k


@njit(cache=True, inline="always")
def deadlock_guard(mu_s, mu_k, stuck_s, events, turning_stuck, dt, deadlock_s):
    """Deadlock guard (docs/theory.md §6.1); returns (μ̂_s, μ̂_k, stuck time [s], interventions).

    While the estimated BHA is stuck and the measured top drive turns (``turning_stuck``)
    the stuck time grows by Δt, else it resets; past ``deadlock_s`` μ̂_s drops to μ̂_k (and
    μ̂_k by 20 % if μ̂_s already was there), the stuck time resets and one intervention is
    counted.
    """
    if not turning_stuck:
        return mu_s, mu_k, 0.0, events
    stuck_s += dt
    if stuck_s > deadlock_s:
        if mu_s <= mu_k * (1.0 + 1e-9):
            mu_k *= 0.8
        return mu_k, mu_k, 0.0, events + 1.0
    return mu_s, mu_k, stuck_s, events


@njit(cache=True, fastmath={"reassoc"})
def bha_speed(W, row, section_start):
    """Mean speed of the BHA cells (sections after the first) in row ``row`` of the speed
    buffer (ghost layout) [rad/s]; decides stuck/sliding in the adaptation (eqs. 42–43).

    Summed in any order (``reassoc``: vectorised; as a sequential sum this scalar loop was
    a fifth of an observer step): the mean differs from a sequential one by round-off,
    ~1e-16 relative.
    """
    acc = 0.0
    for s in range(1, section_start.size - 1):
        for j in range(section_start[s] + 1 + 2 * s, section_start[s + 1] + 1 + 2 * s):
            acc += W[row, j]
    return acc / max(section_start[-1] - section_start[1], 1)


@njit(cache=True)
def measurements_at_steps(u, m_t0, m_dt, t0, dt, n_steps, hold):
    """The measurement series at the model steps t0 + k·Δt, k = 0 … n_steps
    (:func:`measured_value`), computed once for all members."""
    out = np.empty(n_steps + 1)
    for k in range(n_steps + 1):
        out[k] = measured_value(u, m_t0, m_dt, t0 + k * dt, hold)
    return out


@njit(cache=True)
def observe_member(s, alpha, beta, omega0, mu_s, mu_k, guard, t0, n_steps, section_start,
                   junction_z, zeta, fcap, fix_k, fix_s, dt, kt_dt, omega_c, law_speed,
                   law_exp, bit_cap_rel, inv_itd, w_meas, tau_meas, p0, P0, inj_a, inj_b, P1,
                   l_k, l_s, adapt_law, mu_max, deadlock_s, omega_turn, times, out, law,
                   fixed):
    """Advance member ``s`` (row s of the state arrays) ``n_steps`` steps; see
    :func:`run_observer` for the arguments, except that ``w_meas``, ``tau_meas`` are the
    measurements at the model steps (:func:`measurements_at_steps`). The member works in its
    own :func:`drillfric.kernels.plant.work_buffer`. ``law``, ``fixed``: the friction
    variant (:func:`drillfric.kernels.plant.variant`), compile-time constants."""
    literally(law)
    literally(fixed)
    last = alpha.shape[1] + 2 * section_start.size - 4  # the bit cell in the ghost layout
    X = work_buffer(alpha[s], beta[s], section_start, (fcap, fix_k, fix_s, inj_a, inj_b))
    A, B, W = X[0:2], X[2:4], X[4:6]
    fcap, fix_k, fix_s, inj_a, inj_b = X[6], X[7], X[8], X[9], X[10]
    end = padded_size(section_start) - 1
    cur = np.int64(0)  # typed, not Literal[0]: one compiled pass_cells/inflows/bha_speed
    inv_vs = 1.0 / law_speed if law != LAW_STEP else 0.0
    q_td = 0.5 * zeta[0] * dt * inv_itd
    n_rec = times.size
    r = 0
    eps = 1e-9 * dt
    om, ms, mk = omega0[s], mu_s[s], mu_k[s]
    stuck_s, events = guard[s, 0], guard[s, 1]
    e_last = om - w_meas[0]
    w_bha_last = bha_speed(W, cur, section_start)
    for k in range(n_steps + 1):
        t = t0 + k * dt
        while r < n_rec and times[r] <= t + eps:
            out[r, s, 0] = ms
            out[r, s, 1] = mk
            out[r, s, 2] = om
            out[r, s, 3] = W[cur, last]
            out[r, s, 4] = w_bha_last
            out[r, s, 5] = e_last
            out[r, s, 6] = zeta[0] * (om - B[cur, 1])  # string torque at the top, eq. (15)
            r += 1
        if k == n_steps:
            break
        wm = w_meas[k]
        taum = tau_meas[k]
        e = om - wm
        beta0 = B[cur, 1]
        omega_next = top_drive_step(om, beta0, q_td, dt * inv_itd * taum - dt * p0 * e)
        omega_bar = 0.5 * (om + omega_next)
        inflows(A, B, W, cur, section_start, junction_z, 2.0 * omega_bar - beta0 - P0 * e,
                omega_bar, bit_cap_rel)
        if section_start.size > 2:  # β reflected into the pipe at the pipe/BHA junction
            B[cur, section_start[1] + 1] -= P1 * e
        pass_cells(A, B, W, cur, end, kt_dt, fcap, fix_s, fix_k, ms, mk, omega_c, inv_vs,
                   law_exp, law, fixed, inj_a, inj_b, e, True)
        cur = 1 - cur
        w_bha = bha_speed(W, cur, section_start)
        om = omega_next
        stuck = abs(w_bha) <= omega_c
        ms, mk = adapt(ms, mk, e, stuck, l_s, l_k, dt, adapt_law, mu_max)
        ms, mk, stuck_s, events = deadlock_guard(ms, mk, stuck_s, events,
                                                 stuck and abs(wm) > omega_turn, dt,
                                                 deadlock_s)
        e_last = e
        w_bha_last = w_bha
    unpadded(A[cur], section_start, alpha[s])
    unpadded(B[cur], section_start, beta[s])
    omega0[s], mu_s[s], mu_k[s] = om, ms, mk
    guard[s, 0], guard[s, 1] = stuck_s, events


def observer_kernel(law: int, fixed: bool):
    """The compiled observer kernel of one friction variant: it advances members
    ``first`` to ``last - 1`` (rows of the state arrays) ``n_steps`` steps and records at
    ``times``, with the arguments of :func:`run_observer` (without ``parallel``). It runs
    without the GIL (``nogil``), so threads advancing disjoint ranges of members run on
    several cores and give the same numbers as one call over all of them (the members do
    not interact). The variant is a constant of the compiled code (closure variables, cached
    per variant).
    """
    @njit(cache=True, nogil=True)
    def members(alpha, beta, omega0, mu_s, mu_k, guard, t0, n_steps, section_start,
                junction_z, zeta, fcap, fix_k, fix_s, dt, kt_dt, omega_c, law_speed, law_exp,
                bit_cap_rel, inv_itd, w_meas, tau_meas, m_t0, m_dt, hold, p0, P0, inj_a, inj_b,
                P1, l_k, l_s, adapt_law, mu_max, deadlock_s, omega_turn, times, out, first,
                last):
        wm = measurements_at_steps(w_meas, m_t0, m_dt, t0, dt, n_steps, hold)
        taum = measurements_at_steps(tau_meas, m_t0, m_dt, t0, dt, n_steps, hold)
        for s in range(first, last):
            observe_member(s, alpha, beta, omega0, mu_s, mu_k, guard, t0, n_steps,
                           section_start, junction_z, zeta, fcap, fix_k, fix_s, dt, kt_dt,
                           omega_c, law_speed, law_exp, bit_cap_rel, inv_itd, wm, taum, p0, P0,
                           inj_a, inj_b, P1, l_k, l_s, adapt_law, mu_max, deadlock_s,
                           omega_turn, times, out, law, fixed)

    return members


def _ranges(members: int, threads: int) -> list[tuple[int, int]]:
    """``threads`` contiguous, near-equal ranges of ``members`` (none empty).

    >>> _ranges(5, 2)
    [(0, 2), (2, 5)]
    """
    threads = max(1, min(threads, members))
    cuts = [k * members // threads for k in range(threads + 1)]
    return list(zip(cuts[:-1], cuts[1:], strict=True))


_KERNELS: dict = {}


def run_observer(alpha, beta, omega0, mu_s, mu_k, guard, t0, n_steps, section_start,
                 junction_z, zeta, fcap, fix_k, fix_s, dt, kt_dt, omega_c, law_speed, law_exp,
                 bit_cap_rel, inv_itd, w_meas, tau_meas, m_t0, m_dt, hold, p0, P0, inj_a, inj_b,
                 P1, l_k, l_s, adapt_law, mu_max, deadlock_s, omega_turn, times, out,
                 parallel=False):
    """Advance every member of the observer ``n_steps`` steps and record at ``times``.

    State (updated in place), one row per member: ``alpha``, ``beta`` (S, n) invariants,
    ``omega0`` (S,) top-drive speed ω̂₀, ``mu_s``, ``mu_k`` (S,), ``guard`` (S, 2) =
    [time the BHA has been stuck while the top drive turns, deadlock interventions].
    Friction profile and law as in :func:`drillfric.kernels.plant.run_plant` (caps
    μ̂_s·fcap + fix_s, μ̂_k·fcap + fix_k with each member's μ̂; docs/theory.md §3.2).

    Per step and member (docs/theory.md §5): e = ω̂₀ − ω₀(t); top drive (eq. 32) with the
    plant's trapezoidal coupling (:func:`drillfric.kernels.plant.top_drive_step`,
    docs/theory.md E11) and the injection held over the step,
    ω̂₀' = [(1 − q)ω̂₀ + 2qβ̂(0) + Δtτ_m/I_TD − Δt p₀ e]/(1 + q), q = ζΔt/(2I_TD);
    top boundary α̂(0) = ω̂₀ + ω̂₀' − β̂(0) − P₀e (eq. 37, 2ω̄̂₀ with the step-mean speed);
    β̂ reflected into the pipe at the pipe/BHA junction −P₁e (eq. 38); plant steps
    1–3 with μ̂_s, μ̂_k, and in the same pass every cell α̂ −= inj_a·e, β̂ −= inj_b·e, where
    inj = Δt·(p_α, p_β) on the pipe (eqs. 33–34) and Δt·p₁ on both invariants of the BHA
    (eqs. 35–36); adaptation (42)–(44) on the BHA speed (``adapt_law``: corrected or
    paper). Deadlock guard: when the estimated BHA has been stuck for ``deadlock_s`` while
    the measured top drive turns faster than ``omega_turn``, μ̂_s drops to μ̂_k (and μ̂_k by
    20 % if μ̂_s already was there).

    ``out[r, s]`` receives :data:`OBS_COLUMNS` at ``times[r]`` (the step at or after it).
    ``parallel``: run ranges of members on threads, as many as ``numba.get_num_threads()``
    (same numbers as serially). Runs the
    compiled :func:`observer_kernel` of the call's friction variant.
    """
    key = variant(law_speed, law_exp, fix_k, fix_s)
    if key not in _KERNELS:
        _KERNELS[key] = observer_kernel(*key)
    kernel = _KERNELS[key]
    args = (alpha, beta, omega0, mu_s, mu_k, guard, t0, n_steps, section_start, junction_z,
            zeta, fcap, fix_k, fix_s, dt, kt_dt, omega_c, law_speed, law_exp, bit_cap_rel,
            inv_itd, w_meas, tau_meas, m_t0, m_dt, hold, p0, P0, inj_a, inj_b, P1, l_k, l_s,
            adapt_law, mu_max, deadlock_s, omega_turn, times, out)
    members = alpha.shape[0]
    ranges = _ranges(members, get_num_threads() if parallel else 1)
    if len(ranges) == 1:
        kernel(*args, 0, members)
        return
    with ThreadPoolExecutor(len(ranges)) as pool:
        for done in [pool.submit(kernel, *args, first, last) for first, last in ranges]:
            done.result()
