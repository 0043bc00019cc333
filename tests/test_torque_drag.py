"""Soft-string torque and drag (drillfric.torque_drag, docs/theory.md §2).

Analytic checks first (each states its source and why its tolerance is what it is), then
the compiled march against a plain-Python oracle, then API behaviour.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from drillfric.config import load_config
from drillfric.drillstring import G_ACCEL, DrillString, Section, build_string
from drillfric.errors import ModelError
from drillfric.torque_drag import (
    LOAD_CASES,
    back_calculate_friction,
    broomstick,
    broomstick_figure,
    element_normal_force,
    solve,
    solve_config,
)
from drillfric.wellpath import minimum_curvature, no_survey_path, vertical

RHO_STEEL = 7850.0


def pipe(length_m=1000.0, od=0.127, id_=0.1086, tj=0.1651, mass=None, name="dp"):
    mass = RHO_STEEL * np.pi * (od**2 - id_**2) / 4 if mass is None else mass
    return Section(name, od, id_, length_m, tj / 2, mass)


def two_section(bit_m, bha_m=150.0):
    return DrillString((pipe(bit_m - bha_m), Section("dc", 0.1715, 0.0714, bha_m, 0.1715 / 2,
                                                      RHO_STEEL * np.pi * (0.1715**2 - 0.0714**2)
                                                      / 4)))


def build_hold(kop=500.0, eob=1500.0, inc_deg=60.0, td=4000.0, azi_deg=30.0):
    md = [0.0, kop, eob, td]
    return minimum_curvature(md, np.radians([0, 0, inc_deg, inc_deg]),
                             np.radians([azi_deg] * 4))


# ---------------------------------------------------------------------------------------
# plain-Python oracle: docs/theory.md §2 steps 2–5 written literally, one element at a time
def naive_march(md, tangents, w_per_m, rc, mu, sigma, share, f_bit, m_bit):
    n = len(md) - 1
    force, torque, normal = [0.0] * (n + 1), [0.0] * (n + 1), [0.0] * n
    force[n], torque[n] = f_bit, m_bit
    g = np.array([0.0, 0.0, 1.0])
    for e in reversed(range(n)):
        tu, td = tangents[e], tangents[e + 1]
        tbar = (tu + td) / np.linalg.norm(tu + td)
        weight = w_per_m[e] * (md[e + 1] - md[e])
        q = force[e + 1] * (td - tu) + weight * (g - g.dot(tbar) * tbar)
        normal[e] = float(np.linalg.norm(q))
        force[e] = force[e + 1] + weight * g.dot(tbar) + sigma[e] * mu[e] * normal[e]
        torque[e] = torque[e + 1] + share[e] * mu[e] * normal[e] * rc[e]
    return np.array(force), np.array(torque), np.array(normal)


def oracle_for(path, string, res, *, mu, sigma, share, f_bit=0.0, m_bit=0.0, mud=1200.0):
    md = res.md_m
    mid = 0.5 * (md[1:] + md[:-1])
    return naive_march(md, path.tangent(md), string.buoyed_weight_N_m(mid, mud, mud),
                       string.along("contact_radius_m", mid), np.full(mid.size, mu),
                       np.full(mid.size, sigma), np.full(mid.size, share), f_bit, m_bit)


@pytest.mark.parametrize("case,sigma,share,f_bit,m_bit", [
    ("rotating_off_bottom", 0.0, 1.0, 0.0, 0.0),
    ("rotating_on_bottom", 0.0, 1.0, -80e3, 4e3),
    ("pick_up", 1.0, 0.0, 0.0, 0.0),
    ("slack_off", -1.0, 0.0, 0.0, 0.0),
    ("sliding", -1.0, 0.0, -80e3, 0.0),
])
def test_compiled_march_matches_plain_python_oracle(case, sigma, share, f_bit, m_bit):
    """Oracle: docs/theory.md §2 literally. Same arithmetic in another order: rtol 1e-10."""
    path = minimum_curvature([0, 300, 900, 1400, 2500], np.radians([0, 5, 40, 62, 75]),
                             np.radians([0, 20, 70, 95, 100]))
    string = two_section(2400.0)
    res = solve(path, string, friction=0.3, load_case=case, wob_N=80e3, bit_torque_Nm=4e3,
                element_length_m=7.0)
    f, m, n = oracle_for(path, string, res, mu=0.3, sigma=sigma, share=share, f_bit=f_bit,
                         m_bit=m_bit)
    np.testing.assert_allclose(res.tension_N, f, rtol=1e-10, atol=1e-6)
    np.testing.assert_allclose(res.torque_Nm, m, rtol=1e-10, atol=1e-6)
    np.testing.assert_allclose(res.normal_force_N_m * np.diff(res.md_m), n, rtol=1e-10,
                               atol=1e-6)


def test_combined_motion_shares_follow_speed_ratio():
    """docs/theory.md §2 step 3: σ = v/√(v² + (ω r_c)²), torque share ω r_c/√(...). Oracle: rtol
    1e-10."""
    path = build_hold(td=2000.0)
    string = DrillString((pipe(2000.0),))
    v, rpm = 0.2, 30.0
    wr = rpm * 2 * np.pi / 60 * string.sections[0].contact_radius_m
    for case, sign in (("rotating_pick_up", 1.0), ("rotating_slack_off", -1.0)):
        res = solve(path, string, friction=0.25, load_case=case, axial_speed_m_s=v, rpm=rpm)
        f, m, _ = oracle_for(path, string, res, mu=0.25, sigma=sign * v / np.hypot(v, wr),
                             share=wr / np.hypot(v, wr))
        np.testing.assert_allclose(res.tension_N, f, rtol=1e-10)
        np.testing.assert_allclose(res.torque_Nm, m, rtol=1e-10)
    with pytest.raises(ModelError, match="axial speed and RPM"):
        solve(path, string, load_case="rotating_pick_up")


# ---------------------------------------------------------------------------------------
# analytic checks of docs/theory.md §2
@pytest.mark.parametrize("case", ["rotating_off_bottom", "rotating_on_bottom", "pick_up",
                                  "slack_off"])
def test_vertical_hole_zero_side_force_and_buoyed_weight(case):
    """docs/theory.md §2: vertical → N = 0 and F(0) = buoyed weight − WOB. Sums of ~10³ terms:
    1e-12."""
    string = two_section(3000.0)
    wob = 120e3 if case == "rotating_on_bottom" else 0.0
    res = solve(vertical(3000.0), string, friction=0.4, load_case=case, wob_N=wob,
                mud_out_kg_m3=1300.0)
    assert np.max(np.abs(res.normal_force_N_m)) < 1e-9
    buoyed = sum(s.buoyed_weight_N_m(1300.0, 1300.0) * s.length_m for s in string.sections)
    assert res.hookload_N == pytest.approx(buoyed - wob, rel=1e-12)
    assert res.surface_torque_Nm == 0.0 and res.T_N_Nm < 1e-6


@pytest.mark.parametrize("inc_deg", [10.0, 45.0, 80.0])
def test_straight_slant_axial_force_increment_is_exact(inc_deg):
    """docs/theory.md §2: straight hole at I → ΔF = w·Δs·(cos I ± μ sin I), per element, exact.

    Both tangents equal, so N = W sin I with no discretisation error: rtol 1e-12.
    """
    inc = np.radians(inc_deg)
    path = minimum_curvature([0.0, 3000.0], [inc, inc], [1.0, 1.0])
    string = DrillString((pipe(2500.0),))
    w = string.sections[0].buoyed_weight_N_m(1200.0, 1200.0)
    for case, sign in (("pick_up", 1.0), ("slack_off", -1.0), ("rotating_off_bottom", 0.0)):
        res = solve(path, string, friction=0.3, load_case=case, element_length_m=3.0)
        ds = np.diff(res.md_m)
        expected = w * ds * (np.cos(inc) + sign * 0.3 * np.sin(inc))
        np.testing.assert_allclose(-np.diff(res.tension_N), expected, rtol=1e-12)
        np.testing.assert_allclose(res.normal_force_N_m, w * np.sin(inc), rtol=1e-12)


def weightless_arc(beta_rad, radius_m=500.0):
    """Vertical-plane arc from 0 to β inclination starting at surface, weightless pipe."""
    length = beta_rad * radius_m
    path = minimum_curvature([0.0, length], [0.0, beta_rad], [0.0, 0.0])
    od, mud = 0.127, 1500.0
    # mass per metre equal to the displaced mud: W = 0 with a solid pipe and one mud
    string = DrillString((Section("neutral", od, 0.0, length, od / 2,
                                  mud * np.pi * od**2 / 4),))
    return path, string, mud


def test_weightless_arc_tends_to_capstan_with_first_order_convergence():
    """Capstan (Euler–Eytelwein): |F_out| = |F_in|·e^{μβ} on a weightless arc (docs/theory.md §2).

    Sliding with WOB pushes the string through a 90° bend. The march uses the lower-node
    force in N (explicit), so the error per element is O(δ²) and the total O(δ): the
    observed order must be 1 ± 0.1 and the finest mesh (0.25 m, δ = 5e-4 rad) within 1e-3.
    """
    beta, mu, wob = np.pi / 2, 0.35, 50e3
    path, string, mud = weightless_arc(beta)
    errors = []
    hs = [8.0, 4.0, 2.0, 1.0, 0.5, 0.25]
    for h in hs:
        res = solve(path, string, friction=mu, load_case="sliding", wob_N=wob,
                    mud_out_kg_m3=mud, mud_in_kg_m3=0.0, element_length_m=h)
        errors.append(abs(-res.hookload_N / (wob * np.exp(mu * beta)) - 1.0))
    order = np.polyfit(np.log(hs), np.log(errors), 1)[0]
    assert order == pytest.approx(1.0, abs=0.1)
    assert errors[-1] < 1e-3


def test_build_under_tension_normal_force_crosses_zero():
    """docs/theory.md §2 scalar form: planar build, N = |F_d·2sin(ΔI/2) − W sin Ī| exactly.

    Pins the sign that published open-source code gets wrong (+W sin Ī would never vanish):
    deep in the build gravity dominates, near the kick-off tension does, and F_N dips to
    ~0 where F·κ = w·sin I. Exact identity for a planar arc: rtol 1e-9.
    """
    path = build_hold(kop=500.0, eob=2500.0, inc_deg=60.0, td=3500.0, azi_deg=0.0)
    string = DrillString((pipe(3500.0),))
    res = solve(path, string, friction=0.2, load_case="rotating_off_bottom",
                element_length_m=1.0)
    w = string.sections[0].buoyed_weight_N_m(1200.0, 1200.0)
    md = res.md_m
    build = (md[:-1] >= 500.0) & (md[1:] <= 2500.0)
    d_inc = np.diff(res.inc_rad)[build]
    inc_bar = 0.5 * (res.inc_rad[:-1] + res.inc_rad[1:])[build]
    signed = res.tension_N[1:][build] * 2 * np.sin(d_inc / 2) - w * np.diff(md)[build] * np.sin(
        inc_bar)
    n_el = res.normal_force_N_m[build] * np.diff(md)[build]
    np.testing.assert_allclose(n_el, np.abs(signed), rtol=1e-9, atol=1e-9)
    assert signed[0] > 0 > signed[-1]  # tension-dominated at kick-off, gravity at the bottom
    k = int(np.argmax(np.diff(np.sign(signed)) != 0))
    kappa = np.radians(60.0) / 2000.0
    # at the crossing the tension equals w sin I / κ (within one element of 1 m)
    assert res.tension_N[1:][build][k] == pytest.approx(w * np.sin(inc_bar[k]) / kappa,
                                                         rel=2e-3)
    assert res.normal_force_N_m[build].min() < 0.01 * res.normal_force_N_m[build].max()


def test_azimuth_crossing_north_gives_no_spurious_side_force():
    """359° → 1° is a 2° turn, not 358°: profile equal to the same well turned to 179° → 181°.

    Rotating a well about the vertical changes no force: rtol 1e-9 (trigonometric round-off).
    """
    md = [0.0, 800.0, 1500.0, 1530.0, 2500.0]
    inc = np.radians([0.0, 30.0, 30.0, 30.0, 30.0])
    north = minimum_curvature(md, inc, np.radians([359.0, 359.0, 359.0, 1.0, 1.0]))
    south = minimum_curvature(md, inc, np.radians([179.0, 179.0, 179.0, 181.0, 181.0]))
    string = two_section(2500.0)
    a = solve(north, string, friction=0.3, load_case="pick_up")
    b = solve(south, string, friction=0.3, load_case="pick_up")
    np.testing.assert_allclose(a.normal_force_N_m, b.normal_force_N_m, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(a.tension_N, b.tension_N, rtol=1e-9)
    turn = (a.md_m[:-1] >= 1500.0) & (a.md_m[1:] <= 1530.0)
    # dogleg 2°·sin 30° = 1° over 30 m: F·κ bounded by the surface tension times κ, + weight
    kappa = np.radians(1.0) / 30.0
    w = string.sections[0].buoyed_weight_N_m(1200.0, 1200.0)
    assert a.normal_force_N_m[turn].max() < a.hookload_N * kappa + 2 * w


def test_buoyancy_inside_and_outside_mud():
    """docs/theory.md §2 step 1: W = g·Δs·[m − ρ_o A_o + ρ_i A_i]; one mud: w_air·(1 − ρ/ρ_steel).

    Vertical hole, so the hook load is the sum of buoyed weights: rtol 1e-12.
    """
    s = pipe(2000.0)
    string = DrillString((s,))
    res = solve(vertical(2000.0), string, mud_out_kg_m3=1400.0, mud_in_kg_m3=1100.0)
    expected = G_ACCEL * (s.linear_mass_kg_m - 1400.0 * np.pi * s.od_m**2 / 4
                          + 1100.0 * np.pi * s.id_m**2 / 4) * 2000.0
    assert res.hookload_N == pytest.approx(expected, rel=1e-12)
    single = solve(vertical(2000.0), string, mud_out_kg_m3=1400.0)
    assert single.hookload_N == pytest.approx(s.air_weight_N_m * (1 - 1400.0 / RHO_STEEL)
                                              * 2000.0, rel=1e-12)
    heavier_inside = solve(vertical(2000.0), string, mud_out_kg_m3=1400.0, mud_in_kg_m3=1800.0)
    assert heavier_inside.hookload_N > single.hookload_N > res.hookload_N


def test_rotating_torque_is_mu_times_T_N_off_bottom():
    """docs/theory.md §2 step 4 and §5.1: off bottom, rotating, surface torque = μ·∫F_c dx
    exactly."""
    res = solve(build_hold(), two_section(3800.0), friction=0.27)
    assert res.surface_torque_Nm == pytest.approx(0.27 * res.T_N_Nm, rel=1e-12)
    assert res.T_N_Nm == pytest.approx(np.sum(res.fc_Nm_m * np.diff(res.md_m)), rel=1e-12)
    # F_c does not depend on μ when there is no axial motion (σ = 0)
    other = solve(build_hold(), two_section(3800.0), friction=0.6)
    np.testing.assert_allclose(other.fc_Nm_m, res.fc_Nm_m, rtol=1e-12)


def test_fc_at_picks_the_element_below_each_depth():
    res = solve(build_hold(), two_section(3800.0), element_length_m=5.0)
    np.testing.assert_array_equal(res.fc_at(res.md_m[:-1]), res.fc_Nm_m)
    assert res.fc_at(res.bit_depth_m)[0] == res.fc_Nm_m[-1]
    mid = 0.5 * (res.md_m[3] + res.md_m[4])
    assert res.fc_at(mid)[0] == res.fc_Nm_m[3]


def test_nodes_honour_section_boundaries_stations_and_shoe():
    path = build_hold(kop=503.3, eob=1499.7)
    string = two_section(3777.7, bha_m=151.3)
    res = solve(path, string, element_length_m=10.0, extra_nodes_m=(1234.5,))
    for depth in (503.3, 1499.7, 3777.7 - 151.3, 1234.5, 0.0, 3777.7):
        assert np.min(np.abs(res.md_m - depth)) < 1e-9
    assert np.all(np.diff(res.md_m) <= 10.0 + 1e-9)
    # contact radius switches exactly at the BHA top: collars' body OD below
    assert res.fc_at(3777.7 - 1.0)[0] / res.normal_force_N_m[-1] == pytest.approx(0.1715 / 2)


def test_friction_per_hole_section_from_config(tmp_path):
    """Cased above the shoe, open hole below: dM/ds = μ(s)·F_c per element (docs/theory.md §2 step
    4)."""
    cfg_file = tmp_path / "w.toml"
    cfg_file.write_text("[model]\ncasing_shoe_md_m = 1234.5\nfriction_cased = 0.15\n"
                        "friction_open = 0.35\nelement_length_m = 4.0\n")
    cfg = load_config(cfg_file)
    res = solve_config(cfg, build_hold(), 3800.0)
    assert res.friction is None
    mid = 0.5 * (res.md_m[1:] + res.md_m[:-1])
    mu = np.where(mid < 1234.5, 0.15, 0.35)
    np.testing.assert_allclose(-np.diff(res.torque_Nm), mu * res.fc_Nm_m * np.diff(res.md_m),
                               rtol=1e-9, atol=1e-9)
    assert np.min(np.abs(res.md_m - 1234.5)) < 1e-9
    one = solve_config(cfg, build_hold(), 3800.0, friction=0.2)
    assert one.friction == 0.2
    assert one.surface_torque_Nm == pytest.approx(0.2 * one.T_N_Nm, rel=1e-12)


def test_solve_config_defaults_to_vertical_and_config_string():
    """Without a survey and with tortuosity 0 the hole is exactly vertical: hook load =
    buoyed weight of the configured string (rel 1e-12: a sum of ~10³ terms)."""
    cfg = load_config(overrides={"survey.tortuosity_deg_30m": 0.0})
    res = solve_config(cfg, None, 2000.0)
    assert res.T_N_Nm == 0.0
    string = build_string(cfg.sections, 2000.0)
    rho = cfg.fluid.mud_density_kg_m3
    assert res.hookload_N == pytest.approx(
        sum(s.buoyed_weight_N_m(rho, rho) * s.length_m for s in string.sections), rel=1e-12)


# ---------------------------------------------------------------------------------------
# Johancsik et al. 1984, Example 3 (docs/reference_cases.md)
def johancsik_example3(bit_m=3718.0):
    """Vertical to 731.5 m, build to 44° at 1280 m, hold to 3718 m (docs/reference_cases.md).

    String: 5" 19.5 lb/ft DP (adjusted 22.6 lb/ft, 6⅝" tool joints), 840 ft of 5" HWDP
    (49.3 lb/ft, 6½" joints), 372 ft of 6½" × 2¼" collars (91.8 lb/ft); 10 lb/gal mud
    (1198 kg/m³). These are assumed standard sizes: the case lists only the section kinds.
    """
    path = minimum_curvature([0.0, 731.5, 1280.0, 3718.0], np.radians([0, 0, 44.0, 44.0]),
                             [0.0] * 4)
    lbft = 1.48816
    sections = [
        {"name": "5in DP", "od_m": 0.127, "id_m": 0.10861, "tool_joint_od_m": 0.16828,
         "linear_mass_kg_m": 22.6 * lbft},
        {"name": "5in HWDP", "od_m": 0.127, "id_m": 0.0762, "length_m": 840 * 0.3048,
         "tool_joint_od_m": 0.1651, "linear_mass_kg_m": 49.3 * lbft},
        {"name": "6.5in DC", "od_m": 0.1651, "id_m": 0.05715, "length_m": 372 * 0.3048,
         "linear_mass_kg_m": 91.8 * lbft},
    ]
    return path, build_string(sections, bit_m), sections


def build_ode_top_force(f_eob, w, kappa, beta, mu_sigma):
    """Top-of-build force of dF/dφ = σμF + (w/κ)(cos(β−φ) − σμ sin(β−φ)) over φ ∈ [0, β].

    The soft-string ODE of a planar build where tension dominates (N = Fκ − w sin I > 0),
    φ = β − I counted upwards; linear, so F_top = e^{σμβ}[F_eob + ∫e^{−σμφ}(...) dφ].
    """
    from scipy.integrate import quad

    def rhs(phi):
        return np.exp(-mu_sigma * phi) * (w / kappa) * (np.cos(beta - phi)
                                                        - mu_sigma * np.sin(beta - phi))
    return np.exp(mu_sigma * beta) * (f_eob + quad(rhs, 0.0, beta, epsabs=1e-6)[0])


def test_johancsik_example3_against_semi_analytic_solution():
    """Johancsik et al. 1984 Example 3 (docs/reference_cases.md) at μ = 0.39, against closed forms.

    The paper's printed loads are not available here (numbers we get are recorded in
    docs/validation.md). What is exact on this well: the hold is straight
    (slant formula per element) and the build is a planar arc where the string is
    tension-dominated, so the soft-string equations become a linear ODE integrated here by
    quadrature; the vertical part adds w·L. The march is first order in the element size
    (capstan test): at 1 m elements, δ = 1.4e-3 rad, μ = 0.39, the error is ~1e-4: < 5e-4.
    """
    path, string, _ = johancsik_example3()
    mu, rho = 0.39, 1198.0
    kw = {"friction": mu, "mud_out_kg_m3": rho, "element_length_m": 1.0}
    beta, kop, eob = np.radians(44.0), 731.5, 1280.0
    kappa = beta / (eob - kop)
    w_dp = string.sections[0].buoyed_weight_N_m(rho, rho)
    hold = [(s.buoyed_weight_N_m(rho, rho), s.length_m) for s in string.sections]
    hold[0] = (w_dp, string.sections[0].length_m - eob)
    for case, sigma in (("pick_up", 1.0), ("slack_off", -1.0), ("rotating_off_bottom", 0.0)):
        res = solve(path, string, load_case=case, **kw)
        f_eob = sum(w * L * (np.cos(beta) + sigma * mu * np.sin(beta)) for w, L in hold)
        f_top = build_ode_top_force(f_eob, w_dp, kappa, beta, sigma * mu)
        assert f_eob * kappa > w_dp * np.sin(beta)  # the ODE's premise: tension dominates
        assert res.hookload_N == pytest.approx(f_top + w_dp * kop, rel=5e-4)
    pu, so = (solve(path, string, load_case=c, **kw).hookload_N for c in ("pick_up",
                                                                          "slack_off"))
    rot = solve(path, string, **kw)
    assert pu > rot.hookload_N > so > 0
    # rotating torque: hold μ·r_c·w·sin β per metre, build μ·r_c·(Fκ − w sin I) per metre
    from scipy.integrate import quad

    r_dp = string.sections[0].contact_radius_m
    f_eob = sum(w * L * np.cos(beta) for w, L in hold)
    hold_torque = sum(mu * s.contact_radius_m * w * L * np.sin(beta)
                      for s, (w, L) in zip(string.sections, hold, strict=True))

    def build_torque(phi):
        force = f_eob + (w_dp / kappa) * (np.sin(beta) - np.sin(beta - phi))
        return mu * r_dp * (force * kappa - w_dp * np.sin(beta - phi)) / kappa
    expected = hold_torque + quad(build_torque, 0.0, beta)[0]
    assert rot.surface_torque_Nm == pytest.approx(expected, rel=5e-4)


# ---------------------------------------------------------------------------------------
# back-calculation and broomstick
@pytest.mark.parametrize("case,attr", [("rotating_off_bottom", "surface_torque_Nm"),
                                       ("pick_up", "hookload_N"), ("slack_off", "hookload_N")])
def test_back_calculated_friction_round_trip(case, attr):
    """Root find to xtol 1e-8: recovering the μ that produced a load within 1e-6."""
    path, string = build_hold(), two_section(3800.0)
    measured = getattr(solve(path, string, friction=0.237, load_case=case), attr)
    key = "surface_torque_Nm" if attr == "surface_torque_Nm" else "hookload_N"
    mu = back_calculate_friction(path, string, load_case=case, **{key: measured})
    assert mu == pytest.approx(0.237, abs=1e-6)


def test_back_calculation_with_wob_and_bit_torque():
    path, string = build_hold(), two_section(3800.0)
    kw = {"load_case": "rotating_on_bottom", "wob_N": 100e3, "bit_torque_Nm": 3e3}
    measured = solve(path, string, friction=0.18, **kw).surface_torque_Nm
    assert back_calculate_friction(path, string, surface_torque_Nm=measured,
                                   **kw) == pytest.approx(0.18, abs=1e-6)


def test_back_calculation_out_of_range_is_a_clear_error():
    path, string = build_hold(), two_section(3800.0)
    with pytest.raises(ModelError, match="no friction factor in"):
        back_calculate_friction(path, string, surface_torque_Nm=-5.0)
    with pytest.raises(ModelError, match="exactly one"):
        back_calculate_friction(path, string)


def test_broomstick_rows_equal_single_solves():
    """The batched kernel gives the same numbers as one solve per case (rtol 1e-12)."""
    path = build_hold()
    cfg = load_config()
    depths, mus = [1200.0, 2500.0, 3900.0], [0.1, 0.3]
    cases = ["rotating_off_bottom", "rotating_on_bottom", "pick_up", "slack_off"]
    table = broomstick(path, cfg.sections, depths, mus, cases, wob_N=50e3,
                       bit_torque_Nm=2e3, element_length_m=3.0)
    assert len(table) == len(depths) * len(mus) * len(cases)
    for row in table.itertuples():
        res = solve(path, build_string(cfg.sections, row.bit_depth_m),
                    friction=row.friction_factor, load_case=row.load_case, wob_N=50e3,
                    bit_torque_Nm=2e3, element_length_m=3.0)
        assert row.hookload_N == pytest.approx(res.hookload_N, rel=1e-12)
        assert row.surface_torque_Nm == pytest.approx(res.surface_torque_Nm, rel=1e-12,
                                                      abs=1e-9)
        assert row.T_N_Nm == pytest.approx(res.T_N_Nm, rel=1e-12, abs=1e-9)
    fixed = broomstick(path, build_string(cfg.sections, 3000.0), depths, mus, cases,
                       wob_N=50e3, bit_torque_Nm=2e3, element_length_m=3.0)
    np.testing.assert_allclose(fixed["hookload_N"], table["hookload_N"], rtol=1e-12)
    fig = broomstick_figure(table)
    assert len(fig.axes) == 2 and fig.axes[0].get_ylim()[0] > fig.axes[0].get_ylim()[1]


# ---------------------------------------------------------------------------------------
# invariants and bad input
@settings(max_examples=25, deadline=None)
@given(inc=st.lists(st.floats(0.0, 100.0), min_size=4, max_size=4),
       azi=st.lists(st.floats(0.0, 360.0), min_size=4, max_size=4),
       mu=st.floats(0.0, 0.8))
def test_load_case_ordering_and_non_negative_side_force(inc, azi, mu):
    """Friction only adds to pick-up and subtracts from slack-off; N = |q| ≥ 0; torque ≥ 0."""
    path = minimum_curvature([0, 700, 1400, 2100], np.radians(inc), np.radians(azi))
    string = two_section(2000.0)
    pu = solve(path, string, friction=mu, load_case="pick_up", element_length_m=10.0)
    rot = solve(path, string, friction=mu, element_length_m=10.0)
    so = solve(path, string, friction=mu, load_case="slack_off", element_length_m=10.0)
    scale = 1e-9 * rot.T_N_Nm + 1e-6
    assert pu.hookload_N >= rot.hookload_N - scale and rot.hookload_N >= so.hookload_N - scale
    assert np.all(rot.normal_force_N_m >= 0) and np.all(np.diff(rot.torque_Nm) <= scale)


def test_bad_inputs_raise_model_errors():
    path = build_hold(td=3000.0)
    with pytest.raises(ModelError, match="beyond the survey"):
        solve(path, two_section(3500.0))
    with pytest.raises(ModelError, match="not lighter than the steel"):
        solve(path, two_section(2000.0), mud_out_kg_m3=8000.0)
    with pytest.raises(ModelError, match="0 ≤ ID < OD"):
        solve(path, DrillString((pipe(2000.0, od=0.1, id_=0.12),)))
    with pytest.raises(ModelError, match="dimensions must be positive"):
        solve(path, DrillString((pipe(2000.0, od=-0.1, id_=0.0),)))
    with pytest.raises(ModelError, match="element length"):
        solve(path, two_section(2000.0), element_length_m=0.0)
    with pytest.raises(ModelError, match="unknown load case"):
        solve(path, two_section(2000.0), load_case="tripping")
    with pytest.raises(ModelError, match="WOB"):
        solve(path, two_section(2000.0), load_case="rotating_on_bottom", wob_N=-1.0)
    with pytest.raises(ModelError, match="friction"):
        solve(path, two_section(2000.0), friction=-0.1)
    assert set(LOAD_CASES) >= {"rotating_off_bottom", "rotating_on_bottom", "pick_up",
                               "slack_off", "rotating_pick_up", "rotating_slack_off"}


def test_element_normal_force_doctest_case_and_vertical():
    assert element_normal_force(1e5, [0, 0, 1.0], [0, 0, 1.0], 500.0) == 0.0
    # horizontal, tension-free: the whole weight on the wall
    assert element_normal_force(0.0, [1.0, 0, 0], [1.0, 0, 0], 500.0) == pytest.approx(500.0)


# ---------------------------------------------------------------------------------------
# real data: Volve 15/9-F-5 survey + USROP F-5 on-bottom surface torque
F5_STRING = (
    {"name": "5.5in DP (assumed)", "od_m": 0.1397, "id_m": 0.1213, "tool_joint_od_m": 0.1778,
     "linear_mass_kg_m": 37.0},
    {"name": "6.75in DC (assumed)", "od_m": 0.1715, "id_m": 0.0714, "length_m": 150.0},
)
F5_BIT_FRICTION = 0.25  # assumed bit-specific sliding friction: T_bit = μ_b·WOB·D_bit/3


def f5_back_calculated_frictions(real_data, bin_m=10.0):
    """Apparent friction per ``bin_m`` of drilled depth (medians of the USROP rows)."""
    import pandas as pd

    from drillfric.io.survey import read_survey

    path = read_survey(real_data / "volve_surveys" / "F-5_ACTUAL.txt")
    data = pd.read_csv(real_data / "volve_usrop_f5" / "USROP_F-5_depth.csv", index_col=0)
    data.columns = ["md_m", "wob_kkgf", "spp_kPa", "torque_kNm", "rop_m_h", "rpm",
                    "flow_L_min", "mud_g_cm3", "bit_mm", "hookload_kkgf", "tvd_m", "gamma"]
    data = data[data["md_m"] <= path.md_max_m]
    binned = data.groupby(data["md_m"] // bin_m).median()
    out = []
    for row in binned.itertuples():
        wob = row.wob_kkgf * 1e3 * G_ACCEL
        out.append(back_calculate_friction(
            path, build_string(F5_STRING, row.md_m), surface_torque_Nm=row.torque_kNm * 1e3,
            load_case="rotating_on_bottom", wob_N=wob,
            bit_torque_Nm=F5_BIT_FRICTION * wob * row.bit_mm / 1e3 / 3,
            mud_out_kg_m3=row.mud_g_cm3 * 1e3))
    return np.array(out)


def test_volve_f5_apparent_friction_in_plausible_band(real_data):
    """Real data (../shared/data/real README): Volve F-5 survey, USROP F-5 on-bottom torque.

    String and BHA are not published: 5½" DP + 150 m 6¾" collars and the bit torque are
    assumptions (docs/validation.md), so this is a plausibility band, not
    a validated truth: 0.1–0.3 for the 5–95 % range of the per-10-m apparent friction.
    """
    mus = f5_back_calculated_frictions(real_data)
    assert mus.size > 80
    low, median, high = np.percentile(mus, [5, 50, 95])
    assert 0.1 < low and high < 0.3 and 0.13 < median < 0.22


def _tension_from_weight_below(string, md_m, rho, cos_inc):
    """F(s) = cos I·∫_s^L w ds: effective tension rotating off bottom on a constant-
    inclination path (docs/theory.md §2 step 3 with σ = 0), section by section [N]."""
    edges = string.boundaries_m
    w = [sec.buoyed_weight_N_m(rho, rho) for sec in string.sections]
    return cos_inc * np.array([sum(wi * max(0.0, hi - max(lo, s))
                                   for wi, lo, hi in zip(w, edges[:-1], edges[1:],
                                                         strict=True)) for s in md_m])


def test_side_force_on_the_assumed_tortuous_path():
    """No survey: the assumed path (a helix of DLS κ = 1°/30 m, docs/theory.md §1) gives the
    soft-string side force of docs/theory.md §2 step 2 in closed form.

    Tension from the buoyed weight below, F = cos I·∫w ds (rel 1e-5: the element-mean
    inclination inside each 10 m arc dips below the stations' by < 1 %, cos I moves ~1e-6).
    Side force per metre, with a = F_d·κ (F_d the tension at the element's lower node) and
    b = w·sin I: the curvature term lies along the arc's normal, the weight term in the
    vertical plane of the hole; they are orthogonal at mid-arc and the arc's normal tilts by
    at most ΔA/2 = 6° towards the weight term at the stations, while sin I dips to
    sin I·cos 6° at mid-arc (the arc is a great circle of the tangent sphere), so
    a² + (b cos 6°)² − 2ab·sin 6° ≤ F_N² ≤ a² + b² + 2ab·sin 6° (×(1 ± 1e-6) for the chord,
    (κΔs)²/24 ~ 1e-7). Where the tension dominates (a ≥ 30b, the top two thirds
    here), F_N = F·κ to r·sin 6° + r²/2 ≤ 4.1e-3 with r = b/a: checked at 5e-3.
    """
    cfg = load_config()
    assert cfg.survey.tortuosity_deg_30m == 1.0
    kappa, bit = np.radians(1.0) / 30.0, 2500.0
    res = solve_config(cfg, None, bit)
    path = no_survey_path(bit, kappa)
    inc = path.inc_rad[0]
    string = build_string(cfg.sections, bit)
    rho = cfg.fluid.mud_density_kg_m3
    tension = _tension_from_weight_below(string, res.md_m, rho, np.cos(inc))
    np.testing.assert_allclose(res.tension_N, tension, rtol=1e-5)
    mid = 0.5 * (res.md_m[1:] + res.md_m[:-1])
    a = tension[1:] * kappa
    b = string.buoyed_weight_N_m(mid, rho, rho) * np.sin(inc)
    half_turn = np.pi * 10.0 / 300.0  # ΔA/2 of the 10 m stations, 300 m period
    tilt, dip = np.sin(half_turn), np.cos(half_turn)
    fn2 = res.normal_force_N_m**2
    assert np.all(fn2 <= (a**2 + b**2 + 2 * a * b * tilt) * (1 + 1e-6))
    assert np.all(fn2 >= (a**2 + (b * dip)**2 - 2 * a * b * tilt) * (1 - 1e-6))
    dominant = a >= 30 * b
    assert dominant.sum() > 0.6 * dominant.size
    np.testing.assert_allclose(res.normal_force_N_m[dominant], a[dominant], rtol=5e-3)


def test_tortuosity_applies_only_without_a_survey():
    """A survey's own doglegs are real: the nominal tortuosity changes nothing there
    (bit-for-bit), while without a survey T_N grows with it (∝ κ where tension dominates)."""
    heavy = load_config(overrides={"survey.tortuosity_deg_30m": 3.0})
    none = load_config(overrides={"survey.tortuosity_deg_30m": 0.0})
    with_survey = [solve_config(c, build_hold(), 3000.0) for c in (heavy, none)]
    np.testing.assert_array_equal(with_survey[0].fc_Nm_m, with_survey[1].fc_Nm_m)
    t_n = [solve_config(c, None, 3000.0).T_N_Nm for c in (load_config(), heavy, none)]
    assert t_n[2] == 0.0 and t_n[1] == pytest.approx(3.0 * t_n[0], rel=0.01)
