"""The adaptive observer of Aarsnes et al. (2019), Section 4 — docs/theory.md §5.

A copy of the distributed torsional model (:mod:`drillfric.torsional`, same grid, same
F_c(x) profile, friction with the current estimates μ̂_s, μ̂_k) corrected by the measured
top-drive speed ω₀ and driven by the measured motor torque τ_m, with the gains of
:mod:`drillfric.estimation.gains`. Several starts (initial guesses) advance together in one kernel
pass; the final state warm-starts the next window.

Measurements arrive at the logging rate (1–100 Hz) while the observer steps at Δt. The
default is linear interpolation between samples (one sample of lag, fine for a batch tool);
``observer.interpolation = "hold"`` reproduces the paper's zero-order hold, which in the
prototype of docs/theory.md §6 already shifted stick/slip timing at 100 Hz.

[1] U.J.F. Aarsnes, J. Auriol, F. Di Meglio, R.J. Shor, "Estimating friction factors while
    drilling", JPSE 179 (2019) 80–91.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
from scipy.signal import lfilter

from drillfric.config import default
from drillfric.errors import InputError, ModelError
from drillfric.estimation.gains import Gains
from drillfric.kernels.observer import LAW_CORRECTED, LAW_PAPER, OBS_COLUMNS
from drillfric.torsional import Plant, State

_LAWS = {"corrected": LAW_CORRECTED, "paper": LAW_PAPER}


@dataclass(frozen=True)
class Observer:
    """A configured observer for one string at one bit depth.

    Attributes
    ----------
    plant : Plant
        Grid, F_c profile, ω_c, k_t, I_TD and bit boundary of the model copy (its μ values
        are not used: the observer carries its own estimates).
    gains : Gains
        Injection and adaptation gains on the pipe cells of ``plant.grid``.
    law : str
        "corrected" (μ̂_s held, docs/theory.md §6.1) or "paper" (eqs. 42–43 as printed).
    mu_max : float
        Physical clamp on the estimates [-].
    deadlock_s : float
        Guard time: estimated BHA stuck this long while the top drive turns [s].
    hold : bool
        Zero-order hold of the measurements (the paper) instead of linear interpolation.
    """

    plant: Plant
    gains: Gains
    law: str = "corrected"
    mu_max: float = default("observer.mu_max")
    deadlock_s: float = 15.0
    hold: bool = False

    def __post_init__(self):
        if self.law not in _LAWS:
            raise ModelError(f"unknown observer law '{self.law}'", fix="use corrected or paper")
        n_pipe = int(self.plant.grid.section_start[1])
        if self.gains.p_beta.shape != (n_pipe,) or self.gains.p_alpha.shape != (n_pipe,):
            raise ModelError("observer gains must be given on the pipe cells of the grid")

    @property
    def injections(self) -> tuple[np.ndarray, np.ndarray]:
        """Per-cell injection of e into α̂ and β̂ per step, Δt·(p_α, p_β) on the pipe and
        Δt·p₁ on the BHA (eqs. 33–36 of [1]) [-]."""
        g = self.plant.grid
        n_pipe = int(g.section_start[1])
        inj_a = np.full(g.n_cells, self.gains.p1 * g.dt_s)
        inj_b = inj_a.copy()
        inj_a[:n_pipe] = self.gains.p_alpha * g.dt_s
        inj_b[:n_pipe] = self.gains.p_beta * g.dt_s
        return inj_a, inj_b

    @property
    def omega_turn_rad_s(self) -> float:
        """Top-drive speed above which a stuck estimated BHA counts toward a deadlock."""
        return 3.0 * self.plant.omega_c_rad_s


@dataclass(frozen=True)
class Measurements:
    """Surface measurements on a uniform time grid (the observer's inputs).

    Attributes
    ----------
    t0_s, dt_s : float
        Time of the first sample and sample interval [s].
    surface_rad_s : ndarray
        Measured top-drive speed ω₀ [rad/s].
    motor_torque_Nm : ndarray
        Motor torque τ_m [N·m] (string torque already converted, see :meth:`from_samples`).
    """

    t0_s: float
    dt_s: float
    surface_rad_s: np.ndarray
    motor_torque_Nm: np.ndarray

    @property
    def time_s(self) -> np.ndarray:
        """Sample times [s]."""
        return self.t0_s + self.dt_s * np.arange(self.surface_rad_s.size)

    @property
    def t_end_s(self) -> float:
        """Time of the last sample [s]."""
        return self.t0_s + (self.surface_rad_s.size - 1) * self.dt_s

    @classmethod
    def from_samples(cls, time_s, surface_rad_s, torque_Nm, *, torque_kind: str = "motor",
                     top_drive_inertia_kg_m2: float = default("rig.top_drive_inertia_kg_m2"),
                     rate_hz: float | None = None,
                     smooth_s: float = 1.0) -> Measurements:
        """Resample logged samples onto a uniform grid and express the torque as τ_m.

        Parameters
        ----------
        time_s, surface_rad_s, torque_Nm : array_like
            Logged samples (increasing time, finite values).
        torque_kind : str
            "motor": the log is τ_m. "string": the log is τ(0) = τ_m − I_TD dω₀/dt
            (docs/theory.md §3, eq. 7), so τ_m = τ(0) + I_TD dω̄₀/dt with ω̄₀ smoothed over
            ``smooth_s``.
        rate_hz : float, optional
            Uniform rate [Hz] (default: the median sampling rate).
        """
        t = np.asarray(time_s, dtype=float)
        w = np.asarray(surface_rad_s, dtype=float)
        q = np.asarray(torque_Nm, dtype=float)
        if t.size < 2 or np.any(np.diff(t) <= 0):
            raise InputError("observer measurements need at least two samples in increasing "
                             "time")
        if not (np.all(np.isfinite(w)) and np.all(np.isfinite(q))):
            raise InputError("observer measurements contain missing values",
                             fix="split the segment at the gap or fill short gaps")
        dt = 1.0 / rate_hz if rate_hz else float(np.median(np.diff(t)))
        grid = t[0] + np.arange(int(np.floor((t[-1] - t[0]) / dt + 1e-9)) + 1) * dt
        w_u = np.interp(grid, t, w)
        q_u = np.interp(grid, t, q)
        if torque_kind == "string":
            q_u = q_u + top_drive_inertia_kg_m2 * np.gradient(_smooth(w_u, dt, smooth_s), dt)
        elif torque_kind != "motor":
            raise ModelError(f"unknown torque kind '{torque_kind}'", fix="use motor or string")
        return cls(float(grid[0]), dt, w_u, q_u)


def _smooth(x: np.ndarray, dt: float, window_s: float) -> np.ndarray:
    """Centred moving average over ``window_s`` [s] (edges use the shorter window)."""
    n = max(1, int(round(window_s / dt)))
    if n == 1:
        return x
    kernel = np.ones(n)
    return np.convolve(x, kernel, mode="same") / np.convolve(np.ones_like(x), kernel,
                                                             mode="same")


@dataclass
class ObserverState:
    """Observer state between windows, one row per start.

    Attributes
    ----------
    alpha, beta : ndarray, shape (S, n)
        Estimated Riemann invariants [rad/s].
    omega0 : ndarray, shape (S,)
        Estimated top-drive speed ω̂₀ [rad/s].
    mu_s, mu_k : ndarray, shape (S,)
        Friction-factor estimates [-].
    guard : ndarray, shape (S, 2)
        Deadlock guard [stuck time (s), interventions].
    t_s : float
        Time of the state [s].
    """

    alpha: np.ndarray
    beta: np.ndarray
    omega0: np.ndarray
    mu_s: np.ndarray
    mu_k: np.ndarray
    guard: np.ndarray
    t_s: float

    @classmethod
    def from_starts(cls, observer: Observer, starts, *, omega0_rad_s: float = 0.0,
                    t_s: float = 0.0, torque_top_Nm: float = 0.0) -> ObserverState:
        """Initial states for ``starts`` = [(μ_s, μ_k), ...].

        Rotating (|ω₀| > ω_c): every cell at ω₀ with the steady sliding torque
        τ(x) = sign(ω₀)·∫ₓᴸ f(ω₀) dx (docs/theory.md §3.1, steady rotation; f the friction per
        metre at
        ω₀ of docs/theory.md §3.2, μ_k F_c plus the fixed kinetic part under the step law), so
        a window that starts mid-rotation does not begin with a huge transient. At rest: the
        string held by friction at the measured surface torque ``torque_top_Nm`` [N·m]
        (:meth:`drillfric.torsional.State.wound` with each start's kinetic friction per metre)
        — never untwisted when the measured torque says it is wound.
        """
        starts = np.atleast_2d(np.asarray(starts, dtype=float))
        if starts.shape[1] != 2 or np.any(starts < 0) or np.any(starts[:, 1] > starts[:, 0]):
            raise ModelError("observer starts must be pairs (μ_s, μ_k) with 0 ≤ μ_k ≤ μ_s",
                             fix="e.g. observer.starts = [[0.3, 0.2], [0.6, 0.4]]")
        plant = observer.plant
        g = plant.grid
        n_start = starts.shape[0]
        omega = np.full((n_start, g.n_cells), float(omega0_rad_s))
        torque = np.zeros((n_start, g.n_cells))
        if abs(omega0_rad_s) > plant.omega_c_rad_s:
            def below(per_m):
                return np.cumsum((per_m * g.dx_true_m)[::-1])[::-1][None, :]

            est, fix_k, fix_s = (below(plant.fc_Nm_m), below(plant.fixed_k_Nm_m),
                                  below(plant.fixed_s_Nm_m))
            weight = plant.static_weight(omega0_rad_s)
            torque = np.sign(omega0_rad_s) * (
                starts[:, 1:2] * est + fix_k
                + weight * ((starts[:, :1] - starts[:, 1:2]) * est + fix_s - fix_k))
        elif torque_top_Nm:
            torque = np.stack([State.wound(g, mu_k * plant.fc_Nm_m + plant.fixed_k_Nm_m,
                                           torque_top_Nm, 1.0).torque_Nm(g)
                               for mu_k in starts[:, 1]])
        alpha = omega + torque / g.zeta_Nms
        beta = omega - torque / g.zeta_Nms
        return cls(alpha, beta, np.full(n_start, float(omega0_rad_s)),
                   starts[:, 0].copy(), starts[:, 1].copy(), np.zeros((n_start, 2)), t_s)

    def copy(self) -> ObserverState:
        """Deep copy."""
        return ObserverState(self.alpha.copy(), self.beta.copy(), self.omega0.copy(),
                             self.mu_s.copy(), self.mu_k.copy(), self.guard.copy(), self.t_s)


@dataclass(frozen=True)
class ObserverRecord:
    """Observer outputs at the output rate; arrays of shape (R, S) unless noted.

    Attributes
    ----------
    time_s : ndarray, shape (R,)
    mu_s, mu_k : ndarray
        Friction-factor estimates [-].
    surface_rad_s_est : ndarray
        Estimated top-drive speed ω̂₀ [rad/s].
    bit_rad_s_est : ndarray
        Estimated bit speed (last cell) [rad/s].
    bha_rad_s_est : ndarray
        Estimated mean BHA speed [rad/s] (decides stuck/sliding in the adaptation).
    residual_rad_s : ndarray
        Innovation e = ω̂₀ − ω₀ [rad/s].
    surface_torque_est_Nm : ndarray
        Modelled string torque at the top τ̂(0) = ζ(ω̂₀ − β̂(0)) [N·m] (eq. 15).
    deadlock_events : ndarray, shape (S,)
        Deadlock-guard interventions per start.
    """

    time_s: np.ndarray
    mu_s: np.ndarray
    mu_k: np.ndarray
    surface_rad_s_est: np.ndarray
    bit_rad_s_est: np.ndarray
    bha_rad_s_est: np.ndarray
    residual_rad_s: np.ndarray
    surface_torque_est_Nm: np.ndarray
    deadlock_events: np.ndarray


def observe(observer: Observer, meas: Measurements, state: ObserverState, *,
            output_rate_hz: float = 10.0, t_end_s: float | None = None,
            backend: str = "numba", parallel: bool | None = None
            ) -> tuple[ObserverRecord, ObserverState]:
    """Run the observer from ``state.t_s`` to ``t_end_s`` (default: the last measurement).

    Parameters
    ----------
    observer : Observer
    meas : Measurements
    state : ObserverState
        Initial state (not modified); its time must lie within the measurements.
    output_rate_hz : float
        Rate of the returned record [Hz].
    backend : str
        "numba" (compiled) or "numpy" (the twin: tests and benchmarks only).
    parallel : bool, optional
        Run the starts (members) on numba's threads, one member per thread at a time (the
        same numbers as serially: they do not interact). Default: when numba may use more
        than one thread (``numba.get_num_threads()``; ``numba.set_num_threads(1)`` or
        ``NUMBA_NUM_THREADS=1`` forces one, as fleet workers do) and there is more than
        one start.

    Returns
    -------
    (ObserverRecord, ObserverState)
    """
    t_end = meas.t_end_s if t_end_s is None else float(t_end_s)
    duration = t_end - state.t_s
    if duration <= 0:
        raise ModelError(f"nothing to observe: window {state.t_s:.2f}–{t_end:.2f} s")
    plant, gains = observer.plant, observer.gains
    g = plant.grid
    n_steps = int(np.floor(duration / g.dt_s + 1e-9))
    times = state.t_s + np.arange(int(np.floor(duration * output_rate_hz + 1e-9)) + 1) \
        / output_rate_hz
    times = times[times <= state.t_s + n_steps * g.dt_s + 1e-9]
    out = np.empty((times.size, state.alpha.shape[0], len(OBS_COLUMNS)))
    new = state.copy()
    if backend == "numba":
        from drillfric.kernels.observer import run_observer
    elif backend == "numpy":
        from drillfric.kernels.observer_numpy import run_observer
    else:
        raise ModelError(f"unknown backend '{backend}'", fix="use 'numba' or 'numpy'")
    if parallel is None:
        parallel = numba.get_num_threads() > 1 and state.alpha.shape[0] > 1
    run_observer(new.alpha, new.beta, new.omega0, new.mu_s, new.mu_k, new.guard, state.t_s,
                 n_steps, g.section_start, g.junction_z, g.zeta_Nms, plant.fcap_rad_s,
                 plant.fix_k_rad_s, plant.fix_s_rad_s, g.dt_s, plant.k_t_per_s * g.dt_s,
                 plant.omega_c_rad_s, plant.law_speed_rad_s, float(plant.stribeck_exponent),
                 plant.bit_torque_cap_Nm / g.zeta_Nms[-1], 1.0 / plant.top_drive_inertia_kg_m2,
                 meas.surface_rad_s, meas.motor_torque_Nm, meas.t0_s, meas.dt_s, observer.hold,
                 gains.p0, gains.P0, *observer.injections, gains.P1, gains.l_k, gains.l_s,
                 _LAWS[observer.law], observer.mu_max, observer.deadlock_s,
                 observer.omega_turn_rad_s, times, out, parallel)
    new.t_s = state.t_s + n_steps * g.dt_s
    record = ObserverRecord(times, *(out[:, :, c] for c in range(len(OBS_COLUMNS))),
                            deadlock_events=new.guard[:, 1].copy())
    return record, new


@dataclass(frozen=True)
class BitSpeedEstimate:
    """Bit speed from an ensemble of observer members, at the record's times [rad/s].

    Attributes
    ----------
    rad_s : ndarray, shape (R,)
        The estimate: the members' mean weighted by how well each matches the measured
        top-drive speed lately (:func:`ensemble_bit_speed`).
    low_rad_s, high_rad_s : ndarray, shape (R,)
        The members' minimum and maximum (the band).
    weights : ndarray, shape (R, S)
        The members' weights at each time (rows sum to 1).
    """

    rad_s: np.ndarray
    low_rad_s: np.ndarray
    high_rad_s: np.ndarray
    weights: np.ndarray

    def record(self, members: ObserverRecord) -> ObserverRecord:
        """The ensemble as one start: the seed member's μ and deadlock count, the weighted
        mean of every speed and of the innovation (the bit speed is :attr:`rad_s`)."""
        mean = lambda a: (self.weights * a).sum(axis=1, keepdims=True)  # noqa: E731
        return ObserverRecord(members.time_s, members.mu_s[:, :1], members.mu_k[:, :1],
                              mean(members.surface_rad_s_est), self.rad_s[:, None],
                              mean(members.bha_rad_s_est), mean(members.residual_rad_s),
                              mean(members.surface_torque_est_Nm),
                              members.deadlock_events[:1])

    def stuck(self, members: ObserverRecord, omega_c_rad_s: float) -> np.ndarray:
        """Bit stuck at each time: members whose BHA is in the static band (|ω̂_BHA| ≤ ω_c)
        carry more than half the weight (R,)."""
        stuck = np.abs(members.bha_rad_s_est) <= omega_c_rad_s
        return (self.weights * stuck).sum(axis=1) > 0.5


def ensemble_bit_speed(record: ObserverRecord, memory_s: float,
                       noise_rad_s: float) -> BitSpeedEstimate:
    """Bit speed of an ensemble of observer members (the starts of ``record``).

    In stick-slip the members' cycles drift apart in phase (the cycle is chaotic, docs/theory.md
    §6.2) and a member that has drifted shows it in its innovation e = ω̂₀ − ω₀ about one
    wave round trip later. Each member is weighted by 1/(ē² + σ²), ē² the mean square of
    its innovation over the last ``memory_s`` (exponential memory) and σ the measurement
    noise ``noise_rad_s``: members that match the surface lately count most. σ is a floor
    (members at the noise level are not told apart); in stick-slip the innovations are
    several σ and the weights go as 1/ē². A heuristic inverse-mean-square weighting of a
    fixed grid of members, not a posterior (docs/bit_speed.md measures what it gains).

    Parameters
    ----------
    record : ObserverRecord
        One start per member; uniform record times.
    memory_s : float
        Memory of the innovation average [s] (a wave round trip 2L/c is the natural one).
    noise_rad_s : float
        Standard deviation of the measured top-drive speed [rad/s].
    """
    bit = record.bit_rad_s_est
    if record.time_s.size > 1:
        step = min(float(record.time_s[1] - record.time_s[0]) / memory_s, 1.0)
        e2 = record.residual_rad_s ** 2
        mean_e2 = lfilter([step], [1.0, step - 1.0], e2, axis=0, zi=(1.0 - step) * e2[:1])[0]
    else:
        mean_e2 = np.zeros_like(bit)
    weight = 1.0 / (mean_e2 + noise_rad_s ** 2 + 1e-30)
    weight /= weight.sum(axis=1, keepdims=True)
    return BitSpeedEstimate((weight * bit).sum(axis=1), bit.min(axis=1), bit.max(axis=1),
                            weight)
