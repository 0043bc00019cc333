r"""Lumped multi-body torsional drill string with Coulomb wall friction (validation plant).

This module documents itself: it is a validation plant for drillfric and imports nothing of
drillfric (numpy, scipy and numba only). Sections below are cited as §L1–§L6.

§L1 Geometry and loads
----------------------
The string, top-down, is a list of :class:`Section` s (drill pipe, heavy-weight, collars…;
outer and inner diameter OD, ID [m], shear modulus G [Pa], steel density ρ [kg/m³], linear
mass m [kg/m] including tool joints, contact diameter D_c [m] = tool-joint OD, else OD).
Measured depth x runs from the top drive (x = 0) to the bit (x = L). Per section

    J = π(OD⁴ − ID⁴)/32  [m⁴],    c = √(G/ρ)  [m/s],
    w_b = g·(m − ρ_mud·π OD²/4 + ρ_mud·π ID²/4)  [N/m]  (buoyed weight, one mud).

The well path is the plant's own :class:`Survey`: inclination θ(x) interpolated *linearly*
in measured depth between stations (azimuth is irrelevant to this plant). The normal force
per metre is the gravity side force alone, and the Coulomb capacity per metre per unit
friction factor is

    F_N(x) = w_b(x)·sin θ(x)  [N/m],        F_c(x) = r_c(x)·F_N(x)  [N·m/m],  r_c = D_c/2,

(no tension–curvature term, no buckling: the soft-string model drillfric uses adds the
curvature term, which is what the harness's *effective* truth accounts for). The hook load
rotating off bottom is H = ∫ w_b cos θ dx − WOB [N].

§L2 Lumped model
----------------
The string is cut into N ≥ ``min_elements`` segments of length Δx_j ≈ ``element_m``, each
inside one section (section boundaries are nodes). Node 0 is the top drive, nodes
1…N lie at the segment ends x_j = Σ_{l≤j} Δx_l, node N at the bit. Segment j (between nodes
j−1 and j) is a torsional spring and a parallel dashpot (Kelvin–Voigt material damping)

    k_j = G_j J_j / Δx_j  [N·m/rad],      c_j = η·k_j  [N·m·s/rad]   (η [s] = ``material_loss_s``)

and its rotary inertia ρ_j J_j Δx_j is split half to each end node:
I_i = ½ρJΔx (segment above) + ½ρJΔx (segment below); node 0 adds the top-drive inertia
I_TD. Each node i ≥ 1 carries the wall friction of the string from the midpoint of the
segment above to the midpoint of the segment below (node 1 also that of the top half of
segment 1, node N that of the lower half of segment N): its capacity per unit friction
factor is C_i = ∫ F_c dx over that interval [N·m], integrated exactly (θ is linear between
stations, so ∫ sin θ dx has a closed form per piece), and Σ_i C_i = ∫₀ᴸ F_c dx = T_N. With
``contact_every`` = m > 1 the capacity of every run of m nodes is concentrated at its
deepest node (stabilisers / tool joints as discrete contacts; the total is unchanged).
Viscous drag to the hole acts at each node, d_i = κ·I_i^string + χ·ℓ_i [N·m·s/rad]
(κ [1/s] = ``viscous_rate_per_s``, a mass-proportional rate like a k_t; χ [N·m·s/rad per m]
= ``hole_damping_Nms_m``, ℓ_i the length the node carries). With angles q_i and speeds
ω_i = dq_i/dt, and the twist φ_j = q_{j−1} − q_j of segment j:

    I_i dω_i/dt = τ_i − τ_{i+1} − d_i ω_i − f_i + δ_{i0}·τ_m + δ_{iN}·(−τ_bit)
    τ_j = k_j φ_j + c_j (ω_{j−1} − ω_j)       (torque carried by segment j; τ_0 = τ_{N+1} = 0)

**Friction** (set-valued Coulomb law with a Karnopp switching band ω_sw, ``omega_switch_rad_s``):
a node with |ω_i| < ω_sw is *stuck*: it stays at ω_i = 0 as long as the torque that would
move it is within the static capacity μ_s C_i, and when that torque exceeds it, friction
opposes with μ_s C_i (Karnopp's saturation); a node with |ω_i| ≥ ω_sw slides against
μ_k C_i sign ω_i, and is stopped (ω_i = 0) when that friction can stop it within the step.
The bit on bottom is a Coulomb element of capacity T_bit = μ_bit·WOB·(2/3)·R_bit
(R_bit = D_bit/2: uniform pressure over the face), static = kinetic, added to node N.

**Top drive**: a PI speed controller on the set-point ω_set(t)

    τ_m = k_p (ω_set − ω_0) + k_i ∫₀ᵗ (ω_set − ω_0) dt',

or a prescribed motor-torque series. The logged surface torque is the torque in the top
segment τ_1 (a torque sub between the top drive and the string; ``surface_torque_Nm``,
rig torque kind "string"); the motor torque τ_m is recorded as well.

§L3 Integrator (Moreau–Jean θ-method, projected Gauss–Seidel)
-------------------------------------------------------------
Not a characteristic scheme: a velocity-level time stepping of the non-smooth dynamics
(Moreau 1988; Jean 1999, "The non-smooth contact dynamics method", Comput. Methods Appl.
Mech. Eng. 177, 235–257). Step n → n+1 (Δt = ``dt_s``), θ ∈ [½, 1] (default ½: the
trapezoidal rule, which conserves the energy of the linear part exactly):

    φ⁺ = φ + Δt[θ Δω⁺ + (1 − θ) Δω]                         (Δω_j = ω_{j−1} − ω_j)
    I(ω⁺ − ω) = Δt[θ F(φ⁺, ω⁺) + (1 − θ) F(φ, ω)] + Δt τ_m e_0 − p

with F the spring, dashpot and drag torques and p the friction impulses. Eliminating φ⁺
gives a symmetric positive-definite tridiagonal system A ω⁺ = b − p,

    A = I + Δt θ D + Σ_j a_j (e_{j−1} − e_j)(e_{j−1} − e_j)ᵀ + Δt k_p e_0 e_0ᵀ,
    a_j = Δt θ c_j + Δt² θ² k_j,
    b_i = I_i ω_i − Δt(1 − θ) d_i ω_i + Δt(E_i − E_{i+1}) + δ_{i0} Δt (k_p ω_set⁺ + k_i Σ),
    E_j = k_j φ_j + (Δt θ(1 − θ) k_j + (1 − θ) c_j)(ω_{j−1} − ω_j),

(the proportional part of the PI law is implicit in ω_0⁺, the integral Σ explicit), with
the friction impulse of node i bounded by Δt·μ·C_i (μ = μ_s if |ω_i| < ω_sw at step n,
else μ_k). This is the convex problem min ½ωᵀAω − bᵀω + Σ Δt μ_i C_i |ω_i|, solved by
projected Gauss–Seidel (coordinate descent) in red–black order (even nodes, then odd:
each colour depends only on the other, so a sweep is the same in the compiled kernel and
in the NumPy twin). The node update is the soft threshold

    r_i = b_i + a_i ω_{i−1} + a_{i+1} ω_{i+1},    ω_i = sign(r_i)·max(|r_i| − Δt μ_i C_i, 0)/A_ii

(r_i within the capacity: the node sticks, ω_i = 0 exactly), swept until no speed changes
by more than ``tol_rad_s``. Then φ⁺, the integral Σ⁺ = Σ + Δt(ω_set⁺ − ω_0⁺), and
τ_m = k_p(ω_set⁺ − ω_0⁺) + k_i Σ are updated.

**Energy** (θ = ½): with ω̄ = (ω + ω⁺)/2, the step changes E = ½Σ I_i ω_i² + ½Σ k_j φ_j² by
exactly Δt τ_m ω̄_0 − Δt ω̄ᵀDω̄ − Δt Σ c_j Δω̄_j² − pᵀω̄ (motor work, drag, material damping,
friction); the kernel accumulates each term (tests/test_lumped_plant.py checks the balance
to round-off and |p_i| ≤ Δt μ C_i).

Stability: A is SPD for any Δt, so the scheme is unconditionally stable; Δt sets the
accuracy of the stick/slip transitions (first order) and of the waves (the lumped chain's
highest mode, 2c/Δx ≈ 250 rad/s at 25-m segments, is resolved at Δt = 1 ms). The
discrete chain's first frequency differs from the continuous string's c/(4L) by the factor
sin(π/4N)/(π/4N) (uniform string, fixed top, free bit), ≈ 1 − 10⁻⁵ at N = 100.

§L4 Outputs
-----------
:func:`simulate` records spot values every 1/``rate_hz`` s (a whole number of steps):
``time_s``, ``surface_rpm`` (ω_0), ``surface_torque_Nm`` (τ_1), ``motor_torque_Nm`` (τ_m),
``bit_rpm`` (ω_N, the truth), and the constants ``hookload_N``, ``bit_depth_m``,
``hole_depth_m`` (bit + ``off_bottom_m`` off bottom), ``wob_N``. :class:`Noise` adds seeded
Gaussian noise and quantisation to the surface channels (after the truth is taken).

With a :class:`Motor` (a positive displacement mud motor between the string's bottom and the
bit, pumped at the flow Q) the log adds ``flow_in_m3_s`` (Q) and ``bha_rpm`` (ω_N, the
string's bottom), and ``bit_rpm`` becomes the bit's: ω_N plus the motor's speed relative to
its housing, which falls linearly with the torque it delivers to the bit (§L6).

§L6 Mud motor
-------------
A positive displacement motor passes a fixed volume of mud per revolution: without load it
turns at n₀ = k·Q (k [rev/m³] from ``rev_per_litre`` × 1000 L/m³), and its leakage grows with
the differential pressure, i.e. with the torque it delivers, until it stalls at τ_stall:

    ω_motor = 2π·k·Q·max(0, 1 − τ_bit/τ_stall)   [rad/s]

Its housing turns with node N and carries the bit's reaction, so the string sees the bit
torque as before (the motor's own inertia is neglected). With the motor turning, the bit
always slides on the rock: on bottom it delivers the Coulomb bit's T_bit all the time, off
bottom nothing, so the motor turns at n₀·(1 − T_bit/τ_stall) on bottom and n₀ off bottom.
(Like the node-N element, the plant's bit friction still acts on ω_N: what a motor changes
in the string's own stick-slip on bottom is not modelled.)

§L5 Units
---------
SI and radians inside (m, s, kg, N, N·m, rad/s); RPM only in the set-point knots and the
recorded speed channels.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

try:  # numba is a dependency of the project, but the twin works without it
    from numba import njit
except ImportError:  # pragma: no cover
    njit = None

G_ACC = 9.80665  # [m/s²]
RPM = 2.0 * np.pi / 60.0  # [rad/s per RPM]


# ---------------------------------------------------------------------------------------
# §L1 geometry
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Section:
    """One section of the string (§L1).

    Attributes
    ----------
    name : str
    od_m, id_m : float
        Body outer and inner diameter [m].
    length_m : float or None
        Length [m]; None for the one section (the top one) that fills to the bit depth.
    contact_od_m : float or None
        Diameter at which the string touches the wall (tool-joint OD) [m]; default OD.
    linear_mass_kg_m : float or None
        Mass per metre including tool joints [kg/m]; default ρ·π(OD² − ID²)/4.
    shear_modulus_Pa, density_kg_m3 : float
        G [Pa] and steel density ρ [kg/m³] (rotary inertia per metre ρJ).
    """

    name: str
    od_m: float
    id_m: float
    length_m: float | None = None
    contact_od_m: float | None = None
    linear_mass_kg_m: float | None = None
    shear_modulus_Pa: float = 79.3e9
    density_kg_m3: float = 7850.0

    @property
    def polar_moment_m4(self) -> float:
        """J = π(OD⁴ − ID⁴)/32 [m⁴]."""
        return np.pi * (self.od_m ** 4 - self.id_m ** 4) / 32.0

    @property
    def wave_speed_m_s(self) -> float:
        """c = √(G/ρ) [m/s]."""
        return float(np.sqrt(self.shear_modulus_Pa / self.density_kg_m3))

    @property
    def mass_kg_m(self) -> float:
        """Linear mass m [kg/m]."""
        if self.linear_mass_kg_m is not None:
            return self.linear_mass_kg_m
        return self.density_kg_m3 * np.pi * (self.od_m ** 2 - self.id_m ** 2) / 4.0

    @property
    def contact_radius_m(self) -> float:
        """r_c = D_c/2 [m]."""
        return 0.5 * (self.contact_od_m if self.contact_od_m is not None else self.od_m)

    def buoyed_weight_N_m(self, mud_density_kg_m3: float) -> float:
        """w_b = g(m − ρ_mud π OD²/4 + ρ_mud π ID²/4) [N/m] (one mud inside and out)."""
        return G_ACC * (self.mass_kg_m - mud_density_kg_m3 * np.pi
                        * (self.od_m ** 2 - self.id_m ** 2) / 4.0)


@dataclass(frozen=True)
class Survey:
    """The plant's own well path: inclination linear in measured depth between stations.

    Attributes
    ----------
    md_m : ndarray
        Station measured depths [m], increasing, from 0.
    inc_deg : ndarray
        Inclination at the stations [deg].
    """

    md_m: np.ndarray
    inc_deg: np.ndarray

    def __post_init__(self):
        md = np.asarray(self.md_m, dtype=float)
        inc = np.asarray(self.inc_deg, dtype=float)
        if md.ndim != 1 or md.shape != inc.shape or md.size < 2 or md[0] != 0.0 or \
                np.any(np.diff(md) <= 0):
            raise ValueError("a survey needs ≥ 2 stations, md from 0, increasing")
        object.__setattr__(self, "md_m", md)
        object.__setattr__(self, "inc_deg", inc)

    @classmethod
    def build_and_hold(cls, td_m: float, kop_m: float, tangent_deg: float,
                       build_deg_30m: float = 3.0) -> Survey:
        """Vertical to the kick-off ``kop_m``, build at ``build_deg_30m`` to ``tangent_deg``,
        hold to ``td_m`` [m]."""
        end_build = kop_m + tangent_deg / build_deg_30m * 30.0
        md = [0.0, kop_m, end_build, max(td_m, end_build + 1.0)]
        return cls(np.array(md), np.array([0.0, 0.0, tangent_deg, tangent_deg]))

    def inclination_rad(self, md_m) -> np.ndarray:
        """θ(x) [rad], linear between stations, held beyond the last."""
        return np.radians(np.interp(md_m, self.md_m, self.inc_deg))

    def _cumulative(self, fn: str) -> tuple[np.ndarray, np.ndarray]:
        """∫₀^{s_k} sin θ dx (or cos) at the stations, exact for θ linear per piece."""
        th = np.radians(self.inc_deg)
        ds = np.diff(self.md_m)
        dth = np.diff(th)
        slope = np.divide(dth, ds)
        with np.errstate(divide="ignore", invalid="ignore"):
            if fn == "sin":
                piece = np.where(np.abs(dth) > 1e-12,
                                 (np.cos(th[:-1]) - np.cos(th[1:])) / slope,
                                 np.sin(th[:-1]) * ds)
            else:
                piece = np.where(np.abs(dth) > 1e-12,
                                 (np.sin(th[1:]) - np.sin(th[:-1])) / slope,
                                 np.cos(th[:-1]) * ds)
        return np.concatenate([[0.0], np.cumsum(piece)]), slope

    def integral(self, fn: str, md_m) -> np.ndarray:
        """∫₀^x sin θ dx' (``fn`` = "sin") or ∫₀^x cos θ dx' (``"cos"``) [m], exact."""
        x = np.asarray(md_m, dtype=float)
        cum, slope = self._cumulative(fn)
        k = np.clip(np.searchsorted(self.md_m, x, side="right") - 1, 0, self.md_m.size - 1)
        x0 = self.md_m[k]
        th0 = np.radians(self.inc_deg[k])
        s = np.where(k < slope.size, slope[np.minimum(k, slope.size - 1)], 0.0)
        th = th0 + s * (x - x0)
        ok = np.abs(s) > 1e-15
        safe = np.where(ok, s, 1.0)
        if fn == "sin":
            part = np.where(ok, (np.cos(th0) - np.cos(th)) / safe, np.sin(th0) * (x - x0))
        else:
            part = np.where(ok, (np.sin(th) - np.sin(th0)) / safe, np.cos(th0) * (x - x0))
        return cum[k] + part


@dataclass(frozen=True)
class LumpedString:
    """The lumped string at one bit depth (§L2). Arrays are over nodes 0…N (node 0 the top
    drive, whose string share of inertia is ``inertia_kg_m2[0]``) or over segments, index j
    of segment j between nodes j−1 and j (index 0 unused, 0).

    Attributes
    ----------
    x_m : ndarray (N+1)
        Node depths [m].
    inertia_kg_m2 : ndarray (N+1)
        Rotary inertia of the string lumped at each node [kg·m²] (without I_TD).
    stiffness_Nm_rad : ndarray (N+1)
        k_j [N·m/rad].
    capacity_Nm : ndarray (N+1)
        C_i = ∫F_c dx carried by node i per unit friction factor [N·m] (C_0 = 0).
    length_m : ndarray (N+1)
        Length of string whose wall contact node i carries [m].
    hookload_N : float
        ∫w_b cos θ dx [N] (off bottom, no block weight).
    wave_time_s : float
        Σ L_s/c_s [s], the continuous string's top-to-bit travel time.
    sections : tuple of (Section, length_m)
    """

    x_m: np.ndarray
    inertia_kg_m2: np.ndarray
    stiffness_Nm_rad: np.ndarray
    capacity_Nm: np.ndarray
    length_m: np.ndarray
    hookload_N: float
    wave_time_s: float
    sections: tuple
    bit_depth_m: float

    @property
    def n_elements(self) -> int:
        """N, the number of segments (and of string nodes)."""
        return self.x_m.size - 1

    @property
    def T_N_Nm(self) -> float:
        """Σ C_i = ∫₀ᴸ F_c dx [N·m]: the steady sliding torque per unit μ."""
        return float(np.sum(self.capacity_Nm))


def build_string(sections: Sequence[Section], bit_depth_m: float, survey: Survey, *,
                 mud_density_kg_m3: float = 1200.0, element_m: float = 25.0,
                 min_elements: int = 100, contact_every: int = 1,
                 capacity_Nm_m: Callable[[np.ndarray], np.ndarray] | None = None
                 ) -> LumpedString:
    """Lump ``sections`` (top-down) at ``bit_depth_m`` on ``survey`` (§L1–§L2).

    Parameters
    ----------
    element_m : float
        Target segment length [m]; reduced so that there are at least ``min_elements``.
    contact_every : int
        Concentrate the capacity of every run of this many nodes at its deepest node.
    capacity_Nm_m : callable, optional
        F_c(x) [N·m/m] replacing w_b r_c sin θ (e.g. another model's profile for a
        cross-check); integrated by the midpoint rule at ≤ 0.25 m.
    """
    if bit_depth_m <= 0:
        raise ValueError("bit depth must be positive")
    fixed = sum(s.length_m for s in sections if s.length_m is not None)
    fills = [s for s in sections if s.length_m is None]
    if len(fills) > 1 or fixed > bit_depth_m + 1e-9:
        raise ValueError("at most one section without length, and the fixed ones must fit")
    lengths = [(s.length_m if s.length_m is not None else bit_depth_m - fixed)
               for s in sections]
    parts = [(s, L) for s, L in zip(sections, lengths, strict=True) if L > 1e-9]
    target = min(element_m, bit_depth_m / min_elements)
    while True:
        counts = [max(1, int(round(L / target))) for _, L in parts]
        if sum(counts) >= min_elements:
            break
        target *= 0.98
    dx, sec_of = [], []
    for k, ((_, L), n) in enumerate(zip(parts, counts, strict=True)):
        dx += [L / n] * n
        sec_of += [k] * n
    dx = np.array(dx)
    n = dx.size
    x = np.concatenate([[0.0], np.cumsum(dx)])
    x[-1] = bit_depth_m
    props = [(s.density_kg_m3 * s.polar_moment_m4, s.shear_modulus_Pa * s.polar_moment_m4,
              s.contact_radius_m, s.buoyed_weight_N_m(mud_density_kg_m3)) for s, _ in parts]
    rhoJ = np.array([props[k][0] for k in sec_of])
    GJ = np.array([props[k][1] for k in sec_of])
    rc = np.array([props[k][2] for k in sec_of])
    wb = np.array([props[k][3] for k in sec_of])
    inertia = np.zeros(n + 1)
    inertia[:-1] += 0.5 * rhoJ * dx
    inertia[1:] += 0.5 * rhoJ * dx
    k = np.concatenate([[0.0], GJ / dx])
    # capacity of each half segment: upper half → node j−1 (node 1 for segment 1), lower → j
    mid = 0.5 * (x[:-1] + x[1:])
    if capacity_Nm_m is None:
        sin_int = survey.integral("sin", np.concatenate([x, mid]))
        s_node, s_mid = sin_int[: n + 1], sin_int[n + 1:]
        upper = wb * rc * (s_mid - s_node[:-1])
        lower = wb * rc * (s_node[1:] - s_mid)
    else:
        upper = np.array([_midpoint(capacity_Nm_m, a, b) for a, b in zip(x[:-1], mid,
                                                                          strict=True)])
        lower = np.array([_midpoint(capacity_Nm_m, a, b) for a, b in zip(mid, x[1:],
                                                                          strict=True)])
    cap = np.zeros(n + 1)
    cap[1:] += lower
    cap[1:] += np.concatenate([[0.0], upper[1:]])
    cap[1] += upper[0]
    length = np.zeros(n + 1)
    length[1:] += 0.5 * dx
    length[1:-1] += 0.5 * dx[1:]
    length[1] += 0.5 * dx[0]
    if contact_every > 1:
        lumped = np.zeros_like(cap)
        for start in range(1, n + 1, contact_every):
            end = min(start + contact_every, n + 1)
            lumped[end - 1] = cap[start:end].sum()
        cap = lumped
    cos_int = survey.integral("cos", x)
    hook = float(np.sum(wb * np.diff(cos_int)))
    travel = sum(L / s.wave_speed_m_s for s, L in parts)
    return LumpedString(x, inertia, k, cap, length, hook, float(travel),
                        tuple(parts), float(bit_depth_m))


def _midpoint(fn, a: float, b: float) -> float:
    m = max(1, int(np.ceil((b - a) / 0.25)))
    s = a + (np.arange(m) + 0.5) * (b - a) / m
    return float(np.sum(fn(s)) * (b - a) / m)


def natural_frequencies_hz(string: LumpedString, top_inertia_kg_m2: float | None = None,
                           count: int = 3) -> np.ndarray:
    """Lowest undamped natural frequencies of the frictionless chain [Hz]: top fixed
    (``top_inertia_kg_m2`` None) or a free top-drive inertia (then the rigid-body mode 0 is
    left out), bit free. Generalised eigenproblem K v = ω² M v (scipy.linalg.eigh)."""
    from scipy.linalg import eigh

    n = string.n_elements
    k = string.stiffness_Nm_rad
    K = np.zeros((n + 1, n + 1))
    for j in range(1, n + 1):
        K[j - 1, j - 1] += k[j]
        K[j, j] += k[j]
        K[j - 1, j] -= k[j]
        K[j, j - 1] -= k[j]
    m = string.inertia_kg_m2.copy()
    if top_inertia_kg_m2 is None:
        K, m = K[1:, 1:], m[1:]
    else:
        m[0] += top_inertia_kg_m2
    w2 = eigh(K, np.diag(m), eigvals_only=True, subset_by_index=[0, count])
    w = np.sqrt(np.clip(w2, 0.0, None)) / (2 * np.pi)
    return w[1:count + 1] if top_inertia_kg_m2 is not None else w[:count]


# ---------------------------------------------------------------------------------------
# §L2 loads: drive, friction, bit, noise
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Drive:
    """Top drive (§L2). ``setpoint_rpm`` and ``motor_torque_Nm`` are piecewise-linear knots
    ((t [s], value), …) held beyond their ends; with ``motor_torque_Nm`` the PI law is off.

    Attributes
    ----------
    inertia_kg_m2 : float
        I_TD [kg·m²].
    kp_Nms_rad, ki_Nm_rad : float
        PI gains k_p [N·m·s/rad], k_i [N·m/rad].
    """

    setpoint_rpm: tuple = ((0.0, 0.0),)
    inertia_kg_m2: float = 2900.0
    kp_Nms_rad: float = 38e3
    ki_Nm_rad: float = 100e3
    motor_torque_Nm: tuple | None = None

    def series(self, t: np.ndarray) -> tuple[int, np.ndarray]:
        """(mode, values at t): mode 0 set-point [rad/s], 1 motor torque [N·m]."""
        if self.motor_torque_Nm is not None:
            pts = np.asarray(self.motor_torque_Nm, dtype=float)
            return 1, np.interp(t, pts[:, 0], pts[:, 1])
        pts = np.asarray(self.setpoint_rpm, dtype=float)
        return 0, np.interp(t, pts[:, 0], pts[:, 1]) * RPM


def setpoint(rpm: float, duration_s: float, *, idle_s: float = 5.0, ramp_s: float = 10.0,
             creep_rpm: float | None = None, creep_ramp_s: float = 5.0,
             creep_hold_s: float = 30.0, stop_s: float = 5.0,
             stop_hold_s: float = 10.0) -> tuple:
    """Set-point knots (t [s], RPM): rest ``idle_s``; then a ramp to ``rpm`` in ``ramp_s``,
    or with ``creep_rpm`` a creep start (0 → creep_rpm in ``creep_ramp_s``, hold
    ``creep_hold_s``, then the ramp); held until ``idle_s + duration_s``; stopped in
    ``stop_s`` and held at 0 for ``stop_hold_s`` (no stop when both are 0)."""
    t = idle_s
    pts = [(0.0, 0.0), (t, 0.0)]
    if creep_rpm is not None:
        pts += [(t + creep_ramp_s, creep_rpm), (t + creep_ramp_s + creep_hold_s, creep_rpm)]
        t += creep_ramp_s + creep_hold_s
    pts += [(t + ramp_s, rpm), (idle_s + duration_s, rpm)]
    if stop_s > 0 or stop_hold_s > 0:
        pts += [(idle_s + duration_s + stop_s, 0.0),
                (idle_s + duration_s + stop_s + stop_hold_s, 0.0)]
    return tuple(pts)


@dataclass(frozen=True)
class Friction:
    """Wall friction and damping (§L2).

    Attributes
    ----------
    mu_s, mu_k : float
        Static and kinetic friction factors [-], μ_k ≤ μ_s.
    omega_switch_rad_s : float
        Karnopp band ω_sw [rad/s].
    material_loss_s : float
        η [s]: segment dashpot c_j = η k_j.
    viscous_rate_per_s : float
        κ [1/s]: drag d_i = κ I_i (mass-proportional, like a k_t).
    hole_damping_Nms_m : float
        χ [N·m·s/rad per m of string]: drag d_i += χ ℓ_i.
    """

    mu_s: float
    mu_k: float
    omega_switch_rad_s: float = 1.0
    material_loss_s: float = 2e-4
    viscous_rate_per_s: float = 0.1
    hole_damping_Nms_m: float = 0.0

    def __post_init__(self):
        if not 0 <= self.mu_k <= self.mu_s:
            raise ValueError(f"need 0 ≤ μ_k ≤ μ_s, got {self.mu_k}, {self.mu_s}")


@dataclass(frozen=True)
class Bit:
    """Bit: off bottom (``wob_N`` = 0, free) or a Coulomb torque μ_bit·WOB·(2/3)·R_bit."""

    wob_N: float = 0.0
    mu_bit: float = 0.3
    diameter_m: float = 0.2159

    @property
    def torque_Nm(self) -> float:
        """T_bit [N·m]."""
        return self.mu_bit * self.wob_N * (2.0 / 3.0) * 0.5 * self.diameter_m


@dataclass(frozen=True)
class Motor:
    """A mud motor (§L6): ``rev_per_litre`` k [rev/L], ``flow_m3_s`` Q [m³/s],
    ``stall_torque_Nm`` τ_stall [N·m] (None: no drop under load)."""

    rev_per_litre: float
    flow_m3_s: float
    stall_torque_Nm: float | None = None

    def speed_rad_s(self, bit_torque_Nm: float) -> float:
        """The motor's speed relative to its housing at a bit torque [rad/s] (§L6)."""
        no_load = 2.0 * np.pi * self.rev_per_litre * 1000.0 * self.flow_m3_s
        if self.stall_torque_Nm is None:
            return no_load
        return no_load * max(0.0, 1.0 - bit_torque_Nm / self.stall_torque_Nm)


@dataclass(frozen=True)
class Noise:
    """Seeded sensor errors on the recorded surface channels (not on ``bit_rpm``)."""

    rpm_sd: float = 0.0
    torque_sd_Nm: float = 0.0
    hookload_sd_N: float = 0.0
    rpm_step: float = 0.0
    torque_step_Nm: float = 0.0
    seed: int = 0

    def apply(self, cols: dict) -> None:
        """Add noise, then quantise, in place."""
        rng = np.random.default_rng(self.seed)
        for name, sd, step in (("surface_rpm", self.rpm_sd, self.rpm_step),
                               ("surface_torque_Nm", self.torque_sd_Nm, self.torque_step_Nm),
                               ("motor_torque_Nm", self.torque_sd_Nm, self.torque_step_Nm),
                               ("hookload_N", self.hookload_sd_N, 0.0)):
            x = cols[name]
            if sd > 0:
                x = x + rng.normal(0.0, sd, x.size)
            if step > 0:
                x = np.round(x / step) * step
            cols[name] = x


# ---------------------------------------------------------------------------------------
# §L3 integrator: one time loop, compiled and NumPy twins with the same arithmetic
# ---------------------------------------------------------------------------------------
#: Columns of the kernel's record array.
REC = ("omega0", "tau1", "tau_m", "omega_bit", "kinetic", "spring", "work_motor",
       "diss_viscous", "diss_friction", "sweeps")


def _run_python(inertia, k, c, d, cap_s, cap_k, omega_sw, kp, ki, mode, series, dt, theta,
                tol, max_sweeps, v, phi, integ, n_steps, rec_every, out):
    """Plain NumPy twin of the compiled kernel (§L3): whole-colour array updates, a Python
    loop over time. Same arguments; ``v``, ``phi`` are updated in place; returns the PI
    integral at the end."""
    n = v.size - 1
    a = dt * theta * c + dt * dt * theta * theta * k          # a[0] = 0
    diag = inertia + dt * theta * d
    diag[:-1] += a[1:]
    diag[1:] += a[1:]
    if mode == 0:
        diag[0] += dt * kp
    ev = np.arange(0, n + 1, 2)
    od = np.arange(1, n + 1, 2)
    wm = dv = df = 0.0
    kin = 0.5 * np.sum(inertia * v * v)
    spr = 0.5 * np.sum(k * phi * phi)
    _record(out, 0, v, phi, k, c, 0.0, kin, spr, wm, dv, df, 0.0)
    for step in range(n_steps):
        s_new = series[step + 1]
        dw = np.zeros(n + 1)
        dw[1:] = v[:-1] - v[1:]
        e = k * phi + (dt * theta * (1 - theta) * k + (1 - theta) * c) * dw
        b = inertia * v - dt * (1 - theta) * d * v
        b[:-1] -= dt * e[1:]
        b[1:] += dt * e[1:]
        if mode == 0:
            b[0] += dt * (kp * s_new + ki * integ)
        else:
            b[0] += dt * (theta * s_new + (1 - theta) * series[step])
        lim = dt * np.where(np.abs(v) < omega_sw, cap_s, cap_k)
        w = v.copy()
        sweeps = 0
        while sweeps < max_sweeps:
            sweeps += 1
            change = 0.0
            for idx in (ev, od):
                r = b[idx].copy()
                left = idx >= 1
                r[left] = r[left] + a[idx[left]] * w[idx[left] - 1]
                right = idx < n
                r[right] = r[right] + a[idx[right] + 1] * w[idx[right] + 1]
                new = np.sign(r) * np.maximum(np.abs(r) - lim[idx], 0.0) / diag[idx]
                change = max(change, float(np.max(np.abs(new - w[idx]))))
                w[idx] = new
            if change <= tol:
                break
        # friction impulse p = b − A w (the residual of the converged system)
        aw = diag * w
        aw[:-1] -= a[1:] * w[1:]
        aw[1:] -= a[1:] * w[:-1]
        p = b - aw
        vbar = 0.5 * (v + w)
        dwn = np.zeros(n + 1)
        dwn[1:] = w[:-1] - w[1:]
        phi += dt * (theta * dwn + (1 - theta) * dw)
        if mode == 0:
            tau_m = kp * (s_new - w[0]) + ki * integ
            integ += dt * (s_new - w[0])
        else:
            tau_m = theta * s_new + (1 - theta) * series[step]
        wm += dt * tau_m * vbar[0]
        dwbar = np.zeros(n + 1)
        dwbar[1:] = vbar[:-1] - vbar[1:]
        dv += dt * (np.sum(d * vbar * (theta * w + (1 - theta) * v))
                    + np.sum(c * dwbar * (theta * dwn + (1 - theta) * dw)))
        df += float(np.sum(p * vbar))
        v[:] = w
        if (step + 1) % rec_every == 0:
            kin = 0.5 * np.sum(inertia * v * v)
            spr = 0.5 * np.sum(k * phi * phi)
            _record(out, (step + 1) // rec_every, v, phi, k, c, tau_m, kin, spr, wm, dv,
                       df, sweeps)
    return integ


def _record(out, row, v, phi, k, c, tau_m, kin, spr, wm, dv, df, sweeps):
    """Row ``row`` of the record array (:data:`REC`): both kernels write it (compiled for
    the numba one, :data:`_record_nb`)."""
    out[row, 0] = v[0]
    out[row, 1] = k[1] * phi[1] + c[1] * (v[0] - v[1])
    out[row, 2] = tau_m
    out[row, 3] = v[v.size - 1]
    out[row, 4] = kin
    out[row, 5] = spr
    out[row, 6] = wm
    out[row, 7] = dv
    out[row, 8] = df
    out[row, 9] = sweeps


def _run_loops(inertia, k, c, d, cap_s, cap_k, omega_sw, kp, ki, mode, series, dt, theta,
               tol, max_sweeps, v, phi, integ, n_steps, rec_every, out):
    """The compiled kernel (§L3): the twin's arithmetic written as scalar loops."""
    n = v.size - 1
    a = np.empty(n + 1)
    diag = np.empty(n + 1)
    for i in range(n + 1):
        a[i] = dt * theta * c[i] + dt * dt * theta * theta * k[i]
    for i in range(n + 1):
        diag[i] = inertia[i] + dt * theta * d[i]
    for j in range(1, n + 1):
        diag[j - 1] += a[j]
        diag[j] += a[j]
    if mode == 0:
        diag[0] += dt * kp
    b = np.empty(n + 1)
    lim = np.empty(n + 1)
    w = np.empty(n + 1)
    dw = np.zeros(n + 1)
    dwn = np.zeros(n + 1)
    wm = 0.0
    dv = 0.0
    df = 0.0
    kin = 0.0
    spr = 0.0
    for i in range(n + 1):
        kin += 0.5 * inertia[i] * v[i] * v[i]
        spr += 0.5 * k[i] * phi[i] * phi[i]
    _record_nb(out, 0, v, phi, k, c, 0.0, kin, spr, wm, dv, df, 0.0)
    tau_m = 0.0
    for step in range(n_steps):
        s_new = series[step + 1]
        for i in range(n + 1):
            b[i] = inertia[i] * v[i] - dt * (1 - theta) * d[i] * v[i]
        for j in range(1, n + 1):
            dw[j] = v[j - 1] - v[j]
            e = k[j] * phi[j] + (dt * theta * (1 - theta) * k[j] + (1 - theta) * c[j]) * dw[j]
            b[j - 1] -= dt * e
            b[j] += dt * e
        if mode == 0:
            b[0] += dt * (kp * s_new + ki * integ)
        else:
            b[0] += dt * (theta * s_new + (1 - theta) * series[step])
        for i in range(n + 1):
            lim[i] = dt * (cap_s[i] if abs(v[i]) < omega_sw else cap_k[i])
            w[i] = v[i]
        sweeps = 0
        while sweeps < max_sweeps:
            sweeps += 1
            change = 0.0
            for parity in range(2):
                for i in range(parity, n + 1, 2):
                    r = b[i]
                    if i >= 1:
                        r = r + a[i] * w[i - 1]
                    if i < n:
                        r = r + a[i + 1] * w[i + 1]
                    mag = abs(r) - lim[i]
                    if mag < 0.0:
                        mag = 0.0
                    sgn = 1.0 if r > 0 else (-1.0 if r < 0 else 0.0)
                    new = sgn * mag / diag[i]
                    delta = abs(new - w[i])
                    if delta > change:
                        change = delta
                    w[i] = new
            if change <= tol:
                break
        pv = 0.0
        visc = 0.0
        for i in range(n + 1):
            aw = diag[i] * w[i]
            if i >= 1:
                aw -= a[i] * w[i - 1]
            if i < n:
                aw -= a[i + 1] * w[i + 1]
            vbar = 0.5 * (v[i] + w[i])
            pv += (b[i] - aw) * vbar
            visc += d[i] * vbar * (theta * w[i] + (1 - theta) * v[i])
        for j in range(1, n + 1):
            dwn[j] = w[j - 1] - w[j]
            phi[j] += dt * (theta * dwn[j] + (1 - theta) * dw[j])
            dwbar = 0.5 * (dw[j] + dwn[j])
            visc += c[j] * dwbar * (theta * dwn[j] + (1 - theta) * dw[j])
        if mode == 0:
            tau_m = kp * (s_new - w[0]) + ki * integ
            integ += dt * (s_new - w[0])
        else:
            tau_m = theta * s_new + (1 - theta) * series[step]
        wm += dt * tau_m * 0.5 * (v[0] + w[0])
        dv += dt * visc
        df += pv
        for i in range(n + 1):
            v[i] = w[i]
        if (step + 1) % rec_every == 0:
            kin = 0.0
            spr = 0.0
            for i in range(n + 1):
                kin += 0.5 * inertia[i] * v[i] * v[i]
                spr += 0.5 * k[i] * phi[i] * phi[i]
            _record_nb(out, (step + 1) // rec_every, v, phi, k, c, tau_m, kin, spr, wm, dv,
                       df, float(sweeps))
    return integ


if njit is not None:
    _record_nb = njit(cache=False)(_record)
    run_numba = njit(cache=False)(_run_loops)
else:  # pragma: no cover
    _record_nb = _record
    run_numba = None
run_numpy = _run_python


# ---------------------------------------------------------------------------------------
# §L4 simulate
# ---------------------------------------------------------------------------------------
@dataclass
class Record:
    """Result of :func:`simulate`: ``columns`` (the log, §L4), ``energy`` (cumulative terms
    of §L3 at the record times: kinetic, spring, work_motor, diss_viscous, diss_friction
    [J]), the mean projected-Gauss–Seidel sweeps per step and the string."""

    columns: dict
    energy: dict
    string: LumpedString
    mean_sweeps: float
    info: dict = field(default_factory=dict)


def node_arrays(string: LumpedString, drive: Drive, friction: Friction, bit: Bit):
    """(inertia, k, c, d, cap_s, cap_k) over nodes 0…N as the kernel takes them (§L2)."""
    inertia = string.inertia_kg_m2.copy()
    d = friction.viscous_rate_per_s * inertia + friction.hole_damping_Nms_m * string.length_m
    inertia[0] += drive.inertia_kg_m2
    k = string.stiffness_Nm_rad.copy()
    c = friction.material_loss_s * k
    cap_s = friction.mu_s * string.capacity_Nm
    cap_k = friction.mu_k * string.capacity_Nm
    cap_s[-1] += bit.torque_Nm
    cap_k[-1] += bit.torque_Nm
    cap_s[0] = cap_k[0] = 0.0
    return inertia, k, c, d, cap_s, cap_k


def simulate(string: LumpedString, drive: Drive, friction: Friction, duration_s: float, *,
             rate_hz: float = 100.0, dt_s: float = 1e-3, bit: Bit | None = None,
             noise: Noise | None = None, off_bottom_m: float = 5.0, theta: float = 0.5,
             tol_rad_s: float = 1e-10, max_sweeps: int = 500, kernel: str = "numba",
             initial_speed_rad_s: np.ndarray | None = None,
             initial_twist_rad: np.ndarray | None = None,
             motor: Motor | None = None) -> Record:
    """Run the plant from rest (or a given state) for ``duration_s`` and log it (§L3–§L4).

    Parameters
    ----------
    rate_hz : float
        Logging rate [Hz]; 1/(rate·dt) must be a whole number of steps.
    dt_s : float
        Time step Δt [s].
    kernel : str
        "numba" (compiled) or "numpy" (the twin: slow, for tests).
    initial_speed_rad_s, initial_twist_rad : ndarray, optional
        ω over nodes 0…N [rad/s], φ over segments (index 0 unused) [rad].
    motor : Motor, optional
        A mud motor below the string, pumped throughout (§L6).
    """
    bit = bit or Bit()
    every = int(round(1.0 / (rate_hz * dt_s)))
    if every < 1 or abs(every * rate_hz * dt_s - 1.0) > 1e-9:
        raise ValueError("1/rate must be a whole number of time steps")
    n_steps = int(round(duration_s / dt_s))
    n_steps -= n_steps % every
    t = np.arange(n_steps + 1) * dt_s
    mode, series = drive.series(t)
    inertia, k, c, d, cap_s, cap_k = node_arrays(string, drive, friction, bit)
    n = string.n_elements
    v = np.zeros(n + 1) if initial_speed_rad_s is None else \
        np.array(initial_speed_rad_s, dtype=float)
    phi = np.zeros(n + 1) if initial_twist_rad is None else \
        np.array(initial_twist_rad, dtype=float)
    out = np.zeros((n_steps // every + 1, len(REC)))
    fn = run_numba if kernel == "numba" and run_numba is not None else run_numpy
    fn(inertia, k, c, d, cap_s, cap_k, float(friction.omega_switch_rad_s),
       float(drive.kp_Nms_rad), float(drive.ki_Nm_rad), int(mode), series, float(dt_s),
       float(theta), float(tol_rad_s), int(max_sweeps), v, phi, 0.0, int(n_steps), every, out)
    rows = out.shape[0]
    wob = bit.wob_N
    depth = np.full(rows, string.bit_depth_m)
    cols = {"time_s": np.arange(rows) * every * dt_s,
            "surface_rpm": out[:, 0] / RPM,
            "surface_torque_Nm": out[:, 1].copy(),
            "motor_torque_Nm": out[:, 2].copy(),
            "bit_rpm": out[:, 3] / RPM,
            "hookload_N": np.full(rows, string.hookload_N - wob),
            "bit_depth_m": depth,
            "hole_depth_m": depth + (0.0 if wob > 0 else off_bottom_m),
            "wob_N": np.full(rows, wob)}
    if motor is not None:
        cols["flow_in_m3_s"] = np.full(rows, motor.flow_m3_s)
        cols["bha_rpm"] = cols["bit_rpm"]
        cols["bit_rpm"] = cols["bha_rpm"] + motor.speed_rad_s(bit.torque_Nm) / RPM
    if noise is not None:
        noise.apply(cols)
    energy = {name: out[:, i].copy() for i, name in enumerate(REC[4:9], start=4)}
    return Record(cols, energy, string, float(np.mean(out[1:, 9])) if rows > 1 else 0.0,
                  {"dt_s": dt_s, "n_steps": n_steps, "T_N_Nm": string.T_N_Nm,
                   "bit_torque_Nm": bit.torque_Nm})


def severity(bit_rpm: np.ndarray) -> float:
    """Stick-slip severity max(ω_bit)/mean(ω_bit) over the given (steady) samples [-]."""
    mean = float(np.mean(bit_rpm))
    return float(np.max(bit_rpm) / mean) if mean > 0 else float("inf")
