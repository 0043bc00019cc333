"""Semi-lumped model of docs/theory.md §4 and its Courant-1 discretisation
(drillfric.estimation.lumped)."""

from __future__ import annotations

import numpy as np
import pytest

from drillfric.config import config_from_dict
from drillfric.drillstring import build_string
from drillfric.errors import ModelError
from drillfric.estimation import lumped
from drillfric.estimation.lumped import Injection, LumpedParams
from tests.synthetic import AS_SECTIONS


def as_params(md_m: float = 2500.0, **kw) -> LumpedParams:
    cfg = config_from_dict({"string": {"sections": AS_SECTIONS}})
    return LumpedParams.from_string(build_string(cfg.sections, md_m), 2900.0, **kw)


def free_plant_F(s, p: LumpedParams):
    """Characteristic function of the free lumped plant: loop gain R₀ R_L e^{−2 s t_D} = 1.

    Derived from docs/theory.md §4 with no injection: the top drive reflects β into α with
    R₀ = (a₀ − s)/(s + a₀), the BHA α into β with R_L = (a_L − s)/(s + a_L).
    """
    return ((s + p.a0_per_s) * (s + p.aL_per_s)
            - (p.a0_per_s - s) * (p.aL_per_s - s) * np.exp(-2.0 * s * p.t_D_s))


def test_from_string_coefficients():
    """a₀, a_L, c, L_p, I_BHA by hand from docs/theory.md §3–§4 (docs/reference_cases.md: c ≈ 2788
    m/s)."""
    p = as_params()
    J = np.pi * (0.146529**4 - 0.123024**4) / 32
    zeta = J * np.sqrt(61e9 * 7850)
    i_bha = sum(7850 * np.pi * (s["od_m"]**4 - s["id_m"]**4) / 32 * s["length_m"]
                for s in AS_SECTIONS[1:])
    assert p.c_m_s == pytest.approx(2788, abs=1)
    assert p.Lp_m == pytest.approx(2500 - 230.46)
    assert p.zeta_pipe_Nms == pytest.approx(zeta, rel=1e-12)
    assert p.a0_per_s == pytest.approx(zeta / 2900, rel=1e-12)
    assert p.aL_per_s == pytest.approx(zeta / i_bha, rel=1e-12)
    assert p.t_D_s == pytest.approx(p.Lp_m / p.c_m_s)


def test_from_string_needs_a_bha_and_inertia():
    cfg = config_from_dict({"string": {"sections": AS_SECTIONS[:1]}})
    with pytest.raises(ModelError, match="BHA"):
        LumpedParams.from_string(build_string(cfg.sections, 2000.0), 2900.0)
    with pytest.raises(ModelError, match="inertia"):
        LumpedParams.from_string(build_string(config_from_dict(
            {"string": {"sections": AS_SECTIONS}}).sections, 2500.0), 0.0)


def test_transport_is_an_exact_shift():
    """Courant 1 (docs/theory.md §3.1): interior invariants move one node per step, bit for bit."""
    p, n = as_params(), 50
    z = np.random.default_rng(1).normal(size=lumped.state_size(n))
    z1 = lumped.step(p, Injection.none(n), z)
    assert np.array_equal(z1[2:n + 1], z[1:n])                      # α_j ← α_{j−1}
    assert np.array_equal(z1[n + 1:2 * n], z[n + 2:2 * n + 1])      # β_j ← β_{j+1}


def test_steady_rotation_is_a_fixed_point():
    """With τ_m = d the string turns steadily with uniform twist τ = d (docs/theory.md §4)."""
    p, n = as_params(), 40
    z = lumped.steady_state(p, n, 4.0, 9000.0)
    z1 = lumped.step(p, Injection.none(n), z, tau_m=(9000.0, 9000.0))
    np.testing.assert_allclose(z1, z, rtol=0, atol=1e-12 * 20)


def test_column_batch_equals_single_steps():
    """``step`` on a matrix of states equals stepping each column (used for A)."""
    p, n = as_params(), 30
    z = np.random.default_rng(2).normal(size=(lumped.state_size(n), 3))
    inj = Injection(3.0, -5.0, np.linspace(1, 2, n + 1), np.linspace(-4, 4, n + 1), 0.5, 2.0,
                    -700.0)
    batch = lumped.step(p, inj, z)
    for k in range(3):
        np.testing.assert_allclose(batch[:, k], lumped.step(p, inj, z[:, k]), rtol=1e-13,
                                   atol=1e-13)


def test_free_plant_is_lossless():
    """Without damping the lumped plant stores energy only: every discrete eigenvalue lies on
    the unit circle (trapezoidal ODEs and exact transport add no numerical damping). 1e-10:
    round-off of a dense eigen-solve of a 203 × 203 matrix."""
    A = lumped.transition_matrix(as_params(), Injection.none(100))
    np.testing.assert_allclose(np.abs(np.linalg.eigvals(A)), 1.0, atol=1e-10)


def test_damping_only_removes_energy():
    """k_t > 0 (docs/theory.md §3): no eigenvalue outside the unit circle; the rigid rotation now
    decays, and the only ones left on it are the constant friction torque d (λ = 1) and the
    grid's zero-speed torque checkerboard (λ = −1, which nodal viscous damping cannot see)."""
    A = lumped.transition_matrix(as_params(k_t_per_s=0.1), Injection.none(60))
    lam = np.linalg.eigvals(A)
    assert np.abs(lam).max() < 1 + 1e-10
    on_circle = np.sort_complex(lam[np.abs(lam) > 1 - 1e-9])
    np.testing.assert_allclose(on_circle, [-1, 1], atol=1e-9)


@pytest.mark.parametrize("n", [150, 250])
def test_free_plant_modes_match_the_analytic_loop(n):
    """Discrete eigenvalues (s = log λ/Δt, |Im s| < 20 rad/s) are roots of the free plant's
    characteristic function (derived from docs/theory.md §4, see free_plant_F): refined by Newton
    on F, each moves by less than 5e-4·(150/n)² rad/s — the scheme is second order; the
    largest mode error measured is 1.9e-4 rad/s at 150 cells and 6.8e-5 at 250."""
    p = as_params()
    A = lumped.transition_matrix(p, Injection.none(n))
    s_d = np.log(np.linalg.eigvals(A).astype(complex)) / lumped.time_step_s(p, n)
    low = s_d[(np.abs(s_d.imag) < 20) & (np.abs(s_d) > 1e-6)]
    assert low.size == 12                          # six torsional modes up to 3.2 Hz, ± pairs
    for s0 in low:
        s, ds = s0, 1e-7
        for _ in range(30):
            s = s - free_plant_F(s, p) / ((free_plant_F(s + ds, p) - free_plant_F(s, p)) / ds)
        assert abs(free_plant_F(s, p)) < 1e-9 * abs(s)**2
        assert abs(s - s0) < 5e-4 * (150 / n)**2
        assert abs(s.real) < 1e-8                  # lossless: modes on the imaginary axis


def test_first_torsional_mode_near_the_published_one():
    """docs/reference_cases.md: the A&S 2018 synthetic well (2500 m, this pipe, a 230 m BHA) has
    its first
    torsional mode near 0.22 Hz. Lumping the BHA into a rigid inertia stiffens the string,
    so within 15 % only (we get 0.241 Hz)."""
    p, n = as_params(), 100
    A = lumped.transition_matrix(p, Injection.none(n))
    f = np.log(np.linalg.eigvals(A).astype(complex)).imag / lumped.time_step_s(p, n) / (2 * np.pi)
    first = np.min(f[f > 1e-6])
    assert first == pytest.approx(0.22, rel=0.15)


def test_kt_damps_the_speed_checkerboard():
    """docs/theory.md §5.1: physical damping is what kills grid-scale speed waves. With k_t = 0 a
    node-alternating speed pattern (α = β = ±1) is an undamped λ = −1 mode; with k_t > 0
    it decays by (1 − k_t Δt) per step (explicit viscous term)."""
    n = 40
    z = np.zeros(lumped.state_size(n))
    sign = (-1.0) ** np.arange(n + 1)
    z[1:n + 1], z[n + 1:2 * n + 1] = sign[1:], sign[:-1]
    for kt in (0.0, 0.2):
        p = as_params(k_t_per_s=kt)
        z1 = lumped.step(p, Injection.none(n), z)
        interior = slice(2, n)
        ratio = z1[interior] / z[interior]
        np.testing.assert_allclose(ratio, -(1 - kt * lumped.time_step_s(p, n)), rtol=1e-12)

