"""Compiled (numba) kernel of the adaptive observer, THEORY.md §5 (eqs. 32–44 of [1]).

The observer is a copy of the Courant-1 plant of :mod:`drillfric.kernels.plant` (same transport,
junction, friction and top-drive steps, called from there) plus output injection of the
innovation e = ω̂₀ − ω₀ and the friction adaptation laws. Several starts (initial guesses of
μ_s, μ_k) advance together in one pass: the start is an extra state dimension (rows of the
α, β arrays), not an extra run. The plain-NumPy twin is
:func:`drillfric.kernels.observer_numpy.run_observer`.

[1] U.J.F. Aarsnes, J. Auriol, F. Di Meglio, R.J. Shor, "Estimating friction factors while
    drilling", JPSE 179 (2019) 80–91.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from drillfric.kernels.plant import advance_cells, drive_value, inflows, top_drive_step

#: Columns of the observer record, per start.
OBS_COLUMNS = ("mu_s", "mu_k", "surface_rad_s_est", "bit_rad_s_est", "bha_rad_s_est",
               "residual_rad_s")
LAW_CORRECTED, LAW_PAPER = 0, 1


@njit(cache=True)
def measured_value(u, t0, dt, t, hold):
    """A uniformly sampled measurement at time t: linear interpolation, or the last sample
    (zero-order hold, as in the paper) when ``hold`` is true; held beyond the ends."""
    if not hold:
        return drive_value(u, t0, dt, t)
    s = (t - t0) / dt
    return u[min(max(int(s), 0), u.size - 1)] if s > 0.0 else u[0]


@njit(cache=True)
def adapt(mu_s, mu_k, e, stuck, l_s, l_k, dt, law, mu_max):
    """Friction adaptation, eqs. (42)–(44) of [1]; returns (μ̂_s, μ̂_k).

    Sliding BHA: dμ̂_k/dt = +l_k e. Stuck BHA: the paper's law dμ̂_s/dt = −l_s e
    (``law`` = paper) or, by default, μ̂_s held (THEORY §6.1: every μ_s law tried ends at
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


@njit(cache=True)
def run_observer(alpha, beta, omega0, mu_s, mu_k, guard, t0, n_steps, section_start,
                 junction_z, zeta, fcap, dt, kt_dt, omega_c, bit_cap_rel, inv_itd,
                 w_meas, tau_meas, m_t0, m_dt, hold, p0, P0, inj_a, inj_b, P1, l_k, l_s,
                 law, mu_max, deadlock_s, omega_turn, times, out):
    """Advance every start of the observer ``n_steps`` steps and record at ``times``.

    State (updated in place), one row per start: ``alpha``, ``beta`` (S, n) invariants,
    ``omega0`` (S,) top-drive speed ω̂₀, ``mu_s``, ``mu_k`` (S,), ``guard`` (S, 2) =
    [time the BHA has been stuck while the top drive turns, deadlock interventions].

    Per step and start (THEORY §5): e = ω̂₀ − ω₀(t); top drive (eq. 32) with the plant's
    trapezoidal coupling (:func:`drillfric.kernels.plant.top_drive_step`, docs/theory.md E11)
    and the injection held over the step,
    ω̂₀' = [(1 − q)ω̂₀ + 2qβ̂(0) + Δtτ_m/I_TD − Δt p₀ e]/(1 + q), q = ζΔt/(2I_TD);
    top boundary α̂(0) = ω̂₀ + ω̂₀' − β̂(0) − P₀e (eq. 37, 2ω̄̂₀ with the step-mean speed);
    β̂ reflected into the pipe at the pipe/BHA junction −P₁e (eq. 38); plant steps
    1–3 with μ̂_s, μ̂_k; every cell α̂ −= inj_a·e, β̂ −= inj_b·e, where inj = Δt·(p_α, p_β) on
    the pipe (eqs. 33–34) and Δt·p₁ on both invariants of the BHA (eqs. 35–36);
    adaptation (42)–(44) on the BHA speed. Deadlock guard: when the estimated BHA has been
    stuck for ``deadlock_s`` while the measured top drive turns faster than ``omega_turn``,
    μ̂_s drops to μ̂_k (and μ̂_k by 20 % if μ̂_s already was there).

    ``out[r, s]`` receives :data:`OBS_COLUMNS` at ``times[r]`` (the step at or after it).
    """
    n_start, n = alpha.shape
    n_pipe = section_start[1]
    n_sec = section_start.size - 1
    buf_a = np.empty((2, n_start, n))
    buf_b = np.empty((2, n_start, n))
    buf_a[0] = alpha
    buf_b[0] = beta
    a_in = np.empty(n_sec)
    b_in = np.empty(n_sec)
    w_in = np.empty(n_sec + 1)
    q_td = 0.5 * zeta[0] * dt * inv_itd
    n_bha = n - n_pipe
    n_rec = times.size
    r = 0
    eps = 1e-9 * dt
    cur = 0
    e_last = omega0 - measured_value(w_meas, m_t0, m_dt, t0, hold)
    w_bha_last = np.zeros(n_start)
    for s in range(n_start):
        acc = 0.0
        for j in range(n_pipe, n):
            acc += 0.5 * (alpha[s, j] + beta[s, j])
        w_bha_last[s] = acc / max(n_bha, 1)
    for k in range(n_steps + 1):
        t = t0 + k * dt
        while r < n_rec and times[r] <= t + eps:
            for s in range(n_start):
                a = buf_a[cur, s]
                b = buf_b[cur, s]
                out[r, s, 0] = mu_s[s]
                out[r, s, 1] = mu_k[s]
                out[r, s, 2] = omega0[s]
                out[r, s, 3] = 0.5 * (a[n - 1] + b[n - 1])
                out[r, s, 4] = w_bha_last[s]
                out[r, s, 5] = e_last[s]
            r += 1
        if k == n_steps:
            break
        wm = measured_value(w_meas, m_t0, m_dt, t, hold)
        taum = measured_value(tau_meas, m_t0, m_dt, t, hold)
        nxt = 1 - cur
        for s in range(n_start):
            a = buf_a[cur, s]
            b = buf_b[cur, s]
            a2 = buf_a[nxt, s]
            b2 = buf_b[nxt, s]
            e = omega0[s] - wm
            omega_next = top_drive_step(omega0[s], b[0], q_td,
                                        dt * inv_itd * taum - dt * p0 * e)
            omega_bar = 0.5 * (omega0[s] + omega_next)
            inflows(a, b, section_start, junction_z, 2.0 * omega_bar - b[0] - P0 * e,
                    omega_bar, bit_cap_rel, a_in, b_in, w_in)
            if n_sec > 1:
                b_in[0] -= P1 * e
            advance_cells(a, b, a2, b2, section_start, a_in, b_in, w_in, kt_dt, fcap,
                          mu_s[s], mu_k[s], omega_c)
            for j in range(n):
                a2[j] -= inj_a[j] * e
                b2[j] -= inj_b[j] * e
            acc = 0.0
            for j in range(n_pipe, n):
                acc += a2[j] + b2[j]
            w_bha = 0.5 * acc / max(n_bha, 1)
            omega0[s] = omega_next
            stuck = abs(w_bha) <= omega_c
            mu_s[s], mu_k[s] = adapt(mu_s[s], mu_k[s], e, stuck, l_s, l_k, dt, law, mu_max)
            if stuck and abs(wm) > omega_turn:
                guard[s, 0] += dt
                if guard[s, 0] > deadlock_s:
                    if mu_s[s] <= mu_k[s] * (1.0 + 1e-9):
                        mu_k[s] *= 0.8
                    mu_s[s] = mu_k[s]
                    guard[s, 0] = 0.0
                    guard[s, 1] += 1.0
            else:
                guard[s, 0] = 0.0
            e_last[s] = e
            w_bha_last[s] = w_bha
        cur = nxt
    alpha[:, :] = buf_a[cur]
    beta[:, :] = buf_b[cur]
