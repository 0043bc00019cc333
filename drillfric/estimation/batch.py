"""Batch refinement of the friction factors (the "speed-driven fit"), docs/theory.md §6.4.

The plant of docs/theory.md §3 is driven at x = 0 by the measured top-drive speed (lightly
smoothed, interpolated to the model step), α(0) = 2ω₀(t) − β(0), starting at rest with no
twist; its output is the string torque at the top τ(0) = ζ(ω₀ − β(0)), compared with the
measured string torque τ_s = τ_m − I_TD dω̄₀/dt. From that model:

- μ_k matches the **mean** string torque over the rotating samples (the first 30 s after
  the top drive first exceeds ω_c in each rotating run are left out; data and model each
  averaged over whole torque cycles) by a secant root find with a bounded slope that
  returns a point it evaluated (the mean jitters between runs because stick-slip is
  chaotic), with the model in the data's regime (§6.4);
- μ_s is fitted only where the data hold it, on creep start-ups logged at ≥ 2 Hz
  (:mod:`drillfric.estimation.creep`, §6.3): a bounded 1-D minimisation of the smoothed
  torque misfit
  over the creep at Δx ≤ MD/1000, refitted with twice (then four times) the cells and
  reported only once it moves less than 3 %;
- otherwise μ_s is not identifiable; in stick-slip a lower bound comes from the stick-slip
  onset, the highest μ_s of a 0.02 grid below which the model's bit never sticks, and none
  is given where sticking is not monotone in μ_s ("bistable_regime", §6.2, §6.4).

Only the needed parts of a record are simulated: each rotating run (from just before its
start) for μ_k, the first 90 s of rotation of one run for the onset scan, and each creep
(from the preceding rest) for μ_s. Everything is SI (rad/s, N·m, m, s).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.optimize import minimize_scalar
from scipy.signal import savgol_filter

from drillfric import torsional
from drillfric.config import default
from drillfric.drillstring import DrillString
from drillfric.errors import InputError
from drillfric.estimation import creep, relaxation
from drillfric.estimation.creep import bridge_loaded_dips, find_creeps, rotating_runs, smooth
from drillfric.estimation.drive import DriveModel
from drillfric.estimation.drive import identify as identify_drive
from drillfric.friction import CASED_STATIC, FrictionProfile

MU_K_SKIP_S = 30.0  #: rotating samples left out after the top drive first exceeds ω_c [s]
WOUND_SPAN_S = 0.5  #: rest at a window's start over which a trapped torque is measured [s]
#: A stop of the top drive at most this long, with the string still loaded (torque at least
#: DIP_TORQUE_FRACTION of the run's mean), does not end a rotating run (soft-torque drives):
#: the configuration's segmentation.dip_max_s and dip_torque_fraction [s], [-].
DIP_MAX_S, DIP_TORQUE_FRACTION = (default("segmentation.dip_max_s"),
                                  default("segmentation.dip_torque_fraction"))
PRE_ROLL_S = 2.0  #: model starts this long before a run or creep leaves rest [s]
DRIVE_SMOOTH_S = 0.2  #: light smoothing of the speed that drives the model [s]
TORQUE_SMOOTH_S = 1.0  #: smoothing of torques compared in the creep misfit [s]
CREEP_DRIVE_SMOOTH_S = 4.0  #: smoothing of the speed driving a creep (keeps its angle) [s]
STICK_SLIP_FLUCTUATION = 0.1  #: data stick-slip when std/mean of the smoothed torque exceeds
STUCK_FRACTION = 0.01  #: the model's bit sticks when this share of samples is near rest
REST_BIT = 0.1  #: the bit is near rest below this fraction of ω_c
SCAN_STEP = 0.02  #: μ_s grid step of the onset scan (docs/theory.md §6.4)
SCAN_CONFIRM = 3  #: grid points above the first sticking one that must stick too
SCAN_ROTATION_S = 90.0  #: rotation simulated per onset-scan point (30 s skipped + 60 s) [s]
MU_MAX = default("observer.mu_max")  #: upper end of every friction search [-]
CREEP_CELLS_PER_MD = 1000  #: creep fits at Δx ≤ MD/1000 (docs/theory.md §6.4)
CREEP_CONVERGENCE = 0.03  #: relative move allowed when the creep fit doubles its cells
CREEP_MAX_S = 60.0  #: longest creep window fitted [s]
CREEP_LEVELS = 3  #: creep fits at MD/1000, then doubled cells at most twice
CREEP_STENCIL = 0.04  #: relative half-width of the parabola of a creep refit
CREEP_SENSITIVITY_STEP = 0.10  #: relative move of μ_s whose effect on the creep is measured
#: Start of a creep left out of the split-half check (the smoothed drive blurs the onset).
SPLIT_SKIP = 0.2
#: What a creep fit must show before its μ_s is claimed (docs/batch_refinement.md "Checks of
#: a creep fit"; calibrated on the validation plants of benchmarks/validate_trust.py, where
#: fits of the model family stay inside with margin and fits of other laws do not):
MAX_CREEP_MISFIT = 0.03  #: RMS smoothed residual over the creep torque (model family ≤ 1 %)
#: A 10 % change of μ_s must move the creep torque by this many noise levels (over the
#: creep's independent seconds): the fit's 1-σ uncertainty is then ≤ 10 %/3 ≈ 3 %.
MIN_CREEP_SENSITIVITY = 3.0
MIN_SWING_RATIO = 0.5  #: model/data stick-slip fluctuation after the creep
#: First and second half of the creep fitted alone: the first may lie at most this much below
#: the second (a top of lower friction, e.g. casing, the creep wound up first) and this much
#: either way (the onset of a slowly logged creep fits high: +4…+13 % at 5 Hz on the plants).
MAX_HALVES_BELOW, MAX_HALVES_SPLIT = 0.06, 0.15
#: Both limits widen to this many standard deviations of the halves' difference due to
#: noise alone: each half holds about half the creep's information, so the relative 1-σ of
#: their difference is ≈ 2 × CREEP_SENSITIVITY_STEP / sensitivity (4.9 % at sensitivity 4).
HALVES_SIGMAS = 2.0
MAX_HYPOTHESIS_SPLIT = 0.05  #: the two hypotheses for an unknown cased static factor
#: Slowest logging rate for a creep fit [Hz]: the twist is the integral of the logged speed,
#: and its noise (σ√(Δt·T)) moved μ_s by +17…+33 % at 1 Hz with 0.5 RPM noise, ±6 % at 5 Hz
#: (docs/validation.md).
MIN_CREEP_RATE_HZ = 2.0
PROVISIONAL_RATIO = 2.5  #: μ_s/μ_k of the model during the μ_k fit of stick-slip data
MU_K_MAX_RUNS = 8  #: model runs allowed to the μ_k root find
_GRID_SPREAD = 0.05  # make_grid may take up to 5 % fewer cells than requested (rounding)


@dataclass(frozen=True)
class BatchResult:
    """Friction factors of one record from the speed-driven fit (docs/theory.md §6.4).

    Attributes
    ----------
    mu_k : float or None
        Kinetic friction factor [-] (None without usable rotation).
    mu_k_method : str
        "mean_torque".
    mu_s : float or None
        Static friction factor [-], a number only where the data identify it.
    mu_s_identifiable : bool
    mu_s_lower_bound : float or None
        Lower bound on μ_s from the stick-slip onset [-], where the data support one.
    mu_s_method : str
        "creep_fit", "stick_slip_onset" or "none".
    creep_segments : tuple of (float, float)
        Creeps used for μ_s, (t_start_s, t_end_s) [s].
    flags : tuple of str
        e.g. "bistable_regime", "creep_not_grid_converged", "mu_k_not_converged",
        "no_rotation", "rotation_too_short", "regime_mismatch", "creep_fit_at_bound",
        "creep_rate_too_low", "stick_slip_not_reproduced", "relaxation_cycles".
    runs : int
        Model runs spent.
    messages : tuple of str
        One line per notable decision, for the report.
    details : BatchDetails
        Traces: residuals of the μ_k search, the onset scan, the creep fits, T_N, cells.
    """

    mu_k: float | None
    mu_k_method: str
    mu_s: float | None
    mu_s_identifiable: bool
    mu_s_lower_bound: float | None
    mu_s_method: str
    creep_segments: tuple[tuple[float, float], ...]
    flags: tuple[str, ...]
    runs: int
    messages: tuple[str, ...]
    details: BatchDetails = field(default_factory=lambda: BatchDetails())


@dataclass
class BatchDetails:
    """Traces of a speed-driven fit, filled stage by stage (diagnostics and tests).

    Attributes
    ----------
    cells : int
        Cells of the μ_k model.
    T_N_Nm : float
        ∫F_c dx of the model [N·m].
    creeps_found : list of (float, float)
        Creep start-ups found, (t_start_s, t_end_s) [s].
    mean_torque_Nm : float or None
        Whole-cycle mean measured string torque over the μ_k windows [N·m].
    torque_fluctuation : float or None
        std/|mean| of the smoothed measured torque there [-].
    stick_slip : bool
        Whether the data stick-slip (fluctuation above :data:`STICK_SLIP_FLUCTUATION`).
    mu_k_trace : list of (float, float)
        (μ_k, mean-torque residual [N·m]) of every model run of the root find.
    mu_k_residual_Nm : float or None
        Residual at the μ_k reported [N·m].
    mu_s_model : float or None
        μ_s the model used while μ_k was fitted (the regime value) [-].
    creep_fits : list of (int, float, int)
        (cells, μ_s, model runs) of each creep fit level.
    creep_grid_move : float or None
        Relative change of μ_s at the last grid refinement [-].
    creep_checks : CreepChecks or None
        What the creep fit was checked against before μ_s is claimed.
    onset_scan : list of (float, bool)
        (μ_s, the model's bit sticks) of the stick-slip-onset scan.
    drive : DriveModel or None
        The top drive's PI controller identified from the rotation (replayed in closed loop
        when usable, docs/theory.md §6.4).
    relaxation : RelaxationCycles or None
        Stalls and bursts of a soft top drive found in the log (μ_k then not converged,
        :mod:`drillfric.estimation.relaxation`).
    """

    cells: int = 0
    T_N_Nm: float = 0.0
    creeps_found: list = field(default_factory=list)
    mean_torque_Nm: float | None = None
    torque_fluctuation: float | None = None
    stick_slip: bool = False
    mu_k_trace: list = field(default_factory=list)
    mu_k_residual_Nm: float | None = None
    mu_s_model: float | None = None
    creep_fits: list = field(default_factory=list)
    creep_grid_move: float | None = None
    creep_checks: CreepChecks | None = None
    onset_scan: list = field(default_factory=list)
    drive: DriveModel | None = None
    relaxation: relaxation.RelaxationCycles | None = None


@dataclass(frozen=True)
class CreepChecks:
    """The evidence a creep fit must show before its μ_s is claimed (docs/theory.md §6.3).

    Attributes
    ----------
    engaged : float
        Share of the string's static capacity (μ_s T_N + the fixed part) the fitted model's
        creep torque reached [-]: the creep winds the string up from the top like a zipper,
        and only the part it reached is measured.
    misfit : float
        RMS of the smoothed residual over the creep, relative to the creep's torque [-].
    sensitivity : float
        RMS change of the smoothed model torque when μ_s moves by 10 %, relative to the
        smoothed noise of the measured torque [-].
    noise_Nm : float
        Standard deviation of the smoothed measured torque's noise [N·m].
    halves : tuple of float
        μ_s fitted on the first and on the second half of the creep alone [-].
    twist_noise : float
        Relative 1-σ of μ_s due to the speed noise the model integrates into its twist
        (a random walk, σ_ω·√(Δt·t)) [-] (docs/theory.md §6.3).
    swing_ratio : float or None
        Model/data ratio of the torque fluctuation in the rotation after the creep at the
        fitted factors (None without stick-slip rotation to compare) [-].
    other_hypothesis : float or None
        μ_s refitted with the cased static factor equal to the kinetic one, where the cased
        static factor is unknown (None: it is known, or there is no cased part) [-].
    """

    engaged: float
    misfit: float
    sensitivity: float
    noise_Nm: float
    halves: tuple[float, float]
    twist_noise: float = 0.0
    swing_ratio: float | None = None
    other_hypothesis: float | None = None


def measured_string_torque(time_s, surface_rad_s, torque_Nm, torque_kind: str,
                           top_drive_inertia_kg_m2: float, smooth_s: float = 1.0) -> np.ndarray:
    """String torque at the top from the logged torque [N·m] (docs/theory.md §3 top drive, §6.4).

    τ_s = τ_m − I_TD·dω̄₀/dt for a motor torque (eq. 7 of the paper), with ω̄₀ the top-drive
    speed smoothed over ``smooth_s`` (a Savitzky–Golay derivative: least-squares quadratic
    over the window, exact for ramps, also at the ends); a logged string torque is returned
    unchanged.

    Parameters
    ----------
    time_s : array_like
        Sample times [s], increasing.
    surface_rad_s : array_like
        Top-drive speed ω₀ [rad/s].
    torque_Nm : array_like
        Logged surface torque [N·m].
    torque_kind : str
        "motor" or "string" (``rig.torque_kind``).
    top_drive_inertia_kg_m2 : float
        I_TD [kg·m²].
    smooth_s : float
        Smoothing of ω₀ before differentiating [s].

    Examples
    --------
    >>> t = [0.0, 1.0, 2.0, 3.0]
    >>> measured_string_torque(t, [0.0, 1.0, 2.0, 3.0], [10.0] * 4, "motor", 2.0, 0.0).tolist()
    [8.0, 8.0, 8.0, 8.0]
    """
    tau = np.array(torque_Nm, dtype=float)
    if torque_kind == "string":
        return tau
    if torque_kind != "motor":
        raise InputError(f"unknown torque kind '{torque_kind}'",
                         fix="set rig.torque_kind to 'motor' or 'string'")
    t = np.asarray(time_s, dtype=float)
    w = np.asarray(surface_rad_s, dtype=float)
    dt = float(np.median(np.diff(t)))
    n = int(round(smooth_s / dt)) // 2 * 2 + 1
    if n < 5 or n > t.size:
        return tau - top_drive_inertia_kg_m2 * np.gradient(w, t)
    dw = savgol_filter(w, n, polyorder=2, deriv=1, delta=dt, mode="interp")
    return tau - top_drive_inertia_kg_m2 * dw


@dataclass(frozen=True)
class _Data:
    """A record on a uniform time base, with the series the fits compare."""

    t: np.ndarray  # [s]
    dt: float  # [s]
    drive: np.ndarray  # lightly smoothed ω₀ [rad/s]
    motor: np.ndarray  # lightly smoothed motor torque τ_m [N·m]
    creep_drive: np.ndarray  # ω₀ smoothed over CREEP_DRIVE_SMOOTH_S [rad/s]
    w_bar: np.ndarray  # ω₀ smoothed over TORQUE_SMOOTH_S [rad/s]
    tau: np.ndarray  # measured string torque [N·m]
    tau_bar: np.ndarray  # smoothed string torque [N·m]
    speed: np.ndarray  # logged ω₀ on the uniform time base, unsmoothed [rad/s]

    def index(self, t_s: float) -> int:
        return int(np.clip(np.searchsorted(self.t, t_s - 1e-9 * self.dt), 0, self.t.size - 1))


def _prepare(time_s, surface_rad_s, torque_Nm, torque_kind, itd) -> tuple[_Data, list[str]]:
    t = np.asarray(time_s, dtype=float)
    w = np.asarray(surface_rad_s, dtype=float)
    tau = np.asarray(torque_Nm, dtype=float)
    if t.ndim != 1 or w.shape != t.shape or tau.shape != t.shape:
        raise InputError("batch refinement needs equal-length time, speed and torque series")
    ok = np.isfinite(t) & np.isfinite(w) & np.isfinite(tau)
    t, w, tau = t[ok], w[ok], tau[ok]
    if t.size < 3 or np.any(np.diff(t) <= 0):
        raise InputError("batch refinement needs at least 3 samples at increasing times",
                         fix="sort the record by time and drop duplicate samples")
    notes = [] if ok.all() else [f"{int((~ok).sum())} samples with missing values dropped"]
    dt = float(np.median(np.diff(t)))
    if np.max(np.abs(np.diff(t) - dt)) > 0.01 * dt:
        grid = t[0] + dt * np.arange(int(np.floor((t[-1] - t[0]) / dt)) + 1)
        w, tau, t = np.interp(grid, t, w), np.interp(grid, t, tau), grid
        notes.append(f"irregular sampling resampled to {1 / dt:g} Hz")
    tau_s = measured_string_torque(t, w, tau, torque_kind, itd, TORQUE_SMOOTH_S)
    tau_m = tau if torque_kind == "motor" else \
        tau - measured_string_torque(t, w, np.zeros_like(tau), "motor", itd, TORQUE_SMOOTH_S)
    data = _Data(t=t, dt=dt, drive=smooth(w, dt, DRIVE_SMOOTH_S),
                 motor=smooth(tau_m, dt, DRIVE_SMOOTH_S),
                 creep_drive=smooth(w, dt, CREEP_DRIVE_SMOOTH_S),
                 w_bar=smooth(w, dt, max(TORQUE_SMOOTH_S, 3 * dt)), tau=tau_s,
                 tau_bar=smooth(tau_s, dt, TORQUE_SMOOTH_S), speed=w)
    return data, notes


@dataclass(frozen=True)
class _Window:
    """Simulate samples [sim0, end] from rest; compare over ``used`` (sample indices)."""

    sim0: int
    end: int
    used: np.ndarray
    creep: bool = False  # driven by the creep-smoothed speed


class _Model:
    """The plant driven by the log, on grids of any resolution; counts its runs (docs/theory.md
    §6.4). Creeps follow the logged speed; rotation replays the identified drive in closed
    loop (``drive``, :mod:`drillfric.estimation.drive`), else follows the logged speed too.

    Each window starts from rest, holding the twist the measured torque says the string has
    there (:meth:`drillfric.torsional.State.wound`; none after a released stop)."""

    def __init__(self, string, fc_fn, omega_c, k_t, itd, data: _Data, progress,
                 profile: FrictionProfile | None = None):
        self.string, self.fc_fn, self.data = string, fc_fn, data
        self.omega_c, self.k_t, self.itd = omega_c, k_t, itd
        self.progress = progress
        self.profile = profile or FrictionProfile()
        self.cased_static = CASED_STATIC[0]  # the hypothesis for an unknown cased μ_s
        self.drive: DriveModel | None = None  # replayed in rotation when usable
        self.runs = 0
        self._grids: dict[int, tuple[torsional.Grid, np.ndarray]] = {}

    def grid(self, cells: int) -> tuple[torsional.Grid, np.ndarray]:
        if cells not in self._grids:
            g = torsional.make_grid(self.string, cells)
            fc = np.broadcast_to(np.asarray(self.fc_fn(g.x_m), dtype=float), g.x_m.shape)
            self._grids[cells] = (g, np.ascontiguousarray(fc))
        return self._grids[cells]

    def t_n(self, cells: int) -> float:
        """T_N of the estimated part: ∫F_c dx where μ is estimated [N·m]."""
        return self.t_parts(cells)[0]

    def t_parts(self, cells: int) -> tuple[float, float]:
        """(T_N of the estimated part, kinetic torque of the fixed part) [N·m]."""
        g, fc = self.grid(cells)
        est, fix_k, _ = self.profile.parts(g.x_m, g.dx_true_m, fc, 1.0, 1.0)
        return float(np.sum(est * g.dx_true_m)), float(np.sum(fix_k * g.dx_true_m))

    def _initial(self, win: _Window, g, fc, mu_k: float) -> torsional.State:
        """The state a window starts from: at rest, holding the twist of the torque measured
        over its first :data:`WOUND_SPAN_S` when the top drive is at rest all that time (a
        creep window starts untwisted: creeps with trapped torque are not used)."""
        d = self.data
        t0 = float(d.t[win.sim0])
        span = slice(win.sim0, max(win.sim0 + 1, d.index(t0 + WOUND_SPAN_S)))
        if win.creep or np.any(np.abs(d.w_bar[span]) > creep.REST_FRACTION * self.omega_c):
            return torsional.State.rest(g, t0)
        est, fix_k, _ = self.profile.parts(g.x_m, g.dx_true_m, fc, mu_k, mu_k)
        return torsional.State.wound(g, mu_k * est + fix_k, float(np.median(d.tau[span])), 1.0,
                                     t_s=t0)

    def simulate(self, win: _Window, mu_s: float, mu_k: float,
                 cells: int) -> tuple[np.ndarray, np.ndarray]:
        """String torque [N·m] and bit speed [rad/s] at samples sim0..end."""
        d = self.data
        g, fc = self.grid(cells)
        plant = self.profile.plant(g, fc, mu_s, mu_k, omega_c_rad_s=self.omega_c,
                                   k_t_per_s=self.k_t, top_drive_inertia_kg_m2=self.itd,
                                   cased_static=self.cased_static)
        span = slice(win.sim0, win.end + 1)
        state = self._initial(win, g, fc, mu_k)
        if win.creep or self.drive is None or not self.drive.usable:
            speed = d.creep_drive if win.creep else d.drive
            drive = torsional.Drive("speed", speed[span], d.dt, d.t[win.sim0])
        else:
            drive = torsional.Drive("fed", np.vstack([d.motor[span], d.drive[span]]), d.dt,
                                    d.t[win.sim0], kp_Nms_rad=self.drive.kp_Nms_rad,
                                    ki_Nm_rad=self.drive.ki_Nm_rad)
            state.top[0] = d.drive[win.sim0]
        t = d.t[span]
        rec, _ = torsional.run(plant, drive, t[-1] - t[0], 1.0 / d.dt, state)
        self.runs += 1
        if self.progress is not None:
            self.progress(1.0)
        return (np.interp(t, rec.time_s, rec.string_torque_Nm),
                np.interp(t, rec.time_s, rec.bit_rad_s))


def _fluctuation(tau_bar: np.ndarray) -> float:
    """std/|mean| of a smoothed torque: the stick-slip measure of the data [-]."""
    mean = abs(float(np.mean(tau_bar)))
    return float(np.std(tau_bar)) / mean if mean > 0 else 0.0


def _sticks(bit_rad_s: np.ndarray, omega_c: float) -> bool:
    """Whether the model's bit sticks: a share of samples near rest (docs/theory.md §6.4)."""
    return bool(np.mean(np.abs(bit_rad_s) <= REST_BIT * omega_c) >= STUCK_FRACTION)


def _mu_k_windows(data: _Data, omega_c: float) -> tuple[list[_Window], list[str]]:
    """One window per rotating run with samples ≥ MU_K_SKIP_S after first exceeding ω_c."""
    pre = int(round(PRE_ROLL_S / data.dt))
    wins, notes = [], []
    for i0, i1 in bridge_loaded_dips(rotating_runs(data.w_bar, omega_c), data.t, data.tau_bar,
                                     max_dip_s=DIP_MAX_S, fraction=DIP_TORQUE_FRACTION):
        fast = np.flatnonzero(data.w_bar[i0:i1 + 1] > omega_c)
        if fast.size == 0:
            continue
        first = data.index(data.t[i0 + fast[0]] + MU_K_SKIP_S)
        if first >= i1:
            notes.append(f"rotating run {data.t[i0]:.0f}–{data.t[i1]:.0f} s shorter than "
                         f"{MU_K_SKIP_S:.0f} s after reaching ω_c: not used for μ_k")
            continue
        wins.append(_Window(max(0, i0 - pre), i1, np.arange(first, i1 + 1)))
    return wins, notes


def _secant(residual: Callable[[float], float], x0: float, slope0: float, lo: float,
            hi: float, tol: float) -> tuple[float, float, list[tuple[float, float]]]:
    """Root of a jittery monotone residual by secant steps with a bounded slope.

    The slope is kept within [0.5, 2]·``slope0`` so that jitter cannot throw a step far
    away; the point returned is the evaluated one with the smallest |residual| (§6.4).
    """
    trace = [(x0, residual(x0))]
    slope = slope0
    while len(trace) < MU_K_MAX_RUNS and abs(trace[-1][1]) > tol:
        x, r = trace[-1]
        x_new = float(np.clip(x - r / slope, lo, hi))
        if x_new == x:
            break
        trace.append((x_new, residual(x_new)))
        secant = (trace[-1][1] - r) / (x_new - x)
        slope = float(np.clip(secant, 0.5 * slope0, 2.0 * slope0))
    best = min(trace, key=lambda p: abs(p[1]))
    return best[0], best[1], trace


def whole_cycles(tau_Nm, dt_s: float) -> slice:
    """Samples spanning whole torque cycles: from the first to the last upward crossing of
    the 1-s smoothed torque through its mean (all samples with fewer than two crossings).

    A mean over a fractional number of stick-slip cycles carries up to half a cycle's swing
    divided by the cycle count; cutting both ends at the same phase removes that term
    (it cut the jitter of the model's mean from 150 to 60 N·m on 49-s windows, §6.4).

    Examples
    --------
    >>> x = np.sin(np.linspace(0.0, 5.5 * np.pi, 100))  # 2.75 cycles: 2 whole ones
    >>> s = whole_cycles(x, 1.0)
    >>> (s.start, s.stop)
    (1, 73)
    """
    x = np.asarray(tau_Nm, dtype=float)
    xb = smooth(x, dt_s, TORQUE_SMOOTH_S)
    up = np.flatnonzero((xb[:-1] < xb.mean()) & (xb[1:] >= xb.mean())) + 1
    return slice(int(up[0]), int(up[-1])) if up.size >= 2 else slice(0, x.size)


def _cycle_mean(series: list[np.ndarray], dt_s: float) -> float:
    """Mean over the whole cycles of each window, pooled [N·m]."""
    return float(np.mean(np.concatenate([x[whole_cycles(x, dt_s)] for x in series])))


def _pooled_mean(model: _Model, wins: list[_Window], mu_s: float, mu_k: float,
                 cells: int) -> tuple[float, np.ndarray]:
    """Whole-cycle mean model torque over the used samples of all windows, and the bits'
    speeds there."""
    taus, bits = [], []
    for w in wins:
        tau, bit = model.simulate(w, mu_s, mu_k, cells)
        taus.append(tau[w.used - w.sim0])
        bits.append(bit[w.used - w.sim0])
    return _cycle_mean(taus, model.data.dt), np.concatenate(bits)


def _fit_mu_k(model: _Model, wins, target_Nm: float, mu_s_of: Callable[[float], float],
              x0: float, cells: int) -> tuple[float, float, list, bool]:
    """μ_k matching the mean torque; returns (μ_k, residual, trace, model bit sticks)."""
    t_n = model.t_n(cells)
    sticks = {}

    def residual(mu_k: float) -> float:
        mean, bit = _pooled_mean(model, wins, max(mu_s_of(mu_k), mu_k), mu_k, cells)
        sticks[mu_k] = _sticks(bit, model.omega_c)
        return mean - target_Nm

    tol = max(0.01 * abs(target_Nm), 50.0)  # the chaotic jitter of the mean (§6.4)
    mu_k, res, trace = _secant(residual, x0, t_n, 1e-3, MU_MAX, tol)
    return mu_k, res, trace, sticks[mu_k]


def _onset_scan(model: _Model, win: _Window, mu_k: float,
                cells: int) -> tuple[float | None, bool, list]:
    """Lower bound on μ_s from the stick-slip onset (docs/theory.md §6.2, §6.4).

    Scans μ_s = μ_k + 0.02 j upward until the model's bit sticks, then checks that the next
    :data:`SCAN_CONFIRM` points stick too. Returns (bound, bistable, scan): the bound is the
    highest grid value at which the model does not stick (μ_k itself when the first point
    sticks), None when sticking is not monotone (bistable) or never happens.
    """
    scan, first = [], None
    mu_s = mu_k
    while mu_s + SCAN_STEP <= MU_MAX + 1e-9:
        mu_s = round(mu_s + SCAN_STEP, 10)
        _, bit = model.simulate(win, mu_s, mu_k, cells)
        stuck = _sticks(bit[win.used - win.sim0], model.omega_c)
        scan.append((mu_s, stuck))
        if stuck and first is None:
            first = len(scan) - 1
        if not stuck and first is not None:
            return None, True, scan
        if first is not None and len(scan) - 1 - first >= SCAN_CONFIRM:
            break
    if first is None:
        return None, False, scan
    return (scan[first - 1][0] if first > 0 else mu_k), False, scan


def _creep_cells(string: DrillString, cells: int) -> int:
    """Cells giving Δx ≤ MD/1000 in every section (at least ``cells``)."""
    c = np.array([s.wave_speed_m_s for s in string.sections])
    travel = sum(s.length_m / s.wave_speed_m_s for s in string.sections)
    need = CREEP_CELLS_PER_MD * float(c.max()) * travel / string.bit_depth_m
    return max(cells, int(np.ceil(need / (1.0 - _GRID_SPREAD))) + 1)


def _creep_windows(data: _Data, creeps) -> list[_Window]:
    """Creeps simulated from rest; the drive is smoothed over a few seconds: during a creep
    the speed is low and steady, the twist is its integral (which a centred moving average
    keeps), and jitter in the drive moves the creep torque by several % (noise 0.5 RPM).
    The fit stops half a smoothing window before the creep ends (the drive is blurred
    there by the following ramp)."""
    pre = int(round((PRE_ROLL_S + CREEP_DRIVE_SMOOTH_S / 2) / data.dt))
    wins = []
    for t0, t1 in creeps:
        i0 = data.index(t0)
        i1 = data.index(min(t1 - CREEP_DRIVE_SMOOTH_S / 2, t0 + CREEP_MAX_S))
        wins.append(_Window(max(0, i0 - pre), i1, np.arange(i0, i1 + 1), creep=True))
    return wins


def _creep_misfit(model: _Model, wins, mu_k: float, cells: int) -> Callable[[float], float]:
    """Mean squared difference of the 1-s smoothed torques over the creeps [N²·m²]."""
    d = model.data

    def misfit(mu_s: float) -> float:
        err = []
        for w in wins:
            tau, _ = model.simulate(w, mu_s, min(mu_k, mu_s), cells)
            tau_bar = smooth(tau, d.dt, TORQUE_SMOOTH_S)
            err.append(tau_bar[w.used - w.sim0] - d.tau_bar[w.used])
        return float(np.mean(np.concatenate(err) ** 2))

    return misfit


def _fit_creep(model: _Model, wins, mu_k: float, cells: int, lo: float,
               hi: float) -> tuple[float, int]:
    """μ_s minimising the smoothed torque misfit over the creeps (docs/theory.md §6.3–6.4):
    bounded 1-D minimisation (Brent) on [lo, hi]; returns (μ_s, runs)."""
    start = model.runs
    res = minimize_scalar(_creep_misfit(model, wins, mu_k, cells), bounds=(lo, hi),
                          method="bounded", options={"xatol": 2e-3 * hi})
    return float(res.x), model.runs - start


def parabola_vertex(x, j, curvature: float | None = None) -> tuple[float, float]:
    """Vertex and curvature a of J(x) = a(x − v)² + c through three equally spaced points
    (x₀, x₁, x₂), or through the outer two when ``curvature`` is given (J(x₁) unused).
    A non-convex parabola (a ≤ 0) returns (x₁, a).

    Examples
    --------
    >>> parabola_vertex([0.0, 1.0, 2.0], [4.0, 1.0, 0.0])
    (2.0, 1.0)
    >>> parabola_vertex([0.0, 1.0, 2.0], [4.0, float("nan"), 0.0], 1.0)
    (2.0, 1.0)
    """
    x0, x1, x2 = (float(v) for v in x)
    j0, j1, j2 = (float(v) for v in j)
    h = 0.5 * (x2 - x0)
    a = (j0 - 2.0 * j1 + j2) / (2.0 * h * h) if curvature is None else float(curvature)
    if a <= 0.0:  # not convex: no minimum, the caller falls back to a bounded search
        return x1, a
    return x1 - (j2 - j0) / (4.0 * a * h), a


def _refit_creep(model: _Model, wins, mu_k: float, cells: int, centre: float, lo: float,
                 hi: float) -> tuple[float, int]:
    """μ_s near ``centre`` on a finer grid; returns (μ_s, runs).

    The vertex of the misfit parabola through centre·(1 ± 4 %), all three points evaluated
    on this grid (borrowing the previous grid's curvature saved a run but the curvature
    changes by ~30 % between 2290 and 4573 cells, and it hid non-convexity). A vertex
    outside ±8 % or a non-convex parabola falls back to :func:`_fit_creep` on ±10 %. The
    misfit of a creep is smooth in μ_s (no stick-slip, no chaos)."""
    start = model.runs
    misfit = _creep_misfit(model, wins, mu_k, cells)
    x = centre * np.array([1.0 - CREEP_STENCIL, 1.0, 1.0 + CREEP_STENCIL])
    if x[0] >= lo and x[2] <= hi:
        j = np.array([misfit(x[0]), misfit(centre), misfit(x[2])])
        vertex, a = parabola_vertex(x, j)
        if a > 0 and abs(vertex / centre - 1.0) <= 2 * CREEP_STENCIL:
            return vertex, model.runs - start
    mu, _ = _fit_creep(model, wins, mu_k, cells, max(lo, 0.9 * centre), min(hi, 1.1 * centre))
    return mu, model.runs - start


def _as_fc_fn(fc_Nm_m) -> Callable[[np.ndarray], np.ndarray]:
    if callable(fc_Nm_m):
        return fc_Nm_m
    value = float(fc_Nm_m)
    return lambda x: np.full(np.shape(x), value)


def model_string_torque(time_s, surface_rad_s, torque_Nm, *, string: DrillString, fc_Nm_m,
                        omega_c_rad_s: float, k_t_per_s: float,
                        top_drive_inertia_kg_m2: float, mu_s: float, mu_k: float,
                        torque_kind: str = "motor", cells: int = 500,
                        profile: FrictionProfile | None = None
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The fitted model against the data over a whole record (the evidence of a fit).

    The speed-driven plant of docs/theory.md §6.4 at (μ_s, μ_k), driven by the measured top-drive
    speed from rest over the whole record, as :func:`refine`'s fits are.

    Returns
    -------
    time_s, measured_Nm, model_Nm : ndarray
        Sample times on the record's uniform grid [s], the measured string torque and the
        model's string torque at the top [N·m].
    """
    data, _ = _prepare(time_s, surface_rad_s, torque_Nm, torque_kind, top_drive_inertia_kg_m2)
    model = _Model(string, _as_fc_fn(fc_Nm_m), omega_c_rad_s, k_t_per_s,
                   top_drive_inertia_kg_m2, data, None, profile)
    whole = _Window(0, data.t.size - 1, np.arange(data.t.size))
    tau, _ = model.simulate(whole, max(mu_s, mu_k), mu_k, cells)
    return data.t, data.tau, tau


def refine(time_s, surface_rad_s, torque_Nm, *, string: DrillString, fc_Nm_m,
           omega_c_rad_s: float, k_t_per_s: float, top_drive_inertia_kg_m2: float,
           torque_kind: str = "motor", cells: int = 500, mu_s_seed: float | None = None,
           progress: Callable[[float], None] | None = None,
           profile: FrictionProfile | None = None,
           sample_interval_s: float | None = None) -> BatchResult:
    """Refine μ_k and μ_s of one record with the speed-driven model (docs/theory.md §6.4).

    Parameters
    ----------
    time_s : array_like
        Sample times [s] (resampled to a uniform base when irregular).
    surface_rad_s : array_like
        Measured top-drive speed ω₀ [rad/s].
    torque_Nm : array_like
        Logged surface torque [N·m], of kind ``torque_kind``.
    string : DrillString
        The string at this record's bit depth.
    fc_Nm_m : callable or float
        F_c(x) [N·m/m], a function of measured depth [m] (e.g. ``TDResult.fc_at`` from
        torque and drag, docs/theory.md §2), or a constant.
    omega_c_rad_s : float
        Static/kinetic switching speed ω_c [rad/s].
    k_t_per_s : float
        Viscous damping rate k_t [1/s].
    top_drive_inertia_kg_m2 : float
        I_TD [kg·m²].
    torque_kind : str
        "motor" (τ_m, inertia removed here) or "string".
    cells : int
        Cells of the μ_k model (the creep fit uses at least MD/1000 resolution).
    mu_s_seed : float, optional
        μ_s used by the model while fitting μ_k on stick-slip data (default 2.5·μ_k).
    progress : callable, optional
        Called with 1.0 after each model run.
    profile : FrictionProfile, optional
        Friction zones and law of the model (docs/theory.md §3.2); default: one zone, the
        step law. With a known cased zone μ_k, μ_s are the open hole's.
    sample_interval_s : float, optional
        Effective interval of the log when coarser than its spacing (means, held values;
        :mod:`drillfric.estimation.sampling`) [s]: a creep is fitted only when this, too,
        is within :data:`MIN_CREEP_RATE_HZ`.

    Returns
    -------
    BatchResult
    """
    data, messages = _prepare(time_s, surface_rad_s, torque_Nm, torque_kind,
                              top_drive_inertia_kg_m2)
    model = _Model(string, _as_fc_fn(fc_Nm_m), omega_c_rad_s, k_t_per_s,
                   top_drive_inertia_kg_m2, data, progress, profile)
    flags: list[str] = []
    details = BatchDetails(cells=cells, T_N_Nm=model.t_n(cells))
    creeps = find_creeps(data.t, data.drive, omega_c_rad_s, torque_Nm=data.tau,
                         smooth_s=TORQUE_SMOOTH_S)
    details.creeps_found = creeps
    wins, notes = _mu_k_windows(data, omega_c_rad_s)
    messages += notes
    if wins:
        model.drive = identify_drive(data.t, data.drive, data.motor, [w.used for w in wins])
        details.drive = model.drive
        if model.drive is not None:
            messages.append(model.drive.describe())
    mu_k = None
    stick_slip = False
    if wins:
        used = np.concatenate([w.used for w in wins])
        target = _cycle_mean([data.tau[w.used] for w in wins], data.dt)
        fluct = _fluctuation(data.tau_bar[used])
        stick_slip = fluct > STICK_SLIP_FLUCTUATION
        details.mean_torque_Nm, details.torque_fluctuation = target, fluct
        details.stick_slip = stick_slip
        details.relaxation = relaxation.find(data.t, data.speed, data.tau_bar, omega_c_rad_s,
                                             target)
        if details.relaxation is not None:
            flags.append("relaxation_cycles")
            messages.append(details.relaxation.describe(max(data.dt, sample_interval_s or 0)))
        mu_k = _mu_k_stage(model, wins, target, stick_slip, mu_s_seed, cells, details, flags,
                           messages)
    elif any(np.any(data.w_bar[i0:i1 + 1] > omega_c_rad_s)
             for i0, i1 in rotating_runs(data.w_bar, omega_c_rad_s)):
        flags.append("rotation_too_short")
    else:
        flags.append("no_rotation")
    mu_s, mu_k, bound, method, used_creeps = _static_stages(
        model, creeps, wins, mu_k, stick_slip, cells, details, flags, messages,
        rate_hz=1.0 / max(data.dt, sample_interval_s or 0.0))
    return BatchResult(mu_k=mu_k, mu_k_method="mean_torque", mu_s=mu_s,
                       mu_s_identifiable=mu_s is not None, mu_s_lower_bound=bound,
                       mu_s_method=method, creep_segments=tuple(used_creeps),
                       flags=tuple(flags), runs=model.runs, messages=tuple(messages),
                       details=details)


def _static_stages(model: _Model, creeps, wins, mu_k, stick_slip: bool, cells: int,
                   details: BatchDetails, flags: list, messages: list, *, rate_hz: float):
    """μ_s of a record: the creep fit where a creep was logged fast enough and passes its
    checks (μ_k refitted when the fitted μ_s moves the stick-slip model), else the
    stick-slip onset bound (docs/theory.md §6.3–§6.4). Returns (μ_s, μ_k, bound, method,
    creeps used)."""
    data = model.data
    mu_s, bound, method, used_creeps = None, None, "none", ()
    if creeps and rate_hz < MIN_CREEP_RATE_HZ:
        flags.append("creep_rate_too_low")
        messages.append(f"creep start-up found but logged at {rate_hz:.3g} Hz: the creep "
                        f"fit needs ≥ {MIN_CREEP_RATE_HZ:g} Hz (speed noise integrated into "
                        "the twist); μ_s not fitted")
    elif mu_k is not None and creeps:
        mu_s, used_creeps = _creep_stage(model, data, creeps, mu_k, cells, details, flags,
                                         messages, wins)
        if mu_s is not None:
            method = "creep_fit"
            if stick_slip and abs(mu_s / details.mu_s_model - 1.0) > 0.2:
                mu_k = _refit_mu_k(model, wins, details.mean_torque_Nm, mu_s, mu_k, cells,
                                   details, messages)
    if mu_s is None and mu_k is not None and stick_slip:
        bound = _bound_stage(model, wins, mu_k, cells, details, flags, messages, bool(creeps))
        method = "stick_slip_onset" if bound is not None else "none"
    if mu_s is None and not stick_slip and mu_k is not None:
        messages.append("no stick-slip and no creep start-up: μ_s is not in the data; a creep "
                        "break-over from rest (below ω_c for 10–30 s) would make it measurable")
    return mu_s, mu_k, bound, method, used_creeps


def _mu_k_stage(model, wins, target, stick_slip, mu_s_seed, cells, details, flags, messages):
    """μ_k by mean-torque matching with the model in the data's regime (docs/theory.md §6.4)."""
    d = model.data
    used = np.concatenate([w.used for w in wins])
    string_inertia = float(np.sum(model.grid(cells)[0].rho_j_kg_m
                                  * model.grid(cells)[0].dx_true_m))
    viscous = model.k_t * string_inertia * float(np.mean(d.w_bar[used]))
    t_est, t_fixed = model.t_parts(cells)
    x0 = float(np.clip((target - viscous - t_fixed) / t_est, 0.01, 1.0))
    ratios = (PROVISIONAL_RATIO, 4.0) if stick_slip else (1.0,)
    for ratio in ratios:
        def mu_s_of(mu_k, ratio=ratio):
            return max(ratio * mu_k, mu_s_seed or 0.0) if stick_slip else mu_k
        mu_k, res, trace, sticks = _fit_mu_k(model, wins, target, mu_s_of, x0, cells)
        details.mu_k_trace, details.mu_k_residual_Nm = trace, res
        details.mu_s_model = mu_s_of(mu_k)
        if sticks == stick_slip:
            break
        x0 = mu_k
    if sticks != stick_slip:
        flags.append("regime_mismatch")
        messages.append("the model could not be put in the data's regime "
                        f"({'stick-slip' if stick_slip else 'steady rotation'}); μ_k may be "
                        "biased by a few %")
    if abs(res) > 0.02 * abs(target):
        flags.append("mu_k_not_converged")
        messages.append(f"mean torque matched only to {res:+.0f} N·m of {target:.0f} N·m")
    return mu_k


def _refit_mu_k(model, wins, target, mu_s, mu_k, cells, details, messages):
    """μ_k again with the creep μ_s in the model (same regime, better static part)."""
    new, res, trace, _ = _fit_mu_k(model, wins, target, lambda _: mu_s, mu_k, cells)
    if abs(res) <= max(abs(details.mu_k_residual_Nm), 0.02 * abs(target)):
        details.mu_k_trace = details.mu_k_trace + trace
        details.mu_k_residual_Nm, details.mu_s_model = res, mu_s
        messages.append(f"μ_k refitted with the creep μ_s = {mu_s:.3f}")
        return min(new, mu_s)
    return mu_k


def _creep_stage(model, data, creeps, mu_k, cells, details, flags, messages, rotating=()):
    """μ_s from the creeps at Δx ≤ MD/1000, refitted with doubled cells until it moves
    less than :data:`CREEP_CONVERGENCE` (docs/theory.md §6.4); None when it never settles."""
    wins = _creep_windows(data, creeps)
    n = _creep_cells(model.string, cells)
    lo = max(mu_k, 0.02)
    mu, runs = _fit_creep(model, wins, mu_k, n, lo, MU_MAX)
    fits = [(model.grid(n)[0].n_cells, mu, runs)]
    details.creep_fits = fits
    if min(mu - lo, MU_MAX - mu) < 0.01 * (MU_MAX - lo):
        flags.append("creep_fit_at_bound")
        messages.append(f"creep fit ran to its search bound (μ_s = {mu:.3f}): not reported")
        return None, ()
    for _ in range(CREEP_LEVELS - 1):
        n *= 2
        new, runs = _refit_creep(model, wins, mu_k, n, mu, lo, MU_MAX)
        fits.append((model.grid(n)[0].n_cells, new, runs))
        move, mu = abs(new - mu) / new, new
        details.creep_grid_move = move
        if move < CREEP_CONVERGENCE:
            messages.append(f"μ_s = {mu:.3f} from {len(creeps)} creep start-up(s) "
                            f"({fits[-1][0]} cells; {100 * move:.1f} % change from "
                            f"{fits[-2][0]})")
            checks = _creep_checks(model, wins, mu, mu_k, n, rotating, details.stick_slip,
                                   cells)
            if not model.profile.static_known:
                model.cased_static = CASED_STATIC[1]
                other, _ = _refit_creep(model, wins, mu_k, n, mu, lo, MU_MAX)
                model.cased_static = CASED_STATIC[0]
                checks = replace(checks, other_hypothesis=other)
            details.creep_checks = checks
            problems = _creep_problems(mu, checks)
            messages.append(_checks_text(checks))
            if problems:
                flags.append("mu_s_not_explained")
                messages.append(f"μ_s = {mu:.3f} of the creep fit not reported: "
                                + "; ".join(problems))
                return None, ()
            return mu, tuple(creeps)
    flags.append("creep_not_grid_converged")
    messages.append("creep μ_s not grid-converged (" + ", ".join(
        f"{m:.3f} at {c} cells" for c, m, _ in fits) + "): not reported")
    return None, ()


def _creep_checks(model: _Model, wins, mu_s: float, mu_k: float, cells: int,
                  rotating: list[_Window], stick_slip: bool,
                  rotating_cells: int) -> CreepChecks:
    """The evidence of a creep fit at (μ_s, μ_k) on ``cells`` cells (:class:`CreepChecks`);
    the rotation after the creep is compared on the μ_k fit's ``rotating_cells``."""
    d = model.data
    g, fc = model.grid(cells)
    est, _, fix_s = model.profile.parts(g.x_m, g.dx_true_m, fc, mu_s, mu_k, model.cased_static)
    capacity = float(np.sum((mu_s * est + fix_s) * g.dx_true_m))
    base, moved, data, walks = [], [], [], []
    for w in wins:
        at, up = (smooth(model.simulate(w, f * mu_s, min(mu_k, f * mu_s), cells)[0], d.dt,
                         TORQUE_SMOOTH_S) for f in (1.0, 1.0 + CREEP_SENSITIVITY_STEP))
        walks.append(_twist_walk(d, w, at, up, mu_s))
        base.append(at[w.used - w.sim0])
        moved.append(up[w.used - w.sim0])
        data.append(d.tau_bar[w.used])
    base, moved, data = (np.concatenate(x) for x in (base, moved, data))
    jacobian_sq = float(np.sum((moved - base) ** 2)) / (CREEP_SENSITIVITY_STEP * mu_s) ** 2
    noise = _smoothed_noise_Nm(d, np.concatenate([w.used for w in wins]))
    level = max(float(np.max(np.abs(data))), 1e-9)
    independent = np.sqrt(max(1.0, base.size * d.dt / TORQUE_SMOOTH_S))
    return CreepChecks(engaged=float(np.max(base)) / max(capacity, 1e-9),
                       misfit=float(np.sqrt(np.mean((base - data) ** 2))) / level,
                       sensitivity=float(np.sqrt(np.mean((moved - base) ** 2))) / noise
                       * independent, noise_Nm=noise,
                       swing_ratio=_swing_ratio(model, rotating, mu_s, mu_k, rotating_cells)
                       if stick_slip and rotating else None,
                       halves=_split_half(model, wins, mu_s, mu_k, cells),
                       twist_noise=float(np.sqrt(sum(walks))) / max(jacobian_sq, 1e-30) / mu_s)


def _twist_walk(d: _Data, w: _Window, base: np.ndarray, moved: np.ndarray,
                mu_s: float) -> float:
    """One creep window's share of Var(Σ J_i τ'_i W_i): the speed noise the model integrates
    into its twist (docs/theory.md §6.3, check 2). W is the random walk of the twist error,
    Var W(t) = q·t with q its rate (:func:`_walk_rate`); J = ∂τ/∂μ_s the fit's sensitivity
    [N·m per unit μ] and τ' = dτ/dθ the slope of the quasi-static creep torque against the
    top angle [N·m/rad]. Divided by (Σ J²)² it is the variance of μ_s [-]; the caller adds
    the windows and takes the root. A window too short to tell gives inf (not claimed)."""
    span = slice(w.sim0, w.end + 1)
    drive = d.creep_drive[span]
    if drive.size < 5:
        return np.inf
    rows = w.used - w.sim0
    floor = 0.5 * float(np.median(np.abs(drive[rows])))
    slope = np.gradient(base, d.dt) / np.maximum(np.abs(drive), max(floor, 1e-6))
    a = np.zeros(drive.size)
    a[rows] = (moved[rows] - base[rows]) / (CREEP_SENSITIVITY_STEP * mu_s) * slope[rows]
    creep = slice(w.sim0 + int(rows.min()), w.sim0 + int(rows.max()) + 1)
    rate = _walk_rate(d.speed[creep] - d.creep_drive[creep], d.dt)
    return twist_walk_variance(a, rate, d.dt)


def twist_walk_variance(a, walk_rate: float, dt_s: float) -> float:
    """Var(Σ_i a_i W_i) for a random walk W sampled every ``dt_s`` from W_0 = 0 with
    Var W(t) = ``walk_rate``·t: ``walk_rate``·Δt·Σ_m (Σ_{i≥m} a_i)² (docs/theory.md §6.3)."""
    suffix = np.cumsum(np.asarray(a, dtype=float)[::-1])[::-1]
    return walk_rate * dt_s * float(np.sum(suffix ** 2))


def _walk_rate(residual_rad_s: np.ndarray, dt: float) -> float:
    """Rate q [rad²/s] of the random walk that the speed noise adds to the model's twist, from
    the residual of the logged speed about the creep drive (its 4-s moving average) over the
    creep: the variance of its integral over 1-s blocks, per second, made robust to the few
    blocks where the creep's own speed changes (1.4826 × median absolute deviation) and
    corrected for the part of white noise the moving average keeps (a block of b seconds
    against an average over L: variance × (1 − b/L − b²/3L²)). Unlike a second-difference
    estimate of the sample noise it holds for noise averaged or quantised before logging,
    and reads noise filtered over ~1 s about a third low instead of 12× (the walk is made
    by the low frequencies)."""
    block = max(1, int(round(1.0 / dt)))
    n = residual_rad_s.size // block
    if n < 5:
        return np.inf
    integrals = residual_rad_s[:n * block].reshape(n, block).sum(axis=1) * dt
    spread = 1.4826 * float(np.median(np.abs(integrals - np.median(integrals))))
    ratio = block * dt / CREEP_DRIVE_SMOOTH_S
    kept = max(1.0 - ratio - ratio ** 2 / 3.0, 0.5)
    return spread ** 2 / (block * dt) / kept


def _split_half(model: _Model, wins, mu_s: float, mu_k: float,
                cells: int) -> tuple[float, float]:
    """μ_s fitted on the first and on the second half of each creep alone (a parabola
    through the misfits at μ_s·(1 + {−8, 0, +8} %)): one friction factor that explains the
    whole build-up gives the same value twice (docs/theory.md §6.3)."""
    d = model.data
    x = mu_s * np.array([1.0 - 2 * CREEP_STENCIL, 1.0, 1.0 + 2 * CREEP_STENCIL])
    halves = np.zeros((2, 3))
    for j, mu in enumerate(x):
        for w in wins:
            tau, _ = model.simulate(w, mu, min(mu_k, mu), cells)
            err = (smooth(tau, d.dt, TORQUE_SMOOTH_S)[w.used - w.sim0] - d.tau_bar[w.used])**2
            a, b = int(SPLIT_SKIP * err.size), err.size
            mid = (a + b) // 2
            halves[0, j] += float(np.mean(err[a:mid]))
            halves[1, j] += float(np.mean(err[mid:b]))
    return tuple(float(parabola_vertex(x, h)[0]) for h in halves)


def _creep_problems(mu_s: float, c: CreepChecks) -> list[str]:
    """Why a grid-converged creep fit does not identify μ_s (empty: it does)."""
    problems = []
    if c.misfit > MAX_CREEP_MISFIT:
        problems.append(f"the fitted model misses the creep torque by {100 * c.misfit:.0f} % "
                        "RMS: the friction law does not explain the break-over")
    if c.sensitivity < MIN_CREEP_SENSITIVITY:
        problems.append("the creep torque hardly depends on μ_s (a 10 % change is "
                        f"{c.sensitivity:.1f}× its noise)")
    elif not np.hypot(CREEP_SENSITIVITY_STEP / c.sensitivity, c.twist_noise) <= \
            CREEP_SENSITIVITY_STEP / MIN_CREEP_SENSITIVITY:  # NaN or inf: not pinned
        problems.append(f"the speed noise integrated into the twist leaves μ_s uncertain by "
                        f"±{100 * c.twist_noise:.1f} % (1σ; torque noise "
                        f"±{100 * CREEP_SENSITIVITY_STEP / c.sensitivity:.1f} %): a creep "
                        "logged faster or with a quieter speed sensor would pin it")
    if c.swing_ratio is not None and c.swing_ratio < MIN_SWING_RATIO:
        problems.append(f"with this μ_s the model's stick-slip after the creep is "
                        f"{c.swing_ratio:.2f}× the data's: the law that fits the creep does "
                        "not explain the slips (friction falling with speed?)")
    first, second = c.halves
    change = first / max(second, 1e-9) - 1.0
    noise = HALVES_SIGMAS * 2.0 * CREEP_SENSITIVITY_STEP / max(c.sensitivity, 1e-9)
    if change < -max(MAX_HALVES_BELOW, noise) or abs(change) > max(MAX_HALVES_SPLIT, noise):
        problems.append(f"the first and second half of the creep give μ_s = "
                        f"{c.halves[0]:.3f} and {c.halves[1]:.3f}: friction is not the same "
                        "along the string the creep wound up (cased and open hole?)")
    if c.other_hypothesis is not None and \
            abs(c.other_hypothesis / mu_s - 1.0) > MAX_HYPOTHESIS_SPLIT:
        problems.append(f"it depends on the unknown static friction in the casing "
                        f"({mu_s:.3f} with the open hole's ratio, {c.other_hypothesis:.3f} "
                        "without): give model.friction_cased_static")
    return problems


def _checks_text(c: CreepChecks) -> str:
    """The checks as one message (the evidence beside a μ_s)."""
    swing = "—" if c.swing_ratio is None else f"{c.swing_ratio:.2f}"
    return (f"creep checks: misfit {100 * c.misfit:.1f} %, sensitivity {c.sensitivity:.0f}, "
            f"twist noise ±{100 * c.twist_noise:.1f} %, "
            f"string engaged {100 * min(c.engaged, 1.0):.0f} %, halves {c.halves[0]:.3f} / "
            f"{c.halves[1]:.3f}, model/data stick-slip {swing}")


def _smoothed_noise_Nm(d: _Data, samples: np.ndarray) -> float:
    """Noise of the smoothed measured torque [N·m]: the raw noise from second differences
    (robust median estimate, a smooth torque adds little to them) over the smoothing
    window's √n."""
    raw = d.tau[samples]
    if raw.size < 5:
        return 1.0
    sigma = 1.4826 * float(np.median(np.abs(np.diff(raw, 2)))) / np.sqrt(6.0)
    return max(sigma / np.sqrt(max(1.0, TORQUE_SMOOTH_S / d.dt)), 1e-6)


def _swing_ratio(model: _Model, rotating: list[_Window], mu_s: float, mu_k: float,
                 cells: int) -> float:
    """Torque fluctuation of the model at (μ_s, μ_k) over the used samples of the longest
    rotating run, relative to the data's there [-]."""
    w = max(rotating, key=lambda w: w.used.size)
    tau, _ = model.simulate(w, mu_s, mu_k, cells)
    d = model.data
    model_fluct = _fluctuation(smooth(tau, d.dt, TORQUE_SMOOTH_S)[w.used - w.sim0])
    return model_fluct / max(_fluctuation(d.tau_bar[w.used]), 1e-9)


def _bound_stage(model, wins, mu_k, cells, details, flags, messages, had_creep=False):
    """Stick-slip-onset lower bound on μ_s over the first 90 s of rotation of one run.

    With a cased zone of unknown static friction the scan runs under both hypotheses and the
    lower bound is kept (a bound above the truth is a false claim)."""
    w = max(wins, key=lambda w: w.used.size)
    last = min(w.end, w.used[0] + int(round((SCAN_ROTATION_S - MU_K_SKIP_S) / model.data.dt)))
    scan_win = _Window(w.sim0, last, w.used[w.used <= last])
    bound, bistable, scan = _onset_scan(model, scan_win, mu_k, cells)
    if not model.profile.static_known and bound is not None and not bistable:
        model.cased_static = CASED_STATIC[1]
        other, bistable, more = _onset_scan(model, scan_win, mu_k, cells)
        model.cased_static = CASED_STATIC[0]
        scan += more
        bound = None if other is None else min(bound, other)
    details.onset_scan = scan
    if bistable:
        flags.append("bistable_regime")
        messages.append("whether the model sticks is not monotone in μ_s near the onset: "
                        "no lower bound given")
    elif bound is None:
        flags.append("stick_slip_not_reproduced")
        messages.append(f"the model does not stick-slip for μ_s ≤ {MU_MAX}: no lower bound")
    else:
        weak = " (the model sticks for any μ_s above μ_k: no more than μ_s ≥ μ_k)" \
            if bound == mu_k else ""
        why = "no creep fit passed its checks" if had_creep else "no creep"
        messages.append(f"μ_s not identifiable (stick-slip, {why}); μ_s ≥ {bound:.2f} from "
                        f"the stick-slip onset{weak}")
    return bound
