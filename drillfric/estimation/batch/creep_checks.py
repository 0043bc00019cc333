"""What a grid-converged creep fit must show before its μ_s is claimed (docs/theory.md §6.3;
docs/batch_refinement.md "Checks of a creep fit").

The fitted model must explain the creep torque (misfit), the creep must depend on μ_s well
above the torque noise and the speed noise integrated into the twist (sensitivity, twist
noise), the model's stick-slip after the creep must resemble the data's (swing ratio), both
halves of the creep must give the same μ_s, and an unknown cased static factor must not
matter. The thresholds are in :mod:`drillfric.estimation.batch.settings`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drillfric.estimation.batch.harness import FitData, Model, Window, fluctuation
from drillfric.estimation.batch.settings import (
    CREEP_DRIVE_SMOOTH_S,
    CREEP_SENSITIVITY_STEP,
    CREEP_STENCIL,
    HALVES_SIGMAS,
    MAX_CREEP_MISFIT,
    MAX_HALVES_BELOW,
    MAX_HALVES_SPLIT,
    MAX_HYPOTHESIS_SPLIT,
    MIN_CREEP_SENSITIVITY,
    MIN_SWING_RATIO,
    SPLIT_SKIP,
    TORQUE_SMOOTH_S,
)
from drillfric.estimation.creep import smooth


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
    halves_twist_noise : tuple of float
        Relative 1-σ of each half's μ_s due to the twist noise, as ``twist_noise`` but over
        that half alone (the walk accumulated before it included) [-] (docs/theory.md §6.3).
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
    halves_twist_noise: tuple[float, float] = (0.0, 0.0)
    swing_ratio: float | None = None
    other_hypothesis: float | None = None


def measure(model: Model, wins: list[Window], mu_s: float, mu_k: float, cells: int,
            rotating: list[Window], stick_slip: bool, rotating_cells: int) -> CreepChecks:
    """The evidence of a creep fit at (μ_s, μ_k) on ``cells`` cells (:class:`CreepChecks`,
    without ``other_hypothesis``); the rotation after the creep is compared on the μ_k
    fit's ``rotating_cells``."""
    d = model.data
    g, fc = model.grid(cells)
    est, _, fix_s = model.profile.parts(g.x_m, g.dx_true_m, fc, mu_s, mu_k, model.cased_static)
    capacity = float(np.sum((mu_s * est + fix_s) * g.dx_true_m))
    base, moved, data = [], [], []
    walks, jacobians = np.zeros(3), np.zeros(3)  # the whole creep, its first and second half
    for w in wins:
        at, up = (smooth(model.simulate(w, f * mu_s, min(mu_k, f * mu_s), cells)[0], d.dt,
                         TORQUE_SMOOTH_S) for f in (1.0, 1.0 + CREEP_SENSITIVITY_STEP))
        walk, jacobian = _twist_walk(d, w, at, up, mu_s)
        walks += walk
        jacobians += jacobian
        base.append(at[w.used - w.sim0])
        moved.append(up[w.used - w.sim0])
        data.append(d.tau_bar[w.used])
    base, moved, data = (np.concatenate(x) for x in (base, moved, data))
    jacobian_sq = float(np.sum((moved - base) ** 2)) / (CREEP_SENSITIVITY_STEP * mu_s) ** 2
    noise = smoothed_noise_Nm(d, np.concatenate([w.used for w in wins]))
    level = max(float(np.max(np.abs(data))), 1e-9)
    independent = np.sqrt(max(1.0, base.size * d.dt / TORQUE_SMOOTH_S))
    sensitivity = float(np.sqrt(np.mean((moved - base) ** 2))) / noise * independent
    twist_noise = float(np.sqrt(walks[0])) / max(jacobian_sq, 1e-30) / mu_s
    halves_twist = tuple(float(np.sqrt(v)) / max(j, 1e-30) / mu_s
                         for v, j in zip(walks[1:], jacobians[1:], strict=True))
    spread = float(np.hypot(CREEP_SENSITIVITY_STEP / max(sensitivity, 1e-9), twist_noise))
    return CreepChecks(engaged=float(np.max(base)) / max(capacity, 1e-9),
                       misfit=float(np.sqrt(np.mean((base - data) ** 2))) / level,
                       sensitivity=sensitivity, noise_Nm=noise,
                       swing_ratio=swing_ratio(model, rotating, mu_s, mu_k, rotating_cells,
                                               spread) if stick_slip and rotating else None,
                       halves=_split_half(model, wins, mu_s, mu_k, cells),
                       twist_noise=twist_noise, halves_twist_noise=halves_twist)


def _twist_walk(d: FitData, w: Window, base: np.ndarray, moved: np.ndarray,
                mu_s: float) -> tuple[np.ndarray, np.ndarray]:
    """One creep window's shares of Var(Σ J_i τ'_i W_i) and of Σ J_i² over the whole creep,
    its first and its second half (:func:`half_rows`): the speed noise the model integrates
    into its twist (docs/theory.md §6.3, check 2). W is the random walk of the twist error,
    Var W(t) = q·t with q its rate (:func:`walk_rate`), from the start of the window — a
    half's sum carries the walk accumulated before it; J = ∂τ/∂μ_s the fit's sensitivity
    [N·m per unit μ] and τ' = dτ/dθ the slope of the quasi-static creep torque against the
    top angle [N·m/rad]. The caller adds the windows; variance over (Σ J²)² is the variance
    of μ_s [-]. A window too short to tell gives inf (not claimed)."""
    span = slice(w.sim0, w.end + 1)
    drive = d.creep_drive[span]
    if drive.size < 5:
        return np.full(3, np.inf), np.ones(3)
    rows = w.used - w.sim0
    floor = 0.5 * float(np.median(np.abs(drive[rows])))
    slope = np.gradient(base, d.dt) / np.maximum(np.abs(drive), max(floor, 1e-6))
    jacobian = (moved[rows] - base[rows]) / (CREEP_SENSITIVITY_STEP * mu_s)
    creep = slice(w.sim0 + int(rows.min()), w.sim0 + int(rows.max()) + 1)
    rate = walk_rate(d.speed[creep] - d.creep_drive[creep], d.dt)
    walks, jacobians = np.zeros(3), np.zeros(3)
    for k, part in enumerate((slice(None), *half_rows(rows.size))):
        a = np.zeros(drive.size)
        a[rows[part]] = jacobian[part] * slope[rows[part]]
        walks[k] = twist_walk_variance(a, rate, d.dt)
        jacobians[k] = float(np.sum(jacobian[part] ** 2))
    return walks, jacobians


def half_rows(n: int) -> tuple[slice, slice]:
    """The first and second half of a creep's ``n`` used samples that the halves check
    compares, its first :data:`SPLIT_SKIP` left out (the smoothed drive blurs the onset)."""
    start = int(SPLIT_SKIP * n)
    mid = (start + n) // 2
    return slice(start, mid), slice(mid, n)


def twist_walk_variance(a, walk_rate: float, dt_s: float) -> float:
    """Var(Σ_i a_i W_i) for a random walk W sampled every ``dt_s`` from W_0 = 0 with
    Var W(t) = ``walk_rate``·t: ``walk_rate``·Δt·Σ_m (Σ_{i≥m} a_i)² (docs/theory.md §6.3)."""
    suffix = np.cumsum(np.asarray(a, dtype=float)[::-1])[::-1]
    return walk_rate * dt_s * float(np.sum(suffix ** 2))


def walk_rate(residual_rad_s: np.ndarray, dt: float) -> float:
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


def _split_half(model: Model, wins: list[Window], mu_s: float, mu_k: float,
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
            for k, part in enumerate(half_rows(err.size)):
                halves[k, j] += float(np.mean(err[part]))
    return tuple(float(parabola_vertex(x, h)[0]) for h in halves)


def problems(mu_s: float, c: CreepChecks) -> list[str]:
    """Why a grid-converged creep fit does not identify μ_s (empty: it does)."""
    found = []
    pinned = False  # by the torque and twist noise: a fit that is not is not compared again
    if c.misfit > MAX_CREEP_MISFIT:
        found.append(f"the fitted model misses the creep torque by {100 * c.misfit:.0f} % "
                     "RMS: the friction law does not explain the break-over")
    if c.sensitivity < MIN_CREEP_SENSITIVITY:
        found.append("the creep torque hardly depends on μ_s (a 10 % change is "
                     f"{c.sensitivity:.1f}× its noise)")
    elif not np.hypot(CREEP_SENSITIVITY_STEP / c.sensitivity, c.twist_noise) <= \
            CREEP_SENSITIVITY_STEP / MIN_CREEP_SENSITIVITY:  # NaN or inf: not pinned
        found.append(f"the speed noise integrated into the twist leaves μ_s uncertain by "
                     f"±{100 * c.twist_noise:.1f} % (1σ; torque noise "
                     f"±{100 * CREEP_SENSITIVITY_STEP / c.sensitivity:.1f} %): a creep "
                     "logged faster or with a quieter speed sensor would pin it")
    else:
        pinned = True
    if c.swing_ratio is not None and c.swing_ratio < MIN_SWING_RATIO:
        found.append(f"with this μ_s the model's stick-slip after the creep is "
                     f"{c.swing_ratio:.2f}× the data's: the law that fits the creep does "
                     "not explain the slips (friction falling with speed?)")
    found += _halves_problems(c, pinned)
    if c.other_hypothesis is not None and \
            abs(c.other_hypothesis / mu_s - 1.0) > MAX_HYPOTHESIS_SPLIT:
        found.append(f"it depends on the unknown static friction in the casing "
                     f"({mu_s:.3f} with the open hole's ratio, {c.other_hypothesis:.3f} "
                     "without): give model.friction_cased_static")
    return found


def _halves_problems(c: CreepChecks, pinned: bool) -> list[str]:
    """The halves check (docs/theory.md §6.3, check 4): blind where its own noise exceeds
    the −6 % split a cased top must show (said only of a fit the noise checks ``pinned``),
    else the split itself."""
    change = c.halves[0] / max(c.halves[1], 1e-9) - 1.0
    noise = halves_noise(c)
    if not noise <= MAX_HALVES_BELOW:  # NaN or inf too: blind to the split it must catch
        return [f"the creep's halves cannot be compared: noise ±{100 * noise:.1f} % "
                f"({HALVES_SIGMAS:.0f}σ) at this rate > {100 * MAX_HALVES_BELOW:.0f} %, the "
                "lower friction of a cased top would not show: a creep logged faster or "
                "with a quieter speed sensor would"] if pinned else []
    if change < -MAX_HALVES_BELOW or abs(change) > MAX_HALVES_SPLIT:
        return [f"the first and second half of the creep give μ_s = {c.halves[0]:.3f} and "
                f"{c.halves[1]:.3f}: friction is not the same along the string the creep "
                "wound up (cased and open hole?)"]
    return []


def halves_noise(c: CreepChecks) -> float:
    """:data:`HALVES_SIGMAS` standard deviations of the relative difference of the halves'
    μ_s due to noise alone [-] (docs/theory.md §6.3, check 4): the torque noise (each half
    holds about half the creep's information, so the difference's 1-σ is ≈ 2 × 10 % /
    sensitivity) and each half's twist noise, in quadrature."""
    torque = 2.0 * CREEP_SENSITIVITY_STEP / max(c.sensitivity, 1e-9)
    return HALVES_SIGMAS * float(np.sqrt(torque ** 2 + sum(s ** 2 for s in
                                                           c.halves_twist_noise)))


def checks_text(c: CreepChecks, *, values: bool = True) -> str:
    """The checks as one message (the evidence beside a μ_s); without ``values`` the
    halves' μ_s are given only by their difference (a μ_s not reported is not printed)."""
    swing = "—" if c.swing_ratio is None else f"{c.swing_ratio:.2f}"
    apart = abs(c.halves[0] - c.halves[1]) / max(abs(c.halves[1]), 1e-12)
    halves = (f"halves {c.halves[0]:.3f} / {c.halves[1]:.3f}" if values
              else f"halves {100 * apart:.1f} % apart")
    return (f"creep checks: misfit {100 * c.misfit:.1f} %, sensitivity {c.sensitivity:.0f}, "
            f"twist noise ±{100 * c.twist_noise:.1f} %, "
            f"string engaged {100 * min(c.engaged, 1.0):.0f} %, {halves} "
            f"(noise ±{100 * halves_noise(c):.1f} %), model/data stick-slip {swing}")


def smoothed_noise_Nm(d: FitData, samples: np.ndarray) -> float:
    """Noise of the smoothed measured torque [N·m]: the raw noise from second differences
    (robust median estimate, a smooth torque adds little to them) over the smoothing
    window's √n."""
    raw = d.tau[samples]
    if raw.size < 5:
        return 1.0
    sigma = 1.4826 * float(np.median(np.abs(np.diff(raw, 2)))) / np.sqrt(6.0)
    return max(sigma / np.sqrt(max(1.0, TORQUE_SMOOTH_S / d.dt)), 1e-6)


def swing_ratio(model: Model, rotating: list[Window], mu_s: float, mu_k: float, cells: int,
                spread: float = 0.0) -> float:
    """Torque fluctuation of the model over the used samples of the longest rotating run,
    relative to the data's there [-]: the median over μ_s·(1 − s), μ_s, μ_s·(1 + s) with
    s = ``spread``, the fit's own relative 1-σ of μ_s (one point where that is not finite).

    Stick-slip near its onset is bistable and chaotic: the model at one (μ_s, μ_k) may
    settle into steady rotation where its neighbours within the fit's uncertainty
    stick-slip like the data (the step-law stand at 5 Hz: 0.46 at μ_s = 0.614, μ_k =
    0.2507, against 0.86–1.08 at μ_s 0.600 and 0.620 or μ_k 0.2489–0.2500;
    docs/validation.md). The median of the three asks whether the law explains the slips,
    not whether one chaotic run happened to; a law that does not (Stribeck friction: the
    model's stick-slip 0.05–0.2 of the data's) fails at its neighbours as well."""
    w = max(rotating, key=lambda w: w.used.size)
    d = model.data
    data_fluct = max(fluctuation(d.tau_bar[w.used]), 1e-9)
    factors = (1.0 - spread, 1.0, 1.0 + spread) if 0.0 < spread < 1.0 else (1.0,)
    ratios = []
    for f in factors:
        tau, _ = model.simulate(w, f * mu_s, min(mu_k, f * mu_s), cells)
        ratios.append(fluctuation(smooth(tau, d.dt, TORQUE_SMOOTH_S)[w.used - w.sim0])
                      / data_fluct)
    return float(np.median(ratios))
