"""Drill-string description (drillfric.drillstring): per-position properties, resolution."""

from __future__ import annotations

import numpy as np
import pytest

from drillfric.config import DEFAULT_SECTIONS, load_config
from drillfric.drillstring import G_ACCEL, DrillString, Section, build_string
from drillfric.errors import ModelError


def test_section_properties_closed_forms():
    """docs/theory.md §3: J = π(OD⁴ − ID⁴)/32, c = √(G/ρ), ζ = J√(Gρ); §2: A_o, A_i. Exact
    formulas."""
    s = Section("dp", 0.146529, 0.123024, 100.0, 0.0889, 41.41, shear_modulus_Pa=61e9)
    assert s.polar_moment_m4 == pytest.approx(np.pi * (0.146529**4 - 0.123024**4) / 32,
                                              rel=1e-15)
    # docs/reference_cases.md: A&S 2018 drill pipe, c ≈ 2788 m/s (G = 61 GPa, ρ = 7850 kg/m³)
    assert s.wave_speed_m_s == pytest.approx(2788.0, abs=0.5)
    assert s.impedance_Nms == pytest.approx(s.polar_moment_m4 * np.sqrt(61e9 * 7850.0),
                                            rel=1e-15)
    assert s.steel_area_m2 == pytest.approx(s.outer_area_m2 - s.inner_area_m2)
    assert s.air_weight_N_m == pytest.approx(41.41 * G_ACCEL)


def test_buoyed_weight_inside_outside_mud():
    """docs/theory.md §2 step 1: w = g[m − ρ_o A_o + ρ_i A_i]; one mud and steel mass: w(1 −
    ρ/ρ_s)."""
    od, id_ = 0.127, 0.1086
    steel = 7850.0 * np.pi * (od**2 - id_**2) / 4
    s = Section("dp", od, id_, 10.0, od / 2, steel)
    assert s.buoyed_weight_N_m(1300.0, 1300.0) == pytest.approx(
        s.air_weight_N_m * (1 - 1300.0 / 7850.0), rel=1e-13)
    assert s.buoyed_weight_N_m(1300.0, 0.0) == pytest.approx(
        G_ACCEL * (steel - 1300.0 * np.pi * od**2 / 4), rel=1e-13)


def test_build_string_fills_top_section_and_reports_positions():
    cfg = load_config()
    string = build_string(cfg.sections, 3000.0)
    lower = sum(e["length_m"] for e in DEFAULT_SECTIONS[1:])
    assert string.bit_depth_m == pytest.approx(3000.0)
    assert string.bha_top_m == pytest.approx(3000.0 - lower)
    np.testing.assert_allclose(string.boundaries_m, [0.0, 3000.0 - lower, 3000.0 - 120.0,
                                                     3000.0])
    # per-position arrays: contact radius is the tool joint for pipe, the body for collars
    rc = string.along("contact_radius_m", [10.0, 2800.0, 2999.0])
    np.testing.assert_allclose(rc, [0.1778 / 2, 0.1651 / 2, 0.2032 / 2])
    w = string.buoyed_weight_N_m([10.0, 2999.0], 1200.0, 1200.0)
    assert w[0] == pytest.approx(string.sections[0].buoyed_weight_N_m(1200.0, 1200.0))
    assert w[1] == pytest.approx(string.sections[2].buoyed_weight_N_m(1200.0, 1200.0))
    expected = sum(s.steel_density_kg_m3 * s.polar_moment_m4 * s.length_m
                   for s in string.sections[1:])
    assert string.bha_inertia_kg_m2 == pytest.approx(expected)


def test_default_mass_from_steel_area():
    cfg = load_config()
    collar = build_string(cfg.sections, 1000.0).sections[-1]
    assert collar.linear_mass_kg_m == pytest.approx(7850.0 * collar.steel_area_m2)
    assert collar.contact_radius_m == pytest.approx(collar.od_m / 2)


def test_bad_strings():
    cfg = load_config()
    with pytest.raises(ModelError, match="the bit is at 200.0 m"):
        build_string(cfg.sections, 200.0)
    with pytest.raises(ModelError, match="positive"):
        build_string(cfg.sections, -5.0)
    bad = [dict(cfg.sections[0], od_m=0.1, id_m=0.1)]
    with pytest.raises(ModelError, match="id_m < od_m"):
        build_string(bad, 1000.0)


def test_section_index_at_boundaries():
    a, b = Section("a", .2, .1, 10., .1, 50.), Section("b", .3, .1, 5., .15, 90.)
    s = DrillString((a, b))
    assert s.section_index([0.0, 9.999, 10.0, 15.0]).tolist() == [0, 0, 1, 1]


def test_string_longer_than_the_bit_depth_says_when_the_string_is_the_default():
    """Issue 35 (Volve F-9, bit at ~150 m, no [string] given): "fix: shorten the BHA
    sections" did not say the string was the built-in default; the fix names the key to
    give. A configured string keeps the advice to shorten its sections."""
    entries = [dict(s) for s in load_config().sections]
    with pytest.raises(ModelError) as default:
        build_string(entries, 150.0)
    said = str(default.value)
    assert "no [[string.sections]] was given, so the built-in default string is used" in said
    assert "110 m 5in HWDP + 120 m 8in collars" in said and "shorten" not in said
    # a configured string, even one whose sections say "(assumed)" (examples/usrop_f5.toml)
    mine = [{**e, "name": e["name"].replace("5in HWDP", "5in HWDP, 2 joints")} for e in entries]
    with pytest.raises(ModelError, match=r"shorten the BHA sections \(\[\[string.sections\]\]"):
        build_string(mine, 150.0)
