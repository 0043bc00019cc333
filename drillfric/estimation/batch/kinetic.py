"""μ_k of a record by mean-torque matching, with the model in the data's regime
(docs/theory.md §6.4).

The whole-cycle mean of the measured string torque over the rotating samples (each run's
start-up transient left out, :func:`~drillfric.estimation.batch.harness.start_up_end`) is
matched by the model's
with a secant root find whose slope is bounded and which returns a point it evaluated: the
model's mean jitters between runs because stick-slip is chaotic.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from drillfric.estimation.batch.harness import (
    FitData,
    Model,
    Window,
    cycle_mean,
    start_up_end,
    sticks,
    torque_pieces,
)
from drillfric.estimation.batch.settings import (
    MIN_CYCLES,
    MU_K_CLAIM,
    MU_K_MAX_RUNS,
    MU_K_TOLERANCE,
    PRE_ROLL_S,
    PROVISIONAL_RATIO,
    STEADY_BLOCK_S,
    BatchSettings,
)
from drillfric.estimation.creep import bridge_loaded_dips, rotating_runs
from drillfric.io.text import plural
from drillfric.result import Flag


def rotating_windows(data: FitData, settings: BatchSettings, rad_per_Nm: float,
                     round_trip_s: float) -> tuple[list[Window], list[str]]:
    """One window per rotating run that outlasts its start-up transient (:func:`start_up_end`
    with Θ/T_N ``rad_per_Nm`` [rad/(N·m)] and the wave round trip ``round_trip_s`` [s],
    docs/theory.md §6.4 "Start-up") by :data:`MIN_CYCLES` whole torque cycles, compared
    from there to the run's end; a loaded stop
    within ``settings.dip_max_s`` does not end a run (the segmentation's rule). Returns the
    windows and a note per run left out."""
    omega_c = settings.omega_c_rad_s
    pre = int(round(PRE_ROLL_S / data.dt))
    wins, notes = [], []
    for i0, i1 in bridge_loaded_dips(rotating_runs(data.w_bar, omega_c), data.t, data.tau_bar,
                                     max_dip_s=settings.dip_max_s,
                                     fraction=settings.dip_torque_fraction):
        if not np.any(data.w_bar[i0:i1 + 1] > omega_c):
            continue
        turned = data.turned_rad(i0, i1)
        end = start_up_end(data.tau[i0:i1 + 1], turned, data.dt, rad_per_Nm, round_trip_s)
        if end is None:
            peak = float(np.max(data.tau_bar[i0:i1 + 1]))
            notes.append(f"rotating run {data.t[i0]:.0f}–{data.t[i1]:.0f} s ended within its "
                         f"start-up: winding the string to {peak / 1e3:.1f} kN·m takes "
                         f"{peak * rad_per_Nm:.0f} rad of top-drive turning and a "
                         f"{round_trip_s:.1f}-s wave round trip, the run turned "
                         f"{turned[-1]:.0f} rad: not used for μ_k")
            continue
        cycles = len(torque_pieces(data.tau[i0 + end:i1 + 1], data.dt)[0])
        if cycles < MIN_CYCLES:
            notes.append(f"rotating run {data.t[i0]:.0f}–{data.t[i1]:.0f} s holds "
                         f"{plural(max(cycles, 0), 'whole torque cycle')} after its start-up "
                         f"(ended "
                         f"{data.t[i0 + end] - data.t[i0]:.0f} s in), fewer than "
                         f"{MIN_CYCLES} (or {MIN_CYCLES} {STEADY_BLOCK_S:g}-s blocks of steady "
                         "rotation): its mean torque has no stated uncertainty, not used "
                         "for μ_k")
            continue
        wins.append(Window(max(0, i0 - pre), i1, np.arange(i0 + end, i1 + 1)))
    return wins, notes


def secant(residual: Callable[[float], float], x0: float, slope0: float, lo: float,
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
        step = (trace[-1][1] - r) / (x_new - x)
        slope = float(np.clip(step, 0.5 * slope0, 2.0 * slope0))
    best = min(trace, key=lambda p: abs(p[1]))
    return best[0], best[1], trace


def _pooled_mean(model: Model, wins: list[Window], mu_s: float, mu_k: float,
                 cells: int) -> tuple[float, np.ndarray]:
    """Whole-cycle mean model torque over the used samples of all windows [N·m], and the
    bits' speeds there [rad/s]; samples within the model's own start-up (its highest torque
    may wind the string further than the data's, :func:`start_up_end`) are left out."""
    taus, bits = [], []
    rad_per_Nm, round_trip_s = model.wind_up(cells)
    for w in wins:
        tau, bit = model.simulate(w, mu_s, mu_k, cells)
        own = start_up_end(tau, model.data.turned_rad(w.sim0, w.end), model.data.dt,
                           rad_per_Nm, round_trip_s)
        keep = w.used - w.sim0
        if own is not None and np.any(keep >= own):
            keep = keep[keep >= own]
        taus.append(tau[keep])
        bits.append(bit[keep])
    return cycle_mean(taus, model.data.dt), np.concatenate(bits)


@dataclass(frozen=True)
class MeanTorqueFit:
    """One root find of μ_k (model μ_s a function of μ_k).

    Attributes
    ----------
    mu_k : float
        The evaluated μ_k with the smallest residual [-].
    residual_Nm : float
        Model minus measured whole-cycle mean torque there [N·m].
    trace : list of (float, float)
        (μ_k, residual [N·m]) of every model run.
    sticks : bool
        Whether the model's bit sticks at that μ_k.
    """

    mu_k: float
    residual_Nm: float
    trace: list
    sticks: bool


def fit_mean_torque(model: Model, wins, target_Nm: float,
                    mu_s_of: Callable[[float], float], x0: float, cells: int) -> MeanTorqueFit:
    """μ_k matching the mean torque ``target_Nm`` [N·m], searched on [0.001, μ_max]."""
    t_n = model.t_n(cells)
    stuck = {}

    def residual(mu_k: float) -> float:
        mean, bit = _pooled_mean(model, wins, max(mu_s_of(mu_k), mu_k), mu_k, cells)
        stuck[mu_k] = sticks(bit, model.omega_c)
        return mean - target_Nm

    tol = max(0.01 * abs(target_Nm), 50.0)  # the chaotic jitter of the mean (§6.4)
    mu_k, res, trace = secant(residual, x0, t_n, 1e-3, model.settings.mu_max, tol)
    return MeanTorqueFit(mu_k, res, trace, stuck[mu_k])


@dataclass(frozen=True)
class KineticOutcome:
    """What the μ_k stage found (docs/theory.md §6.4).

    Attributes
    ----------
    mu_k : float
        The fitted kinetic friction factor [-].
    residual_Nm : float
        Mean-torque residual there [N·m].
    trace : list of (float, float)
        (μ_k, residual [N·m]) of every model run of the last root find.
    mu_s_model : float
        μ_s the model used at that μ_k (the regime value) [-].
    flags : tuple of Flag
    messages : tuple of str
    """

    mu_k: float
    residual_Nm: float
    trace: list
    mu_s_model: float
    flags: tuple[Flag, ...] = ()
    messages: tuple[str, ...] = ()


def viscous_torque_Nm(model: Model, wins: list[Window], cells: int) -> float:
    """The viscous part of the model's mean torque over the rotation fitted [N·m]:
    k_t·J·ω̄, J = ∫ρJ dx the string's polar mass moment, ω̄ the mean speed over ``wins``
    (docs/theory.md §3 eq. 2–3, §6.4)."""
    used = np.concatenate([w.used for w in wins])
    g = model.grid(cells)[0]
    inertia = float(np.sum(g.rho_j_kg_m * g.dx_true_m))
    return model.k_t * inertia * float(np.mean(model.data.w_bar[used]))


def fit_kinetic(model: Model, wins: list[Window], target_Nm: float, stick_slip: bool,
                mu_s_seed: float | None, cells: int) -> KineticOutcome:
    """μ_k by mean-torque matching with the model in the data's regime (docs/theory.md §6.4):
    stick-slip data are fitted with μ_s = :data:`PROVISIONAL_RATIO`·μ_k (then 4·μ_k if the
    model does not stick), steady data with μ_s = μ_k."""
    viscous = viscous_torque_Nm(model, wins, cells)
    t_est, t_fixed = model.t_parts(cells)
    top = model.settings.mu_max
    x0 = float(np.clip((target_Nm - viscous - t_fixed) / t_est, min(0.01, top), min(1.0, top)))
    tried = []
    for ratio in (PROVISIONAL_RATIO, 4.0) if stick_slip else (1.0,):
        def mu_s_of(mu_k, ratio=ratio):
            return max(ratio * mu_k, mu_s_seed or 0.0) if stick_slip else mu_k
        fit = fit_mean_torque(model, wins, target_Nm, mu_s_of, x0, cells)
        tried.append((ratio, fit.mu_k))
        if fit.sticks == stick_slip:
            break
        x0 = fit.mu_k
    flags, messages = [], []
    if len(tried) > 1 and abs(tried[-1][1] / tried[0][1] - 1.0) > MU_K_CLAIM:
        flags.append(Flag.MU_K_DEPENDS_ON_MU_S)
        messages.append(
            f"μ_k depends on the μ_s the model assumes: {tried[0][1]:.3f} with μ_s = "
            f"{tried[0][0]:g} μ_k (the model does not stick), {tried[-1][1]:.3f} with "
            f"{tried[-1][0]:g} μ_k — more than {100 * MU_K_CLAIM:.0f} % apart, and μ_s is not "
            "known: not converged")
    if fit.sticks != stick_slip:
        flags.append(Flag.REGIME_MISMATCH)
        messages.append("the model could not be put in the data's regime "
                        f"({'stick-slip' if stick_slip else 'steady rotation'}); μ_k may be "
                        "biased by a few %")
    res = fit.residual_Nm
    if abs(res) > MU_K_TOLERANCE * abs(target_Nm):
        flags.append(Flag.MU_K_NOT_CONVERGED)
        messages.append(f"mean torque matched only to {res:+.0f} N·m of {target_Nm:.0f} N·m"
                        + (f": μ_k ran to observer.mu_max = {top:g}, raise it" if
                           res < 0 and fit.mu_k >= 0.999 * top else ""))
    return KineticOutcome(fit.mu_k, res, fit.trace, mu_s_of(fit.mu_k), tuple(flags),
                          tuple(messages))


def refit_kinetic(model: Model, wins: list[Window], target_Nm: float, mu_s: float,
                  first: KineticOutcome, cells: int) -> KineticOutcome | None:
    """μ_k again with the creep μ_s in the model (same regime, better static part); None
    when the refit matches the mean torque worse (the first fit stands). The outcome's
    trace holds both fits' runs; its flags and messages are the refit's own."""
    fit = fit_mean_torque(model, wins, target_Nm, lambda _: mu_s, first.mu_k, cells)
    if not abs(fit.residual_Nm) <= max(abs(first.residual_Nm), MU_K_TOLERANCE * abs(target_Nm)):
        return None
    return KineticOutcome(min(fit.mu_k, mu_s), fit.residual_Nm, first.trace + fit.trace, mu_s,
                          messages=(f"μ_k refitted with the creep μ_s = {mu_s:.3f}",))
