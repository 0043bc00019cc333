"""Batch refinement (drillfric.estimation.batch, .creep) against synthetic truths, docs/theory.md
§6.

Truths are the plant of docs/theory.md §3 in PI mode (A&S 2018 gains, I_TD = 2900 kg·m²) on a
finer grid (1500 cells) than the estimator (500 cells for μ_k, ≥ MD/1000 for creeps),
with the six-section BHA of A&S Well A and gravity F_c, sampled at 100, 5 and 1 Hz with
noise (0.5 RPM, 200 N·m), torque logged as motor torque. Tolerances are the acceptance
lines of issue 5 (μ_k 5 % at 100/5 Hz, 10 % at 1 Hz; μ_s 10 % on creeps; no false bound):
the prototype studies of docs/theory.md §6.4 found ±2 % for μ_k and 0–3 % for creeps, the margin
covers the chaotic jitter of the mean torque and the speed noise integrated in a creep.
The case builders here are also used by benchmarks/validate_batch.py.
"""

from __future__ import annotations

import json
from dataclasses import asdict, replace
from functools import lru_cache

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from drillfric import torsional
from drillfric.drillstring import DrillString, Section
from drillfric.errors import InputError
from drillfric.estimation import batch
from drillfric.estimation.batch import creep_checks, harness, kinetic
from drillfric.estimation.creep import find_creeps, rotating_runs, smooth

#: Several seconds a test, or a costly shared fixture: not in the fast lane
#: (`pytest -m "not slow"`, docs/performance.md "The test suite").
pytestmark = pytest.mark.slow

RPM = np.pi / 30.0
OMEGA_C = 1.0  # [rad/s] docs/theory.md §6 prototypes
K_T = 0.1  # [1/s]
I_TD = 2900.0  # [kg·m²] A&S 2018
#: A&S 2018 Well A / synthetic BHA (length, OD, ID) [m], docs/reference_cases.md.
WELL_A_BHA = ((19.080, 0.150167, 0.096799), (10.240, 0.206375, 0.076200),
              (57.240, 0.150167, 0.096799), (9.750, 0.206248, 0.069850),
              (95.400, 0.150167, 0.096799), (38.750, 0.222392, 0.095964))


def _steel(od, idm):
    return 7850.0 * np.pi * (od**2 - idm**2) / 4.0


def well_string(md_m: float) -> DrillString:
    """A&S drill pipe (G = 61 GPa) to the six-section Well A BHA (G = 67 GPa),
    docs/reference_cases.md."""
    bha = sum(b[0] for b in WELL_A_BHA)
    dp = Section("dp", 0.146529, 0.123024, md_m - bha, 0.1778 / 2,
                 _steel(0.146529, 0.123024), 61e9)
    return DrillString((dp,) + tuple(
        Section(f"bha{i}", od, idm, length, od / 2, _steel(od, idm), 67e9)
        for i, (length, od, idm) in enumerate(WELL_A_BHA)))


def build_hold_inc(kop_m: float = 1500.0, hold_deg: float = 60.0):
    """Build-and-hold: vertical to the kick-off, 3°/30 m to ``hold_deg`` (A&S Well A)."""
    return lambda x: np.radians(np.clip((np.asarray(x) - kop_m) / 10.0, 0.0, hold_deg))


def schedule(kind: str, duration_s: float, rpm: float) -> np.ndarray:
    """Set-point every 0.5 s [rad/s]: a creep start (5 s rest, 0 → 5 RPM in 5 s, hold
    30 s, ramp to ``rpm`` in 10 s; issue 5) or a normal start (2 s rest, 10-s ramp)."""
    if kind == "creep":
        knots = ([0, 5, 10, 40, 50], [0, 0, 5, 5, rpm])
    else:
        knots = ([0, 2, 12], [0, 0, rpm])
    t = np.arange(0.0, duration_s + 1.0, 0.5)
    return np.interp(t, *knots) * RPM


def make_case(mu_s, mu_k, kind, duration_s, rpm, md_m=2500.0, cells=1500, kop_m=1500.0,
              hold_deg=60.0, kp=38e3, ki=100e3):
    """Truth record at 100 Hz: (string, F_c function, Record); PI drive gains ``kp`` [N·m·s/rad]
    and ``ki`` [N·m/rad] (default A&S 2018's)."""
    string = well_string(md_m)
    inc = build_hold_inc(kop_m, hold_deg)

    def fc(x):
        return torsional.gravity_fc(string, inc, x)

    grid = torsional.make_grid(string, cells)
    plant = torsional.Plant(grid, fc(grid.x_m), mu_s, mu_k, OMEGA_C, K_T, I_TD)
    drive = torsional.Drive("pi", schedule(kind, duration_s, rpm), 0.5, kp_Nms_rad=kp,
                            ki_Nm_rad=ki)
    rec, _ = torsional.run(plant, drive, duration_s, 100.0)
    return string, fc, rec


@lru_cache(maxsize=4)
def cached_case(*args, **kw):
    """:func:`make_case`, memoised within the test session (truth runs are the slow part)."""
    return make_case(*args, **kw)


def sample(rec, rate_hz, seed=0, noise=True, speed_rpm=0.5):
    """Decimate a 100-Hz record to ``rate_hz`` and add noise (``speed_rpm``, 200 N·m)."""
    step = int(round(100.0 / rate_hz))
    rng = np.random.default_rng(seed)
    t = rec.time_s[::step]
    w = rec.surface_rad_s[::step].copy()
    tau = rec.motor_torque_Nm[::step].copy()
    if noise:
        w += rng.normal(0.0, speed_rpm * RPM, w.size)
        tau += rng.normal(0.0, 200.0, tau.size)
    return t, w, tau


#: The fit's settings of these truths (ω_c, k_t, I_TD; the schema's defaults otherwise).
SETTINGS = batch.BatchSettings(omega_c_rad_s=OMEGA_C, k_t_per_s=K_T, top_drive_inertia_kg_m2=I_TD)


def estimate(string, fc, t, w, tau, settings=SETTINGS, **kw):
    return batch.refine(t, w, tau, string=string, fc_Nm_m=fc, settings=settings,
                        torque_kind="motor", **kw)


# --- pure functions -----------------------------------------------------------------------

def test_measured_string_torque_removes_top_drive_inertia():
    """τ_s = τ_m − I_TD dω₀/dt (eq. 7 of [1]): a top drive spun up at 0.5 rad/s² by
    τ_m = 1000 + I_TD·0.5 leaves 1000 N·m on the string (exact for a linear ramp)."""
    t = np.arange(0.0, 10.0, 0.01)
    w = 0.5 * t
    tau = batch.measured_string_torque(t, w, 1000.0 + I_TD * 0.5 + 0 * t, "motor", I_TD)
    np.testing.assert_allclose(tau, 1000.0, rtol=1e-9)
    same = batch.measured_string_torque(t, w, tau, "string", I_TD)
    np.testing.assert_array_equal(same, tau)
    with pytest.raises(InputError):
        batch.measured_string_torque(t, w, tau, "hook", I_TD)


def test_find_creeps_detects_a_creep_start_and_nothing_else():
    """A 0 → 5 RPM creep after 5 s at rest is found (issue 5 schedule; docs/theory.md §6.3);
    a normal start, a creep after too short a hold, and a creep with trapped torque are not."""
    t = np.arange(0.0, 60.0, 0.01)
    creep = np.interp(t, [0, 5, 10, 40, 50], [0, 0, 5, 5, 40]) * RPM
    found = find_creeps(t, creep, OMEGA_C)
    assert len(found) == 1
    t0, t1 = found[0]
    assert 5.0 <= t0 <= 6.5 and 40.0 <= t1 <= 41.5
    normal = np.interp(t, [0, 2, 12], [0, 0, 40]) * RPM
    assert find_creeps(t, normal, OMEGA_C) == []
    short = np.interp(t, [0, 5, 10, 15, 20], [0, 0, 5, 5, 40]) * RPM
    assert find_creeps(t, short, OMEGA_C) == []
    trapped = np.where(t < 6.0, 3000.0, 3000.0 + 100.0 * (t - 6.0))
    assert find_creeps(t, creep, OMEGA_C, torque_Nm=trapped) == []
    built_up = np.where(t < 6.0, 0.0, 300.0 * (t - 6.0))
    assert len(find_creeps(t, creep, OMEGA_C, torque_Nm=built_up)) == 1


@settings(max_examples=30, deadline=None)
@given(hold_s=st.floats(2.0, 40.0), creep_rpm=st.floats(2.5, 8.0), rest_s=st.floats(2.0, 20.0))
def test_find_creeps_needs_a_long_enough_hold_below_omega_c(hold_s, creep_rpm, rest_s):
    """Property (docs/theory.md §6.3): a start from rest that holds a speed below 0.9 ω_c is a creep
    iff it lasts ≥ 10 s (±1.5 s for the 1-s smoothing and the 2-s ramp); its start lies
    within 2 s of the true start of motion."""
    t = np.arange(0.0, rest_s + hold_s + 20.0, 0.05)
    knots = [0, rest_s, rest_s + 2, rest_s + hold_s, rest_s + hold_s + 5]
    w = np.interp(t, knots, [0, 0, creep_rpm, creep_rpm, 60]) * RPM
    found = find_creeps(t, w, OMEGA_C)
    if hold_s >= 11.5:
        assert len(found) == 1 and abs(found[0][0] - rest_s) <= 2.0
    elif hold_s <= 8.5:
        assert found == []


def test_rotating_runs_and_smooth():
    """Runs split at rest; the moving average keeps a constant and the mean of a series."""
    assert rotating_runs(np.array([0, 2, 2, 0, 0, 3.0]), OMEGA_C) == [(1, 2), (5, 5)]
    y = np.random.default_rng(1).normal(size=1000)
    np.testing.assert_allclose(smooth(np.full(50, 3.0), 0.01, 1.0), 3.0)
    assert abs(np.mean(smooth(y, 0.01, 0.5)) - np.mean(y)) < 0.01


@settings(max_examples=40, deadline=None)
@given(root=st.floats(0.05, 1.0), slope=st.floats(1e3, 1e5), jitter=st.floats(0.0, 100.0),
       x0=st.floats(0.02, 1.4), seed=st.integers(0, 1000))
def test_secant_returns_an_evaluated_point_with_bounded_steps(root, slope, jitter, x0, seed):
    """Invariants of the μ_k root find (docs/theory.md §6.4): the answer is a point it evaluated,
    with
    the smallest |residual| among them, inside the bounds, within the run budget; with the
    slope known to a factor 2 and jitter j it lands within ~2j/slope + tol of the root."""
    rng = np.random.default_rng(seed)
    calls = []

    def residual(x):
        r = slope * (x - root) * (1.0 + 0.3 * np.tanh(x)) + jitter * rng.uniform(-1, 1)
        calls.append((x, r))
        return r

    x, r, trace = kinetic.secant(residual, x0, slope, 1e-3, 1.5, tol=20.0)
    assert (x, r) in calls and trace == calls
    assert abs(r) == min(abs(c[1]) for c in calls)
    assert 1e-3 <= x <= 1.5 and len(calls) <= batch.settings.MU_K_MAX_RUNS
    assert abs(x - root) <= (2 * jitter + 20.0) / slope + 1e-9


@settings(max_examples=50, deadline=None)
@given(a=st.floats(1e-2, 1e7), v=st.floats(0.05, 1.5), c=st.floats(0.0, 1e5),
       x1=st.floats(0.1, 1.4), h=st.floats(1e-3, 0.1))
def test_parabola_vertex_is_exact_for_quadratics(a, v, c, x1, h):
    """The creep refit's vertex (3 points, or 2 points with a known curvature) recovers
    the minimum of an exact quadratic misfit a(x − v)² + c (to round-off)."""
    x = np.array([x1 - h, x1, x1 + h])
    j = a * (x - v) ** 2 + c
    for vertex, curv in (batch.parabola_vertex(x, j), batch.parabola_vertex(x, j, a)):
        scale = (abs(x1 - v) + h) ** 2 * a + c
        assert abs(vertex - v) <= 1e-6 * (1.0 + scale / (a * h))
        assert curv == pytest.approx(a, rel=1e-5, abs=1e-6 * scale / h**2)


def test_bad_input_and_no_rotation():
    string = well_string(1000.0)
    t = np.arange(0.0, 20.0, 0.1)
    with pytest.raises(InputError):
        estimate(string, 500.0, t, np.zeros(t.size - 1), np.zeros(t.size))
    res = estimate(string, 500.0, t, np.zeros_like(t), np.zeros_like(t))
    assert res.mu_k is None and res.mu_s is None and not res.mu_s_identifiable
    assert "no_rotation" in res.flags and res.runs == 0 and res.mu_s_method == "none"
    short = np.interp(t, [0, 2, 5], [0, 0, 40]) * RPM
    res = estimate(string, 500.0, t, short, np.full_like(t, 3000.0))
    assert res.mu_k is None and "rotation_too_short" in res.flags


# --- acceptance: synthetic truths (issue 5) -------------------------------------------------

@pytest.fixture(scope="module")
def paper_stick_slip():
    """The paper's case (docs/reference_cases.md: build-and-hold, μ_k = 0.187, μ_s = 0.6) at 40
    RPM."""
    return make_case(0.6, 0.187, "normal", 120.0, 40.0)


@pytest.mark.parametrize("rate_hz, tol", [(100.0, 0.05), (5.0, 0.05), (1.0, 0.10)])
def test_paper_case_stick_slip_mu_k_and_honest_mu_s(paper_stick_slip, rate_hz, tol):
    """μ_k within 5 % (100/5 Hz) / 10 % (1 Hz); stick-slip without a creep: μ_s not
    identifiable and any lower bound below the truth (issue 5 acceptance)."""
    string, fc, rec = paper_stick_slip
    res = estimate(string, fc, *sample(rec, rate_hz, seed=1))
    assert res.details.stick_slip
    assert res.mu_k == pytest.approx(0.187, rel=tol)
    assert res.mu_k_method == "mean_torque"
    assert not res.mu_s_identifiable and res.mu_s is None
    assert res.mu_s_lower_bound is None or res.mu_s_lower_bound < 0.6
    assert res.mu_s_method in ("stick_slip_onset", "none")


def test_stiff_drive_is_identified_only_where_the_log_resolves_it(paper_stick_slip):
    """A&S 2018's stiff PI drive (k_p = 38 kN·m·s/rad, k_i = 100 kN·m/rad): at 100 Hz the
    law explains ≥ 75 % of the motor torque's fluctuation and is replayed (gains within
    20 %: the 0.5-RPM speed noise biases k_p a little low); at 1 Hz the loop's response
    is not in the log, so the model follows the logged speed (docs/theory.md §6.4)."""
    string, fc, rec = paper_stick_slip
    fast = estimate(string, fc, *sample(rec, 100.0, seed=1)).details.drive
    assert fast.usable and fast.kp_Nms_rad == pytest.approx(38e3, rel=0.2)
    assert fast.ki_Nm_rad == pytest.approx(100e3, rel=0.2)
    slow = estimate(string, fc, *sample(rec, 1.0, seed=1))
    assert not slow.details.drive.usable
    assert any("follows the logged speed" in m for m in slow.messages)


@pytest.fixture(scope="module")
def soft_drive():
    """A soft PI drive (k_p = 900 N·m·s/rad, k_i = 2500 N·m/rad: the speed dips from 60 to
    ~20 RPM between slips), μ_s = 0.6, μ_k = 0.25 at 2300 m, 200 s."""
    return make_case(0.6, 0.25, "normal", 200.0, 60.0, md_m=2300.0, kp=900.0, ki=2500.0)


@pytest.mark.parametrize("seed", [0, 1])
def test_soft_drive_mu_k_not_biased(soft_drive, seed):
    """Regression (issue 14, soft-torque drive): following the logged speed, the model runs
    under an infinitely stiff drive, falls out of step with the rig and sticks more often —
    μ_k +3.6…+5 % (0.259–0.262 over three seeds). Replaying the identified drive in closed
    loop it is within 0.5 % (0.249–0.250); 2 % is the chaotic jitter of a 170-s mean."""
    string, fc, rec = soft_drive
    res = estimate(string, fc, *sample(rec, 100.0, seed=seed))
    drive = res.details.drive
    assert drive.usable and drive.kp_Nms_rad == pytest.approx(900.0, rel=0.05)
    assert drive.ki_Nm_rad == pytest.approx(2500.0, rel=0.05)
    assert res.mu_k == pytest.approx(0.25, rel=0.02)


def test_steady_rotation_gives_mu_k_and_no_mu_s_bound():
    """Steady rotation (paper case at 100 RPM: no stick-slip, no creep): μ_k within 5 %,
    μ_s not identifiable and no bound (docs/theory.md §6.2); the same with a logged string
    torque."""
    string, fc, rec = make_case(0.6, 0.187, "normal", 75.0, 100.0)
    calls = []
    res = estimate(string, fc, *sample(rec, 5.0, seed=2), progress=calls.append)
    assert len(calls) == res.runs >= 1
    assert not res.details.stick_slip
    assert res.mu_k == pytest.approx(0.187, rel=0.05)
    assert not res.mu_s_identifiable and res.mu_s_lower_bound is None
    assert res.mu_s_method == "none"
    json.dumps(asdict(res.details))  # goes into summary.json as is
    t, w, _ = sample(rec, 5.0, seed=2)
    tau_string = rec.string_torque_Nm[::20] + np.random.default_rng(2).normal(0, 200, t.size)
    res = batch.refine(t, w, tau_string, string=string, fc_Nm_m=fc, settings=SETTINGS,
                       torque_kind="string")
    assert res.mu_k == pytest.approx(0.187, rel=0.05)


def test_steady_short_rotation_without_torque_cycles_gives_mu_k():
    """Issue 33 item 8: a 45-s steady rotation whose torque holds no cycles (a damped plant,
    a clean 1-s-mean torque: here the truth's torque without noise) got no μ_k — the
    3-whole-cycle rule meant for stick-slip refused it. Its 5-s blocks now state the mean
    torque's error; μ_k within the 5 % of a 5-Hz log (docs/validation.md), with a 2σ that
    is neither zero nor wider than that."""
    string, fc, rec = cached_case(0.187, 0.187, "normal", 45.0, 100.0)
    t, w, tau = sample(rec, 5.0, noise=False)
    # this plant rings nearly undamped after the ramp (period ~5 s); a damped string's
    # ringing dies out: from the ramp's end its swing about the mean decays in 3 s
    level = float(np.mean(tau[t > 25.0]))
    tau = np.where(t > 12.0, level + (tau - level) * np.exp(-(t - 12.0) / 3.0), tau)
    assert len(harness.up_crossings(tau[t > 13.0], 0.2)) < 4  # fewer than 3 cycles
    res = estimate(string, fc, t, w, tau)
    assert res.mu_k == pytest.approx(0.187, rel=0.05)
    two_sigma = 2.0 * res.details.mu_k_sigma
    assert 0.0 < two_sigma < 0.05 * 0.187 and abs(res.mu_k - 0.187) <= two_sigma
    assert res.details.torque_cycles >= harness.MIN_CYCLES  # the 5-s blocks


def test_second_truth_deeper_stick_slip():
    """Another truth and depth (MD 3000 m, μ_k = 0.25, μ_s = 0.45, 50 RPM, 100 Hz)."""
    string, fc, rec = make_case(0.45, 0.25, "normal", 100.0, 50.0, md_m=3000.0)
    res = estimate(string, fc, *sample(rec, 100.0, seed=3))
    assert res.mu_k == pytest.approx(0.25, rel=0.05)
    assert not res.mu_s_identifiable
    assert res.mu_s_lower_bound is None or res.mu_s_lower_bound < 0.45


@pytest.mark.slow
def test_creep_logged_at_5_hz_is_withheld_for_the_twist_noise():
    """The model integrates the logged speed into its twist, so speed noise becomes a random
    walk of the twist, Var = σ_ω²Δt·t (docs/theory.md §6.3, check 2). Its 1-σ on μ_s grows
    as √Δt: 5 Hz against 100 Hz on the same record is √20 ≈ 4.5× (tolerance 3–6.5×: the two
    noise draws differ and the slopes τ' come from each fit). With 0.5 RPM of noise it is
    ≈ 2 % at 100 Hz (passes) and ≈ 9 % at 5 Hz, above the 10 %/3 a claim needs: withheld
    with the reason (validation found 5-Hz fits scattered −3…+11 % over three noise seeds),
    and the fallback bound stays below the truth. (At 100 Hz the halves check withholds
    μ_s: test_creep_start_identifies_mu_s.)"""
    string, fc, rec = cached_case(0.6, 0.187, "creep", 120.0, 40.0, md_m=2500.0,
                                  kop_m=1500.0)
    fast = estimate(string, fc, *sample(rec, 100.0, seed=0))
    slow = estimate(string, fc, *sample(rec, 5.0, seed=0))
    assert not any("speed noise integrated into the twist" in m for m in fast.messages)
    assert not slow.mu_s_identifiable and "mu_s_not_explained" in slow.flags
    assert any("speed noise integrated into the twist" in m for m in slow.messages)
    ratio = slow.details.creep_checks.twist_noise / fast.details.creep_checks.twist_noise
    assert 3.0 < ratio < 6.5
    assert slow.mu_s_lower_bound is None or slow.mu_s_lower_bound < 0.6


@pytest.mark.slow
@pytest.mark.parametrize("mu_s, mu_k, md_m, kop_m, rate_hz", [
    (0.6, 0.187, 2500.0, 1500.0, 100.0),  # the paper's case, creep start
    # docs/reference_cases.md field fit at 2,506 m, on a shallower well:
    (0.43, 0.185, 1800.0, 900.0, 100.0),
])
def test_creep_start_identifies_mu_s(mu_s, mu_k, md_m, kop_m, rate_hz):
    """Records with a creep start (0 → 5 RPM in 5 s, hold 30 s, ramp): μ_s within 10 %
    (issue 5), grid-converged (docs/theory.md §6.4), method recorded; μ_k within 5 %. 120-s records:
    μ_k uses rotation from the end of its start-up on (docs/theory.md §6.4 "Start-up"); with
    only ~6 stick-slip cycles the chaotic mean alone moved μ_k by 6 %
    (docs/batch_refinement.md). Speed noise 0.1 RPM: with 0.5 RPM the halves' twist noise
    (≈ ±2–3 % each) leaves them unable to see a cased top (2σ ≈ 7 % > 6 %) and μ_s is
    withheld with that reason, the bound below the truth."""
    string, fc, rec = cached_case(mu_s, mu_k, "creep", 120.0, 40.0, md_m=md_m, kop_m=kop_m)
    noisy = estimate(string, fc, *sample(rec, rate_hz, seed=0))
    assert not noisy.mu_s_identifiable
    assert any("halves cannot be compared" in m for m in noisy.messages)
    assert noisy.mu_s_lower_bound is None or noisy.mu_s_lower_bound < mu_s
    res = estimate(string, fc, *sample(rec, rate_hz, seed=0, speed_rpm=0.1))
    assert res.mu_s_identifiable and res.mu_s_method == "creep_fit"
    assert res.mu_s == pytest.approx(mu_s, rel=0.10)
    assert res.mu_k == pytest.approx(mu_k, rel=0.05)
    assert len(res.creep_segments) == 1 and res.mu_s_lower_bound is None
    assert res.details.creep_grid_move < batch.settings.CREEP_CONVERGENCE


@pytest.mark.slow
def test_creep_at_1_hz_is_not_fitted():
    """At 1 Hz the speed noise integrated into the twist moved creep μ_s by +17…+33 %
    (validation table): the creep is found but not fitted, μ_s is not reported, and the
    stick-slip that follows still gives only a bound below the truth."""
    string, fc, rec = cached_case(0.6, 0.187, "creep", 120.0, 40.0, md_m=2500.0,
                                  kop_m=1500.0)
    res = estimate(string, fc, *sample(rec, 1.0, seed=0))
    assert "creep_rate_too_low" in res.flags
    assert res.mu_s is None and not res.mu_s_identifiable and res.creep_segments == ()
    assert res.mu_s_lower_bound is None or res.mu_s_lower_bound < 0.6
    assert res.mu_k == pytest.approx(0.187, rel=0.10)


@pytest.mark.slow
def test_creep_fit_with_no_room_above_mu_k_is_at_its_bound():
    """The rule of ``creep_fit_at_bound`` (drillfric.result.FLAG_RAISED_BY): with μ_k at the
    clamp ``observer.mu_max`` (0.15 below the data's 0.187) no μ_s above μ_k can be
    searched: the creep is not fitted, μ_s not reported, and the message names the clamp."""
    string, fc, rec = cached_case(0.6, 0.187, "creep", 120.0, 40.0, md_m=2500.0,
                                  kop_m=1500.0)
    res = estimate(string, fc, *sample(rec, 100.0, seed=0, speed_rpm=0.1),
                   settings=replace(SETTINGS, mu_max=0.15))
    assert "creep_fit_at_bound" in res.flags and res.mu_s is None
    assert any("within observer.mu_max = 0.15" in m for m in res.messages)


@pytest.mark.slow
def test_creep_fit_that_keeps_moving_on_refinement_is_not_reported(monkeypatch):
    """The rule of ``creep_not_grid_converged``: a creep μ_s that still moves on the last
    grid refinement is not reported (here every move counts as too large: the
    convergence threshold set to 0), with each grid's μ_s in the message."""
    from drillfric.estimation.batch import creep_fit

    monkeypatch.setattr(creep_fit, "CREEP_CONVERGENCE", 0.0)
    string, fc, rec = cached_case(0.6, 0.187, "creep", 120.0, 40.0, md_m=2500.0,
                                  kop_m=1500.0)
    res = estimate(string, fc, *sample(rec, 100.0, seed=0, speed_rpm=0.1))
    assert "creep_not_grid_converged" in res.flags and res.mu_s is None
    assert any("not grid-converged" in m and "cells" in m for m in res.messages)


# --- the configuration reaches the fit (issue 21: settings bound at import time) ----------

def test_batch_settings_take_every_key_from_the_configuration():
    """Regression: ``segmentation.dip_max_s``, ``dip_torque_fraction`` and ``observer.mu_max``
    were bound to the schema defaults at import; every field must come from the file."""
    from drillfric.config import config_from_dict
    cfg = config_from_dict({"model": {"omega_c_rpm": 6.0, "k_t_per_s": 0.3,
                                      "k_t_uncertainty_factor": 2.0},
                            "rig": {"top_drive_inertia_kg_m2": 1500.0},
                            "observer": {"mu_max": 0.95},
                            "segmentation": {"dip_max_s": 25.0, "dip_torque_fraction": 0.3},
                            "batch": {"window_s": 300.0, "trend_window_s": 90.0}})
    got = batch.BatchSettings.from_config(cfg)
    assert got == batch.BatchSettings(omega_c_rad_s=6.0 * RPM, k_t_per_s=0.3,
                                      top_drive_inertia_kg_m2=1500.0, mu_max=0.95,
                                      dip_max_s=25.0, dip_torque_fraction=0.3, window_s=300.0,
                                      trend_window_s=90.0, k_t_uncertainty_factor=2.0)
    defaults = batch.BatchSettings.from_config(config_from_dict({}))
    assert all(getattr(got, f) != getattr(defaults, f) for f in got.__dataclass_fields__)


def test_mu_max_bounds_the_mu_k_search():
    """Regression: ``observer.mu_max = 0.15`` left the fit searching up to 1.5, and the seeded
    observer then failed every segment with the wrong reason. With μ_k = 0.187 in the data,
    the search stops at the clamp and says so (not converged, the key named)."""
    string, fc, rec = cached_case(0.6, 0.187, "normal", 75.0, 100.0)
    res = estimate(string, fc, *sample(rec, 5.0, seed=2),
                   settings=replace(SETTINGS, mu_max=0.15))
    assert res.mu_k <= 0.15
    assert all(mu <= 0.15 for mu, _ in res.details.mu_k_trace)
    assert "mu_k_not_converged" in res.flags
    assert any("observer.mu_max = 0.15" in m for m in res.messages)


def test_mu_max_bounds_the_onset_scan(paper_stick_slip):
    """The stick-slip-onset scan stops at ``observer.mu_max`` (here below the truth μ_s 0.6):
    no point above the clamp, and no bound claimed above it."""
    string, fc, rec = paper_stick_slip
    res = estimate(string, fc, *sample(rec, 5.0, seed=1), settings=replace(SETTINGS, mu_max=0.3))
    assert res.details.onset_scan and all(mu <= 0.3 for mu, _ in res.details.onset_scan)
    assert res.mu_s_lower_bound is None or res.mu_s_lower_bound <= 0.3


def _loaded_stop_record():
    """Rotation at 100 RPM, a 15-s stop of the top drive with the string still wound (the
    PI drive ramps down over 10 s, the string torque held at ~85 % of the run's mean), rotation
    again for 25 s; 1500 m, 10 Hz, no noise."""
    string = well_string(1500.0)
    inc = build_hold_inc(500.0, 60.0)

    def fc(x):
        return torsional.gravity_fc(string, inc, x)

    grid = torsional.make_grid(string, 300)
    plant = torsional.Plant(grid, fc(grid.x_m), 0.4, 0.25, OMEGA_C, K_T, I_TD)
    knots = ([0, 2, 12, 50, 60, 75, 77, 100], [0, 0, 100, 100, 0, 0, 100, 100])
    setpoint = np.interp(np.arange(0.0, 101.0, 0.5), *knots) * RPM
    rec, _ = torsional.run(plant, torsional.Drive("pi", setpoint, 0.5), 100.0, 10.0)
    return string, fc, rec


def _fit_runs(dip_max_s: float, fraction: float) -> int:
    """The rotating runs of the loaded-stop record as the μ_k fit cuts them (used or left
    out with a note)."""
    string, fc, rec = _loaded_stop_record()
    settings = replace(SETTINGS, dip_max_s=dip_max_s, dip_torque_fraction=fraction)
    data, _ = harness.prepare(rec.time_s, rec.surface_rad_s, rec.motor_torque_Nm, "motor", I_TD)
    model = harness.Model(string, harness.as_fc_fn(fc), settings, data)
    wins, notes = kinetic.rotating_windows(data, settings, *model.wind_up(300))
    return len(wins) + len(notes)


@pytest.mark.parametrize("dip_max_s, runs", [(10.0, 2), (25.0, 1)])
def test_dip_max_s_cuts_the_fit_where_segmentation_cuts(dip_max_s, runs):
    """Regression: ``segmentation.dip_max_s = 25`` joined a loaded stop into one rotation in
    the segmentation but not in the fit. Both now cut at the same place: two rotations
    or one."""
    import pandas as pd

    from drillfric.config import config_from_dict
    from drillfric.segmentation import segment
    _, _, rec = _loaded_stop_record()
    frame = pd.DataFrame({"time_s": rec.time_s, "surface_rpm": rec.surface_rad_s / RPM,
                          "surface_torque_Nm": rec.motor_torque_Nm})
    cfg = config_from_dict({"segmentation": {"dip_max_s": dip_max_s, "min_segment_s": 1.0}})
    assert len(segment(frame, cfg)) == runs
    told = batch.BatchSettings.from_config(cfg)
    assert _fit_runs(told.dip_max_s, told.dip_torque_fraction) == runs


def test_dip_torque_fraction_reaches_the_fit():
    """The stop holds ~85 % of the run's mean string torque: loaded for a fraction of 0.5,
    released (the run ends there) for 0.9."""
    assert _fit_runs(25.0, 0.5) == 1
    assert _fit_runs(25.0, 0.9) == 2


# --- the start-up transient (docs/theory.md §6.4 "Start-up") --------------------------------

def test_wind_up_twist_of_a_uniform_string_is_l_over_2gj():
    """Θ/T_N of a uniform string with uniform F_c: the static profile τ(x) = F_c(L − x)
    twists it by F_c L²/(2GJ) at top torque F_c L, so Θ/T_N = L/(2GJ) (to half a cell)."""
    pipe = Section("pipe", 0.127, 0.1086, 2000.0, 0.0635, _steel(0.127, 0.1086))
    string = DrillString((pipe,))
    data, _ = harness.prepare(np.arange(3.0), np.zeros(3), np.zeros(3), "string", I_TD)
    model = harness.Model(string, harness.as_fc_fn(20.0), SETTINGS, data)
    rad_per_Nm, round_trip_s = model.wind_up(400)
    gj = pipe.shear_modulus_Pa * pipe.polar_moment_m4
    assert rad_per_Nm == pytest.approx(2000.0 / (2.0 * gj), rel=1 / 400)
    assert round_trip_s == pytest.approx(2.0 * 2000.0 / pipe.wave_speed_m_s, rel=0.01)


def test_start_up_ends_after_the_bit_breaks_free():
    """On the paper case's start-up (μ_s = 0.6, 40 RPM) the rule's end, from surface data
    alone, lies after the truth's bit first exceeds ω_c: the wind-up is never compared."""
    string, fc, rec = cached_case(0.6, 0.187, "normal", 32.0, 40.0)
    t, w, tau = sample(rec, 100.0, seed=4)
    data, _ = harness.prepare(t, w, tau, "motor", I_TD)
    model = harness.Model(string, fc, SETTINGS, data)
    i0 = int(np.flatnonzero(data.w_bar > 0.1 * OMEGA_C)[0])
    end = harness.start_up_end(data.tau[i0:], data.turned_rad(i0, t.size - 1), data.dt,
                               *model.wind_up(500))
    free = rec.time_s[np.flatnonzero(rec.bit_rad_s > OMEGA_C)[0]]
    assert free < data.t[i0 + end] < free + 10.0


def test_thirty_second_rotation_gap_mu_k_converges():
    """Regression (issue 22, the 30-s gap): a fixed 30 s left out after ω_c left nothing of
    a 30-s off-bottom rotation. With the start-up rule a 30-s stick-slip rotation (10-s ramp
    to 60 RPM, paper case) gives μ_k within 5 % at 100 and 5 Hz, its stated 2σ within the
    claim (docs/theory.md §6.4). (At 40 RPM its ~7-s cycles leave two after the start-up:
    withheld, as the next test shows for a shorter run.)"""
    string, fc, rec = cached_case(0.6, 0.187, "normal", 32.0, 60.0)
    for rate in (100.0, 5.0):
        res = estimate(string, fc, *sample(rec, rate, seed=1))
        assert res.details.stick_slip and "mu_k_not_converged" not in res.flags
        assert res.mu_k == pytest.approx(0.187, rel=0.05)
        assert 2.0 * res.details.mu_k_sigma <= 0.05 * res.mu_k
        assert res.details.torque_cycles >= 3


def test_rotation_within_its_start_up_is_withheld_with_the_reason():
    """A 12-s rotation (the 10-s ramp and 2 s at 40 RPM) ends before three torque cycles
    follow its start-up: no μ_k, flag ``rotation_too_short`` and the note says why."""
    string, fc, rec = cached_case(0.6, 0.187, "normal", 14.0, 40.0)
    res = estimate(string, fc, *sample(rec, 100.0, seed=1))
    assert res.mu_k is None and "rotation_too_short" in res.flags
    assert any(m.startswith("rotating run") and ("start-up" in m) for m in res.messages)


class _ChaoticModel:
    """Stands in for :class:`harness.Model` in the swing check: its torque stick-slips like
    the data's (±30 % about 10 kN·m, a 6-s cycle) at every μ_s but those listed in
    ``steady_at``, where the run settled into steady rotation instead."""

    def __init__(self, steady_at=()):
        t = np.arange(0.0, 200.0, 0.2)
        wave = 10e3 * (1.0 + 0.3 * np.sign(np.sin(2 * np.pi * t / 6.0)))
        still = np.zeros(t.size)
        self.data = harness.FitData(t=t, dt=0.2, drive=still, motor=still, creep_drive=still,
                                    w_bar=still, tau=wave, tau_bar=smooth(wave, 0.2, 1.0),
                                    speed=still)
        self.steady_at = steady_at
        self.wave = wave

    def simulate(self, w, mu_s, mu_k, cells):
        steady = any(abs(mu_s - m) < 1e-9 for m in self.steady_at)
        tau = np.full(self.wave.size, 10e3) if steady else self.wave
        return tau[w.sim0:w.end + 1], np.zeros(w.end + 1 - w.sim0)


def test_swing_check_one_chaotic_steady_run_does_not_withhold_a_right_mu_s():
    """Regression (validate_real_wells / validate_trust, step-law stand at 5 Hz, 27 Nov 2026):
    the creep fit's μ_s = 0.614 (truth 0.6) was withheld as `mu_s_not_explained` because the
    model at exactly (0.614, 0.2507) settled into steady rotation (model/data stick-slip
    0.46), while at μ_s 0.600 or 0.620 it stick-slipped like the data (0.86–1.08). The check
    takes the median over μ_s and μ_s·(1 ± its own 1-σ); a law whose neighbours do not
    stick-slip either (Stribeck) still fails it."""
    w = harness.Window(0, 999, np.arange(100, 1000))
    one_off = _ChaoticModel(steady_at=(0.614,))
    assert creep_checks.swing_ratio(one_off, [w], 0.614, 0.25, 500) < 0.1  # one point
    assert creep_checks.swing_ratio(one_off, [w], 0.614, 0.25, 500, spread=0.023) \
        == pytest.approx(1.0)
    law_fails = _ChaoticModel(steady_at=tuple(0.614 * f for f in (0.977, 1.0, 1.023)))
    assert creep_checks.swing_ratio(law_fails, [w], 0.614, 0.25, 500, spread=0.023) < 0.1
    # an unpinned fit (infinite spread) is judged at its own point
    assert creep_checks.swing_ratio(one_off, [w], 0.614, 0.25, 500, spread=np.inf) < 0.1


def test_cased_effective_5_hz_seed_8_halves_blind_to_the_cased_top():
    """Regression (issue 22; docs/validation.md seed probe): the cased-effective plant of
    validate_trust.py (μ_s 0.35 above the 1500-m shoe, 0.6 below, no casing keys; effective
    0.500) logged at 5 Hz with noise seed 8 claimed μ_s = 0.412 (−17.5 %). Its creep checks
    as measured: misfit 0.8 %, sensitivity 22, twist noise ±2.1 %, halves 0.404 / 0.419
    (−3.6 %, inside the −6 % line) — but each half's twist noise (≈ ±2.4 %, the walk over
    that half) makes the halves' 2σ ±7.0 %, more than the 6 % split a cased top must show:
    the check cannot see it, and μ_s is withheld with that reason. The same creep logged
    with quiet speed (each half ±1 %: 2σ ≈ 3.3 %) is judged by the line and passes."""
    seed_8 = creep_checks.CreepChecks(engaged=1.0, misfit=0.008, sensitivity=22.0,
                                      noise_Nm=20.0, halves=(0.404, 0.419), twist_noise=0.021,
                                      halves_twist_noise=(0.024, 0.024), swing_ratio=0.85)
    assert creep_checks.halves_noise(seed_8) == pytest.approx(0.070, abs=0.002)
    problems = creep_checks.problems(0.412, seed_8)
    assert len(problems) == 1
    assert "halves cannot be compared: noise ±7.0 % (2σ) at this rate > 6 %" in problems[0]
    assert creep_checks.problems(0.412, replace(seed_8, halves_twist_noise=(0.01, 0.01))) == []


def _model_whose_sticking_needs(ratio_mu_k: dict):
    """A stand-in for the batch model: fit_mean_torque answers, per provisional μ_s/μ_k
    ratio, the root μ_k and whether the model then sticks (``ratio_mu_k``: ratio → (μ_k,
    sticks))."""
    from types import SimpleNamespace

    grid = SimpleNamespace(rho_j_kg_m=np.ones(10), dx_true_m=np.ones(10))
    model = SimpleNamespace(data=SimpleNamespace(w_bar=np.full(100, 6.0)), k_t=0.0,
                            grid=lambda cells: (grid, None),
                            t_parts=lambda cells: (1e5, 0.0),
                            settings=SimpleNamespace(mu_max=1.5))

    def fit(model, wins, target, mu_s_of, x0, cells):
        ratio = round(mu_s_of(1.0), 6)
        mu_k, sticks = ratio_mu_k[ratio]
        return kinetic.MeanTorqueFit(mu_k, 0.0, [(mu_k, 0.0)], sticks)
    return model, fit


@pytest.mark.parametrize(("at_4", "flagged"), [(0.150, False), (0.125, True)])
def test_mu_k_that_moves_with_the_assumed_mu_s_is_not_converged(at_4, flagged, monkeypatch):
    """Issue 33: when the model stick-slips only at μ_s = 4 μ_k, not 2.5 μ_k, the μ_k of the
    two differ; more than 5 % apart, the unidentified μ_s sets μ_k: not converged
    (mu_k_depends_on_mu_s, in the verdict's NOT_CONVERGED)."""
    from types import SimpleNamespace

    from drillfric.estimation.verdict import NOT_CONVERGED
    from drillfric.result import Flag

    model, fit = _model_whose_sticking_needs({2.5: (0.155, False), 4.0: (at_4, True)})
    monkeypatch.setattr(kinetic, "fit_mean_torque", fit)
    wins = [SimpleNamespace(used=np.arange(10, 100))]
    out = kinetic.fit_kinetic(model, wins, 15e3, True, None, 100)
    assert out.mu_k == at_4
    assert (Flag.MU_K_DEPENDS_ON_MU_S in out.flags) is flagged
    assert Flag.MU_K_DEPENDS_ON_MU_S in NOT_CONVERGED
