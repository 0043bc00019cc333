"""Plain-NumPy twins of :mod:`drillfric.kernels.plant` (docs/theory.md §3.1, §3.2).

Same argument lists and the same arithmetic, written with whole-array NumPy operations and
a Python loop over time steps: the oracle of the kernel tests (agreement to round-off) and
the baseline of ``benchmarks/bench_plant.py``. Not for production use (slow).
"""

from __future__ import annotations

import math

import numpy as np

from drillfric.kernels.plant import (
    LAW_STEP,
    LAW_STRIBECK,
    LAW_STRIBECK_1,
    LAW_STRIBECK_2,
    axial_args,
)

_MODE_PI, _MODE_TORQUE, _MODE_SPEED, _MODE_FED = 0, 1, 2, 3
_EXP_COEF = (1.6059043836821613e-10, 2.08767569878681e-09, 2.505210838544172e-08,
             2.755731922398589e-07, 2.7557319223985893e-06, 2.48015873015873e-05,
             0.0001984126984126984, 0.001388888888888889, 0.008333333333333333,
             0.041666666666666664, 0.16666666666666666, 0.5, 1.0, 1.0)


def drive_value(u, u_t0, u_dt, t):
    """Linear interpolation of a uniform series at time t, held beyond its ends."""
    s = (t - u_t0) / u_dt
    if s <= 0.0:
        return float(u[0])
    if s >= u.size - 1:
        return float(u[-1])
    i = int(s)
    return float(u[i] + (s - i) * (u[i + 1] - u[i]))


def transport(a, b, a_new, b_new, w_a, w_b, section_start, junction_z, alpha_top, omega_top,
              bit_cap_rel):
    """Step 1: shift α down and β up, section ends from boundaries and junctions.

    Also fills ``w_a``/``w_b``: ω^k at the foot of the α/β characteristic of each cell
    (the neighbour above/below, the interface speed at section ends).
    """
    w = 0.5 * (a + b)
    a_new[1:] = a[:-1]
    b_new[:-1] = b[1:]
    w_a[1:] = w[:-1]
    w_b[:-1] = w[1:]
    first = section_start[1:-1]
    last = first - 1
    z = junction_z
    a_new[first] = (2.0 * a[last] - (1.0 - z) * b[first]) / (1.0 + z)
    b_new[last] = ((1.0 - z) * a[last] + 2.0 * z * b[first]) / (1.0 + z)
    w_a[first] = w_b[last] = 0.5 * (a[last] + b_new[last])
    a_new[0] = alpha_top
    w_a[0] = omega_top
    al = a[-1]
    b_new[-1] = al - 2.0 * min(max(al, -bit_cap_rel), bit_cap_rel)
    w_b[-1] = 0.5 * (al + b_new[-1])


def law_code(law_speed, law_exp):
    """Friction-law variant; see :func:`drillfric.kernels.plant.law_code`."""
    if law_speed <= 0.0:
        return LAW_STEP
    return {1.0: LAW_STRIBECK_1, 2.0: LAW_STRIBECK_2}.get(law_exp, LAW_STRIBECK)


def exp_neg(x):
    """e^(−x) for x ≥ 0, the arithmetic of :func:`drillfric.kernels.plant.exp_neg`."""
    x = np.minimum(x, 40.0)
    n = np.floor(x * 1.44269504088896338700e+00 + 0.5)
    y = (n * 6.93147180369123816490e-01 - x) + n * 1.90821492927058770002e-10
    p = np.full_like(x, _EXP_COEF[0])
    for c in _EXP_COEF[1:]:
        p = p * y + c
    k = n.astype(np.int64)
    s = np.ones_like(x)
    for bit in range(6):
        s *= np.where(k & (1 << bit), 2.0 ** -(1 << bit), 1.0)
    return p * s


def friction_cap(w_old, cap_s, cap_k, omega_c, inv_vs, delta, law):
    """Cap of each cell (docs/theory.md §3.2); see :func:`drillfric.kernels.plant.friction_cap`."""
    if law == LAW_STEP:
        return np.where(np.abs(w_old) <= omega_c, cap_s, cap_k)
    u = np.abs(w_old) * inv_vs
    if law == LAW_STRIBECK_1:
        x = u
    elif law == LAW_STRIBECK_2:
        x = u * u
    else:  # the C library's pow, as the kernel (NumPy's own vectorised pow differs by an ulp)
        x = np.array([math.pow(v, delta) for v in u])
    return cap_k + (cap_s - cap_k) * exp_neg(x)


def damp_and_friction(a, b, a_new, b_new, w_a, w_b, kt_dt, fcap, fix_s, fix_k, mu_s, mu_k,
                      omega_c, inv_vs, delta, law):
    """Steps 2–3: viscous term along the characteristics and friction inclusion, in place."""
    w_old = 0.5 * (a + b)
    an = a_new - kt_dt * w_a
    bn = b_new - kt_dt * w_b
    w = 0.5 * (an + bn)
    cap = friction_cap(w_old, mu_s * fcap + fix_s, mu_k * fcap + fix_k, omega_c, inv_vs,
                       delta, law)
    d = np.minimum(np.maximum(w, -cap), cap)
    a_new[:] = an - d
    b_new[:] = bn - d


def damp_and_friction_axial(a, b, a_new, b_new, w_a, w_b, kt_dt, fcap, fix_s, fix_k, mu_s,
                            mu_k, omega_c, inv_vs, delta, law, u):
    """Steps 2–3 of a string moving axially, in place (docs/theory.md §3.3, eqs. 3.3a–3.3c);
    ``u`` = |v|/r_c per cell [rad/s]. See :func:`drillfric.kernels.plant.cell_update_axial`."""
    w_old = 0.5 * (a + b)
    an = a_new - kt_dt * w_a
    bn = b_new - kt_dt * w_b
    w = 0.5 * (an + bn)
    s = np.sqrt(w_old * w_old + u * u)
    cap = friction_cap(s, mu_s * fcap + fix_s, mu_k * fcap + fix_k, omega_c, inv_vs, delta,
                       law)
    d = np.minimum(np.maximum(w * cap / (s + cap), -cap), cap)
    if law == LAW_STEP:
        d = np.where(s <= omega_c, np.minimum(np.maximum(w, -cap), cap), d)
    a_new[:] = an - d
    b_new[:] = bn - d


def motor_torque(mode, u_now, u_aux, omega0, integral, tau0, kp, ki, dt, inv_itd):
    """Motor torque τ_m at step k [N·m] (PI, prescribed torque, prescribed speed or fed)."""
    if mode == _MODE_PI:
        return kp * (u_now - omega0) + ki * integral
    if mode == _MODE_TORQUE:
        return u_now
    if mode == _MODE_FED:
        return u_now + kp * (u_aux - omega0) + ki * integral
    return tau0 + (u_aux - u_now) / (dt * inv_itd)


def top_drive_step(omega0, beta0, q, accel_dt):
    """Trapezoidal step 4 (docs/theory.md E11); see :func:`drillfric.kernels.plant.top_drive_step`:
    [(1 − q)ω₀ + 2qβ(0) + Δtτ_m/I_TD]/(1 + q), q = ζΔt/(2I_TD) (works on arrays too)."""
    return ((1.0 - q) * omega0 + 2.0 * q * beta0 + accel_dt) / (1.0 + q)


def bit_cap(cap_k_rel, weak_rel, inv_speed, w_bit):
    """Rate-weakening bit capacity T_bit(ω)/ζ_bit [rad/s]; see
    :func:`drillfric.kernels.plant.bit_cap` (the same arithmetic)."""
    return cap_k_rel + weak_rel * float(exp_neg(np.array([abs(w_bit) * inv_speed]))[0])


def run_plant(alpha, beta, top, t0, n_steps, section_start, junction_z, zeta, fcap, fix_k,
              fix_s, dt, kt_dt, mu_s, mu_k, omega_c, law_speed, law_exp, bit_cap_rel,
              bit_weak_rel, bit_inv_speed, inv_itd, mode, u, u_t0, u_dt, kp, ki, times, out,
              axial=None):
    """NumPy twin of :func:`drillfric.kernels.plant.run_plant` (same arguments and effects)."""
    (v_ax, v_t0, v_dt, inv_rc), moving = axial_args(axial, alpha.size)
    law = law_code(law_speed, law_exp)
    inv_vs = 1.0 / law_speed if law != LAW_STEP else 0.0
    a, b = alpha.copy(), beta.copy()
    a2, b2 = alpha.copy(), beta.copy()
    w_a, w_b = np.empty_like(a), np.empty_like(a)
    omega0, integral = float(top[0]), float(top[1])
    q_td = 0.5 * zeta[0] * dt * inv_itd
    r, eps = 0, 1e-9 * dt
    prev = np.zeros(5)
    w_face = 0.5 * (a[-1] + b[-1])  # bit speed of the step before (the bit cell's at start)
    for k in range(n_steps + 1):
        t = t0 + k * dt
        if mode == _MODE_FED:
            half = u.size // 2
            u_now = drive_value(u[:half], u_t0, u_dt, t)
            u_aux = drive_value(u[half:], u_t0, u_dt, t)
        else:
            u_now = drive_value(u, u_t0, u_dt, t)
            u_aux = u_now
        if mode == _MODE_SPEED:
            omega0 = u_now
            u_aux = drive_value(u, u_t0, u_dt, t + dt)
        tau0 = zeta[0] * (omega0 - b[0])
        tau_m = motor_torque(mode, u_now, u_aux, omega0, integral, tau0, kp, ki, dt, inv_itd)
        cap = bit_cap(bit_cap_rel, bit_weak_rel, bit_inv_speed, w_face)
        tau_bit = zeta[-1] * min(max(a[-1], -cap), cap)
        cur = np.array([omega0, tau_m, tau0, 0.5 * (a[-1] + b[-1]), tau_bit])
        while r < times.size and times[r] <= t + eps:
            f = 1.0 if k == 0 else (times[r] - (t - dt)) / dt
            out[r] = prev + f * (cur - prev)
            r += 1
        prev = cur
        if k == n_steps:
            break
        omega_next = omega0
        if mode != _MODE_SPEED:
            omega_next = top_drive_step(omega0, b[0], q_td, dt * inv_itd * tau_m)
        omega_bar = 0.5 * (omega0 + omega_next)
        transport(a, b, a2, b2, w_a, w_b, section_start, junction_z, 2.0 * omega_bar - b[0],
                  omega_bar, cap)
        w_face = 0.5 * (a[-1] + b2[-1])
        v_now = drive_value(v_ax, v_t0, v_dt, t) if moving else 0.0
        if v_now != 0.0:
            damp_and_friction_axial(a, b, a2, b2, w_a, w_b, kt_dt, fcap, fix_s, fix_k, mu_s,
                                    mu_k, omega_c, inv_vs, law_exp, law, abs(v_now) * inv_rc)
        else:
            damp_and_friction(a, b, a2, b2, w_a, w_b, kt_dt, fcap, fix_s, fix_k, mu_s, mu_k,
                              omega_c, inv_vs, law_exp, law)
        if mode == _MODE_PI:
            integral += dt * (u_now - omega0)
        elif mode == _MODE_FED:
            integral += dt * (u_aux - omega0)
        omega0 = float(omega_next)
        a, a2 = a2, a
        b, b2 = b2, b
    alpha[:] = a
    beta[:] = b
    top[0], top[1] = omega0, integral
