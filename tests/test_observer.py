"""Adaptive observer (THEORY.md §5): kernel vs NumPy twin, signs, convergence, guards.

Truth plants run on a finer grid than the observer (800 vs 400 cells) with measurement noise
(0.5 RPM, 200 N·m, the issue's levels), so these are not self-consistency checks.
"""

from __future__ import annotations

import numpy as np
import pytest

from drillfric import torsional
from drillfric.errors import InputError, ModelError
from drillfric.estimation.gains import gains_from_config
from drillfric.estimation.observer import Measurements, Observer, ObserverState, observe
from tests.synthetic import RPM, build_and_hold, config, noisy, simulate

PATH = build_and_hold(600.0, 50.0, 1600.0)


def make_observer(case, cfg, cells=400, **kw) -> Observer:
    grid = torsional.make_grid(case.string, cells)
    plant = torsional.Plant(grid, case.td.fc_at(grid.x_m), 0.0, 0.0, cfg.omega_c_rad_s,
                            cfg.model.k_t_per_s, cfg.rig.top_drive_inertia_kg_m2)
    n_pipe = grid.section_start[1]
    gains = gains_from_config(cfg, case.string, plant.T_N_Nm, grid.x_m[:n_pipe], grid.dt_s)
    return Observer(plant, gains, **kw)


@pytest.fixture(scope="module")
def steady():
    """Steady rotation at 100 RPM with μ_s close to μ_k: no stick-slip."""
    return simulate(PATH, 1600.0, 0.2, 0.15, 100.0, 60.0)


def test_kernel_matches_numpy_twin(steady):
    """Compiled kernel and NumPy twin agree to round-off (same arithmetic, same order)."""
    cfg = config()
    obs = make_observer(steady, cfg, cells=120, law="paper")
    w, q = noisy(steady.record)
    meas = Measurements.from_samples(steady.record.time_s, w, q)
    start = ObserverState.from_starts(obs, [[0.5, 0.1], [0.3, 0.25]])
    n_steps = 3000
    t_end = n_steps * obs.plant.grid.dt_s
    fast, s_fast = observe(obs, meas, start, t_end_s=t_end, output_rate_hz=50.0)
    slow, s_slow = observe(obs, meas, start, t_end_s=t_end, output_rate_hz=50.0,
                           backend="numpy")
    for name in ("mu_s", "mu_k", "surface_rad_s_est", "bit_rad_s_est", "residual_rad_s"):
        np.testing.assert_allclose(getattr(fast, name), getattr(slow, name), rtol=1e-9,
                                   atol=1e-9, err_msg=name)
    np.testing.assert_allclose(s_fast.alpha, s_slow.alpha, rtol=1e-9, atol=1e-9)


def test_started_at_truth_stays_at_truth():
    """Signs (THEORY §5.2): observer = plant (same grid, exact samples at every step, no
    noise) started at the true state and friction keeps zero innovation and its estimates."""
    cfg = config()
    case = simulate(PATH, 1600.0, 0.3, 0.2, 80.0, 20.0, cells=300, rate_hz=200.0)
    obs = make_observer(case, cfg, cells=300)
    grid = obs.plant.grid
    plant = torsional.Plant(grid, case.td.fc_at(grid.x_m), 0.3, 0.2, 1.0, 0.1, 2900.0)
    t = np.arange(0.0, 21.0, 0.1)
    drive = torsional.Drive("pi", np.minimum(t / 10.0, 1.0) * 80.0 * RPM, 0.1)
    rec, _ = torsional.run(plant, drive, 20.0, 1.0 / grid.dt_s)
    meas = Measurements(0.0, grid.dt_s, rec.surface_rad_s, rec.motor_torque_Nm)
    state = ObserverState.from_starts(obs, [[0.3, 0.2]])
    out, _ = observe(obs, meas, state)
    assert np.max(np.abs(out.residual_rad_s)) < 1e-9
    assert np.max(np.abs(out.mu_k - 0.2)) < 1e-9 and np.max(np.abs(out.mu_s - 0.3)) < 1e-9


@pytest.mark.parametrize("design, starts, tol", [
    ("kalman", [[0.3, 0.05], [0.6, 0.4], [0.9, 0.2]], 0.02),
    # backstepping: a start with μ̂_s far above the truth makes the model copy stick-slip
    # while the string turns steadily and biases μ̂_k (+50 % at μ̂_s = 0.6, recorded in
    # docs/validation.md); the Kalman design does not show it.
    ("backstepping", [[0.3, 0.05], [0.2, 0.2]], 0.03)])
def test_mu_k_converges_in_steady_rotation(steady, design, starts, tol):
    """μ̂_k → μ_k from starts spanning 0.05–0.4 (THEORY §5.2 linear convergence). Tolerance:
    2 % (Kalman) / 3 % (backstepping, noisier: P₀ ≈ −56 injects the speed noise) of the
    truth, the grid mismatch (400 vs 800 cells) being a fraction of that."""
    cfg = config(gains=design)
    obs = make_observer(steady, cfg)
    w, q = noisy(steady.record)
    meas = Measurements.from_samples(steady.record.time_s, w, q)
    out, _ = observe(obs, meas, ObserverState.from_starts(obs, starts))
    late = out.time_s > 40.0
    estimate = out.mu_k[late].mean(axis=0)
    np.testing.assert_allclose(estimate, 0.15, rtol=tol)


def test_bit_speed_in_steady_rotation(steady):
    """Issue 5 acceptance: estimated bit speed RMS error ≤ 2 RPM in steady rotation."""
    obs = make_observer(steady, config())
    w, q = noisy(steady.record)
    meas = Measurements.from_samples(steady.record.time_s, w, q)
    out, _ = observe(obs, meas, ObserverState.from_starts(obs, [[0.2, 0.15]]))
    late = out.time_s > 30.0
    truth = np.interp(out.time_s[late], steady.record.time_s, steady.record.bit_rad_s)
    rms_rpm = np.sqrt(np.mean((out.bit_rad_s_est[late, 0] - truth) ** 2)) / RPM
    assert rms_rpm <= 2.0


def test_deadlock_guard_releases_a_stuck_observer(steady):
    """THEORY §6.1: started with μ̂ far too high the estimated string never breaks free and
    the μ_k law never runs; the guard must intervene and the estimate recover."""
    obs = make_observer(steady, config(), deadlock_s=5.0)
    w, q = noisy(steady.record)
    meas = Measurements.from_samples(steady.record.time_s, w, q)
    out, _ = observe(obs, meas, ObserverState.from_starts(obs, [[1.4, 1.2]]))
    assert out.deadlock_events[0] >= 1
    assert abs(out.mu_k[-100:, 0].mean() - 0.15) < 0.15 * 0.05


def test_paper_law_moves_mu_s_corrected_holds_it():
    """The printed law (42) adapts μ̂_s while the BHA is stuck; the default holds it
    (THEORY §6.1) — μ_s comes from the batch fit."""
    case = simulate(PATH, 1600.0, 0.6, 0.2, 40.0, 40.0, cells=400)
    w, q = noisy(case.record)
    meas = Measurements.from_samples(case.record.time_s, w, q)
    held, _ = observe(make_observer(case, config()), meas,
                      ObserverState.from_starts(make_observer(case, config()), [[0.5, 0.2]]))
    paper_obs = make_observer(case, config(), law="paper")
    moved, _ = observe(paper_obs, meas, ObserverState.from_starts(paper_obs, [[0.5, 0.2]]))
    assert np.all(held.mu_s[:, 0] == np.maximum(0.5, held.mu_k[:, 0]))
    assert np.ptp(moved.mu_s[:, 0]) > 0.01


def test_string_torque_converted_to_motor_torque():
    """τ_m = τ(0) + I_TD dω₀/dt (THEORY §3 eq. 7): a pure spin-up at constant τ_m."""
    t = np.arange(0.0, 20.0, 0.01)
    w = 0.5 * t  # rad/s, constant acceleration 0.5 rad/s²
    string_torque = np.full_like(t, 8000.0)
    meas = Measurements.from_samples(t, w, string_torque, torque_kind="string",
                                     top_drive_inertia_kg_m2=2900.0)
    inner = slice(200, -200)  # away from the smoothing window's edges
    np.testing.assert_allclose(meas.motor_torque_Nm[inner], 8000.0 + 2900.0 * 0.5, rtol=1e-9)


def test_bad_measurements_and_starts(steady):
    with pytest.raises(InputError, match="missing values"):
        Measurements.from_samples([0.0, 1.0, 2.0], [1.0, np.nan, 1.0], [0.0, 0.0, 0.0])
    obs = make_observer(steady, config(), cells=100)
    with pytest.raises(ModelError, match="μ_k ≤ μ_s"):
        ObserverState.from_starts(obs, [[0.1, 0.3]])


@pytest.mark.parametrize("hold", [False, True])
def test_measurement_interpolation(hold):
    """Linear interpolation (default) or the paper's zero-order hold, held at both ends;
    compiled kernel and twin agree."""
    from drillfric.kernels import observer as observer_kernels
    from drillfric.kernels import observer_numpy as observer_kernels_numpy

    u = np.array([0.0, 10.0, 20.0])
    times = [-1.0, 0.0, 0.25, 0.5, 0.999, 1.0, 1.5, 3.0]
    linear = [0.0, 0.0, 2.5, 5.0, 9.99, 10.0, 15.0, 20.0]
    held = [0.0, 0.0, 0.0, 0.0, 0.0, 10.0, 10.0, 20.0]
    for t, want in zip(times, held if hold else linear, strict=True):
        for module in (observer_kernels, observer_kernels_numpy):
            assert module.measured_value(u, 0.0, 1.0, t, hold) == pytest.approx(want)
