"""Observer gains (drillfric.estimation.gains) by the linear analysis of docs/theory.md
§5.1–§5.2."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from drillfric.config import config_from_dict
from drillfric.drillstring import build_string
from drillfric.errors import ConfigError, ModelError
from drillfric.estimation import lumped
from drillfric.estimation.gains import (
    Gains,
    GainSettings,
    KalmanNoise,
    Tuning,
    backstepping_gains,
    characteristic_dN,
    characteristic_N,
    design_gains,
    error_system,
    injection_on_nodes,
    kalman_filter_gain,
    kalman_gains,
    top_reflection,
)
from drillfric.estimation.lumped import Injection, LumpedParams
from tests.conftest import REPO
from tests.synthetic import AS_SECTIONS

T_N = 40e3  # a plausible ∫F_c dx for a 2500 m build-and-hold well [N·m]
TUNINGS = [Tuning(), Tuning(0.5, 15.0, 0.5, 2.0), Tuning(1.5, 8.0, 1.0, 1.2)]


def as_string(md_m: float = 2500.0):
    return build_string(config_from_dict({"string": {"sections": AS_SECTIONS}}).sections, md_m)


def as_params(md_m: float = 2500.0, **kw) -> LumpedParams:
    return LumpedParams.from_string(as_string(md_m), 2900.0, **kw)


def discrete_s(A: np.ndarray, dt: float) -> np.ndarray:
    """Continuous-time exponents s = log(λ)/Δt of a discrete transition matrix."""
    return np.log(np.linalg.eigvals(A).astype(complex)) / dt


def newton_root(s0, params, tuning, iterations=40):
    s = complex(s0)
    for _ in range(iterations):
        s -= complex(characteristic_N(s, params, tuning) / characteristic_dN(s, params, tuning))
    return s


def zeros_inside(params, tuning, re_lo, re_hi, im_hi, points=40000):
    """Number of zeros of N in the rectangle (argument principle, phase unwrapped)."""
    edges = [np.linspace(re_lo - 1j * im_hi, re_hi - 1j * im_hi, points),
             np.linspace(re_hi - 1j * im_hi, re_hi + 1j * im_hi, points),
             np.linspace(re_hi + 1j * im_hi, re_lo + 1j * im_hi, points),
             np.linspace(re_lo + 1j * im_hi, re_lo - 1j * im_hi, points)]
    phase = np.unwrap(np.angle(characteristic_N(np.concatenate(edges), params, tuning)))
    return round((phase[-1] - phase[0]) / (2 * np.pi))


# --- closed-form design ------------------------------------------------------------------

def test_backstepping_closed_form_values():
    """docs/theory.md §5.1 term by term, with hand-computed a₀, a_L for the A&S string."""
    p, tun = as_params(), Tuning()
    x = np.array([0.0, 1000.0, p.Lp_m])
    g = backstepping_gains(p, tun, x, T_N)
    lam, a1, a2, aL = 10.0, 2.5, 1.5, p.aL_per_s
    ratio = lam / p.a0_per_s
    assert g.p0 == pytest.approx(lam - p.a0_per_s)
    assert g.P0 == pytest.approx(2 - ratio)
    assert g.p_beta[0] == pytest.approx(ratio * (a1 - aL))          # x = 0: 2g·l₁
    decay = np.exp(-aL * 1000.0 / p.c_m_s)
    assert g.p_beta[1] == pytest.approx(ratio * ((a1 - aL) * decay + a2 / aL * (1 - decay)))
    assert g.p1 == pytest.approx(g.p_beta[2] / 2)
    assert g.p_d == pytest.approx(-ratio * a2 * p.I_BHA_kg_m2 / 2)
    assert g.l_k == pytest.approx(-g.p_d / T_N) and g.l_k > 0
    assert g.l_s == pytest.approx(2 * g.l_k)
    assert g.P1 == 0 and np.all(g.p_alpha == 0) and g.design == "backstepping"


@settings(max_examples=50, deadline=None)
@given(k1=st.floats(0.05, 1.95), lam=st.floats(0.5, 50), z=st.floats(0.05, 5),
       pp=st.floats(0.05, 5), md=st.floats(800, 6000))
def test_N_at_zero_is_lambda0_a2(k1, lam, z, pp, md):
    """docs/theory.md §5.1: N(0) = λ₀·a₂ ≠ 0 — the rigid-body mode and the disturbance integrator
    are both removed. Exact in floating point up to round-off (1e-12 relative)."""
    tun = Tuning(k1, lam, z, pp)
    assert complex(characteristic_N(0.0, as_params(md), tun)) == pytest.approx(lam * z * pp,
                                                                               rel=1e-12)


@settings(max_examples=200, deadline=None)
@given(k1=st.floats(1e-3, 2 - 1e-3), lam=st.floats(0.1, 100), sigma=st.floats(0, 50),
       omega=st.floats(-1e3, 1e3))
def test_top_reflection_is_contractive(k1, lam, sigma, omega):
    """docs/theory.md §5.1: |R(s)| ≤ 1 on the closed right half-plane for 0 < κ₁ < 2 (a
    first-order all-pass scaled by |1 − κ₁| < 1 at s = 0 and → 1 as |s| → ∞)."""
    assert abs(complex(top_reflection(sigma + 1j * omega, Tuning(kappa1=k1, lambda0_per_s=lam)))
               ) <= 1 + 1e-12


def test_top_reflection_grows_outside_the_range():
    """The bound above is sharp: for κ₁ ∉ [0, 2], |R(0)| = |1 − κ₁| > 1 (negative control)."""
    tun = dataclasses.replace(Tuning(), kappa1=1.0)
    object.__setattr__(tun, "kappa1", 2.5)          # bypass validation on purpose
    assert abs(complex(top_reflection(0.0, tun))) == pytest.approx(1.5)


def test_dN_is_the_derivative_of_N():
    """Newton refinement relies on dN/ds: compare with a central difference (h = 1e-6,
    truncation ~1e-12·|N'''|, round-off ~1e-10·|N|/h: agreement to 1e-6 relative)."""
    p, tun = as_params(), Tuning(0.7, 12.0, 0.8, 1.9)
    for s in (0.3 + 2j, -1.2 + 7.5j, -8.0 + 0.1j):
        fd = (characteristic_N(s + 1e-6, p, tun) - characteristic_N(s - 1e-6, p, tun)) / 2e-6
        assert complex(characteristic_dN(s, p, tun)) == pytest.approx(complex(fd), rel=1e-6)


# --- the linear error system against N(s) ----------------------------------------------

@pytest.mark.parametrize("tuning", TUNINGS, ids=["default", "k0.5-l15", "k1.5-l8"])
def test_error_system_eigenvalues_are_the_roots_of_N(tuning):
    """docs/theory.md §5.2, first bullet. The Courant-1 error system (observer − plant of §4,
    lumped friction, no saturation) at 250 cells, eigenvalues mapped by s = log(λ)/Δt.
    Matching: every discrete s with |Im s| < 25 rad/s and Re s > −60 is refined by Newton on
    N(s); the refined point is a root (|N| tiny), within 1e-3 rad/s of the discrete s
    (second-order scheme: the largest mismatch measured is 3.7e-4 at 250 cells and 1.0e-3 at
    150), and distinct discrete eigenvalues land on distinct roots. Completeness: the number
    of zeros of N in the same rectangle (argument principle) equals the number of discrete
    eigenvalues there, so the map is one-to-one."""
    p, n = as_params(), 250
    A, dt = error_system(p, tuning, n)
    s_d = discrete_s(A, dt)
    box = (np.abs(s_d.imag) < 25) & (s_d.real > -60)
    low = s_d[box]
    # guard: no eigenvalue near the contour, so the zero count is well defined
    assert np.min(np.abs(np.abs(s_d.imag) - 25)) > 0.2 and np.all(s_d.real[box] < 1.0)
    assert np.min(np.abs(s_d.real[np.abs(s_d.imag) < 25] + 60)) > 0.2
    roots = np.array([newton_root(s0, p, tuning) for s0 in low])
    scale = np.abs(roots) ** 3 + 1.0
    assert np.all(np.abs(characteristic_N(roots, p, tuning)) < 1e-9 * scale)
    assert np.max(np.abs(roots - low)) < 1e-3
    gaps = np.abs(roots[:, None] - roots[None, :]) + np.eye(roots.size) * 1e9
    assert gaps.min() > 1e-2
    assert zeros_inside(p, tuning, -60.0, 1.0, 25.0) == low.size


def test_default_tuning_low_modes_decay():
    """docs/theory.md §5.2: for the default tuning the modes of the error system with
    |Im s| < 25 rad/s all have Re s < 0, at several depths, and the lowest ones
    (|Im s| < 10 rad/s, the first torsional modes) decay faster than 0.1 1/s. The damping
    falls with frequency (−0.027 1/s at 25 rad/s for a 1200 m string): high-frequency error
    waves are damped by k_t alone (§5.1), so no uniform rate is asserted."""
    for md in (1200.0, 2500.0, 4500.0):
        p = as_params(md)
        A, dt = error_system(p, Tuning(), 150)
        s_d = discrete_s(A, dt)
        low = s_d[np.abs(s_d.imag) < 25]
        assert low.size >= 8
        assert low.real.max() < 0
        assert s_d[np.abs(s_d.imag) < 10].real.max() < -0.1


def test_error_system_accepts_gains_on_any_grid():
    """``error_system`` with Gains sampled on a finer cell-centred grid (resampled linearly)
    gives the same low modes as with the tuning (exact nodes): 1e-3 rad/s, the interpolation
    error of a smooth exponential profile on 500 cells."""
    p, n = as_params(), 150
    x = (np.arange(500) + 0.5) * p.Lp_m / 500
    A1, dt = error_system(p, Tuning(), n)
    A2, _ = error_system(p, backstepping_gains(p, Tuning(), x, T_N), n)
    s1, s2 = discrete_s(A1, dt), discrete_s(A2, dt)
    low1 = np.sort_complex(s1[np.abs(s1.imag) < 25])
    low2 = np.sort_complex(s2[np.abs(s2.imag) < 25])
    np.testing.assert_allclose(low1, low2, atol=1e-3)


# --- linear convergence of the estimates (signs) ---------------------------------------

def observer_injection(gains: Gains, params: LumpedParams, n: int, T_N_Nm: float) -> Injection:
    """Injection as the kernel applies it: the friction state adapts by dμ̂/dt = +l_k e, so
    dd̂/dt = T_N l_k e (the Gains' own p_d is not used — this pins the sign of l_k)."""
    inj = injection_on_nodes(gains, params, n)
    return dataclasses.replace(inj, p_d=-gains.l_k * T_N_Nm)


def simulate_pair(params, inj, n, mu_true, mu_start, seconds):
    """Lumped plant (true μ: constant friction torque μ·T_N at the BHA) and its observer, both
    starting at rest without twist, μ̂ = mu_start; the motor torque ramps to μ·T_N + 3 kN·m
    in 10 s (the linear plant then swings by tens of rad/s, undamped or lightly damped).
    Returns the histories of μ̂ and of ω̂_L − ω_L, one value per step."""
    d = mu_true * T_N
    plant = np.zeros(lumped.state_size(n))
    plant[-1] = d
    obs = np.zeros_like(plant)
    obs[-1] = mu_start * T_N
    dt = lumped.time_step_s(params, n)
    t = np.arange(round(seconds / dt) + 1) * dt
    tau = np.minimum(t / 10.0, 1.0) * (d + 3000.0)
    mu_hat, e_bha = np.empty(t.size - 1), np.empty(t.size - 1)
    for k in range(t.size - 1):
        new = lumped.step(params, Injection.none(n), plant, tau_m=(tau[k], tau[k + 1]))
        obs = lumped.step(params, inj, obs, y=(plant[0], new[0]), tau_m=(tau[k], tau[k + 1]))
        plant = new
        mu_hat[k], e_bha[k] = obs[-1] / T_N, obs[2 * n + 1] - plant[2 * n + 1]
    return mu_hat, e_bha


@pytest.mark.parametrize("design", ["backstepping", "kalman"])
def test_linear_convergence_of_friction_and_bit_speed(design):
    """docs/theory.md §5.2: with a constant true lumped friction torque d, d̂ → d and ω̂_L → ω_L.
    Observer and plant from rest, μ̂ = 0.1 against 0.3. Backstepping on the undamped model of
    §4; Kalman on its design model (k_t = 0.1 1/s, plant alike). After 50 s the low modes
    (slowest ≈ −0.15 1/s or faster) have shrunk the initial error by > e⁻⁷: μ̂ within 0.1 %
    and |ω̂_L − ω_L| < 0.02 rad/s over the last 10 s (measured 0.012 / 0.008), while the
    plant's BHA swings by ±30 rad/s — so the estimate tracks it."""
    n = 80
    if design == "kalman":
        p = as_params(k_t_per_s=0.1)
        gains = kalman_gains(p, lumped.nodes_m(p, n), T_N, lumped.time_step_s(p, n),
                             max_design_cells=40)
    else:
        p = as_params()
        gains = backstepping_gains(p, Tuning(), lumped.nodes_m(p, n), T_N)
    mu_hat, e_bha = simulate_pair(p, observer_injection(gains, p, n, T_N), n, 0.3, 0.1, 60.0)
    last = slice(round(50.0 / lumped.time_step_s(p, n)), None)
    assert np.all(np.abs(mu_hat[last] / 0.3 - 1) < 1e-3)
    assert np.abs(e_bha[last]).max() < 0.02


def test_started_at_the_truth_the_estimate_stays():
    """docs/theory.md §5.2 (signs): observer = plant initially, so e ≡ 0 and nothing moves, even
    through a torque kick: μ̂ stays at the truth to round-off."""
    p, n = as_params(), 60
    inj = observer_injection(backstepping_gains(p, Tuning(), lumped.nodes_m(p, n), T_N), p, n,
                             T_N)
    d = 0.3 * T_N
    plant = lumped.steady_state(p, n, 4.0, d)
    obs = plant.copy()
    for k in range(1500):
        tau = d + (2000.0 if 300 < k < 400 else 0.0)
        new = lumped.step(p, Injection.none(n), plant, tau_m=(tau, tau))
        obs = lumped.step(p, inj, obs, y=(plant[0], new[0]), tau_m=(tau, tau))
        plant = new
    np.testing.assert_allclose(obs, plant, rtol=1e-12, atol=1e-9)


def test_wrong_sign_of_l_k_does_not_converge():
    """Negative control for the sign test above: with dμ̂/dt = −l_k e the estimate runs away
    (more than 50 % off after 30 s), so the convergence test can fail."""
    p, n = as_params(), 60
    gains = backstepping_gains(p, Tuning(), lumped.nodes_m(p, n), T_N)
    inj = dataclasses.replace(observer_injection(gains, p, n, T_N), p_d=gains.l_k * T_N)
    mu_hat, _ = simulate_pair(p, inj, n, 0.3, 0.1, 30.0)
    assert abs(mu_hat[-1] - 0.3) > 0.15


# --- Kalman design ------------------------------------------------------------------------

@pytest.mark.parametrize("k_t", [0.0, 0.1])
def test_kalman_closed_loop_is_stable(k_t):
    """docs/theory.md §5.1: the steady-state Kalman error dynamics A − LC of the Courant-1 model
    (undamped as in §4, or with the default k_t) have every eigenvalue inside the unit
    circle except one: the grid's zero-speed torque checkerboard at λ = −1, which ω₀ cannot
    see (C v = 0) and which is left untouched. 1e-9 margin: round-off of the dense
    eigen-solve."""
    p, n = as_params(k_t_per_s=k_t), 40
    L = kalman_filter_gain(p, n)
    A = lumped.transition_matrix(p, Injection.none(n)) - np.outer(L, lumped.output_matrix(n))
    lam, vec = np.linalg.eig(A)
    outside = np.abs(lam) >= 1 - 1e-9
    assert np.count_nonzero(outside) == 1
    k = np.flatnonzero(outside)[0]
    assert lam[k] == pytest.approx(-1.0, abs=1e-9)
    v = vec[:, k]
    assert abs(v[0]) < 1e-9 and abs(v[2 * n + 1]) < 1e-9 and abs(v[2 * n + 2]) < 1e-9
    s_low = np.log(lam[~outside].astype(complex)) / lumped.time_step_s(p, n)
    assert s_low[np.abs(s_low.imag) < 25].real.max() < 0
    assert s_low[np.abs(s_low.imag) < 10].real.max() < -0.1      # measured −0.142 / −0.149


def test_kalman_mapping_preserves_the_low_modes():
    """The gain mapped onto the injection points (per unit time, P₀ = P₁ = 0) and run through
    the trapezoidal injection of ``error_system`` reproduces the DARE closed loop's low modes
    (|Im s| < 10 rad/s) within 0.05 rad/s — the O(Δt·p) difference between explicit (e_k) and
    trapezoidal (e_k, e_k+1) injection at Δt = 20 ms with |p| up to 80 1/s."""
    p, n = as_params(k_t_per_s=0.1), 40
    dt = lumped.time_step_s(p, n)
    L = kalman_filter_gain(p, n)
    A_dare = lumped.transition_matrix(p, Injection.none(n)) - np.outer(L, lumped.output_matrix(n))
    gains = kalman_gains(p, lumped.nodes_m(p, n), T_N, dt, max_design_cells=n)
    A_map, _ = error_system(p, gains, n)
    s1, s2 = discrete_s(A_dare, dt), discrete_s(A_map, dt)
    low1 = np.sort_complex(s1[(np.abs(s1.imag) < 10) & (s1.real > -3)])
    low2 = np.sort_complex(s2[(np.abs(s2.imag) < 10) & (s2.real > -3)])
    np.testing.assert_allclose(low2, low1, atol=0.05)
    assert gains.P0 == 0 and gains.P1 == 0 and gains.design == "kalman"
    assert gains.l_k == pytest.approx(-gains.p_d / T_N) and gains.l_k > 0


def test_kalman_gains_converge_with_the_design_grid():
    """Noise scaled as Q = qΔt, R = r/Δt: the gains per unit time converge as the grid is
    refined (Kalman–Bucy limit); 40 → 60 cells changes p_d and p₀ by < 5 % (measured 2.8 %,
    1.5 %)."""
    p = as_params(k_t_per_s=0.1)
    x = np.linspace(0, p.Lp_m, 50)
    g40 = kalman_gains(p, x, T_N, p.t_D_s / 40)
    g60 = kalman_gains(p, x, T_N, p.t_D_s / 60)
    assert g60.p_d == pytest.approx(g40.p_d, rel=0.05)
    assert g60.p0 == pytest.approx(g40.p0, rel=0.05)


def test_kalman_friction_injection_matches_backstepping_by_default():
    """KalmanNoise defaults are set so that p_d (the friction adaptation rate, l_k·T_N) is at
    the default backstepping level on this string (docs/observer_gains.md): within 10 %."""
    p = as_params(k_t_per_s=0.1)
    x = np.linspace(0, p.Lp_m, 50)
    kal = kalman_gains(p, x, T_N, 1e-3)
    bs = backstepping_gains(p, Tuning(), x, T_N)
    assert kal.p_d == pytest.approx(bs.p_d, rel=0.10)


# --- validation and configuration -------------------------------------------------------

def test_bad_inputs_raise_model_errors():
    p = as_params()
    with pytest.raises(ModelError, match="T_N"):
        backstepping_gains(p, Tuning(), [0.0, 10.0], 0.0)
    with pytest.raises(ModelError, match="depths"):
        backstepping_gains(p, Tuning(), [[0.0]], T_N)
    with pytest.raises(ModelError, match="κ₁"):
        Tuning(kappa1=2.0)
    with pytest.raises(ModelError, match="poles"):
        Tuning(z_per_s=0.0)
    with pytest.raises(ModelError, match="time step"):
        kalman_gains(as_params(k_t_per_s=0.1), [0.0], T_N, 0.0)


def test_gain_settings_select_the_design():
    string = as_string()
    x = np.linspace(5.0, string.bha_top_m - 5.0, 20)
    base = {"string": {"sections": AS_SECTIONS}}
    custom = config_from_dict({**base, "observer": {"gains": "backstepping", "kappa1": 0.8,
                                                    "lambda0_per_s": 12.0,
                                                    "poles_per_s": [0.8, 2.0]}})
    g = design_gains(GainSettings.from_config(custom), string, T_N, x, 2e-3)
    ref = backstepping_gains(LumpedParams.from_string(string, 2900.0), Tuning(0.8, 12.0, 0.8, 2.0),
                             x, T_N)
    assert g.P0 == pytest.approx(ref.P0) and g.l_k == pytest.approx(ref.l_k)
    kal = design_gains(GainSettings.from_config(config_from_dict(
        {**base, "observer": {"gains": "kalman"}})), string, T_N, x, 2e-3)
    assert kal.design == "kalman" and kal.p_beta.shape == x.shape
    assert g.design == "backstepping"
    with pytest.raises(ConfigError, match="poles_per_s"):
        GainSettings.from_config(config_from_dict({**base, "observer": {"gains": "backstepping",
                                                                 "poles_per_s": [1.0]}}),
                          string, T_N, x, 2e-3)


def test_kalman_noise_is_a_tuning_knob():
    """More trust in the measurement (smaller speed noise) gives larger injections."""
    p = as_params(k_t_per_s=0.1)
    x = np.linspace(0, p.Lp_m, 20)
    quiet = kalman_gains(p, x, T_N, 0.02, noise=KalmanNoise(speed_psd=2.7e-6))
    base = kalman_gains(p, x, T_N, 0.02)
    assert quiet.p0 > base.p0 and abs(quiet.p_d) > abs(base.p_d)


def test_kalman_injection_follows_the_logging_interval():
    """R = σ²·Δt_log: a 5 Hz log (20× the noise intensity of 100 Hz) gets a gentler
    top-drive injection and friction adaptation than a 100 Hz one."""
    from drillfric.config import config_from_dict
    from drillfric.drillstring import build_string

    cfg = config_from_dict({"string": {"sections": AS_SECTIONS}, "model": {"k_t_per_s": 0.1}})
    string = build_string(cfg.sections, 2500.0)
    x = np.linspace(1.0, string.bha_top_m - 1.0, 200)
    fast = design_gains(GainSettings.from_config(cfg), string, 50e3, x, 1e-3, sample_dt_s=0.01)
    slow = design_gains(GainSettings.from_config(cfg), string, 50e3, x, 1e-3, sample_dt_s=0.2)
    assert slow.p0 < fast.p0 and slow.l_k < fast.l_k


def test_kalman_design_is_shared_within_a_depth_band():
    """Issue 17 item 3: stands within gains.DESIGN_BAND_M share one Riccati solve. Moving
    the pipe length by half the band changes the injections by < 2 % (measured: p₀ and p_d
    by ≤ 0.06 %, p₁ by ≤ 1.1 % at 1500–3500 m) — far inside the tuning's own latitude
    (docs/observer_gains.md), so estimates do not move beyond noise."""
    from dataclasses import replace

    from drillfric.config import load_config
    from drillfric.drillstring import build_string
    from drillfric.estimation import gains as G

    cfg = load_config(REPO / "examples" / "demo" / "demo.toml")
    G._kalman_design.cache_clear()
    designs = []
    for depth in (2481.0, 2490.0, 2499.0):  # pipe lengths in at most two bands
        string = build_string(cfg.sections, depth)
        params = LumpedParams.from_string(string, 2900.0, k_t_per_s=0.1)
        x = np.linspace(0.0, params.Lp_m, 50)
        designs.append(G.kalman_gains(params, x, 1e4, 0.002))
    assert G._kalman_design.cache_info().misses <= 2
    params = LumpedParams.from_string(build_string(cfg.sections, 2500.0), 2900.0, k_t_per_s=0.1)
    n = 60
    exact = G.kalman_filter_gain(params, n)
    moved = G.kalman_filter_gain(replace(params, Lp_m=params.Lp_m + G.DESIGN_BAND_M / 2), n)
    for index in (0, 2 * n + 1, 2 * n + 2):  # p0, p1, p_d
        assert abs(moved[index] / exact[index] - 1.0) < 0.02
