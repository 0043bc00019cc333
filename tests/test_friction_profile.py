"""Friction zones along the string (drillfric.friction, docs/theory.md §3.2) and the checks a
creep fit must pass before its μ_s is claimed (drillfric.estimation.batch, docs/theory.md
§6.3, docs/batch_refinement.md "Checks of a creep fit").

The profile's parts are exact bookkeeping, so they are checked to round-off against hand
sums: the friction capacity of a string with a cased top is the cased factor times F_c over
the cased length plus the open-hole factor times F_c below it.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from drillfric.config import config_from_dict
from drillfric.estimation import batch
from drillfric.estimation.batch import creep_checks, harness, settings
from drillfric.estimation.creep import smooth
from drillfric.friction import EFFECTIVE, OPEN_HOLE, FrictionProfile

#: Ten 100-m cells from 0 to 1000 m, F_c = 40 N·m/m, shoe at 350 m (half a cell).
X_M = np.arange(50.0, 1000.0, 100.0)
DX_M = np.full(10, 100.0)
FC = 40.0


def _capacity(parts, mu: float, which: int) -> float:
    """∫ (μ·estimated + fixed) dx over the string [N·m] (which: 1 kinetic, 2 static)."""
    est, fixed = parts[0], parts[which]
    return float(np.sum((mu * est + fixed) * DX_M))


def test_one_zone_is_all_estimated():
    """Without casing keys the whole F_c is estimated and nothing is fixed: μ is an
    effective factor."""
    p = FrictionProfile()
    est, fix_k, fix_s = p.parts(X_M, DX_M, FC, 0.6, 0.25)
    assert np.all(est == FC) and not fix_k.any() and not fix_s.any()
    assert p.zone == EFFECTIVE and p.static_known


def test_known_cased_factor_fixes_the_cased_length():
    """Shoe at 350 m, cased μ_k = 0.2: 350 m carry 0.2·F_c fixed, 650 m carry μ_open·F_c —
    the kinetic capacity is 0.2·40·350 + 0.3·40·650 N·m."""
    p = FrictionProfile(shoe_md_m=350.0, cased_kinetic=0.2, cased_static=0.3)
    parts = p.parts(X_M, DX_M, FC, 0.6, 0.3)
    assert p.cased_share(X_M, DX_M)[3] == pytest.approx(0.5)
    assert _capacity(parts, 0.3, 1) == pytest.approx(0.2 * FC * 350 + 0.3 * FC * 650)
    assert _capacity(parts, 0.6, 2) == pytest.approx(0.3 * FC * 350 + 0.6 * FC * 650)
    assert p.zone == OPEN_HOLE and p.static_known


@pytest.mark.parametrize("hypothesis, cased_static", [("tied", 0.2 * 0.6 / 0.3),
                                                       ("kinetic", 0.2)])
def test_unknown_cased_static_follows_the_hypothesis(hypothesis, cased_static):
    """Unknown cased μ_s: "tied" keeps the open hole's μ_s/μ_k (0.2·2 = 0.4), "kinetic"
    gives the casing no static excess (0.2)."""
    p = FrictionProfile(shoe_md_m=350.0, cased_kinetic=0.2)
    parts = p.parts(X_M, DX_M, FC, 0.6, 0.3, hypothesis)
    assert not p.static_known
    assert _capacity(parts, 0.6, 2) == pytest.approx(cased_static * FC * 350
                                                     + 0.6 * FC * 650)


def test_ratio_scales_the_cased_fc():
    """μ_cased = 0.5·μ_open: the estimated F_c is halved above the shoe, nothing fixed."""
    p = FrictionProfile(shoe_md_m=350.0, ratio=0.5)
    est, fix_k, fix_s = p.parts(X_M, DX_M, FC, 0.6, 0.3)
    assert float(np.sum(est * DX_M)) == pytest.approx(FC * (0.5 * 350 + 650))
    assert not fix_k.any() and not fix_s.any() and p.static_known


def test_profile_from_config_needs_the_shoe_and_a_cased_factor():
    """A shoe alone changes nothing (no known factor): the estimate stays effective."""
    assert FrictionProfile.from_config(config_from_dict({})).zone == EFFECTIVE
    shoe = config_from_dict({"model": {"casing_shoe_md_m": 1500.0}})
    assert FrictionProfile.from_config(shoe).zone == EFFECTIVE
    cased = config_from_dict({"model": {"casing_shoe_md_m": 1500.0, "friction_cased": 0.2}})
    assert FrictionProfile.from_config(cased) == FrictionProfile(shoe_md_m=1500.0,
                                                                 cased_kinetic=0.2)


# --- checks of a creep fit ----------------------------------------------------------------

#: A creep fit of the model family (validation plant "step" at 100 Hz: misfit 0.6 %,
#: halves within 3 %, swing ratio ≈ 1).
PASSING = batch.CreepChecks(engaged=0.9, misfit=0.006, sensitivity=25.0, noise_Nm=20.0,
                            halves=(0.59, 0.60), swing_ratio=0.95)


def test_a_fit_of_the_model_family_passes():
    assert creep_checks.problems(0.6, PASSING) == []


@pytest.mark.parametrize("change, words", [
    ({"misfit": 0.08}, "misses the creep torque by 8 %"),
    ({"sensitivity": 1.2}, "hardly depends on μ_s"),
    ({"swing_ratio": 0.05}, "does not explain the slips"),
    ({"halves": (0.50, 0.60)}, "not the same along the string"),  # first half 17 % low
    ({"halves": (0.70, 0.60)}, "not the same along the string"),  # 17 % high
    ({"other_hypothesis": 0.66}, "give model.friction_cased_static"),
    ({"twist_noise": 0.05}, "speed noise integrated into the twist"),
    ({"twist_noise": float("nan")}, "speed noise integrated into the twist"),
])
def test_each_failed_check_withholds_mu_s_with_its_reason(change, words):
    """Each check fails alone, and its reason names the physics (issue 14: a μ_s the model
    does not explain is withheld, visibly)."""
    problems = creep_checks.problems(0.6, replace(PASSING, **change))
    assert len(problems) == 1 and words in problems[0]


def test_halves_allow_a_slowly_logged_onset_but_not_a_low_top():
    """The first half may fit up to 15 % high (onset of a slowly logged creep) but at most
    6 % low (a top of lower friction wound up first)."""
    assert creep_checks.problems(0.6, replace(PASSING, halves=(0.68, 0.60))) == []
    assert creep_checks.problems(0.6, replace(PASSING, halves=(0.57, 0.60))) == []
    assert creep_checks.problems(0.6, replace(PASSING, halves=(0.555, 0.60)))


def test_halves_too_noisy_to_see_a_cased_top_withhold_mu_s():
    """The halves check states its own noise: 2σ of the halves' difference, the torque noise
    (2 × 10 %/sensitivity) and each half's twist noise in quadrature. Where that exceeds the
    6 % line a cased top must cross, the check is blind and μ_s is withheld however close
    the halves are: a quiet creep (sensitivity 4: 2σ = 10 %) or a slow one (each half's
    twist noise 3 %: 2σ ≈ 8.6 %); a well-measured one is judged by the line."""
    quiet = replace(PASSING, sensitivity=4.0, halves=(0.43, 0.43))
    slow = replace(PASSING, halves=(0.60, 0.60), halves_twist_noise=(0.03, 0.03))
    for blind in (quiet, slow):
        problems = creep_checks.problems(0.43, blind)
        assert len(problems) == 1 and "halves cannot be compared" in problems[0]
    assert creep_checks.problems(0.6, replace(slow, halves_twist_noise=(0.015, 0.015))) == []
    assert creep_checks.problems(0.43, replace(quiet, sensitivity=25.0)) == []
    assert creep_checks.halves_noise(replace(slow, sensitivity=1e9)) == pytest.approx(
        2.0 * np.hypot(0.03, 0.03))


def test_smoothed_noise_of_white_noise_on_a_smooth_torque():
    """σ from second differences (var Δ²n = 6σ² for white noise) over √(T_smooth/Δt): white
    noise of 200 N·m at 100 Hz on a slow torque build-up is 200/√100 = 20 N·m after 1-s
    smoothing. 5 %: the median estimator's sampling error on 6000 samples is ≈ 2 %."""
    rng = np.random.default_rng(1)
    t = np.arange(0.0, 60.0, 0.01)
    tau = 8000.0 * (1.0 - np.exp(-t / 20.0)) + rng.normal(0.0, 200.0, t.size)
    data = harness.FitData(t=t, dt=0.01, drive=0 * t, motor=tau, creep_drive=0 * t,
                       w_bar=0 * t, tau=tau, tau_bar=tau, speed=0 * t)
    noise = creep_checks.smoothed_noise_Nm(data, np.arange(t.size))
    assert noise == pytest.approx(20.0, rel=0.05)


def test_twist_and_torque_noise_add_in_quadrature():
    """Each 1-σ alone within 10 %/3 = 3.33 % passes; 2.5 % and 2.5 % together are 3.54 %:
    withheld (docs/theory.md §6.3, check 2). (Sensitivity 4 leaves the halves blind, 2σ =
    10 % > 6 %: that check is left out here.)"""
    def twist_check(c):
        return [p for p in creep_checks.problems(0.6, c) if "halves" not in p]

    torque_only = replace(PASSING, sensitivity=4.0)  # 10 %/4 = 2.5 %
    assert twist_check(torque_only) == []
    assert twist_check(replace(PASSING, twist_noise=0.025)) == []
    assert twist_check(replace(torque_only, twist_noise=0.025))


def test_twist_walk_variance_of_a_constant_weight():
    """Σ_i c·W_i over U rows after P rows of pre-roll, W a random walk from 0 with
    Var W(t) = q·t: Var = q·Δt·c²·(P·U² + U(U+1)(2U+1)/6) (the suffix sums are c·U for each
    pre-roll step and c·k, k = U…1, after it) — exact."""
    q, dt, c, pre, used = 2e-4, 0.01, 3.0, 40, 200
    a = np.r_[np.zeros(pre), np.full(used, c)]
    expected = q * dt * c ** 2 * (pre * used ** 2 + used * (used + 1) * (2 * used + 1) / 6)
    assert batch.twist_walk_variance(a, q, dt) == pytest.approx(expected, rel=1e-12)


def test_twist_walk_variance_against_monte_carlo():
    """The closed form against 4000 simulated walks (increments N(0, q·Δt)): the sample
    variance of Σ a_i W_i has a relative standard error √(2/4000) ≈ 2.2 %; 8 % is 3.5σ."""
    rng = np.random.default_rng(5)
    q, dt = 1e-3, 0.2
    a = rng.normal(0.0, 1.0, 150)
    walks = np.cumsum(rng.normal(0.0, np.sqrt(q * dt), (4000, a.size)), axis=1)
    assert np.var(walks @ a) == pytest.approx(batch.twist_walk_variance(a, q, dt), rel=0.08)


@pytest.mark.parametrize("case, low, high", [
    ("white 100 Hz", 0.75, 1.3), ("white 5 Hz", 0.75, 1.3), ("1-s means", 0.75, 1.3),
    ("quantised 0.5 RPM", 0.75, 1.3), ("filtered 1 s at 10 Hz", 0.5, 1.0)])
def test_walk_rate_holds_for_noise_filtered_averaged_or_quantised(case, low, high):
    """The walk's rate q (Var of the twist error per second) from the residual about the 4-s
    creep drive: for noise of density σ²·δt (white at 1 kHz, σ = 0.5 RPM) q = σ²·δt whatever
    was done to it before logging, since block means or sampling keep its low frequencies,
    which make the walk (quantisation adds its own step²/12). Tolerances: the robust spread
    of 300 one-second blocks has a sampling error of ≈ 13 % (−25 %/+30 % is ≈ 2σ). Noise
    filtered over 1 s is correlated over the block, so the 4-s average removes more of it
    than of white noise: it reads ≈ 35 % low (documented in creep_checks.walk_rate), where a
    second-difference estimate of the sample noise reads it 12× low."""
    rng = np.random.default_rng(11)
    fine_dt, sigma = 0.001, 0.5 * np.pi / 30.0
    fine = 5.0 * np.pi / 30.0 + rng.normal(0.0, sigma, 300_000)
    q_true = sigma ** 2 * fine_dt
    if case.startswith("white"):
        step = {"white 100 Hz": 10, "white 5 Hz": 200}[case]
        logged, dt = fine[::step], fine_dt * step
        q_true = sigma ** 2 * dt  # sampled white noise: density σ²·Δt
    elif case == "filtered 1 s at 10 Hz":
        logged, dt = smooth(fine, fine_dt, 1.0)[::100], 0.1
    elif case == "1-s means":
        logged, dt = fine.reshape(-1, 1000).mean(axis=1), 1.0
    else:  # 10 Hz spot samples in 0.5-RPM steps
        step_rad_s, dt = 0.5 * np.pi / 30.0, 0.1
        logged = np.round(fine[::100] / step_rad_s) * step_rad_s
        q_true = (sigma ** 2 + step_rad_s ** 2 / 12.0) * dt
    residual = logged - smooth(logged, dt, settings.CREEP_DRIVE_SMOOTH_S)
    assert low < creep_checks.walk_rate(residual, dt) / q_true < high
