"""Semi-lumped ODE–PDE–ODE torsional model and its Courant-1 linear discretisation.

docs/theory.md §4 (Section 3 of Aarsnes et al. 2019, eqs. (30)–(31)): the drill pipe [0, L_p] is
a lossless transmission line in the Riemann invariants α, β; the top drive (x = 0) and the
BHA, lumped into one rigid inertia at x = L_p carrying all the friction as a torque d, are
ODEs at its ends::

    α_t + c α_x = −p_α(x) e,          β_t − c β_x = −p_β(x) e
    dω₀/dt = a₀ (β(0) − ω₀) + τ_m/I_TD − p₀ e,        α(0)   = 2ω₀ − β(0) − P₀ e
    dω_L/dt = a_L (α(L_p) − ω_L) − d/I_BHA − p₁ e,    β(L_p) = 2ω_L − α(L_p) − P₁ e
    dd/dt = −p_d e

with e = ω₀ − y the innovation against a measured top-drive speed y. Without injections
(all gains zero) this is the plant of §4; with them it is the observer of §5 (and, written
for observer − plant with y = 0, its linear error system).

With k_t > 0 the pipe also carries the viscous term −(k_t/2)(α + β) of docs/theory.md §3 on
both invariants (the §4 model and N(s) have k_t = 0; the Kalman design uses the physical
damping, which is what damps the grid-scale modes).

Discretisation: nodes x_j = j·Δx, j = 0..n, with Δx = L_p/n and Δt = Δx/c (Courant
number 1), so transport along a characteristic is an exact shift of one node per step.
The sources along each characteristic, and the two ODEs, use the trapezoidal rule; the
values a boundary ODE needs at step k+1 (β(0) = β₁ shifted, α(L_p) = α_{n−1} shifted) are
known from step k, so the only implicit unknowns are the two scalars ω₀, ω_L, solved in
closed form; the viscous term (when k_t > 0) is explicit at the departure node. The
scheme without viscous term is second-order accurate in Δt and has no numerical diffusion.
State vector (length 2n + 3)::

    [ω₀, α₁ … α_n, β₀ … β_{n−1}, ω_L, d]

α₀ and β_n are boundary values, functions of the state (not stored).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drillfric.drillstring import DrillString
from drillfric.errors import ModelError


@dataclass(frozen=True)
class LumpedParams:
    """Coefficients of the semi-lumped model (docs/theory.md §4, eqs. (30)–(31) of [1]).

    Attributes
    ----------
    a0_per_s : float
        a₀ = ζ_pipe/I_TD [1/s].
    aL_per_s : float
        a_L = ζ_pipe/I_BHA [1/s].
    c_m_s : float
        Torsional wave speed of the drill pipe [m/s].
    Lp_m : float
        Pipe length = measured depth of the BHA top L_p [m].
    I_TD_kg_m2, I_BHA_kg_m2 : float
        Top-drive and lumped BHA inertias [kg·m²].
    zeta_pipe_Nms : float
        Line impedance of the pipe ζ_pipe [N·m·s/rad].
    k_t_per_s : float
        Viscous damping of the pipe k_t [1/s] (docs/theory.md §3, eq. (2)–(3)); 0 in the §4 model
        and its error analysis, positive for the Kalman design.
    """

    a0_per_s: float
    aL_per_s: float
    c_m_s: float
    Lp_m: float
    I_TD_kg_m2: float
    I_BHA_kg_m2: float
    zeta_pipe_Nms: float
    k_t_per_s: float = 0.0

    @property
    def t_D_s(self) -> float:
        """One-way travel time of a torsional wave along the pipe t_D = L_p/c [s]."""
        return self.Lp_m / self.c_m_s

    @classmethod
    def from_string(cls, string: DrillString, top_drive_inertia_kg_m2: float, *,
                    k_t_per_s: float = 0.0) -> LumpedParams:
        """Lump a drill string: first section = pipe, the rest = rigid BHA (docs/theory.md §4).

        Parameters
        ----------
        string : DrillString
            Top-down sections; at least one below the drill pipe.
        top_drive_inertia_kg_m2 : float
            Top-drive inertia I_TD [kg·m²].
        k_t_per_s : float
            Viscous damping of the pipe [1/s] (keep 0 for the §4 model).

        Raises
        ------
        ModelError
            Without a BHA section or with a non-positive inertia.
        """
        if len(string.sections) < 2:
            raise ModelError("the semi-lumped observer model needs a BHA (a section below "
                             "the drill pipe)", fix="add the collars/BHA to [[string.sections]]")
        if not np.isfinite(top_drive_inertia_kg_m2) or top_drive_inertia_kg_m2 <= 0:
            raise ModelError(f"top-drive inertia must be positive, got {top_drive_inertia_kg_m2}",
                             fix="set rig.top_drive_inertia_kg_m2")
        pipe = string.sections[0]
        zeta = pipe.impedance_Nms
        i_bha = string.bha_inertia_kg_m2
        return cls(a0_per_s=zeta / top_drive_inertia_kg_m2, aL_per_s=zeta / i_bha,
                   c_m_s=pipe.wave_speed_m_s, Lp_m=string.bha_top_m,
                   I_TD_kg_m2=float(top_drive_inertia_kg_m2), I_BHA_kg_m2=i_bha,
                   zeta_pipe_Nms=zeta, k_t_per_s=float(k_t_per_s))


@dataclass(frozen=True)
class Injection:
    """Output injection gains of the observer, sampled on the model nodes (docs/theory.md §5).

    Attributes
    ----------
    p0 : float
        Top-drive injection [1/s].
    P0 : float
        Top boundary injection into α(0) [–].
    p_alpha, p_beta : numpy.ndarray
        Distributed injections at the nodes x_j = j·L_p/n, length n + 1 [1/s].
    P1 : float
        Pipe/BHA junction injection into β(L_p) [–].
    p1 : float
        BHA speed injection [1/s].
    p_d : float
        Lumped friction torque injection [N·m·s/rad /s] (dd/dt = −p_d e).
    """

    p0: float
    P0: float
    p_alpha: np.ndarray
    p_beta: np.ndarray
    P1: float
    p1: float
    p_d: float

    @classmethod
    def none(cls, n_cells: int) -> Injection:
        """No injection: the plant of docs/theory.md §4."""
        zeros = np.zeros(n_cells + 1)
        return cls(0.0, 0.0, zeros, zeros, 0.0, 0.0, 0.0)


def time_step_s(params: LumpedParams, n_cells: int) -> float:
    """Courant-1 time step Δt = L_p/(n c) [s]."""
    return params.t_D_s / n_cells


def nodes_m(params: LumpedParams, n_cells: int) -> np.ndarray:
    """Node positions x_j = j·L_p/n, j = 0..n [m]."""
    return np.linspace(0.0, params.Lp_m, n_cells + 1)


def state_size(n_cells: int) -> int:
    """Length of the state vector [ω₀, α₁…α_n, β₀…β_{n−1}, ω_L, d]."""
    return 2 * n_cells + 3


def step(params: LumpedParams, inj: Injection, z: np.ndarray, y=(0.0, 0.0),
         tau_m=(0.0, 0.0)) -> np.ndarray:
    """Advance the state one Courant-1 step (trapezoidal sources, exact transport).

    Parameters
    ----------
    params : LumpedParams
    inj : Injection
        Gains on the n + 1 nodes (``Injection.none(n)`` for the plant).
    z : numpy.ndarray
        State(s), shape (2n + 3,) or (2n + 3, m) for m independent columns.
    y : pair of float or array
        Measured top-drive speed at steps k and k+1 [rad/s] (0 for the error system).
    tau_m : pair of float or array
        Motor torque at steps k and k+1 [N·m].

    Returns
    -------
    numpy.ndarray
        State at step k+1, same shape as ``z``.
    """
    n = inj.p_alpha.size - 1
    h = time_step_s(params, n)
    a0, aL, ibha, itd = params.a0_per_s, params.aL_per_s, params.I_BHA_kg_m2, params.I_TD_kg_m2
    pa, pb = inj.p_alpha, inj.p_beta
    if z.ndim == 2:
        pa, pb = pa[:, None], pb[:, None]
    w0, al, be, wl, d = z[0], z[1:n + 1], z[n + 1:2 * n + 1], z[2 * n + 1], z[2 * n + 2]
    e = w0 - y[0]
    a_top = 2.0 * w0 - be[0] - inj.P0 * e            # α₀ at step k
    b_bot = 2.0 * wl - al[-1] - inj.P1 * e           # β_n at step k
    twice_omega = np.concatenate([(a_top + be[0])[None], al[:-1] + be[1:], (al[-1] + b_bot)[None]])
    visc = 0.5 * h * params.k_t_per_s * twice_omega  # explicit, at the departure node
    # everything at step k+1 except the terms in e_{k+1} (shift + trapezoid sources)
    al_known = np.concatenate([a_top[None], al[:-1]]) - 0.5 * h * pa[:-1] * e - visc[:-1]
    be_known = np.concatenate([be[1:], b_bot[None]]) - 0.5 * h * pb[1:] * e - visc[1:]
    f0 = a0 * (be[0] - w0) + tau_m[0] / itd - inj.p0 * e
    rhs = (w0 + 0.5 * h * f0 + 0.5 * h * (a0 * (be_known[0] + 0.5 * h * pb[0] * y[1])
                                          + tau_m[1] / itd + inj.p0 * y[1]))
    w0_new = rhs / (1.0 + 0.5 * h * (a0 + inj.p0 + 0.5 * h * a0 * pb[0]))
    e_new = w0_new - y[1]
    al_new = al_known - 0.5 * h * pa[1:] * e_new
    be_new = be_known - 0.5 * h * pb[:-1] * e_new
    d_new = d - 0.5 * h * inj.p_d * (e + e_new)
    fl = aL * (al[-1] - wl) - d / ibha - inj.p1 * e
    wl_new = ((wl + 0.5 * h * fl + 0.5 * h * (aL * al_new[-1] - d_new / ibha - inj.p1 * e_new))
              / (1.0 + 0.5 * h * aL))
    return np.concatenate([w0_new[None], al_new, be_new, wl_new[None], d_new[None]])


def transition_matrix(params: LumpedParams, inj: Injection) -> np.ndarray:
    """Matrix A of z_{k+1} = A z_k for y ≡ 0, τ_m ≡ 0 (plant, or observer-error system).

    With ``Injection.none(n)`` this is the free plant of docs/theory.md §4; with the observer's
    gains it is the linear error system observer − plant (the measured speed is the
    plant's, so the error's "measurement" is zero).
    """
    size = state_size(inj.p_alpha.size - 1)
    return step(params, inj, np.eye(size))


def output_matrix(n_cells: int) -> np.ndarray:
    """Row C with y = C z = ω₀ (the measured top-drive speed)."""
    c = np.zeros((1, state_size(n_cells)))
    c[0, 0] = 1.0
    return c


def steady_state(params: LumpedParams, n_cells: int, omega_rad_s: float,
                 d_Nm: float) -> np.ndarray:
    """Steady rotation at ω with friction torque d (needs τ_m = d): a uniform twist.

    The pipe carries τ = d everywhere: α = ω + d/ζ, β = ω − d/ζ (docs/theory.md §3, eq. (8)).
    """
    z = np.empty(state_size(n_cells))
    z[0] = omega_rad_s
    z[1:n_cells + 1] = omega_rad_s + d_Nm / params.zeta_pipe_Nms
    z[n_cells + 1:2 * n_cells + 1] = omega_rad_s - d_Nm / params.zeta_pipe_Nms
    z[2 * n_cells + 1] = omega_rad_s
    z[2 * n_cells + 2] = d_Nm
    return z
