"""Numba kernel vs its plain-NumPy twin (drillfric.kernels.plant vs drillfric.kernels.plant_numpy).

Both implement THEORY.md §3.1 with the same operations in the same order, so they must agree
to round-off; 10 000 steps of stick-slip (the most sensitive regime: a cell that sticks in
one run and not in the other would show at once) with every boundary type.
"""

from __future__ import annotations

import numpy as np
import pytest

from drillfric import torsional as T
from drillfric.drillstring import DrillString, Section
from drillfric.kernels import plant as kernels
from drillfric.kernels import plant_numpy as kernels_numpy
from drillfric.simulator import well_b_plant

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
