"""Numba kernel vs its plain-NumPy twin (drillfric.kernels.plant vs drillfric.kernels.plant_numpy).

Both implement docs/theory.md §3.1 and the friction profile and laws of docs/theory.md §3.2 with
the same operations in the same order (no fastmath), so they must agree to round-off; 10 000
steps of stick-slip (the most sensitive regime: a cell that sticks in one run and not in the
other would show at once) with every boundary type. Measured: bit-identical.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from drillfric import torsional as T
from drillfric.drillstring import DrillString, Section
from drillfric.kernels import plant as kernels
from drillfric.kernels import plant_numpy as kernels_numpy
from drillfric.sim.well_b import well_b_plant

RPM = np.pi / 30.0


def _both(plant, drive, n_steps, rate_hz, state=None):
    out = {}
    for backend in ("numba", "numpy"):
        out[backend] = T.run(plant, drive, n_steps * plant.grid.dt_s, rate_hz, state,
                             backend=backend)
    return out["numba"], out["numpy"]


def _assert_same(a, b):
    (ra, sa), (rb, sb) = a, b
    for name in T.RECORD_COLUMNS:
        x, y = getattr(ra, name), getattr(rb, name)
        scale = max(1.0, float(np.abs(y).max()))
        np.testing.assert_allclose(x, y, rtol=0, atol=1e-12 * scale, err_msg=name)
    np.testing.assert_allclose(sa.alpha, sb.alpha, rtol=0, atol=1e-12)
    np.testing.assert_allclose(sa.beta, sb.beta, rtol=0, atol=1e-12)
    np.testing.assert_allclose(sa.top, sb.top, rtol=1e-12)


@pytest.fixture(scope="module")
def plant():
    """Well B at 200 cells with damping, in stick-slip, and a Coulomb bit on bottom."""
    p = well_b_plant(cells=200, k_t_per_s=0.2)
    return T.Plant(p.grid, p.fc_Nm_m, p.mu_s, p.mu_k, p.omega_c_rad_s, p.k_t_per_s,
                   p.top_drive_inertia_kg_m2, bit_torque_cap_Nm=1500.0)


def test_pi_drive_agrees_over_10000_steps(plant):
    drive = T.Drive("pi", np.array([0.0, 40 * RPM, 40 * RPM, 10 * RPM]), 5.0)
    _assert_same(*_both(plant, drive, 10_000, 50.0))


def test_torque_drive_agrees_from_a_twisted_state(plant):
    rng = np.random.default_rng(7)
    n = plant.grid.n_cells
    state = T.State(rng.normal(0, 2, n), rng.normal(0, 2, n), np.array([1.0, 0.0]), 3.0)
    drive = T.Drive("torque", np.array([0.0, 40e3, 20e3]), 4.0, 3.0)
    _assert_same(*_both(plant, drive, 10_000, 37.0, state))


def test_speed_drive_agrees(plant):
    t = np.arange(0, 30, 0.1)
    drive = T.Drive("speed", 4.0 * np.minimum(t / 5, 1.0) + 0.5 * np.sin(t), 0.1)
    _assert_same(*_both(plant, drive, 10_000, 100.0))


def test_fed_drive_agrees(plant):
    t = np.arange(0, 30, 0.1)
    drive = T.Drive("fed", np.vstack([20e3 + 5e3 * np.sin(t), 4.0 + 0.5 * np.sin(0.7 * t)]),
                    0.1, kp_Nms_rad=900.0, ki_Nm_rad=2500.0)
    _assert_same(*_both(plant, drive, 10_000, 100.0))


def test_one_cell_sections_agree():
    """Sections of a single cell take the special path of section_cells."""
    secs = tuple(Section(f"s{i}", od, 0.05, length, od / 2, 60.0, 70e9)
                 for i, (od, length) in enumerate([(0.15, 300.0), (0.2, 3.0), (0.25, 3.2),
                                                   (0.18, 40.0)]))
    g = T.make_grid(DrillString(secs), 60)
    assert 1 in np.diff(g.section_start)
    p = T.Plant(g, np.full(g.n_cells, 30.0), 0.5, 0.3, 1.0, 0.1)
    drive = T.Drive("pi", np.array([0.0, 5.0]), 2.0)
    _assert_same(*_both(p, drive, 3_000, 200.0))


def test_drive_value_interpolates_and_holds():
    u = np.array([1.0, 3.0, 2.0])
    for f in (kernels.drive_value, kernels_numpy.drive_value):
        assert f(u, 1.0, 0.5, 0.0) == 1.0
        assert f(u, 1.0, 0.5, 1.25) == pytest.approx(2.0)
        assert f(u, 1.0, 0.5, 1.75) == pytest.approx(2.5)
        assert f(u, 1.0, 0.5, 9.0) == 2.0


def test_records_interpolate_linearly_between_steps():
    """Samples between two model steps are the linear interpolation of the step values."""
    g = T.make_grid(DrillString((Section("a", 0.15, 0.12, 1000.0, 0.075, 40.0, 79e9),)), 50)
    p = T.Plant(g, np.zeros(g.n_cells), 0.0, 0.0, 1.0)
    ramp = T.Drive("speed", np.array([0.0, 10.0]), 1.0)
    rec, _ = T.run(p, ramp, 0.5, 1000.0)
    np.testing.assert_allclose(rec.surface_rad_s, 10.0 * rec.time_s, atol=1e-12)


#: Friction laws of docs/theory.md §3.2: the step law, and Stribeck with the kernel's two
#: vectorised exponents and a general one (a C-library pow per cell, as in the twin).
LAWS = {"step": {}, "stribeck-1": {"stribeck_speed_rad_s": 0.8},
        "stribeck-2": {"stribeck_speed_rad_s": 0.8, "stribeck_exponent": 2.0},
        "stribeck-1.5": {"stribeck_speed_rad_s": 0.8, "stribeck_exponent": 1.5}}


def cased_open(plant, shoe_m=1600.0, mu_s_cased=0.35, mu_k_cased=0.25, **law):
    """``plant`` with the friction above ``shoe_m`` moved into the fixed part of the profile
    (a cased hole of known factors) and the friction law ``law`` (docs/theory.md §3.2)."""
    cased = plant.grid.x_m < shoe_m
    fc = plant.fc_Nm_m
    return dataclasses.replace(plant, fc_Nm_m=np.where(cased, 0.0, fc),
                               fc_fixed_k_Nm_m=np.where(cased, mu_k_cased * fc, 0.0),
                               fc_fixed_s_Nm_m=np.where(cased, mu_s_cased * fc, 0.0), **law)


@pytest.mark.parametrize("law", LAWS)
def test_profile_and_friction_laws_agree_with_twin(law):
    """Well B with a cased zone above 1600 m (fixed part) and each friction law, in
    stick-slip at 40 RPM (bit stuck 70 % of the time, peaks ~20 rad/s): kernel and twin
    agree to round-off over 10 000 steps (tolerance 1e-12 of each record's scale, as
    above; measured bit-identical)."""
    plant = cased_open(well_b_plant(cells=200, k_t_per_s=0.2), **LAWS[law])
    assert plant.T_fixed_k_Nm > 0.1 * plant.mu_k * plant.T_N_Nm
    drive = T.Drive("pi", np.array([0.0, 40 * RPM]), 5.0)
    fast, slow = _both(plant, drive, 10_000, 50.0)
    _assert_same(fast, slow)
    bit = fast[0].bit_rad_s
    assert np.mean(np.abs(bit) < 0.05) > 0.2 and bit.max() > 2 * 40 * RPM


def test_rate_weakening_bit_agrees_with_twin(plant):
    """The rate-weakening bit (docs/theory.md §3, bit; r = 3, ω_b = 1 rad/s on the 1500-N·m
    bit of the fixture) with the step law along the string at 60 RPM, in bit stick-slip:
    kernel and twin agree to round-off over 10 000 steps, the bit torque record included
    (tolerance as above; measured bit-identical)."""
    weak = dataclasses.replace(plant, bit_weakening_ratio=3.0, bit_weakening_speed_rad_s=1.0)
    drive = T.Drive("pi", np.array([0.0, 60 * RPM]), 5.0)
    fast, slow = _both(weak, drive, 10_000, 50.0)
    _assert_same(fast, slow)
    rec = fast[0]
    assert rec.bit_torque_Nm.max() > 2.0 * 1500.0  # it held above T_k at rest
    assert np.mean(np.abs(rec.bit_rad_s) < 0.05) > 0.05


@pytest.mark.parametrize("law", LAWS)
def test_zero_fixed_part_is_bit_identical(law):
    """docs/theory.md §3.2: with zero fixed arrays the caps are μ·fcap exactly, so the kernel
    variant with a fixed part gives the same bits as the one without — which performs the
    operations of the kernel before the profile existed (step law: μ selected by |ω^k| ≤ ω_c,
    times fcap), so today's results are unchanged bit for bit."""
    plant = dataclasses.replace(well_b_plant(cells=200, k_t_per_s=0.2), **LAWS[law])
    drive = T.Drive("pi", np.array([0.0, 40 * RPM]), 5.0)
    args = T.kernel_args(plant, drive)
    code = kernels.law_code(plant.law_speed_rad_s, float(plant.stribeck_exponent))
    assert kernels.variant(plant.law_speed_rad_s, plant.stribeck_exponent, args[4],
                           args[5]) == (code, False)
    outputs = []
    no_axial = kernels.axial_args(None, plant.grid.n_cells)[0]
    for kernel, extra in ((kernels.run_plant, ()), (kernels.plant_kernel(code, True), no_axial)):
        state = T.State.rest(plant.grid)
        times = np.linspace(0.0, 3000 * plant.grid.dt_s, 301)
        out = np.empty((times.size, len(T.RECORD_COLUMNS)))
        kernel(state.alpha, state.beta, state.top, 0.0, 3000, *args, times, out, *extra)
        outputs.append((out, state.alpha, state.beta))
    for x, y in zip(*outputs, strict=True):
        np.testing.assert_array_equal(x, y)


def test_exp_neg_matches_the_exponential():
    """The vectorisable e^−x of the Stribeck law: within 4e-16 relative of the C library's
    exp on [0, 40] (degree-13 Taylor after Cody–Waite reduction, truncation < 1e-17), and
    the twin's copy gives the same bits."""
    x = np.concatenate([np.linspace(0.0, 40.0, 20001), np.geomspace(1e-12, 1.0, 2000)])
    want = np.exp(-x)
    fast = np.array([kernels.exp_neg(v) for v in x])
    np.testing.assert_allclose(fast, want, rtol=4e-16, atol=0)
    np.testing.assert_array_equal(kernels_numpy.exp_neg(x), fast)
    assert kernels.exp_neg(1e3) == pytest.approx(np.exp(-40.0), rel=4e-16)


def _axial(plant):
    """``plant`` with the contact radius of Well B's string at its cells (docs/theory.md
    §3.3)."""
    from drillfric.sim.well_b import well_b_string

    return dataclasses.replace(plant, contact_radius_m=T.contact_radius(well_b_string(),
                                                                        plant.grid))


@pytest.mark.parametrize("law", ["step", "stribeck-1", "stribeck-1.5"])
def test_axial_motion_agrees_with_twin(law):
    """docs/theory.md §3.3: Well B (cased zone above 1600 m as a fixed part) in stick-slip at
    40 RPM, the pipe then moving at 0.03 m/s (inside the static band ω_c·r_c = 0.066 m/s:
    cells still stick), −0.3 m/s (pulling out, no cell can stick), back to rest and running
    in at 0.1 m/s: kernel and twin agree to round-off over 10 000 steps (tolerance as the
    tests above; measured bit-identical — the same operations, np.sqrt and numba's sqrt both
    correctly rounded)."""
    plant = _axial(cased_open(well_b_plant(cells=200, k_t_per_s=0.2), **LAWS[law]))
    drive = T.Drive("pi", np.array([0.0, 40 * RPM]), 5.0)
    axial = T.Axial(np.array([0.0, 0.0, 0.03, 0.03, -0.3, -0.3, 0.0, 0.0, 0.1]), 4.0)
    out = [T.run(plant, drive, 10_000 * plant.grid.dt_s, 50.0, backend=backend, axial=axial)
           for backend in ("numba", "numpy")]
    _assert_same(*out)
    pulling = out[0][0].time_s > 20.0
    assert np.ptp(out[0][0].bit_rad_s[~pulling]) > 40 * RPM  # it oscillated strongly first


@pytest.mark.parametrize("law", ["step", "stribeck-1"])
def test_axial_kernel_at_zero_speed_is_bit_identical(law):
    """docs/theory.md §3.3: v = 0 is today's plant bit for bit. The axial variant of the
    kernel, run with v = 0 throughout, takes every step through :func:`pass_cells` and gives
    the same bits as the kernel without axial motion (which :func:`run_plant` runs when there
    is no axial series or it is zero) — in stick-slip, where one differing cell would show."""
    plant = _axial(dataclasses.replace(well_b_plant(cells=200, k_t_per_s=0.2), **LAWS[law]))
    drive = T.Drive("pi", np.array([0.0, 40 * RPM]), 5.0)
    args = T.kernel_args(plant, drive)
    code = kernels.law_code(plant.law_speed_rad_s, float(plant.stribeck_exponent))
    zero = (np.zeros(4), 0.0, 1.0, 1.0 / plant.contact_radius_m)
    runs = ((kernels.run_plant, {}), (kernels.run_plant, {"axial": zero}),
            (kernels.plant_kernel(code, False, True), None))
    outputs = []
    for kernel, kw in runs:
        state = T.State.rest(plant.grid)
        times = np.linspace(0.0, 3000 * plant.grid.dt_s, 301)
        out = np.empty((times.size, len(T.RECORD_COLUMNS)))
        extra = zero if kw is None else ()
        kernel(state.alpha, state.beta, state.top, 0.0, 3000, *args, times, out, *extra,
               **(kw or {}))
        outputs.append((out, state.alpha, state.beta))
    for other in outputs[1:]:
        for x, y in zip(outputs[0], other, strict=True):
            np.testing.assert_array_equal(x, y)


def test_axial_cell_rule_bounds_and_matches_twin():
    """docs/theory.md eq. (3.3c), the friction one cell loses in a step while the pipe moves,
    over 20 000 random cells (speeds ±20 rad/s, u = |v|/r_c 0–8 rad/s, caps 0–2 rad/s, step
    and Stribeck laws): never more than the cap (Coulomb bound), never past rest (|d| ≤
    |ω**|, same sign), held only inside the static band (step law), exact in steady
    sliding (ω^k = ω^{k+1} ⇒ d = cap·ω/s); the compiled cell and the twin give the same
    bits. The bounds hold to the round-off of forming d back from ω** − d (1e-14·|ω**|)."""
    rng = np.random.default_rng(36)
    n = 20_000
    w_old = rng.uniform(-20, 20, n) * (rng.random(n) > 0.2)
    w = w_old + rng.normal(0, 3, n) * (rng.random(n) > 0.5)
    u, fcap = rng.uniform(0, 8, n) * (rng.random(n) > 0.1), rng.uniform(0, 2, n)
    for law, inv_vs in ((kernels.LAW_STEP, 0.0), (kernels.LAW_STRIBECK_1, 1.0 / 0.8)):
        twin_a, twin_b = np.zeros(n), np.zeros(n)
        kernels_numpy.damp_and_friction_axial(w_old, w_old, twin_a, twin_b, np.zeros(n),
                                              np.zeros(n), 0.0, fcap, np.zeros(n),
                                              np.zeros(n), 0.6, 0.3, 1.0, inv_vs, 1.0, law, u)
        twin_a[:], twin_b[:] = w, w  # same call with ω** = w: α* = β* = w
        kernels_numpy.damp_and_friction_axial(w_old, w_old, twin_a, twin_b, np.zeros(n),
                                              np.zeros(n), 0.0, fcap, np.zeros(n),
                                              np.zeros(n), 0.6, 0.3, 1.0, inv_vs, 1.0, law, u)
        d = w - twin_a
        compiled = np.array([kernels.cell_update_axial(w[j], w[j], 0.0, 0.0, w_old[j], 0.0,
                                                       fcap[j], 0.0, 0.0, 0.6, 0.3, 1.0,
                                                       inv_vs, 1.0, law, False, u[j])[0]
                             for j in range(n)])
        np.testing.assert_array_equal(compiled, twin_a)
        s = np.sqrt(w_old * w_old + u * u)
        cap = np.where(s <= 1.0, 0.6, 0.3) * fcap if law == kernels.LAW_STEP else \
            (0.3 + 0.3 * np.exp(-s * inv_vs)) * fcap
        slack = 1e-14 * np.abs(w)  # d = ω** − (ω** − d) re-rounds at the scale of ω**
        assert np.all(np.abs(d) <= cap + slack)
        assert np.all(np.abs(d) <= np.abs(w) + slack) and np.all(d * w >= -slack * cap)
        if law == kernels.LAW_STEP:
            sliding = s > 1.0
            steady_w = w_old + cap * w_old / np.where(sliding, s, 1.0)  # ends it at ω^k
            twin_a[:], twin_b[:] = steady_w, steady_w
            kernels_numpy.damp_and_friction_axial(w_old, w_old, twin_a, twin_b,
                                                  np.zeros(n), np.zeros(n), 0.0, fcap,
                                                  np.zeros(n), np.zeros(n), 0.6, 0.3, 1.0,
                                                  0.0, 1.0, law, u)
            np.testing.assert_allclose(twin_a[sliding], w_old[sliding], rtol=1e-12,
                                       atol=1e-12)
