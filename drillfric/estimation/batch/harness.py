"""The model harness of the speed-driven fit: the log on a uniform time base, the windows
simulated, and the plant driven by the log (docs/theory.md §3, §6.4).

Everything is SI (rad/s, N·m, m, s).
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from scipy.signal import savgol_filter

from drillfric import torsional
from drillfric.errors import InputError
from drillfric.estimation import creep
from drillfric.estimation.batch.settings import (
    CREEP_DRIVE_SMOOTH_S,
    DRIVE_SMOOTH_S,
    MIN_CYCLES,
    REST_BIT,
    STEADY_BLOCK_S,
    STICK_SLIP_FLUCTUATION,
    STUCK_FRACTION,
    TORQUE_SMOOTH_S,
    WOUND_SPAN_S,
    BatchSettings,
)
from drillfric.estimation.creep import smooth
from drillfric.estimation.drive import DriveModel
from drillfric.friction import CASED_STATIC, FrictionProfile


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
class FitData:
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
    # I_TD·dω̄₀/dt taken off a motor torque, smoothed as tau_bar (0: a string torque) [N·m]
    inertia_bar: np.ndarray | None = None

    def index(self, t_s: float) -> int:
        """The first sample at or after ``t_s`` [s] (clipped to the record)."""
        return int(np.clip(np.searchsorted(self.t, t_s - 1e-9 * self.dt), 0, self.t.size - 1))

    def turned_rad(self, i0: int, i1: int) -> np.ndarray:
        """Angle the top drive has turned since sample ``i0``, at samples i0..i1 [rad]."""
        return np.cumsum(np.abs(self.drive[i0:i1 + 1])) * self.dt


def prepare(time_s, surface_rad_s, torque_Nm, torque_kind: str,
            top_drive_inertia_kg_m2: float) -> tuple[FitData, list[str]]:
    """The log on a uniform time base (missing samples dropped, irregular ones resampled)
    with its smoothed series; returns the data and a note per repair."""
    t = np.asarray(time_s, dtype=float)
    w = np.asarray(surface_rad_s, dtype=float)
    tau = np.asarray(torque_Nm, dtype=float)
    if t.ndim != 1 or w.shape != t.shape or tau.shape != t.shape:
        raise InputError("batch refinement needs equal-length time, speed and torque series")
    ok = np.isfinite(t) & np.isfinite(w) & np.isfinite(tau)
    t, w, tau = t[ok], w[ok], tau[ok]
    if t.size < 3:
        raise InputError(f"batch refinement needs at least 3 samples; its window holds "
                         f"{t.size}", fix="a longer [batch] window_s, or a faster log")
    if np.any(np.diff(t) <= 0):
        raise InputError("batch refinement needs samples at increasing times",
                         fix="sort the record by time and drop duplicate samples")
    notes = [] if ok.all() else [f"{int((~ok).sum())} samples with missing values dropped"]
    dt = float(np.median(np.diff(t)))
    if np.max(np.abs(np.diff(t) - dt)) > 0.01 * dt:
        grid = t[0] + dt * np.arange(int(np.floor((t[-1] - t[0]) / dt)) + 1)
        w, tau, t = np.interp(grid, t, w), np.interp(grid, t, tau), grid
        notes.append(f"irregular sampling resampled to {1 / dt:g} Hz")
    itd = top_drive_inertia_kg_m2
    tau_s = measured_string_torque(t, w, tau, torque_kind, itd, TORQUE_SMOOTH_S)
    tau_m = tau if torque_kind == "motor" else \
        tau - measured_string_torque(t, w, np.zeros_like(tau), "motor", itd, TORQUE_SMOOTH_S)
    data = FitData(t=t, dt=dt, drive=smooth(w, dt, DRIVE_SMOOTH_S),
                   motor=smooth(tau_m, dt, DRIVE_SMOOTH_S),
                   creep_drive=smooth(w, dt, CREEP_DRIVE_SMOOTH_S),
                   w_bar=smooth(w, dt, max(TORQUE_SMOOTH_S, 3 * dt)), tau=tau_s,
                   tau_bar=smooth(tau_s, dt, TORQUE_SMOOTH_S), speed=w,
                   inertia_bar=smooth(tau - tau_s, dt, TORQUE_SMOOTH_S)
                   if torque_kind == "motor" else None)
    return data, notes


@dataclass(frozen=True)
class Window:
    """Simulate samples [sim0, end] from rest; compare over ``used`` (sample indices)."""

    sim0: int
    end: int
    used: np.ndarray
    creep: bool = False  # driven by the creep-smoothed speed


class RunCounter:
    """Model runs spent on one record, shared by a model and its copies."""

    def __init__(self, progress: Callable[[float], None] | None = None):
        self.runs = 0
        self.progress = progress

    def tick(self) -> None:
        self.runs += 1
        if self.progress is not None:
            self.progress(1.0)


class Model:
    """The plant driven by the log, on grids of any resolution; counts its runs (docs/theory.md
    §6.4). Creeps follow the logged speed; rotation replays the identified drive in closed
    loop (``drive``, :mod:`drillfric.estimation.drive`), else follows the logged speed too.

    Each window starts from rest, holding the twist the measured torque says the string has
    there (:meth:`drillfric.torsional.State.wound`; none after a released stop).

    With ``axial`` (a reaming segment's pipe speed v(t), docs/theory.md §3.3) every run splits
    the Coulomb force between the torque and the drag at the contact radius of each cell
    (:func:`drillfric.torsional.contact_radius`)."""

    def __init__(self, string, fc_fn, settings: BatchSettings, data: FitData,
                 progress: Callable[[float], None] | None = None,
                 profile: FrictionProfile | None = None,
                 axial: torsional.Axial | None = None):
        self.string, self.fc_fn, self.data = string, fc_fn, data
        self.axial = axial
        self.settings = settings
        self.omega_c, self.k_t = settings.omega_c_rad_s, settings.k_t_per_s
        self.itd = settings.top_drive_inertia_kg_m2
        self.profile = profile or FrictionProfile()
        self.cased_static = CASED_STATIC[0]  # the hypothesis for an unknown cased μ_s
        self.drive: DriveModel | None = None  # replayed in rotation when usable
        self.bit_torque_cap_Nm = 0.0  # Coulomb bit torque on bottom [N·m] (bit_torque.py)
        self.counter = RunCounter(progress)
        self._grids: dict[int, tuple[torsional.Grid, np.ndarray]] = {}

    @property
    def runs(self) -> int:
        """Model runs so far (this model and its copies)."""
        return self.counter.runs

    def assuming(self, cased_static: str) -> Model:
        """This model under another hypothesis for an unknown cased static factor (a copy
        sharing the grids and the run count)."""
        other = copy.copy(self)
        other.cased_static = cased_static
        return other

    def grid(self, cells: int) -> tuple[torsional.Grid, np.ndarray]:
        """The grid of ``cells`` cells and F_c on it [N·m/m] (cached)."""
        if cells not in self._grids:
            g = torsional.make_grid(self.string, cells)
            fc = np.broadcast_to(np.asarray(self.fc_fn(g.x_m), dtype=float), g.x_m.shape)
            self._grids[cells] = (g, np.ascontiguousarray(fc))
        return self._grids[cells]

    def t_n(self, cells: int) -> float:
        """T_N of the estimated part: ∫F_c dx where μ is estimated [N·m]."""
        return self.t_parts(cells)[0]

    def wind_up(self, cells: int) -> tuple[float, float]:
        """(Θ/T_N, 2L/c) of the string (docs/theory.md §6.4 "Start-up"): the twist of a
        string wound to break-away per N·m of top torque [rad/(N·m)], Θ/T_N =
        ∫₀ᴸ τ(x)/(G J) dx / τ(0) with τ(x) = ∫ₓᴸ F_c dξ, and the wave round trip [s]."""
        g, fc = self.grid(cells)
        cell = fc * g.dx_true_m
        below = np.cumsum(cell[::-1])[::-1] - 0.5 * cell  # below each cell's centre [N·m/μ]
        gj = g.zeta_Nms * np.repeat(g.wave_speed_m_s, np.diff(g.section_start))
        twist, t_n = float(np.sum(below * g.dx_true_m / gj)), float(np.sum(cell))
        return (twist / t_n if t_n > 0 else 0.0), 2.0 * g.travel_time_s

    def t_parts(self, cells: int) -> tuple[float, float]:
        """(T_N of the estimated part, kinetic torque of the fixed part) [N·m]."""
        g, fc = self.grid(cells)
        est, fix_k, _ = self.profile.parts(g.x_m, g.dx_true_m, fc, 1.0, 1.0)
        return float(np.sum(est * g.dx_true_m)), float(np.sum(fix_k * g.dx_true_m))

    def _initial(self, win: Window, g, fc, mu_k: float) -> torsional.State:
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

    def simulate(self, win: Window, mu_s: float, mu_k: float,
                 cells: int) -> tuple[np.ndarray, np.ndarray]:
        """String torque [N·m] and bit speed [rad/s] at samples sim0..end."""
        d = self.data
        g, fc = self.grid(cells)
        plant = self.profile.plant(g, fc, mu_s, mu_k, omega_c_rad_s=self.omega_c,
                                   k_t_per_s=self.k_t, top_drive_inertia_kg_m2=self.itd,
                                   bit_torque_cap_Nm=self.bit_torque_cap_Nm,
                                   cased_static=self.cased_static)
        if self.axial is not None:
            plant = replace(plant, contact_radius_m=torsional.contact_radius(self.string, g))
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
        rec, _ = torsional.run(plant, drive, t[-1] - t[0], 1.0 / d.dt, state,
                               axial=self.axial)
        self.counter.tick()
        return (np.interp(t, rec.time_s, rec.string_torque_Nm),
                np.interp(t, rec.time_s, rec.bit_rad_s))


def as_fc_fn(fc_Nm_m) -> Callable[[np.ndarray], np.ndarray]:
    """F_c(x) [N·m/m] as a function of measured depth (a constant made one)."""
    if callable(fc_Nm_m):
        return fc_Nm_m
    value = float(fc_Nm_m)
    return lambda x: np.full(np.shape(x), value)


def fluctuation(tau_bar: np.ndarray) -> float:
    """std/|mean| of a smoothed torque: the stick-slip measure of the data [-]."""
    mean = abs(float(np.mean(tau_bar)))
    return float(np.std(tau_bar)) / mean if mean > 0 else 0.0


def fluctuation_range(data: FitData, used: np.ndarray,
                      inertia_factors: tuple[float, float]) -> tuple[float, float]:
    """The smoothed string torque's :func:`fluctuation` over the samples ``used`` with the
    top-drive inertia taken ``inertia_factors`` × the configured — (least, most) [-]. A
    motor torque's stick-slip swing partly rests on the inertia subtracted (eq. 7 of the
    paper): with the gear's inertia unknown, a swing that vanishes at either end of the
    range is no evidence of stick-slip. A string torque has one value."""
    if data.inertia_bar is None:
        value = fluctuation(data.tau_bar[used])
        return value, value
    values = [fluctuation(data.tau_bar[used] + (1.0 - f) * data.inertia_bar[used])
              for f in (1.0, *inertia_factors)]
    return min(values), max(values)


def sticks(bit_rad_s: np.ndarray, omega_c: float) -> bool:
    """Whether the model's bit sticks: a share of samples near rest (docs/theory.md §6.4)."""
    return bool(np.mean(np.abs(bit_rad_s) <= REST_BIT * omega_c) >= STUCK_FRACTION)


def start_up_end(tau_Nm, turned_rad, dt_s: float, rad_per_Nm: float,
                 round_trip_s: float) -> int | None:
    """First sample past the start-up transient of a rotation that starts from rest, or
    None when the series ends first (docs/theory.md §6.4 "Start-up").

    The bit cannot break free before the top drive has turned the twist of the string
    wound to its break-away torque, τ_b·Θ/T_N (:meth:`Model.wind_up`), and τ_b is at most
    the highest 1-s smoothed torque of the series; one wave round trip later the release
    of the bit has reached the top and come back.

    Parameters
    ----------
    tau_Nm : array_like
        String torque at the top from the run's start [N·m].
    turned_rad : array_like
        Angle the top drive has turned by each sample [rad].
    dt_s : float
        Sample interval [s].
    rad_per_Nm : float
        Θ/T_N, twist of the wound string per N·m of top torque [rad/(N·m)].
    round_trip_s : float
        Wave round trip 2L/c [s].

    Examples
    --------
    >>> tau = np.r_[np.linspace(0.0, 10.0, 11), np.full(10, 8.0)]
    >>> start_up_end(tau, np.arange(21.0), 1.0, 1.0, 2.0)
    12
    >>> start_up_end(tau, np.arange(21.0), 1.0, 2.0, 2.0) is None
    True
    """
    tau = np.abs(np.asarray(tau_Nm, dtype=float))
    peak = float(np.max(smooth(tau, dt_s, TORQUE_SMOOTH_S)))
    wound = np.flatnonzero(np.abs(np.asarray(turned_rad, dtype=float)) >= peak * rad_per_Nm)
    if wound.size == 0:
        return None
    end = int(wound[0] + np.ceil(round_trip_s / dt_s - 1e-9))
    return end if end < tau.size else None


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
    up = up_crossings(x, dt_s)
    return slice(int(up[0]), int(up[-1])) if up.size >= 2 else slice(0, x.size)


def up_crossings(tau_Nm, dt_s: float) -> np.ndarray:
    """Samples where the 1-s smoothed torque crosses its mean upwards: the bounds of the
    whole torque cycles of a series (one fewer cycles than crossings).

    Examples
    --------
    >>> up_crossings(np.sin(np.linspace(0.0, 5.5 * np.pi, 100)), 1.0).tolist()
    [1, 37, 73]
    """
    xb = smooth(np.asarray(tau_Nm, dtype=float), dt_s, TORQUE_SMOOTH_S)
    return np.flatnonzero((xb[:-1] < xb.mean()) & (xb[1:] >= xb.mean())) + 1


def torque_pieces(tau_Nm, dt_s: float) -> tuple[list[tuple[int, int]], bool]:
    """The pieces whose means scatter like the mean torque's error, and whether they are
    steady blocks: the whole torque
    cycles (:func:`up_crossings`), or — for a steady rotation (1-s smoothed torque
    fluctuating by at most ``STICK_SLIP_FLUCTUATION``) with fewer than :data:`MIN_CYCLES`
    of them — blocks of :data:`STEADY_BLOCK_S` (docs/theory.md §6.4 "Uncertainty of μ_k":
    a steady torque has no cycles, its mean's error is the scatter of its block means,
    drift included).

    Examples
    --------
    >>> pieces, steady = torque_pieces(np.full(200, 8e3) + np.linspace(0.0, 1.0, 200), 0.2)
    >>> len(pieces), steady
    (8, True)
    >>> torque_pieces(np.sin(np.linspace(0.0, 5.5 * np.pi, 100)), 1.0)
    ([(1, 37), (37, 73)], False)
    """
    x = np.asarray(tau_Nm, dtype=float)
    up = up_crossings(x, dt_s)
    cycles = [(int(a), int(b)) for a, b in zip(up[:-1], up[1:], strict=True)]
    if len(cycles) >= MIN_CYCLES or \
            fluctuation(smooth(x, dt_s, TORQUE_SMOOTH_S)) > STICK_SLIP_FLUCTUATION:
        return cycles, False
    n = max(int(round(STEADY_BLOCK_S / dt_s)), 2)
    return [(i * n, (i + 1) * n) for i in range(x.size // n)], True


def cycle_mean(series: list[np.ndarray], dt_s: float) -> float:
    """Mean over the whole cycles of each window, pooled [N·m]."""
    return float(np.mean(np.concatenate([x[whole_cycles(x, dt_s)] for x in series])))


def cycle_mean_error(series: list, dt_s: float) -> tuple[float, int] | None:
    """Standard error of :func:`cycle_mean` from the scatter of its cycles [N·m], and the
    number of whole cycles; None with fewer than :data:`MIN_CYCLES` (docs/theory.md §6.4
    "Uncertainty of μ_k").

    ``series`` holds each window's torque, or a list of its parts where samples were left
    out (held readings): the parts' cycles pool, and a steady window's drift is taken over
    its parts together. Each whole torque cycle (between upward crossings of the 1-s
    smoothed torque through its mean) gives one mean; the pooled mean is their
    length-weighted average, and its standard error the ratio estimator's,
    √Σ(Lᵢ(mᵢ − m))² / ΣLᵢ. A steady series cut in blocks (:func:`torque_pieces`) adds its
    drift in quadrature — the difference of its halves' means: blocks of a torque still
    settling are not independent samples of its level.

    Examples
    --------
    >>> t = np.arange(0.0, 100.0, 0.1)
    >>> x = 1e4 + 2e3 * np.sin(2 * np.pi * t / 5.0)
    >>> err, n = cycle_mean_error([x], 0.1)
    >>> err < 1.0, n
    (True, 18)
    """
    means, lengths, drift = [], [], 0.0
    for window in series:
        parts = [np.asarray(x, dtype=float) for x in
                 (window if isinstance(window, list) else [window])]
        steady = False
        for x in parts:
            pieces, part_steady = torque_pieces(x, dt_s)
            means += [float(np.mean(x[a:b])) for a, b in pieces]
            lengths += [float(b - a) for a, b in pieces]
            steady |= part_steady
        if steady:  # the settling of the window's level, over all its parts
            x = np.concatenate(parts)
            half = x.size // 2
            drift = max(drift, abs(float(np.mean(x[:half]) - np.mean(x[half:]))))
    if len(means) < MIN_CYCLES:
        return None
    m, w = np.asarray(means), np.asarray(lengths)
    mean = float(np.sum(w * m) / np.sum(w))
    scatter = float(np.sqrt(np.sum((w * (m - mean)) ** 2)) / np.sum(w))
    return float(np.hypot(scatter, drift)), len(means)
