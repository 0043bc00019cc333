"""Minimum-curvature well path (docs/theory.md §1; Sawaryn & Thorogood 2005, SPE-84246-PA).

Analytic geometry is the oracle: a straight line, a circular arc and the ratio-factor
Taylor series. Tolerances are float64 round-off scaled by the lengths involved (1e-9 m on
paths of a few km) unless stated otherwise.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from drillfric.errors import InputError
from drillfric.wellpath import (
    TORTUOUS_PERIOD_M,
    TORTUOUS_STATION_M,
    dogleg,
    minimum_curvature,
    no_survey_path,
    ratio_factor,
    tortuous_vertical,
    unit_tangent,
    vertical,
)

DEG = np.pi / 180.0
depth = st.floats(1.0, 5000.0)
incl = st.floats(0.0, np.pi)
azim = st.floats(0.0, 2 * np.pi)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(0.5, 500.0), min_size=1, max_size=20), azim)
def test_vertical_survey_tvd_equals_md(steps, azi):
    """Vertical stations (any azimuth): TVD = MD and no horizontal displacement, exactly."""
    md = np.concatenate([[0.0], np.cumsum(steps)])
    path = minimum_curvature(md, np.zeros_like(md), np.full_like(md, azi))
    np.testing.assert_allclose(path.tvd_m, md, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(np.hypot(path.north_m, path.east_m), 0.0, atol=1e-9)
    np.testing.assert_allclose(path.dogleg_rad, 0.0, atol=1e-12)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(0.5, 500.0), min_size=1, max_size=20), incl, azim)
def test_straight_slant(steps, inc, azi):
    """Constant I, A from MD 0: TVD = MD·cos I, horizontal displacement = MD·sin I along A."""
    md = np.concatenate([[0.0], np.cumsum(steps)])
    path = minimum_curvature(md, np.full_like(md, inc), np.full_like(md, azi), tie_in=(0, 0, 0))
    np.testing.assert_allclose(path.tvd_m, md * np.cos(inc), atol=1e-9 * md[-1] + 1e-12)
    np.testing.assert_allclose(path.north_m, md * np.sin(inc) * np.cos(azi), atol=1e-9 * md[-1])
    np.testing.assert_allclose(path.east_m, md * np.sin(inc) * np.sin(azi), atol=1e-9 * md[-1])
    # between stations too
    mid = 0.5 * (md[:-1] + md[1:])
    np.testing.assert_allclose(path.at(mid)["tvd_m"], mid * np.cos(inc), atol=1e-9 * md[-1])


def _arc_centre(p1, t1, t2, ds, beta):
    """Centre of the circle through p1 tangent to t1, turning towards t2 (radius ds/β)."""
    normal = t2 - np.dot(t1, t2) * t1
    return p1 + ds / beta * normal / np.linalg.norm(normal)


@settings(max_examples=80, deadline=None)
@given(depth, st.floats(1.0, 300.0), incl, azim, incl, azim,
       st.lists(st.floats(0.0, 1.0), min_size=1, max_size=10))
def test_interpolated_points_lie_on_the_arc(md1, ds, i1, a1, i2, a2, fracs):
    """Points between two stations are on the circle of radius Δs/β (distance to centre)
    and their tangents are the circle's (perpendicular to the radius)."""
    t1, t2 = unit_tangent(i1, a1), unit_tangent(i2, a2)
    beta = float(dogleg(t1, t2))
    assume(1e-3 < beta < np.pi - 0.05)  # straight or (near-)reversing: no unique circle
    path = minimum_curvature([md1, md1 + ds], [i1, i2], [a1, a2], tie_in=(md1, 0.0, 0.0))
    p1 = np.array([0.0, 0.0, md1])
    centre = _arc_centre(p1, t1, t2, ds, beta)
    md = md1 + ds * np.asarray(fracs)
    pos = path.position(md)
    radius = ds / beta
    np.testing.assert_allclose(np.linalg.norm(pos - centre, axis=1), radius,
                               rtol=1e-9, atol=1e-9)
    along = np.einsum("ij,ij->i", path.tangent(md), pos - centre)
    np.testing.assert_allclose(along, 0.0, atol=1e-8 * radius)
    # arc length: chord subtending fβ is 2R sin(fβ/2)
    chord = np.linalg.norm(pos - p1, axis=1)
    np.testing.assert_allclose(chord, 2 * radius * np.sin(np.asarray(fracs) * beta / 2),
                               rtol=1e-9, atol=1e-9)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(1.0, 200.0), st.floats(0.0, 179.0),
                          st.floats(0.0, 359.99)), min_size=2, max_size=15))
def test_at_station_depths_reproduces_stations(rows):
    """`.at()` at the station depths returns the stations' own angles and positions."""
    steps, inc_deg, azi_deg = map(np.array, zip(*rows, strict=True))
    md = np.cumsum(steps)
    inc, azi = inc_deg * DEG, azi_deg * DEG
    t = unit_tangent(inc, azi)
    assume(np.all(dogleg(t[:-1], t[1:]) < np.pi - 0.05))  # near-reversal: RF blows up
    path = minimum_curvature(md, inc, azi)
    got = path.at(md)
    own = slice(path.md_m.size - md.size, None)  # a surface station may be prepended
    np.testing.assert_allclose(path.md_m[own], md)
    np.testing.assert_allclose(got["tvd_m"], path.tvd_m[own], atol=1e-9 * md[-1])
    np.testing.assert_allclose(got["north_m"], path.north_m[own], atol=1e-9 * md[-1])
    np.testing.assert_allclose(got["east_m"], path.east_m[own], atol=1e-9 * md[-1])
    np.testing.assert_allclose(path.tangent(md), t, atol=1e-12)
    np.testing.assert_allclose(got["inc_rad"], inc, atol=1e-9)
    # azimuth is undefined on vertical stations; compare on the unit circle elsewhere
    tilted = inc_deg > 0.01
    np.testing.assert_allclose(np.exp(1j * got["azi_rad"][tilted]), np.exp(1j * azi[tilted]),
                               atol=1e-7)


@pytest.mark.parametrize("inc_deg", [3.0, 45.0, 90.0])
def test_azimuth_wrap_gives_small_dogleg(inc_deg):
    """359° → 1° at constant inclination I is a 2° azimuth change: β = 2·asin(sin I·sin 1°)
    (spherical geometry; β = 2° at I = 90°), never ~358°."""
    t1 = unit_tangent(inc_deg * DEG, 359.0 * DEG)
    t2 = unit_tangent(inc_deg * DEG, 1.0 * DEG)
    expected = 2 * np.arcsin(np.sin(inc_deg * DEG) * np.sin(1.0 * DEG))
    assert float(dogleg(t1, t2)) == pytest.approx(expected, rel=1e-12)
    path = minimum_curvature([0.0, 30.0], [inc_deg * DEG] * 2, [359.0 * DEG, 1.0 * DEG])
    assert path.dls_rad_m[0] * 30.0 == pytest.approx(expected, rel=1e-12)
    mid = path.at([15.0])["azi_rad"][0]  # the arc passes through north, not south
    assert min(mid, 2 * np.pi - mid) == pytest.approx(0.0, abs=1e-9)


@settings(max_examples=200, deadline=None)
@given(st.floats(1e-9, 1e-3))
def test_ratio_factor_series_is_continuous(beta):
    """RF switches to 1 + β²/12 + β⁴/120 below 1e-4 rad; the two forms must agree there.

    Series truncation error is O(β⁶) ≈ 1e-24 at the switch; the closed form (2/β)tan(β/2)
    is accurate to a few ulp. Relative 1e-14 covers both."""
    closed = 2.0 / beta * np.tan(beta / 2.0)
    assert float(ratio_factor(np.array(beta))) == pytest.approx(closed, rel=1e-14)


def test_ratio_factor_is_continuous_across_the_switch():
    """Just below and just above 1e-4 rad the values differ by the slope only."""
    below, above = ratio_factor(np.array([1e-4 * (1 - 1e-12), 1e-4 * (1 + 1e-12)]))
    assert abs(above - below) < 1e-15


def test_quarter_circle_build():
    """A 90° build over Δs: radius R = 2Δs/π, ΔTVD = ΔN = R (closed-form arc)."""
    ds = 300.0
    path = minimum_curvature([1000.0, 1000.0 + ds], [0.0, np.pi / 2], [0.0, 0.0],
                             tie_in=(1000.0, 0.0, 0.0))
    radius = 2 * ds / np.pi
    assert path.tvd_m[-1] - 1000.0 == pytest.approx(radius, rel=1e-12)
    assert path.north_m[-1] == pytest.approx(radius, rel=1e-12)
    assert path.east_m[-1] == pytest.approx(0.0, abs=1e-9)
    assert np.degrees(path.dls_rad_m[0]) * 30 == pytest.approx(90 * 30 / ds, rel=1e-12)
    half = path.at([1000.0 + ds / 2])
    assert half["inc_rad"][0] == pytest.approx(np.pi / 4, rel=1e-12)
    assert half["tvd_m"][0] - 1000.0 == pytest.approx(radius * np.sin(np.pi / 4), rel=1e-12)


def test_vertical_helper():
    path = vertical(2500.0)
    assert path.md_max_m == 2500.0
    np.testing.assert_allclose(path.at([0.0, 1234.5, 2500.0])["tvd_m"], [0.0, 1234.5, 2500.0])


@settings(max_examples=40, deadline=None)
@given(st.floats(5.0, 6000.0), st.floats(0.001, 10.0))
def test_tortuous_vertical_has_the_tortuosity_everywhere(depth_m, dls_deg_30m):
    """The path assumed without a survey: every minimum-curvature interval has DLS = the
    tortuosity, at one constant inclination, the azimuth turning 2π per period (derivation
    in the docstring). rtol 1e-9: the dogleg is recomputed from unit tangents by §1's atan2
    form, whose round-off (~1e-16 absolute) is below 1e-10 of the smallest dogleg here."""
    kappa = dls_deg_30m * DEG / 30.0
    path = tortuous_vertical(depth_m, kappa)
    assert depth_m <= path.md_max_m < depth_m + TORTUOUS_STATION_M
    np.testing.assert_allclose(path.dls_rad_m, kappa, rtol=1e-9)
    np.testing.assert_allclose(path.inc_rad, path.inc_rad[0], rtol=1e-12)
    turn = np.unwrap(path.azi_rad)
    np.testing.assert_allclose(turn - turn[0], 2 * np.pi * path.md_m / TORTUOUS_PERIOD_M,
                               rtol=1e-12, atol=1e-12)


def test_tortuous_vertical_is_a_helix():
    """The chain of 10 m arcs is the minimum-curvature version of the helix of curvature
    κ = (2π/P)·sin I. Its inclination is the helix's up to the station-spacing correction
    sin I = sin(κh/2)/sin(πh/P) = (κP/2π)·(1 + (πh/P)²/6 + …) (1e-5: the next term is
    ~1e-6). Each interval moves h·RF·sin I·cos(ΔA/2) horizontally, turning ΔA, and
    h·RF·cos I down (§1 displacement; RF the ratio factor): the plan is a regular polygon
    whose farthest station is one circumscribed diameter from the surface, and TVD =
    MD·RF·cos I (both 1e-9: float round-off over a few thousand metres)."""
    kappa = 1.0 * DEG / 30.0
    path = tortuous_vertical(3000.0, kappa)
    h, period = TORTUOUS_STATION_M, TORTUOUS_PERIOD_M
    x = np.pi * h / period  # ΔA/2
    sin_i, rf = np.sin(path.inc_rad[0]), ratio_factor(kappa * h)
    assert sin_i == pytest.approx(kappa * period / (2 * np.pi) * (1 + x**2 / 6), rel=1e-5)
    side = h * rf * sin_i * np.cos(x)
    assert np.hypot(path.north_m, path.east_m).max() == pytest.approx(side / np.sin(x),
                                                                      rel=1e-9)
    np.testing.assert_allclose(path.tvd_m, path.md_m * rf * np.cos(path.inc_rad[0]),
                               rtol=1e-9, atol=1e-9)


def test_no_survey_path_zero_tortuosity_is_exactly_vertical():
    """Tortuosity 0 restores the exactly vertical path (no side force, docs/theory.md §2)."""
    zero, plain = no_survey_path(2345.0, 0.0), vertical(2345.0)
    for name in ("md_m", "inc_rad", "azi_rad", "tvd_m", "north_m", "east_m", "dogleg_rad"):
        np.testing.assert_array_equal(getattr(zero, name), getattr(plain, name))
    tortuous = no_survey_path(2345.0, 1.0 * DEG / 30.0)
    assert tortuous.dls_rad_m.min() > 0


@pytest.mark.parametrize("args", [(0.0, 1e-3), (100.0, 0.0), (100.0, -1e-3), (100.0, 0.05)])
def test_tortuous_vertical_bad_arguments(args):
    """Non-positive inputs, or a curvature no helix of the period can have (sin I > 1)."""
    with pytest.raises(ValueError):
        tortuous_vertical(*args)


@pytest.mark.parametrize("md, inc, problem", [
    ([0.0, 10.0, 10.0], [0.0, 0.0, 0.0], "not increasing"),
    ([0.0, 10.0], [0.0, 3.5], "inclination outside"),
    ([0.0, np.nan], [0.0, 0.0], "missing values"),
])
def test_bad_stations_are_input_errors(md, inc, problem):
    with pytest.raises(InputError, match=problem):
        minimum_curvature(md, inc, np.zeros(len(md)))


def test_depth_outside_survey_is_an_input_error():
    with pytest.raises(InputError, match="outside the survey"):
        vertical(100.0).at([150.0])


def test_single_station_path():
    """A lone station (tie-in only) is a valid path at its own depth and nowhere else."""
    path = minimum_curvature([500.0], [0.3], [1.0], tie_in=(499.0, 2.0, 3.0))
    got = path.at([500.0])
    assert (got["north_m"][0], got["east_m"][0], got["tvd_m"][0]) == (2.0, 3.0, 499.0)
    assert got["inc_rad"][0] == pytest.approx(0.3, rel=1e-12)
    with pytest.raises(InputError, match="outside the survey"):
        path.position([501.0])


def test_survey_starting_below_surface_is_one_path():
    """Without a tie-in, a survey starting below MD 0 gets a vertical surface station, so
    positions and tangents (used by torque and drag) describe the same arc above it."""
    path = minimum_curvature([300.0, 1000.0], np.radians([30.0, 30.0]), [0.0, 0.0])
    assert path.md_m[0] == 0.0 and path.inc_rad[0] == 0.0
    mid = path.at([150.0])
    assert 0.0 < mid["inc_rad"][0] < np.radians(30.0)  # on the arc, not at 30°
    chord = np.hypot(path.tvd_m[1], path.north_m[1])
    assert chord < 300.0 and path.tvd_m[1] < 300.0


def test_reversal_has_no_unique_arc():
    """A 180° dogleg has no unique minimum-curvature plane: an input error, not a guess."""
    with pytest.raises(InputError, match="dogleg 180°"):
        minimum_curvature([0.0, 100.0], np.radians([90.0, 90.0]), np.radians([0.0, 180.0]))
