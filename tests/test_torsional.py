"""Torsional plant (docs/theory.md §3, §3.1): exact wave invariants and friction closed forms."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from drillfric import torsional as T
from drillfric.drillstring import DrillString, Section
from drillfric.errors import ModelError

RPM = np.pi / 30.0


def section(name, od, id_, length, g=61e9):
    """A plain-steel section (mass from the steel area, contact radius OD/2)."""
    return Section(name, od, id_, length, od / 2.0, 7850.0 * np.pi * (od**2 - id_**2) / 4.0, g)


def two_section_string(pipe_m=2270.0):
    """A&S drill pipe over 230 m of 8in collars (docs/reference_cases.md)."""
    return DrillString((section("dp", 0.146529, 0.123024, pipe_m),
                        section("dc", 0.2096, 0.0714, 230.0, 67e9)))


def clamp_top():
    """Top drive held at ω₀ = 0 (prescribed speed): α(0) = −β(0), no energy exchange."""
    return T.Drive("speed", np.array([0.0]), 1.0)


def steps(plant, drive, n, state):
    """Advance exactly n model steps."""
    _, out = T.run(plant, drive, n * plant.grid.dt_s, 1.0 / (n * plant.grid.dt_s), state)
    return out


def frictionless(grid, k_t=0.0):
    return T.Plant(grid, np.zeros(grid.n_cells), 0.0, 0.0, 1.0, k_t)


# ------------------------------------------------------------------------------ grid

def test_grid_courant_one_in_every_section():
    """docs/theory.md §3.1: Δx_i = c_i·Δt, whole cells, rounding at most half a cell per section."""
    g = T.make_grid(two_section_string(), 500)
    counts = np.diff(g.section_start)
    np.testing.assert_allclose(g.model_length_m, counts * g.wave_speed_m_s * g.dt_s,
                               rtol=1e-15)
    assert np.all(np.abs(g.rounding_m) <= 0.5 * g.wave_speed_m_s * g.dt_s + 1e-9)
    assert abs(g.n_cells - 500) <= 25
    assert g.travel_time_s == pytest.approx(np.sum(g.model_length_m / g.wave_speed_m_s))


def test_grid_keeps_true_friction_integral():
    """Cells spread over the true lengths: Σ F_c·Δx_true = ∫F_c dx despite the rounding."""
    g = T.make_grid(two_section_string(), 97)
    plant = T.Plant(g, np.full(g.n_cells, 20.0), 0.5, 0.3, 1.0)
    assert plant.T_N_Nm == pytest.approx(20.0 * 2500.0, rel=1e-12)


# --------------------------------------------------------------- waves (no friction)

def test_pulse_reaches_bit_after_exactly_L_over_c_and_reflects():
    """docs/theory.md §3: with Courant 1 a pulse is shifted one cell per step, exactly.

    A one-step speed pulse at the top (α(0) = 2ω₀) enters cell 0 at step 1 and the bit
    cell at step N: travel time N·Δt = L/c. The free bit reflects β = α (coefficient +1,
    eq. 40 erratum) and the clamped top α = −β (coefficient −1). Exact to the last bit.
    """
    dp = section("dp", 0.146529, 0.123024, 1000.0)
    g = T.make_grid(DrillString((dp,)), 200)
    n = g.n_cells
    assert g.travel_time_s == pytest.approx(1000.0 / dp.wave_speed_m_s, rel=1e-12)
    plant = frictionless(g)
    pulse = T.Drive("speed", np.array([1.0, 0.0, 0.0]), g.dt_s)
    state = steps(plant, pulse, n - 1, T.State.rest(g))
    assert state.alpha[-1] == 0.0
    state = steps(plant, clamp_top(), 1, state)
    assert state.alpha[-1] == 2.0 and state.beta[-1] == 0.0
    state = steps(plant, clamp_top(), 1, state)
    assert state.beta[-1] == 2.0
    state = steps(plant, clamp_top(), n - 1, state)
    assert state.beta[0] == 2.0 and state.alpha[0] == 0.0
    state = steps(plant, clamp_top(), 1, state)
    assert state.alpha[0] == -2.0


def test_junction_reflection_and_transmission_coefficients():
    """docs/theory.md §3 eqs. (12)–(14): α_b = 2α_a/(1+Z), β_a = (1−Z)α_a/(1+Z) for an incoming
    α_a."""
    s = two_section_string(1000.0)
    g = T.make_grid(s, 300)
    first = int(g.section_start[1])
    z = g.junction_z[0]
    state = T.State.rest(g)
    state.alpha[first - 1] = 1.0
    state = steps(frictionless(g), clamp_top(), 1, state)
    assert state.alpha[first] == pytest.approx(2.0 / (1.0 + z), rel=1e-15)
    assert state.beta[first - 1] == pytest.approx((1.0 - z) / (1.0 + z), rel=1e-15)
    assert z == pytest.approx(s.sections[1].impedance_Nms / s.sections[0].impedance_Nms)


def _junction_string(lower_od):
    """1000 m of 5 7/8in pipe over 300 m of a section with another OD (Z ≠ 1)."""
    return DrillString((section("dp", 0.146529, 0.123024, 1000.0),
                        section("low", lower_od, 0.6 * lower_od, 300.0, 67e9)))


@pytest.mark.parametrize("lower_od", [0.2096, 0.11])
def test_junction_mirror_case_beta_from_below(lower_od):
    """docs/theory.md §3 eqs. (12)–(14), the other direction: a β wave arriving from the lower
    section (α_a = 0) is transmitted as β_a = 2Zβ_b/(1+Z) and reflected as
    α_b = −(1 − Z)β_b/(1+Z), Z = ζ_b/ζ_a, for a stiffer (Z > 1, collars) and a softer (Z < 1)
    lower section. Energy flux is conserved across the junction:
    ζ_aβ_a² + ζ_bα_b² = ζ_bβ_b². One step of the exact formulas: rel 1e-15 (round-off).
    """
    s = _junction_string(lower_od)
    g = T.make_grid(s, 300)
    first = int(g.section_start[1])
    z = g.junction_z[0]
    assert (z > 1.0) == (lower_od > 0.15)
    state = T.State.rest(g)
    state.beta[first] = 1.0
    state = steps(frictionless(g), clamp_top(), 1, state)
    beta_a, alpha_b = state.beta[first - 1], state.alpha[first]
    assert beta_a == pytest.approx(2.0 * z / (1.0 + z), rel=1e-15)
    assert alpha_b == pytest.approx(-(1.0 - z) / (1.0 + z), rel=1e-15)
    za, zb = g.zeta_Nms[first - 1], g.zeta_Nms[first]
    assert za * beta_a**2 + zb * alpha_b**2 == pytest.approx(zb, rel=1e-14)
    assert np.count_nonzero(state.alpha) == 1 and np.count_nonzero(state.beta) == 1


@pytest.mark.parametrize("direction", ["alpha", "beta"])
def test_unit_impedance_junction_passes_a_pulse_unchanged(direction):
    """Z = 1 (docs/theory.md §3.1): the junction formulas give α_b = α_a and β_a = β_b exactly, so a
    pulse crosses in either direction bit-identically and nothing is reflected."""
    two = DrillString((section("a", 0.15, 0.12, 600.0), section("b", 0.15, 0.12, 900.0)))
    g = T.make_grid(two, 300)
    first = int(g.section_start[1])
    assert g.junction_z[0] == 1.0
    state = T.State.rest(g)
    if direction == "alpha":
        state.alpha[first - 3: first] = [0.3, -1.7, 2.9]
    else:
        state.beta[first: first + 3] = [0.3, -1.7, 2.9]
    state = steps(frictionless(g), clamp_top(), 3, state)
    if direction == "alpha":
        np.testing.assert_array_equal(state.alpha[first: first + 3], [0.3, -1.7, 2.9])
        assert not np.any(state.beta)
    else:
        np.testing.assert_array_equal(state.beta[first - 3: first], [0.3, -1.7, 2.9])
        assert not np.any(state.alpha)


@pytest.mark.parametrize("end", ["clamped", "free"])
def test_bit_reflection_clamped_and_free(end):
    """docs/theory.md §3, bit boundary (and erratum E2 on eq. 40). A square speed pulse (α = 1 over
    m cells: ω = 1/2, τ = ζ/2) runs into the bit.

    Clamped bit — a stuck bit whose Coulomb cap T_bit exceeds the wave's torque, so
    β = α − 2τ_bit/ζ = −α (the paper's printed eq. 40): the reflection carries the speed
    inverted (ω = −1/2) and the torque with the same sign (τ = +ζ/2); where incident and
    reflected overlap the speed is 0 and the torque doubled (ζ). Free bit (off bottom,
    β = α): speed keeps its sign and doubles in the overlap, torque inverts and cancels.
    Exact shifts of exact values: compared bit-for-bit.
    """
    g = T.make_grid(DrillString((section("dp", 0.146529, 0.123024, 1000.0),
                                 section("dc", 0.2096, 0.0714, 200.0, 67e9))), 300)
    n, m = g.n_cells, 10
    zeta = g.zeta_Nms[-1]
    cap = 1e12 if end == "clamped" else 0.0
    plant = T.Plant(g, np.zeros(n), 0.0, 0.0, 1.0, 0.0, bit_torque_cap_Nm=cap)
    state = T.State.rest(g)
    state.alpha[n - m:] = 1.0
    half = steps(plant, clamp_top(), m // 2, state)
    overlap = slice(n - m // 2, n)
    omega = half.omega_rad_s[overlap]
    torque = half.torque_Nm(g)[overlap]
    sign = -1.0 if end == "clamped" else 1.0
    np.testing.assert_array_equal(omega, 0.0 if end == "clamped" else 1.0)
    np.testing.assert_array_equal(torque, zeta if end == "clamped" else 0.0)
    full = steps(plant, clamp_top(), m // 2, half)
    np.testing.assert_array_equal(full.beta[n - m:], sign)
    np.testing.assert_array_equal(full.alpha[n - m:], 0.0)
    np.testing.assert_array_equal(full.omega_rad_s[n - m:], sign * 0.5)
    np.testing.assert_array_equal(full.torque_Nm(g)[n - m:], -sign * 0.5 * zeta)


def test_coulomb_bit_holds_below_its_cap_and_slips_above():
    """docs/theory.md §3 bit: τ(L) = ζ·clamp(α, ±T_bit/ζ). An incident wave whose clamped-end
    torque ζα stays within T_bit reflects as from a clamped end (β = −α); a stronger one
    slips the bit with τ(L) = T_bit exactly, β = α − 2T_bit/ζ."""
    g = T.make_grid(DrillString((section("dp", 0.146529, 0.123024, 1000.0),)), 100)
    n, zeta = g.n_cells, g.zeta_Nms[-1]
    cap = 2.0 * zeta  # T_bit/ζ = 2 rad/s
    plant = T.Plant(g, np.zeros(n), 0.0, 0.0, 1.0, 0.0, bit_torque_cap_Nm=cap)
    for a_in, b_out in ((1.5, -1.5), (3.0, 3.0 - 4.0)):
        state = T.State.rest(g)
        state.alpha[-1] = a_in
        out = steps(plant, clamp_top(), 1, state)
        assert out.beta[-1] == pytest.approx(b_out, rel=1e-15)
        assert 0.5 * zeta * (a_in - out.beta[-1]) == pytest.approx(min(zeta * a_in, cap),
                                                                   rel=1e-15)


def test_rate_weakening_bit_at_rest_holds_r_times_T_k_then_slips_at_it():
    """docs/theory.md §3 bit, rate-weakening: a bit at rest (face speed 0 at the step before)
    has the break-away capacity r·T_k. A wave arriving at a resting bit with ζα between T_k
    and r·T_k reflects as from a clamped end (β = −α), where the Coulomb bit would slip; a
    stronger one slips it with τ(L) = r·T_k exactly (the capacity at ω = 0)."""
    g = T.make_grid(DrillString((section("dp", 0.146529, 0.123024, 1000.0),)), 100)
    n, zeta = g.n_cells, g.zeta_Nms[-1]
    t_k, r = 2.0 * zeta, 2.5  # T_k/ζ = 2 rad/s, r·T_k/ζ = 5 rad/s
    plant = T.Plant(g, np.zeros(n), 0.0, 0.0, 1.0, 0.0, bit_torque_cap_Nm=t_k,
                    bit_weakening_ratio=r, bit_weakening_speed_rad_s=1.0)
    for a_in, b_out in ((4.0, -4.0), (6.0, 6.0 - 10.0)):
        state = T.State.rest(g)
        state.alpha[-2] = a_in  # reaches the bit cell after one step, the bit at rest
        out = steps(plant, clamp_top(), 2, state)
        assert out.beta[-1] == pytest.approx(b_out, rel=1e-15)


@pytest.mark.parametrize("ratio", [1.0, 2.5])
def test_stuck_bit_breaks_away_at_r_times_T_k(ratio):
    """A frictionless string wound up by a slowly rising motor torque (150 N·m/s) against a
    stuck bit: the recorded bit torque follows the twist up to r·T_k (within 1e-3; the
    ramp moves 0.6 N·m per model step) while the bit stays put (|ω_bit| < 1e-3 rad/s), then
    the bit slips and the torque falls to the sliding T_bit(ω) → T_k at speed (ω ≫ ω_b).
    The Coulomb bit (r = 1) lets go at T_k, (r − 1)·T_k/150 s = 15 s earlier for r = 2.5."""
    from drillfric.sim.well_b import well_b_plant

    t_k = 1500.0
    p = well_b_plant(cells=200, k_t_per_s=0.1, mu_s=0.0, mu_k=0.0)
    plant = T.Plant(p.grid, p.fc_Nm_m, 0.0, 0.0, p.omega_c_rad_s, p.k_t_per_s,
                    bit_torque_cap_Nm=t_k, bit_weakening_ratio=ratio,
                    bit_weakening_speed_rad_s=1.0)
    rec, _ = T.run(plant, T.Drive("torque", np.array([0.0, 4 * t_k]), 40.0), 40.0, 100.0)
    assert rec.bit_torque_Nm.max() == pytest.approx(ratio * t_k, rel=1e-3)
    broke = int(np.argmax(rec.bit_torque_Nm >= 0.99 * ratio * t_k))
    assert np.abs(rec.bit_rad_s[:broke]).max() < 1e-3
    assert rec.time_s[broke] == pytest.approx(ratio * t_k / 150.0, abs=2.0)
    assert rec.bit_rad_s[-1] > 10.0
    assert rec.bit_torque_Nm[-1] == pytest.approx(plant.bit_torque_Nm(rec.bit_rad_s[-1]),
                                                  rel=1e-3)


@pytest.mark.parametrize("ratio, speed_rad_s, rpm", [(3.0, 5.0, 100.0), (2.0, 3.0, 60.0)])
def test_steady_rotation_on_a_rate_weakening_bit_adds_T_bit_of_omega(ratio, speed_rad_s, rpm):
    """docs/theory.md §3 bit: turning steadily at ω (Well B, μ_s = μ_k, k_t = 0.5 1/s: stable
    sliding, the law's slope (r − 1)·T_k/ω_b·e^(−ω/ω_b) ≤ 75 N·m·s against ζ_BHA ≈ 7900),
    the mean motor torque on bottom exceeds the off-bottom one by
    T_bit(ω) = T_k·(1 + (r − 1)·exp(−ω/ω_b)) — 12–25 % above T_k here — within 1e-4
    (measured 3e-6 and 4e-6 over the last 20 s of 80), and the recorded bit torque is
    the same."""
    from drillfric.sim.well_b import well_b_plant

    off = well_b_plant(cells=200, k_t_per_s=0.5, mu_s=0.2, mu_k=0.2)
    on = T.Plant(off.grid, off.fc_Nm_m, off.mu_s, off.mu_k, off.omega_c_rad_s,
                 off.k_t_per_s, bit_torque_cap_Nm=1500.0, bit_weakening_ratio=ratio,
                 bit_weakening_speed_rad_s=speed_rad_s)
    drive = T.Drive("pi", np.array([0.0, rpm * RPM]), 10.0)
    off_rec, _ = T.run(off, drive, 80.0, 5.0)
    on_rec, _ = T.run(on, drive, 80.0, 5.0)
    last = on_rec.time_s > 60.0
    gained = float(np.mean(on_rec.motor_torque_Nm[last] - off_rec.motor_torque_Nm[last]))
    want = 1500.0 * (1.0 + (ratio - 1.0) * np.exp(-rpm * RPM / speed_rad_s))
    assert want == pytest.approx(on.bit_torque_Nm(rpm * RPM), rel=1e-12)
    assert want > 1.1 * 1500.0
    assert gained == pytest.approx(want, rel=1e-4)
    assert float(np.mean(on_rec.bit_torque_Nm[last])) == pytest.approx(want, rel=1e-4)


def test_unit_impedance_junction_is_transparent():
    """Z = 1: the junction formulas reduce to α_b = α_a, β_a = β_b (bit-identical states).

    docs/theory.md §3.1 states it without damping; friction is cell-local, so it is included.
    """
    one = DrillString((section("a", 0.15, 0.12, 1500.0),))
    two = DrillString((section("a", 0.15, 0.12, 600.0), section("b", 0.15, 0.12, 900.0)))
    g1, g2 = T.make_grid(one, 300), T.make_grid(two, 300)
    assert g2.junction_z[0] == 1.0 and g1.n_cells == g2.n_cells
    rng = np.random.default_rng(3)
    a, b = rng.normal(size=g1.n_cells), rng.normal(size=g1.n_cells)
    drive = T.Drive("pi", np.array([0.0, 4.0]), 5.0)
    fc = np.linspace(5.0, 30.0, g1.n_cells)
    p1, p2 = (T.Plant(g, fc, 0.6, 0.3, 1.0) for g in (g1, g2))
    r1, s1 = T.run(p1, drive, 5.0, 20.0, T.State(a.copy(), b.copy()))
    r2, s2 = T.run(p2, drive, 5.0, 20.0, T.State(a.copy(), b.copy()))
    np.testing.assert_array_equal(s1.alpha, s2.alpha)
    np.testing.assert_array_equal(r1.string_torque_Nm, r2.string_torque_Nm)


def _random_string(lengths, ods, g_moduli):
    rows = zip(lengths, ods, g_moduli, strict=True)
    return DrillString(tuple(section(f"s{i}", od, 0.6 * od, length, gm)
                             for i, (length, od, gm) in enumerate(rows)))


@settings(max_examples=15, deadline=None)
@given(n_sec=st.integers(1, 4), seed=st.integers(0, 2**31 - 1))
def test_energy_conserved_without_friction_and_damping(n_sec, seed):
    """docs/theory.md §3.1: transport is a shift and the junctions are lossless, so the energy
    Σ ζΔt(α² + β²)/4 is conserved exactly (up to round-off, ~1e-13 after 10 000 steps)."""
    rng = np.random.default_rng(seed)
    s = _random_string(rng.uniform(30.0, 800.0, n_sec), rng.uniform(0.1, 0.25, n_sec),
                       rng.uniform(60e9, 80e9, n_sec))
    g = T.make_grid(s, 150)
    state = T.State(rng.normal(size=g.n_cells), rng.normal(size=g.n_cells))
    e0 = T.energy(g, state)
    out = steps(frictionless(g), clamp_top(), 10_000, state)
    assert T.energy(g, out) == pytest.approx(e0, rel=1e-11)


def free_top():
    """Top drive free: no motor torque, its inertia coupled to the string (eq. 7)."""
    return T.Drive("torque", np.array([0.0]), 1.0)


@settings(max_examples=10, deadline=None)
@given(n_sec=st.integers(1, 4), seed=st.integers(0, 2**31 - 1),
       i_td=st.floats(50.0, 5000.0), backend=st.sampled_from(["numba", "numpy"]))
def test_energy_conserved_with_free_top_drive(n_sec, seed, i_td, backend):
    """docs/theory.md §3 eq. (7) with τ_m = 0, no friction, k_t = 0, free bit: the total energy
    ½∫ρJω² dx + ½∫τ²/(GJ) dx + ½I_TDω₀² of the continuum is constant.

    The top-drive coupling of docs/theory.md erratum E11 (trapezoidal ω₀ update with the
    boundary value α(0) = 2ω̄₀ − β(0)) conserves the discrete energy exactly, so the check
    is to round-off: rel 1e-10 after 20 000 steps (round-off drifts up to ~2e-16 per step;
    measured ≤ 4e-12 over 36 draws). The explicit Euler step 4 of docs/theory.md §3.1 adds
    ½ζa₀Δt²(β(0) − ω₀)² every step: +3.2 % in 100 s for a random state on the A&S string,
    and it is unstable for a₀Δt > 2 (light top drive, stiff pipe: ×10³⁴ here at I_TD = 50).
    """
    rng = np.random.default_rng(seed)
    s = _random_string(rng.uniform(30.0, 800.0, n_sec), rng.uniform(0.1, 0.25, n_sec),
                       rng.uniform(60e9, 80e9, n_sec))
    g = T.make_grid(s, 150)
    plant = T.Plant(g, np.zeros(g.n_cells), 0.0, 0.0, 1.0, 0.0, i_td)
    state = T.State(rng.normal(size=g.n_cells), rng.normal(size=g.n_cells),
                    np.array([rng.normal(), 0.0]))
    e0 = T.energy(g, state, i_td)
    n = 20_000 if backend == "numba" else 2_000
    out = steps(plant, free_top(), n, state)
    assert T.energy(g, out, i_td) == pytest.approx(e0, rel=1e-10)


def test_energy_after_motor_torque_stops_is_constant():
    """Spin the A&S string up with 20 kN·m for 5 s, then τ_m = 0 (no friction, k_t = 0,
    free bit): from then on the energy of string + top drive must stay constant (docs/theory.md §3
    eq. 7; docs/theory.md E11). Tolerance rel 1e-10 over 200 s (1.1·10⁵ steps): round-off
    of the ω₀ update drifts ~1e-16 per step on this nearly rigid rotation (measured −1.4e-11
    at the end). With the explicit step 4 of docs/theory.md §3.1 it grew by +1.2e-4.
    """
    g = T.make_grid(two_section_string(), 500)
    plant = T.Plant(g, np.zeros(g.n_cells), 0.0, 0.0, 1.0, 0.0, 2900.0)
    drive = T.Drive("torque", np.array([20e3, 20e3, 0.0]), 5.0)
    _, state = T.run(plant, drive, 10.0, 10.0)
    energies = [T.energy(g, state, 2900.0)]
    for _ in range(10):
        _, state = T.run(plant, drive, 20.0, 10.0, state)
        energies.append(T.energy(g, state, 2900.0))
    assert energies[0] > 1e6
    np.testing.assert_allclose(energies, energies[0], rtol=1e-10)


def test_motor_work_equals_energy_change():
    """Discrete work–energy identity of the trapezoidal top-drive coupling (docs/theory.md
    E11): E^N − E^0 = Σ_k Δt·τ_m^k·(ω₀^k + ω₀^{k+1})/2 exactly, for any motor torque (no
    friction, k_t = 0, free bit). Recorded at every step; rel 1e-10 covers the round-off of
    the step-time interpolation of the records (measured 1e-13; the explicit coupling of
    docs/theory.md §3.1 step 4 misses by −7.5e-5)."""
    g = T.make_grid(two_section_string(), 200)
    plant = T.Plant(g, np.zeros(g.n_cells), 0.0, 0.0, 1.0, 0.0, 2900.0)
    t = np.arange(0.0, 12.0, 0.5)
    drive = T.Drive("torque", 15e3 * np.sin(t) + 5e3 * np.cos(3.1 * t), 0.5)
    n = 4000
    start = T.State.rest(g)
    rec, out = T.run(plant, drive, n * g.dt_s, 1.0 / g.dt_s, start)
    assert rec.time_s.size == n + 1
    w, q = rec.surface_rad_s, rec.motor_torque_Nm
    work = float(np.sum(g.dt_s * q[:-1] * 0.5 * (w[:-1] + w[1:])))
    assert T.energy(g, out, 2900.0) == pytest.approx(work, rel=1e-10)
    assert work > 1e4


@settings(max_examples=10, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), k_t=st.floats(0.01, 5.0))
def test_viscous_damping_dissipates_every_step(seed, k_t):
    """Viscous term along the characteristics (docs/simulator.md): energy never grows,
    even for grid-scale waves (evaluated at the cell itself it would grow at rate k_t)."""
    rng = np.random.default_rng(seed)
    g = T.make_grid(two_section_string(), 100)
    state = T.State(rng.normal(size=g.n_cells), rng.normal(size=g.n_cells))
    plant = frictionless(g, k_t)
    energies = [T.energy(g, state)]
    for _ in range(20):
        state = steps(plant, clamp_top(), 50, state)
        energies.append(T.energy(g, state))
    assert np.all(np.diff(energies) <= 1e-12 * energies[0])
    assert energies[-1] < energies[0]


def test_sawtooth_is_damped():
    """The grid-scale mode that the cell-centred viscous term amplifies decays here."""
    g = T.make_grid(DrillString((section("a", 0.15, 0.12, 1000.0),)), 200)
    saw = np.cos(np.pi * np.arange(g.n_cells))
    state = T.State(saw.copy(), saw.copy())
    out = steps(frictionless(g, 1.0), clamp_top(), int(5.0 / g.dt_s), state)
    assert T.energy(g, out) < 0.01 * T.energy(g, state)


# ----------------------------------------------------------------- friction, closed forms

def _string_and_fc(fc=20.0, cells=500):
    g = T.make_grid(two_section_string(), cells)
    return g, np.full(g.n_cells, fc)


def test_steady_rotation_torque_is_kinetic_friction_plus_viscous():
    """docs/theory.md §3.1: steady sliding at Ω needs τ(0) = μ_k∫F_c dx + k_t Ω ∫ρJ dx.

    Tolerance 0.5 %: the steady state of the first-order scheme carries an O(k_t·Δt) speed
    gradient along the string (0.07 % here); the PI integral removes the speed error.
    """
    g, fc = _string_and_fc()
    k_t, omega = 0.3, 60 * RPM
    plant = T.Plant(g, fc, 0.3, 0.2, 0.5, k_t)
    rec, _ = T.run(plant, T.Drive("pi", np.array([0.0, omega]), 10.0), 100.0, 10.0)
    viscous = k_t * omega * float(np.sum(g.rho_j_kg_m * g.dx_model_m))
    expected = 0.2 * plant.T_N_Nm + viscous
    assert rec.motor_torque_Nm[-1] == pytest.approx(expected, rel=5e-3)
    assert rec.string_torque_Nm[-1] == pytest.approx(expected, rel=5e-3)
    assert rec.bit_rad_s[-1] == pytest.approx(omega, rel=5e-3)


def test_creep_torque_is_static_friction():
    """docs/theory.md §6.3: with the whole string turning below ω_c every element carries μ_s·F_c,
    so the mean torque tends to μ_s∫F_c dx (no damping). Without damping the BHA keeps
    oscillating inside the static band, so means over the last 50 s are compared; 1 %
    covers the residual oscillation of the mean."""
    g, fc = _string_and_fc()
    plant = T.Plant(g, fc, 0.6, 0.3, 1.0, 0.0)
    rec, _ = T.run(plant, T.Drive("pi", np.array([0.0, 0.3]), 5.0), 200.0, 10.0)
    late = rec.time_s > 150.0
    assert rec.string_torque_Nm[late].mean() == pytest.approx(0.6 * plant.T_N_Nm, rel=0.01)
    assert rec.bit_rad_s[late].mean() == pytest.approx(0.3, rel=0.05)
    assert rec.bit_rad_s[late].max() < 1.0


def _break_free_torque(cells):
    g, fc = _string_and_fc(cells=cells)
    plant = T.Plant(g, fc, 0.6, 0.3, 1.0, 0.0)
    rec, _ = T.run(plant, T.Drive("pi", np.array([0.0, 0.3]), 5.0), 120.0, 100.0)
    moving = np.argmax(np.abs(rec.bit_rad_s) > 1e-6)
    assert moving > 0
    return rec.string_torque_Nm[: moving + 1].max() / (0.6 * plant.T_N_Nm)


def test_break_free_torque_converges_to_static_friction_integral():
    """A&S 2018 eq. 27: the bit breaks free when the top torque reaches μ_s∫F_c dx.

    The Courant-1 friction inclusion lets torque diffuse through stuck cells (numerical
    diffusivity ≈ cΔx/2, docs/simulator.md), so the bit breaks free early on a coarse grid:
    −9 % at 500 cells for a 3 RPM creep. The deficit must shrink at least 1.7× per doubling
    of the cells (first order), and never overshoot.
    """
    r500, r1000 = _break_free_torque(500), _break_free_torque(1000)
    assert 0.85 < r500 < r1000 <= 1.0
    assert (1.0 - r1000) < (1.0 - r500) / 1.7


def test_stick_slip_torque_swing_well_b(well_b):
    """A&S 2018 eqs. 30, 34: swing ≈ 2(1 − μ_k/μ_s)·μ_s∫F_c dx if the whole string sticks.

    That is an upper estimate: the string is released progressively from the top (docs/theory.md
    §6.2) and the top drive keeps sliding, so the torque never climbs to μ_s∫F_c dx (max
    0.74–0.76 μ_sT_N here). Statistics over 60–300 s, as in docs/validation.md.

    The swing (max − min of a chaotic cycle sequence) is set by the single most extreme
    cycle; it is not a stable property of the model: over 14 runs (grids 400–2000 cells,
    I_TD ±1 %/±3 %, k_t ±5 %, set-point ±1 RPM) it spans 0.36–0.54 of the estimate with the
    trapezoidal top drive and 0.39–0.54 with the old explicit one (60-s windows: 0.32–0.54).
    The former lower bound 0.45 over 60–120 s sat at the median of that spread and passed by
    chance (0.54; the same code with I_TD 1 % off gave 0.36). So the lower bound here only
    says "a substantial swing" (0.3, below every value measured), the physics is the upper
    bound, and stick-slip itself is required directly: bit stuck part of the time (0.62–0.66
    measured; > 0.2) and peaks above twice the set-point (5–7× measured).

    The mean torque is the stable statistic (docs/theory.md §6.4 fits μ_k on it): μ_k∫F_c dx, +1.0 %
    viscous k_tΩ∫ρJ dx, plus the share of stuck cells holding more than μ_kF_c; 1.026–1.033
    μ_kT_N in the same 14 runs, so 5 % (formerly 10 %).
    """
    plant, rec = well_b
    m = rec.time_s > 60.0
    swing = np.ptp(rec.motor_torque_Nm[m])
    estimate = 2.0 * (plant.mu_s - plant.mu_k) * plant.T_N_Nm
    assert 0.3 * estimate < swing < estimate
    bit = rec.bit_rad_s[m]
    assert np.mean(np.abs(bit) < 0.05) > 0.2
    assert bit.max() > 2 * 40 * RPM
    assert np.mean(rec.motor_torque_Nm[m]) == pytest.approx(plant.mu_k * plant.T_N_Nm, rel=0.05)


def test_fed_drive_replays_its_own_pi_run_exactly():
    """A PI run of Well B in stick-slip, logged at every model step, replayed with the "fed"
    drive (logged motor torque + the same PI on the logged speed, docs/theory.md §6.4): in
    sync the correction is zero and the replay is the run itself. Stick-slip amplifies
    round-off (the logged series carry 1e-16 relative error), so 20 s are compared — the
    top-drive speed within 1e-6 rad/s and the string torque within 1e-3 N·m."""
    from drillfric.sim.well_b import well_b_plant

    plant = well_b_plant(cells=200)
    dt = plant.grid.dt_s
    pi = T.Drive("pi", np.array([0.0, 40 * RPM]), 10.0)
    n = int(round(20.0 / dt))
    rec, _ = T.run(plant, pi, n * dt, 1.0 / dt)
    fed = T.Drive("fed", np.vstack([rec.motor_torque_Nm, rec.surface_rad_s]), dt,
                  kp_Nms_rad=pi.kp_Nms_rad, ki_Nm_rad=pi.ki_Nm_rad)
    replay, _ = T.run(plant, fed, n * dt, 1.0 / dt)
    assert np.mean(np.abs(rec.bit_rad_s) < 0.05) > 0.1  # it does stick-slip
    np.testing.assert_allclose(replay.surface_rad_s, rec.surface_rad_s, rtol=0, atol=1e-6)
    np.testing.assert_allclose(replay.string_torque_Nm, rec.string_torque_Nm, rtol=0,
                               atol=1e-3)


def test_fed_drive_corrects_towards_the_logged_speed():
    """A logged speed the motor torque cannot explain (torque 0, speed 2 rad/s, frictionless
    string): the PI correction brings the top drive to the logged speed."""
    g, _ = _string_and_fc(cells=50)
    p = frictionless(g, k_t=0.1)
    fed = T.Drive("fed", np.array([[0.0, 0.0], [2.0, 2.0]]), 100.0, kp_Nms_rad=2e4,
                  ki_Nm_rad=5e4)
    rec, _ = T.run(p, fed, 60.0, 1.0)
    assert rec.surface_rad_s[-1] == pytest.approx(2.0, rel=1e-3)
    with pytest.raises(ModelError, match="two series"):
        T.Drive("fed", np.array([1.0, 2.0]), 1.0)


# ------------------------------------------------ friction profile and law (theory §3.2)

def _cased_open_plant(k_t, shoe_m=1000.0, omega_c=0.5, **law):
    """Two-section string, F_c = 20 N·m/m: open hole below ``shoe_m`` (μ_s 0.3, μ_k 0.2
    multiply F_c), cased above with the known factors 0.25 / 0.15 as the fixed part."""
    g, fc = _string_and_fc()
    cased = g.x_m < shoe_m
    plant = T.Plant(g, np.where(cased, 0.0, fc), 0.3, 0.2, omega_c, k_t, 2900.0, 0.0,
                    np.where(cased, 0.15 * fc, 0.0), np.where(cased, 0.25 * fc, 0.0), **law)
    open_m = float(np.sum(np.where(cased, 0.0, fc) * g.dx_true_m))
    cased_m = float(np.sum(np.where(cased, fc, 0.0) * g.dx_true_m))
    t_k, t_s = 0.2 * open_m + 0.15 * cased_m, 0.3 * open_m + 0.25 * cased_m
    return plant, t_k, t_s


@pytest.mark.parametrize("law", [{}, {"stribeck_speed_rad_s": 4.0},
                                 {"stribeck_speed_rad_s": 4.0, "stribeck_exponent": 2.0}],
                         ids=["step", "stribeck-1", "stribeck-2"])
def test_steady_rotation_with_cased_open_profile_and_friction_law(law):
    """docs/theory.md §3.2: steady sliding at Ω needs τ(0) = T_k + (T_s − T_k)·w(Ω) +
    k_tΩ∫ρJ dx with T_k = μ_k∫F_c,open + μ_k,cased∫F_c,cased (T_s likewise) and
    w = exp(−(Ω/v_s)^δ), 0 for the step law above ω_c. At 60 RPM and v_s = 4 rad/s the
    Stribeck term is 21 % (δ = 1) and 8.5 % (δ = 2) of T_s − T_k, i.e. 7.6 % and 3.1 % of
    the friction torque, far outside the tolerance. k_t = 1 1/s keeps steady sliding stable
    against the velocity weakening (slope ≤ 333 N·m·s/rad < k_t∫ρJ dx = 743). Tolerance
    0.5 % as for the uniform profile (the O(k_tΔt) speed gradient; measured ≤ 0.09 %).
    """
    k_t, omega = 1.0, 60 * RPM
    plant, t_k, t_s = _cased_open_plant(k_t, **law)
    g = plant.grid
    assert plant.T_fixed_k_Nm == pytest.approx(t_k - 0.2 * plant.T_N_Nm, rel=1e-12)
    assert plant.T_fixed_s_Nm == pytest.approx(t_s - 0.3 * plant.T_N_Nm, rel=1e-12)
    rec, _ = T.run(plant, T.Drive("pi", np.array([0.0, omega]), 10.0), 100.0, 10.0)
    speed = law.get("stribeck_speed_rad_s")
    w = np.exp(-(omega / speed) ** law.get("stribeck_exponent", 1.0)) if speed else 0.0
    friction = t_k + (t_s - t_k) * w
    assert plant.friction_torque_Nm(omega) == pytest.approx(friction, rel=1e-12)
    expected = friction + k_t * omega * float(np.sum(g.rho_j_kg_m * g.dx_model_m))
    assert rec.motor_torque_Nm[-1] == pytest.approx(expected, rel=5e-3)
    assert rec.string_torque_Nm[-1] == pytest.approx(expected, rel=5e-3)
    assert rec.bit_rad_s[-1] == pytest.approx(omega, rel=5e-3)


@pytest.mark.parametrize("delta, v_s", [(1.0, 0.5), (2.0, 1.0)])
def test_creep_plateau_follows_the_stribeck_curve(delta, v_s):
    """docs/theory.md §3.2, docs/theory.md §6.3: a string turned from rest at the creep speed
    Ω = 0.5 rad/s; once all of it turns, every element carries
    F_k + (F_s − F_k)·exp(−(Ω/v_s)^δ), so the torque plateau is
    μ_k T_N + (μ_s − μ_k)T_N·w + k_tΩ∫ρJ dx with w = e^−1 = 0.37 (δ = 1) and e^−0.25 = 0.78
    (δ = 2) — far from the step law's μ_s T_N (the creep test above). F_c = 2 N·m/m and
    k_t = 2 1/s keep the creep stable (Stribeck slope ≤ 780 N·m·s/rad < k_t∫ρJ dx =
    1487: a steeper one turns it into stick-slip, as it should). Mean over the last 50 s,
    1 %: the static part is 23 % (δ = 1) and 39 % (δ = 2) of the plateau and w differs
    from the step law's 1 by 63 % and 22 % (measured within 0.065 %).
    """
    g, fc = _string_and_fc(fc=2.0)
    k_t, omega = 2.0, 0.5
    plant = T.Plant(g, fc, 0.3, 0.1, 1.0, k_t, stribeck_speed_rad_s=v_s,
                    stribeck_exponent=delta)
    rec, _ = T.run(plant, T.Drive("pi", np.array([0.0, omega]), 5.0), 150.0, 10.0)
    late = rec.time_s > 100.0
    t_n = plant.T_N_Nm
    expected = (0.1 * t_n + 0.2 * t_n * np.exp(-(omega / v_s) ** delta)
                + k_t * omega * float(np.sum(g.rho_j_kg_m * g.dx_model_m)))
    assert rec.string_torque_Nm[late].mean() == pytest.approx(expected, rel=0.01)
    assert rec.bit_rad_s[late].mean() == pytest.approx(omega, rel=0.01)


def test_stribeck_with_vanishing_speed_tends_to_the_step_law_in_sliding():
    """docs/theory.md §3.2: as v_s → 0 the Stribeck cap at any speed ≠ 0 tends to the
    kinetic cap, so steady rotation needs the step law's kinetic torque. The excess
    over the step-law torque falls with v_s (4.3 % of T_s − T_k left at v_s = 2 rad/s,
    3.5e-6 at 0.5) and at v_s = 1e-3 rad/s (weight e^−40 by the clamp of the kernel's exp)
    the steady torque is the step law's to round-off (1e-12)."""
    omega = 60 * RPM
    step, t_k, t_s = _cased_open_plant(1.0)
    drive = T.Drive("pi", np.array([0.0, omega]), 10.0)
    ref = T.run(step, drive, 100.0, 10.0)[0].motor_torque_Nm[-1]
    excess = []
    for v_s in (2.0, 0.5, 1e-3):
        plant = _cased_open_plant(1.0, stribeck_speed_rad_s=v_s)[0]
        excess.append(T.run(plant, drive, 100.0, 10.0)[0].motor_torque_Nm[-1] - ref)
    assert excess[0] == pytest.approx((t_s - t_k) * np.exp(-omega / 2.0), rel=0.05)
    assert 0 < excess[1] < 1e-3 * excess[0]
    assert abs(excess[2]) < 1e-12 * ref


def test_friction_split_into_fixed_part_is_the_same_plant():
    """docs/theory.md §3.2: the caps are μ_s·F_c + F_fixed,s and μ_k·F_c + F_fixed,k, so
    moving all friction into the fixed part (F_c = 0, F_fixed = μ·F_c) is the same plant.
    Stick-slip on Well B for 30 s: μ·fcap and the fixed cap differ by round-off (8e-17
    relative), which the chaotic stick-slip may amplify; records within 1e-9 of their scale
    (measured 1.6e-15 here, 2.4e-15 over 120 s)."""
    from drillfric.sim.well_b import well_b_plant

    p = well_b_plant(cells=200)
    moved = T.Plant(p.grid, np.zeros(p.grid.n_cells), p.mu_s, p.mu_k, p.omega_c_rad_s,
                    p.k_t_per_s, p.top_drive_inertia_kg_m2, 0.0, p.mu_k * p.fc_Nm_m,
                    p.mu_s * p.fc_Nm_m)
    drive = T.Drive("pi", np.array([0.0, 40 * RPM]), 5.0)
    a, _ = T.run(p, drive, 30.0, 20.0)
    b, _ = T.run(moved, drive, 30.0, 20.0)
    assert moved.T_fixed_k_Nm == pytest.approx(p.mu_k * p.T_N_Nm, rel=1e-12)
    assert np.mean(np.abs(a.bit_rad_s) < 0.05) > 0.2  # stick-slip
    scale = np.abs(a.motor_torque_Nm).max()
    np.testing.assert_allclose(b.motor_torque_Nm, a.motor_torque_Nm, atol=1e-9 * scale)
    np.testing.assert_allclose(b.bit_rad_s, a.bit_rad_s, atol=1e-9 * np.abs(a.bit_rad_s).max())


@settings(max_examples=5, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), delta=st.sampled_from([1.0, 1.5, 2.0]))
def test_energy_conserved_without_friction_under_the_stribeck_law(seed, delta):
    """The Stribeck variant of the kernel with zero caps (no friction, k_t = 0, clamped top)
    conserves energy exactly like the step law (docs/theory.md §3.1): rel 1e-11 after 10 000
    steps, as the step-law test."""
    rng = np.random.default_rng(seed)
    g = T.make_grid(two_section_string(), 150)
    plant = T.Plant(g, np.zeros(g.n_cells), 0.0, 0.0, 1.0, 0.0, stribeck_speed_rad_s=0.3,
                    stribeck_exponent=delta)
    state = T.State(rng.normal(size=g.n_cells), rng.normal(size=g.n_cells))
    out = steps(plant, clamp_top(), 10_000, state)
    assert T.energy(g, out) == pytest.approx(T.energy(g, state), rel=1e-11)


# ------------------------------------------------------------- axial motion (§3.3)

def _viscous_Nm(grid, k_t, omega):
    return k_t * omega * float(np.sum(grid.rho_j_kg_m * grid.dx_model_m))


@pytest.mark.parametrize("v", [0.1, 0.3, -0.3, 1.0])
def test_steady_rotation_with_axial_motion_gives_the_split_torque(v):
    """docs/theory.md eq. (3.3d): a string turning steadily at Ω while it moves axially at v
    needs τ(0) = Σ μ_k F_c Δx·Ωr_c/√((Ωr_c)² + v²) + k_tΩ∫ρJ dx — each cell's friction
    opposes its contact's slip and only the tangential share loads the torque. The sign of
    v (running in or pulling out) does not matter. The expected value is summed here from
    the cells, independent of ``Plant.friction_torque_Nm`` (which must agree to round-off).
    Pipe r_c = 0.073 m, collars 0.105 m: at 60 RPM the pipe's share is 0.84 (v = 0.3 m/s)
    to 0.42 (v = 1 m/s), 0.98–0.40 for the collars — far outside the tolerance. Tolerance
    0.5 % as for pure rotation (the O(k_tΔt) speed gradient; measured ≤ 0.1 %)."""
    string = two_section_string()
    g, fc = _string_and_fc()
    rc = T.contact_radius(string, g)
    k_t, omega = 0.3, 60 * RPM
    plant = T.Plant(g, fc, 0.3, 0.2, 0.5, k_t, contact_radius_m=rc)
    rec, _ = T.run(plant, T.Drive("pi", np.array([0.0, omega]), 10.0), 100.0, 10.0,
                   axial=T.Axial(np.array([v]), 1.0))
    share = omega * rc / np.sqrt((omega * rc) ** 2 + v**2)
    friction = float(np.sum(0.2 * fc * g.dx_true_m * share))
    assert plant.friction_torque_Nm(omega, v) == pytest.approx(friction, rel=1e-12)
    assert friction < 0.99 * 0.2 * plant.T_N_Nm
    expected = friction + _viscous_Nm(g, k_t, omega)
    assert rec.motor_torque_Nm[-1] == pytest.approx(expected, rel=5e-3)
    assert rec.string_torque_Nm[-1] == pytest.approx(expected, rel=5e-3)
    assert rec.bit_rad_s[-1] == pytest.approx(omega, rel=5e-3)


@pytest.mark.parametrize("case, v", [("rotating_pick_up", 0.3), ("rotating_slack_off", -0.3),
                                     ("rotating_pick_up", 0.15)])
def test_steady_axial_torque_equals_torque_and_drag(case, v):
    """docs/theory.md §2 steps 3–4 and eq. (3.3d): the plant turning steadily at 60 RPM while
    moving at v, with F_c of the soft-string model's rotating pick-up / slack-off case at the
    same μ_k, v and RPM (the axial friction changes the tension, hence F_N), needs the
    surface torque of that case: both sum μ_k·N·r_c·ωr_c/√((ωr_c)² + v²) along the string.
    Deviated well (vertical to 500 m, built to 60° at 1500 m, held to 2600 m), bit at 2500
    m. |v| > ω_c·r_c in every cell (0.073 m/s for the pipe, 0.105 m/s for the collars), so
    no cell sticks (slower, inside the static band, this string stick-slips at μ_s = 0.35).
    Tolerance 0.5 %: the plant samples F_c at its 500 cell centres where torque and drag
    sums it over 2-m elements, and the O(k_tΔt) speed gradient (measured ≤ 0.09 %)."""
    from drillfric.torque_drag import solve
    from drillfric.wellpath import minimum_curvature

    path = minimum_curvature([0, 500, 1500, 2600], np.radians([0, 0, 60, 60]),
                             np.radians([0, 0, 30, 30]))
    string = two_section_string()
    rpm, k_t = 60.0, 0.1
    td = solve(path, string, friction=0.25, load_case=case, axial_speed_m_s=abs(v), rpm=rpm)
    g = T.make_grid(string, 500)
    plant = T.Plant(g, td.fc_at(g.x_m), 0.35, 0.25, 1.0, k_t,
                    contact_radius_m=T.contact_radius(string, g))
    rec, _ = T.run(plant, T.Drive("pi", np.array([0.0, rpm * RPM]), 10.0), 100.0, 10.0,
                   axial=T.Axial(np.array([v]), 1.0))
    rotating = solve(path, string, friction=0.25, load_case="rotating_off_bottom")
    if abs(v) >= 0.3:  # the split is far outside the tolerance (at 0.15 m/s the share is 0.95)
        assert td.surface_torque_Nm < 0.97 * rotating.surface_torque_Nm
    surface = rec.motor_torque_Nm[-1] - _viscous_Nm(g, k_t, rpm * RPM)
    assert surface == pytest.approx(td.surface_torque_Nm, rel=5e-3)


def test_axial_motion_ends_stick_slip():
    """docs/theory.md §3.3: a moving contact cannot stick. Well B (μ_s 0.885, μ_k 0.425,
    ω_c = 0.9 rad/s; 200 cells) stick-slips at 40 RPM with the pipe at rest (bit stuck
    ~70 % of the time, torque swing ~1.2 μ_kT_N). Inside the static band, |v| = 0.03 m/s <
    ω_c·r_c = 0.066 m/s (pipe), cells can still stick, and it still stick-slips. With |v|
    well above ω_c·r_c in every cell (0.2 and 0.5 m/s; 0.11 m/s for the largest collar) no
    cell can stick, the friction grows with ω (the share ωr_c/√((ωr_c)² + v²)) and damps
    the torsional waves: the stick-slip is gone — the bit never slows below 95 % of the
    set-point, the torque swing is below 1 % of the mean (measured 0: steady) — and the
    swing shrinks from > 50 % to < 1 % of the mean as v grows. Statistics after 60 s, as in
    the stick-slip test of Well B.
    (The steady bit turns 2.3 % below the top drive at 200 cells, 1.2 % at 400: the
    Courant-1 scheme's first-order steady offset, half the per-step friction speed change of
    the heavy bottom cells, docs/theory.md §3.3 — hence 95 %, not the 0.5 % of a fine grid.)"""
    from drillfric.sim.well_b import well_b_plant, well_b_string

    base = well_b_plant(cells=200)
    plant = T.Plant(base.grid, base.fc_Nm_m, base.mu_s, base.mu_k, base.omega_c_rad_s,
                    base.k_t_per_s, contact_radius_m=T.contact_radius(well_b_string(),
                                                                      base.grid))
    drive = T.Drive("pi", np.array([0.0, 40 * RPM]), 10.0)
    swing, stuck, bit_min = {}, {}, {}
    for v in (0.0, 0.03, 0.2, 0.5):
        rec, _ = T.run(plant, drive, 150.0, 20.0, axial=T.Axial(np.array([v]), 1.0))
        late = rec.time_s > 60.0
        swing[v] = np.ptp(rec.motor_torque_Nm[late]) / np.mean(rec.motor_torque_Nm[late])
        stuck[v] = np.mean(np.abs(rec.bit_rad_s[late]) < 0.1 * plant.omega_c_rad_s)
        bit_min[v] = rec.bit_rad_s[late].min()
    for v in (0.0, 0.03):
        assert stuck[v] > 0.2 and swing[v] > 0.5
    for v in (0.2, 0.5):
        assert stuck[v] == 0.0 and bit_min[v] > 0.95 * 40 * RPM and swing[v] < 0.01


def test_state_on_another_grid_keeps_the_twist_above_the_bit():
    """docs/theory.md §3.3 (stand phases): carried to the same grid a state is unchanged to
    round-off (ω ± τ/ζ re-formed); carried to the string 30 m longer, each cell keeps the
    torque and speed of the old string at its distance above the bit: a string wound by
    μF_c = 2 N·m/m from 8 kN·m at the top (linear in x, so the interpolation is exact)
    reads τ = 8000 − 2(x − 30) at depth x of the new string, and the 30 m of new pipe at
    the top the old top cell's torque. 1e-9: interpolation and sums of lengths."""
    rng = np.random.default_rng(3)
    g = T.make_grid(two_section_string(), 200)
    state = T.State(rng.normal(0, 2, g.n_cells), rng.normal(0, 2, g.n_cells),
                    np.array([1.0, 2.0]), 7.0)
    same = state.on_grid(g, g)
    np.testing.assert_allclose(same.alpha, state.alpha, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(same.beta, state.beta, rtol=1e-9, atol=1e-12)
    assert same.t_s == 7.0 and list(same.top) == [1.0, 2.0]
    wound = T.State.wound(g, np.full(g.n_cells, 20.0), 8000.0, 0.1, omega_rad_s=3.0)
    longer = T.make_grid(two_section_string(2300.0), 200)
    moved = wound.on_grid(g, longer)
    x = longer.x_m
    inside = x - 30.0 >= g.x_m[0]
    expected = np.where(inside, 8000.0 - 2.0 * (x - 30.0), wound.torque_Nm(g)[0])
    np.testing.assert_allclose(moved.torque_Nm(longer), expected, rtol=1e-9)
    np.testing.assert_allclose(moved.omega_rad_s, 3.0, rtol=1e-12)


def test_axial_motion_needs_the_contact_radius():
    """Axial motion splits the friction by ωr_c against v: without r_c per cell the plant
    refuses it (and a radius that is not positive), rather than guessing."""
    g, fc = _string_and_fc(cells=50)
    plant = T.Plant(g, fc, 0.6, 0.3, 1.0)
    drive = T.Drive("pi", np.array([1.0]), 1.0)
    with pytest.raises(ModelError, match="contact radius"):
        T.run(plant, drive, 1.0, 10.0, axial=T.Axial(np.array([0.1]), 1.0))
    with pytest.raises(ModelError, match="contact_radius_m"):
        T.Plant(g, fc, 0.6, 0.3, 1.0, contact_radius_m=np.zeros(g.n_cells))
    T.run(plant, drive, 1.0, 10.0, axial=T.Axial(np.zeros(3), 1.0))  # v = 0: not needed


@pytest.fixture(scope="module")
def well_b():
    """A&S 2018 Well B (docs/reference_cases.md), 500 cells, k_t = 0.1 1/s, 40 RPM, 300 s."""
    from drillfric.sim.well_b import well_b_plant

    plant = well_b_plant()
    rec, _ = T.run(plant, T.Drive("pi", np.array([0.0, 40 * RPM]), 10.0), 300.0, 100.0)
    return plant, rec


# ---------------------------------------------------------------------------- bad input

@pytest.mark.parametrize("kw, word", [({"top_drive_inertia_kg_m2": 0.0}, "inertia"),
                                      ({"omega_c_rad_s": 0.0}, "ω_c"),
                                      ({"mu_k": 0.7}, "μ_k")])
def test_bad_plant_settings_raise(kw, word):
    g, fc = _string_and_fc(cells=50)
    args = {"grid": g, "fc_Nm_m": fc, "mu_s": 0.6, "mu_k": 0.3, "omega_c_rad_s": 1.0} | kw
    with pytest.raises(ModelError, match=word):
        T.Plant(**args)


@pytest.mark.parametrize("kw, word", [
    ({"fc_fixed_k_Nm_m": 2.0, "fc_fixed_s_Nm_m": 1.0}, "exceeds"),
    ({"fc_fixed_k_Nm_m": -1.0}, "non-negative"),
    ({"stribeck_speed_rad_s": -1.0}, "Stribeck speed"),
    ({"stribeck_exponent": 2.5}, "exponent"),
    ({"bit_weakening_ratio": 0.5}, "rate-weakening"),
    ({"bit_weakening_speed_rad_s": 0.0}, "rate-weakening")])
def test_bad_friction_profile_and_law_raise(kw, word):
    g, fc = _string_and_fc(cells=50)
    kw = {k: np.full(g.n_cells, v) if k.startswith("fc_") else v for k, v in kw.items()}
    with pytest.raises(ModelError, match=word):
        T.Plant(g, fc, 0.6, 0.3, 1.0, **kw)


def test_bad_duration_and_rate_raise():
    g, fc = _string_and_fc(cells=50)
    plant = T.Plant(g, fc, 0.6, 0.3, 1.0)
    drive = T.Drive("pi", np.array([1.0]), 1.0)
    for duration, rate in ((0.0, 10.0), (1.0, -1.0)):
        with pytest.raises(ModelError, match="positive"):
            T.run(plant, drive, duration, rate)


#: A&S 2018 Well A / synthetic BHA (docs/reference_cases.md): length, OD, ID [m], top-down as
#: listed.
WELL_A_BHA = ((19.080, 0.150167, 0.096799), (10.240, 0.206375, 0.076200),
              (57.240, 0.150167, 0.096799), (9.750, 0.206248, 0.069850),
              (95.400, 0.150167, 0.096799), (38.750, 0.222392, 0.095964))


def test_first_torsional_mode_of_well_a_synthetic():
    """A&S 2018: first torsional mode of the Well A synthetic case about 0.22 Hz (≈ 4.5 s).

    No friction, light damping, a small set-point step under the PI controller; the bit
    speed spectrum peaks at the first closed-loop mode. Tolerance 5 %: A&S give two digits
    (±2.3 %) and model the BHA as one averaged section.
    """
    bha = tuple(section(f"b{i}", od, id_, length, 67e9)
                for i, (length, od, id_) in enumerate(WELL_A_BHA))
    pipe = section("dp", 0.146529, 0.123024, 2500.0 - sum(b.length_m for b in bha))
    g = T.make_grid(DrillString((pipe,) + bha), 500)
    plant = T.Plant(g, np.zeros(g.n_cells), 0.0, 0.0, 1.0, 0.02)
    rec, _ = T.run(plant, T.Drive("pi", np.array([0.0, 0.1, 0.1]), 0.05), 400.0, 20.0)
    x = (rec.bit_rad_s - rec.bit_rad_s.mean()) * np.hanning(rec.time_s.size)
    freq = np.fft.rfftfreq(x.size, 1 / 20.0)
    spectrum = np.abs(np.fft.rfft(x))
    band = freq > 0.05
    assert freq[band][np.argmax(spectrum[band])] == pytest.approx(0.22, rel=0.05)
