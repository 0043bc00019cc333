"""μ_s from creep start-ups (docs/theory.md §6.3–§6.4).

A bounded 1-D minimisation of the smoothed torque misfit over the creeps at Δx ≤ MD/1000,
refitted with twice (then four times) the cells and reported only once it moves less than
:data:`CREEP_CONVERGENCE` and passes the checks of :mod:`.creep_checks`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import minimize_scalar

from drillfric.drillstring import DrillString
from drillfric.estimation.batch.creep_checks import (
    CreepChecks,
    checks_text,
    measure,
    parabola_vertex,
    problems,
)
from drillfric.estimation.batch.harness import FitData, Model, Window
from drillfric.estimation.batch.settings import (
    CREEP_CELLS_PER_MD,
    CREEP_CONVERGENCE,
    CREEP_DRIVE_SMOOTH_S,
    CREEP_LEVELS,
    CREEP_MAX_S,
    CREEP_MU_MIN,
    CREEP_STENCIL,
    GRID_SPREAD,
    PRE_ROLL_S,
    TORQUE_SMOOTH_S,
)
from drillfric.estimation.creep import smooth
from drillfric.friction import CASED_STATIC
from drillfric.io.text import plural
from drillfric.result import Flag


def creep_cells(string: DrillString, cells: int) -> int:
    """Cells giving Δx ≤ MD/1000 in every section (at least ``cells``)."""
    c = np.array([s.wave_speed_m_s for s in string.sections])
    travel = sum(s.length_m / s.wave_speed_m_s for s in string.sections)
    need = CREEP_CELLS_PER_MD * float(c.max()) * travel / string.bit_depth_m
    return max(cells, int(np.ceil(need / (1.0 - GRID_SPREAD))) + 1)


def creep_windows(data: FitData, creeps) -> list[Window]:
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
        wins.append(Window(max(0, i0 - pre), i1, np.arange(i0, i1 + 1), creep=True))
    return wins


def _misfit(model: Model, wins: list[Window], mu_k: float,
            cells: int) -> Callable[[float], float]:
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


def fit_creep(model: Model, wins: list[Window], mu_k: float, cells: int, lo: float,
              hi: float) -> tuple[float, int]:
    """μ_s minimising the smoothed torque misfit over the creeps (docs/theory.md §6.3–6.4):
    bounded 1-D minimisation (Brent) on [lo, hi]; returns (μ_s, runs)."""
    start = model.runs
    res = minimize_scalar(_misfit(model, wins, mu_k, cells), bounds=(lo, hi),
                          method="bounded", options={"xatol": 2e-3 * hi})
    return float(res.x), model.runs - start


def refit_creep(model: Model, wins: list[Window], mu_k: float, cells: int, centre: float,
                lo: float, hi: float) -> tuple[float, int]:
    """μ_s near ``centre`` on a finer grid; returns (μ_s, runs).

    The vertex of the misfit parabola through centre·(1 ± 4 %), all three points evaluated
    on this grid (borrowing the previous grid's curvature saved a run but the curvature
    changes by ~30 % between 2290 and 4573 cells, and it hid non-convexity). A vertex
    outside ±8 % or a non-convex parabola falls back to :func:`fit_creep` on ±10 %. The
    misfit of a creep is smooth in μ_s (no stick-slip, no chaos)."""
    start = model.runs
    misfit = _misfit(model, wins, mu_k, cells)
    x = centre * np.array([1.0 - CREEP_STENCIL, 1.0, 1.0 + CREEP_STENCIL])
    if x[0] >= lo and x[2] <= hi:
        j = np.array([misfit(x[0]), misfit(centre), misfit(x[2])])
        vertex, a = parabola_vertex(x, j)
        if a > 0 and abs(vertex / centre - 1.0) <= 2 * CREEP_STENCIL:
            return vertex, model.runs - start
    mu, _ = fit_creep(model, wins, mu_k, cells, max(lo, 0.9 * centre), min(hi, 1.1 * centre))
    return mu, model.runs - start


@dataclass(frozen=True)
class CreepOutcome:
    """What the creep stage found (docs/theory.md §6.3–§6.4).

    Attributes
    ----------
    mu_s : float or None
        The claimed static friction factor [-] (None: not grid-converged, at the search
        bound, or a check failed).
    creeps : tuple of (float, float)
        Creeps μ_s comes from, (t_start_s, t_end_s) [s] (empty without a μ_s).
    fits : list of (int, float, int)
        (cells, μ_s, model runs) of each grid level.
    grid_move : float or None
        Relative change of μ_s at the last grid refinement [-].
    checks : CreepChecks or None
        The evidence of the grid-converged fit.
    flags : tuple of Flag
    messages : tuple of str
    """

    mu_s: float | None
    creeps: tuple = ()
    fits: list = ()
    grid_move: float | None = None
    checks: CreepChecks | None = None
    flags: tuple[Flag, ...] = ()
    messages: tuple[str, ...] = ()


def fit_creeps(model: Model, creeps, mu_k: float, cells: int, rotating: list[Window],
               stick_slip: bool) -> CreepOutcome:
    """μ_s from the creeps at Δx ≤ MD/1000, refitted with doubled cells until it moves
    less than :data:`CREEP_CONVERGENCE`, then checked (:mod:`.creep_checks`) against the
    creeps and the ``rotating`` windows of the μ_k fit (``cells``)."""
    wins = creep_windows(model.data, creeps)
    n = creep_cells(model.string, cells)
    lo, hi = max(mu_k, CREEP_MU_MIN), model.settings.mu_max
    if lo >= hi:
        return CreepOutcome(None, flags=(Flag.CREEP_FIT_AT_BOUND,), messages=(
            f"no μ_s above μ_k = {mu_k:.3f} within observer.mu_max = {hi:g}: creep not "
            "fitted",))
    mu, runs = fit_creep(model, wins, mu_k, n, lo, hi)
    fits = [(model.grid(n)[0].n_cells, mu, runs)]
    if mu - lo < 0.01 * (hi - lo):
        return CreepOutcome(None, fits=fits, flags=(Flag.CREEP_FIT_AT_BOUND,), messages=(
            "creep fit ran to its lower bound (μ_s = μ_k): the break-over shows no static "
            "friction above the kinetic, not reported as identified",))
    if hi - mu < 0.01 * (hi - lo):
        return CreepOutcome(None, fits=fits, flags=(Flag.CREEP_FIT_AT_BOUND,), messages=(
            f"creep fit ran to its search bound (observer.mu_max = {hi:g}): not reported",))
    move = None
    for _ in range(CREEP_LEVELS - 1):
        n *= 2
        new, runs = refit_creep(model, wins, mu_k, n, mu, lo, hi)
        fits.append((model.grid(n)[0].n_cells, new, runs))
        move, mu = abs(new - mu) / new, new
        if move < CREEP_CONVERGENCE:
            found = (f"from {plural(len(creeps), 'creep start-up')} ({fits[-1][0]} cells; "
                     f"{100 * move:.1f} % change from {fits[-2][0]})")
            checks = measure(model, wins, mu, mu_k, n, rotating, stick_slip, cells)
            if not model.profile.static_known:
                other, _ = refit_creep(model.assuming(CASED_STATIC[1]), wins, mu_k, n, mu, lo,
                                       hi)
                checks = replace(checks, other_hypothesis=other)
            return _judged(mu, tuple(creeps), fits, move, checks, found)
    return CreepOutcome(None, fits=fits, grid_move=move,
                        flags=(Flag.CREEP_NOT_GRID_CONVERGED,),
                        messages=("creep μ_s not grid-converged (it moved "
                                  f"{100 * (move or 0.0):.1f} % between {fits[-2][0]} and "
                                  f"{fits[-1][0]} cells): not reported",))


def _judged(mu: float, creeps: tuple, fits: list, move: float, checks: CreepChecks,
            found: str) -> CreepOutcome:
    """The grid-converged fit ``mu``, claimed only when its checks find no problem."""
    failed = problems(mu, checks)
    if failed:
        return CreepOutcome(None, (), fits, move, checks, (Flag.MU_S_NOT_EXPLAINED,),
                            (f"creep fit {found}", checks_text(checks, values=False),
                             "the creep fit's μ_s is not reported: " + "; ".join(failed)))
    return CreepOutcome(mu, creeps, fits, move, checks, (),
                        (f"μ_s = {mu:.3f} {found}", checks_text(checks)))
