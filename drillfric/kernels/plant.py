"""Compiled (numba) kernels of the torsional plant, docs/theory.md §3.1 and §3.2.

One step k → k+1 of the Courant-1 scheme is split into small functions that the adaptive
observer (docs/theory.md §5, a copy of this plant plus injections) reuses:

- :func:`inflows` — the values entering each section at step 1: top boundary (eq. 15),
  section junctions (eqs. 12–14 / 38–39) and the bit (β = α − 2τ_bit/ζ, erratum of eq. 40),
  written into the ghost cells that frame every section;
- :func:`cell_update` — steps 2–3 for one cell: viscous term −(k_t/2)(α + β) (erratum of
  eq. 11), taken at the foot of each characteristic (see docs/simulator.md: evaluated at
  the cell itself, as docs/theory.md §3.1 step 2 reads, it amplifies grid-scale waves at rate k_t),
  and the friction inclusion (eqs. 5–6, A.1–A.5 with consistent units) with the cap of
  :func:`friction_cap` (docs/theory.md §3.2: friction profile, step or Stribeck law);
- :func:`pass_cells` — steps 1–3 fused in one vectorised pass over every cell (exact
  shift; the ghost cells make section ends like any other cell), with the observer's
  per-cell injections when asked;
- :func:`cell_update_axial`, :func:`pass_cells_axial` — the same for a string that also
  moves axially at v (docs/theory.md §3.3: friction at the contact speed, its tangential
  share taken semi-implicitly), run for the steps with v ≠ 0;
- :func:`drive_value`, :func:`motor_torque`, :func:`top_drive_step` — the top-drive input
  (PI on a set-point series, prescribed torque, or prescribed speed) and step 4, taken
  trapezoidally and solved *before* step 1 because the top inflow α(0) = 2ω̄₀ − β(0) uses
  the step-mean speed ω̄₀ = (ω₀^k + ω₀^(k+1))/2 (docs/theory.md erratum E11: the explicit
  step 4 of docs/theory.md §3.1 adds energy at every step);
- :func:`run_plant` — many steps in one call, recording at the requested times by linear
  interpolation between steps (no Python loop over time steps); it runs the compiled
  :func:`plant_kernel` of the call's friction variant.

Arguments: cell arrays ``alpha``, ``beta`` over the whole string, ``section_start`` (first
cell of each section + total), per-cell ``zeta``, ``fcap`` (speed change friction can impose
in one step per unit μ, F_c·Δt/(ρJ) [rad/s]) and the fixed part of the profile ``fix_k``,
``fix_s`` (the same for a zone of known friction, already times its friction factor
[rad/s]); the friction law is given by ``law_speed`` (Stribeck decay speed v_s [rad/s]; 0
is the step law at ω_c) and ``law_exp`` (Stribeck exponent δ). The plain-NumPy twin with
the same argument list is :mod:`drillfric.kernels.plant_numpy`.

Inside, the state is three double buffers ``A`` (α), ``B`` (β) and ``W`` (ω = (α + β)/2,
stored so that no cell recomputes its neighbours' speeds) of shape (2, m) in the ghost
layout of :func:`padded`: a ghost cell above the string, two between consecutive sections,
one below the bit, the cell loop padded to whole 8-wide vectors; they and the per-cell
arrays are rows of one :func:`work_buffer` whose row stride avoids 4K aliasing
(:func:`row_length`). Row ``cur`` holds step k and the
step writes row 1 − ``cur``. Performance rules (docs/performance.md): no array views or
swaps in the time loop and no inlined helper with array arguments (each cost atomic
reference counting at every step — it was half the time of a 65-cell step); the friction
variant (law, fixed part, injection) is a compile-time constant of every cell loop
(:func:`plant_kernel` closes over it; :func:`pass_cells` is specialised with
``literally``), so each loop is branch-free and vectorised. The arithmetic is that of the
twin, operation for operation (no fastmath): the kernels agree with it bit for bit.
"""

from __future__ import annotations

import numpy as np
from numba import literally, njit

_MODE_PI, _MODE_TORQUE, _MODE_SPEED, _MODE_FED = 0, 1, 2, 3
#: Friction-law variants of the cell loop (:func:`law_code`): the step law at ω_c, and the
#: Stribeck law with δ = 1, δ = 2 (vectorised) or any other δ (a scalar power per cell).
LAW_STEP, LAW_STRIBECK_1, LAW_STRIBECK_2, LAW_STRIBECK = 0, 1, 2, 3
_EXP_CLAMP = 40.0  # e^−40 = 4.2e-18: below round-off of any cap it multiplies
_LN2_HI = 6.93147180369123816490e-01  # ln 2 split so that n·_LN2_HI is exact (n ≤ 58)
_LN2_LO = 1.90821492927058770002e-10
_INV_LN2 = 1.44269504088896338700e+00


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
def drive_half(u, half, u_t0, u_dt, t):
    """:func:`drive_value` of the first (``half`` = 0) or second half of ``u`` (two series
    of equal length one after the other; no array view is made)."""
    n = u.size // 2
    base = half * n
    s = (t - u_t0) / u_dt
    if s <= 0.0:
        return u[base]
    if s >= n - 1:
        return u[base + n - 1]
    i = int(s)
    return u[base + i] + (s - i) * (u[base + i + 1] - u[base + i])


@njit(cache=True)
def law_code(law_speed, law_exp):
    """Variant of the friction law: :data:`LAW_STEP` when ``law_speed`` ≤ 0, else Stribeck
    with δ = ``law_exp`` (1 and 2 have their own vectorised variants)."""
    if law_speed <= 0.0:
        return LAW_STEP
    if law_exp == 1.0:
        return LAW_STRIBECK_1
    if law_exp == 2.0:
        return LAW_STRIBECK_2
    return LAW_STRIBECK


@njit(cache=True, inline="always")
def exp_neg(x):
    """e^(−x) for x ≥ 0 [-], within 3e-16 relative, in operations the compiler vectorises.

    x is clamped to 40 (e^−40 = 4.2e-18); x = n·ln 2 + r with |r| ≤ ln 2/2 (Cody–Waite),
    e^(−r) by its Taylor polynomial of degree 13 (truncation < 1e-17), times 2^(−n) built
    from the six bits of n (≤ 58). Used by the Stribeck law (docs/theory.md §3.2); numba has
    no vectorised exp without Intel's SVML, and a libm call per cell is ~10× the cell update.
    """
    x = min(x, _EXP_CLAMP)
    n = np.floor(x * _INV_LN2 + 0.5)
    y = (n * _LN2_HI - x) + n * _LN2_LO  # −r
    p = 1.6059043836821613e-10
    p = p * y + 2.08767569878681e-09
    p = p * y + 2.505210838544172e-08
    p = p * y + 2.755731922398589e-07
    p = p * y + 2.7557319223985893e-06
    p = p * y + 2.48015873015873e-05
    p = p * y + 0.0001984126984126984
    p = p * y + 0.001388888888888889
    p = p * y + 0.008333333333333333
    p = p * y + 0.041666666666666664
    p = p * y + 0.16666666666666666
    p = p * y + 0.5
    p = p * y + 1.0
    p = p * y + 1.0
    k = int(n)
    s = 0.5 if k & 1 else 1.0
    s *= 0.25 if k & 2 else 1.0
    s *= 0.0625 if k & 4 else 1.0
    s *= 0.00390625 if k & 8 else 1.0
    s *= 1.52587890625e-05 if k & 16 else 1.0
    s *= 2.3283064365386963e-10 if k & 32 else 1.0
    return p * s


@njit(cache=True, inline="always")
def friction_cap(w_old, fcap_j, fix_s_j, fix_k_j, mu_s, mu_k, omega_c, inv_vs, delta, law,
                 fixed):
    """Friction cap of a cell at speed ω^k = ``w_old`` [rad/s per step] (docs/theory.md §3.2).

    Static and kinetic caps μ_s·fcap_j + fix_s_j and μ_k·fcap_j + fix_k_j (the fixed part
    only when ``fixed``). Step law (eqs. 5–6): the static cap if |ω^k| ≤ ω_c, else the
    kinetic one. Stribeck law: cap_k + (cap_s − cap_k)·exp(−(|ω^k|/v_s)^δ), ``inv_vs`` =
    1/v_s [s/rad].
    """
    if law == LAW_STEP:
        stuck = abs(w_old) <= omega_c
        cap = (mu_s if stuck else mu_k) * fcap_j
        if fixed:
            cap += fix_s_j if stuck else fix_k_j
        return cap
    cap_s = mu_s * fcap_j
    cap_k = mu_k * fcap_j
    if fixed:
        cap_s += fix_s_j
        cap_k += fix_k_j
    u = abs(w_old) * inv_vs
    if law == LAW_STRIBECK_1:
        x = u
    elif law == LAW_STRIBECK_2:
        x = u * u
    else:
        x = u ** delta
    return cap_k + (cap_s - cap_k) * exp_neg(x)


@njit(cache=True)
def padded_size(section_start):
    """Cells of the ghost layout (:func:`padded`): n + 2·n_sec, rounded up so that the cells
    between the first and the last fill whole 8-wide vectors (no scalar loop remainder)."""
    return 2 + (section_start[-1] + 2 * (section_start.size - 1) - 2 + 7) // 8 * 8


@njit(cache=True)
def row_length(section_start):
    """Length of a row of the work buffer (:func:`work_buffer`): the smallest 88 + 512·q
    cells ≥ :func:`padded_size`, i.e. a row stride of 704 bytes modulo 4096.

    The loop stores three rows while it loads from the others; a load whose address equals
    a store still in flight modulo 4096 waits for it ("4K aliasing"). With separately
    allocated arrays that depended on where the heap put them: the same 475-cell step took
    266–641 ns over 24 placements. Rows 704 bytes apart (mod 4096) keep every load at least
    576 bytes (72 cells) from the stores of the last iterations, for up to 11 rows.
    """
    return 88 + 512 * max(0, (padded_size(section_start) - 88 + 511) // 512)


@njit(cache=True)
def padded(x, section_start):
    """Per-cell values in the ghost layout of the kernels: a zero ghost cell at the top, two
    between consecutive sections and one at the bottom, zeros after the last
    (length :func:`row_length`)."""
    n_sec = section_start.size - 1
    out = np.zeros(row_length(section_start))
    for s in range(n_sec):
        for j in range(section_start[s], section_start[s + 1]):
            out[j + 1 + 2 * s] = x[j]
    return out


@njit(cache=True)
def padded_inverse_radius(inv_rc, section_start):
    """1/r_c per cell [1/m] in the ghost layout of :func:`padded`, with 1 in the ghost and
    padding cells instead of 0 (their axial contact speed is then |v| > 0)."""
    out = np.ones(row_length(section_start))
    for s in range(section_start.size - 1):
        for j in range(section_start[s], section_start[s + 1]):
            out[j + 1 + 2 * s] = inv_rc[j]
    return out


@njit(cache=True)
def unpadded(xp, section_start, out):
    """The real cells of ``xp`` (ghost layout of :func:`padded`) into ``out`` (length n)."""
    for s in range(section_start.size - 1):
        for j in range(section_start[s], section_start[s + 1]):
            out[j] = xp[j + 1 + 2 * s]


@njit(cache=True)
def inflows(A, B, W, cur, section_start, junction_z, alpha_top, omega_top, bit_cap_rel):
    """Boundary values of step 1 of docs/theory.md §3.1 into the ghost cells of row ``cur`` of the
    state buffers ``A`` (α), ``B`` (β), ``W`` (ω = (α + β)/2), from the real cells at step k.

    Each section is framed by ghost cells (layout of :func:`padded`): the one above its
    first cell holds the α entering it and the interface speed ω, the one below its last
    cell the β entering it and ω; :func:`pass_cells` then updates every cell the same way.
    The top boundary α(0) = 2ω̄₀ − β(0) (eq. 15) is passed in as ``alpha_top`` with
    ``omega_top`` = ω̄₀, the top-drive speed averaged over the step (:func:`top_drive_step`;
    for a prescribed speed, ω₀ at step k); a junction between an upper section (last cell
    α_a) and a lower one (first cell β_b) with Z = ζ_b/ζ_a gives
    α_b = [2α_a − (1 − Z)β_b]/(1 + Z) and β_a = [(1 − Z)α_a + 2Zβ_b]/(1 + Z) (eqs. 12–14,
    38–39) and the interface speed (α_a + β_a)/2; the bit gives β = α − 2τ_bit/ζ with
    τ_bit = ζ·clamp(α, ±T_bit/ζ) (Coulomb bit, solved exactly; ``bit_cap_rel`` = T_bit/ζ
    [rad/s]; 0 is the free end β = α, erratum of eq. 40).
    """
    n_sec = section_start.size - 1
    A[cur, 0] = alpha_top
    W[cur, 0] = omega_top
    for s in range(1, n_sec):
        last = section_start[s] + 2 * s - 2  # last cell of section s − 1
        z = junction_z[s - 1]
        a_up = A[cur, last]
        b_dn = B[cur, last + 3]
        b_up = ((1.0 - z) * a_up + 2.0 * z * b_dn) / (1.0 + z)
        w_if = 0.5 * (a_up + b_up)
        A[cur, last + 2] = (2.0 * a_up - (1.0 - z) * b_dn) / (1.0 + z)
        W[cur, last + 2] = w_if
        B[cur, last + 1] = b_up
        W[cur, last + 1] = w_if
    end = section_start[-1] + 2 * n_sec - 1  # the ghost cell below the bit
    al = A[cur, end - 1]
    b_bit = al - 2.0 * min(max(al, -bit_cap_rel), bit_cap_rel)
    B[cur, end] = b_bit
    W[cur, end] = 0.5 * (al + b_bit)


@njit(cache=True, inline="always")
def cell_update(a_src, b_src, w_src_a, w_src_b, w_old, kt_dt, fcap_j, fix_s_j, fix_k_j, mu_s,
                mu_k, omega_c, inv_vs, delta, law, fixed):
    """Steps 2–3 of docs/theory.md §3.1 for one cell; returns (α, β) at step k+1 [rad/s].

    ``a_src``, ``b_src`` are the transported values α*, β* (step 1) and ``w_src_a``,
    ``w_src_b`` the speeds ω^k at the feet of their characteristics (the cell above and the
    cell below), ``w_old`` the cell's own ω^k. Viscous (erratum of eq. 11, integrated along
    the characteristic so that it dissipates energy): α** = α* − Δt·k_t·ω^k_(j−1),
    β** = β* − Δt·k_t·ω^k_(j+1). Friction inclusion (eqs. 5–6, A.1–A.5 with consistent
    units): the speed change that would stop the cell, ω** = (α** + β**)/2, is clamped to
    ±cap with the cap of :func:`friction_cap` at ω^k (docs/theory.md §3.2) and removed from
    both invariants (τ is untouched).
    """
    an = a_src - kt_dt * w_src_a
    bn = b_src - kt_dt * w_src_b
    w = 0.5 * (an + bn)
    cap = friction_cap(w_old, fcap_j, fix_s_j, fix_k_j, mu_s, mu_k, omega_c, inv_vs, delta,
                       law, fixed)
    d = min(max(w, -cap), cap)
    return an - d, bn - d


@njit(cache=True)
def pass_cells(A, B, W, cur, end, kt_dt, fcap, fix_s, fix_k, mu_s, mu_k, omega_c, inv_vs, delta,
               law, fixed, inj_a, inj_b, e, inject):
    """Steps 1–3 of docs/theory.md §3.1 on every cell: α*_j = α_{j−1}, β*_j = β_{j+1} (exact
    Courant-1 shift) from row ``cur`` of the state buffers ``A`` (α), ``B`` (β), ``W`` (ω),
    then :func:`cell_update`, written to row 1 − ``cur``, for the cells 1 … ``end`` − 1
    (``end`` = :func:`padded_size` − 1).

    Buffers and per-cell arrays are in the ghost layout of :func:`padded`, the ghost cells
    of row ``cur`` filled by :func:`inflows`, so section ends, junctions, the top drive and
    the bit need no separate pass (the ghost cells are updated too, meaninglessly, and
    refilled before they are read). With ``inject`` (the observer, docs/theory.md §5) each
    cell then loses ``inj_a[j]·e``, ``inj_b[j]·e`` in the same pass; without ``fixed`` the
    fixed arrays are not read. ``law``, ``fixed`` and ``inject`` must be compile-time
    constants at the call site: each combination compiles to its own branch-free loop,
    which the compiler vectorises.
    """
    literally(law)
    literally(fixed)
    literally(inject)
    nxt = 1 - cur
    for j in range(1, end):
        an, bn = cell_update(A[cur, j - 1], B[cur, j + 1], W[cur, j - 1], W[cur, j + 1],
                             W[cur, j], kt_dt, fcap[j], fix_s[j] if fixed else 0.0,
                             fix_k[j] if fixed else 0.0, mu_s, mu_k, omega_c, inv_vs, delta,
                             law, fixed)
        if inject:
            an -= inj_a[j] * e
            bn -= inj_b[j] * e
        A[nxt, j] = an
        B[nxt, j] = bn
        W[nxt, j] = 0.5 * (an + bn)


@njit(cache=True, inline="always", error_model="numpy")
def cell_update_axial(a_src, b_src, w_src_a, w_src_b, w_old, kt_dt, fcap_j, fix_s_j, fix_k_j,
                      mu_s, mu_k, omega_c, inv_vs, delta, law, fixed, u_j):
    """Steps 2–3 of docs/theory.md §3.1 for one cell of a string that also moves axially
    (docs/theory.md §3.3, eqs. 3.3a–3.3c); returns (α, β) at step k+1 [rad/s].

    ``u_j`` = |v|/r_c [rad/s] is the axial pipe speed in the cell's angular units. The
    contact speed s = √((ω^k)² + u_j²) [rad/s] (eq. 3.3a) decides the regime: under the step
    law the contact counts as at rest when s ≤ ω_c, and the static cap holds the cell as in
    :func:`cell_update`; otherwise the friction force opposes the contact's slip, and its
    torsional share ω/s of the cap (eq. 3.3b) is taken semi-implicitly with the magnitude
    at step k, d = clamp(ω**·cap/(s + cap), ±cap) (eq. 3.3c): exact in steady sliding,
    never past rest, never beyond the Coulomb cap. The Stribeck law takes its cap at the
    contact speed s.
    """
    an = a_src - kt_dt * w_src_a
    bn = b_src - kt_dt * w_src_b
    w = 0.5 * (an + bn)
    s = np.sqrt(w_old * w_old + u_j * u_j)
    cap = friction_cap(s, fcap_j, fix_s_j, fix_k_j, mu_s, mu_k, omega_c, inv_vs, delta, law,
                       fixed)
    slide = min(max(w * cap / (s + cap), -cap), cap)
    if law == LAW_STEP:
        held = min(max(w, -cap), cap)
        d = held if s <= omega_c else slide
    else:
        d = slide
    return an - d, bn - d


@njit(cache=True, error_model="numpy")
def pass_cells_axial(A, B, W, cur, end, kt_dt, fcap, fix_s, fix_k, mu_s, mu_k, omega_c,
                     inv_vs, delta, law, fixed, inv_rc, v_abs):
    """:func:`pass_cells` (without injection) for a string moving axially at speed
    ``v_abs`` = |v| [m/s]: the cells through :func:`cell_update_axial` with u_j = |v|/r_c,
    ``inv_rc`` = 1/r_c per cell [1/m] in the ghost layout of :func:`padded` with 1 in the
    ghost cells (:func:`padded_inverse_radius`: s + cap > 0 in every cell, no 0/0 even in
    the meaningless ghost updates). ``law`` and ``fixed`` must be compile-time constants at
    the call site (one vectorised loop each; NumPy's error model: no zero-division check
    that would stop the compiler from vectorising)."""
    literally(law)
    literally(fixed)
    nxt = 1 - cur
    for j in range(1, end):
        an, bn = cell_update_axial(A[cur, j - 1], B[cur, j + 1], W[cur, j - 1], W[cur, j + 1],
                                   W[cur, j], kt_dt, fcap[j], fix_s[j] if fixed else 0.0,
                                   fix_k[j] if fixed else 0.0, mu_s, mu_k, omega_c, inv_vs,
                                   delta, law, fixed, v_abs * inv_rc[j])
        A[nxt, j] = an
        B[nxt, j] = bn
        W[nxt, j] = 0.5 * (an + bn)


@njit(cache=True)
def work_buffer(alpha, beta, section_start, cells):
    """All the rows the cell loop touches, in one array of :func:`row_length` columns: the
    double-buffered state α (rows 0, 1), β (2, 3), ω = (α + β)/2 (4, 5), row 0, 2, 4 from
    ``alpha``, ``beta``, then the per-cell arrays of the tuple ``cells`` (rows 6, …), all
    in the ghost layout of :func:`padded`."""
    X = np.zeros((6 + len(cells), row_length(section_start)))
    X[0] = padded(alpha, section_start)
    X[2] = padded(beta, section_start)
    X[4] = 0.5 * (X[0] + X[2])
    for i in range(len(cells)):
        X[6 + i] = padded(cells[i], section_start)
    return X


@njit(cache=True)
def motor_torque(mode, u_now, u_aux, omega0, integral, tau0, kp, ki, dt, inv_itd):
    """Motor torque τ_m at step k [N·m] (docs/theory.md §3, top-drive controller).

    PI: k_p(ω_ref − ω₀) + k_i∫(ω_ref − ω₀)dt; prescribed torque: the series; prescribed
    speed: the torque that makes the top drive follow it, τ(0) + I_TD·Δω₀/Δt (``u_aux`` the
    next speed); fed: the logged motor torque plus the PI on the logged speed ``u_aux``,
    τ_m,log + k_p(ω_log − ω₀) + k_i∫(ω_log − ω₀)dt (docs/theory.md §6.4).
    """
    if mode == _MODE_PI:
        return kp * (u_now - omega0) + ki * integral
    if mode == _MODE_TORQUE:
        return u_now
    if mode == _MODE_FED:
        return u_now + kp * (u_aux - omega0) + ki * integral
    return tau0 + (u_aux - u_now) / (dt * inv_itd)


@njit(cache=True, inline="always")
def top_drive_step(omega0, beta0, q, accel_dt):
    """Step 4 of docs/theory.md §3.1, eq. (7), trapezoidal (docs/theory.md erratum E11) [rad/s].

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


@njit(cache=True, inline="always")
def bit_cap(cap_k_rel, weak_rel, inv_speed, w_bit):
    """Bit capacity T_bit(ω)/ζ_bit of a rate-weakening bit [rad/s] (docs/theory.md §3, bit).

    T_bit(ω) = T_k·(1 + (r − 1)·exp(−|ω|/ω_b)): ``cap_k_rel`` = T_k/ζ_bit (the high-speed
    sliding torque), ``weak_rel`` = (r − 1)·T_k/ζ_bit, ``inv_speed`` = 1/ω_b [s/rad], taken
    at ``w_bit``, the bit speed of the step before (explicit, as the friction caps of
    :func:`friction_cap` at ω^k). A bit at rest (``w_bit`` = 0) holds up to r·T_k; with
    ``weak_rel`` = 0 the result is ``cap_k_rel`` exactly (the Coulomb bit).
    """
    return cap_k_rel + weak_rel * exp_neg(abs(w_bit) * inv_speed)


def plant_kernel(law: int, fixed: bool, axial: bool = False):
    """The compiled plant kernel for one friction-law variant (``law``, :func:`law_code`) with
    or without a fixed friction part, and with or without axial pipe motion (``axial``):
    :func:`run_plant` without the variant dispatch. Its last four arguments are the axial
    speed series ``v_ax`` [m/s] (start ``v_t0``, interval ``v_dt``) and 1/r_c per cell
    ``inv_rc`` [1/m]; the kernel without ``axial`` reads none of them, and the one with it
    runs a step at v = 0 through :func:`pass_cells`, bit for bit the kernel without.

    The variant flags are constants of the compiled code (closure variables), so the cell
    loop of :func:`pass_cells` is branch-free and vectorised, and no reference counting
    happens inside the time loop (a run-time dispatch there cost ~30 atomic reference-count
    updates per step: half the time of a 65-cell step). Compiled on first use, cached on
    disk per variant. It runs without the GIL (``nogil``: arrays only), so a long fit in one
    thread does not stall another (``drillfric live`` writes live.json while fits run).
    """
    @njit(cache=True, nogil=True)
    def kernel(alpha, beta, top, t0, n_steps, section_start, junction_z, zeta, fcap, fix_k,
               fix_s, dt, kt_dt, mu_s, mu_k, omega_c, law_speed, law_exp, bit_cap_rel,
               bit_weak_rel, bit_inv_speed, inv_itd, mode, u, u_t0, u_dt, kp, ki, times,
               out, v_ax, v_t0, v_dt, inv_rc):
        last = alpha.size + 2 * section_start.size - 4  # the bit cell in the ghost layout
        X = work_buffer(alpha, beta, section_start, (fcap, fix_s, fix_k))
        A, B, W, fcap_p, fix_s_p, fix_k_p = X[0:2], X[2:4], X[4:6], X[6], X[7], X[8]
        inv_rc_p = padded_inverse_radius(inv_rc, section_start) if axial else fcap_p
        end = padded_size(section_start) - 1
        cur = np.int64(0)  # typed, not Literal[0]: pass_cells and inflows compile once
        inv_vs = 1.0 / law_speed if law != LAW_STEP else 0.0
        omega0 = top[0]
        integral = top[1]
        zeta0 = zeta[0]
        q_td = 0.5 * zeta0 * dt * inv_itd
        n_rec = times.size
        r = 0
        eps = 1e-9 * dt
        p0 = p1 = p2 = p3 = p4 = 0.0
        zeta_bit = zeta[zeta.size - 1]
        w_face = W[0, last]  # bit speed of the step before (the bit cell's at the start)
        for k in range(n_steps + 1):
            t = t0 + k * dt
            if mode == _MODE_FED:
                u_now = drive_half(u, np.int64(0), u_t0, u_dt, t)
                u_aux = drive_half(u, np.int64(1), u_t0, u_dt, t)
            else:
                u_now = drive_value(u, u_t0, u_dt, t)
                u_aux = u_now
            if mode == _MODE_SPEED:
                omega0 = u_now
                u_aux = drive_value(u, u_t0, u_dt, t + dt)
            beta0 = B[cur, 1]
            tau0 = zeta0 * (omega0 - beta0)
            tau_m = motor_torque(mode, u_now, u_aux, omega0, integral, tau0, kp, ki, dt,
                                 inv_itd)
            w_bit = W[cur, last]
            cap = bit_cap(bit_cap_rel, bit_weak_rel, bit_inv_speed, w_face)
            tau_bit = zeta_bit * min(max(A[cur, last], -cap), cap)
            while r < n_rec and times[r] <= t + eps:
                f = 1.0 if k == 0 else (times[r] - (t - dt)) / dt
                out[r, 0] = p0 + f * (omega0 - p0)
                out[r, 1] = p1 + f * (tau_m - p1)
                out[r, 2] = p2 + f * (tau0 - p2)
                out[r, 3] = p3 + f * (w_bit - p3)
                out[r, 4] = p4 + f * (tau_bit - p4)
                r += 1
            p0, p1, p2, p3, p4 = omega0, tau_m, tau0, w_bit, tau_bit
            if k == n_steps:
                break
            omega_next = omega0
            if mode != _MODE_SPEED:
                omega_next = top_drive_step(omega0, beta0, q_td, dt * inv_itd * tau_m)
            omega_bar = 0.5 * (omega0 + omega_next)
            inflows(A, B, W, cur, section_start, junction_z, 2.0 * omega_bar - beta0,
                    omega_bar, cap)
            w_face = W[cur, last + 1]
            v_now = drive_value(v_ax, v_t0, v_dt, t) if axial else 0.0
            if v_now != 0.0:
                pass_cells_axial(A, B, W, cur, end, kt_dt, fcap_p, fix_s_p, fix_k_p, mu_s,
                                 mu_k, omega_c, inv_vs, law_exp, law, fixed, inv_rc_p,
                                 abs(v_now))
            else:
                pass_cells(A, B, W, cur, end, kt_dt, fcap_p, fix_s_p, fix_k_p, mu_s, mu_k,
                           omega_c, inv_vs, law_exp, law, fixed, fcap_p, fcap_p, 0.0, False)
            if mode == _MODE_PI:
                integral += dt * (u_now - omega0)
            elif mode == _MODE_FED:
                integral += dt * (u_aux - omega0)
            omega0 = omega_next
            cur = 1 - cur
        unpadded(A[cur], section_start, alpha)
        unpadded(B[cur], section_start, beta)
        top[0] = omega0
        top[1] = integral

    return kernel


_KERNELS: dict = {}


def variant(law_speed: float, law_exp: float, fix_k, fix_s) -> tuple[int, bool]:
    """(law code, has a fixed part) of a kernel call: the variant that runs it."""
    return law_code(law_speed, law_exp), bool(np.any(fix_k) or np.any(fix_s))


def axial_args(axial, n_cells: int) -> tuple:
    """The kernel's axial arguments (v series [m/s], its t0 [s], its interval [s], 1/r_c per
    cell [1/m]) from ``axial`` = (v, v_t0, v_dt, inv_rc) or None, and whether any v ≠ 0 (the
    axial variant runs only then: without, the call is that of the kernel before axial
    motion existed)."""
    if axial is None or not np.any(np.asarray(axial[0]) != 0.0):
        return (np.zeros(1), 0.0, 1.0, np.zeros(n_cells)), False
    v, v_t0, v_dt, inv_rc = axial
    return (np.ascontiguousarray(v, dtype=float).ravel(), float(v_t0), float(v_dt),
            np.ascontiguousarray(inv_rc, dtype=float)), True


def run_plant(alpha, beta, top, t0, n_steps, section_start, junction_z, zeta, fcap, fix_k,
              fix_s, dt, kt_dt, mu_s, mu_k, omega_c, law_speed, law_exp, bit_cap_rel,
              bit_weak_rel, bit_inv_speed, inv_itd, mode, u, u_t0, u_dt, kp, ki, times, out,
              axial=None):
    """Advance ``n_steps`` steps from time ``t0`` and record at ``times`` (docs/theory.md §3.1).

    ``alpha``, ``beta`` (cells) and ``top`` = [ω₀, PI integral] are updated in place.
    Friction (docs/theory.md §3.2): caps μ_s·fcap + fix_s, μ_k·fcap + fix_k, step law at
    ``omega_c`` when ``law_speed`` = 0, else Stribeck with v_s = ``law_speed`` and
    δ = ``law_exp``. Per step: τ_m from the state at step k (held over the step), ω₀^(k+1)
    by the trapezoidal :func:`top_drive_step` (except for a prescribed speed), then steps
    1–3 with the top inflow α(0) = 2ω̄₀ − β(0) (erratum E11).
    Bit (docs/theory.md §3, rate-weakening bit): capacity T_bit(ω)/ζ_bit =
    ``bit_cap_rel`` + ``bit_weak_rel``·exp(−|ω|·``bit_inv_speed``) [rad/s] at the bit speed
    of the step before (:func:`bit_cap`); ``bit_weak_rel`` = 0 is the Coulomb bit.
    ``out[r]`` receives (ω₀, τ_m, τ(0) = ζ(ω₀ − β(0)), ω_bit, τ_bit) at ``times[r]`` (step
    values, τ(0) from ω₀ and β(0) at the step, τ_bit the bit torque applied over the step),
    linearly interpolated
    between the bracketing steps; ``times`` must lie in [t0, t0 + n_steps·dt].
    Axial pipe motion (docs/theory.md §3.3): ``axial`` = (v [m/s], v_t0 [s], v_dt [s],
    1/r_c per cell [1/m]), v a uniform series like ``u``, taken at the start of each step
    (:func:`axial_args`); None (default) or all v = 0 is the plant without it, bit for bit.
    Argument order: see :func:`drillfric.torsional.kernel_args`. Runs the compiled
    :func:`plant_kernel` of the call's variant (:func:`variant`).
    """
    ax, moving = axial_args(axial, alpha.size)
    key = variant(law_speed, law_exp, fix_k, fix_s) + (moving,)
    if key not in _KERNELS:
        _KERNELS[key] = plant_kernel(*key)
    _KERNELS[key](alpha, beta, top, t0, n_steps, section_start, junction_z, zeta, fcap, fix_k,
                  fix_s, dt, kt_dt, mu_s, mu_k, omega_c, law_speed, law_exp, bit_cap_rel,
                  bit_weak_rel, bit_inv_speed, inv_itd, mode, u, u_t0, u_dt, kp, ki, times, out,
                  *ax)
