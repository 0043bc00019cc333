"""Plain-NumPy twin of :func:`drillfric.kernels.observer.run_observer` (docs/theory.md §5).

Same arguments and effects, built from the plant twin's whole-array steps
(:mod:`drillfric.kernels.plant_numpy`, with the friction profile and law of docs/theory.md
§3.2) with a Python loop over time steps and members: the oracle of the observer kernel
tests and the baseline of ``benchmarks/bench_observer.py``.
"""

from __future__ import annotations

import numpy as np

from drillfric.kernels.observer import LAW_PAPER
from drillfric.kernels.plant_numpy import (
    LAW_STEP,
    damp_and_friction,
    drive_value,
    law_code,
    top_drive_step,
    transport,
)


def measured_value(u, t0, dt, t, hold):
    """Measurement at time t: linear interpolation or zero-order hold, held at the ends."""
    if not hold:
        return drive_value(u, t0, dt, t)
    s = (t - t0) / dt
    return float(u[min(max(int(s), 0), u.size - 1)]) if s > 0.0 else float(u[0])


def adapt(mu_s, mu_k, e, stuck, l_s, l_k, dt, law, mu_max):
    """Adaptation (42)–(44); see :func:`drillfric.kernels.observer.adapt`."""
    if stuck:
        if law == LAW_PAPER:
            mu_s -= dt * l_s * e
    else:
        mu_k += dt * l_k * e
    mu_k = min(max(mu_k, 0.0), mu_max)
    return min(max(mu_s, mu_k), mu_max), mu_k


def run_observer(alpha, beta, omega0, mu_s, mu_k, guard, t0, n_steps, section_start,
                 junction_z, zeta, fcap, fix_k, fix_s, dt, kt_dt, omega_c, law_speed, law_exp,
                 bit_cap_rel, inv_itd, w_meas, tau_meas, m_t0, m_dt, hold, p0, P0, inj_a, inj_b,
                 P1, l_k, l_s, adapt_law, mu_max, deadlock_s, omega_turn, times, out,
                 parallel=False):
    """NumPy twin of :func:`drillfric.kernels.observer.run_observer` (``parallel`` is
    accepted and ignored: the twin is serial)."""
    law = law_code(law_speed, law_exp)
    inv_vs = 1.0 / law_speed if law != LAW_STEP else 0.0
    n_start, n = alpha.shape
    n_pipe = int(section_start[1])
    a, b = alpha.copy(), beta.copy()
    a2, b2 = alpha.copy(), beta.copy()
    e_last = omega0 - measured_value(w_meas, m_t0, m_dt, t0, hold)
    w_bha = 0.5 * (a[:, n_pipe:] + b[:, n_pipe:]).mean(axis=1) if n > n_pipe \
        else np.zeros(n_start)
    r, eps = 0, 1e-9 * dt
    for k in range(n_steps + 1):
        t = t0 + k * dt
        while r < times.size and times[r] <= t + eps:
            out[r] = np.stack([mu_s, mu_k, omega0, 0.5 * (a[:, -1] + b[:, -1]), w_bha, e_last,
                               zeta[0] * (omega0 - b[:, 0])], axis=1)
            r += 1
        if k == n_steps:
            break
        wm = measured_value(w_meas, m_t0, m_dt, t, hold)
        taum = measured_value(tau_meas, m_t0, m_dt, t, hold)
        e = omega0 - wm
        omega_next = top_drive_step(omega0, b[:, 0], 0.5 * zeta[0] * dt * inv_itd,
                                    dt * inv_itd * taum - dt * p0 * e)
        omega_bar = 0.5 * (omega0 + omega_next)
        w_a, w_b = np.empty(n), np.empty(n)
        for s in range(n_start):
            transport(a[s], b[s], a2[s], b2[s], w_a, w_b, section_start, junction_z,
                      2.0 * omega_bar[s] - b[s, 0] - P0 * e[s], omega_bar[s], bit_cap_rel)
            if section_start.size > 2:
                b2[s, n_pipe - 1] -= P1 * e[s]
            damp_and_friction(a[s], b[s], a2[s], b2[s], w_a, w_b, kt_dt, fcap, fix_s, fix_k,
                              mu_s[s], mu_k[s], omega_c, inv_vs, law_exp, law)
        a2 -= inj_a[None, :] * e[:, None]
        b2 -= inj_b[None, :] * e[:, None]
        w_bha = 0.5 * (a2[:, n_pipe:] + b2[:, n_pipe:]).mean(axis=1) if n > n_pipe \
            else np.zeros(n_start)
        omega0[:] = omega_next
        for s in range(n_start):
            stuck = abs(w_bha[s]) <= omega_c
            mu_s[s], mu_k[s] = adapt(mu_s[s], mu_k[s], e[s], stuck, l_s, l_k, dt, adapt_law,
                                     mu_max)
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
        e_last = e
        a, a2 = a2, a
        b, b2 = b2, b
    alpha[:] = a
    beta[:] = b
