"""What the speed-driven fit is told and the thresholds it works by (docs/theory.md §6.2–§6.4).

:class:`BatchSettings` holds every key of the configuration the fit uses, built once per
segment; the module constants are the fit's own thresholds, grouped by the stage that uses
them, each with its meaning, unit and reference (docs/batch_refinement.md explains them).
"""

from __future__ import annotations

from dataclasses import dataclass

from drillfric.config import Config, default


@dataclass(frozen=True)
class BatchSettings:
    """What the configuration sets for the speed-driven fit (docs/configuration.md), SI.

    Built once per segment (:meth:`from_config`) and passed to
    :func:`~drillfric.estimation.batch.refine` and
    :func:`~drillfric.estimation.batch.model_string_torque`, so that every key given reaches
    every place that uses it.

    Attributes
    ----------
    omega_c_rad_s : float
        Static/kinetic switching speed ω_c [rad/s] (``model.omega_c_rad_s``/``omega_c_rpm``).
    k_t_per_s : float
        Viscous damping rate k_t [1/s] (``model.k_t_per_s``).
    k_t_uncertainty_factor : float
        The true damping may lie within k_t/f … f·k_t [-] (``model.k_t_uncertainty_factor``).
    top_drive_inertia_kg_m2 : float
        I_TD [kg·m²] (``rig.top_drive_inertia_kg_m2``).
    mu_max : float
        Upper end of every friction search: μ_k, the creep μ_s, the onset scan [-]
        (``observer.mu_max``).
    dip_max_s, dip_torque_fraction : float
        A stop of the top drive at most ``dip_max_s`` [s], with the string still loaded
        (torque at least ``dip_torque_fraction`` of the run's mean [-]), does not end a
        rotating run — the segmentation's rule (``segmentation.dip_max_s``,
        ``segmentation.dip_torque_fraction``).
    window_s : float
        The fit uses the first this-many seconds of a segment [s] (``batch.window_s``).
    trend_window_s : float
        Window of the re-fits of μ_k(t) over the whole segment, overlapping by half [s]
        (``batch.trend_window_s``, docs/theory.md §6.6).
    """

    omega_c_rad_s: float
    k_t_per_s: float
    top_drive_inertia_kg_m2: float
    mu_max: float = default("observer.mu_max")
    dip_max_s: float = default("segmentation.dip_max_s")
    dip_torque_fraction: float = default("segmentation.dip_torque_fraction")
    window_s: float = default("batch.window_s")
    k_t_uncertainty_factor: float = default("model.k_t_uncertainty_factor")
    trend_window_s: float = default("batch.trend_window_s")

    @classmethod
    def from_config(cls, cfg: Config) -> BatchSettings:
        """The settings of a :class:`drillfric.config.Config`."""
        return cls(omega_c_rad_s=cfg.omega_c_rad_s, k_t_per_s=cfg.model.k_t_per_s,
                   top_drive_inertia_kg_m2=cfg.rig.top_drive_inertia_kg_m2,
                   mu_max=cfg.observer.mu_max, dip_max_s=cfg.segmentation.dip_max_s,
                   dip_torque_fraction=cfg.segmentation.dip_torque_fraction,
                   window_s=cfg.batch.window_s, trend_window_s=cfg.batch.trend_window_s,
                   k_t_uncertainty_factor=cfg.model.k_t_uncertainty_factor)


# --- the series compared (docs/theory.md §6.4) ---------------------------------------------
PRE_ROLL_S = 2.0  #: model starts this long before a run or creep leaves rest [s]
WOUND_SPAN_S = 0.5  #: rest at a window's start over which a trapped torque is measured [s]
DRIVE_SMOOTH_S = 0.2  #: light smoothing of the speed that drives the model [s]
TORQUE_SMOOTH_S = 1.0  #: smoothing of torques compared in the creep misfit [s]
CREEP_DRIVE_SMOOTH_S = 4.0  #: smoothing of the speed driving a creep (keeps its angle) [s]

# --- the μ_k fit by mean-torque matching (docs/theory.md §6.4) -----------------------------
#: Whole torque cycles a rotating run must hold after its start-up to be compared: fewer
#: give no standard error of the mean torque, so no stated uncertainty of μ_k (§6.4).
MIN_CYCLES = 3
#: A steady rotation (no stick-slip) has no torque cycles: its mean torque's error comes from
#: the scatter of blocks this long instead, MIN_CYCLES of them at least (§6.4) [s].
STEADY_BLOCK_S = 5.0
#: A gear change puts the top drive's inertia at 0.4–2.5× the configured (issue 34): a motor
#: torque's stick-slip swing must hold over that range to count as evidence of stick-slip
#: for the onset bound on μ_s (on a steady lumped plant under set-point steps, 2.5× the
#: inertia made a swing of 0.13 of the mean and a bound of 0.19 over a true μ_s of 0.157).
GEAR_RANGE = (0.4, 2.5)
STICK_SLIP_FLUCTUATION = 0.1  #: data stick-slip when std/mean of the smoothed torque exceeds
PROVISIONAL_RATIO = 2.5  #: μ_s/μ_k of the model during the μ_k fit of stick-slip data
MU_K_MAX_RUNS = 8  #: model runs allowed to the μ_k root find
MU_K_TOLERANCE = 0.02  #: mean torque matched to worse than this share: not converged [-]
MU_K_REFIT_MOVE = 0.2  #: μ_k refitted when the creep μ_s moves the model's μ_s by more [-]
#: A μ_k is claimed converged within this share [-]: its statistical uncertainty (2σ, from
#: the scatter of the record's whole torque cycles, data and model alike) must be within it.
MU_K_CLAIM = 0.05
#: Validated μ_k tolerance (docs/validation.md, both plant families) by effective sample
#: interval [s]: logged at ≤ 0.2 s within 5 %, coarser within 10 %; the floor of a
#: converged μ_k's 95 % half-width (model-form error included).
VALIDATED_MU_K = ((0.2, 0.05), (float("inf"), 0.10))


def mu_k_tolerance(sample_interval_s: float | None) -> float:
    """Relative 95 % half-width of a converged μ_k logged at this interval [-]
    (:data:`VALIDATED_MU_K`).

    Examples
    --------
    >>> mu_k_tolerance(0.01), mu_k_tolerance(1.0)
    (0.05, 0.1)
    """
    interval = 0.0 if sample_interval_s is None else sample_interval_s
    return next(tol for limit, tol in VALIDATED_MU_K if interval <= limit)

# --- sticking and the stick-slip-onset bound (docs/theory.md §6.2, §6.4) --------------------
STUCK_FRACTION = 0.01  #: the model's bit sticks when this share of samples is near rest
REST_BIT = 0.1  #: the bit is near rest below this fraction of ω_c
SCAN_STEP = 0.02  #: μ_s grid step of the onset scan
SCAN_CONFIRM = 3  #: grid points above the first sticking one that must stick too
SCAN_COMPARED_S = 60.0  #: rotation compared after the start-up per onset-scan point [s]

# --- the creep fit of μ_s (docs/theory.md §6.3–§6.4) ---------------------------------------
CREEP_CELLS_PER_MD = 1000  #: creep fits at Δx ≤ MD/1000
CREEP_CONVERGENCE = 0.03  #: relative move allowed when the creep fit doubles its cells
CREEP_MAX_S = 60.0  #: longest creep window fitted [s]
CREEP_LEVELS = 3  #: creep fits at MD/1000, then doubled cells at most twice
CREEP_STENCIL = 0.04  #: relative half-width of the parabola of a creep refit
GRID_SPREAD = 0.05  #: make_grid may take up to 5 % fewer cells than requested (rounding)
CREEP_MU_MIN = 0.02  #: lowest μ_s a creep fit searches (and never below μ_k) [-]
#: Slowest logging rate for a creep fit [Hz]: the twist is the integral of the logged speed,
#: and its noise (σ√(Δt·T)) moved μ_s by +17…+33 % at 1 Hz with 0.5 RPM noise, ±6 % at 5 Hz
#: (docs/validation.md).
MIN_CREEP_RATE_HZ = 2.0

# --- the checks of a creep fit before its μ_s is claimed (docs/theory.md §6.3) --------------
# (docs/batch_refinement.md "Checks of a creep fit"; calibrated on the validation plants of
# benchmarks/validate_trust.py, where fits of the model family stay inside with margin and
# fits of other laws do not)
CREEP_SENSITIVITY_STEP = 0.10  #: relative move of μ_s whose effect on the creep is measured
#: Start of a creep left out of the split-half check (the smoothed drive blurs the onset).
SPLIT_SKIP = 0.2
MAX_CREEP_MISFIT = 0.03  #: RMS smoothed residual over the creep torque (model family ≤ 1 %)
#: A 10 % change of μ_s must move the creep torque by this many noise levels (over the
#: creep's independent seconds): the fit's 1-σ uncertainty is then ≤ 10 %/3 ≈ 3 %.
MIN_CREEP_SENSITIVITY = 3.0
MIN_SWING_RATIO = 0.5  #: model/data stick-slip fluctuation after the creep
#: First and second half of the creep fitted alone: the first may lie at most this much below
#: the second (a top of lower friction, e.g. casing, the creep wound up first) and this much
#: either way (the onset of a slowly logged creep fits high: +4…+13 % at 5 Hz on the plants).
MAX_HALVES_BELOW, MAX_HALVES_SPLIT = 0.06, 0.15
#: Standard deviations of the halves' difference due to noise alone that must stay within
#: MAX_HALVES_BELOW, else the check is blind to a cased top and μ_s is withheld: the torque
#: noise (each half holds about half the creep's information: ≈ 2 × CREEP_SENSITIVITY_STEP /
#: sensitivity, 1-σ) and each half's twist noise in quadrature (creep_checks.halves_noise).
HALVES_SIGMAS = 2.0
MAX_HYPOTHESIS_SPLIT = 0.05  #: the two hypotheses for an unknown cased static factor
