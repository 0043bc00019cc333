"""The speed-driven fit of one record: the stages wired together (docs/theory.md §6.4).

:func:`refine` runs the μ_k stage (:mod:`.kinetic`), then μ_s from a creep
(:mod:`.creep_fit`, checked by :mod:`.creep_checks`) where one was logged fast enough, else
the stick-slip-onset bound (:mod:`.onset`); each stage returns a frozen outcome and
:func:`refine` alone assembles the :class:`BatchResult`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from drillfric import torsional
from drillfric.drillstring import DrillString
from drillfric.estimation import relaxation
from drillfric.estimation.batch.creep_checks import CreepChecks
from drillfric.estimation.batch.creep_fit import CreepOutcome, fit_creeps
from drillfric.estimation.batch.harness import (
    Model,
    Window,
    as_fc_fn,
    cycle_mean,
    cycle_mean_error,
    fluctuation,
    fluctuation_range,
    prepare,
)
from drillfric.estimation.batch.kinetic import (
    KineticOutcome,
    fit_kinetic,
    refit_kinetic,
    rotating_windows,
    viscous_torque_Nm,
)
from drillfric.estimation.batch.onset import BoundOutcome, onset_bound
from drillfric.estimation.batch.settings import (
    GEAR_RANGE,
    MIN_CREEP_RATE_HZ,
    MU_K_REFIT_MOVE,
    STEADY_BLOCK_S,
    STICK_SLIP_FLUCTUATION,
    TORQUE_SMOOTH_S,
    BatchSettings,
    mu_k_tolerance,
)
from drillfric.estimation.creep import find_creeps, rotating_runs, true_runs
from drillfric.estimation.drive import DriveModel
from drillfric.estimation.drive import identify as identify_drive
from drillfric.friction import FrictionProfile
from drillfric.result import Flag


@dataclass(frozen=True)
class BatchDetails:
    """Traces of a speed-driven fit (diagnostics and tests).

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
    mu_k_sigma : float or None
        Statistical 1-σ uncertainty of μ_k [-]: √2 × the standard error of the data's
        whole-cycle mean torque over T_N (the model's mean scatters as much); None with fewer
        than 3 whole cycles (docs/theory.md §6.4).
    torque_cycles : int
        Whole torque cycles the uncertainty rests on.
    mu_k_damping : float or None
        Half-width of μ_k [-] from the viscous damping assumed (:func:`damping_half_width`).
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
    mu_k_sigma: float | None = None
    torque_cycles: int = 0
    mu_k_damping: float | None = None


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
    flags : tuple of Flag
        e.g. ``bistable_regime``, ``creep_not_grid_converged``, ``mu_k_not_converged``,
        ``no_rotation``, ``rotation_too_short``, ``regime_mismatch``, ``creep_fit_at_bound``,
        ``creep_rate_too_low``, ``stick_slip_not_reproduced`` (docs/outputs.md).
    runs : int
        Model runs spent.
    messages : tuple of str
        One line per notable decision, for the report.
    interval_note : str or None
        The note stating μ_k's 95 % interval (its half-width and statistical part), kept apart
        from ``messages``: a segment states it only where its μ_k is converged.
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
    flags: tuple[Flag, ...]
    runs: int
    messages: tuple[str, ...]
    interval_note: str | None = None
    details: BatchDetails = field(default_factory=BatchDetails)


def model_string_torque(time_s, surface_rad_s, torque_Nm, *, string: DrillString, fc_Nm_m,
                        settings: BatchSettings, mu_s: float, mu_k: float,
                        torque_kind: str = "motor", cells: int = 500,
                        profile: FrictionProfile | None = None, bit_torque_Nm: float = 0.0,
                        axial: torsional.Axial | None = None
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The fitted model against the data over a whole record (the evidence of a fit).

    The speed-driven plant of docs/theory.md §6.4 at (μ_s, μ_k), driven by the measured
    top-drive speed from rest over the whole record, as :func:`refine`'s fits are; with
    ``bit_torque_Nm`` > 0 a Coulomb bit of that torque [N·m] (docs/theory.md §2.3); with
    ``axial`` the pipe moving at v(t) as it turns (docs/theory.md §3.3).

    Returns
    -------
    time_s, measured_Nm, model_Nm : ndarray
        Sample times on the record's uniform grid [s], the measured string torque and the
        model's string torque at the top [N·m].
    """
    data, _ = prepare(time_s, surface_rad_s, torque_Nm, torque_kind,
                      settings.top_drive_inertia_kg_m2)
    model = Model(string, as_fc_fn(fc_Nm_m), settings, data, None, profile, axial)
    model.bit_torque_cap_Nm = max(float(bit_torque_Nm), 0.0)
    whole = Window(0, data.t.size - 1, np.arange(data.t.size))
    tau, _ = model.simulate(whole, max(mu_s, mu_k), mu_k, cells)
    return data.t, data.tau, tau


def refine(time_s, surface_rad_s, torque_Nm, *, string: DrillString, fc_Nm_m,
           settings: BatchSettings, torque_kind: str = "motor", cells: int = 500,
           mu_s_seed: float | None = None,
           progress: Callable[[float], None] | None = None,
           profile: FrictionProfile | None = None,
           sample_interval_s: float | None = None,
           axial: torsional.Axial | None = None, unobserved_s: tuple = ()) -> BatchResult:
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
    settings : BatchSettings
        ω_c, k_t, I_TD and the search settings of the configuration.
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
    axial : drillfric.torsional.Axial, optional
        The pipe's axial speed v(t) of a reaming segment (docs/theory.md §3.3): the model
        splits the friction at every run, and μ_s is not looked for — no creep fit, no onset
        bound: with |v| > ω_c·r_c no cell sticks, and what sticks below that is not told
        apart from μ_k by the mean torque (the verdict says so,
        :func:`drillfric.estimation.verdict.decide`).
    unobserved_s : tuple of (float, float)
        [s] Spans whose samples held an earlier reading (EDR defects): the whole-cycle mean
        torque and its error are taken from the cycles outside them (a 10-s hold in
        stick-slip is one "cycle" of another mean, which had left μ_k unconverged).

    Returns
    -------
    BatchResult
    """
    data, messages = prepare(time_s, surface_rad_s, torque_Nm, torque_kind,
                             settings.top_drive_inertia_kg_m2)
    model = Model(string, as_fc_fn(fc_Nm_m), settings, data, progress, profile, axial)
    omega_c = settings.omega_c_rad_s
    creeps = [] if axial is not None else find_creeps(data.t, data.drive, omega_c,
                                                       torque_Nm=data.tau,
                                                       smooth_s=TORQUE_SMOOTH_S)
    wins, notes = rotating_windows(data, settings, *model.wind_up(cells))
    messages += notes
    flags: list[Flag] = []
    rotation = _Rotation.of(model, wins, unobserved_s)
    kinetic = cycles = None
    if wins:
        cycles = relaxation.find(data.t, data.speed, data.tau_bar, omega_c, rotation.target_Nm,
                                 rotation.mean_speed_rad_s)
        if cycles is not None:
            flags.append(Flag.RELAXATION_CYCLES)
            messages.append(cycles.describe(max(data.dt, sample_interval_s or 0.0)))
        model.drive = identify_drive(data.t, data.drive, data.motor, [w.used for w in wins])
        if model.drive is not None:
            messages.append(model.drive.describe())
        kinetic = fit_kinetic(model, wins, rotation.target_Nm, rotation.stick_slip, mu_s_seed,
                              cells)
        flags += kinetic.flags
        messages += kinetic.messages
    elif any(np.any(data.w_bar[i0:i1 + 1] > omega_c)
             for i0, i1 in rotating_runs(data.w_bar, omega_c)):
        flags.append(Flag.ROTATION_TOO_SHORT)
    else:
        flags.append(Flag.NO_ROTATION)
    static = _static_stages(model, creeps, wins, kinetic, rotation, cells,
                            rate_hz=1.0 / max(data.dt, sample_interval_s or 0.0),
                            moving=axial is not None)
    flags += static.flags
    messages += static.messages
    interval = damping = None
    if static.kinetic is not None:
        damping = damping_half_width(model, wins, cells)
    if static.kinetic is not None and rotation.target_error is not None:
        interval = _uncertainty_note(model, rotation, static.kinetic.mu_k, cells,
                                     max(data.dt, sample_interval_s or 0.0), damping)
    return BatchResult(
        mu_k=None if static.kinetic is None else static.kinetic.mu_k,
        mu_k_method="mean_torque", mu_s=static.mu_s, mu_s_identifiable=static.mu_s is not None,
        mu_s_lower_bound=static.bound, mu_s_method=static.method,
        creep_segments=static.creeps, flags=tuple(flags), runs=model.runs,
        messages=tuple(messages), interval_note=interval,
        details=_details(model, cells, creeps, rotation, static, cycles, damping))


@dataclass(frozen=True)
class _Rotation:
    """What the rotating windows of the data show: the whole-cycle mean string torque
    [N·m], its fluctuation over the later half of each window [-], whether the data
    stick-slip, and the mean top-drive speed (a PI drive's set-point) [rad/s]
    (None/False/0 without windows)."""

    target_Nm: float | None = None
    fluctuation: float | None = None
    stick_slip: bool = False
    mean_speed_rad_s: float = 0.0
    target_error: tuple[float, int] | None = None  # (standard error [N·m], whole cycles)

    @classmethod
    def of(cls, model: Model, wins: list[Window], unobserved_s: tuple = ()) -> _Rotation:
        if not wins:
            return cls()
        d = model.data
        used = np.concatenate([w.used for w in wins])
        # the regime where the start-up has had longest to die out: the later half of each
        # window (a steady rotation's release still rings early on, docs/theory.md §6.4)
        fluct = fluctuation(d.tau_bar[np.concatenate([w.used[w.used.size // 2:]
                                                      for w in wins])])
        parts = [[d.tau[piece] for piece in _observed(d.t, w.used, unobserved_s)]
                 for w in wins]
        return cls(cycle_mean([x for p in parts for x in p], d.dt), fluct,
                   fluct > STICK_SLIP_FLUCTUATION, float(np.mean(d.speed[used])),
                   cycle_mean_error(parts, d.dt))


def _later_fluctuation_range(model: Model, wins: list[Window]) -> tuple[float, float]:
    """:func:`~.harness.fluctuation_range` over the later half of each window (where
    :meth:`_Rotation.of` judges the regime) and the inertia range of a gear change."""
    later = np.concatenate([w.used[w.used.size // 2:] for w in wins])
    return fluctuation_range(model.data, later, GEAR_RANGE)


def _observed(t: np.ndarray, used: np.ndarray, unobserved_s: tuple) -> list[np.ndarray]:
    """``used`` (sample indices) cut where their times ``t`` [s] fall in an ``unobserved_s``
    span, those samples left out: the contiguous pieces."""
    if not unobserved_s:
        return [used]
    out = np.zeros(used.size, dtype=bool)
    for a, b in unobserved_s:
        out |= (t[used] >= a) & (t[used] <= b)
    return [used[i0:i1 + 1] for i0, i1 in true_runs(~out)]


@dataclass(frozen=True)
class _Static:
    """What the μ_s stages found: μ_s or a bound, the method, the creeps used, the μ_k
    outcome after a possible refit, and each stage's outcome (None: not run)."""

    mu_s: float | None
    kinetic: KineticOutcome | None
    bound: float | None = None
    method: str = "none"
    creeps: tuple = ()
    creep: CreepOutcome | None = None
    onset: BoundOutcome | None = None
    flags: tuple[Flag, ...] = ()
    messages: tuple[str, ...] = ()


def _static_stages(model: Model, creeps, wins: list[Window], kinetic: KineticOutcome | None,
                   rotation: _Rotation, cells: int, *, rate_hz: float,
                   moving: bool = False) -> _Static:
    """μ_s of a record: the creep fit where a creep was logged fast enough and passes its
    checks (μ_k refitted when the fitted μ_s moves the stick-slip model), else the
    stick-slip onset bound (docs/theory.md §6.3–§6.4); none while the pipe moves axially
    (``moving``, docs/theory.md §3.3)."""
    flags, messages = [], []
    mu_s, method, used, creep, onset = None, "none", (), None, None
    if creeps and rate_hz < MIN_CREEP_RATE_HZ:
        flags.append(Flag.CREEP_RATE_TOO_LOW)
        messages.append(f"creep start-up found but logged at {rate_hz:.3g} Hz: the creep "
                        f"fit needs ≥ {MIN_CREEP_RATE_HZ:g} Hz (speed noise integrated into "
                        "the twist); μ_s not fitted")
    elif kinetic is not None and creeps:
        creep = fit_creeps(model, creeps, kinetic.mu_k, cells, wins, rotation.stick_slip)
        flags += creep.flags
        messages += creep.messages
        mu_s, used = creep.mu_s, creep.creeps
        if mu_s is not None:
            method = "creep_fit"
            if rotation.stick_slip and abs(mu_s / kinetic.mu_s_model - 1.0) > MU_K_REFIT_MOVE:
                refit = refit_kinetic(model, wins, rotation.target_Nm, mu_s, kinetic, cells)
                if refit is not None:
                    kinetic = refit
                    messages += refit.messages
    if mu_s is None and kinetic is not None and rotation.stick_slip and not moving:
        low, high = _later_fluctuation_range(model, wins)
        if low > STICK_SLIP_FLUCTUATION:
            onset = onset_bound(model, wins, kinetic.mu_k, cells, bool(creeps))
            flags += onset.flags
            messages += onset.messages
            method = "stick_slip_onset" if onset.bound is not None else "none"
        else:
            messages.append(
                "no μ_s bound from the stick-slip onset: the motor torque's swing, "
                f"{low:.2f}–{high:.2f} of its mean with the top-drive inertia "
                f"{GEAR_RANGE[0]:g}–{GEAR_RANGE[1]:g}× rig.top_drive_inertia_kg_m2 (a gear "
                "change), rests on the inertia subtracted: the string may not stick-slip at "
                "all (docs/theory.md §6.4)")
    if mu_s is None and not rotation.stick_slip and kinetic is not None and not creeps \
            and not moving:
        messages.append("no stick-slip and no creep start-up: μ_s is not in the data; a creep "
                        "break-over from rest (below ω_c for 10–30 s) would make it measurable")
    return _Static(mu_s, kinetic, None if onset is None else onset.bound, method, used, creep,
                   onset, tuple(flags), tuple(messages))


def _mu_k_sigma(model: Model, rotation: _Rotation, cells: int) -> float | None:
    """1-σ statistical uncertainty of μ_k [-] (docs/theory.md §6.4 "Uncertainty of μ_k"): the
    data's whole-cycle mean torque is known to its standard error, the model's — another
    realisation of the same chaotic cycles — to as much, and the mean moves by T_N per unit
    μ_k."""
    if rotation.target_error is None:
        return None
    return float(np.sqrt(2.0) * rotation.target_error[0] / model.t_n(cells))


def damping_half_width(model: Model, wins: list, cells: int) -> float:
    """Half-width of μ_k [-] from the viscous damping the model assumes (docs/theory.md §6.4
    "Uncertainty of μ_k"): the mean torque's viscous part k_t·J·ω̄ (J the string's polar
    mass moment, ω̄ the mean speed of the rotation fitted) is taken as friction in
    proportion where the true damping differs; with the truth within k_t/f … f·k_t
    (``model.k_t_uncertainty_factor``) μ_k moves by up to (f − 1)·k_t·J·ω̄ / T_N (heavier
    damping read as friction; the lighter side moves it less, (1 − 1/f)·…).

    Three times the configured damping had put μ_k 9 % high at 100 Hz, outside its stated
    5 % (issue 34); on the demo the viscous part is 1.4–1.9 % of the friction torque."""
    factor = model.settings.k_t_uncertainty_factor
    return float((factor - 1.0) * abs(viscous_torque_Nm(model, wins, cells))
                 / model.t_parts(cells)[0])


def _uncertainty_note(model: Model, rotation: _Rotation, mu_k: float, cells: int,
                      sample_interval_s: float | None, damping: float | None = None) -> str:
    """The message stating μ_k's 95 % half-width — its statistical 2σ, never below the
    validated tolerance of the logging (:func:`~drillfric.estimation.batch.settings.
    mu_k_tolerance`: model-form error included) combined with what the assumed damping may
    move it by (:func:`damping_half_width`; independent errors, in quadrature) — and the
    statistical part."""
    two_sigma = 2.0 * _mu_k_sigma(model, rotation, cells)
    tolerance = mu_k_tolerance(sample_interval_s)
    floor = float(np.hypot(tolerance * mu_k, damping or 0.0))
    half = max(two_sigma, floor)
    err, n = rotation.target_error
    factor = model.settings.k_t_uncertainty_factor
    why = ("its statistical 2σ" if two_sigma >= floor else
           f"the validated {100 * tolerance:.0f} % of this logging, model-form error included"
           + (f", and ±{damping:.3f} for the viscous damping assumed (k_t within ×1/{factor:g}"
              f"…×{factor:g}, model.k_t_uncertainty_factor)" if damping else ""))
    return (f"μ_k = {mu_k:.3f} ± {half:.3f} (95 %: {why}; statistical 2σ ± {two_sigma:.3f}, "
            f"±{100 * two_sigma / mu_k:.1f} %: the mean torque of {n} whole cycles (or "
            f"{STEADY_BLOCK_S:g}-s blocks of steady rotation) is known to ±{err:.0f} N·m (1σ), "
            "the model's as well)")


def _details(model: Model, cells: int, creeps, rotation: _Rotation, static: _Static,
             cycles: relaxation.RelaxationCycles | None,
             damping: float | None = None) -> BatchDetails:
    """The traces of a fit from its stages' outcomes."""
    kinetic, creep = static.kinetic, static.creep
    return BatchDetails(
        cells=cells, T_N_Nm=model.t_n(cells), creeps_found=creeps,
        mean_torque_Nm=rotation.target_Nm, torque_fluctuation=rotation.fluctuation,
        stick_slip=rotation.stick_slip,
        mu_k_trace=[] if kinetic is None else kinetic.trace,
        mu_k_residual_Nm=None if kinetic is None else kinetic.residual_Nm,
        mu_s_model=None if kinetic is None else kinetic.mu_s_model,
        creep_fits=[] if creep is None else list(creep.fits),
        creep_grid_move=None if creep is None else creep.grid_move,
        creep_checks=None if creep is None else creep.checks,
        onset_scan=[] if static.onset is None else static.onset.scan, drive=model.drive,
        relaxation=cycles, mu_k_sigma=_mu_k_sigma(model, rotation, cells),
        torque_cycles=0 if rotation.target_error is None else rotation.target_error[1],
        mu_k_damping=damping)
