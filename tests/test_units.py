"""Unit conversion: drilling spellings against exact definitions (NIST SP 811 factors)."""

from __future__ import annotations

import math
import re
import subprocess
import sys
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from drillfric.errors import ConfigError, InputError
from drillfric.units import (
    RESOLUTION_SI,
    conversion_factor,
    display_factor,
    display_resolution,
    display_unit,
    format_number,
    format_value,
    from_si,
    number,
    quantity_value,
    to_display,
    to_si,
)

LBF = 4.4482216152605  # N, exact by definition of the avoirdupois pound and g_n
FT = 0.3048  # m, exact


@pytest.mark.parametrize("unit, kind, factor", [
    ("kN.m", "torque", 1000.0), ("kNm", "torque", 1000.0), ("kN-m", "torque", 1000.0),
    ("N.m", "torque", 1.0), ("ft.lbf", "torque", FT * LBF), ("ft-lbf", "torque", FT * LBF),
    ("klbf", "force", 1000 * LBF), ("kkgf", "force", 1000 * 9.80665), ("kN", "force", 1e3),
    ("g/cm3", "density", 1000.0), ("sg", "density", 1000.0),
    ("ppg", "density", 0.45359237 / 3.785411784e-3),
    ("rpm", "rpm", 1.0), ("RPM", "rpm", 1.0), ("c/s", "rpm", 60.0),
    ("rpm", "angular_velocity", 2 * np.pi / 60), ("ft", "length", FT), ("m", "length", 1.0),
    ("deg", "angle", np.pi / 180),
])
def test_drilling_spellings(unit, kind, factor):
    # exact definitions: only float round-off allowed
    assert conversion_factor(unit, kind) == pytest.approx(factor, rel=1e-12)


def test_wrong_kind_is_one_line():
    with pytest.raises(InputError, match="'klbf' is not a torque unit"):
        conversion_factor("klbf", "torque")


def test_unknown_unit():
    with pytest.raises(InputError, match="unknown unit 'furlongs/fortnight2'"):
        conversion_factor("furlongs/fortnight2", "length")


@given(st.lists(st.floats(-1e6, 1e6, allow_nan=False), min_size=1, max_size=20),
       st.sampled_from([("kN.m", "torque"), ("ft.lbf", "torque"), ("klbf", "force"),
                        ("ppg", "density"), ("ft", "length"), ("rpm", "angular_velocity")]))
def test_round_trip(values, unit_kind):
    """to_si then from_si is the identity (to round-off)."""
    unit, kind = unit_kind
    back = from_si(to_si(values, unit, kind), unit, kind)
    np.testing.assert_allclose(back, values, rtol=1e-12, atol=1e-9)


# --------------------------------------------------------------------------- quantities
IN = Fraction("0.0254")
LB = Fraction("0.45359237")
LBF_X = LB * Fraction("9.80665")


@pytest.mark.parametrize("text, unit, exact", [
    ("5 in", "m", 5 * IN),
    ("5 1/2 in", "m", Fraction(11, 2) * IN),
    ("5-1/2 in", "m", Fraction(11, 2) * IN),
    ("5½ in", "m", Fraction(11, 2) * IN),
    ("3/8 in", "m", Fraction(3, 8) * IN),
    ("-2 1/4 in", "m", -Fraction(9, 4) * IN),
    ("8200 ft", "m", 8200 * 12 * IN),
    ("1.2e3 ft", "m", 1200 * 12 * IN),
    ("10.5 ppg", "kg/m³", Fraction("10.5") * LB / (231 * IN ** 3)),
    ("1.42 sg", "kg/m³", Fraction(1420)),
    ("1.2 g/cm3", "kg/m³", Fraction(1200)),
    ("19.5 lb/ft", "kg/m", Fraction("19.5") * LB / (12 * IN)),
    ("40 klbf", "N", 40000 * LBF_X),
    ("35 kips", "N", 35000 * LBF_X),
    ("15 kkgf", "N", Fraction("15000") * Fraction("9.80665")),
    ("25 kft.lbf", "N·m", 25000 * 12 * IN * LBF_X),
    ("20 kN.m", "N·m", Fraction(20000)),
    ("3000 psi", "Pa", 3000 * LBF_X / IN ** 2),
    ("120 rpm", "RPM", Fraction(120)),
    ("2 min", "s", Fraction(120)),
    ("3 deg/(100 ft)", "°/30 m", Fraction(3 * 30) / (100 * 12 * IN)),
])
def test_quantity_values_are_the_exact_conversion_rounded_once(text, unit, exact):
    """Exact unit definitions (NIST SP 811) in rational arithmetic, rounded once: the
    conversion must give that float exactly (not within a tolerance)."""
    assert quantity_value(text, unit) == float(exact)


@pytest.mark.parametrize("text, unit, problem", [
    ("5 in", "kg/m³", "'5 in' is a length, not a density (kg/m³)"),
    ("40 klbf", "N·m", "'40 klbf' is a force, not a torque (N·m)"),
    ("7 kg", "m", "'7 kg' is a mass, not a length (m)"),
    ("5 furlongz", "m", "unknown unit 'furlongz'"),
    ("1200", "kg/m³", "'1200' has no unit"),
    ("heavy", "kg/m³", "'heavy' is not a number"),
])
def test_quantity_errors_say_what_was_given_and_what_is_expected(text, unit, problem):
    with pytest.raises(ConfigError, match=re.escape(problem)):
        quantity_value(text, unit)


def test_bare_numbers_are_in_the_unit_asked_for():
    assert quantity_value("8200", "m", bare=True) == 8200.0


@pytest.mark.parametrize("quantity, system, label, factor", [
    ("length", "field", "ft", 1 / 0.3048), ("force", "field", "klbf", 1 / (1000 * LBF)),
    ("torque", "field", "kft·lbf", 1 / (1000 * FT * LBF)),
    ("density", "field", "ppg", 3.785411784e-3 / 0.45359237),
    ("diameter", "field", "in", 1 / 0.0254), ("force", "si", "kN", 1e-3),
    ("torque", "si", "kN·m", 1e-3), ("length", "si", "m", 1.0),
])
def test_display_units(quantity, system, label, factor):
    # exact definitions: only float round-off allowed
    assert display_unit(quantity, system) == label
    assert display_factor(quantity, system) == pytest.approx(factor, rel=1e-12)


def test_format_value():
    assert format_value(2286.0, "length", "field", ".0f") == "7500 ft"
    assert format_value(float("nan"), "length") == "—"


def test_pint_is_not_imported_with_the_configuration():
    """The registry is built on first use: importing the configuration (every command does)
    must not import pint (0.2–0.3 s) nor build a registry (0.15 s)."""
    code = "import sys, drillfric.config, drillfric.units; print('pint' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "False"


# --------------------------------------------------------------------------- number text
_QUANTITIES = sorted(RESOLUTION_SI)


@given(st.floats(allow_nan=False, allow_infinity=False, min_value=-1e8, max_value=1e8),
       st.sampled_from(_QUANTITIES), st.sampled_from(["si", "field"]))
def test_bit_rpm_median_printed_as_1e_34(value, quantity, system):
    """Issue 35 (fourth newcomer): inspect printed a bit_rpm median as "1.173e-34". A value
    of an ordinary quantity is written without an exponent, a value below half its
    resolution as 0, never finer than the resolution, and reads back within it."""
    shown = to_display(value, quantity, system)
    assume(abs(shown) < 1e9)  # beyond: an exponent (a broken log's 1e308)
    text = format_number(value, quantity, system)
    step = display_resolution(quantity, system)
    assert "e" not in text.lower() and text != "-0"
    if abs(shown) < step / 2:
        assert text == "0"
    if "." in text:
        assert len(text.split(".")[1]) <= round(-math.log10(step))
    # 4 significant digits at most, or the resolution: within either of the two
    assert abs(float(text) - shown) <= max(step / 2, 5e-4 * abs(shown)) * (1 + 1e-9) + 1e-12


@given(st.floats(allow_nan=False, allow_infinity=False, min_value=-1e-3, max_value=1e-3))
def test_tiny_rpm_is_zero(value):
    """A numerical zero of a speed (within 0.05 RPM) prints as 0, whatever its sign."""
    assert number(value, 0.1) == "0"


def test_number_text_cases():
    assert [number(v, r) for v, r in ((1.173e-34, 0.1), (40.1, 0.1), (-13.49, 0.1),
                                      (2.549e5, None), (3e12, None), (None, 0.1))] == [
        "0", "40.1", "-13.5", "254900", "3e+12", "—"]
