"""Compiled (numba) kernels of the torsional plant, THEORY.md §3.1.

One step k → k+1 of the Courant-1 scheme is split into small functions that the adaptive
observer (THEORY §5, a copy of this plant plus injections) reuses:

- :func:`inflows` — the values entering each section at step 1: top boundary (eq. 15),
  section junctions (eqs. 12–14 / 38–39) and the bit (β = α − 2τ_bit/ζ, erratum of eq. 40);
- :func:`cell_update` — steps 2–3 for one cell: viscous term −(k_t/2)(α + β) (erratum of
  eq. 11), taken at the foot of each characteristic (see docs/simulator.md: evaluated at
  the cell itself, as THEORY §3.1 step 2 reads, it amplifies grid-scale waves at rate k_t),
  and the friction inclusion (eqs. 5–6, A.1–A.5 with consistent units);
- :func:`advance_cells` — steps 1–3 fused in one vectorised pass over the
  cells (exact shift);
- :func:`drive_value`, :func:`motor_torque`, :func:`top_drive_step` — the top-drive input
  (PI on a set-point series, prescribed torque, or prescribed speed) and step 4, taken
  trapezoidally and solved *before* step 1 because the top inflow α(0) = 2ω̄₀ − β(0) uses
  the step-mean speed ω̄₀ = (ω₀^k + ω₀^(k+1))/2 (docs/theory.md erratum E11: the explicit
  step 4 of THEORY §3.1 adds energy at every step);
- :func:`run_plant` — many steps in one call, recording at the requested times by linear
  interpolation between steps (no Python loop over time steps).

Array layout: one contiguous cell array for α and one for β over the whole string,
``section_start`` (first cell of each section + total), per-cell ``zeta`` and ``fcap``
(speed change friction can impose in one step per unit μ, F_c·Δt/(ρJ) [rad/s]).
The plain-NumPy twin with the same argument list is :mod:`drillfric.kernels.plant_numpy`.
For an observer: ``alpha_top`` of :func:`inflows` is an argument (pass
ω̂₀^k + ω̂₀^(k+1) − β̂(0) − P₀e with ω̂₀^(k+1) from :func:`top_drive_step`);
``b_in[0]`` after :func:`inflows` is the β reflected into the pipe at the pipe/BHA junction
(add −P₁e there before :func:`advance_cells`); per-cell injections go on ``a_new``,
``b_new`` afterwards.
"""

from __future__ import annotations

import numpy as np
from numba import njit

_MODE_PI, _MODE_TORQUE, _MODE_SPEED = 0, 1, 2


@njit(cache=True)
def drive_value(u, u_t0, u_dt, t):
    """Linear interpolation of a uniform series at time t, held beyond its ends."""
    s = (t - u_t0) / u_dt
    n = u.size
    if s <= 0.0:
        return u[0]
    if s >= n - 1:
        return u[n - 1]
    i = int(s)
    return u[i] + (s - i) * (u[i + 1] - u[i])


@njit(cache=True)
def inflows(a, b, section_start, junction_z, alpha_top, omega_top, bit_cap_rel, a_in, b_in,
            w_in):
    """Boundary values of step 1 of THEORY §3.1, from the invariants at step k.

    Fills ``a_in[s]`` (α entering section s at its top), ``b_in[s]`` (β entering it at its
    bottom) and ``w_in[s]``, ``w_in[s + 1]`` (ω at the section's top and bottom interfaces,
    used by the viscous term of the end cells). The top boundary α(0) = 2ω̄₀ − β(0) (eq. 15)
    is passed in as ``alpha_top`` with ``omega_top`` = ω̄₀, the top-drive speed averaged
    over the step (:func:`top_drive_step`; for a prescribed speed, ω₀ at step k); a
    junction between an upper section (last cell α_a) and a lower one (first cell β_b)
    with Z = ζ_b/ζ_a gives
    α_b = [2α_a − (1 − Z)β_b]/(1 + Z) and β_a = [(1 − Z)α_a + 2Zβ_b]/(1 + Z) (eqs. 12–14,
    38–39); the bit gives β = α − 2τ_bit/ζ with τ_bit = ζ·clamp(α, ±T_bit/ζ) (Coulomb bit,
    solved exactly; ``bit_cap_rel`` = T_bit/ζ [rad/s]; 0 is the free end β = α, erratum of
    eq. 40).
    """
    n_sec = section_start.size - 1
    a_in[0] = alpha_top
    w_in[0] = omega_top
    for s in range(1, n_sec):
        first = section_start[s]
        z = junction_z[s - 1]
        a_up = a[first - 1]
        b_dn = b[first]
        a_in[s] = (2.0 * a_up - (1.0 - z) * b_dn) / (1.0 + z)
        b_in[s - 1] = ((1.0 - z) * a_up + 2.0 * z * b_dn) / (1.0 + z)
        w_in[s] = 0.5 * (a_up + b_in[s - 1])
    al = a[a.size - 1]
    b_in[n_sec - 1] = al - 2.0 * min(max(al, -bit_cap_rel), bit_cap_rel)
    w_in[n_sec] = 0.5 * (al + b_in[n_sec - 1])


@njit(cache=True, inline="always")
def cell_update(a_src, b_src, w_src_a, w_src_b, w_old, kt_dt, fcap_j, mu_s, mu_k, omega_c):
    """Steps 2–3 of THEORY §3.1 for one cell; returns (α, β) at step k+1 [rad/s].

    ``a_src``, ``b_src`` are the transported values α*, β* (step 1) and ``w_src_a``,
    ``w_src_b`` the speeds ω^k at the feet of their characteristics (the cell above and the
    cell below), ``w_old`` the cell's own ω^k. Viscous (erratum of eq. 11, integrated along
    the characteristic so that it dissipates energy): α** = α* − Δt·k_t·ω^k_(j−1),
    β** = β* − Δt·k_t·ω^k_(j+1). Friction inclusion (eqs. 5–6, A.1–A.5 with consistent
    units): the speed change that would stop the cell, ω** = (α** + β**)/2, is clamped to
    ±μ·fcap_j with μ = μ_s if |ω^k_j| ≤ ω_c else μ_k and removed from both invariants (τ is
    untouched).
    """
    an = a_src - kt_dt * w_src_a
    bn = b_src - kt_dt * w_src_b
    w = 0.5 * (an + bn)
    mu = mu_s if abs(w_old) <= omega_c else mu_k
    cap = mu * fcap_j
    d = min(max(w, -cap), cap)
    return an - d, bn - d


@njit(cache=True, inline="always")
def _end_cell(a, b, a_new, b_new, j, a_src, b_src, w_src_a, w_src_b, kt_dt, fcap, mu_s, mu_k,
              omega_c):
    a_new[j], b_new[j] = cell_update(a_src, b_src, w_src_a, w_src_b, 0.5 * (a[j] + b[j]),
                                     kt_dt, fcap[j], mu_s, mu_k, omega_c)


@njit(cache=True)
def advance_cells(a, b, a_new, b_new, section_start, a_in, b_in, w_in, kt_dt, fcap, mu_s,
                  mu_k, omega_c):
    """Steps 1–3 of THEORY §3.1 over the whole string: α*_j = α_{j−1}, β*_j = β_{j+1}
    (exact Courant-1 shift), then :func:`cell_update`.

    Reads ``a``, ``b`` (step k), writes ``a_new``, ``b_new`` (step k+1 before the top-drive
    update); ``a_in``, ``b_in``, ``w_in`` come from :func:`inflows`. One branch-free pass
    over all interior cells as if the string were uniform (the compiler vectorises it),
    then the first and last cell of every section are redone with the section inflows
    (each cell reads only step-k values, so the overwrite is exact).
    """
    n = a.size
    for j in range(1, n - 1):
        a_new[j], b_new[j] = cell_update(a[j - 1], b[j + 1], 0.5 * (a[j - 1] + b[j - 1]),
                                         0.5 * (a[j + 1] + b[j + 1]), 0.5 * (a[j] + b[j]),
                                         kt_dt, fcap[j], mu_s, mu_k, omega_c)
    for s in range(section_start.size - 1):
        lo = section_start[s]
        hi = section_start[s + 1]
        if hi - lo == 1:
            _end_cell(a, b, a_new, b_new, lo, a_in[s], b_in[s], w_in[s], w_in[s + 1], kt_dt,
                      fcap, mu_s, mu_k, omega_c)
            continue
        _end_cell(a, b, a_new, b_new, lo, a_in[s], b[lo + 1], w_in[s],
                  0.5 * (a[lo + 1] + b[lo + 1]), kt_dt, fcap, mu_s, mu_k, omega_c)
        _end_cell(a, b, a_new, b_new, hi - 1, a[hi - 2], b_in[s],
                  0.5 * (a[hi - 2] + b[hi - 2]), w_in[s + 1], kt_dt, fcap, mu_s, mu_k,
                  omega_c)


@njit(cache=True)
def motor_torque(mode, u_now, u_next, omega0, integral, tau0, kp, ki, dt, inv_itd):
    """Motor torque τ_m at step k [N·m] (THEORY §3, top-drive controller).

    PI: k_p(ω_ref − ω₀) + k_i∫(ω_ref − ω₀)dt; prescribed torque: the series; prescribed
    speed: the torque that makes the top drive follow it, τ(0) + I_TD·Δω₀/Δt.
    """
    if mode == _MODE_PI:
        return kp * (u_now - omega0) + ki * integral
    if mode == _MODE_TORQUE:
        return u_now
    return tau0 + (u_next - u_now) / (dt * inv_itd)


@njit(cache=True, inline="always")
def top_drive_step(omega0, beta0, q, accel_dt):
    """Step 4 of THEORY §3.1, eq. (7), trapezoidal (docs/theory.md erratum E11) [rad/s].

    Eq. (7), I_TD dω₀/dt = τ_m − τ(0), with τ(0) = ζ_pipe(ω(0) − β(0)) (eq. 15), over one
    step: β(0) is the β of cell 0 at step k — under Courant-1 transport exactly the wave
    leaving the string through x = 0 during [t_k, t_k+1] — and the boundary speed is the
    step mean ω̄₀ = (ω₀^k + ω₀^(k+1))/2, which is also what enters the string through
    α(0) = 2ω̄₀ − β(0) (eq. 15). Solving
    ω₀^(k+1) = ω₀^k + (Δt/I_TD)(τ_m − ζ(ω̄₀ − β(0))) for ω₀^(k+1):

        ω₀^(k+1) = [(1 − q)ω₀^k + 2q β(0) + Δt τ_m/I_TD] / (1 + q),   q = ζΔt/(2 I_TD).

    The string gains Δt·ω̄₀·ζ(ω̄₀ − β(0)) through α(0) and the top drive loses exactly that,
    so string + top-drive energy changes by Δt·ω̄₀·τ_m only (conserved for τ_m = 0; the
    explicit Euler step ω₀ + (Δt/I_TD)(τ_m − ζ(ω₀ − β(0))) adds ½ζa₀Δt²(β(0) − ω₀)² every
    step). Unconditionally stable (|1 − q|/(1 + q) < 1) and second-order; the top drive of
    :mod:`drillfric.estimation.lumped` uses the trapezoidal rule too. ``accel_dt`` = Δt·τ_m/I_TD
    (the observer adds −Δt p₀ e). Callers form the inflow α(0) = ω₀^k + ω₀^(k+1) − β(0)
    (= 2ω̄₀ − β(0)).
    """
    return ((1.0 - q) * omega0 + 2.0 * q * beta0 + accel_dt) / (1.0 + q)


@njit(cache=True)
def run_plant(alpha, beta, top, t0, n_steps, section_start, junction_z, zeta, fcap, dt,
              kt_dt, mu_s, mu_k, omega_c, bit_cap_rel, inv_itd, mode, u, u_t0, u_dt, kp, ki,
              times, out):
    """Advance ``n_steps`` steps from time ``t0`` and record at ``times`` (THEORY §3.1).

    ``alpha``, ``beta`` (cells) and ``top`` = [ω₀, PI integral] are updated in place.
    Per step: τ_m from the state at step k (held over the step), ω₀^(k+1) by the trapezoidal
    :func:`top_drive_step` (except for a prescribed speed), then steps 1–3 with the top
    inflow α(0) = 2ω̄₀ − β(0) (erratum E11).
    ``out[r]`` receives (ω₀, τ_m, τ(0) = ζ(ω₀ − β(0)), ω_bit) at ``times[r]`` (step values,
    τ(0) from ω₀ and β(0) at the step), linearly interpolated
    between the bracketing steps; ``times`` must lie in [t0, t0 + n_steps·dt].
    Argument order: see :func:`drillfric.torsional.kernel_args`.
    """
    n = alpha.size
    a = alpha
    b = beta
    a2 = alpha.copy()
    b2 = beta.copy()
    a_in = np.empty(section_start.size - 1)
    b_in = np.empty(section_start.size - 1)
    w_in = np.empty(section_start.size)
    omega0 = top[0]
    integral = top[1]
    zeta0 = zeta[0]
    q_td = 0.5 * zeta0 * dt * inv_itd
    n_rec = times.size
    r = 0
    eps = 1e-9 * dt
    p0 = p1 = p2 = p3 = 0.0
    for k in range(n_steps + 1):
        t = t0 + k * dt
        u_now = drive_value(u, u_t0, u_dt, t)
        u_next = u_now
        if mode == _MODE_SPEED:
            omega0 = u_now
            u_next = drive_value(u, u_t0, u_dt, t + dt)
        tau0 = zeta0 * (omega0 - b[0])
        tau_m = motor_torque(mode, u_now, u_next, omega0, integral, tau0, kp, ki, dt, inv_itd)
        w_bit = 0.5 * (a[n - 1] + b[n - 1])
        while r < n_rec and times[r] <= t + eps:
            f = 1.0 if k == 0 else (times[r] - (t - dt)) / dt
            out[r, 0] = p0 + f * (omega0 - p0)
            out[r, 1] = p1 + f * (tau_m - p1)
            out[r, 2] = p2 + f * (tau0 - p2)
            out[r, 3] = p3 + f * (w_bit - p3)
            r += 1
        p0, p1, p2, p3 = omega0, tau_m, tau0, w_bit
        if k == n_steps:
            break
        omega_next = omega0
        if mode != _MODE_SPEED:
            omega_next = top_drive_step(omega0, b[0], q_td, dt * inv_itd * tau_m)
        omega_bar = 0.5 * (omega0 + omega_next)
        inflows(a, b, section_start, junction_z, 2.0 * omega_bar - b[0], omega_bar,
                bit_cap_rel, a_in, b_in, w_in)
        advance_cells(a, b, a2, b2, section_start, a_in, b_in, w_in, kt_dt, fcap, mu_s, mu_k,
                      omega_c)
        if mode == _MODE_PI:
            integral += dt * (u_now - omega0)
        omega0 = omega_next
        a, a2 = a2, a
        b, b2 = b2, b
    if n_steps % 2 == 1:
        alpha[:] = a
        beta[:] = b
    top[0] = omega0
    top[1] = integral
