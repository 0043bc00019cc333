"""Per-segment estimation helpers (drillfric.estimation.chain) the end-to-end tests do not pin."""

from __future__ import annotations

import numpy as np
import pytest

from drillfric.drillstring import build_string
from drillfric.estimation.batch import BatchDetails, BatchResult
from drillfric.estimation.chain import _creep_advice, ensemble_starts
from drillfric.estimation.observer import Measurements, ObserverRecord, ensemble_bit_speed
from tests.synthetic import RPM, config


def test_creep_advice_is_the_wind_up_time():
    """Twist to break free under uniform friction = μ_s·T_N·L/(2GJ) (torque falls linearly
    from the top, docs/theory.md §3, §6.3); at the creep speed that takes twist/ω seconds."""
    string = build_string(config().sections, 3000.0)
    pipe = string.sections[0]
    t = np.arange(0.0, 60.0, 0.1)
    speed = np.where((t > 5.0) & (t < 35.0), 5.0 * RPM, 0.0)
    meas = Measurements(0.0, 0.1, speed, np.zeros_like(t))
    refined = BatchResult(None, "mean_torque", None, False, None, "none", (), (), 0, (),
                          details=BatchDetails(creeps_found=[(10.0, 30.0)]))
    text = _creep_advice(string, 80e3, 0.3, refined, meas)
    expected = 2 * 0.3 * 80e3 * 3000.0 / (2 * pipe.shear_modulus_Pa * pipe.polar_moment_m4)
    assert f"about {expected / (5.0 * RPM):.0f} s" in text and "20 s at 5.0 RPM" in text


def test_ensemble_members_span_the_mu_s_uncertainty():
    """Seed first, μ_s·(1 ± spread) evenly, never below μ_k (μ_s ≥ μ_k by definition)."""
    members = ensemble_starts(0.6, 0.28, 5, 0.1, 1.5)
    np.testing.assert_allclose(members[0], [0.6, 0.28])
    np.testing.assert_allclose(np.sort(members[:, 0]), [0.54, 0.57, 0.6, 0.63, 0.66])
    assert np.all(members[:, 1] == 0.28)
    np.testing.assert_allclose(ensemble_starts(0.6, 0.28, 1, 0.1, 1.5), [[0.6, 0.28]])
    np.testing.assert_allclose(ensemble_starts(0.6, 0.28, 5, 0.0, 1.5), [[0.6, 0.28]])


@pytest.mark.parametrize("mu_s, mu_k, mu_max", [(0.30, 0.30, 1.5), (0.32, 0.30, 1.5),
                                                (1.4, 0.3, 1.5), (0.3, 0.29, 0.31)])
def test_ensemble_members_stay_distinct_where_the_bounds_cut(mu_s, mu_k, mu_max):
    """μ_k ≤ μ_s ≤ μ_max cut the spread (e.g. the seed is μ_k when the batch gave no regime
    value): the members are then compressed into what is left, never duplicated (identical
    members run identical trajectories: wasted work, one trajectory counted twice)."""
    members = ensemble_starts(mu_s, mu_k, 5, 0.15, mu_max)
    assert members[0, 0] == pytest.approx(mu_s)
    assert np.unique(members[:, 0]).size == len(members) == 5
    assert np.all((members[:, 0] >= mu_k - 1e-12) & (members[:, 0] <= mu_max + 1e-12))


def _record(bit, residual):
    time = np.arange(bit.shape[0]) * 0.1
    zero = np.zeros_like(bit)
    return ObserverRecord(time, zero, zero, zero, bit, bit, residual, zero,
                          np.zeros(bit.shape[1]))


def test_ensemble_weights_favour_the_member_matching_the_surface():
    """A member whose innovation is 20 × the noise gets ~1/400 of the weight of one at the
    noise level (weights 1/(ē² + σ²)); members indistinguishable from noise count equally;
    the band is the members' min–max."""
    n = 200
    bit = np.column_stack([np.full(n, 5.0), np.full(n, 9.0)])
    noise = 0.05
    residual = np.column_stack([np.full(n, noise), np.full(n, 20 * noise)])
    est = ensemble_bit_speed(_record(bit, residual), memory_s=1.0, noise_rad_s=noise)
    w_bad = (1 / (400 * noise**2 + noise**2)) / (1 / (2 * noise**2) + 1 / (401 * noise**2))
    np.testing.assert_allclose(est.rad_s[-1], 5.0 + 4.0 * w_bad, rtol=1e-3)
    quiet = ensemble_bit_speed(_record(bit, np.zeros_like(bit)), 1.0, noise)
    np.testing.assert_allclose(quiet.rad_s, 7.0)
    np.testing.assert_allclose(quiet.low_rad_s, 5.0)
    np.testing.assert_allclose(quiet.high_rad_s, 9.0)


def test_ensemble_weights_start_from_the_first_innovation():
    """The innovation average starts at the first sample's e² (not at 0, which would give
    every member the same weight until the memory fills)."""
    n = 50
    bit = np.column_stack([np.full(n, 5.0), np.full(n, 9.0)])
    residual = np.column_stack([np.full(n, 0.05), np.full(n, 1.0)])
    est = ensemble_bit_speed(_record(bit, residual), memory_s=10.0, noise_rad_s=0.05)
    np.testing.assert_allclose(est.rad_s[0], est.rad_s[-1], rtol=1e-12)
    np.testing.assert_allclose(est.weights.sum(axis=1), 1.0)


def test_ensemble_weights_forget_old_innovations():
    """The innovation average has memory ``memory_s``: a member that drifted long ago (here
    20 memories) and matches now counts equally again."""
    n = 400
    bit = np.column_stack([np.full(n, 5.0), np.full(n, 9.0)])
    residual = np.zeros_like(bit)
    residual[:100, 1] = 1.0
    est = ensemble_bit_speed(_record(bit, residual), memory_s=1.0, noise_rad_s=0.05)
    assert est.rad_s[99] < 5.1
    np.testing.assert_allclose(est.rad_s[-1], 7.0, atol=1e-3)
