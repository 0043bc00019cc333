"""The independent lumped validation plant (benchmarks/plants/lumped.py, its §L1–§L6):
physics against closed forms, its compiled kernel against its NumPy twin, and its
independence from drillfric's own model (no import of drillfric's plant, simulator, kernels,
torque and drag or well path)."""

from __future__ import annotations

import ast
import dataclasses

import numpy as np
import pytest

from benchmarks.plants import lumped as L
from tests.conftest import REPO

#: ≈ 10 s in all (the compiled kernel's first call, 80-s and 200-s runs, the NumPy twin).
pytestmark = pytest.mark.slow

#: The demo well's drill pipe and collars (examples/demo/demo.toml).
DP = L.Section("5 7/8in DP", 0.146529, 0.123024, None, 0.1778, 41.41, 61.0e9)
DC = L.Section("8in collars", 0.2032, 0.0714, 120.0, None, None, 67.0e9)
SURVEY = L.Survey.build_and_hold(td_m=2000.0, kop_m=500.0, tangent_deg=40.0)


@pytest.fixture(scope="module")
def string():
    return L.build_string([DP, DC], 1500.0, SURVEY, mud_density_kg_m3=1250.0)


def test_geometry_sums_to_the_closed_forms(string):
    """Σ C_i = ∫ w_b r_c sin θ dx and the hook load ∫ w_b cos θ dx, computed here by a
    fine midpoint rule (0.05 m) from §L1 alone: agreement to 1e-6 — the module integrates
    sin θ and cos θ exactly per piece, the midpoint rule's error is (Δ²/24)θ'² ≈ 1e-9."""
    x = (np.arange(30000) + 0.5) * 0.05
    th = np.radians(np.interp(x, SURVEY.md_m, SURVEY.inc_deg))
    dp = x < 1500.0 - 120.0
    w = np.where(dp, DP.buoyed_weight_N_m(1250.0), DC.buoyed_weight_N_m(1250.0))
    rc = np.where(dp, DP.contact_radius_m, DC.contact_radius_m)
    assert string.T_N_Nm == pytest.approx(np.sum(w * rc * np.sin(th)) * 0.05, rel=1e-6)
    assert string.hookload_N == pytest.approx(np.sum(w * np.cos(th)) * 0.05, rel=1e-6)
    assert string.n_elements >= 100
    assert string.inertia_kg_m2.sum() == pytest.approx(
        (1380.0 * DP.density_kg_m3 * DP.polar_moment_m4
         + 120.0 * DC.density_kg_m3 * DC.polar_moment_m4), rel=1e-12)


def test_steady_rotation_torque_is_the_sliding_capacity(string):
    """μ_s = μ_k, 120 RPM (12.6 rad/s ≫ ω_sw = 1 rad/s: no node sticks): in steady state
    every node turns at Ω and the top segment carries all the friction and drag below it,
    τ_1 = Σ_{i≥1} (μ_k C_i + d_i Ω) (§L2). Tolerance 0.1 %: the start-up's torsional
    ringing is damped at κ/2 = 0.25 1/s (κ = 0.5 1/s here), e^{-0.25·50} ≈ 4e-6 of it left
    after 50 s of hold, and the PI integral settles the speed to Ω within the same time."""
    fr = L.Friction(0.25, 0.25, viscous_rate_per_s=0.5)
    drive = L.Drive(L.setpoint(120.0, 80.0, idle_s=1.0, ramp_s=10.0, stop_s=0.0,
                               stop_hold_s=0.0), 2900.0, 38e3, 100e3)
    rec = L.simulate(string, drive, fr, 80.0, rate_hz=10.0)
    cols = rec.columns
    late = cols["time_s"] >= 60.0
    omega = 120.0 * L.RPM
    d = fr.viscous_rate_per_s * string.inertia_kg_m2
    expect = 0.25 * string.T_N_Nm + omega * d[1:].sum()
    assert np.mean(cols["surface_torque_Nm"][late]) == pytest.approx(expect, rel=1e-3)
    assert np.min(cols["bit_rpm"][cols["time_s"] >= 30.0]) > 1.0 / L.RPM


def test_mud_motor_adds_its_speed_and_slows_under_the_bit_torque(string):
    """§L6: off bottom the bit turns at ω_N + 2π·k·Q exactly (k = 0.1 rev/L, Q = 0.03 m³/s:
    180 RPM, the motor's no-load speed); on bottom (T_bit = μ_bit·WOB·D/3 = 1295.4 N·m,
    τ_stall = 2·T_bit) at half of it. The plant's string is not changed by the motor: the
    same run without it gives the same ω_N (to the last bit)."""
    fr = L.Friction(0.25, 0.25, viscous_rate_per_s=0.5)
    drive = L.Drive(L.setpoint(60.0, 20.0, idle_s=1.0, ramp_s=5.0, stop_s=0.0,
                               stop_hold_s=0.0), 2900.0, 38e3, 100e3)
    bit = L.Bit(wob_N=60e3)
    for on_bottom, motor_rpm in ((False, 180.0), (True, 90.0)):
        motor = L.Motor(0.1, 0.03, stall_torque_Nm=2.0 * bit.torque_Nm)
        used = bit if on_bottom else None
        cols = L.simulate(string, drive, fr, 20.0, rate_hz=10.0, bit=used, motor=motor).columns
        plain = L.simulate(string, drive, fr, 20.0, rate_hz=10.0, bit=used).columns
        assert np.array_equal(cols["bha_rpm"], plain["bit_rpm"])
        assert cols["bit_rpm"] - cols["bha_rpm"] == pytest.approx(motor_rpm, rel=1e-12)
        assert np.all(cols["flow_in_m3_s"] == 0.03)


def test_first_frequency_is_the_continuous_strings():
    """Uniform string (drill pipe only, 2000 m), top held (I_TD = 1e12 kg·m², no motor),
    frictionless and undamped, started in the continuous first mode ω(x) = sin(πx/2L): the
    bit speed oscillates at f1 = c/(4L) (fixed–free string). The lumped chain's exact first
    frequency is f1·sin(π/4N)/(π/4N) (N masses, half mass at the tip: 1 − 1.0e-5 at N = 100,
    checked here against the eigen-solver to 1e-9); the trapezoidal rule's period error is
    (ωΔt)²/12 ≈ 1e-7 and the zero crossings are interpolated linearly on a 100-Hz record
    (error ≈ 1e-6 s per crossing over 10 periods of 8 s). Tolerance 1e-4."""
    uniform = L.Survey(np.array([0.0, 3000.0]), np.array([30.0, 30.0]))
    s = L.build_string([DP], 2000.0, uniform)
    n = s.n_elements
    c = DP.wave_speed_m_s
    f1 = c / (4 * 2000.0)
    lumping = np.sin(np.pi / (4 * n)) / (np.pi / (4 * n))
    assert L.natural_frequencies_hz(s)[0] == pytest.approx(f1 * lumping, rel=1e-9)
    assert 1.0 - lumping < 2e-5
    v0 = np.sin(np.pi * s.x_m / (2 * 2000.0))
    v0[0] = 0.0
    fr = L.Friction(0.0, 0.0, material_loss_s=0.0, viscous_rate_per_s=0.0)
    drive = L.Drive(inertia_kg_m2=1e12, kp_Nms_rad=0.0, ki_Nm_rad=0.0)
    rec = L.simulate(s, drive, fr, 82.0, rate_hz=100.0, initial_speed_rad_s=v0)
    t, w = rec.columns["time_s"], rec.columns["bit_rpm"]
    k = np.nonzero((w[:-1] > 0) & (w[1:] <= 0))[0]
    crossings = t[k] + (t[k + 1] - t[k]) * w[k] / (w[k] - w[k + 1])
    f = (len(crossings) - 1) / (crossings[-1] - crossings[0])
    assert len(crossings) >= 10
    assert f == pytest.approx(f1, rel=1e-4)
    assert s.wave_time_s == pytest.approx(2000.0 / c, rel=1e-12)


@pytest.mark.parametrize("share,stuck", [(0.9, True), (1.1, False)])
def test_a_stuck_node_holds_below_its_static_capacity(string, share, stuck):
    """Friction only at the bit node (C_N = 10 kN·m, μ_s = 0.5: static capacity 5 kN·m), the
    motor torque raised smoothly (half a cosine over 120 s, 15 periods of the top drive on
    the stuck string) to 90 % or 110 % of it and held: at 90 % the bit never moves — its
    speed is exactly 0 in every record (the projection of §L3 sets a stuck node to 0) — at
    110 % it breaks free. The quasi-static ramp keeps the dynamic overshoot of the torque
    at the bit below a few per cent (the 90 % run shows it: a 10 % overshoot would break
    the bit)."""
    cap = np.zeros_like(string.capacity_Nm)
    cap[-1] = 1e4
    s = dataclasses.replace(string, capacity_Nm=cap)
    target = share * 0.5 * 1e4
    ramp = tuple((t, target * 0.5 * (1 - np.cos(np.pi * t / 120.0)))
                 for t in np.linspace(0.0, 120.0, 241)) + ((200.0, target),)
    drive = L.Drive(inertia_kg_m2=2900.0, motor_torque_Nm=ramp)
    rec = L.simulate(s, drive, L.Friction(0.5, 0.3), 200.0, rate_hz=20.0)
    bit = np.abs(rec.columns["bit_rpm"])
    if stuck:
        assert np.all(bit == 0.0)
        assert rec.columns["surface_torque_Nm"][-1] == pytest.approx(target, rel=0.05)
    else:
        assert bit.max() > 10.0


@pytest.fixture(scope="module")
def stick_slip(string):
    """12 s of a stiff-drive start-up into stick-slip (μ_s/μ_k = 2), by both kernels."""
    drive = L.Drive(L.setpoint(60.0, 100.0, idle_s=0.5, ramp_s=3.0), 2900.0, 38e3, 100e3)
    fr = L.Friction(0.5, 0.25)
    return {k: L.simulate(string, drive, fr, 5.0, rate_hz=100.0, kernel=k)
            for k in ("numba", "numpy")}


def test_energy_balance(stick_slip):
    """θ = ½: the step changes E = ½Σ I ω² + ½Σ k φ² by exactly the motor work minus the
    drag, material and friction dissipation (§L3), so the balance holds to round-off
    (1e-9 of the work, float64 sums over 5000 steps); friction never does work on the
    string (its cumulative dissipation never falls by more than round-off) and the drive
    did work (the string wound up and moved)."""
    rec = stick_slip["numba"]
    e = rec.energy
    bal = e["kinetic"] + e["spring"] - e["work_motor"] + e["diss_viscous"] + \
        e["diss_friction"]
    assert e["work_motor"][-1] > 1e4
    assert np.max(np.abs(bal)) < 1e-9 * e["work_motor"][-1]
    assert np.min(np.diff(e["diss_friction"])) > -1e-9 * e["work_motor"][-1]
    assert np.min(np.diff(e["diss_viscous"])) >= 0.0
    assert np.any(rec.columns["bit_rpm"] == 0.0) and rec.columns["bit_rpm"].max() > 30.0


def test_compiled_kernel_matches_its_numpy_twin(stick_slip):
    """The same red–black sweeps in both (§L3): agreement to 1e-9 relative over 5 s of
    stick-slip (observed ~1e-14: the same arithmetic, summed in another order in the
    twin's whole-array products; stick/slip decisions amplify such differences only after
    many cycles)."""
    a, b = stick_slip["numba"].columns, stick_slip["numpy"].columns
    for name in ("surface_rpm", "surface_torque_Nm", "motor_torque_Nm", "bit_rpm"):
        scale = np.max(np.abs(b[name]))
        np.testing.assert_allclose(a[name], b[name], rtol=0, atol=1e-9 * scale)


FORBIDDEN = ("drillfric.kernels", "drillfric.torsional", "drillfric.sim",
             "drillfric.torque_drag", "drillfric.wellpath", "drillfric.drillstring",
             "drillfric.estimation", "drillfric.friction")
ALLOWED_ROOTS = {"numpy", "scipy", "numba", "__future__", "collections", "dataclasses",
                 "typing", "math", "benchmarks"}


@pytest.mark.parametrize("path", sorted((REPO / "benchmarks" / "plants").glob("*.py")),
                         ids=lambda p: p.name)
def test_plants_import_no_model_of_drillfric(path):
    """The plants are independent of drillfric's model: no import of drillfric's plant,
    simulator, kernels, torque and drag or well path (pyproject.toml contract "plants",
    which lint-imports checks with indirect imports, tests/test_architecture.py); here each
    import statement is read, and only numpy/scipy/numba and the standard helpers pass."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    names = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            assert node.level == 0 or node.module is None or "drillfric" not in node.module
            names.append(node.module or "")
    for name in names:
        assert not any(name == f or name.startswith(f + ".") for f in FORBIDDEN), name
        assert name.split(".")[0] in ALLOWED_ROOTS, f"{path.name} imports {name}"
