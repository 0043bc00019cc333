"""Observer gains: the closed-form backstepping design and a steady-state Kalman design.

docs/theory.md §5.1. The adaptive observer of Aarsnes et al. (2019) [1], Section 4, eqs.
(32)–(43), corrects a copy of the torsional model with the top-drive speed innovation
e = ω̂₀ − ω₀ at fixed injection points: the top-drive ODE (p₀), the top boundary (P₀),
the pipe invariants (p_α(x), p_β(x)), the pipe/BHA junction (P₁), the BHA speed (p₁) and
the friction adaptation (l_k, l_s). The paper does not print its gains; the closed form
here was derived for drillfric on the semi-lumped model of docs/theory.md §4
(:mod:`drillfric.estimation.lumped`) and is checked against the exact characteristic function N(s)
by ``tests/test_gains.py``. The Kalman alternative solves the discrete algebraic Riccati
equation on the Courant-1 discretisation of the same model and maps the gain back onto
the same injection points (see docs/observer_gains.md).

[1] U.J.F. Aarsnes, J. Auriol, F. Di Meglio, R.J. Shor, "Estimating friction factors while
    drilling", J. Petroleum Science and Engineering 179 (2019) 80–91.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
import scipy.linalg

from drillfric.config import default
from drillfric.drillstring import DrillString
from drillfric.errors import ModelError
from drillfric.estimation import lumped
from drillfric.estimation.lumped import Injection, LumpedParams
from drillfric.units import RPM_TO_RAD_S

if TYPE_CHECKING:
    from drillfric.config import Config


@dataclass(frozen=True)
class Tuning:
    """Tuning of the backstepping design (docs/theory.md §5.1).

    Attributes
    ----------
    kappa1 : float
        Fraction κ₁ ∈ (0, 2) of the top-side reflection cancelled [–].
    lambda0_per_s : float
        Bandwidth λ₀ of the top-drive injection [1/s]; keep λ₀ ≳ 5·max(z, p).
    z_per_s, p_per_s : float
        The two poles placed for the downhole error (ω_L, d) [1/s].
    """

    kappa1: float = default("observer.kappa1")
    lambda0_per_s: float = default("observer.lambda0_per_s")
    z_per_s: float = default("observer.poles_per_s")[0]
    p_per_s: float = default("observer.poles_per_s")[1]

    def __post_init__(self):
        if not 0.0 < self.kappa1 < 2.0:
            raise ModelError(f"observer κ₁ must be in (0, 2), got {self.kappa1}",
                             fix="set observer.kappa1 (1.0 cancels the top reflection)")
        for name in ("lambda0_per_s", "z_per_s", "p_per_s"):
            value = getattr(self, name)
            if not np.isfinite(value) or value <= 0:
                raise ModelError(f"observer tuning {name} must be positive, got {value}",
                                 fix="set observer.lambda0_per_s / observer.poles_per_s")


@dataclass(frozen=True)
class Gains:
    """Output-injection and adaptation gains of the observer (docs/theory.md §5, eqs. (32)–(43)).

    Sign convention (e = ω̂₀ − ω₀ [rad/s], per observer step Δt): ω̂₀ += −Δt p₀ e;
    α̂_j += −Δt p_α(x_j) e and β̂_j += −Δt p_β(x_j) e on the pipe cells; both BHA invariants
    += −Δt p₁ e; α̂(0) = 2ω̂₀ − β̂(0) − P₀ e; β̂ reflected at the pipe/BHA junction −= P₁ e;
    dμ̂_k/dt = +l_k e (sliding) and dμ̂_s/dt = −l_s e (stuck), as printed in eqs. (42)–(43).
    With d̂ = μ̂·T_N the lumped law is dd̂/dt = −p_d e, i.e. l_k = −p_d/T_N.

    Attributes
    ----------
    x_m : numpy.ndarray
        Pipe positions where p_alpha, p_beta are given (cell centres) [m].
    p0 : float
        Top-drive injection [1/s].
    P0 : float
        Top boundary injection [–].
    p_alpha, p_beta : numpy.ndarray
        Distributed injections on the pipe at ``x_m`` [1/s].
    P1 : float
        Junction injection [–].
    p1 : float
        BHA speed injection [1/s].
    p_d : float
        Lumped friction-torque injection [N·m/(rad/s)/s].
    l_k, l_s : float
        Friction-factor adaptation gains [1/(rad/s)/s] = [1/rad].
    design : str
        "backstepping" or "kalman".
    """

    x_m: np.ndarray
    p0: float
    P0: float
    p_alpha: np.ndarray
    p_beta: np.ndarray
    P1: float
    p1: float
    p_d: float
    l_k: float
    l_s: float
    design: str


@dataclass(frozen=True)
class KalmanNoise:
    """Noise intensities of the Kalman design, continuous-time (docs/theory.md §5.1).

    They are tuning knobs, not measured statistics: only their ratios matter for the gain.
    Discretised as Q = q·Δt, R = r/Δt, so the gains converge as the grid is refined. The
    defaults put the friction-torque injection p_d at the level of the default
    backstepping tuning on an A&S-like 2500 m string (docs/observer_gains.md).

    Attributes
    ----------
    speed_psd : float
        Measurement noise on ω₀ [(rad/s)²·s]; 0.5 RPM white noise at 100 Hz is 2.7e-5.
    friction_psd : float
        Random-walk intensity of the lumped friction torque d [(N·m)²/s].
    string_psd : float
        Distributed torque noise along the pipe (unmodelled friction), as a speed-rate
        intensity on both invariants, white in time and along the pipe [(rad/s)²·m/s].
    motor_psd, bha_psd : float
        Speed-rate noise on the top drive and on the BHA [(rad/s)²/s].
    """

    speed_psd: float = 2.7e-5
    friction_psd: float = 1.5e3
    string_psd: float = 1.0e-1
    motor_psd: float = 1.0e-3
    bha_psd: float = 1.0e-1


def _validate(x_m, T_N_Nm: float) -> np.ndarray:
    x = np.asarray(x_m, dtype=float)
    if x.ndim != 1 or x.size == 0 or not np.all(np.isfinite(x)) or np.any(x < 0):
        raise ModelError("observer gain positions must be a non-empty 1-D array of depths ≥ 0 m")
    if not np.isfinite(T_N_Nm) or T_N_Nm <= 0:
        raise ModelError(f"the Coulomb torque capacity T_N = ∫F_c dx is {T_N_Nm} N·m: friction "
                         "does not act on the torque here, so it cannot be estimated",
                         fix="skip this stand (vertical hole) or check the survey and string")
    return x


def _p_beta(params: LumpedParams, tuning: Tuning, x: np.ndarray) -> np.ndarray:
    """p_β(x) of docs/theory.md §5.1 [1/s] (closed-form backstepping kernel)."""
    aL, a1, a2 = params.aL_per_s, tuning.z_per_s + tuning.p_per_s, tuning.z_per_s * tuning.p_per_s
    g = tuning.lambda0_per_s / params.a0_per_s
    decay = np.exp(-aL * x / params.c_m_s)
    # 2g[l₁ E − (l₂/(a_L I_BHA))(1 − E)] with l₁ = (a₁ − a_L)/2, l₂ = −a₂ I_BHA/2
    return g * ((a1 - aL) * decay + (a2 / aL) * (1.0 - decay))


def backstepping_gains(params: LumpedParams, tuning: Tuning, x_m, T_N_Nm: float) -> Gains:
    """Closed-form backstepping gains of docs/theory.md §5.1.

    Parameters
    ----------
    params : LumpedParams
        Semi-lumped model of the string (docs/theory.md §4).
    tuning : Tuning
        κ₁, λ₀, z, p.
    x_m : array_like
        Pipe cell centres where p_α, p_β are wanted, in [0, L_p] [m].
    T_N_Nm : float
        Coulomb torque capacity T_N = ∫₀^L F_c dx [N·m] (> 0).

    Returns
    -------
    Gains
        p₀ = λ₀ − a₀, P₀ = 2 − κ₁λ₀/a₀, p_α ≡ 0, p_β(x), P₁ = 0, p₁ = p_β(L_p)/2,
        p_d = −(λ₀/a₀)·a₂·I_BHA/2, l_k = −p_d/T_N, l_s = 2 l_k.
    """
    x = _validate(x_m, T_N_Nm)
    g = tuning.lambda0_per_s / params.a0_per_s
    p_d = -g * tuning.z_per_s * tuning.p_per_s * params.I_BHA_kg_m2 / 2.0
    l_k = -p_d / T_N_Nm
    return Gains(x_m=x, p0=tuning.lambda0_per_s - params.a0_per_s,
                 P0=2.0 - tuning.kappa1 * g, p_alpha=np.zeros_like(x),
                 p_beta=_p_beta(params, tuning, x), P1=0.0,
                 p1=float(_p_beta(params, tuning, np.array([params.Lp_m]))[0]) / 2.0,
                 p_d=p_d, l_k=l_k, l_s=2.0 * l_k, design="backstepping")


def characteristic_N(s, params: LumpedParams, tuning: Tuning):
    """Characteristic function N(s) of the linear error system (docs/theory.md §5.1).

    N(s) = s²(s + a_L) + λ₀(s² + a₁s + a₂) + e^{−2 s t_D}·s·(a_L − s)(s + (1 − κ₁)λ₀),
    a₁ = z + p, a₂ = z·p. Its roots are the error system's eigenvalues [1/s].

    Examples
    --------
    >>> p = LumpedParams(0.2, 3.0, 2800.0, 2000.0, 2900.0, 160.0, 500.0)
    >>> complex(characteristic_N(0.0, p, Tuning()))  # λ₀·a₂ = 10 × 1.5
    (15+0j)
    """
    s = np.asarray(s, dtype=complex)
    lam, k1, aL = tuning.lambda0_per_s, tuning.kappa1, params.aL_per_s
    a1, a2 = tuning.z_per_s + tuning.p_per_s, tuning.z_per_s * tuning.p_per_s
    delay = np.exp(-2.0 * s * params.t_D_s)
    return (s**2 * (s + aL) + lam * (s**2 + a1 * s + a2)
            + delay * s * (aL - s) * (s + (1.0 - k1) * lam))


def characteristic_dN(s, params: LumpedParams, tuning: Tuning):
    """Derivative dN/ds of :func:`characteristic_N` (for Newton refinement of its roots)."""
    s = np.asarray(s, dtype=complex)
    lam, k1, aL, tD = tuning.lambda0_per_s, tuning.kappa1, params.aL_per_s, params.t_D_s
    a1 = tuning.z_per_s + tuning.p_per_s
    b = (1.0 - k1) * lam
    delay = np.exp(-2.0 * s * tD)
    poly = s * (aL - s) * (s + b)            # = −s³ + (aL − b)s² + aL·b·s
    dpoly = -3.0 * s**2 + 2.0 * (aL - b) * s + aL * b
    return 3.0 * s**2 + 2.0 * aL * s + lam * (2.0 * s + a1) + delay * (dpoly - 2.0 * tD * poly)


def top_reflection(s, tuning: Tuning):
    """Top-drive reflection of the error waves R(s) = −(s + (1 − κ₁)λ₀)/(s + λ₀) (§5.1)."""
    s = np.asarray(s, dtype=complex)
    lam = tuning.lambda0_per_s
    return -(s + (1.0 - tuning.kappa1) * lam) / (s + lam)


def injection_on_nodes(gains: Gains, params: LumpedParams, n_cells: int) -> Injection:
    """Gains resampled (linear interpolation) onto the n + 1 nodes of
    :mod:`drillfric.estimation.lumped`."""
    x = lumped.nodes_m(params, n_cells)
    return Injection(p0=gains.p0, P0=gains.P0, p_alpha=np.interp(x, gains.x_m, gains.p_alpha),
                     p_beta=np.interp(x, gains.x_m, gains.p_beta), P1=gains.P1, p1=gains.p1,
                     p_d=gains.p_d)


def error_system(params: LumpedParams, design: Tuning | Gains,
                 n_cells: int) -> tuple[np.ndarray, float]:
    """Discrete linear error system observer − plant of docs/theory.md §4 (lumped friction).

    Parameters
    ----------
    params : LumpedParams
    design : Tuning or Gains
        A tuning (backstepping gains evaluated exactly on the nodes) or any gains (resampled).
    n_cells : int
        Pipe cells; Δt = t_D/n (Courant 1, exact delay line).

    Returns
    -------
    A : numpy.ndarray
        (2n + 3)² transition matrix of the error [ω̃₀, α̃₁…α̃_n, β̃₀…β̃_{n−1}, ω̃_L, d̃].
    dt : float
        Its time step [s]; eigenvalues λ map to s = log(λ)/dt.
    """
    if isinstance(design, Tuning):
        # T_N only scales l_k; the error dynamics of d use p_d
        design = backstepping_gains(params, design, lumped.nodes_m(params, n_cells), 1.0)
    inj = injection_on_nodes(design, params, n_cells)
    return lumped.transition_matrix(params, inj), lumped.time_step_s(params, n_cells)


def _process_noise(params: LumpedParams, n: int, noise: KalmanNoise) -> np.ndarray:
    """Discrete process covariance Q = q·Δt of the Kalman design, state d scaled by 1/I_BHA."""
    h, dx = lumped.time_step_s(params, n), params.Lp_m / n
    q = np.zeros((lumped.state_size(n), lumped.state_size(n)))
    q[0, 0] = noise.motor_psd * h
    var = noise.string_psd * h / dx                  # a torque noise moves α and β alike
    alpha = np.arange(1, n)                          # interior nodes carry both invariants
    beta = n + 1 + alpha
    for i, j in ((alpha, alpha), (beta, beta), (alpha, beta), (beta, alpha)):
        q[i, j] += var
    q[n, n] += var                                   # α_n (BHA end), β₀ (top end)
    q[n + 1, n + 1] += var
    q[2 * n + 1, 2 * n + 1] = noise.bha_psd * h
    q[2 * n + 2, 2 * n + 2] = noise.friction_psd * h / params.I_BHA_kg_m2**2
    return q


def _observable_part(a: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Reduction that removes the unobservable unit-circle modes before the Riccati solve.

    The Courant-1 grid carries an exact mode at λ = −1: a node-to-node alternating torque with
    zero speed at every node (ω₀ = ω_L = 0). No damping acting on nodal speeds touches it and
    ω₀ never sees it, so the Riccati equation has no stabilising solution on the full state.
    With V its right and W its left (real) eigenvectors, the subspace {z : Wᵀz = 0} is
    A-invariant; U is an orthonormal basis of it and R = Uᵀ(I − V(WᵀV)⁻¹Wᵀ) the projection
    along V onto it (z_r = R z). The gain designed there leaves the mode at λ = −1.

    Returns
    -------
    U, R : numpy.ndarray
        Basis (N × N_r) and reduction map (N_r × N); identities when nothing is removed.
    """
    lam, right = np.linalg.eig(a)
    lam_left, left = np.linalg.eig(a.T)
    vs, ws = [], []
    for k in np.flatnonzero((np.abs(lam) > 1.0 - 1e-9) & (lam.imag >= 0)):
        if abs((c @ right[:, k])[0]) < 1e-9 * np.linalg.norm(right[:, k]):
            w = left[:, np.argmin(np.abs(lam_left - lam[k]))]
            parts = (0,) if abs(lam[k].imag) < 1e-12 else (0, 1)
            vs += [(right[:, k].real, right[:, k].imag)[i] for i in parts]
            ws += [(w.real, w.imag)[i] for i in parts]
    if not vs:
        return np.eye(a.shape[0]), np.eye(a.shape[0])
    v, w = np.array(vs).T, np.array(ws).T
    basis = scipy.linalg.null_space(w.T)
    oblique = np.eye(a.shape[0]) - v @ np.linalg.solve(w.T @ v, w.T)
    return basis, basis.T @ oblique


def kalman_filter_gain(params: LumpedParams, n_cells: int,
                       noise: KalmanNoise = KalmanNoise()) -> np.ndarray:
    """Steady-state predictor gain L of the Courant-1 lumped model (docs/theory.md §5.1).

    ẑ_{k+1} = A ẑ_k + B u_k − L (C ẑ_k − y_k), L = A P Cᵀ (C P Cᵀ + R)⁻¹ with P the
    stabilising solution of the discrete algebraic Riccati equation
    (:func:`scipy.linalg.solve_discrete_are`), solved on the invariant subspace that
    excludes the grid's unobservable λ = −1 mode (:func:`_observable_part`). Returned in the
    state units of :mod:`drillfric.estimation.lumped` (the d row in N·m per rad/s).
    """
    a = lumped.transition_matrix(params, Injection.none(n_cells))
    scale = np.ones(lumped.state_size(n_cells))
    scale[-1] = 1.0 / params.I_BHA_kg_m2             # design in δ = d/I_BHA (conditioning)
    a = a * scale[:, None] / scale[None, :]
    c = lumped.output_matrix(n_cells)
    basis, reduce = _observable_part(a, c)
    a_r, c_r = basis.T @ a @ basis, c @ basis
    q_r = reduce @ _process_noise(params, n_cells, noise) @ reduce.T
    r = np.array([[noise.speed_psd / lumped.time_step_s(params, n_cells)]])
    try:
        p = scipy.linalg.solve_discrete_are(a_r.T, c_r.T, q_r, r)
    except (np.linalg.LinAlgError, ValueError) as exc:  # e.g. k_t so high no wave survives
        raise ModelError(f"the observer's Kalman gains have no finite solution ({exc}) for "
                         f"this string and damping (k_t = {params.k_t_per_s:g} 1/s)",
                         fix="check [model] k_t_per_s (typical 0.01–10 1/s) and the string "
                             "sections") from None
    gain = basis @ (a_r @ p @ c_r.T / (c_r @ p @ c_r.T + r))
    return gain[:, 0] / scale


#: Pipe lengths within one band of this width share a Kalman design [m]: stands a few
#: metres apart reuse the design of the band's centre (its gains differ by far less than
#: their own tuning uncertainty: docs/observer_gains.md "Design cache").
DESIGN_BAND_M = 30.0


def _banded(params: LumpedParams) -> LumpedParams:
    """The design parameters with the pipe length moved to its band's centre."""
    centre = (np.floor(params.Lp_m / DESIGN_BAND_M) + 0.5) * DESIGN_BAND_M
    return replace(params, Lp_m=float(centre))


@functools.lru_cache(maxsize=64)
def _kalman_design(params: LumpedParams, n: int,
                   noise: KalmanNoise) -> tuple[np.ndarray, np.ndarray]:
    """Kalman gain per unit time on the design nodes, and the nodes [m] (cached: one dense
    Riccati solve per string, depth band and step; BLAS on one thread — the machine's cores
    go to the kernels and the fleet's workers, and a solve this size gains nothing from more).
    """
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1):
        gain = kalman_filter_gain(params, n, noise) / lumped.time_step_s(params, n)
    nodes = lumped.nodes_m(params, n)
    gain.setflags(write=False)
    nodes.setflags(write=False)
    return gain, nodes


def kalman_gains(params: LumpedParams, x_m, T_N_Nm: float, dt_s: float, *,
                 noise: KalmanNoise = KalmanNoise(), max_design_cells: int = 60) -> Gains:
    """Steady-state Kalman gains mapped onto the observer's injection points (docs/theory.md §5.1).

    The Riccati equation is solved on the Courant-1 model of :mod:`drillfric.estimation.lumped` with
    n = round(t_D/dt_s) pipe cells, capped at ``max_design_cells`` (the noise is scaled
    with the step, so the gain per unit time converges as the grid is refined; the cap
    keeps the dense Riccati solve below a second). Mapping, per unit time: p₀ = L_ω₀/Δt,
    p_α(x_j) = L_α_j/Δt, p_β(x_j) = L_β_j/Δt, p₁ = L_ωL/Δt, p_d = L_d/Δt, and no boundary
    injections (P₀ = P₁ = 0): the Kalman gain is a covariance, distributed along the pipe.

    Parameters
    ----------
    params : LumpedParams
    x_m : array_like
        Pipe cell centres where p_α, p_β are wanted [m].
    T_N_Nm : float
        Coulomb torque capacity T_N = ∫F_c dx [N·m].
    dt_s : float
        Observer time step [s] (sets the design grid).
    noise : KalmanNoise
        Continuous-time noise intensities (tuning).
    max_design_cells : int
        Upper bound on the design grid.
    """
    x = _validate(x_m, T_N_Nm)
    if not np.isfinite(dt_s) or dt_s <= 0:
        raise ModelError(f"observer time step must be positive, got {dt_s} s")
    n = int(np.clip(round(params.t_D_s / dt_s), 20, max_design_cells))
    gain, nodes = _kalman_design(_banded(params), n, noise)
    p_d = float(gain[2 * n + 2])
    l_k = -p_d / T_N_Nm
    return Gains(x_m=x, p0=float(gain[0]), P0=0.0,
                 p_alpha=np.interp(x, nodes[1:], gain[1:n + 1]),
                 p_beta=np.interp(x, nodes[:-1], gain[n + 1:2 * n + 1]), P1=0.0,
                 p1=float(gain[2 * n + 1]), p_d=p_d, l_k=l_k, l_s=2.0 * l_k, design="kalman")


@dataclass(frozen=True)
class GainSettings:
    """What the configuration sets for the observer's gains (docs/theory.md §5.1), SI;
    derived once per well (:meth:`from_config`).

    Attributes
    ----------
    design : str
        ``"kalman"`` or ``"backstepping"`` (``observer.gains``).
    tuning : Tuning or None
        The backstepping design's tuning (None for the Kalman design).
    speed_noise_rad_s : float
        Standard deviation of the logged speed's noise [rad/s] (``observer.speed_noise_rpm``):
        the Kalman design's measurement noise.
    top_drive_inertia_kg_m2 : float
        I_TD of the design model [kg·m²].
    k_t_per_s : float
        Viscous damping rate of the design model [1/s].
    """

    design: str
    tuning: Tuning | None
    speed_noise_rad_s: float
    top_drive_inertia_kg_m2: float
    k_t_per_s: float

    @classmethod
    def from_config(cls, cfg: Config) -> GainSettings:
        """The gain settings of ``[observer]``, ``[rig]`` and ``[model]``."""
        obs = cfg.observer
        tuning = None if obs.gains == "kalman" else Tuning(
            kappa1=obs.kappa1, lambda0_per_s=obs.lambda0_per_s,
            z_per_s=float(obs.poles_per_s[0]), p_per_s=float(obs.poles_per_s[1]))
        return cls(obs.gains, tuning, obs.speed_noise_rpm * RPM_TO_RAD_S,
                   cfg.rig.top_drive_inertia_kg_m2, cfg.model.k_t_per_s)


def design_gains(settings: GainSettings, string: DrillString, T_N_Nm: float, x_m,
                 dt_s: float, sample_dt_s: float | None = None) -> Gains:
    """Observer gains of the design ``settings`` select (docs/theory.md §5.1).

    Parameters
    ----------
    settings : GainSettings
    string : DrillString
        The string at the current bit depth.
    T_N_Nm : float
        T_N = ∫F_c dx from torque-and-drag at this depth [N·m].
    x_m : array_like
        Pipe cell centres of the observer grid [m].
    dt_s : float
        Observer time step [s].
    sample_dt_s : float, optional
        Logging interval of the measured speed [s]: the Kalman design's measurement-noise
        intensity is σ²·Δt_log with σ = ``settings.speed_noise_rad_s`` (white noise of that
        standard deviation per sample), so slower logs get a gentler injection. Default:
        the 100 Hz value of :class:`KalmanNoise`.
    """
    params = LumpedParams.from_string(string, settings.top_drive_inertia_kg_m2,
                                      k_t_per_s=settings.k_t_per_s)
    if settings.tuning is None:
        noise = KalmanNoise()
        if sample_dt_s is not None:
            noise = KalmanNoise(speed_psd=settings.speed_noise_rad_s**2 * sample_dt_s)
        return kalman_gains(params, x_m, T_N_Nm, dt_s, noise=noise)
    return backstepping_gains(params, settings.tuning, x_m, T_N_Nm)
